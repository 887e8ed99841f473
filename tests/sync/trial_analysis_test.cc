#include "liftoff/sync/trial_analysis.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/capture/laika2018.h"
#include "support/test_support.h"

namespace liftoff::sync {
namespace {

using liftoff::testing::ScratchDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::StartsWith;

EventTimes HandTimes(int64_t led_on_ms, int64_t liftoff_ms) {
  EventTimes times;
  times.led_on_ns = NsFromMilliseconds(led_on_ms);
  times.liftoff_ns = NsFromMilliseconds(liftoff_ms);
  return times;
}

TrialRecord Trial(std::string id, Foot foot, std::filesystem::path log_path) {
  TrialRecord trial;
  trial.id = std::move(id);
  trial.foot = foot;
  trial.log_path = std::move(log_path);
  trial.log_format = LogFormat::kLaika2018;
  return trial;
}

// a 2018-style log: 0 .. 1 s every 0.1 s, shaft 2 rad/s * t (vertebra 0.5 rad/s * t)
std::string RampLog() {
  std::string text;
  for (int ms = 0; ms <= 1000; ms += 100) {
    char line[32];
    std::snprintf(line, sizeof line, "%d,%.2f,\r", ms, 2.0 * ms / 1000.0);
    text += line;
  }
  return text;
}

AnalysisOptions Hold() {
  AnalysisOptions options;
  options.lookup.rule = LookupRule::kSampleAndHold;
  return options;
}

TEST(AnalyzeManifest, AMissingLogFailsOnlyItsTrialAndNamesTheFile) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog());
  TrialManifest manifest;
  manifest.trials.push_back(Trial("B1", Foot::kB, scratch / "good.txt"));
  manifest.trials.back().times = HandTimes(5000, 5350);  // log 0.35 s: sample at 0.3 s
  manifest.trials.push_back(Trial("B2", Foot::kB, scratch / "missing.txt"));
  manifest.trials.back().times = HandTimes(5000, 5350);

  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), Hold());
  ASSERT_EQ(analysis.outcomes.size(), 2u);
  EXPECT_EQ(analysis.failed(), 1);
  EXPECT_EQ(analysis.rule, LookupRule::kSampleAndHold);
  EXPECT_EQ(analysis.calibration, "test (built in code)");

  const TrialOutcome& good = analysis.outcomes[0];
  ASSERT_TRUE(good.status.ok()) << good.status.ToString();
  ASSERT_TRUE(good.measurement.has_value());
  EXPECT_NEAR(good.measurement->liftoff_rad, 0.15, 1e-12);  // 0.60 rad shaft / 4
  EXPECT_EQ(good.log_report.samples, 11);

  const TrialOutcome& bad = analysis.outcomes[1];
  EXPECT_EQ(bad.status.code(), StatusCode::kNotFound);
  EXPECT_THAT(bad.status.message(), StartsWith("B2: "));
  EXPECT_THAT(bad.status.message(), HasSubstr("missing.txt"));
  EXPECT_FALSE(bad.measurement.has_value());

  const std::vector<stats::TrialValue> values = analysis.Values();
  ASSERT_EQ(values.size(), 1u);
  EXPECT_EQ(values[0].trial_id, "B1");
  EXPECT_EQ(values[0].foot, Foot::kB);
  EXPECT_NEAR(values[0].liftoff_rad, 0.15, 1e-12);
  EXPECT_NEAR(values[0].lower_rad, 0.15, 1e-12);
  EXPECT_NEAR(values[0].upper_rad, 0.15, 1e-12);
  EXPECT_EQ(values[0].flags, "");
}

