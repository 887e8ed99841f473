// The video pipeline's acceptance tests (issue 4, "done when"), on the synthetic CI set:
// 24 clips with every nuisance and option, and 4 invalid inputs, rendered once per test
// binary (`synth::WriteSet("ci", ...)`, about 20 s) and judged against the set's truth.
//   - the LED switch-on within half a frame of truth in every clip;
//   - the rotation at liftoff, as a user gets it (AnalyzeManifest on the set's manifest:
//     video analysis, then sync on each clip's log through calib/laika-2018.json), within
//     0.01 rad of truth in at least 95 % of the clips and within 0.02 rad in all;
//   - every invalid input rejected with its own error, by the library and by the CLI;
//   - `liftoff table <set>/manifest.json --format json --verify-dir DIR` end to end.
// The set is read from LIFTOFF_CI_SET_DIR (environment), else from the folder CTest's
// ci_set fixture renders it into (compiled in), else rendered into a scratch folder; it is
// rendered into the chosen folder when that holds no set.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/sync/trial_analysis.h"
#include "liftoff/synth/sets.h"
#include "liftoff/synth/spec.h"
#include "liftoff/video/clip_analysis.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

#ifdef LIFTOFF_CI_SET_DIR
constexpr char kRenderedSetDir[] = LIFTOFF_CI_SET_DIR;
#else
constexpr char kRenderedSetDir[] = "";
#endif

using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;

// The rendered set and its index.
struct CiSetFiles {
  std::unique_ptr<ScratchDir> scratch;  // when rendered for this run only
  std::filesystem::path dir;
  nlohmann::json index;
  /// The valid trials' truths, by trial id, in set order.
  std::vector<synth::GroundTruth> truths;
  std::string error;
};

const CiSetFiles& CiSet() {
  static CiSetFiles files;
  static std::once_flag once;
  std::call_once(once, [] {
    if (const char* kept = std::getenv("LIFTOFF_CI_SET_DIR"); kept != nullptr && *kept != '\0') {
      files.dir = kept;
    } else if (std::string(kRenderedSetDir).size() > 0) {
      files.dir = kRenderedSetDir;
    } else {
      files.scratch = std::make_unique<ScratchDir>();
      files.dir = files.scratch->path() / "ci";
    }
    if (!std::filesystem::exists(files.dir / "set.json")) {
      auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
      if (!calibration.ok()) {
        files.error = calibration.status().ToString();
        return;
      }
      auto summary = synth::WriteSet("ci", *calibration, files.dir);
      if (!summary.ok()) {
        files.error = summary.status().ToString();
        return;
      }
      std::printf("%s\n", summary->Brief().c_str());
    }
    auto index = LoadJsonFile(files.dir / "set.json");
    if (!index.ok()) {
      files.error = index.status().ToString();
      return;
    }
    files.index = *index;
    for (const nlohmann::json& entry : files.index["trials"]) {
      auto truth = synth::GroundTruthFromJson(entry["truth"], "set.json");
      if (!truth.ok()) {
        files.error = truth.status().ToString();
        return;
      }
      files.truths.push_back(std::move(truth).value());
    }
  });
  return files;
}

// The set's manifest through sync, as `liftoff table` runs it, once per test binary.
struct CiSetRun {
  sync::ManifestAnalysis analysis;
  double wall_s = 0.0;
  std::string error;
};

const CiSetRun& CiAnalysis() {
  static CiSetRun run;
  static std::once_flag once;
  std::call_once(once, [] {
    const CiSetFiles& files = CiSet();
    if (!files.error.empty()) {
      run.error = files.error;
      return;
    }
    auto manifest = LoadManifest(files.dir / "manifest.json");
    auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
    if (!manifest.ok() || !calibration.ok()) {
      run.error = (manifest.ok() ? calibration.status() : manifest.status()).ToString();
      return;
    }
    const int64_t started_ns = MonotonicNowNs();
    run.analysis = sync::AnalyzeManifest(*manifest, *calibration, sync::AnalysisOptions{});
    run.wall_s = SecondsFromNs(MonotonicNowNs() - started_ns);
  });
  return run;
}

#define LIFTOFF_REQUIRE_CI_SET(files) \
  const CiSetFiles& files = CiSet();  \
  ASSERT_TRUE(files.error.empty()) << files.error

#define LIFTOFF_REQUIRE_CI_RUN(run)   \
  const CiSetRun& run = CiAnalysis(); \
  ASSERT_TRUE(run.error.empty()) << run.error

const synth::GroundTruth* TruthOf(const CiSetFiles& files, const std::string& id) {
  for (const synth::GroundTruth& truth : files.truths) {
    if (truth.trial_id == id) return &truth;
  }
  return nullptr;
}

