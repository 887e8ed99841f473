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
#include "support/short_clip.h"
#include "support/test_support.h"

namespace liftoff::cli {

struct VideoCampaign {
  std::filesystem::path manifest_path;
  /// The rendered trial and its exact answer.
  synth::WrittenTrial trial;
  /// Empty, or why the campaign could not be made.
  std::string error;
};

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
  auto written = synth::WriteTrial(liftoff::testing::ShortClipSpec("clip"), *calibration, dir);
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
