// The switch-on and switch-off intervals of a centred exposure (src/video/led_timing.h)
// against cases worked out by hand: a frame with timestamp t exposes [t - E/2, t + E/2],
// so an LED on at s lights it for clamp((t + E/2 - s) / E, 0, 1) of its exposure.
#include "led_timing.h"

#include <gtest/gtest.h>

namespace liftoff::video::internal {
namespace {

constexpr double kT = 1e6;  // frame interval in these cases, ns (whole numbers keep it exact)

TEST(SwitchOnInterval, PartialFrameWithKnownExposureIsExact) {
  // E = 0.5 T, lit frame at 10 T lit 30 %: s = 10 T + E/2 - 0.3 E = 10.1 T
  const InstantInterval interval =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {0.3, 0.3}, {0.5 * kT, 0.5 * kT});
  EXPECT_NEAR(interval.low_ns, 10.1 * kT, 1e-6);
  EXPECT_NEAR(interval.high_ns, 10.1 * kT, 1e-6);
}

TEST(SwitchOnInterval, PartialFrameWithUnknownExposureSpansEveryExposureUpToTheInterval) {
  // lit 30 %: s = t + (0.5 - 0.3) E for E in (0, T]: [t, t + 0.2 T], middle t + 0.1 T
  const InstantInterval interval =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {0.3, 0.3}, {0.0, kT});
  EXPECT_NEAR(interval.low_ns, 10 * kT, 1e-6);
  EXPECT_NEAR(interval.high_ns, 10.2 * kT, 1e-6);
  EXPECT_EQ(interval.Middle(), static_cast<int64_t>(10.1 * kT));
  // lit 80 %: s = t - 0.3 E: [t - 0.3 T, t]
  const InstantInterval later =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {0.8, 0.8}, {0.0, kT});
  EXPECT_NEAR(later.low_ns, 9.7 * kT, 1e-6);
  EXPECT_NEAR(later.high_ns, 10 * kT, 1e-6);
}

TEST(SwitchOnInterval, HalfLitFrameDatesTheSwitchAtItsTimestampWhateverTheExposure) {
  const InstantInterval interval =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {0.5, 0.5}, {0.0, kT});
  EXPECT_NEAR(interval.low_ns, 10 * kT, 1e-6);
  EXPECT_NEAR(interval.high_ns, 10 * kT, 1e-6);
}

TEST(SwitchOnInterval, FullyLitFrameAfterADarkOneSpansTheGapBetweenThem) {
  // E known: after the dark exposure's end (9 T + E/2), before the lit one's start
  const InstantInterval known =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.4 * kT, 0.4 * kT});
  EXPECT_NEAR(known.low_ns, 9.2 * kT, 1e-6);
  EXPECT_NEAR(known.high_ns, 9.8 * kT, 1e-6);
  // E unknown: the whole interval between the timestamps, half-width T / 2
  const InstantInterval unknown =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.0, kT});
  EXPECT_NEAR(unknown.low_ns, 9 * kT, 1e-6);
  EXPECT_NEAR(unknown.high_ns, 10 * kT, 1e-6);
  EXPECT_EQ(unknown.HalfWidth(), static_cast<int64_t>(0.5 * kT));
}

TEST(SwitchOnInterval, DroppedFramesWidenTheIntervalToTheRealTimestamps) {
  // two frames missing between the dark frame (7 T) and the lit one (10 T); the exposure
  // is still at most the usual interval T
  const InstantInterval interval =
      SwitchOnInterval(7 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.0, kT});
  EXPECT_NEAR(interval.low_ns, 7 * kT, 1e-6);
  EXPECT_NEAR(interval.high_ns, 10 * kT, 1e-6);
  EXPECT_EQ(interval.Middle(), static_cast<int64_t>(8.5 * kT));
  // with a partly lit last frame (30 %), only the lit frame matters: [10 T, 10.2 T]
  const InstantInterval partial =
      SwitchOnInterval(7 * kT, {0.0, 0.0}, 10 * kT, {0.3, 0.3}, {0.0, kT});
  EXPECT_NEAR(partial.low_ns, 10 * kT, 1e-6);
  EXPECT_NEAR(partial.high_ns, 10.2 * kT, 1e-6);
}

TEST(DateSwitchOn, WithoutAGapTheEstimateIsTheIntervalsMiddle) {
  const SwitchOnDating dating =
      DateSwitchOn(9 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.0, kT}, kT);
  EXPECT_EQ(dating.missing_frames, 0);
  EXPECT_NEAR(dating.estimate_ns, 9.5 * kT, 1e-6);
  EXPECT_EQ(dating.HalfWidth(), static_cast<int64_t>(0.5 * kT));
}

