// Trials on disk: frame schedule, truth, the matching controller log, determinism, the
// CI set's coverage, and `liftoff synth` end to end.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/time.h"
#include "liftoff/sync/lookup.h"
#include "liftoff/synth/sets.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "support/test_support.h"

namespace liftoff::synth {
namespace {

using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;
// 12 counts per rotor revolution x 1000 x 4: one count of the vertebra, rad.
constexpr double kVertebraRadPerCount = 2.0 * kPi / 48000.0;

// The 2018 drive chain plus a spool: grooves 4-4-8-12 mm, cables 88 mm.
Calibration TestCalibration() {
  Calibration calibration = liftoff::testing::DriveChainCalibration();
  calibration.spool_groove_radii_m = {0.004, 0.004, 0.008, 0.012};
  calibration.cable_lengths_m = {0.088, 0.088, 0.088, 0.088};
  return calibration;
}

// 320 x 240 at 30 fps, lossless, 1.6 s: LED at 0.3 s, a 0.5 rad/s ramp from 0.1 s after
// it, liftoff at 0.4 rad (1.2 s), 1 mm at 0.4 + 0.004^(2/3) rad (1.25 s).
TrialSpec SmallSpec() {
  TrialSpec spec;
  spec.id = "small";
  spec.seed = 42;
  spec.duration_s = 1.6;
  spec.camera.width_px = 320;
  spec.camera.height_px = 240;
  spec.camera.fps = 30.0;
  spec.camera.exposure_s = 1.0 / 60.0;
  spec.camera.codec = VideoCodec::kFfv1;
  spec.led.on_video_s = 0.3;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.05;
  spec.motion.ramp_start_s = 0.1;
  spec.motion.ramp_rate_rad_per_s = 0.5;
  spec.motion.height.liftoff_rad = 0.4;
  spec.motion.height.gain_m = 0.25;
  spec.motion.height.exponent = 1.5;
  spec.log.lead_s = 0.2;
  spec.log.tail_s = 0.3;
  return spec;
}

// ---------------------------------------------------------------------------------------
// frame schedule and LED truth

TEST(FrameSchedule, ConstantRateSlotsAreAtIndexOverFps) {
  TrialSpec spec = SmallSpec();
  spec.camera.fps = 60.0;
  spec.duration_s = 1.0;
  const std::vector<int64_t> times = FrameScheduleNs(spec);
  ASSERT_EQ(times.size(), 60u);
  EXPECT_EQ(times[0], 0);
  EXPECT_EQ(times[1], 16'666'667);
  EXPECT_EQ(times[3], 50'000'000);
  EXPECT_EQ(times[59], 983'333'333);
}

TEST(FrameSchedule, DropsSkipSlotsAndJitterStaysWithinBound) {
  TrialSpec spec = SmallSpec();
  spec.camera.fps = 100.0;
  spec.duration_s = 20.0;
  spec.camera.drop_probability = 0.25;
  spec.camera.timestamp_jitter_s = 0.003;
  const std::vector<int64_t> times = FrameScheduleNs(spec);
  EXPECT_EQ(times[0], 0);
  // about 3/4 of 2000 slots survive (binomial: sd ~19)
  EXPECT_NEAR(static_cast<double>(times.size()), 1500.0, 100.0);
  int jittered = 0;
  for (size_t i = 1; i < times.size(); ++i) {
    EXPECT_GT(times[i], times[i - 1]);
    const int64_t slot_ns = (times[i] + 5'000'000) / 10'000'000 * 10'000'000;
    EXPECT_LE(std::abs(times[i] - slot_ns), 3'000'000) << "frame " << i;
    if (times[i] != slot_ns) ++jittered;
  }
  EXPECT_GT(jittered, 1000);
}

TEST(FrameSchedule, SameSeedSameScheduleOtherSeedOther) {
  TrialSpec spec = SmallSpec();
  spec.camera.drop_probability = 0.2;
  spec.camera.timestamp_jitter_s = 0.005;
  const auto first = FrameScheduleNs(spec);
  EXPECT_EQ(FrameScheduleNs(spec), first);
  spec.seed = 43;
  EXPECT_NE(FrameScheduleNs(spec), first);
}

TEST(LedTruth, SwitchOnInsideAnExposureGivesThePartialFraction) {
  TrialSpec spec = SmallSpec();
  spec.camera.fps = 100.0;
  spec.camera.exposure_s = 0.005;
  // frame 1 (timestamp 10 ms, the middle of its exposure) exposes [7.5, 12.5) ms: on for
  // 3 of its 5 ms
  spec.led.on_video_s = 0.0095;
  GroundTruth truth;
  FillLedTruth(spec, {0, 10'000'000, 20'000'000, 30'000'000}, truth);
  ASSERT_TRUE(truth.led_on_video_ns && truth.led_first_frame);
  EXPECT_EQ(*truth.led_on_video_ns, 9'500'000);
  EXPECT_EQ(*truth.led_first_frame, 1);
  EXPECT_NEAR(truth.led_first_frame_fraction, 0.6, 1e-12);
}

TEST(LedTruth, SwitchOnBetweenExposuresGivesAWholeFrame) {
  TrialSpec spec = SmallSpec();
  spec.camera.fps = 100.0;
  spec.camera.exposure_s = 0.005;
  spec.led.on_video_s = 0.016;  // after frame 1's exposure ended at 12.5 ms, before 2's at 17.5
  GroundTruth truth;
  FillLedTruth(spec, {0, 10'000'000, 20'000'000, 30'000'000}, truth);
  ASSERT_TRUE(truth.led_first_frame);
  EXPECT_EQ(*truth.led_first_frame, 2);
  EXPECT_EQ(truth.led_first_frame_fraction, 1.0);
}

TEST(LedTruth, LedOutsideTheClipIsNeverOn) {
  TrialSpec spec = SmallSpec();
  for (const double on_s : {-0.5, 1.6, 5.0}) {
    spec.led.on_video_s = on_s;
    GroundTruth truth;
    FillLedTruth(spec, FrameScheduleNs(spec), truth);
    EXPECT_FALSE(truth.led_on_video_ns) << on_s;
    EXPECT_FALSE(truth.led_first_frame) << on_s;
  }
}

// ---------------------------------------------------------------------------------------
// the controller log

TEST(TrialPieces, PulledGroupFollowsTableTwoByFootLetter) {
  EXPECT_EQ(PaperTableTwoMotion(Foot::kA).pulled_group, CableGroup::kHR);
  EXPECT_EQ(PaperTableTwoMotion(Foot::kB).pulled_group, CableGroup::kHR);
  EXPECT_EQ(PaperTableTwoMotion(Foot::kC).pulled_group, CableGroup::kHL);
  EXPECT_EQ(PaperTableTwoMotion(Foot::kD).pulled_group, CableGroup::kHL);
}

TEST(TrialPieces, BendTargetPutsTheLargestGroovesCableAtEightyPercent) {
  // 0.2 * 0.088 m / 0.012 m
  EXPECT_NEAR(BendSpoolTargetRad(TestCalibration(), CableGroup::kHR), 1.4666667, 1e-6);
  EXPECT_NEAR(BendSpoolTargetRad(TestCalibration(), CableGroup::kHL), -1.4666667, 1e-6);
}

Result<ControllerLog> WriteAndReadLog(const TrialSpec& spec, const ScratchDir& scratch) {
  auto timeline = Timeline::Create(spec);
  if (!timeline.ok()) return timeline.status();
  const auto path = scratch / (spec.id + ".csv");
  LIFTOFF_RETURN_IF_ERROR(WriteTrialLog(*timeline, TestCalibration(), path));
  return ReadControllerLog(path);
}

TEST(TrialLog, SamplesAtTheRateFromLeadBeforeLedToTailAfterClip) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.log.led_on_device_ns = 5'000'000'000;
  auto log = WriteAndReadLog(spec, scratch);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  // LED at device 5 s = video 0.3 s; span: video 0.1 s .. 1.9 s = device 4.8 .. 6.6 s
  EXPECT_EQ(log->LedOnTimeNs(), 5'000'000'000);
  EXPECT_EQ(log->FirstSampleNs(), 4'800'000'000);
  EXPECT_EQ(log->LastSampleNs(), 6'600'000'000);
  EXPECT_EQ(log->samples.size(), 181u);  // every 10 ms
  for (const LogSample& sample : log->samples) {
    EXPECT_EQ(*sample.led_on, sample.device_time_ns >= 5'000'000'000) << sample.device_time_ns;
  }
  // the end of the bend: HR's spool target in counts, 1.4667 rad * 12000 / (2 pi)
  EXPECT_EQ(log->samples.back().bend_counts, 2801);
  // the ramp: 0.5 rad/s from device 5.1 s; at 6.6 s the vertebra is at 0.75 rad
  EXPECT_NEAR(log->samples.back().vertebra_rad, 0.75, kVertebraRadPerCount);
  EXPECT_EQ(log->samples.back().rotate_counts, std::lround(0.75 * 4 * 12000 / (2 * kPi)));
  EXPECT_EQ(log->header.metadata.at("pulled_group"), "HR");
}

TEST(TrialLog, OriginStyleLogStartsAtTheLedWithoutAnEvent) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.log.led_event = false;
  spec.log.burst_period_s = 1.0;
  spec.log.burst_length_s = 0.17;
  spec.motion.foot = Foot::kD;
  spec.motion.rotation = RotationSense::kNegative;
  auto log = WriteAndReadLog(spec, scratch);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_TRUE(log->events.empty());
  EXPECT_FALSE(log->LedOnTimeNs());
  EXPECT_EQ(log->FirstSampleNs(), 0);
  // bursts of 17 samples at 0 s and 1 s (the log runs to 1.6 s of device time)
  ASSERT_EQ(log->samples.size(), 34u);
  for (const LogSample& sample : log->samples) {
    EXPECT_LT(sample.device_time_ns % 1'000'000'000, 170'000'000);
    EXPECT_TRUE(*sample.led_on);
    EXPECT_LE(sample.vertebra_rad, 0.0);  // negative sense
  }
  EXPECT_EQ(log->samples.back().bend_counts, -2801);  // HL pulls the other way
}

TEST(TrialLog, LedEventWithoutZeroOriginIsRejectedWhenEventIsOff) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.log.led_event = false;
  spec.log.led_on_device_ns = 7;
  auto log = WriteAndReadLog(spec, scratch);
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(log.status().message(), HasSubstr("log.led_on_device_ns"));
}

TEST(TrialLog, JitteredSamplesStayWithinBoundOfTheGrid) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.log.rate_hz = 200.0;
  spec.log.jitter_s = 0.002;
  auto log = WriteAndReadLog(spec, scratch);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  int moved = 0;
  for (const LogSample& sample : log->samples) {
    const int64_t grid_ns =
        std::llround(static_cast<double>(sample.device_time_ns) / 5e6) * 5'000'000;
    EXPECT_LE(std::abs(sample.device_time_ns - grid_ns), 2'000'000);
    if (sample.device_time_ns != grid_ns) ++moved;
  }
  EXPECT_GT(moved, static_cast<int>(log->samples.size()) / 2);
}

// ---------------------------------------------------------------------------------------
// a whole trial

TEST(WriteTrial, DecodedVideoHasTruthFrameTimes) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.camera.drop_probability = 0.2;
  spec.camera.timestamp_jitter_s = 0.01;
  auto written = WriteTrial(spec, TestCalibration(), scratch.path());
  ASSERT_TRUE(written.ok()) << written.status().ToString();
  const GroundTruth& truth = written->truth;
  EXPECT_EQ(written->video_path, scratch / "small.mkv");
  EXPECT_EQ(truth.frame_times_ns.front(), 0);
  EXPECT_LT(truth.frame_times_ns.size(), 48u);  // some of the 48 slots dropped
  for (const int64_t t_ns : truth.frame_times_ns) EXPECT_EQ(t_ns % 1'000'000, 0) << "Matroska: ms";

  cv::VideoCapture capture(written->video_path.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  cv::Mat frame;
  size_t index = 0;
  while (capture.read(frame)) {
    ASSERT_LT(index, truth.frame_times_ns.size());
    EXPECT_NEAR(capture.get(cv::CAP_PROP_POS_MSEC),
                static_cast<double>(truth.frame_times_ns[index]) * 1e-6, 1e-6)
        << "frame " << index;
    EXPECT_EQ(frame.cols, 320);
    EXPECT_EQ(frame.rows, 240);
    ++index;
  }
  EXPECT_EQ(index, truth.frame_times_ns.size());
}

TEST(WriteTrial, TruthHoldsTheHandComputedLiftoff) {
  ScratchDir scratch;
  auto written = WriteTrial(SmallSpec(), TestCalibration(), scratch.path());
  ASSERT_TRUE(written.ok()) << written.status().ToString();
  const GroundTruth& truth = written->truth;
  // parametric: height = 0.25 (theta - 0.4)^1.5 -> 1 mm at 0.4 + 0.004^(2/3) rad
  const double one_mm_rad = 0.4 + std::pow(0.004, 2.0 / 3.0);
  ASSERT_TRUE(truth.liftoff_0mm_rad && truth.liftoff_1mm_rad);
  EXPECT_NEAR(*truth.liftoff_0mm_rad, 0.4, 1e-6);
  EXPECT_NEAR(*truth.liftoff_1mm_rad, one_mm_rad, 1e-6);
  // instants: LED 0.3 s + ramp start 0.1 s + rotation / 0.5 rad/s
  EXPECT_NEAR(static_cast<double>(*truth.liftoff_0mm_video_ns), 1.2e9, 2.0);
  EXPECT_NEAR(static_cast<double>(*truth.liftoff_1mm_video_ns), (0.4 + one_mm_rad / 0.5) * 1e9,
              2.0);
  // LED at 0.3 s = frame 9's timestamp at 30 fps, the middle of its 1/60 s exposure
  // [291666667, 308333334) ns: lit for 8333334 of its 16666667 ns
  EXPECT_EQ(truth.led_on_video_ns, 300'000'000);
  EXPECT_EQ(truth.led_first_frame, 9);
  EXPECT_NEAR(truth.led_first_frame_fraction, 8333334.0 / 16666667.0, 1e-12);
  EXPECT_GT(truth.px_per_mm, 0.0);
  EXPECT_GT(truth.led_roi_px.width_px, 0);
  EXPECT_GT(truth.foot_roi_px.height_px, 0);

  // the truth file reads back as the same truth
  auto document = LoadJsonFile(written->truth_path);
  ASSERT_TRUE(document.ok());
  auto read = GroundTruthFromJson(*document, written->truth_path.string());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->frame_times_ns, truth.frame_times_ns);
  EXPECT_EQ(read->liftoff_1mm_video_ns, truth.liftoff_1mm_video_ns);
}

// The log read back, synced with the truth's instants, gives the truth's rotation.
void ExpectLogGivesTruthRotation(const TrialSpec& spec, double tolerance_rad) {
  ScratchDir scratch;
  auto written = WriteTrial(spec, TestCalibration(), scratch.path());
  ASSERT_TRUE(written.ok()) << written.status().ToString();
  const GroundTruth& truth = written->truth;
  auto log = ReadControllerLog(written->log_path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_TRUE(truth.led_on_video_ns && truth.liftoff_1mm_video_ns && truth.liftoff_1mm_rad);
  EventTimes times;
  times.led_on_ns = *truth.led_on_video_ns;
  times.liftoff_ns = *truth.liftoff_1mm_video_ns;
  times.source = "synthetic";
  auto measured = sync::MeasureLiftoff(*log, times, sync::LookupOptions{});
  ASSERT_TRUE(measured.ok()) << measured.status().ToString();
  EXPECT_NEAR(measured->liftoff_rad, *truth.liftoff_1mm_rad, tolerance_rad) << spec.id;
}

TEST(WriteTrial, LogSyncedAtTruthInstantsGivesTruthRotation) {
  // linear ramp, linear lookup: only the encoder's half count remains
  const double tolerance_rad = 0.5 * kVertebraRadPerCount + 1e-9;
  TrialSpec spec = SmallSpec();
  spec.log.led_on_device_ns = 3'000'000'000;
  spec.log.jitter_s = 0.004;
  ExpectLogGivesTruthRotation(spec, tolerance_rad);

  TrialSpec origin = SmallSpec();
  origin.id = "origin";
  origin.motion.foot = Foot::kB;
  origin.motion.rotation = RotationSense::kNegative;
  origin.log.led_event = false;
  origin.log.burst_period_s = 0.5;
  origin.log.burst_length_s = 0.1;
  ExpectLogGivesTruthRotation(origin, tolerance_rad);

  // drift: sync assumes equal clock rates, so it is off by rate * interval * drift
  TrialSpec drift = SmallSpec();
  drift.id = "drift";
  drift.log.clock_drift_ppm = 500.0;
  ExpectLogGivesTruthRotation(drift, tolerance_rad + 0.5 * 1.0 * 500e-6);
}

TEST(WriteTrial, ManifestEntryNamesFootGroupRotationAndFilesButNoTimes) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.motion.foot = Foot::kC;
  auto written = WriteTrial(spec, TestCalibration(), scratch.path());
  ASSERT_TRUE(written.ok()) << written.status().ToString();
  const TrialRecord& entry = written->manifest_entry;
  EXPECT_EQ(entry.id, "small");
  EXPECT_EQ(entry.foot, Foot::kC);
  EXPECT_EQ(entry.pulled_group, CableGroup::kHL);
  EXPECT_EQ(entry.rotation, RotationSense::kPositive);
  EXPECT_EQ(entry.log_path, scratch / "small.csv");
  EXPECT_EQ(entry.video_path, scratch / "small.mkv");
  EXPECT_FALSE(entry.times);
  ASSERT_TRUE(entry.led_roi_px && entry.foot_roi_px);
  EXPECT_EQ(entry.led_roi_px->x_px, written->truth.led_roi_px.x_px);
}

TEST(WriteTrial, SameSpecGivesIdenticalFiles) {
  ScratchDir first, second;
  TrialSpec spec = SmallSpec();
  spec.camera.drop_probability = 0.1;
  spec.nuisance.noise_sigma = 4.0;
  spec.nuisance.shake_px = 0.5;
  spec.log.jitter_s = 0.003;
  auto a = WriteTrial(spec, TestCalibration(), first.path());
  auto b = WriteTrial(spec, TestCalibration(), second.path());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(ReadFile(a->log_path), ReadFile(b->log_path));
  EXPECT_EQ(ReadFile(a->truth_path), ReadFile(b->truth_path));
  const std::string video = ReadFile(a->video_path);
  EXPECT_GT(video.size(), 1000u);
  EXPECT_TRUE(video == ReadFile(b->video_path)) << "FFV1 bytes differ";
}

TEST(WriteTrial, BadSpecFailsNamingTheField) {
  ScratchDir scratch;
  TrialSpec spec = SmallSpec();
  spec.camera.fps = 0.0;
  auto written = WriteTrial(spec, TestCalibration(), scratch.path());
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(written.status().message(), HasSubstr("camera.fps"));
}

// ---------------------------------------------------------------------------------------
// the CI set

TEST(CiSet, EveryNuisanceAndOptionIsExercisedAtLeastOnce) {
  const std::vector<TrialSpec> set = CiSet();
  ASSERT_GE(set.size(), 20u);
  const auto any = [&](auto predicate) { return std::any_of(set.begin(), set.end(), predicate); };
  using S = const TrialSpec&;
  // resolutions (the 1080p clip is short)
  EXPECT_TRUE(any([](S s) { return s.camera.width_px == 640 && s.camera.height_px == 480; }));
  EXPECT_TRUE(any([](S s) { return s.camera.width_px == 1280 && s.camera.height_px == 720; }));
  EXPECT_TRUE(any([](S s) {
    return s.camera.width_px == 1920 && s.camera.height_px == 1080 && s.duration_s <= 3.0;
  }));
  // frame rates, variable frame rate
  for (const double fps : {30.0, 60.0, 120.0, 240.0}) {
    EXPECT_TRUE(any([&](S s) { return s.camera.fps == fps; })) << fps;
  }
  EXPECT_TRUE(any([](S s) { return s.camera.drop_probability > 0; }));
  EXPECT_TRUE(any([](S s) { return s.camera.timestamp_jitter_s > 0; }));
  // exposure: a full-frame one, a short one, an LED switching on inside an exposure
  EXPECT_TRUE(any([](S s) { return s.camera.exposure_s * s.camera.fps > 0.99; }));
  EXPECT_TRUE(any([](S s) { return s.camera.exposure_s * s.camera.fps < 0.25; }));
  EXPECT_TRUE(any([](S s) {
    // exposures are centred on the frames' timestamps (whole slots)
    const double slots = s.led.on_video_s * s.camera.fps;
    const double from_timestamp = std::abs(slots - std::round(slots));
    return s.camera.drop_probability == 0 && s.camera.timestamp_jitter_s == 0 &&
           from_timestamp < 0.5 * s.camera.exposure_s * s.camera.fps - 0.01;
  }));
  // image nuisances
  EXPECT_TRUE(any([](S s) { return s.nuisance.noise_sigma > 0; }));
  EXPECT_TRUE(any([](S s) { return s.nuisance.motion_blur_samples > 1; }));
  EXPECT_TRUE(
      any([](S s) { return s.nuisance.flicker_amplitude > 0 && s.nuisance.flicker_hz == 100; }));
  EXPECT_TRUE(
      any([](S s) { return s.nuisance.flicker_amplitude > 0 && s.nuisance.flicker_hz == 120; }));
  EXPECT_TRUE(any([](S s) { return s.nuisance.shake_px > 0; }));
  EXPECT_TRUE(any([](S s) { return s.nuisance.shadow; }));
  EXPECT_TRUE(any([](S s) { return !s.nuisance.shadow; }));
  // the LED: colours, sizes, saturation, bloom
  std::set<std::array<int, 3>> colours;
  for (S s : set) colours.insert({s.led.blue, s.led.green, s.led.red});
  EXPECT_GE(colours.size(), 4u);
  EXPECT_TRUE(any([](S s) { return s.led.radius_px < 4; }));
  EXPECT_TRUE(any([](S s) { return s.led.radius_px > 10; }));
  EXPECT_TRUE(any([](S s) { return s.led.intensity < 1; }));
  EXPECT_TRUE(any([](S s) { return s.led.intensity > 2; }));
  EXPECT_TRUE(any([](S s) { return s.led.bloom == 0; }));
  EXPECT_TRUE(any([](S s) { return s.led.bloom > 4; }));
  // codecs
  for (const VideoCodec codec : {VideoCodec::kH264, VideoCodec::kMjpeg, VideoCodec::kFfv1}) {
    EXPECT_TRUE(any([&](S s) { return s.camera.codec == codec; })) << VideoCodecName(codec);
  }
  // every foot, both senses, both curve kinds, the diagonal partner
  for (const Foot foot : kAllFeet) {
    EXPECT_TRUE(any([&](S s) { return s.motion.foot == foot; })) << FootName(foot);
  }
  EXPECT_TRUE(any([](S s) { return s.motion.rotation == RotationSense::kPositive; }));
  EXPECT_TRUE(any([](S s) { return s.motion.rotation == RotationSense::kNegative; }));
  EXPECT_TRUE(any([](S s) { return s.motion.height.kind == "parametric"; }));
  EXPECT_TRUE(any([](S s) { return s.motion.height.kind == "csv"; }));
  EXPECT_TRUE(any([](S s) { return s.motion.diagonal_lag_rad > 0; }));
  // the log
  EXPECT_TRUE(any([](S s) { return s.log.burst_period_s > 0; }));
  EXPECT_TRUE(any([](S s) { return s.log.clock_drift_ppm != 0; }));
  EXPECT_TRUE(any([](S s) { return s.log.jitter_s > 0; }));
  EXPECT_TRUE(any([](S s) { return !s.log.led_event; }));
  EXPECT_TRUE(any([](S s) { return s.log.led_event && s.log.led_on_device_ns != 0; }));
}

TEST(CiSet, ClipsAreValidUniqueShortAndLiftWithinTheClip) {
  std::set<std::string> ids;
  double vga_frames = 0.0;
  int checked_by_hand = 0;
  for (const TrialSpec& spec : CiSet()) {
    EXPECT_TRUE(spec.Validate().ok()) << spec.id << ": " << spec.Validate().ToString();
    EXPECT_TRUE(ids.insert(spec.id).second) << spec.id;
    EXPECT_LE(spec.duration_s, 5.0) << spec.id;
    EXPECT_GE(spec.led.on_video_s * spec.camera.fps, 15.0) << spec.id << ": baseline frames";
    vga_frames += spec.duration_s * spec.camera.fps * spec.camera.width_px * spec.camera.height_px /
                  (640.0 * 480.0);
    // the clip ends 0.4 s after the 1 mm instant, rounded up to 0.1 s; by hand, with
    // gain 0.25 m and exponent 1.5, 1 mm is (0.001 / 0.25)^(1 / 1.5) = 0.02520 rad past
    // liftoff, reached at LED + ramp start + (liftoff + 0.02520) / rate:
    //   ci-01 A: 0.61 + 0.2 + 0.49520 / 0.2 = 3.286 s, + 0.4 -> 3.7 s
    //   ci-02 B: 0.61 + 0.2 + 0.60520 / 0.2 = 3.836 s, + 0.4 -> 4.3 s
    //   ci-06 C: 0.61 + 0.2 + 0.32520 / 0.5 = 1.460 s, + 0.4 -> 1.9 s
    //   ci-07 B: 0.6004 + 0.2 + 0.60520 / 0.3 = 2.818 s, + 0.4 -> 3.3 s
    //   ci-13 A: 0.61 + 0.2 + 0.49520 / 0.4 = 2.048 s, + 0.4 -> 2.5 s
    const std::map<std::string, double> by_hand = {
        {"ci-01-baseline-ffv1", 3.7}, {"ci-02-h264-bframes-30fps", 4.3},
        {"ci-06-1080p-short", 1.9},   {"ci-07-120fps-short-exposure", 3.3},
        {"ci-13-motion-blur", 2.5},
    };
    if (const auto expected = by_hand.find(spec.id); expected != by_hand.end()) {
      EXPECT_NEAR(spec.duration_s, expected->second, 1e-9) << spec.id;
      ++checked_by_hand;
    }
  }
  EXPECT_EQ(checked_by_hand, 5);
  EXPECT_LT(vga_frames, 9000.0);  // keeps generation within the test budget
}

TEST(CiSet, InvalidInputsCoverTheFourFailures) {
  const std::vector<InvalidInput> inputs = CiInvalidInputs();
  ASSERT_EQ(inputs.size(), 4u);
  EXPECT_EQ(inputs[0].id, "invalid-led-never-on");
  EXPECT_TRUE(inputs[0].spec.led.on_video_s < 0 ||
              inputs[0].spec.led.on_video_s >= inputs[0].spec.duration_s);
  EXPECT_EQ(inputs[1].id, "invalid-foot-never-lifts");
  const auto& m = inputs[1].spec.motion;
  EXPECT_LT((inputs[1].spec.duration_s - inputs[1].spec.led.on_video_s - m.ramp_start_s) *
                m.ramp_rate_rad_per_s,
            m.height.liftoff_rad);
  EXPECT_EQ(inputs[2].kind, InvalidInput::Kind::kTruncated);
  EXPECT_EQ(inputs[3].kind, InvalidInput::Kind::kNotAVideo);
  for (const InvalidInput& input : inputs) {
    if (input.kind != InvalidInput::Kind::kNotAVideo) {
      EXPECT_TRUE(input.spec.Validate().ok()) << input.id;
      EXPECT_EQ(input.spec.id, input.id);
    }
  }
}

TEST(CiSet, SetByNameKnowsCiAndPaperOnly) {
  auto ci = SetByName("ci");
  ASSERT_TRUE(ci.ok());
  EXPECT_EQ(ci->size(), CiSet().size());
  auto paper = SetByName("paper");
  ASSERT_TRUE(paper.ok());
  EXPECT_EQ(paper->size(), 4u);
  for (const TrialSpec& spec : *paper) EXPECT_TRUE(spec.Validate().ok()) << spec.id;
  auto unknown = SetByName("nope");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(unknown.status().message(), HasSubstr("ci, paper"));
}

// ---------------------------------------------------------------------------------------
// `liftoff synth` end to end

CommandRun RunBinary(const std::string& arguments, const ScratchDir& scratch) {
  return liftoff::testing::RunCommand(LIFTOFF_BINARY, arguments, scratch);
}

TEST(SynthCommand, CiSetEndToEnd) {
  ScratchDir scratch;
  const auto dir = scratch / "ci";
  const int64_t started_ns = MonotonicNowNs();
  const CommandRun run = RunBinary("synth --set ci -o " + Quoted(dir), scratch);
  const double seconds = SecondsFromNs(MonotonicNowNs() - started_ns);
  ASSERT_EQ(run.code, 0) << run.err;
  std::printf("liftoff synth --set ci: %.1f s\n%s", seconds, run.out.c_str());
  EXPECT_THAT(run.err, HasSubstr("/28] invalid-not-a-video"));

  // the index lists every file, and each exists
  auto index = LoadJsonFile(dir / "set.json");
  ASSERT_TRUE(index.ok()) << index.status().ToString();
  ASSERT_EQ((*index)["trials"].size(), CiSet().size());
  for (const auto& trial : (*index)["trials"]) {
    for (const char* key : {"video", "log", "truth_file"}) {
      EXPECT_TRUE(std::filesystem::exists(dir / trial[key].get<std::string>())) << trial[key];
    }
  }
  // the manifest loads, with a video and ROIs per trial
  auto manifest = LoadManifest(dir / "manifest.json");
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  ASSERT_EQ(manifest->trials.size(), CiSet().size());
  for (const TrialRecord& trial : manifest->trials) {
    ASSERT_TRUE(trial.video_path) << trial.id;
    EXPECT_TRUE(std::filesystem::exists(*trial.video_path)) << trial.id;
    EXPECT_TRUE(trial.led_roi_px && trial.foot_roi_px) << trial.id;
  }
  // the invalid inputs exist; the non-video and the truncated file do not decode whole
  ASSERT_EQ((*index)["invalid"].size(), 4u);
  for (const auto& input : (*index)["invalid"]) {
    EXPECT_TRUE(std::filesystem::exists(dir / input["file"].get<std::string>())) << input["id"];
  }
  cv::VideoCapture not_a_video((dir / "invalid-not-a-video.mp4").string(), cv::CAP_FFMPEG);
  EXPECT_FALSE(not_a_video.isOpened());
  cv::VideoCapture truncated((dir / "invalid-truncated.mp4").string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(truncated.isOpened()) << "the index is up front: it opens, then runs dry";
  const double listed = truncated.get(cv::CAP_PROP_FRAME_COUNT);
  double decoded = 0;
  while (truncated.grab()) ++decoded;
  EXPECT_GT(decoded, 0);
  EXPECT_LT(decoded, listed);

  // every valid clip decodes to exactly its truth's frames, at its truth's times (but the
  // last two of an H.264 file, which OpenCV reports at 0: see video_writer.h)
  for (const auto& trial : (*index)["trials"]) {
    const std::string video = trial["video"].get<std::string>();
    cv::VideoCapture capture((dir / video).string(), cv::CAP_FFMPEG);
    ASSERT_TRUE(capture.isOpened()) << trial["id"];
    const std::vector<int64_t> times = trial["truth"]["frame_times_ns"].get<std::vector<int64_t>>();
    const size_t reliable = video.ends_with(".mp4") ? times.size() - 2 : times.size();
    size_t frames = 0;
    for (; capture.grab(); ++frames) {
      if (frames >= reliable) continue;
      ASSERT_NEAR(capture.get(cv::CAP_PROP_POS_MSEC), static_cast<double>(times[frames]) * 1e-6,
                  1e-3)
          << trial["id"] << " frame " << frames;
    }
    EXPECT_EQ(frames, times.size()) << trial["id"];
  }
}

TEST(SynthCommand, OneSpecFromJsonWritesTheTrial) {
  ScratchDir scratch;
  nlohmann::json spec = TrialSpecToJson(SmallSpec());
  spec["id"] = "from-json";
  WriteFile(scratch / "spec.json", spec.dump(2));
  const CommandRun run = RunBinary(
      "synth " + Quoted(scratch / "spec.json") + " -o " + Quoted(scratch / "out"), scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("from-json: 48 frames"));
  EXPECT_THAT(run.out, HasSubstr("LED on: 0.300 s (frame 9"));
  EXPECT_TRUE(std::filesystem::exists(scratch / "out" / "from-json.mkv"));
  EXPECT_TRUE(std::filesystem::exists(scratch / "out" / "from-json.csv"));
  EXPECT_TRUE(std::filesystem::exists(scratch / "out" / "from-json.truth.json"));
}

TEST(SynthCommand, PrintSpecRoundTripsAsTheDefault) {
  ScratchDir scratch;
  const CommandRun run = RunBinary("synth --print-spec", scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  auto document = ParseJsonText(run.out, "<stdout>");
  ASSERT_TRUE(document.ok()) << document.status().ToString();
  auto spec = TrialSpecFromJson(*document, "<stdout>", ".");
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(spec->duration_s, 24.0);
  EXPECT_EQ(spec->camera.width_px, 1280);
  EXPECT_EQ(spec->camera.codec, VideoCodec::kFfv1);
}

TEST(SynthCommand, ErrorsHaveTheirExitCodes) {
  ScratchDir scratch;
  // usage (2): no job, two jobs, no output folder
  EXPECT_EQ(RunBinary("synth", scratch).code, 2);
  EXPECT_EQ(RunBinary("synth --set ci --print-spec", scratch).code, 2);
  EXPECT_EQ(RunBinary("synth --set ci", scratch).code, 2);
  // a bad field: the file and the JSON pointer
  WriteFile(scratch / "bad.json", R"({"camera": {"fps": 0}})");
  const CommandRun bad =
      RunBinary("synth " + Quoted(scratch / "bad.json") + " -o " + Quoted(scratch / "x"), scratch);
  EXPECT_EQ(bad.code, 3);
  EXPECT_THAT(bad.err, HasSubstr("bad.json"));
  EXPECT_THAT(bad.err, HasSubstr("/camera/fps"));
  // malformed JSON, a missing spec, an unknown set
  WriteFile(scratch / "broken.json", "{\"camera\": ");
  EXPECT_EQ(RunBinary("synth " + Quoted(scratch / "broken.json") + " -o x", scratch).code, 5);
  EXPECT_EQ(RunBinary("synth /nonexistent/spec.json -o x", scratch).code, 4);
  const CommandRun unknown = RunBinary("synth --set nope -o " + Quoted(scratch / "y"), scratch);
  EXPECT_EQ(unknown.code, 4);
  EXPECT_THAT(unknown.err, HasSubstr("expected one of ci, paper"));
}

}  // namespace
}  // namespace liftoff::synth
