// The LED detector on the dev set of an independent 3D renderer (shared/video-dev beside
// the source tree: 13 clips with exact truth, see its README.md), through the same
// one-clip pipeline `liftoff video` runs (AnalyzeClip, LED only, the truth's led_roi):
//   - every clip whose LED switches on: the switch-on within half a frame interval of the
//     truth's t_led_on, and the truth inside the reported uncertainty;
//   - the clip whose LED never switches on: rejected, kNotFound "the LED never switches on".
// Skipped, saying why, where the set is absent.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/video/clip_analysis.h"

namespace liftoff::video {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

struct DevClip {
  std::string name;
  fs::path video;
  cv::Rect led_roi_px;
  bool led_switches_on = false;
  double led_on_s = 0.0;
  double frame_interval_s = 0.0;  // median of the truth's intervals
};

std::vector<DevClip> LoadDevSet(const fs::path& root) {
  std::vector<DevClip> clips;
  for (const auto& entry : fs::directory_iterator(root)) {
    const fs::path truth_path = entry.path() / "truth.json";
    if (!entry.is_directory() || !fs::exists(truth_path)) continue;
    std::ifstream in(truth_path);
    const nlohmann::json truth = nlohmann::json::parse(in);
    DevClip clip;
    clip.name = entry.path().filename().string();
    clip.video = entry.path() / truth.at("video").get<std::string>();
    const auto roi = truth.at("led_roi").get<std::vector<int>>();
    clip.led_roi_px = cv::Rect(roi.at(0), roi.at(1), roi.at(2), roi.at(3));
    clip.led_switches_on = !truth.at("t_led_on").is_null();
    if (clip.led_switches_on) clip.led_on_s = truth.at("t_led_on").get<double>();
    const auto pts = truth.at("pts").get<std::vector<double>>();
    std::vector<double> intervals;
    for (size_t i = 1; i < pts.size(); ++i) intervals.push_back(pts[i] - pts[i - 1]);
    const auto middle = intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2);
    std::nth_element(intervals.begin(), middle, intervals.end());
    clip.frame_interval_s = *middle;
    clips.push_back(clip);
  }
  std::sort(clips.begin(), clips.end(),
            [](const DevClip& a, const DevClip& b) { return a.name < b.name; });
  return clips;
}

TEST(LedDevSet, SwitchOnWithinHalfAFrameAndInsideItsUncertaintyOrRejected) {
  const fs::path root = LIFTOFF_VIDEO_DEV_DIR;
  if (!fs::exists(root)) GTEST_SKIP() << "no dev set at " << root << " (shared/video-dev)";
  const std::vector<DevClip> clips = LoadDevSet(root);
  ASSERT_FALSE(clips.empty()) << "no clip with a truth.json in " << root;
  std::printf("%-32s %12s %14s %8s\n", "clip", "error (fr)", "+- (fr)", "lit");
  for (const DevClip& clip : clips) {
    SCOPED_TRACE(clip.name);
    ClipAnalysisOptions options;
    options.led.roi_px = clip.led_roi_px;
    const Result<ClipAnalysis> analysis = AnalyzeClip(clip.video, options);
    if (!clip.led_switches_on) {
      ASSERT_FALSE(analysis.ok()) << analysis->led.Brief();
      EXPECT_EQ(analysis.status().code(), StatusCode::kNotFound);
      EXPECT_THAT(analysis.status().message(), HasSubstr("the LED never switches on"));
      std::printf("%-32s %12s\n", clip.name.c_str(), "rejected");
      continue;
    }
    ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
    const LedPulse& pulse = analysis->led_on();
    const double error_s = static_cast<double>(pulse.on_ns) * 1e-9 - clip.led_on_s;
    const double uncertainty_s = static_cast<double>(pulse.on_uncertainty_ns) * 1e-9;
    std::printf("%-32s %+12.3f %14.3f %7.0f%%\n", clip.name.c_str(),
                error_s / clip.frame_interval_s, uncertainty_s / clip.frame_interval_s,
                100.0 * pulse.first_lit_fraction);
    EXPECT_LE(std::abs(error_s), 0.5 * clip.frame_interval_s) << analysis->led.Brief();
    // 1 us: the truth's seconds are rounded in its JSON
    EXPECT_LE(std::abs(error_s), uncertainty_s + 1e-6) << analysis->led.Brief();
  }
}

}  // namespace
}  // namespace liftoff::video
