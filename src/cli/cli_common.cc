#include "cli_common.h"

#include <cstdio>
#include <ostream>

#include "liftoff/capture/laika2018.h"
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

Status CheckFlagRange(std::string_view flag, double value, const NumberRange& range,
                      std::string_view unit) {
  if (InNumberRange(value, range)) return Status::Ok();
  return InvalidArgumentError(std::string(flag) + ": expected " + DescribeNumberRange(range) +
                              (unit.empty() ? "" : " ") + std::string(unit) + ", got " +
                              FormatNumber(value));
}

Result<stats::TableFormat> TableFormatFlag(const std::string& text) {
  if (const auto format = stats::ParseTableFormat(text)) return *format;
  return InvalidArgumentError("--format: expected md, csv, latex or json, got \"" + text + "\"");
}

void AddCalibrationFlag(Command& app, CalibrationChoice& choice) {
  app.AddOption("--calibration,-c", choice.calibration_path,
                 "Calibration JSON (default: the manifest's, else calib/laika-2018.json)");
}

void AddLookupFlags(Command& app, LookupChoice& lookup) {
  app.AddOption("--rule", lookup.rule,
                 "Angle lookup: linear (interpolate) or hold (last sample at or before, the "
                 "2018 authors' rule)")
      ->ShowDefault();
  app.AddOption("--gap-threshold", lookup.gap_threshold_s,
                 "Samples further apart than this bracket a gap, seconds")
      ->ShowDefault();
  app.AddOption("--max-past-end", lookup.max_past_end_s,
                 "Answer lookups up to this far past the log's last sample, seconds")
      ->ShowDefault();
  app.AddOption("--max-bad-lines", lookup.max_bad_lines,
                 "Malformed log lines to skip (reported) before a log is rejected")
      ->ShowDefault();
}

Status NameFlagsIn(const Status& status,
                   std::initializer_list<std::pair<std::string, std::string>> flag_fields) {
  if (status.ok()) return status;
  for (const auto& [flag, field] : flag_fields) {
    if (auto message = MessageNamingFlag(status.message(), flag, field, false)) {
      return Status(status.code(), *message);
    }
  }
  return status;
}

Status CheckMaxBadLinesFlag(int64_t max_bad_lines) {
  LogReadOptions options;
  options.max_bad_lines = max_bad_lines;
  return NameFlagsIn(options.Validate(), {{"--max-bad-lines", "LogReadOptions.max_bad_lines"}});
}

Status CheckLookupFlags(const sync::LookupOptions& options) {
  return NameFlagsIn(options.Validate(), {{"--gap-threshold", "lookup options.gap_threshold_s"},
                                          {"--max-past-end", "lookup options.max_past_end_s"}});
}

Result<sync::LookupOptions> LookupOptionsFrom(const LookupChoice& choice) {
  LIFTOFF_RETURN_IF_ERROR(CheckMaxBadLinesFlag(choice.max_bad_lines));
  sync::LookupOptions options;
  const auto rule = sync::ParseLookupRule(choice.rule);
  if (!rule) {
    return InvalidArgumentError("--rule: expected linear or hold, got \"" + choice.rule + "\"");
  }
  options.rule = *rule;
  options.gap_threshold_s = choice.gap_threshold_s;
  options.max_past_end_s = choice.max_past_end_s;
  LIFTOFF_RETURN_IF_ERROR(CheckLookupFlags(options));
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

Result<TrialManifest> LoadTrials(const std::filesystem::path& path, std::ostream& err) {
  std::error_code error;
  if (!std::filesystem::is_directory(path, error)) return LoadManifest(path);
  if (!std::filesystem::exists(path / capture::kLaika2018TimesCsv, error)) {
    return InvalidArgumentError(path.string() + ": is a folder without \"" +
                                capture::kLaika2018TimesCsv +
                                "\"; expected a trial manifest (JSON) or a 2018 Laika folder");
  }
  auto imported = capture::ImportLaika2018Folder(path, path / "manifest.json");
  if (!imported.ok()) return imported.status();
  for (const std::string& warning : imported->warnings) err << "warning: " << warning << '\n';
  return std::move(imported->manifest);
}

std::vector<NamedPath> TrialInputs(const TrialManifest& manifest) {
  std::vector<NamedPath> inputs;
  if (manifest.calibration_path) {
    inputs.push_back({"the manifest's calibration", *manifest.calibration_path});
  }
  for (const TrialRecord& trial : manifest.trials) {
    inputs.push_back({"trial " + trial.id + "'s log", trial.log_path});
    if (trial.video_path) inputs.push_back({"trial " + trial.id + "'s video", *trial.video_path});
  }
  return inputs;
}

int RefuseToOverwriteInputs(const std::vector<NamedPath>& outputs,
                            const std::vector<NamedPath>& inputs, std::ostream& err) {
  const Status checked = CheckOutputsAreNotInputs(outputs, inputs);
  return checked.ok() ? kExitOk : ReportError(checked, err);
}

std::string HashHex(std::string_view bytes) {
  uint64_t hash = 14695981039346656037ULL;
  for (const char byte : bytes) {
    hash ^= static_cast<unsigned char>(byte);
    hash *= 1099511628211ULL;
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
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