// half the clip's median frame interval, from the truth's frame times
double MedianIntervalNs(const synth::GroundTruth& truth) {
  std::vector<int64_t> intervals;
  for (size_t i = 1; i < truth.frame_times_ns.size(); ++i) {
    intervals.push_back(truth.frame_times_ns[i] - truth.frame_times_ns[i - 1]);
  }
  std::nth_element(intervals.begin(),
                   intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2),
                   intervals.end());
  return static_cast<double>(intervals[intervals.size() / 2]);
}

// One clip's errors against truth.
struct ClipErrors {
  std::string id;
  double led_frames = NAN;    // (found - truth) / median frame interval
  double liftoff_ms = NAN;    // found liftoff - truth 1 mm instant
  double rotation_rad = NAN;  // found |rotation| - truth
  std::string status;
};

std::vector<ClipErrors> Errors(const CiSetFiles& files, const CiSetRun& run) {
  std::vector<ClipErrors> errors;
  for (const sync::TrialOutcome& outcome : run.analysis.outcomes) {
    ClipErrors clip;
    clip.id = outcome.trial.id;
    clip.status = outcome.status.ok() ? "ok" : outcome.status.ToString();
    const synth::GroundTruth* truth = TruthOf(files, clip.id);
    if (truth != nullptr && outcome.video) {
      const double interval_ns = MedianIntervalNs(*truth);
      clip.led_frames =
          static_cast<double>(outcome.video->led_on().on_ns - *truth->led_on_video_ns) /
          interval_ns;
      if (const TimedEvent* liftoff = outcome.video->liftoff()) {
        clip.liftoff_ms = 1e-6 * static_cast<double>(liftoff->t_ns - *truth->liftoff_1mm_video_ns);
      }
    }
    if (truth != nullptr && outcome.measurement) {
      clip.rotation_rad = outcome.measurement->liftoff_rad - *truth->liftoff_1mm_rad;
    }
    errors.push_back(clip);
  }
  return errors;
}

void PrintTable(const std::vector<ClipErrors>& errors, double wall_s) {
  std::printf("\n%-36s %11s %12s %14s  %s\n", "clip", "LED (frame)", "liftoff (ms)",
              "rotation (rad)", "status");
  for (const ClipErrors& clip : errors) {
    std::printf("%-36s %+11.3f %+12.1f %+14.4f  %s\n", clip.id.c_str(), clip.led_frames,
                clip.liftoff_ms, clip.rotation_rad, clip.status.c_str());
  }
  std::printf("(%zu clips analysed and synced in %.1f s)\n\n", errors.size(), wall_s);
}

TEST(VideoOnCiSet, EveryClipIsAnalysedFromItsVideoAndSynced) {
  LIFTOFF_REQUIRE_CI_SET(files);
  LIFTOFF_REQUIRE_CI_RUN(run);
  ASSERT_EQ(run.analysis.outcomes.size(), 24u);
  ASSERT_EQ(files.truths.size(), 24u);
  for (const sync::TrialOutcome& outcome : run.analysis.outcomes) {
    SCOPED_TRACE(outcome.trial.id);
    EXPECT_TRUE(outcome.status.ok()) << outcome.status.ToString();
    ASSERT_TRUE(outcome.video.has_value());
    ASSERT_NE(TruthOf(files, outcome.trial.id), nullptr);
    EXPECT_EQ(outcome.video->timing.frames,
              static_cast<int64_t>(TruthOf(files, outcome.trial.id)->frame_times_ns.size()));
    auto events = outcome.video->Events();
    ASSERT_TRUE(events.ok()) << events.status().ToString();
    EXPECT_EQ(events->source, "video");
  }
}

TEST(VideoOnCiSet, LedSwitchOnWithinHalfAFrameOfTruthInEveryClip) {
  LIFTOFF_REQUIRE_CI_SET(files);
  LIFTOFF_REQUIRE_CI_RUN(run);
  const std::vector<ClipErrors> errors = Errors(files, run);
  PrintTable(errors, run.wall_s);
  double worst = 0.0;
  for (const ClipErrors& clip : errors) {
    ASSERT_FALSE(std::isnan(clip.led_frames)) << clip.id << ": " << clip.status;
    EXPECT_LE(std::abs(clip.led_frames), 0.5) << clip.id;
    worst = std::max(worst, std::abs(clip.led_frames));
  }
  std::printf("worst LED error: %.3f frame\n", worst);
}