TEST(AnalyzeManifest, ValuesFlagGapsAndQueriesPastTheEnd) {
  ScratchDir scratch;
  // bursts at 5.000-5.071 s and 6.004-6.030 s; shaft angles are 4x the vertebra's
  WriteFile(scratch / "bursts.txt",
            "5000,-1.48,\r5030,-1.52,\r5071,-1.54,\r6004,-1.63,\r6030,-1.64,\r");
  TrialManifest manifest;
  manifest.trials.push_back(Trial("D2", Foot::kD, scratch / "bursts.txt"));
  manifest.trials.back().times = HandTimes(1000, 7000);  // log 6.000 s: inside the gap
  manifest.trials.push_back(Trial("D3", Foot::kD, scratch / "bursts.txt"));
  manifest.trials.back().times = HandTimes(1000, 7530);  // log 6.530 s: 0.5 s past the end

  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), Hold());
  EXPECT_EQ(analysis.failed(), 0);
  const std::vector<stats::TrialValue> values = analysis.Values();
  ASSERT_EQ(values.size(), 2u);
  EXPECT_NEAR(values[0].liftoff_rad, 0.385, 1e-12);
  EXPECT_NEAR(values[0].lower_rad, 0.385, 1e-12);
  EXPECT_NEAR(values[0].upper_rad, 0.4075, 1e-12);
  EXPECT_EQ(values[0].flags, "gap 0.93 s");
  EXPECT_NEAR(values[1].liftoff_rad, 0.41, 1e-12);
  EXPECT_EQ(values[1].flags, "past end 0.500 s");
}

TEST(AnalyzeManifest, TrialsWithoutTimesFailWithTheirReason) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog());
  TrialManifest manifest;
  manifest.source_path = scratch / "trials.json";
  manifest.trials.push_back(Trial("A1", Foot::kA, scratch / "good.txt"));
  manifest.trials.back().video_path = scratch / "A1.mp4";
  manifest.trials.push_back(Trial("A2", Foot::kA, scratch / "good.txt"));
  manifest.trials.push_back(Trial("A3", Foot::kA, scratch / "good.txt"));
  manifest.trials.back().times = HandTimes(0, 700);

  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), Hold());
  ASSERT_EQ(analysis.outcomes.size(), 3u);
  EXPECT_EQ(analysis.failed(), 2);
  // a video without a foot region cannot be analysed
  const Status& video_only = analysis.outcomes[0].status;
  EXPECT_EQ(video_only.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(video_only.message(), StartsWith("A1: "));
  EXPECT_THAT(video_only.message(), HasSubstr("A1.mp4"));
  EXPECT_THAT(video_only.message(), HasSubstr("no foot region (roi.foot_px)"));
  EXPECT_FALSE(analysis.outcomes[0].video.has_value());
  const Status& nothing = analysis.outcomes[1].status;
  EXPECT_EQ(nothing.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(nothing.message(), StartsWith("A2: "));
  EXPECT_THAT(nothing.message(), HasSubstr("trials.json"));
  EXPECT_TRUE(analysis.outcomes[2].status.ok());
  EXPECT_NEAR(analysis.outcomes[2].measurement->liftoff_rad, 0.35, 1e-12);
}

// (Video analysis that succeeds, end to end through sync on rendered clips, is tested in
// tests/video/ci_set_test.cc: this test binary has no renderer.)
TEST(AnalyzeManifest, TrialsWithAVideoAndNoTimesGoThroughVideoAnalysis) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog());
  WriteFile(scratch / "notes.mp4", "not a video\n");
  TrialManifest manifest;
  const auto video_trial = [&](std::string id, std::filesystem::path video) {
    manifest.trials.push_back(Trial(std::move(id), Foot::kB, scratch / "good.txt"));
    manifest.trials.back().video_path = std::move(video);
    manifest.trials.back().foot_roi_px = RegionPx{10, 10, 30, 40};
  };
  video_trial("B1", scratch / "absent.mp4");
  video_trial("B2", scratch / "notes.mp4");
  // hand times win over the video: its file is never opened
  video_trial("B3", scratch / "absent.mp4");
  manifest.trials.back().times = HandTimes(0, 700);

  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), Hold());
  ASSERT_EQ(analysis.outcomes.size(), 3u);
  EXPECT_EQ(analysis.outcomes[0].status.code(), StatusCode::kNotFound);
  EXPECT_THAT(analysis.outcomes[0].status.message(), StartsWith("B1: "));
  EXPECT_THAT(analysis.outcomes[0].status.message(), HasSubstr("absent.mp4"));
  EXPECT_EQ(analysis.outcomes[1].status.code(), StatusCode::kParse);
  EXPECT_THAT(analysis.outcomes[1].status.message(), StartsWith("B2: "));
  EXPECT_THAT(analysis.outcomes[1].status.message(), HasSubstr("not a video"));
  ASSERT_TRUE(analysis.outcomes[2].status.ok()) << analysis.outcomes[2].status.ToString();
  EXPECT_FALSE(analysis.outcomes[2].video.has_value());
  EXPECT_NEAR(analysis.outcomes[2].measurement->liftoff_rad, 0.35, 1e-12);
}

