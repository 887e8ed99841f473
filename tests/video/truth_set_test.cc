// Video analysis on clips made by renderers other than the detector's own, with exact
// truth: ../shared/video-dev/ (an independent 3D renderer; skipped with a message where the
// folder is absent, as in a user's fresh clone), and liftoff's own 3D CI set. Every clip goes through AnalyzeClip as
// `liftoff video` runs it, with the truth's regions, scale and foot letter; a per-clip
// table is printed and the targets asserted:
//   - LED switch-on within half a frame interval of the truth, every ok clip;
//   - liftoff rotation (1 mm rule, through the ramp rate) within 0.01 rad in every ok clip
//     and within 0.005 rad in at least 90 % of them;
//   - the truth inside the reported interval (LED and liftoff uncertainties added);
//   - the reject clips rejected with their own errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/video/clip_analysis.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

namespace fs = std::filesystem;

struct ClipScore {
  std::string id;
  bool expect_ok = true;
  Status status;
  double led_error_frames = 0;
  double liftoff_error_ms = 0;
  double rotation_error_rad = 0;
  double interval_uncertainty_ms = 0;
  bool truth_inside = false;
  size_t warnings = 0;
  bool low_confidence = false;
};

cv::Rect RectOf(const nlohmann::json& values) {
  return {values.at(0).get<int>(), values.at(1).get<int>(), values.at(2).get<int>(),
          values.at(3).get<int>()};
}

ClipScore ScoreClip(const fs::path& folder) {
  std::ifstream in(folder / "truth.json");
  const nlohmann::json truth = nlohmann::json::parse(in);
  ClipScore score;
  score.id = folder.filename().string();
  score.expect_ok = truth.at("expect").get<std::string>() == "ok";
  ClipAnalysisOptions options;
  options.led.roi_px = RectOf(truth.at("led_roi"));
  options.foot.foot_roi_px = RectOf(truth.at("foot_roi"));
  options.foot.px_per_mm = truth.at("pixels_per_mm").get<double>();
  options.foot.tape_colour = ParseFoot(truth.at("foot").get<std::string>());
  Result<ClipAnalysis> analysis =
      AnalyzeClip(folder / truth.at("video").get<std::string>(), options);
  if (!analysis.ok()) {
    score.status = analysis.status();
    return score;
  }
  Result<EventTimes> events = analysis->Events();
  if (!events.ok()) {
    score.status = events.status();
    return score;
  }
  if (!score.expect_ok) {  // a reject clip has no truth to score against
    score.status = Status(StatusCode::kOutOfRange, "a reject clip was not rejected: " +
                                                       analysis->foot->Brief());
    return score;
  }
  const std::vector<double> pts = truth.at("pts").get<std::vector<double>>();
  const double frame_s = (pts.back() - pts.front()) / static_cast<double>(pts.size() - 1);
  const double t_led_s = truth.at("t_led_on").get<double>();
  const double t_lift_s = truth.at("t_lift_1mm").get<double>();
  const double rate = truth.at("theta_rate_rad_s").get<double>();
  const double led_s = static_cast<double>(events->led_on_ns) * 1e-9;
  const double lift_s = static_cast<double>(events->liftoff_ns) * 1e-9;
  score.led_error_frames = (led_s - t_led_s) / frame_s;
  const double error_s = (lift_s - led_s) - (t_lift_s - t_led_s);
  score.liftoff_error_ms = error_s * 1e3;
  score.rotation_error_rad = error_s * rate;
  score.interval_uncertainty_ms =
      static_cast<double>(events->led_on_uncertainty_ns + events->liftoff_uncertainty_ns) * 1e-6;
  score.truth_inside = std::abs(score.liftoff_error_ms) <= score.interval_uncertainty_ms;
  score.warnings = analysis->warnings.size();
  for (const std::string& warning : analysis->warnings) {
    // one module prefix: "foot: low confidence: ...", never "foot: foot: ..."
    EXPECT_EQ(warning.find("foot: foot:"), std::string::npos) << warning;
  }
  score.low_confidence = analysis->foot && analysis->foot->low_confidence;
  // a foot seen by fewer than 3 patches may be measured short: its interval reaches down to
  // the rise's start (the fit's earliest knee, at or before the onset)
  if (analysis->foot && analysis->foot->foot_patches_px.size() < 3) {
    const TimedEvent& lift = analysis->foot->above_threshold;
    EXPECT_LE(lift.t_ns - lift.uncertainty_ns, analysis->foot->onset.t_ns) << score.id;
  }
  return score;
}

