// `liftoff synth`: synthetic trials (video, controller log, ground truth) from a spec,
// or a whole named set. Same shape as commands.h: AddSynthCommand binds flags to
// SynthCommand; RunSynth writes results to `out`, progress and diagnostics to `err`, and
// returns the process exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

#include "liftoff/cli/commands.h"

namespace liftoff::cli {

/// Exactly one of spec_path, set_name and print_spec:
///   liftoff synth SPEC.json -o DIR     one trial
///   liftoff synth --set ci -o DIR      a named set (synth/sets.h)
///   liftoff synth --print-spec         the default spec as JSON, for editing
struct SynthCommand {
  /// Trial spec (JSON, docs/synth.md); relative CSV paths inside resolve against its folder.
  std::filesystem::path spec_path;
  /// Named set: "ci", "paper", "ci3d", "hard3d" or "campaign" (the 3D camera, trial3d.h,
  /// campaign.h).
  std::string set_name;
  /// --set campaign: trials per foot (CampaignOptions::trials_per_foot).
  int campaign_trials_per_foot = 5;
  uint64_t seed_offset = 0;  ///< --seed: the 3D sets' seeds offset by it
  /// --rise-slowdown: ci3d and hard3d's feet rising this many times slower (1 .. 20;
  /// synth::Set3dVariation).
  double rise_slowdown = 1.0;
  /// --keyframe-interval: ci3d and hard3d's H.264 key frames at most this many frames apart
  /// (0 .. 10000; 0: a nominal second; synth::Set3dVariation).
  int keyframe_interval_frames = 0;
  /// --led-on-spread: ci3d and hard3d's LED switch-ons each moved later by a seeded draw
  /// from [0, this) s (0 .. 10; synth::Set3dVariation).
  double led_on_spread_s = 0.0;
  /// --flicker, --flicker-readout-ms: ci3d and hard3d's lamp flicker amplitude (0 .. 0.5)
  /// and readout (0 .. the frame interval, ms); negative: each clip's own
  /// (synth::Set3dVariation).
  double flicker_amplitude = -1.0;
  double flicker_readout_ms = -1.0;
  /// --exposure-ms: ci3d and hard3d's exposure (0 < e <= the frame interval, ms); negative:
  /// each clip's own.
  double exposure_ms = -1.0;
  /// --led-radius-mm: ci3d and hard3d's LED radius (1 .. 20 mm); negative: each clip's own.
  double led_radius_mm = -1.0;
  /// Folder the files go to (created when missing).
  std::filesystem::path output_dir;
  /// Print the default TrialSpec as JSON on `out` and do nothing else.
  bool print_spec = false;
  /// No progress lines on `err`.
  bool quiet = false;
  CalibrationChoice calibration;
};
int RunSynth(const SynthCommand& command, std::ostream& out, std::ostream& err);

/// The command added to the command line `parent` (flags bound to its struct).
Subcommand AddSynthCommand(Command& parent);

}  // namespace liftoff::cli