TEST(AnalyzeManifest, InvalidVideoOptionsFailEveryTrial) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog());
  TrialManifest manifest;
  manifest.trials.push_back(Trial("A1", Foot::kA, scratch / "good.txt"));
  manifest.trials.back().times = HandTimes(0, 500);
  AnalysisOptions options;
  options.video.rest_min_frames = 0;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), options);
  EXPECT_EQ(analysis.failed(), 1);
  EXPECT_THAT(analysis.outcomes[0].status.message(), StartsWith("A1: video: rest_min_frames"));
}

TEST(AnalyzeManifest, LookupErrorsNameTheTrialAndTheLog) {
  ScratchDir scratch;
  WriteFile(scratch / "short.txt", RampLog());
  TrialManifest manifest;
  manifest.trials.push_back(Trial("C4", Foot::kC, scratch / "short.txt"));
  manifest.trials.back().times = HandTimes(0, 5000);  // 4 s past the 1 s log

  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), Hold());
  EXPECT_EQ(analysis.failed(), 1);
  const Status& status = analysis.outcomes[0].status;
  EXPECT_EQ(status.code(), StatusCode::kOutOfRange);
  EXPECT_THAT(status.message(), StartsWith("C4: "));
  EXPECT_THAT(status.message(), HasSubstr("short.txt"));
  EXPECT_THAT(status.message(),
              HasSubstr("instant 5.000 s is after the log's last sample at 1.000 s"));
}

TEST(AnalyzeManifest, InvalidOptionsFailEveryTrial) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog());
  TrialManifest manifest;
  manifest.trials.push_back(Trial("A1", Foot::kA, scratch / "good.txt"));
  manifest.trials.back().times = HandTimes(0, 500);
  AnalysisOptions options;
  options.lookup.gap_threshold_s = -1.0;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  const ManifestAnalysis analysis =
      AnalyzeManifest(manifest, liftoff::testing::DriveChainCalibration(), options);
  EXPECT_EQ(analysis.failed(), 1);
  EXPECT_THAT(analysis.outcomes[0].status.message(), StartsWith("A1: "));
  EXPECT_THAT(analysis.outcomes[0].status.message(), HasSubstr("gap_threshold_s"));
}

// laika-model.md section 7: the authors' sample-and-hold angles, tests 1..5 per foot
const std::map<std::string, double>& AuthorsAngles() {
  static const std::map<std::string, double> angles = {
      {"A1", 0.460}, {"A2", 0.385}, {"A3", 0.432}, {"A4", 0.502}, {"A5", 0.455},
      {"B1", 0.560}, {"B2", 0.552}, {"B3", 0.600}, {"B4", 0.557}, {"B5", 0.590},
      {"C1", 0.525}, {"C2", 0.512}, {"C3", 0.510}, {"C4", 0.540}, {"C5", 0.495},
      {"D1", 0.422}, {"D2", 0.357}, {"D3", 0.435}, {"D4", 0.407}, {"D5", 0.438}};
  return angles;
}