std::vector<ClipScore> ScoreFolder(const fs::path& root) {
  std::vector<fs::path> folders;
  for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
    if (entry.is_directory() && fs::exists(entry.path() / "truth.json")) {
      folders.push_back(entry.path());
    }
  }
  std::sort(folders.begin(), folders.end());
  std::vector<ClipScore> scores;
  std::printf("%-32s %9s %10s %10s %9s %6s %s\n", "clip", "LED fr", "lift ms", "rot rad",
              "+- ms", "inside", "warnings");
  for (const fs::path& folder : folders) {
    scores.push_back(ScoreClip(folder));
    const ClipScore& s = scores.back();
    if (!s.status.ok()) {
      std::printf("%-32s %s\n", s.id.c_str(), s.status.ToString().c_str());
      continue;
    }
    std::printf("%-32s %+9.3f %+10.0f %+10.4f %9.0f %6s %zu%s\n", s.id.c_str(),
                s.led_error_frames, s.liftoff_error_ms, s.rotation_error_rad,
                s.interval_uncertainty_ms, s.truth_inside ? "yes" : "NO", s.warnings,
                s.low_confidence ? " (low confidence)" : "");
  }
  return scores;
}

// The rotation targets: every ok clip within `every_clip_rad`, at least `share_within_5mrad`
// of them within 0.005 rad (the issue's: 0.01 rad, 90 %).
struct RotationTargets {
  double every_clip_rad = 0.01;
  double share_within_5mrad = 0.9;
};

// The targets of the issue, asserted per clip and over the set: the rejects not found; on
// every ok clip the LED within half a frame and the truth inside the interval; the
// rotation targets. Returns the number of ok clips.
size_t ExpectTargets(const std::vector<ClipScore>& scores, RotationTargets targets = {}) {
  size_t ok_clips = 0, within_5mrad = 0, within_10mrad = 0;
  for (const ClipScore& s : scores) {
    if (!s.expect_ok) {
      EXPECT_EQ(s.status.code(), StatusCode::kNotFound) << s.id << ": " << s.status.ToString();
      continue;
    }
    EXPECT_TRUE(s.status.ok()) << s.id << ": " << s.status.ToString();
    if (!s.status.ok()) continue;
    ++ok_clips;
    EXPECT_LE(std::abs(s.led_error_frames), 0.5) << s.id;
    EXPECT_TRUE(s.truth_inside) << s.id << ": error " << s.liftoff_error_ms << " ms, +- "
                                << s.interval_uncertainty_ms << " ms";
    EXPECT_LE(std::abs(s.rotation_error_rad), targets.every_clip_rad) << s.id;
    if (std::abs(s.rotation_error_rad) <= 0.005) ++within_5mrad;
    if (std::abs(s.rotation_error_rad) <= 0.01) ++within_10mrad;
  }
  std::printf("%zu of %zu ok clips within 0.005 rad, %zu within 0.01 rad\n", within_5mrad,
              ok_clips, within_10mrad);
  if (ok_clips > 0) {
    EXPECT_GE(static_cast<double>(within_5mrad),
              targets.share_within_5mrad * static_cast<double>(ok_clips))
        << within_5mrad << " of " << ok_clips << " clips within 0.005 rad";
  }
  return ok_clips;
}

const ClipScore* Find(const std::vector<ClipScore>& scores, const std::string& prefix) {
  for (const ClipScore& s : scores) {
    if (s.id.rfind(prefix, 0) == 0) return &s;
  }
  return nullptr;
}

#ifdef LIFTOFF_CI3D_SET_DIR
// liftoff's own 3D CI set (MuJoCo's renderer; rendered by the ci3d_set fixture). Its clips
// ramp at the paper's rate, as the dev set's do, and end 1.5 s after the 1 mm instant: the
// same targets as the dev set's.
TEST(Video3dCiSet, EveryClipMeetsTheTargets) {
  const fs::path root = LIFTOFF_CI3D_SET_DIR;
  if (!fs::exists(root / "set.json")) GTEST_SKIP() << root << " was not rendered (no headless GL)";
  const std::vector<ClipScore> scores = ScoreFolder(root);
  const size_t ok_clips = ExpectTargets(scores);
  EXPECT_EQ(ok_clips, 8u);
  const ClipScore* led_never_on = Find(scores, "ci3d-09");
  const ClipScore* never_lifts = Find(scores, "ci3d-10");
  ASSERT_NE(led_never_on, nullptr);
  ASSERT_NE(never_lifts, nullptr);
  EXPECT_NE(led_never_on->status.message().find("the LED never switches on"), std::string::npos);
  EXPECT_NE(never_lifts->status.message().find("the foot never lifts"), std::string::npos);
}
#else

TEST(VideoDevSet, EveryClipMeetsTheTargets) {
  const fs::path root = fs::path(LIFTOFF_SHARED_DIR) / "video-dev";
  if (!fs::exists(root)) GTEST_SKIP() << root << " is absent (a fresh clone has no ../shared)";
  const std::vector<ClipScore> scores = ScoreFolder(root);
  EXPECT_EQ(ExpectTargets(scores), 11u);
  // the two reject clips, each with its own error
  const ClipScore* led_never_on = Find(scores, "d11");
  const ClipScore* never_lifts = Find(scores, "d12");
  ASSERT_NE(led_never_on, nullptr);
  ASSERT_NE(never_lifts, nullptr);
  EXPECT_NE(led_never_on->status.message().find("the LED never switches on"), std::string::npos)
      << led_never_on->status.ToString();
  EXPECT_NE(never_lifts->status.message().find("the foot never lifts"), std::string::npos)
      << never_lifts->status.ToString();
}

