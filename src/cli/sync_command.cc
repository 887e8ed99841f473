// `liftoff sync`: one trial's rotation at liftoff.
#include "liftoff/cli/commands.h"

#include <memory>
#include <ostream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/sync/trial_analysis.h"
#include "liftoff/video/clip_analysis.h"
#include "liftoff/video/verification.h"

namespace liftoff::cli {
namespace {

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

// Exactly one source of the video instants: the clip (with the foot's region), or both
// instants on the command line.
Status CheckInstantSources(const SyncCommand& command) {
  const bool from_video = !command.video_path.empty();
  const bool from_flags = command.led_on_s || command.liftoff_s;
  if (from_video && (from_flags || command.uncertainty_s != 0.0)) {
    return InvalidArgumentError("--video excludes --led-on, --liftoff and --uncertainty: the "
                                "clip's analysis gives the instants and their uncertainties");
  }
  if (!from_video && !from_flags) {
    return InvalidArgumentError("no video instants: give --led-on S --liftoff S, or --video CLIP "
                                "--foot-roi x,y,w,h to find them");
  }
  if (from_video && command.clip.foot.foot_roi_px.empty()) {
    return InvalidArgumentError(
        "--video needs --foot-roi x,y,w,h: the liftoff comes from the foot");
  }
  return Status::Ok();
}

// The result as `sync --json` prints it.
nlohmann::json SyncJson(const SyncCommand& command, const Calibration& calibration,
                        const sync::LookupOptions& lookup,
                        const sync::LiftoffMeasurement& measured, const EventTimes& times,
                        const std::optional<video::ClipAnalysis>& clip) {
  const sync::AngleLookup& at = measured.lookup;
  return {
      {"log", command.log_path.string()},
      {"calibration", calibration.Brief()},
      {"rule", sync::LookupRuleName(lookup.rule)},
      {"interval_s", SecondsFromNs(measured.interval_ns)},
      {"interval_uncertainty_s", SecondsFromNs(measured.interval_uncertainty_ns)},
      {"liftoff_log_s", SecondsFromNs(measured.liftoff_log_ns)},
      {"vertebra_rad", at.vertebra_rad},
      {"liftoff_rad", measured.liftoff_rad},
      {"lower_rad", measured.lower_rad},
      {"upper_rad", measured.upper_rad},
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
}

// The result as `sync` prints it.
void PrintSync(const Calibration& calibration, const sync::LookupOptions& lookup,
               const sync::LiftoffMeasurement& measured,
               const std::optional<video::ClipAnalysis>& clip, std::ostream& out) {
  if (clip) out << "video: " << clip->Brief() << '\n';
  out << "calibration: " << calibration.Brief() << "; rule: " << sync::LookupRuleName(lookup.rule)
      << '\n'
      << "interval LED on -> liftoff: " << FormatSeconds(measured.interval_ns, 3) << " s +- "
      << FormatSeconds(measured.interval_uncertainty_ns, 3) << " s\n"
      << "log instant: " << FormatSeconds(measured.liftoff_log_ns, 3) << " s\n"
      << "vertebra angle: " << FormatFixed(measured.lookup.vertebra_rad, 4)
      << " rad; at liftoff |angle| " << FormatFixed(measured.liftoff_rad, 4) << " rad in ["
      << FormatFixed(measured.lower_rad, 4) << ", " << FormatFixed(measured.upper_rad, 4) << "]\n";
  for (const std::string& warning : measured.lookup.warnings) out << "note: " << warning << '\n';
}

}  // namespace

// ---------------------------------------------------------------------------------------
// liftoff sync

int RunSync(const SyncCommand& command, std::ostream& out, std::ostream& err) {
  // flags: exactly one source of the video instants
  auto lookup = LookupOptionsFrom(command.lookup);
  if (!lookup.ok()) return ReportError(lookup.status(), err);
  const bool from_video = !command.video_path.empty();
  if (const Status sources = CheckInstantSources(command); !sources.ok()) {
    return ReportError(sources, err);
  }
  EventTimes times;
  std::optional<video::ClipAnalysisOptions> clip_options;
  std::optional<VideoProgress> progress;
  if (from_video) {
    auto options = CheckedClipOptions(command.clip);
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

  if (command.json) {
    out << SyncJson(command, *calibration, *lookup, *measured, times, clip).dump(2) << '\n';
    return kExitOk;
  }
  PrintSync(*calibration, *lookup, *measured, clip, out);
  return kExitOk;
}

Subcommand AddSyncCommand(Command& parent) {
  auto command = std::make_shared<SyncCommand>();
  Command* app = parent.AddSubcommand(
      "sync",
      "Rotation at liftoff from one log and the two video instants, given or found in the clip");
  app->AddOption("log", command->log_path, "Controller log")->Required();
  Flag* led_on =
      app->AddOption("--led-on", command->led_on_s, "Video time of the LED switch-on, s");
  Flag* liftoff =
      app->AddOption("--liftoff", command->liftoff_s, "Video time of the liftoff, s");
  Flag* uncertainty =
      app->AddOption("--uncertainty", command->uncertainty_s,
                      "Timing uncertainty of each instant, s")
          ->ShowDefault();
  led_on->Needs(liftoff);
  liftoff->Needs(led_on);
  Flag* video =
      app->AddOption("--video", command->video_path,
                      "Find the two instants in this clip (instead of --led-on and --liftoff)")
          ->Excludes(led_on)
          ->Excludes(liftoff)
          ->Excludes(uncertainty);
  for (Flag* option : AddClipFlags(*app, command->clip)) option->Needs(video);
  app->AddOption("--verify", command->verify_path,
                  "With --video: write a verification image (PNG)")
      ->Needs(video);
  app->AddOption("--progress", command->progress,
                  "With --video: progress on stderr: auto, live, lines or off")
      ->ShowDefault();
  app->AddOption("--log-format", command->log_format, "auto, liftoff or laika-2018")
      ->ShowDefault();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  app->AddSwitch("--json", command->json, "JSON output");
  return RunsWith(app, command, RunSync);
}

}  // namespace liftoff::cli