// The linear rule's |vertebra angle| at liftoff, derived outside liftoff from the raw 2018
// lines: log instant = liftoff - LED-on time, linear between the two bracketing
// `t_ms,shaft_rad,` samples (held past the end: A4, B1, C1), vertebra = |shaft| / 4. A1:
// 6.130 s between 6.073 s (-1.84) and 7.006 s (-1.92): (1.84 + 0.08 * 57/933) / 4 = 0.4612.
const std::map<std::string, double>& LinearAngles() {
  static const std::map<std::string, double> angles = {
      {"A1", 0.4612}, {"A2", 0.4074}, {"A3", 0.4342}, {"A4", 0.5025}, {"A5", 0.4563},
      {"B1", 0.5600}, {"B2", 0.5545}, {"B3", 0.6013}, {"B4", 0.5577}, {"B5", 0.6081},
      {"C1", 0.5250}, {"C2", 0.5125}, {"C3", 0.5125}, {"C4", 0.5405}, {"C5", 0.4974},
      {"D1", 0.4345}, {"D2", 0.3607}, {"D3", 0.4350}, {"D4", 0.4086}, {"D5", 0.4376}};
  return angles;
}

TEST(AnalyzeManifest, Laika2018SampleAndHoldReproducesTheAuthorsAngles) {
  LIFTOFF_REQUIRE_REFERENCE(reference);
  ScratchDir scratch;
  auto imported =
      capture::ImportLaika2018Folder(reference / "laika-2018-hardware", scratch / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  auto calibration = LoadCalibration(liftoff::testing::SourceDir() / "calib" / "laika-2018.json");
  ASSERT_TRUE(calibration.ok()) << calibration.status().ToString();

  const ManifestAnalysis hold = AnalyzeManifest(imported->manifest, *calibration, Hold());
  AnalysisOptions linear_options;
  linear_options.lookup.rule = LookupRule::kLinear;
  const ManifestAnalysis linear = AnalyzeManifest(imported->manifest, *calibration, linear_options);
  EXPECT_EQ(hold.failed(), 0);
  EXPECT_EQ(linear.failed(), 0);
  ASSERT_EQ(hold.outcomes.size(), 20u);
  ASSERT_EQ(linear.outcomes.size(), 20u);

  for (size_t i = 0; i < hold.outcomes.size(); ++i) {
    const TrialOutcome& outcome = hold.outcomes[i];
    SCOPED_TRACE(outcome.trial.id);
    ASSERT_TRUE(outcome.status.ok()) << outcome.status.ToString();
    ASSERT_EQ(AuthorsAngles().count(outcome.trial.id), 1u);
    const LiftoffMeasurement& measurement = *outcome.measurement;
    EXPECT_NEAR(measurement.liftoff_rad, AuthorsAngles().at(outcome.trial.id), 0.001);
    EXPECT_LE(measurement.lower_rad, measurement.liftoff_rad);
    EXPECT_GE(measurement.upper_rad, measurement.liftoff_rad);
    // B1's liftoff (9.170 s) is past its log's last sample (9.079 s): held and flagged
    EXPECT_EQ(measurement.lookup.past_end,
              outcome.trial.id == "B1" || outcome.trial.id == "A4" || outcome.trial.id == "C1");
    if (outcome.trial.id == "B1") {
      EXPECT_EQ(measurement.liftoff_log_ns, NsFromMilliseconds(9170));
      EXPECT_EQ(measurement.lookup.sample_before_ns, NsFromMilliseconds(9079));
    }
    // the linear rule's values, to the 4 decimals they were derived to
    const TrialOutcome& linear_outcome = linear.outcomes[i];
    ASSERT_TRUE(linear_outcome.status.ok()) << linear_outcome.status.ToString();
    ASSERT_EQ(linear_outcome.trial.id, outcome.trial.id);
    const LiftoffMeasurement& linear_measurement = *linear_outcome.measurement;
    EXPECT_NEAR(linear_measurement.liftoff_rad, LinearAngles().at(outcome.trial.id), 0.00005);
    EXPECT_LE(linear_measurement.lower_rad, linear_measurement.liftoff_rad);
    EXPECT_GE(linear_measurement.upper_rad, linear_measurement.liftoff_rad);
  }
}

}  // namespace
}  // namespace liftoff::sync