TEST(DateSwitchOn, AcrossAGapTheFirstMissingFrameIsTakenAsTheFirstLit) {
  // two frames missing (8 T and 9 T): frame 8 T lit for some part of its exposure E in
  // (0, T]: s in [7 T + E/2, 8 T + E/2], over every E: [7 T, 8.5 T], middle 7.75 T; the
  // interval that surely holds it stays the whole gap [7 T, 10 T]
  const SwitchOnDating unknown =
      DateSwitchOn(7 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.0, kT}, kT);
  EXPECT_EQ(unknown.missing_frames, 2);
  EXPECT_NEAR(unknown.estimate_ns, 7.75 * kT, 1e-6);
  EXPECT_NEAR(unknown.surely.low_ns, 7 * kT, 1e-6);
  EXPECT_NEAR(unknown.surely.high_ns, 10 * kT, 1e-6);
  EXPECT_EQ(unknown.HalfWidth(), static_cast<int64_t>(2.25 * kT));
  // E = 0.5 T known: [7.25 T, 8.25 T], middle 7.75 T; surely [7.25 T, 9.75 T]
  const SwitchOnDating known =
      DateSwitchOn(7 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.5 * kT, 0.5 * kT}, kT);
  EXPECT_NEAR(known.estimate_ns, 7.75 * kT, 1e-6);
  EXPECT_NEAR(known.surely.low_ns, 7.25 * kT, 1e-6);
  EXPECT_NEAR(known.surely.high_ns, 9.75 * kT, 1e-6);
  EXPECT_EQ(known.HalfWidth(), static_cast<int64_t>(2 * kT));
  // E = 0.8 T: [7.4 T, 8.4 T], middle 7.9 T
  const SwitchOnDating longer =
      DateSwitchOn(7 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.8 * kT, 0.8 * kT}, kT);
  EXPECT_NEAR(longer.estimate_ns, 7.9 * kT, 1e-6);
  // one frame missing, E = 0.5 T: [8.25 T, 9.25 T], middle 8.75 T
  const SwitchOnDating one =
      DateSwitchOn(8 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.5 * kT, 0.5 * kT}, kT);
  EXPECT_EQ(one.missing_frames, 1);
  EXPECT_NEAR(one.estimate_ns, 8.75 * kT, 1e-6);
}

TEST(DateSwitchOn, APartlyLitFrameAfterAGapDatesTheSwitchItself) {
  const SwitchOnDating dating =
      DateSwitchOn(7 * kT, {0.0, 0.0}, 10 * kT, {0.3, 0.3}, {0.0, kT}, kT);
  EXPECT_EQ(dating.missing_frames, 0);  // not bridged: the partly lit frame dates it
  EXPECT_NEAR(dating.estimate_ns, 10.1 * kT, 1e-6);
}

TEST(DateSwitchOn, AGapOfAnyLengthIsCountedWithoutOverflow) {
  const SwitchOnDating dating = DateSwitchOn(0.0, {0.0, 0.0}, 9e18, {1.0, 1.0}, {0.0, 1.0}, 1.0);
  EXPECT_EQ(dating.missing_frames, 999'999'999);
  EXPECT_TRUE(dating.surely.Contains(dating.estimate_ns));
  EXPECT_GT(dating.HalfWidth(), 0);
  // a gap wider than int64 can hold as a half-width is capped, not wrapped
  const SwitchOnDating wider =
      DateSwitchOn(-9e18, {0.0, 0.0}, 9e18, {1.0, 1.0}, {0.0, 1.0}, 1.0);
  EXPECT_EQ(wider.HalfWidth(), static_cast<int64_t>(kMaxNs));
  EXPECT_EQ(wider.surely.HalfWidth(), static_cast<int64_t>(kMaxNs));
}

TEST(DateSwitchOn, JitterBelowHalfAnIntervalIsNoGap) {
  const SwitchOnDating dating =
      DateSwitchOn(8.6 * kT, {0.0, 0.0}, 10 * kT, {1.0, 1.0}, {0.0, kT}, kT);
  EXPECT_EQ(dating.missing_frames, 0);
  EXPECT_NEAR(dating.estimate_ns, 9.3 * kT, 1e-6);
}

TEST(SwitchOnInterval, NoiseBandsWidenTheInterval) {
  // E = T; lit in [0.2, 0.4]: s in [t + 0.1 T, t + 0.3 T]; a dark frame lit up to 15 %
  // allows nothing earlier than 9 T + 0.35 T
  const InstantInterval interval =
      SwitchOnInterval(9 * kT, {0.0, 0.15}, 10 * kT, {0.2, 0.4}, {kT, kT});
  EXPECT_NEAR(interval.low_ns, 10.1 * kT, 1e-6);
  EXPECT_NEAR(interval.high_ns, 10.3 * kT, 1e-6);
  // the lit frame may be whole (band up to 1): anything after the dark frame's allowance
  const InstantInterval whole =
      SwitchOnInterval(9 * kT, {0.0, 0.15}, 10 * kT, {0.9, 1.0}, {kT, kT});
  EXPECT_NEAR(whole.low_ns, 9.35 * kT, 1e-6);
  EXPECT_NEAR(whole.high_ns, 9.6 * kT, 1e-6);
}

