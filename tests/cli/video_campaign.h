// A small campaign with video for the report's tests: one synthetic trial rendered by synth
// (2.4 s, 640 x 480 at 60 fps, H.264; about a second), entered twice under ids that make
// the same file name ("clip/1" and "clip_1"), beside the sample trials with hand times.
#pragma once

#include <filesystem>
#include <string>

#include "liftoff/core/calibration.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "support/test_support.h"

namespace liftoff::cli {

struct VideoCampaign {
  std::filesystem::path manifest_path;
  /// The rendered trial and its exact answer.
  synth::WrittenTrial trial;
  /// Empty, or why the campaign could not be made.
  std::string error;
};

// the LED on at 0.61 s, a 0.4 rad/s ramp from 0.2 s, foot A lifting at 0.47 rad
inline synth::TrialSpec ShortClipSpec() {
  synth::TrialSpec spec;
  spec.id = "clip";
  spec.seed = 77;
  spec.duration_s = 2.4;
  spec.camera.width_px = 640;
  spec.camera.height_px = 480;
  spec.camera.fps = 60.0;
  spec.camera.exposure_s = 1.0 / 120.0;
  spec.camera.codec = synth::VideoCodec::kH264;
  spec.led.on_video_s = 0.61;
  spec.motion.foot = Foot::kA;
  spec.motion.height.liftoff_rad = 0.47;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.15;
  spec.motion.ramp_start_s = 0.2;
  spec.motion.ramp_rate_rad_per_s = 0.4;
  return spec;
}

/// Writes the clip and DIR/manifest.json: "clip/1", "clip_1" (the clip), then the sample
/// trials (`hand_trials` of them, logs and times as in samples/trials).
inline VideoCampaign WriteVideoCampaign(const std::filesystem::path& dir, size_t hand_trials) {
  VideoCampaign campaign;
  const std::filesystem::path samples = liftoff::testing::SourceDir() / "samples" / "trials";
  auto calibration = LoadCalibration(liftoff::testing::SourceDir() / "calib" / "laika-2018.json");
  auto sample_manifest = LoadManifest(samples / "manifest.json");
  if (!calibration.ok() || !sample_manifest.ok()) {
    campaign.error = "cannot load the samples' calibration or manifest";
    return campaign;
  }
  auto written = synth::WriteTrial(ShortClipSpec(), *calibration, dir);
  if (!written.ok()) {
    campaign.error = written.status().ToString();
    return campaign;
  }
  campaign.trial = std::move(written).value();
  TrialManifest manifest;
  manifest.base_dir = dir;
  manifest.description = "the report's test campaign: a synthetic clip twice, sample trials";
  for (const std::string id : {"clip/1", "clip_1"}) {
    TrialRecord trial = campaign.trial.manifest_entry;
    trial.id = id;
    manifest.trials.push_back(trial);
  }
  for (size_t i = 0; i < hand_trials && i < sample_manifest->trials.size(); ++i) {
    manifest.trials.push_back(sample_manifest->trials[i]);
  }
  campaign.manifest_path = dir / "manifest.json";
  const Status saved = WriteManifest(campaign.manifest_path, manifest);
  if (!saved.ok()) campaign.error = saved.ToString();
  return campaign;
}

}  // namespace liftoff::cli
