#include "liftoff/cli/synth_commands.h"

#include <memory>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/synth/sets.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#if LIFTOFF_HAVE_SYNTH3D
#include "liftoff/synth/campaign.h"
#include "liftoff/synth/trial3d.h"
#endif

namespace liftoff::cli {
namespace {

std::string PerFrameMs(double seconds, size_t frames) {
  return FormatFixed(1e3 * seconds / static_cast<double>(frames == 0 ? 1 : frames), 2) +
         " ms/frame";
}

// One line per trial: frames and the time spent on them.
void PrintTrial(const synth::WrittenTrial& written, std::ostream& out) {
  const synth::GroundTruth& truth = written.truth;
  const size_t frames = truth.frame_times_ns.size();
  out << truth.trial_id << ": " << frames << " frames, render "
      << PerFrameMs(written.render_seconds, frames) << ", encode "
      << PerFrameMs(written.encode_seconds, frames) << '\n';
}

int RunOneTrial(const SynthCommand& command, const Calibration& calibration, std::ostream& out,
                std::ostream& err) {
  auto document = LoadJsonFile(command.spec_path);
  if (!document.ok()) return ReportError(document.status(), err);
  auto spec = synth::TrialSpecFromJson(*document, command.spec_path.string(),
                                       command.spec_path.parent_path());
  if (!spec.ok()) return ReportError(spec.status(), err);
  if (!command.quiet)
    err << "rendering " << spec->id << " into " << command.output_dir.string() << '\n';
  auto written = synth::WriteTrial(*spec, calibration, command.output_dir);
  if (!written.ok()) return ReportError(written.status(), err);

  // what was written and the answer it holds
  PrintTrial(*written, out);
  const synth::GroundTruth& truth = written->truth;
  out << "video: " << written->video_path.string() << '\n'
      << "log: " << written->log_path.string() << '\n'
      << "truth: " << written->truth_path.string() << '\n';
  if (truth.led_on_video_ns && truth.led_first_frame) {
    out << "LED on: " << FormatSeconds(*truth.led_on_video_ns) << " s (frame "
        << *truth.led_first_frame << ", " << FormatFixed(truth.led_first_frame_fraction, 3)
        << " of its exposure)\n";
  } else {
    out << "LED on: never within the clip\n";
  }
  if (truth.liftoff_1mm_video_ns && truth.liftoff_1mm_rad) {
    out << "liftoff (1 mm): " << FormatSeconds(*truth.liftoff_1mm_video_ns) << " s, |vertebra| "
        << FormatFixed(*truth.liftoff_1mm_rad, 4) << " rad\n";
  } else {
    out << "liftoff: the foot does not lift within the clip\n";
  }
  out << "calibration: " << calibration.Brief() << '\n';
  return kExitOk;
}

int RunSet(const SynthCommand& command, const Calibration& calibration, std::ostream& out,
           std::ostream& err) {
  const auto progress = [&](const synth::SetProgress& at) {
    if (!command.quiet) err << "[" << at.index + 1 << "/" << at.count << "] " << at.id << '\n';
  };
  auto summary = synth::WriteSet(command.set_name, calibration, command.output_dir, progress);
  if (!summary.ok()) return ReportError(summary.status(), err);
  for (const synth::WrittenTrial& written : summary->trials) PrintTrial(written, out);
  out << summary->Brief() << '\n'
      << "manifest: " << summary->manifest_path.string() << '\n'
      << "index: " << summary->index_path.string() << '\n'
      << "calibration: " << calibration.Brief() << '\n';
  return kExitOk;
}

#if LIFTOFF_HAVE_SYNTH3D
synth::CampaignOptions CampaignOptionsFrom(const SynthCommand& command) {
  synth::CampaignOptions options;
  options.trials_per_foot = command.campaign_trials_per_foot;
  options.seed += command.seed_offset;
  return options;
}

// The 3D set or campaign of the command, written.
Result<synth::Set3dSummary> WriteNamedSet3d(const SynthCommand& command,
                                            const Calibration& calibration, std::ostream& err) {
  const auto progress = [&](int index, int count, const std::string& id) {
    if (!command.quiet) err << "[" << index + 1 << "/" << count << "] " << id << '\n';
  };
  if (command.set_name != "campaign") {
    synth::Set3dVariation variation;
    variation.seed_offset = command.seed_offset;
    variation.rise_slowdown = command.rise_slowdown;
    variation.keyframe_interval_frames = command.keyframe_interval_frames;
    variation.led_on_spread_s = command.led_on_spread_s;
    variation.flicker_amplitude = command.flicker_amplitude;
    variation.flicker_readout_s =
        command.flicker_readout_ms < 0 ? -1.0 : 1e-3 * command.flicker_readout_ms;
    variation.exposure_s = command.exposure_ms < 0 ? -1.0 : 1e-3 * command.exposure_ms;
    variation.led_radius_m = command.led_radius_mm < 0 ? -1.0 : 1e-3 * command.led_radius_mm;
    const std::string invalid = variation.Validate().message();
    struct FlagField {
      const char* flag;
      const char* field;
      bool scaled;  // the flag's unit differs from the field's (ms against s, mm against m)
    };
    for (const FlagField& f : {FlagField{"--rise-slowdown", "rise_slowdown", false},
                               FlagField{"--keyframe-interval", "keyframe_interval_frames", false},
                               FlagField{"--led-on-spread", "led_on_spread_s", false},
                               FlagField{"--flicker", "flicker_amplitude", false},
                               FlagField{"--flicker-readout-ms", "flicker_readout_s", true},
                               FlagField{"--exposure-ms", "exposure_s", true},
                               FlagField{"--led-radius-mm", "led_radius_m", true}}) {
      if (auto named = MessageNamingFlag(invalid, f.flag, f.field, f.scaled)) {
        return InvalidArgumentError(*named);
      }
    }
    return synth::WriteSet3d(command.set_name, command.output_dir, calibration, progress,
                             variation);
  }
  return synth::WriteCampaign(CampaignOptionsFrom(command), calibration, command.output_dir,
                             progress);
}
#endif

// The 3D camera's sets (trial3d.h, campaign.h): their own folder format.
int RunSet3d(const SynthCommand& command, const Calibration& calibration, std::ostream& out,
             std::ostream& err) {
#if LIFTOFF_HAVE_SYNTH3D
  auto summary = WriteNamedSet3d(command, calibration, err);
  if (!summary.ok()) return ReportError(summary.status(), err);
  for (const synth::WrittenTrial3d& written : summary->trials) {
    const auto seconds = [](const std::optional<double>& value, int places) {
      return value ? FormatFixed(*value, places) : std::string("-");
    };
    out << written.folder.filename().string() << ": " << written.frames << " frames, render "
        << PerFrameMs(written.render_seconds, static_cast<size_t>(written.frames)) << ", encode "
        << PerFrameMs(written.encode_seconds, static_cast<size_t>(written.frames)) << "; "
        << written.expect << ", LED on " << seconds(written.t_led_on_s, 3) << " s, 1 mm at "
        << seconds(written.t_lift_1mm_s, 4) << " s, " << seconds(written.theta_at_lift_1mm_rad, 4)
        << " rad\n";
  }
  out << summary->Brief() << '\n' << "renderer: " << summary->renderer << '\n'
      << "manifest: " << (command.output_dir / "manifest.json").string() << '\n'
      << "index: " << (command.output_dir / "set.json").string() << '\n';
  if (command.set_name == "campaign") {
    out << "truth: " << (command.output_dir / "campaign-truth.json").string()
        << " (the hidden tension; liftoff report never reads it)\n"
        << "report: liftoff report " << (command.output_dir / "manifest.json").string() << ' '
        << synth::CampaignReportFlags(CampaignOptionsFrom(command)) << " -o DIR\n";
  }
  out << "calibration: " << calibration.Brief() << '\n';
  return kExitOk;
#else
  (void)out;
  (void)calibration;
  return ReportError(UnsupportedError("liftoff synth --set " + command.set_name +
                                      ": this build has no 3D camera (needs libmujoco-dev and "
                                      "libegl-dev at build time)"),
                     err);
#endif
}

}  // namespace

int RunSynth(const SynthCommand& command, std::ostream& out, std::ostream& err) {
  // exactly one job
  const int jobs = (command.spec_path.empty() ? 0 : 1) + (command.set_name.empty() ? 0 : 1) +
                   (command.print_spec ? 1 : 0);
  if (jobs != 1) {
    err << "liftoff synth: give exactly one of SPEC.json, --set NAME or --print-spec\n";
    return kExitUsage;
  }
  if (command.print_spec) {
    out << synth::TrialSpecToJson(synth::TrialSpec{}).dump(2) << '\n';
    return kExitOk;
  }
  if (command.output_dir.empty()) {
    err << "liftoff synth: --output DIR is required with a spec or --set\n";
    return kExitUsage;
  }
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  const bool set3d = command.set_name == "ci3d" || command.set_name == "hard3d";
  for (const auto& [flag, given] :
       {std::pair{"--rise-slowdown", command.rise_slowdown != 1.0},
        std::pair{"--keyframe-interval", command.keyframe_interval_frames != 0},
        std::pair{"--led-on-spread", command.led_on_spread_s != 0.0},
        // (negative: not given; NaN is given, and out of range)
        std::pair{"--flicker", !(command.flicker_amplitude < 0)},
        std::pair{"--flicker-readout-ms", !(command.flicker_readout_ms < 0)},
        std::pair{"--exposure-ms", !(command.exposure_ms < 0)},
        std::pair{"--led-radius-mm", !(command.led_radius_mm < 0)}}) {
    if (given && !set3d) {
      err << "liftoff synth: " << flag << " works with --set ci3d or hard3d\n";
      return kExitUsage;
    }
  }
  if (set3d || command.set_name == "campaign") {
    return RunSet3d(command, *calibration, out, err);
  }
  if (command.seed_offset != 0) {
    err << "liftoff synth: --seed works with --set ci3d, hard3d or campaign (a spec has its "
           "own seed)\n";
    return kExitUsage;
  }
  return command.set_name.empty() ? RunOneTrial(command, *calibration, out, err)
                                  : RunSet(command, *calibration, out, err);
}

Subcommand AddSynthCommand(Command& parent) {
  auto command = std::make_shared<SynthCommand>();
  Command* app = parent.AddSubcommand(
      "synth",
      "Render synthetic trials (video, controller log, ground truth) from a spec or a set");
  app->AddOption("spec", command->spec_path, "Trial spec JSON (see --print-spec)");
  app->AddOption("--set", command->set_name,
                  "Write a whole named set: ci, paper, ci3d, hard3d or campaign (the 3D camera)");
  app->AddOption("--per-foot", command->campaign_trials_per_foot,
                  "--set campaign: trials per foot (1 .. 20)")
      ->ShowDefault();
  app->AddOption("--seed", command->seed_offset,
                  "--set ci3d, hard3d or campaign: every clip's seeds offset by this (0: the "
                  "set as documented; another: its conditions drawn anew)")
      ->ShowDefault();
  app->AddOption("--rise-slowdown", command->rise_slowdown,
                 "--set ci3d or hard3d: every foot rises this many times slower than simulated "
                 "once off the ground (1 .. 20)")
      ->ShowDefault();
  app->AddOption("--keyframe-interval", command->keyframe_interval_frames,
                 "--set ci3d or hard3d: H.264's key frames at most this many frames apart (0 .. "
                 "10000; 0: a nominal second; a camera's H.264 often has 250)")
      ->ShowDefault();
  app->AddOption("--led-on-spread", command->led_on_spread_s,
                 "--set ci3d or hard3d: every LED switch-on moved later by a draw from [0, S) "
                 "s seeded by the clip (0 .. 10; 0: as documented, most on a frame's time and "
                 "a key frame)")
      ->ShowDefault();
  app->AddOption("--flicker", command->flicker_amplitude,
                 "--set ci3d or hard3d: every clip's lamp flicker amplitude (0 .. 0.5; it "
                 "scales the whole picture, the LED too; negative: each clip's own)")
      ->ShowDefault();
  app->AddOption("--flicker-readout-ms", command->flicker_readout_ms,
                 "--set ci3d or hard3d: every clip's readout, ms (0: a global shutter; up to "
                 "the frame interval: a rolling shutter's bands; negative: each clip's own)")
      ->ShowDefault();
  app->AddOption("--exposure-ms", command->exposure_ms,
                 "--set ci3d or hard3d: every clip's exposure, ms (0 < e <= the frame "
                 "interval; short ones see a lamp's flicker whole; negative: each clip's own)")
      ->ShowDefault();
  app->AddOption("--led-radius-mm", command->led_radius_mm,
                 "--set ci3d or hard3d: every clip's LED radius, mm (1 .. 20; hard3d-06's 1.5 "
                 "mm is 0.59 px; negative: each clip's own)")
      ->ShowDefault();
  app->AddOption("--output,-o", command->output_dir, "Folder for the files");
  app->AddSwitch("--print-spec", command->print_spec, "Print the default spec as JSON");
  app->AddSwitch("--quiet,-q", command->quiet, "No progress lines on stderr");
  AddCalibrationFlag(*app, command->calibration);
  return RunsWith(app, command, RunSynth);
}

}  // namespace liftoff::cli
