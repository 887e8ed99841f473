// `liftoff log`: what a controller log holds; its conversion.
#include "liftoff/cli/commands.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <ostream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/sync/trial_analysis.h"

namespace liftoff::cli {
namespace {

// The sample stream's span, rate and gaps, and the vertebra's range.
struct LogStats {
  int64_t gaps = 0;                // steps longer than the gap threshold
  int64_t longest_gap_ns = 0;      // the longest step
  int64_t longest_gap_at_ns = 0;   // the sample it follows
  double rate_hz = 0.0;            // mean sample rate; 0 for under two instants
  double min_angle_rad = INFINITY, max_angle_rad = -INFINITY;  // infinite without angles
};

LogStats MeasureLog(const ControllerLog& log, int64_t gap_threshold_ns) {
  const std::vector<LogSample>& samples = log.samples;
  LogStats stats;
  for (size_t i = 1; i < samples.size(); ++i) {
    const int64_t step = samples[i].device_time_ns - samples[i - 1].device_time_ns;
    if (step > gap_threshold_ns) ++stats.gaps;
    if (step > stats.longest_gap_ns) {
      stats.longest_gap_ns = step;
      stats.longest_gap_at_ns = samples[i - 1].device_time_ns;
    }
  }
  const int64_t span_ns = log.LastSampleNs() - log.FirstSampleNs();
  if (span_ns > 0) stats.rate_hz = static_cast<double>(samples.size() - 1) / SecondsFromNs(span_ns);
  for (const LogSample& sample : samples) {
    if (std::isnan(sample.vertebra_rad)) continue;
    stats.min_angle_rad = std::min(stats.min_angle_rad, sample.vertebra_rad);
    stats.max_angle_rad = std::max(stats.max_angle_rad, sample.vertebra_rad);
  }
  return stats;
}

// The summary as `log --json` prints it.
nlohmann::json LogJson(const LogCommand& command, const ControllerLog& log, const LogStats& stats) {
  const std::optional<int64_t> led_ns = log.LedOnTimeNs();
  return {
      {"log", command.log_path.string()},
      {"format", log.report.format},
      {"calibration", log.header.calibration},
      {"samples", log.samples.size()},
      {"events", log.events.size()},
      {"first_sample_s", SecondsFromNs(log.FirstSampleNs())},
      {"last_sample_s", SecondsFromNs(log.LastSampleNs())},
      {"mean_rate_hz", stats.rate_hz},
      {"gaps", stats.gaps},
      {"gap_threshold_s", command.gap_threshold_s},
      {"longest_gap_s", SecondsFromNs(stats.longest_gap_ns)},
      {"led_on_s", led_ns ? nlohmann::json(SecondsFromNs(*led_ns)) : nlohmann::json()},
      {"vertebra_min_rad", NumberOrNull(stats.min_angle_rad)},
      {"vertebra_max_rad", NumberOrNull(stats.max_angle_rad)},
      {"bad_lines", log.report.bad_lines},
      {"truncated_last_line", log.report.truncated_last_line},
  };
}

// The summary as `log` prints it.
void PrintLog(const LogCommand& command, const ControllerLog& log, const LogStats& stats,
              const Calibration& calibration, std::ostream& out) {
  const std::optional<int64_t> led_ns = log.LedOnTimeNs();
  out << command.log_path.string() << " (" << log.report.format << ")\n"
      << "  samples: " << log.samples.size() << ", events: " << log.events.size()
      << ", bad lines: " << log.report.bad_lines
      << (log.report.truncated_last_line ? " (last line truncated)" : "") << '\n'
      << "  device time: " << FormatSeconds(log.FirstSampleNs()) << " .. "
      << FormatSeconds(log.LastSampleNs()) << " s, mean rate " << FormatFixed(stats.rate_hz, 1)
      << " Hz\n"
      << "  gaps longer than " << FormatFixed(command.gap_threshold_s, 3) << " s: " << stats.gaps;
  if (stats.longest_gap_ns > 0) {
    out << " (longest " << FormatSeconds(stats.longest_gap_ns) << " s after "
        << FormatSeconds(stats.longest_gap_at_ns) << " s)";
  }
  out << '\n'
      << "  LED on: "
      << (led_ns ? FormatSeconds(*led_ns) + " s" : "no LED event (origin = LED on)") << '\n';
  if (std::isfinite(stats.min_angle_rad)) {
    out << "  vertebra angle: " << FormatFixed(stats.min_angle_rad, 4) << " .. "
        << FormatFixed(stats.max_angle_rad, 4) << " rad (calibration " << calibration.Brief()
        << ")\n";
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// liftoff log

int RunLog(const LogCommand& command, std::ostream& out, std::ostream& err) {
  sync::LookupOptions lookup;
  lookup.gap_threshold_s = command.gap_threshold_s;
  const Status gap_checked = CheckLookupFlags(lookup);
  if (!gap_checked.ok()) return ReportError(gap_checked, err);
  const Status bad_lines_checked = CheckMaxBadLinesFlag(command.max_bad_lines);
  if (!bad_lines_checked.ok()) return ReportError(bad_lines_checked, err);
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  if (const int refused = RefuseToOverwriteInputs(
          {{"--convert", command.convert_path}},
          {{"LOG", command.log_path}, {"calibration", calibration->source_path}}, err);
      refused != kExitOk) {
    return refused;
  }
  LogReadOptions read_options;
  read_options.max_bad_lines = command.max_bad_lines;
  auto log = LoadLogByName(command.log_path, command.log_format, *calibration, read_options);
  if (!log.ok()) return ReportError(log.status(), err);
  PrintLogWarnings(log->report, err);

  const LogStats stats = MeasureLog(*log, NsFromSeconds(command.gap_threshold_s));
  if (command.json) {
    out << LogJson(command, *log, stats).dump(2) << '\n';
  } else {
    PrintLog(command, *log, stats, *calibration, out);
  }

  if (!command.convert_path.empty()) {
    const Status written = WriteControllerLog(command.convert_path, *log);
    if (!written.ok()) return ReportError(written, err);
    err << "wrote " << command.convert_path.string() << '\n';
  }
  return kExitOk;
}

Subcommand AddLogCommand(Command& parent) {
  auto command = std::make_shared<LogCommand>();
  Command* app = parent.AddSubcommand(
      "log", "What a controller log holds; optionally convert it to liftoff's format");
  app->AddOption("log", command->log_path, "Controller log")->Required();
  app->AddOption("--log-format", command->log_format, "auto, liftoff or laika-2018")
      ->ShowDefault();
  AddCalibrationFlag(*app, command->calibration);
  app->AddOption("--max-bad-lines", command->max_bad_lines, "Malformed lines to skip (reported)")
      ->ShowDefault();
  app->AddOption("--gap-threshold", command->gap_threshold_s, "Gap threshold, seconds")
      ->ShowDefault();
  app->AddOption("--convert", command->convert_path, "Write the log in liftoff's format here");
  app->AddSwitch("--json", command->json, "JSON output");
  return RunsWith(app, command, RunLog);
}

}  // namespace liftoff::cli
