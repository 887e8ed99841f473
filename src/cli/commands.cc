#include "liftoff/cli/commands.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/capture/laika2018.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/output.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/stats/plot.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/table.h"
#include "liftoff/sync/trial_analysis.h"
#include "liftoff/video/clip_analysis.h"
#include "liftoff/video/verification.h"

namespace liftoff::cli {
namespace {

// Sends finished text to the output file, or to `out` when none is named.
int Emit(const std::string& text, const std::filesystem::path& output_path, std::ostream& out,
         std::ostream& err) {
  if (output_path.empty()) {
    out << text;
    return kExitOk;
  }
  const Status written = WriteFileAtomically(output_path, text);
  if (!written.ok()) return ReportError(written, err);
  err << "wrote " << output_path.string() << '\n';
  return kExitOk;
}

// the two instants from the command line: both, bounded so they convert to nanoseconds
Result<EventTimes> TimesFromFlags(const SyncCommand& command) {
  if (!command.led_on_s || !command.liftoff_s) {
    return InvalidArgumentError("--led-on and --liftoff: give both video instants, or --video");
  }
  constexpr NumberRange kTimeRange{.min = 0.0, .max = kMaxTimeSeconds};
  for (const auto& [flag, value_s] :
       {std::pair{"--led-on", *command.led_on_s}, std::pair{"--liftoff", *command.liftoff_s},
        std::pair{"--uncertainty", command.uncertainty_s}}) {
    LIFTOFF_RETURN_IF_ERROR(CheckFlagRange(flag, value_s, kTimeRange, "s"));
  }
  EventTimes times;
  times.led_on_ns = NsFromSeconds(*command.led_on_s);
  times.liftoff_ns = NsFromSeconds(*command.liftoff_s);
  times.led_on_uncertainty_ns = NsFromSeconds(command.uncertainty_s);
  times.liftoff_uncertainty_ns = times.led_on_uncertainty_ns;
  times.source = "command line";
  return times;
}

// what `table` writes: the tables, the plot, a verification image per trial with a video
std::vector<NamedPath> TableOutputs(const TableCommand& command, const TrialManifest& manifest) {
  std::vector<NamedPath> outputs = {{"--output", command.output_path},
                                    {"--plot", command.plot_path}};
  if (command.verify_dir.empty()) return outputs;
  for (const TrialRecord& trial : manifest.trials) {
    if (!trial.video_path) continue;
    outputs.push_back({"--verify-dir", TrialVerificationPath(command.verify_dir, trial.id)});
  }
  return outputs;
}

// what `table` reads: the manifest (or the 2018 folder's times), the calibration, the
// simulation results, every trial's log and video
std::vector<NamedPath> TableInputs(const TableCommand& command, const TrialManifest& manifest,
                                   const Calibration& calibration) {
  std::vector<NamedPath> inputs = TrialInputs(manifest);
  std::error_code error;
  inputs.push_back({"MANIFEST", std::filesystem::is_directory(command.manifest_path, error)
                                    ? command.manifest_path / capture::kLaika2018TimesCsv
                                    : command.manifest_path});
  inputs.push_back({"calibration", calibration.source_path});
  inputs.push_back({"--sim", command.sim_path});
  return inputs;
}

// The lines about one trial a person should see: log warnings, the video's brief and
// warnings, the failure, the lookup's notes.
void PrintOutcomeNotes(const sync::TrialOutcome& outcome, std::ostream& err) {
  PrintLogWarnings(outcome.log_report, err);
  if (outcome.video) {
    err << "note: " << outcome.trial.id << ": video: " << outcome.video->Brief() << '\n';
    for (const std::string& warning : outcome.video->warnings) {
      err << "warning: " << outcome.trial.id << ": video: " << warning << '\n';
    }
  }
  if (!outcome.status.ok()) {
    err << "error: " << outcome.status.ToString() << '\n';
    return;
  }
  for (const std::string& warning : outcome.measurement->lookup.warnings) {
    err << "note: " << outcome.trial.id << ": " << warning << '\n';
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// liftoff table

Result<CampaignAnalysis> AnalyzeCampaign(const std::filesystem::path& manifest_path,
                                         const CalibrationChoice& calibration_choice,
                                         const LookupChoice& lookup_choice,
                                         std::string_view progress_mode, std::ostream& err) {
  // options, then inputs: manifest (or a 2018 folder read as one) and calibration
  auto lookup = LookupOptionsFrom(lookup_choice);
  if (!lookup.ok()) return lookup.status();
  auto progress = VideoProgress::Create(progress_mode, err);
  if (!progress.ok()) return progress.status();
  CampaignAnalysis campaign;
  auto manifest = LoadTrials(manifest_path, err);
  if (!manifest.ok()) return manifest.status();
  campaign.manifest = std::move(manifest).value();
  auto calibration = ChooseCalibration(
      calibration_choice, campaign.manifest.calibration_path.value_or(std::filesystem::path()));
  if (!calibration.ok()) return calibration.status();
  campaign.calibration = std::move(calibration).value();

  // every trial through sync (videos without times through video analysis)
  sync::AnalysisOptions options;
  options.lookup = *lookup;
  options.log.max_bad_lines = lookup_choice.max_bad_lines;
  options.video_progress = [&](const TrialRecord& trial, int64_t frames_done, int64_t t_ns) {
    progress->Show(trial.id, frames_done, t_ns);
  };
  campaign.analysis = sync::AnalyzeManifest(campaign.manifest, campaign.calibration, options);
  progress->Done();

  // what a person should know about each trial, on `err` and kept per trial
  for (const sync::TrialOutcome& outcome : campaign.analysis.outcomes) {
    std::ostringstream lines;
    PrintOutcomeNotes(outcome, lines);
    err << lines.str();
    std::vector<std::string>& notes = campaign.notes.emplace_back();
    std::istringstream split(lines.str());
    for (std::string line; std::getline(split, line);) notes.push_back(line);
    if (!outcome.status.ok() && campaign.first_failure.ok()) {
      campaign.first_failure = outcome.status;
    }
  }
  return campaign;
}

int RunTable(const TableCommand& command, std::ostream& out, std::ostream& err) {
  // flags
  const auto format = stats::ParseTableFormat(command.format);
  if (!format) {
    return ReportError(InvalidArgumentError("--format: expected md, csv, latex or json, got \"" +
                                            command.format + "\""),
                       err);
  }
  if (command.tables != "both" && command.tables != "trials" && command.tables != "feet") {
    return ReportError(InvalidArgumentError("--tables: expected both, trials or feet, got \"" +
                                            command.tables + "\""),
                       err);
  }
  std::optional<stats::SimResults> sim = command.sim_results;
  if (!sim && !command.sim_path.empty()) {
    auto loaded = stats::LoadSimResults(command.sim_path);
    if (!loaded.ok()) return ReportError(loaded.status(), err);
    sim = std::move(loaded).value();
  }

  // every trial; failures are reported and the rest still tabulated
  auto campaign = AnalyzeCampaign(command.manifest_path, command.calibration, command.lookup,
                                  command.progress, err);
  if (!campaign.ok()) return ReportError(campaign.status(), err);
  // nothing is written before this: no output may be one of the inputs
  if (const int refused = RefuseToOverwriteInputs(
          TableOutputs(command, campaign->manifest),
          TableInputs(command, campaign->manifest, campaign->calibration), err);
      refused != kExitOk) {
    return refused;
  }
  const sync::ManifestAnalysis& analysis = campaign->analysis;
  const Status first_failure = campaign->first_failure;

  // tables
  const std::vector<stats::TrialValue> values = analysis.Values();
  const std::string rule_name(sync::LookupRuleName(analysis.rule));
  const stats::ResultsTable table =
      stats::BuildResultsTable(values, sim ? &*sim : nullptr, analysis.calibration, rule_name);
  std::string text;
  if (command.tables == "trials") {
    text = stats::RenderTrialTable(values, *format, analysis.calibration, rule_name);
  } else if (command.tables == "feet" || *format == stats::TableFormat::kJson) {
    text = stats::RenderResultsTable(table, *format);  // JSON holds the trials too
  } else {
    text = stats::RenderTrialTable(values, *format, analysis.calibration, rule_name) + "\n" +
           stats::RenderResultsTable(table, *format);
  }
  const int emitted = Emit(text, command.output_path, out, err);
  if (emitted != kExitOk) return emitted;
  Status verified;
  if (!command.verify_dir.empty()) {
    verified = WriteTrialVerifications(analysis, command.verify_dir, err);
  }
  if (!command.plot_path.empty() && verified.ok()) {
    auto plot = stats::RenderResultsPlotSvg(table);
    verified = plot.ok() ? WriteFileAtomically(command.plot_path, *plot) : plot.status();
    if (verified.ok()) err << "wrote " << command.plot_path.string() << '\n';
  }

  if (!first_failure.ok()) {
    err << "liftoff: " << analysis.failed() << " of " << analysis.outcomes.size()
        << " trials failed; the table holds the others\n";
    return ExitCodeFor(first_failure.code());
  }
  return verified.ok() ? kExitOk : ExitCodeFor(verified.code());
}

// ---------------------------------------------------------------------------------------
// liftoff import-2018

int RunImport2018(const Import2018Command& command, std::ostream& out, std::ostream& err) {
  if (command.output_path.empty()) {
    return ReportError(InvalidArgumentError("--output: name the manifest file to write"), err);
  }
  auto imported = capture::ImportLaika2018Folder(command.folder, command.output_path);
  if (!imported.ok()) return ReportError(imported.status(), err);
  // never onto the folder's own files, --force or not
  std::vector<NamedPath> inputs = TrialInputs(imported->manifest);
  inputs.push_back({"FOLDER's times", command.folder / capture::kLaika2018TimesCsv});
  if (const int refused =
          RefuseToOverwriteInputs({{"--output", command.output_path}}, inputs, err);
      refused != kExitOk) {
    return refused;
  }
  if (const Status refused = RefuseToReplace(command.output_path, "", command.force);
      !refused.ok()) {
    return ReportError(refused, err);
  }
  for (const std::string& warning : imported->warnings) err << "warning: " << warning << '\n';
  const Status written = WriteManifest(command.output_path, imported->manifest);
  if (!written.ok()) return ReportError(written, err);
  out << "wrote " << command.output_path.string() << ": " << imported->manifest.trials.size()
      << " trials from " << command.folder.string() << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff sync

int RunSync(const SyncCommand& command, std::ostream& out, std::ostream& err) {
  // flags: exactly one source of the video instants
  auto lookup = LookupOptionsFrom(command.lookup);
  if (!lookup.ok()) return ReportError(lookup.status(), err);
  const bool from_video = !command.video_path.empty();
  const bool from_flags = command.led_on_s || command.liftoff_s;
  if (from_video && (from_flags || command.uncertainty_s != 0.0)) {
    return ReportError(InvalidArgumentError("--video excludes --led-on, --liftoff and "
                                            "--uncertainty: the clip's analysis gives the instants "
                                            "and their uncertainties"),
                       err);
  }
  if (!from_video && !from_flags) {
    return ReportError(InvalidArgumentError("no video instants: give --led-on S --liftoff S, or "
                                            "--video CLIP --foot-roi x,y,w,h to find them"),
                       err);
  }
  EventTimes times;
  std::optional<video::ClipAnalysisOptions> clip_options;
  std::optional<VideoProgress> progress;
  if (from_video) {
    if (command.clip.foot_roi.empty()) {
      return ReportError(
          InvalidArgumentError("--video needs --foot-roi x,y,w,h: the liftoff comes from the foot"),
          err);
    }
    auto options = ClipOptionsFrom(command.clip);
    if (!options.ok()) return ReportError(options.status(), err);
    clip_options = std::move(options).value();
    auto created = VideoProgress::Create(command.progress, err);
    if (!created.ok()) return ReportError(created.status(), err);
    progress = std::move(created).value();
  } else {
    auto flagged = TimesFromFlags(command);
    if (!flagged.ok()) return ReportError(flagged.status(), err);
    times = std::move(flagged).value();
  }

  // the log (before the video: a bad log fails fast)
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  LogReadOptions read_options;
  read_options.max_bad_lines = command.lookup.max_bad_lines;
  if (const int refused = RefuseToOverwriteInputs(
          {{"--verify", command.verify_path}},
          {{"LOG", command.log_path}, {"--video", command.video_path},
           {"calibration", calibration->source_path}},
          err);
      refused != kExitOk) {
    return refused;
  }
  auto log = LoadLogByName(command.log_path, command.log_format, *calibration, read_options);
  if (!log.ok()) return ReportError(log.status(), err);
  PrintLogWarnings(log->report, err);

  // the instants from the clip, with proof when asked for
  std::optional<video::ClipAnalysis> clip;
  if (from_video) {
    auto analysis = AnalyzeClipShowingProgress(command.video_path, *clip_options, *progress);
    if (!analysis.ok()) return ReportError(analysis.status(), err);
    clip = std::move(analysis).value();
    for (const std::string& warning : clip->warnings) err << "warning: video: " << warning << '\n';
    auto events = clip->Events();
    if (!events.ok()) return ReportError(events.status(), err);
    times = std::move(events).value();
    if (!command.verify_path.empty()) {
      video::VerificationOptions verify_options;
      verify_options.image_path = command.verify_path;
      auto written = video::WriteVerification(*clip, verify_options);
      if (!written.ok()) return ReportError(written.status(), err);
      err << "wrote " << written->Brief() << '\n';
    }
  }
  auto measured = sync::MeasureLiftoff(*log, times, *lookup);
  if (!measured.ok()) {
    return ReportError(measured.status().WithContext(command.log_path.filename().string()), err);
  }

  const sync::AngleLookup& at = measured->lookup;
  if (command.json) {
    nlohmann::json document = {
        {"log", command.log_path.string()},
        {"calibration", calibration->Brief()},
        {"rule", sync::LookupRuleName(lookup->rule)},
        {"interval_s", SecondsFromNs(measured->interval_ns)},
        {"interval_uncertainty_s", SecondsFromNs(measured->interval_uncertainty_ns)},
        {"liftoff_log_s", SecondsFromNs(measured->liftoff_log_ns)},
        {"vertebra_rad", at.vertebra_rad},
        {"liftoff_rad", measured->liftoff_rad},
        {"lower_rad", measured->lower_rad},
        {"upper_rad", measured->upper_rad},
        {"in_gap", at.in_gap},
        {"past_end", at.past_end},
        {"warnings", at.warnings},
        {"times",
         {{"source", times.source},
          {"led_on_s", SecondsFromNs(times.led_on_ns)},
          {"led_on_uncertainty_s", SecondsFromNs(times.led_on_uncertainty_ns)},
          {"liftoff_s", SecondsFromNs(times.liftoff_ns)},
          {"liftoff_uncertainty_s", SecondsFromNs(times.liftoff_uncertainty_ns)}}},
        {"video", clip ? clip->ToJson() : nlohmann::json()},
    };
    out << document.dump(2) << '\n';
    return kExitOk;
  }
  if (clip) out << "video: " << clip->Brief() << '\n';
  out << "calibration: " << calibration->Brief() << "; rule: " << sync::LookupRuleName(lookup->rule)
      << '\n'
      << "interval LED on -> liftoff: " << FormatSeconds(measured->interval_ns, 3) << " s +- "
      << FormatSeconds(measured->interval_uncertainty_ns, 3) << " s\n"
      << "log instant: " << FormatSeconds(measured->liftoff_log_ns, 3) << " s\n"
      << "vertebra angle: " << FormatFixed(at.vertebra_rad, 4) << " rad; at liftoff |angle| "
      << FormatFixed(measured->liftoff_rad, 4) << " rad in [" << FormatFixed(measured->lower_rad, 4)
      << ", " << FormatFixed(measured->upper_rad, 4) << "]\n";
  for (const std::string& warning : at.warnings) out << "note: " << warning << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff log

int RunLog(const LogCommand& command, std::ostream& out, std::ostream& err) {
  const Status gap_checked = CheckFlagRange("--gap-threshold", command.gap_threshold_s,
                                            sync::LookupOptions::kGapThresholdRange, "s");
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

  // span, rate and gaps of the sample stream
  const std::vector<LogSample>& samples = log->samples;
  const int64_t gap_threshold_ns = NsFromSeconds(command.gap_threshold_s);
  int64_t gaps = 0;
  int64_t longest_gap_ns = 0;
  int64_t longest_gap_at_ns = 0;
  for (size_t i = 1; i < samples.size(); ++i) {
    const int64_t step = samples[i].device_time_ns - samples[i - 1].device_time_ns;
    if (step > gap_threshold_ns) ++gaps;
    if (step > longest_gap_ns) {
      longest_gap_ns = step;
      longest_gap_at_ns = samples[i - 1].device_time_ns;
    }
  }
  const int64_t span_ns = log->LastSampleNs() - log->FirstSampleNs();
  const double rate_hz =
      span_ns > 0 ? static_cast<double>(samples.size() - 1) / SecondsFromNs(span_ns) : 0.0;
  const std::optional<int64_t> led_ns = log->LedOnTimeNs();
  double min_angle = INFINITY, max_angle = -INFINITY;
  for (const LogSample& sample : samples) {
    if (std::isnan(sample.vertebra_rad)) continue;
    min_angle = std::min(min_angle, sample.vertebra_rad);
    max_angle = std::max(max_angle, sample.vertebra_rad);
  }

  if (command.json) {
    nlohmann::json document = {
        {"log", command.log_path.string()},
        {"format", log->report.format},
        {"calibration", log->header.calibration},
        {"samples", samples.size()},
        {"events", log->events.size()},
        {"first_sample_s", SecondsFromNs(log->FirstSampleNs())},
        {"last_sample_s", SecondsFromNs(log->LastSampleNs())},
        {"mean_rate_hz", rate_hz},
        {"gaps", gaps},
        {"gap_threshold_s", command.gap_threshold_s},
        {"longest_gap_s", SecondsFromNs(longest_gap_ns)},
        {"led_on_s", led_ns ? nlohmann::json(SecondsFromNs(*led_ns)) : nlohmann::json()},
        {"vertebra_min_rad",
         std::isfinite(min_angle) ? nlohmann::json(min_angle) : nlohmann::json()},
        {"vertebra_max_rad",
         std::isfinite(max_angle) ? nlohmann::json(max_angle) : nlohmann::json()},
        {"bad_lines", log->report.bad_lines},
        {"truncated_last_line", log->report.truncated_last_line},
    };
    out << document.dump(2) << '\n';
  } else {
    out << command.log_path.string() << " (" << log->report.format << ")\n"
        << "  samples: " << samples.size() << ", events: " << log->events.size()
        << ", bad lines: " << log->report.bad_lines
        << (log->report.truncated_last_line ? " (last line truncated)" : "") << '\n'
        << "  device time: " << FormatSeconds(log->FirstSampleNs()) << " .. "
        << FormatSeconds(log->LastSampleNs()) << " s, mean rate " << FormatFixed(rate_hz, 1)
        << " Hz\n"
        << "  gaps longer than " << FormatFixed(command.gap_threshold_s, 3) << " s: " << gaps;
    if (longest_gap_ns > 0) {
      out << " (longest " << FormatSeconds(longest_gap_ns) << " s after "
          << FormatSeconds(longest_gap_at_ns) << " s)";
    }
    out << '\n'
        << "  LED on: "
        << (led_ns ? FormatSeconds(*led_ns) + " s" : "no LED event (origin = LED on)") << '\n';
    if (std::isfinite(min_angle)) {
      out << "  vertebra angle: " << FormatFixed(min_angle, 4) << " .. "
          << FormatFixed(max_angle, 4) << " rad (calibration " << calibration->Brief() << ")\n";
    }
  }

  if (!command.convert_path.empty()) {
    const Status written = WriteControllerLog(command.convert_path, *log);
    if (!written.ok()) return ReportError(written, err);
    err << "wrote " << command.convert_path.string() << '\n';
  }
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff calib

int RunCalib(const CalibCommand& command, std::ostream& out, std::ostream& err) {
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  const Calibration& c = *calibration;
  if (command.json) {
    out << CalibrationToJson(c).dump(2) << '\n';
    return kExitOk;
  }
  const double counts_per_shaft_rev = c.encoder_counts_per_motor_rev * c.gearbox_ratio;
  out << "calibration: " << c.Brief() << '\n';
  if (!c.description.empty()) out << "  " << c.description << '\n';
  out << "rotating vertebra: " << FormatFixed(c.encoder_counts_per_motor_rev, 0)
      << " counts/motor rev x " << FormatFixed(c.gearbox_ratio, 0) << ":1 gearbox x "
      << FormatFixed(c.spur_gear_ratio, 2) << ":1 spur gear\n"
      << "  " << FormatFixed(counts_per_shaft_rev, 0) << " counts per output-shaft revolution, "
      << FormatFixed(counts_per_shaft_rev * c.spur_gear_ratio, 0) << " per vertebra revolution\n"
      << "  one count = " << FormatFixed(c.VertebraAngleFromCounts(1) * 1e6, 1)
      << " microrad of vertebra rotation\n"
      << "bending spool grooves (m):";
  for (double radius : c.spool_groove_radii_m) out << ' ' << FormatFixed(radius, 4);
  out << "; cable lengths (m):";
  for (double length : c.cable_lengths_m) out << ' ' << FormatFixed(length, 4);
  const auto percent = c.PercentLengthChangeFromSpoolAngle(1.0);
  out << "\n  percent length change per spool radian:";
  for (double p : percent) out << ' ' << FormatFixed(p, 2);
  out << "\nmaterials (N/m):";
  for (const MaterialConstant& m : c.materials) {
    out << ' ' << m.name << ' ' << FormatFixed(m.stiffness_n_per_m, 0) << " +- "
        << FormatFixed(m.stiffness_stddev_n_per_m, 0) << ';';
  }
  out << "\ntension points (silicone / Buna-N / spring, N/m):\n";
  for (const TensionPoint& p : c.tension_points) {
    out << "  " << p.name << " (" << (p.sigma >= 0 ? "+" : "") << FormatFixed(p.sigma, 0)
        << " sigma): " << FormatFixed(p.silicone_n_per_m, 0) << " / "
        << FormatFixed(p.buna_n_n_per_m, 0) << " / " << FormatFixed(p.spring_n_per_m, 0) << '\n';
  }
  if (!c.notes.empty()) {
    out << "provenance:\n";
    for (const auto& [field, note] : c.notes) out << "  " << field << ": " << note << '\n';
  }
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// the flags of each command

Subcommand AddTableCommand(CLI::App& parent) {
  auto command = std::make_shared<TableCommand>();
  CLI::App* app = parent.add_subcommand(
      "table", "Rotation at liftoff per trial and the per-foot table (paper Table IV layout)");
  app->add_option("manifest", command->manifest_path,
                  "Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV)")
      ->required();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  app->add_option("--format,-f", command->format, "md, csv, latex or json")->capture_default_str();
  app->add_option("--tables", command->tables, "both, trials or feet")->capture_default_str();
  app->add_option("--sim", command->sim_path, "Simulation results JSON for the sim columns");
  app->add_option("--output,-o", command->output_path, "Write here instead of stdout");
  app->add_option("--plot", command->plot_path,
                  "Write the hardware-vs-simulation plot here (SVG)");
  app->add_option("--verify-dir", command->verify_dir,
                  "Write a verification image per video-analysed trial here (<id>.png)");
  app->add_option("--progress", command->progress,
                  "Video analysis progress on stderr: auto, live, lines or off")
      ->capture_default_str();
  return {app, [command](std::ostream& out, std::ostream& err) {
            return RunTable(*command, out, err);
          }};
}

Subcommand AddImport2018Command(CLI::App& parent) {
  auto command = std::make_shared<Import2018Command>();
  CLI::App* app = parent.add_subcommand(
      "import-2018", "Turn a 2018 Laika folder (logs + video times CSV) into a trial manifest");
  app->add_option("folder", command->folder, "Folder with TestN*.txt and the times CSV")
      ->required();
  app->add_option("--output,-o", command->output_path, "Manifest to write")->required();
  app->add_flag("--force", command->force, "Overwrite an existing manifest");
  return {app, [command](std::ostream& out, std::ostream& err) {
            return RunImport2018(*command, out, err);
          }};
}

Subcommand AddSyncCommand(CLI::App& parent) {
  auto command = std::make_shared<SyncCommand>();
  CLI::App* app = parent.add_subcommand(
      "sync",
      "Rotation at liftoff from one log and the two video instants, given or found in the clip");
  app->add_option("log", command->log_path, "Controller log")->required();
  CLI::Option* led_on =
      app->add_option("--led-on", command->led_on_s, "Video time of the LED switch-on, s");
  CLI::Option* liftoff =
      app->add_option("--liftoff", command->liftoff_s, "Video time of the liftoff, s");
  CLI::Option* uncertainty =
      app->add_option("--uncertainty", command->uncertainty_s,
                      "Timing uncertainty of each instant, s")
          ->capture_default_str();
  led_on->needs(liftoff);
  liftoff->needs(led_on);
  CLI::Option* video =
      app->add_option("--video", command->video_path,
                      "Find the two instants in this clip (instead of --led-on and --liftoff)")
          ->excludes(led_on)
          ->excludes(liftoff)
          ->excludes(uncertainty);
  for (CLI::Option* option : AddClipFlags(*app, command->clip)) option->needs(video);
  app->add_option("--verify", command->verify_path,
                  "With --video: write a verification image (PNG)")
      ->needs(video);
  app->add_option("--progress", command->progress,
                  "With --video: progress on stderr: auto, live, lines or off")
      ->capture_default_str();
  app->add_option("--log-format", command->log_format, "auto, liftoff or laika-2018")
      ->capture_default_str();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  app->add_flag("--json", command->json, "JSON output");
  return {app, [command](std::ostream& out, std::ostream& err) {
            return RunSync(*command, out, err);
          }};
}

Subcommand AddLogCommand(CLI::App& parent) {
  auto command = std::make_shared<LogCommand>();
  CLI::App* app = parent.add_subcommand(
      "log", "What a controller log holds; optionally convert it to liftoff's format");
  app->add_option("log", command->log_path, "Controller log")->required();
  app->add_option("--log-format", command->log_format, "auto, liftoff or laika-2018")
      ->capture_default_str();
  AddCalibrationFlag(*app, command->calibration);
  app->add_option("--max-bad-lines", command->max_bad_lines, "Malformed lines to skip (reported)")
      ->capture_default_str();
  app->add_option("--gap-threshold", command->gap_threshold_s, "Gap threshold, seconds")
      ->capture_default_str();
  app->add_option("--convert", command->convert_path, "Write the log in liftoff's format here");
  app->add_flag("--json", command->json, "JSON output");
  return {app, [command](std::ostream& out, std::ostream& err) {
            return RunLog(*command, out, err);
          }};
}

Subcommand AddCalibCommand(CLI::App& parent) {
  auto command = std::make_shared<CalibCommand>();
  CLI::App* app =
      parent.add_subcommand("calib", "Show a calibration, its provenance and its conversions");
  app->add_option("calibration", command->calibration.calibration_path,
                  "Calibration JSON (default: calib/laika-2018.json)");
  app->add_flag("--json", command->json, "Print the calibration as JSON");
  return {app, [command](std::ostream& out, std::ostream& err) {
            return RunCalib(*command, out, err);
          }};
}

}  // namespace liftoff::cli