TEST(VideoOnCiSet, LiftoffRotationWithin0p01RadIn95PercentAnd0p02InAll) {
  LIFTOFF_REQUIRE_CI_SET(files);
  LIFTOFF_REQUIRE_CI_RUN(run);
  const std::vector<ClipErrors> errors = Errors(files, run);
  PrintTable(errors, run.wall_s);
  std::vector<double> magnitudes;
  int within_0p01 = 0;
  for (const ClipErrors& clip : errors) {
    ASSERT_FALSE(std::isnan(clip.rotation_rad)) << clip.id << ": " << clip.status;
    const double magnitude = std::abs(clip.rotation_rad);
    EXPECT_LE(magnitude, 0.02) << clip.id;
    if (magnitude <= 0.01) ++within_0p01;
    magnitudes.push_back(magnitude);
  }
  std::sort(magnitudes.begin(), magnitudes.end());
  const auto count = static_cast<double>(magnitudes.size());
  std::printf(
      "rotation error: worst %.4f rad, 95th percentile %.4f rad, median %.4f rad; "
      "%d of %zu within 0.01 rad\n",
      magnitudes.back(), magnitudes[static_cast<size_t>(std::ceil(0.95 * count)) - 1],
      magnitudes[magnitudes.size() / 2], within_0p01, magnitudes.size());
  EXPECT_GE(within_0p01, static_cast<int>(std::ceil(0.95 * count)));
}

