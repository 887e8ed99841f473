#include "cli_common.h"

#include <ostream>

#include "liftoff/capture/log_loader.h"

namespace liftoff::cli {

int ExitCodeFor(StatusCode code) {
  switch (code) {
    case StatusCode::kOk: return kExitOk;
    case StatusCode::kInvalidArgument: return 3;
    case StatusCode::kNotFound: return 4;
    case StatusCode::kParse: return 5;
    case StatusCode::kIo: return 6;
    case StatusCode::kTimeout: return 7;
    case StatusCode::kUnsupported: return 8;
    case StatusCode::kOutOfRange: return 9;
  }
  return kExitInternal;
}

int ReportError(const Status& status, std::ostream& err) {
  err << "liftoff: " << status.ToString() << '\n';
  return ExitCodeFor(status.code());
}

Result<Calibration> ChooseCalibration(const CalibrationChoice& choice,
                                      const std::filesystem::path& manifest_choice) {
  // flag, then manifest, then the built-in default
  std::filesystem::path path = choice.calibration_path;
  if (path.empty()) path = manifest_choice;
  if (path.empty()) path = DefaultCalibrationPath();
  return LoadCalibration(path);
}

Status CheckSecondsFlag(std::string_view flag, double value_s, const NumberRange& range) {
  if (InNumberRange(value_s, range)) return Status::Ok();
  return InvalidArgumentError(std::string(flag) + ": expected " + DescribeNumberRange(range) +
                              " s, got " + FormatNumber(value_s));
}

Result<sync::LookupOptions> LookupOptionsFrom(const LookupChoice& choice) {
  sync::LookupOptions options;
  const auto rule = sync::ParseLookupRule(choice.rule);
  if (!rule) {
    return InvalidArgumentError("--rule: expected linear or hold, got \"" + choice.rule + "\"");
  }
  options.rule = *rule;
  LIFTOFF_RETURN_IF_ERROR(CheckSecondsFlag("--gap-threshold", choice.gap_threshold_s,
                                           sync::LookupOptions::kGapThresholdRange));
  LIFTOFF_RETURN_IF_ERROR(CheckSecondsFlag("--max-past-end", choice.max_past_end_s,
                                           sync::LookupOptions::kMaxPastEndRange));
  options.gap_threshold_s = choice.gap_threshold_s;
  options.max_past_end_s = choice.max_past_end_s;
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  return options;
}

Result<ControllerLog> LoadLogByName(const std::filesystem::path& path, const std::string& format,
                                    const Calibration& calibration, const LogReadOptions& options) {
  std::optional<LogFormat> parsed;
  if (format == "auto") {
    LIFTOFF_ASSIGN_OR_RETURN(parsed, DetectLogFormat(path));
  } else {
    parsed = ParseLogFormat(format);
    if (!parsed) {
      return InvalidArgumentError("--log-format: expected auto, liftoff or laika-2018, got \"" +
                                  format + "\"");
    }
  }
  return capture::LoadControllerLog(path, *parsed, calibration, options);
}

void PrintLogWarnings(const LogReadReport& report, std::ostream& err) {
  if (report.bad_lines == 0) return;
  err << "warning: " << report.Brief() << '\n';
  for (const LogIssue& issue : report.issues) {
    err << "  " << report.source.filename().string() << ":" << issue.line << ": " << issue.reason
        << '\n';
  }
  const auto listed = static_cast<int64_t>(report.issues.size());
  if (report.bad_lines > listed) {
    err << "  ... and " << (report.bad_lines - listed) << " more\n";
  }
}

}  // namespace liftoff::cli