// A small robot in frame, from footage we did not make: every constant-rate dev clip
// shrunk to half its width and height (area averaging, H.264 through OpenCV's writer)
// with its truth scaled to match: a side view's foot is then 7 px across and 1 mm is 0.21
// to 0.28 px. Targets asserted: the rejects rejected, every ok clip measured with the LED
// within half a frame and the truth inside its interval, every rotation within 0.015 rad
// and 8 of the 10 within 0.005 rad (measured: 8 within 0.005, 9 within 0.01, the largest
// d01's 0.0128).
// Writes the clip in `from` (its truth given) at half size into `to`; false where OpenCV
// cannot write H.264.
bool WriteHalfSizeClip(const fs::path& from, nlohmann::json truth, const fs::path& to) {
  cv::VideoCapture capture((from / truth.at("video").get<std::string>()).string(), cv::CAP_FFMPEG);
  cv::Mat frame, half;
  if (!capture.read(frame)) return false;
  fs::create_directories(to);
  cv::VideoWriter writer((to / "video.mp4").string(), cv::CAP_FFMPEG,
                         cv::VideoWriter::fourcc('a', 'v', 'c', '1'),
                         truth.at("nominal_fps").get<double>(),
                         cv::Size(frame.cols / 2, frame.rows / 2));
  if (!writer.isOpened()) return false;
  do {
    cv::resize(frame, half, cv::Size(frame.cols / 2, frame.rows / 2), 0, 0, cv::INTER_AREA);
    writer.write(half);
  } while (capture.read(frame));
  const auto halve = [](const nlohmann::json& rect) {
    const int x = rect.at(0).get<int>() / 2, y = rect.at(1).get<int>() / 2;
    const int right = (rect.at(0).get<int>() + rect.at(2).get<int>() + 1) / 2;
    const int bottom = (rect.at(1).get<int>() + rect.at(3).get<int>() + 1) / 2;
    return nlohmann::json::array({x, y, right - x, bottom - y});
  };
  truth["video"] = "video.mp4";
  truth["led_roi"] = halve(truth.at("led_roi"));
  truth["foot_roi"] = halve(truth.at("foot_roi"));
  truth["pixels_per_mm"] = 0.5 * truth.at("pixels_per_mm").get<double>();
  std::ofstream((to / "truth.json").string()) << truth.dump();
  std::printf("%s at half size: %.2f px a mm, foot region %dx%d px\n",
              from.filename().string().c_str(), truth.at("pixels_per_mm").get<double>(),
              truth.at("foot_roi").at(2).get<int>(), truth.at("foot_roi").at(3).get<int>());
  return true;
}

TEST(VideoDevSetAtHalfSize, EveryClipMeetsTheSmallRobotTargets) {
  const fs::path root = fs::path(LIFTOFF_SHARED_DIR) / "video-dev";
  if (!fs::exists(root)) GTEST_SKIP() << root << " is absent (a fresh clone has no ../shared)";
  const testing::ScratchDir scratch;
  const fs::path half = scratch.path();
  for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
    if (!fs::exists(entry.path() / "truth.json")) continue;
    std::ifstream in(entry.path() / "truth.json");
    const nlohmann::json truth = nlohmann::json::parse(in);
    // the writer keeps a constant rate: the variable-rate clip stays out
    if (truth.at("timing").get<std::string>() != "cfr") continue;
    if (!WriteHalfSizeClip(entry.path(), truth, half / entry.path().filename())) {
      GTEST_SKIP() << entry.path() << ": OpenCV's H.264 writer is not available here";
    }
  }
  // every ok clip measured (10), within 0.015 rad, 8 of 10 within 0.005 rad
  EXPECT_EQ(ExpectTargets(ScoreFolder(half), {.every_clip_rad = 0.015, .share_within_5mrad = 0.8}),
            10u);
}

// Any folder of clips in the same format, such as `liftoff synth --set hard3d -o DIR`:
//   LIFTOFF_TRUTH_SET_DIR=DIR build/tests/video_truth_set_test --gtest_filter='AnyTruthSet.*'
TEST(AnyTruthSet, EveryClipMeetsTheTargets) {
  const char* dir = std::getenv("LIFTOFF_TRUTH_SET_DIR");
  if (dir == nullptr || *dir == '\0') GTEST_SKIP() << "LIFTOFF_TRUTH_SET_DIR is not set";
  ExpectTargets(ScoreFolder(dir));
}
#endif

}  // namespace
}  // namespace liftoff::video