TEST(SwitchOnInterval, InconsistentFractionsFallBackToShorterExposures) {
  // E given as T: the dark frame at 9 T wants s >= 9.5 T, the lit one at 9.2 T (lit 90 %)
  // s = 8.8 T: no instant fits. Exposures e < T: s in [9 T + e/2, 9.2 T - 0.4 e], which
  // holds for e <= 0.2 T / 0.9: the union is [9 T + 0.1 T / 0.9, 9.2 T]
  const InstantInterval interval =
      SwitchOnInterval(9 * kT, {0.0, 0.0}, 9.2 * kT, {0.9, 0.9}, {kT, kT});
  EXPECT_NEAR(interval.low_ns, 9 * kT + 0.1 * kT / 0.9, 1e-3);
  EXPECT_NEAR(interval.high_ns, 9.2 * kT, 1e-3);
}

TEST(HalfLitInstant, IsWhereTheLitFractionCrossesOneHalf) {
  // 20 % at 10 T, 80 % at 11 T: half lit a half of the way between them
  EXPECT_NEAR(HalfLitInstant(10 * kT, 0.2, 11 * kT, 0.8), 10.5 * kT, 1e-6);
  // 49 % at 60 T, 70 % at 61 T (a codec's build-up of a 0.8 px LED half lit at 60 T):
  // close to 60 T, not at the frame that first passed a threshold of one half
  EXPECT_NEAR(HalfLitInstant(60 * kT, 0.49, 61 * kT, 0.70), (60 + 0.01 / 0.21) * kT, 1e-6);
  // a frame lit exactly half its exposure is the switch-on
  EXPECT_NEAR(HalfLitInstant(59 * kT, 0.0, 60 * kT, 0.5), 60 * kT, 1e-6);
}

TEST(HalfLitInstant, FractionsNotStraddlingOneHalfGiveTheFrameOnItsSide) {
  // the first frame lit half or more already: it (continuous with a crossing at it)
  EXPECT_EQ(HalfLitInstant(10 * kT, 0.6, 11 * kT, 0.6), 10 * kT);
  EXPECT_EQ(HalfLitInstant(10 * kT, 0.6, 11 * kT, 0.6000001), 10 * kT);
  EXPECT_NEAR(HalfLitInstant(10 * kT, 0.4999999, 11 * kT, 0.6), 10 * kT, 1e-3 * kT);
  // the second still under half: it
  EXPECT_EQ(HalfLitInstant(10 * kT, 0.3, 11 * kT, 0.3), 11 * kT);
  EXPECT_EQ(HalfLitInstant(10 * kT, 0.4, 11 * kT, 0.3), 11 * kT);
  EXPECT_NEAR(HalfLitInstant(10 * kT, 0.3, 11 * kT, 0.5), 11 * kT, 1e-6);
  // fractions beyond 0 .. 1 (noise) stay between the two frames
  EXPECT_NEAR(HalfLitInstant(10 * kT, -0.5, 11 * kT, 1.5), 10.5 * kT, 1e-6);
  EXPECT_NEAR(HalfLitInstant(10 * kT, 0.0, 11 * kT, 2.0), 10.25 * kT, 1e-6);
}

TEST(SwitchOffInterval, IsTheSwitchOnWithTimeReversed) {
  // last lit frame at 10 T lit for its first 30 %, E unknown up to T: s = t - E/2 + 0.3 E
  // = t - 0.2 E: [t - 0.2 T, t]
  const InstantInterval partial =
      SwitchOffInterval(10 * kT, {0.3, 0.3}, 11 * kT, {0.0, 0.0}, {0.0, kT});
  EXPECT_NEAR(partial.low_ns, 9.8 * kT, 1e-6);
  EXPECT_NEAR(partial.high_ns, 10 * kT, 1e-6);
  // fully lit, then dark: between the two timestamps
  const InstantInterval whole =
      SwitchOffInterval(10 * kT, {1.0, 1.0}, 11 * kT, {0.0, 0.0}, {0.0, kT});
  EXPECT_NEAR(whole.low_ns, 10 * kT, 1e-6);
  EXPECT_NEAR(whole.high_ns, 11 * kT, 1e-6);
}

}  // namespace
}  // namespace liftoff::video::internal