// The frame rate of a file with timestamps rounded to 1 ms (FFV1 in MKV at 60 fps: 17, 17,
// 16 ms) is its true rate, not 1 / the median interval (58.8 fps); the codec is known.
TEST(VideoOnCiSet, MillisecondTimestampsGiveTheTrueFrameRate) {
  LIFTOFF_REQUIRE_CI_SET(files);
  LIFTOFF_REQUIRE_CI_RUN(run);
  int checked = 0;
  for (const nlohmann::json& entry : files.index["trials"]) {
    const std::string id = entry["id"];
    if (id != "ci-01-baseline-ffv1" && id != "ci-02-h264-bframes-30fps") continue;
    const double fps = entry["spec"]["camera"]["fps"].get<double>();
    for (const sync::TrialOutcome& outcome : run.analysis.outcomes) {
      if (outcome.trial.id != id) continue;
      ASSERT_TRUE(outcome.video.has_value()) << id;
      EXPECT_NEAR(outcome.video->timing.fps, fps, 0.005 * fps) << id;
      EXPECT_EQ(outcome.video->timing.lossless_codec, id == "ci-01-baseline-ffv1")
          << id << ": " << outcome.video->timing.codec_fourcc;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2);
}

// Each instant's interval (value +- uncertainty) must hold the truth: the LED switch-on in
// every clip, and the 1 mm liftoff (whatever the codec does to slow sub-pixel motion).
TEST(VideoOnCiSet, EveryUncertaintyHoldsTheTruth) {
  LIFTOFF_REQUIRE_CI_SET(files);
  LIFTOFF_REQUIRE_CI_RUN(run);
  std::vector<double> led_ms, liftoff_ms;
  for (const sync::TrialOutcome& outcome : run.analysis.outcomes) {
    SCOPED_TRACE(outcome.trial.id);
    const synth::GroundTruth* truth = TruthOf(files, outcome.trial.id);
    ASSERT_NE(truth, nullptr);
    ASSERT_TRUE(outcome.video.has_value()) << outcome.status.ToString();
    const LedPulse& led = outcome.video->led_on();
    const auto led_error_ns = std::abs(led.on_ns - *truth->led_on_video_ns);
    EXPECT_LE(led_error_ns, led.on_uncertainty_ns)
        << "LED error " << 1e-6 * static_cast<double>(led_error_ns) << " ms";
    const TimedEvent* liftoff = outcome.video->liftoff();
    ASSERT_NE(liftoff, nullptr);
    const auto liftoff_error_ns = std::abs(liftoff->t_ns - *truth->liftoff_1mm_video_ns);
    EXPECT_LE(liftoff_error_ns, liftoff->uncertainty_ns)
        << "liftoff error " << 1e-6 * static_cast<double>(liftoff_error_ns) << " ms";
    led_ms.push_back(1e-6 * static_cast<double>(led.on_uncertainty_ns));
    liftoff_ms.push_back(1e-6 * static_cast<double>(liftoff->uncertainty_ns));
  }
  ASSERT_EQ(liftoff_ms.size(), 24u);
  std::sort(led_ms.begin(), led_ms.end());
  std::sort(liftoff_ms.begin(), liftoff_ms.end());
  std::printf(
      "half-widths: LED median %.1f ms, worst %.1f ms; liftoff median %.1f ms, worst %.1f ms\n",
      led_ms[led_ms.size() / 2], led_ms.back(), liftoff_ms[liftoff_ms.size() / 2],
      liftoff_ms.back());
}

// The analysis options an invalid input is tried with: its truth's regions and scale, or
// (for files that are no clip) the first trial's.
ClipAnalysisOptions InvalidInputOptions(const CiSetFiles& files, const nlohmann::json& entry) {
  const synth::GroundTruth* truth = &files.truths.front();
  std::optional<synth::GroundTruth> own;
  if (entry.contains("truth")) {
    auto parsed = synth::GroundTruthFromJson(entry["truth"], "set.json");
    if (parsed.ok()) own = std::move(parsed).value();
    if (own) truth = &*own;
  }
  ClipAnalysisOptions options;
  options.led.roi_px = RectFromRegion(truth->led_roi_px);
  options.foot.foot_roi_px = RectFromRegion(truth->foot_roi_px);
  options.foot.tape_colour = truth->foot;
  options.foot.px_per_mm = truth->px_per_mm;
  return options;
}

std::string RectFlag(const cv::Rect& rect) {
  return std::to_string(rect.x) + "," + std::to_string(rect.y) + "," + std::to_string(rect.width) +
         "," + std::to_string(rect.height);
}

// docs/cli.md's exit codes
int ExitCodeOf(std::string_view code_name) {
  if (code_name == "invalid argument") return 3;
  if (code_name == "not found") return 4;
  if (code_name == "parse error") return 5;
  return -1;
}

TEST(VideoOnCiSet, EveryInvalidInputIsRejectedWithItsOwnError) {
  LIFTOFF_REQUIRE_CI_SET(files);
  ScratchDir scratch;
  ASSERT_EQ(files.index["invalid"].size(), 4u);
  for (const nlohmann::json& entry : files.index["invalid"]) {
    const std::string id = entry["id"];
    const std::string expected = entry["expected_error"];
    SCOPED_TRACE(id + " (" + expected + ")");
    const std::filesystem::path file = files.dir / entry["file"].get<std::string>();
    const ClipAnalysisOptions options = InvalidInputOptions(files, entry);

    // the library
    auto analysis = AnalyzeClip(file, options);
    ASSERT_FALSE(analysis.ok());
    EXPECT_EQ(StatusCodeName(analysis.status().code()), expected) << analysis.status().ToString();
    EXPECT_THAT(analysis.status().message(), ::testing::HasSubstr(file.filename().string()));
    std::printf("%-26s -> %s\n", id.c_str(), analysis.status().ToString().c_str());

    // the command line
    const CommandRun run = liftoff::testing::RunCommand(
        LIFTOFF_BINARY,
        "video " + Quoted(file) + " --led-roi " + RectFlag(options.led.roi_px) + " --foot-roi " +
            RectFlag(options.foot.foot_roi_px) + " --px-per-mm " +
            std::to_string(options.foot.px_per_mm),
        scratch);
    EXPECT_EQ(run.code, ExitCodeOf(expected)) << run.err;
    EXPECT_THAT(run.err, ::testing::HasSubstr("liftoff: " + expected));
  }
}

TEST(VideoOnCiSet, TableCommandOnTheManifestMatchesTruth) {
  LIFTOFF_REQUIRE_CI_SET(files);
  ScratchDir scratch;
  const CommandRun run =
      liftoff::testing::RunCommand(LIFTOFF_BINARY,
                                   "table " + Quoted(files.dir / "manifest.json") +
                                       " --format json --verify-dir " + Quoted(scratch / "proof"),
                                   scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json table = nlohmann::json::parse(run.out);
  int checked = 0;
  for (const nlohmann::json& row : table["rows"]) {
    for (const nlohmann::json& trial : row["trials"]) {
      const std::string id = trial["trial_id"];
      const synth::GroundTruth* truth = TruthOf(files, id);
      ASSERT_NE(truth, nullptr) << id;
      ASSERT_TRUE(trial["liftoff_rad"].is_number()) << id;
      EXPECT_NEAR(trial["liftoff_rad"].get<double>(), *truth->liftoff_1mm_rad, 0.02) << id;
      EXPECT_LE(trial["lower_rad"].get<double>(), trial["liftoff_rad"].get<double>()) << id;
      EXPECT_GE(trial["upper_rad"].get<double>(), trial["liftoff_rad"].get<double>()) << id;
      // the interval holds the truth, not only the value
      EXPECT_LE(trial["lower_rad"].get<double>(), *truth->liftoff_1mm_rad) << id;
      EXPECT_GE(trial["upper_rad"].get<double>(), *truth->liftoff_1mm_rad) << id;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 24);
  EXPECT_THAT(run.err, ::testing::HasSubstr("video: "));
  // a verification image per trial, named after it
  for (const synth::GroundTruth& truth : files.truths) {
    EXPECT_TRUE(std::filesystem::exists(scratch / "proof" / (truth.trial_id + ".png")))
        << truth.trial_id;
  }
}

}  // namespace
}  // namespace liftoff::video
