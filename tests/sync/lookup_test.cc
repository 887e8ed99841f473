#include "liftoff/sync/lookup.h"

#include <cmath>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace liftoff::sync {
namespace {

using ::testing::HasSubstr;

constexpr double kTight = 1e-12;

// a log of (device time ms, vertebra angle rad) samples
ControllerLog MakeLog(const std::vector<std::pair<int64_t, double>>& samples) {
  ControllerLog log;
  for (const auto& [time_ms, vertebra_rad] : samples) {
    LogSample sample;
    sample.device_time_ns = NsFromMilliseconds(time_ms);
    sample.vertebra_rad = vertebra_rad;
    log.samples.push_back(sample);
  }
  return log;
}

// 0 .. 1 s every 0.1 s, angle 0.5 rad/s * t
ControllerLog Ramp() {
  std::vector<std::pair<int64_t, double>> samples;
  for (int64_t ms = 0; ms <= 1000; ms += 100) {
    samples.push_back({ms, 0.5 * static_cast<double>(ms) / 1000.0});
  }
  return MakeLog(samples);
}

// two bursts with a 0.933 s gap between 5.071 s and 6.004 s
ControllerLog Bursts() {
  return MakeLog({{5000, -0.370}, {5030, -0.380}, {5071, -0.385}, {6004, -0.4075}, {6030, -0.410}});
}

LookupOptions Rule(LookupRule rule) {
  LookupOptions options;
  options.rule = rule;
  return options;
}

constexpr int64_t Ms(int64_t ms) { return NsFromMilliseconds(ms); }

TEST(LookupRule, NamesAndParsesBothRules) {
  EXPECT_EQ(LookupRuleName(LookupRule::kLinear), "linear");
  EXPECT_EQ(LookupRuleName(LookupRule::kSampleAndHold), "sample-and-hold");
  EXPECT_EQ(ParseLookupRule("linear"), LookupRule::kLinear);
  EXPECT_EQ(ParseLookupRule("hold"), LookupRule::kSampleAndHold);
  EXPECT_EQ(ParseLookupRule("sample-and-hold"), LookupRule::kSampleAndHold);
  EXPECT_EQ(ParseLookupRule("Linear"), std::nullopt);
  EXPECT_EQ(ParseLookupRule(""), std::nullopt);
}

TEST(LookupOptions, RejectsNonPositiveGapThresholdAndNegativeTolerance) {
  EXPECT_TRUE(LookupOptions{}.Validate().ok());
  LookupOptions options;
  options.gap_threshold_s = 0.0;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(options.Validate().message(), HasSubstr("gap_threshold_s"));
  options = {};
  options.max_past_end_s = -0.1;
  EXPECT_THAT(options.Validate().message(), HasSubstr("max_past_end_s"));
  options.max_past_end_s = std::nan("");
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  // a lookup with bad options fails the same way
  EXPECT_EQ(LookupVertebraAngle(Ramp(), Ms(500), 0, options).status().code(),
            StatusCode::kInvalidArgument);
}

TEST(LookupOptions, RejectsSecondsBeyondKMaxTimeSeconds) {
  // 1e10 s once became INT64_MIN ns and answered every query far past the log's end
  LookupOptions options;
  options.max_past_end_s = 1e10;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(options.Validate().message(),
            "lookup options: max_past_end_s: expected a number in [0, 1e+06] s, got 1e+10");
  EXPECT_EQ(LookupVertebraAngle(Ramp(), Ms(500), 0, options).status().code(),
            StatusCode::kInvalidArgument);
  options = {};
  options.gap_threshold_s = 1e10;
  EXPECT_EQ(options.Validate().message(),
            "lookup options: gap_threshold_s: expected a number in (0, 1e+06] s, got 1e+10");
  options.gap_threshold_s = kMaxTimeSeconds;
  EXPECT_TRUE(options.Validate().ok());
}

TEST(LookupVertebraAngle, LinearInterpolatesAndHoldTakesTheSampleBefore) {
  // 0.25 s lies halfway between 0.2 s (0.10 rad) and 0.3 s (0.15 rad)
  auto linear = LookupVertebraAngle(Ramp(), Ms(250), 0, Rule(LookupRule::kLinear));
  ASSERT_TRUE(linear.ok()) << linear.status().ToString();
  EXPECT_NEAR(linear->vertebra_rad, 0.125, kTight);
  EXPECT_NEAR(linear->lower_rad, 0.125, kTight);
  EXPECT_NEAR(linear->upper_rad, 0.125, kTight);
  EXPECT_EQ(linear->sample_before_ns, Ms(200));
  EXPECT_EQ(linear->sample_after_ns, Ms(300));
  EXPECT_FALSE(linear->in_gap);
  EXPECT_FALSE(linear->past_end);
  EXPECT_FALSE(linear->before_start);
  EXPECT_TRUE(linear->warnings.empty());

  auto hold = LookupVertebraAngle(Ramp(), Ms(250), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(hold.ok()) << hold.status().ToString();
  EXPECT_NEAR(hold->vertebra_rad, 0.10, kTight);
  EXPECT_NEAR(hold->lower_rad, 0.10, kTight);
  EXPECT_NEAR(hold->upper_rad, 0.10, kTight);
  EXPECT_EQ(hold->rule, LookupRule::kSampleAndHold);
}

TEST(LookupVertebraAngle, HoldIsInclusiveAtAnExactSample) {
  // the sample at 0.3 s itself answers, not the one at 0.2 s
  auto hold = LookupVertebraAngle(Ramp(), Ms(300), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(hold.ok());
  EXPECT_NEAR(hold->vertebra_rad, 0.15, kTight);
  EXPECT_EQ(hold->sample_before_ns, Ms(300));
  EXPECT_EQ(hold->sample_after_ns, Ms(300));
  auto linear = LookupVertebraAngle(Ramp(), Ms(300), 0, Rule(LookupRule::kLinear));
  ASSERT_TRUE(linear.ok());
  EXPECT_NEAR(linear->vertebra_rad, 0.15, kTight);
  // one nanosecond earlier, hold falls back to the previous sample
  auto just_before = LookupVertebraAngle(Ramp(), Ms(300) - 1, 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(just_before.ok());
  EXPECT_NEAR(just_before->vertebra_rad, 0.10, kTight);
}

TEST(LookupVertebraAngle, IntervalCoversTheRuleOverAWindowOfSeveralSamples) {
  // window 0.5 +/- 0.22 s = [0.28, 0.72] s
  auto linear = LookupVertebraAngle(Ramp(), Ms(500), Ms(220), Rule(LookupRule::kLinear));
  ASSERT_TRUE(linear.ok());
  EXPECT_NEAR(linear->vertebra_rad, 0.25, kTight);
  EXPECT_NEAR(linear->lower_rad, 0.14, kTight);  // 0.5 * 0.28
  EXPECT_NEAR(linear->upper_rad, 0.36, kTight);  // 0.5 * 0.72
  // hold: from the sample at 0.2 s (0.10) to the one at 0.7 s (0.35)
  auto hold = LookupVertebraAngle(Ramp(), Ms(500), Ms(220), Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(hold.ok());
  EXPECT_NEAR(hold->vertebra_rad, 0.25, kTight);
  EXPECT_NEAR(hold->lower_rad, 0.10, kTight);
  EXPECT_NEAR(hold->upper_rad, 0.35, kTight);
  EXPECT_FALSE(hold->in_gap);
}

TEST(LookupVertebraAngle, QueryInsideAGapCoversBothBracketingValues) {
  auto hold = LookupVertebraAngle(Bursts(), Ms(6000), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(hold.ok()) << hold.status().ToString();
  EXPECT_NEAR(hold->vertebra_rad, -0.385, kTight);
  EXPECT_NEAR(hold->lower_rad, -0.4075, kTight);
  EXPECT_NEAR(hold->upper_rad, -0.385, kTight);
  EXPECT_TRUE(hold->in_gap);
  EXPECT_EQ(hold->gap_ns, Ms(933));
  EXPECT_EQ(hold->sample_before_ns, Ms(5071));
  EXPECT_EQ(hold->sample_after_ns, Ms(6004));
  ASSERT_EQ(hold->warnings.size(), 1u);
  EXPECT_THAT(hold->warnings[0],
              HasSubstr("inside a 0.93 s gap between samples at 5.071 s and 6.004 s"));
  EXPECT_THAT(hold->Brief(), HasSubstr("0.93 s gap"));

  // linear: -0.385 + (0.929 / 0.933) * (-0.0225), same interval
  auto linear = LookupVertebraAngle(Bursts(), Ms(6000), 0, Rule(LookupRule::kLinear));
  ASSERT_TRUE(linear.ok());
  EXPECT_NEAR(linear->vertebra_rad, -0.385 - 0.929 / 0.933 * 0.0225, 1e-12);
  EXPECT_NEAR(linear->lower_rad, -0.4075, kTight);
  EXPECT_NEAR(linear->upper_rad, -0.385, kTight);
  EXPECT_TRUE(linear->in_gap);
}

TEST(LookupVertebraAngle, WindowReachingIntoAGapIsWidenedButASampleAloneIsNot) {
  // exactly at the sample before the gap, no uncertainty: not in the gap
  auto at_sample = LookupVertebraAngle(Bursts(), Ms(5071), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(at_sample.ok());
  EXPECT_FALSE(at_sample->in_gap);
  EXPECT_NEAR(at_sample->lower_rad, -0.385, kTight);
  EXPECT_NEAR(at_sample->upper_rad, -0.385, kTight);
  // +/- 10 ms: [5.061, 5.081] s holds -0.380 and -0.385 and reaches into the gap
  auto window = LookupVertebraAngle(Bursts(), Ms(5071), Ms(10), Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(window.ok());
  EXPECT_TRUE(window->in_gap);
  EXPECT_EQ(window->gap_ns, Ms(933));
  EXPECT_NEAR(window->vertebra_rad, -0.385, kTight);
  EXPECT_NEAR(window->lower_rad, -0.4075, kTight);
  EXPECT_NEAR(window->upper_rad, -0.380, kTight);
  ASSERT_EQ(window->warnings.size(), 1u);
  EXPECT_THAT(window->warnings[0], HasSubstr("overlaps a 0.93 s gap"));
}

TEST(LookupVertebraAngle, GapThresholdDecidesWhatIsAGap) {
  LookupOptions options = Rule(LookupRule::kSampleAndHold);
  options.gap_threshold_s = 1.0;  // 0.933 s is now an ordinary spacing
  auto hold = LookupVertebraAngle(Bursts(), Ms(6000), 0, options);
  ASSERT_TRUE(hold.ok());
  EXPECT_FALSE(hold->in_gap);
  EXPECT_NEAR(hold->lower_rad, -0.385, kTight);
  EXPECT_NEAR(hold->upper_rad, -0.385, kTight);
}

TEST(LookupVertebraAngle, PastTheEndWithinToleranceHoldsAndWidensByTheMeanRate) {
  // 0.5 s past the end of a 0.5 rad/s ramp: held 0.5, widened by 0.25
  for (LookupRule rule : {LookupRule::kLinear, LookupRule::kSampleAndHold}) {
    auto past = LookupVertebraAngle(Ramp(), Ms(1500), 0, Rule(rule));
    ASSERT_TRUE(past.ok()) << past.status().ToString();
    EXPECT_NEAR(past->vertebra_rad, 0.5, kTight);
    EXPECT_NEAR(past->lower_rad, 0.25, kTight);
    EXPECT_NEAR(past->upper_rad, 0.75, kTight);
    EXPECT_TRUE(past->past_end);
    EXPECT_FALSE(past->before_start);
    EXPECT_EQ(past->sample_before_ns, Ms(1000));
    EXPECT_EQ(past->sample_after_ns, std::nullopt);
    ASSERT_EQ(past->warnings.size(), 1u);
    EXPECT_THAT(past->warnings[0], HasSubstr("0.500 s after the log's last sample at 1.000 s"));
  }
}

TEST(LookupVertebraAngle, WindowReachingPastTheEndIsWidenedForThePartOutside) {
  // window [0.85, 1.05] s: 0.425 .. 0.5 (held), widened by 0.5 rad/s * 0.05 s
  auto lookup = LookupVertebraAngle(Ramp(), Ms(950), Ms(100), Rule(LookupRule::kLinear));
  ASSERT_TRUE(lookup.ok());
  EXPECT_FALSE(lookup->past_end);
  EXPECT_NEAR(lookup->vertebra_rad, 0.475, kTight);
  EXPECT_NEAR(lookup->lower_rad, 0.4, kTight);
  EXPECT_NEAR(lookup->upper_rad, 0.525, kTight);
  ASSERT_EQ(lookup->warnings.size(), 1u);
  EXPECT_THAT(lookup->warnings[0], HasSubstr("past the log's last sample at 1.000 s"));
}

TEST(LookupVertebraAngle, BeforeTheStartWithinToleranceHoldsTheFirstValue) {
  // 0.5 .. 1.0 s at 0.2 rad/s; 0.3 s before the start: 0.10 +/- 0.06
  const ControllerLog log =
      MakeLog({{500, 0.10}, {600, 0.12}, {700, 0.14}, {800, 0.16}, {900, 0.18}, {1000, 0.20}});
  auto lookup = LookupVertebraAngle(log, Ms(200), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(lookup.ok()) << lookup.status().ToString();
  EXPECT_NEAR(lookup->vertebra_rad, 0.10, kTight);
  EXPECT_NEAR(lookup->lower_rad, 0.04, 1e-12);
  EXPECT_NEAR(lookup->upper_rad, 0.16, 1e-12);
  EXPECT_TRUE(lookup->before_start);
  EXPECT_FALSE(lookup->past_end);
  EXPECT_EQ(lookup->sample_before_ns, std::nullopt);
  EXPECT_EQ(lookup->sample_after_ns, Ms(500));
  ASSERT_EQ(lookup->warnings.size(), 1u);
  EXPECT_THAT(lookup->warnings[0], HasSubstr("0.300 s before the log's first sample at 0.500 s"));
}

TEST(LookupVertebraAngle, BeyondToleranceIsOutOfRangeNamingInstantAndSpan) {
  const ControllerLog log = MakeLog({{4, 0.0}, {9079, 0.56}});
  auto after = LookupVertebraAngle(log, Ms(12400), 0, LookupOptions{});
  EXPECT_EQ(after.status().code(), StatusCode::kOutOfRange);
  EXPECT_THAT(after.status().message(),
              HasSubstr("instant 12.400 s is after the log's last sample at 9.079 s "
                        "(log spans 0.004-9.079 s)"));
  EXPECT_THAT(after.status().message(), HasSubstr("max_past_end_s"));
  auto before = LookupVertebraAngle(log, Ms(-1500), 0, LookupOptions{});
  EXPECT_EQ(before.status().code(), StatusCode::kOutOfRange);
  EXPECT_THAT(before.status().message(),
              HasSubstr("instant -1.500 s is before the log's first sample at 0.004 s "
                        "(log spans 0.004-9.079 s)"));
  // the edge of the tolerance is still answered; a tolerance of 0 answers nothing outside
  EXPECT_TRUE(LookupVertebraAngle(log, Ms(10079), 0, LookupOptions{}).ok());
  LookupOptions strict;
  strict.max_past_end_s = 0.0;
  EXPECT_EQ(LookupVertebraAngle(log, Ms(9079) + 1, 0, strict).status().code(),
            StatusCode::kOutOfRange);
  EXPECT_TRUE(LookupVertebraAngle(log, Ms(9079), 0, strict).ok());
}

TEST(LookupVertebraAngle, SkipsSamplesWithoutAnAngle) {
  const ControllerLog log = MakeLog({{0, 0.0}, {100, kNotMeasured}, {200, 0.1}});
  auto linear = LookupVertebraAngle(log, Ms(100), 0, Rule(LookupRule::kLinear));
  ASSERT_TRUE(linear.ok());
  EXPECT_NEAR(linear->vertebra_rad, 0.05, kTight);
  EXPECT_EQ(linear->sample_before_ns, Ms(0));
  EXPECT_EQ(linear->sample_after_ns, Ms(200));
  auto hold = LookupVertebraAngle(log, Ms(150), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(hold.ok());
  EXPECT_NEAR(hold->vertebra_rad, 0.0, kTight);
  // a log whose last sample has no angle ends at the last one that has
  const ControllerLog tail = MakeLog({{0, 0.0}, {100, 0.1}, {200, kNotMeasured}});
  auto past = LookupVertebraAngle(tail, Ms(150), 0, Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(past.ok());
  EXPECT_TRUE(past->past_end);
}

TEST(LookupVertebraAngle, EmptyLogOrNoAngleIsNotFound) {
  auto empty = LookupVertebraAngle(ControllerLog{}, 0, 0, LookupOptions{});
  EXPECT_EQ(empty.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(empty.status().message(), HasSubstr("no samples"));
  auto no_angle =
      LookupVertebraAngle(MakeLog({{0, kNotMeasured}, {100, kNotMeasured}}), 0, 0, LookupOptions{});
  EXPECT_EQ(no_angle.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(no_angle.status().message(), HasSubstr("vertebra angle"));
}

TEST(LookupVertebraAngle, RejectsANegativeUncertainty) {
  EXPECT_EQ(LookupVertebraAngle(Ramp(), Ms(500), -1, LookupOptions{}).status().code(),
            StatusCode::kInvalidArgument);
}

// 2.0 .. 3.0 s every 0.1 s, angle -0.5 rad/s * (t - 2 s), LED switched on at 2.0 s
ControllerLog NegativeRampWithLedEvent() {
  std::vector<std::pair<int64_t, double>> samples;
  for (int64_t ms = 2000; ms <= 3000; ms += 100) {
    samples.push_back({ms, -0.5 * static_cast<double>(ms - 2000) / 1000.0});
  }
  ControllerLog log = MakeLog(samples);
  LogEvent led;
  led.device_time_ns = Ms(2000);
  led.kind = LogEventKind::kLedOn;
  log.events.push_back(led);
  return log;
}

EventTimes VideoTimes(int64_t led_on_ms, int64_t liftoff_ms, int64_t led_on_uncertainty_ms,
                      int64_t liftoff_uncertainty_ms) {
  EventTimes times;
  times.led_on_ns = Ms(led_on_ms);
  times.liftoff_ns = Ms(liftoff_ms);
  times.led_on_uncertainty_ns = Ms(led_on_uncertainty_ms);
  times.liftoff_uncertainty_ns = Ms(liftoff_uncertainty_ms);
  return times;
}

TEST(MeasureLiftoff, MapsTheVideoLedOnToTheLogsLedEvent) {
  // video: LED 10.000 s, liftoff 10.350 s -> log 2.350 s; window +/- 30 ms
  auto measurement = MeasureLiftoff(NegativeRampWithLedEvent(), VideoTimes(10000, 10350, 10, 20),
                                    Rule(LookupRule::kLinear));
  ASSERT_TRUE(measurement.ok()) << measurement.status().ToString();
  EXPECT_EQ(measurement->interval_ns, Ms(350));
  EXPECT_EQ(measurement->interval_uncertainty_ns, Ms(30));
  EXPECT_EQ(measurement->log_from_video.source_origin_ns, Ms(10000));
  EXPECT_EQ(measurement->log_from_video.target_at_origin_ns, Ms(2000));
  EXPECT_EQ(measurement->log_from_video.scale, 1.0);
  EXPECT_EQ(measurement->liftoff_log_ns, Ms(2350));
  EXPECT_NEAR(measurement->lookup.vertebra_rad, -0.175, kTight);
  EXPECT_NEAR(measurement->liftoff_rad, 0.175, kTight);
  EXPECT_NEAR(measurement->lower_rad, 0.160, kTight);  // |angle| at 2.32 s
  EXPECT_NEAR(measurement->upper_rad, 0.190, kTight);  // |angle| at 2.38 s
  EXPECT_THAT(measurement->Brief(), HasSubstr("0.1750"));
}

TEST(MeasureLiftoff, WithoutAnLedEventTheLogOriginIsTheLedSwitchOn) {
  // the 2018 logs: device clock 0 = LED on, so liftoff 0.35 s after it is 0.35 s
  auto measurement =
      MeasureLiftoff(Ramp(), VideoTimes(5000, 5350, 0, 0), Rule(LookupRule::kSampleAndHold));
  ASSERT_TRUE(measurement.ok());
  EXPECT_EQ(measurement->log_from_video.target_at_origin_ns, 0);
  EXPECT_EQ(measurement->liftoff_log_ns, Ms(350));
  EXPECT_NEAR(measurement->liftoff_rad, 0.15, kTight);  // the sample at 0.3 s
}

TEST(MeasureLiftoff, AbsoluteIntervalStartsAtZeroWhenTheAngleChangesSign) {
  // -0.25 .. 0.25 rad over 0 .. 1 s; window [0.4, 0.6] s is -0.05 .. 0.05 rad
  std::vector<std::pair<int64_t, double>> samples;
  for (int64_t ms = 0; ms <= 1000; ms += 100) {
    samples.push_back({ms, 0.5 * static_cast<double>(ms) / 1000.0 - 0.25});
  }
  auto measurement =
      MeasureLiftoff(MakeLog(samples), VideoTimes(0, 500, 50, 50), Rule(LookupRule::kLinear));
  ASSERT_TRUE(measurement.ok());
  EXPECT_NEAR(measurement->liftoff_rad, 0.0, kTight);
  EXPECT_EQ(measurement->lower_rad, 0.0);
  EXPECT_NEAR(measurement->upper_rad, 0.05, kTight);
}

TEST(MeasureLiftoff, RejectsLiftoffBeforeLedOnAndNegativeUncertainties) {
  auto early = MeasureLiftoff(Ramp(), VideoTimes(5000, 4000, 0, 0), LookupOptions{});
  EXPECT_EQ(early.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(early.status().message(),
              HasSubstr("liftoff at 4.000 s is before the LED switched on at 5.000 s"));
  auto negative = MeasureLiftoff(Ramp(), VideoTimes(0, 500, -1, 0), LookupOptions{});
  EXPECT_EQ(negative.status().code(), StatusCode::kInvalidArgument);
}

TEST(MeasureLiftoff, PassesOnTheLookupsOutOfRange) {
  auto far = MeasureLiftoff(Ramp(), VideoTimes(0, 3000, 0, 0), LookupOptions{});
  EXPECT_EQ(far.status().code(), StatusCode::kOutOfRange);
  EXPECT_THAT(far.status().message(), HasSubstr("instant 3.000 s is after"));
}

}  // namespace
}  // namespace liftoff::sync
