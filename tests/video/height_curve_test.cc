// The height curve's kernels (src/video/height_curve.h) on hand-made curves whose answers
// follow by hand.
#include "height_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace liftoff::video::internal {
namespace {

constexpr double kFrameS = 0.04;  // 25 fps
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<HeightSample> Samples(size_t count) {
  std::vector<HeightSample> samples(count);
  for (size_t i = 0; i < count; ++i) {
    samples[i].frame_index = static_cast<int64_t>(i);
    samples[i].t_ns = static_cast<int64_t>(std::llround(static_cast<double>(i) * kFrameS * 1e9));
    samples[i].keyframe = false;
  }
  return samples;
}

TEST(LagBound, AHeldFrameAndItsCatchUpGiveTheHeldAmountTimesTheFactor) {
  // rising 0.2 px a frame; frame 5 held at frame 4's height, frame 6 catches up (+0.4)
  const std::vector<double> height = {0, 0.2, 0.4, 0.6, 0.8, 0.8, 1.2, 1.4, 1.6};
  // the catch-up exceeds its neighbours' larger change (0.2) by 0.2, the held amount
  EXPECT_NEAR(LagBoundPx(height, 0, 8, 0.0, 1.5), 1.5 * 0.2, 1e-12);
  EXPECT_NEAR(LagBoundPx(height, 0, 8, 0.5, 1.5), 0.5, 1e-12);  // the floor
}

TEST(LagBound, ACatchUpCountsBeyondTheNoiseOnly) {
  // the held frame and its catch-up as above, then the noise allowance taken off the
  // catch-up's 0.2 px; a noise allowance beyond it leaves the floor
  const std::vector<double> height = {0, 0.2, 0.4, 0.6, 0.8, 0.8, 1.2, 1.4, 1.6};
  EXPECT_NEAR(LagBoundPx(height, 0, 8, 0.0, 1.5, 0.05), 1.5 * 0.15, 1e-12);
  EXPECT_NEAR(LagBoundPx(height, 0, 8, 0.3, 1.5, 0.25), 0.3, 1e-12);
  // a still foot's noise (+-0.2 px alternating: every other change stands out by 0.4 px)
  // is no lag once 3 sigmas of its frame-to-frame change are allowed for
  const std::vector<double> noisy = {0, 0.2, -0.2, 0.2, -0.2, 0.2, -0.2, 0.2, -0.2};
  EXPECT_GT(LagBoundPx(noisy, 0, 8, 0.0, 1.5), 0.5);
  EXPECT_NEAR(LagBoundPx(noisy, 0, 8, 0.0, 1.5, 3 * std::sqrt(2.0) * 0.2), 0.0, 1e-12);
}

TEST(LagBound, AFastSmoothRiseIsMotionNotLag) {
  // accelerating by 0.1 px a frame per frame: every change is beyond the one before it by
  // 0.1 and short of the next, so only the last frame (no next) counts, by 0.1 px
  std::vector<double> height;
  for (int i = 0; i < 20; ++i) height.push_back(0.05 * i * i);
  EXPECT_NEAR(LagBoundPx(height, 0, 19, 0.0, 1.5), 1.5 * 0.1, 1e-9);
  // (the rule before, the largest change less the median one, read 1.35 px of lag here)
}

TEST(Crossings, SustainedAndFinalRunsAndTheLineThroughThem) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // a 3-frame excursion at 2..4, back down, then a rise from frame 8 on (frame 10 unmeasured)
  const std::vector<double> height = {0, 0, 1.2, 1.3, 1.1, 0, 0, 0.5, 1.5, 2.5, nan, 4.5};
  EXPECT_EQ(SustainedCrossing(height, 0, 11, 1.0), 2u);
  EXPECT_EQ(FinalRunStart(height, 0, 11, 1.0), 8u);
  EXPECT_EQ(FinalRunStart(height, 0, 9, 3.0), 10u);  // ends below: last + 1
  // frames 6..9 lie on h = (t - 6.5 frames) / frame: crossing 1.0 at 7.5 frames
  const std::vector<HeightSample> samples = Samples(height.size());
  const std::vector<double> line = {0, 0, 0, 0, 0, 0, -0.5, 0.5, 1.5, 2.5, 3.5, 4.5};
  EXPECT_NEAR(LineCrossingS(samples, line, 8, 0, 11, 1.0), 7.5 * kFrameS, 1e-9);
  EXPECT_TRUE(std::isnan(LineCrossingS(samples, line, 1, 0, 11, 1.0)));  // too early
}

TEST(CheckCrossing, AModelCrossingWhollyAfterTheCurveIsReplacedByTheCurves) {
  // rest at 0 with a 0.2 px step at frame 10 (campaign trial B3), then a fast rise: the
  // curve crosses 0.57 between frames 20 (0.26) and 21 (0.61)
  std::vector<double> height(25, 0.0);
  for (size_t f = 10; f < 20; ++f) height[f] = 0.2;
  const std::vector<double> rise = {0.26, 0.61, 1.04, 1.79, 2.64};
  for (size_t i = 0; i < rise.size(); ++i) height[20 + i] = rise[i];
  const std::vector<HeightSample> samples = Samples(height.size());
  // a model 1 s later, +-0.7 s
  const CurveCheck late = CheckCrossing(samples, height, 0, 24, 0.57, 21 * kFrameS + 1.0, 0.7);
  ASSERT_TRUE(late.disagreed);
  EXPECT_GT(late.crossing_s, 20 * kFrameS);
  EXPECT_LT(late.crossing_s, 21 * kFrameS);
  EXPECT_EQ(late.uncertainty_s, 0.7);
  // a model that lies within its uncertainty of the curve holds (a codec may have held the
  // curve back: an earlier model is never replaced)
  EXPECT_FALSE(CheckCrossing(samples, height, 0, 24, 0.57, 21 * kFrameS + 0.1, 0.2).disagreed);
  EXPECT_FALSE(CheckCrossing(samples, height, 0, 24, 0.57, 15 * kFrameS, 0.01).disagreed);
  // a certain model a frame late: the curve's crossing, a frame interval wide
  const CurveCheck certain = CheckCrossing(samples, height, 0, 24, 0.57, 22 * kFrameS, 0.001);
  ASSERT_TRUE(certain.disagreed);
  EXPECT_NEAR(certain.uncertainty_s, kFrameS, 1e-9);
}

TEST(QuietKeyframes, AKeyFramesStepBetweenStillStretchesIsLevelledAndACatchUpIsNot) {
  // still at 0, a key frame at 10 renews the picture to +0.1 px, still again, then at frame
  // 20 another key frame steps +0.1 with the rise going on after it (a catch-up)
  std::vector<double> height(30, 0.0);
  for (size_t f = 10; f < 20; ++f) height[f] = 0.1;
  for (size_t f = 20; f < 30; ++f) height[f] = 0.2 + 0.1 * static_cast<double>(f - 20);
  std::vector<HeightSample> samples = Samples(height.size());
  samples[10].keyframe = samples[20].keyframe = true;
  std::vector<double> levelled = height;
  LevelQuietKeyframes(samples, 0, 29, 5, 0.05, levelled);
  for (size_t f = 0; f < 20; ++f) EXPECT_NEAR(levelled[f], 0.1, 1e-12) << "frame " << f;
  for (size_t f = 20; f < 30; ++f) EXPECT_EQ(levelled[f], height[f]) << "frame " << f;
  // a step the still stretches do not hold within quiet_px is no renewal
  std::vector<double> noisy = height;
  noisy[12] = 0.2;
  std::vector<double> kept = noisy;
  LevelQuietKeyframes(samples, 0, 29, 5, 0.05, kept);
  EXPECT_EQ(kept, noisy);
}

TEST(ReachKeyframe, TheFirstKeyFrameAfterTheTopUnlessTheCurveFellBackOrOutgrewTheReach) {
  // the top at frame 10 (2 px), rising 0.5 px a frame; key frames at 13 and 16
  std::vector<double> height(30);
  for (size_t f = 0; f < height.size(); ++f) height[f] = 0.5 * (static_cast<double>(f) - 6);
  std::vector<HeightSample> samples = Samples(height.size());
  samples[13].keyframe = samples[16].keyframe = true;
  EXPECT_EQ(ReachKeyframe(samples, height, height, 10, 2, 0.5, 1.0, 3.0), 13u);
  // out of reach in time (13 is 0.12 s after the top) or in height (3.5 px > 1.5 x 2 px)
  EXPECT_EQ(ReachKeyframe(samples, height, height, 10, 2, 0.5, 0.1, 3.0), 0u);
  EXPECT_EQ(ReachKeyframe(samples, height, height, 10, 2, 0.5, 1.0, 1.5), 0u);
  // the tracker loses the foot at 12: the key frames after it anchor nothing (re-drawn
  // hard3d-01: a key frame at 7 px while the frames before it read 14 and 19 px)
  std::vector<double> lost = height;
  for (size_t f = 12; f < lost.size(); ++f) lost[f] = 1.0;
  EXPECT_EQ(ReachKeyframe(samples, lost, height, 10, 2, 0.5, 1.0, 3.0), 0u);
  // a dip of less than the threshold is noise
  std::vector<double> wobbly = height;
  wobbly[12] = height[11] - 0.4;
  EXPECT_EQ(ReachKeyframe(samples, wobbly, height, 10, 2, 0.5, 1.0, 3.0), 13u);
  // the fall-back rule holds when the top frame itself was not measured
  std::vector<double> lost_from_unmeasured_top = lost;
  lost_from_unmeasured_top[10] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ReachKeyframe(samples, lost_from_unmeasured_top, height, 10, 2, 0.5, 1.0, 3.0), 0u);
}

TEST(SankBefore, ACurveBelowRestBeforeItsRiseIsNotTheFootAlone) {
  // at rest (0) to frame 9, sinking to -2 px by frame 14 (a tilting leg: re-drawn hard3d-06),
  // the rise crossing +0.5 at frame 16
  const std::vector<double> height = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, -0.3, -0.8, -1.2, -1.6,
                                      -2.0, -0.5, 0.6, 1.5};
  const std::vector<HeightSample> samples = Samples(height.size());
  const Sinking sank = SankBefore(samples, height, 0, 16, 0.0, 0.5, 1.0);
  ASSERT_TRUE(sank.sank);
  EXPECT_NEAR(sank.depth_px, 2.0, 1e-12);
  EXPECT_NEAR(sank.rest_s, 10 * kFrameS, 1e-9);  // -0.3 at frame 10 is within 0.5 of rest
  // sinking by less than sunk_px is noise
  EXPECT_FALSE(SankBefore(samples, height, 0, 16, 0.0, 0.5, 2.5).sank);
  EXPECT_FALSE(SankBefore(samples, height, 0, 10, 0.0, 0.5, 1.0).sank);
}

TEST(SunkCrossing, TheMiddleOfTheLastRestAndTheCrossingCoveringBoth) {
  // re-drawn hard3d-06 (--seed 2000): rest to 18.467 s, then sinking; crossing at 19.042 s
  const Instant between = SunkCrossing(18.467, 19.042, 0.1);
  EXPECT_NEAR(between.t_s - between.uncertainty_s, 18.467, 1e-9);
  EXPECT_NEAR(between.t_s + between.uncertainty_s, 19.142, 1e-9);  // the crossing's own +-0.1 s
  // an uncertainty reaching back beyond the rest frame: the crossing's own interval
  const Instant wide = SunkCrossing(18.467, 19.042, 0.8);
  EXPECT_NEAR(wide.t_s, 19.042, 1e-9);
  EXPECT_NEAR(wide.uncertainty_s, 0.8, 1e-9);
}

TEST(LevelStep, MediansEitherSideOfTheKeyIgnoringUnmeasuredFrames) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> curve = {1, 1, 5, 1, 2, 2, nan, 9, 2};
  EXPECT_EQ(LevelStep(curve, 4, 4), 1.0);  // median {2, 2, 9, 2} - median {1, 1, 5, 1}
  EXPECT_EQ(LevelStep(std::vector<double>(4, nan), 2, 2), 0.0);
}

TEST(ResetsADrift, AKeyFrameUndoingItsPredictedFramesDriftButNotANewLevel) {
  // key frames at 0, 20 and 40 (hard3d-07, --seed 21000 --led-on-spread 1: the curve held
  // 0.55 px from one key frame, crept to 0.84 in codec steps and fell to 0.3 at the next)
  std::vector<HeightSample> samples = Samples(60);
  samples[0].keyframe = samples[20].keyframe = samples[40].keyframe = true;
  std::vector<double> drift(60, 0.55);
  for (size_t f = 30; f < 33; ++f) drift[f] = 0.74;
  for (size_t f = 33; f < 40; ++f) drift[f] = 0.84;
  for (size_t f = 40; f < 60; ++f) drift[f] = 0.3;
  const double reset = LevelStep(drift, 40, 5);
  EXPECT_NEAR(reset, -0.54, 1e-12);
  EXPECT_TRUE(ResetsADrift(samples, drift, 40, reset, 5));
  // the same step after a stretch that held its level: a new picture quality
  std::vector<double> held(60, 0.84);
  for (size_t f = 40; f < 60; ++f) held[f] = 0.3;
  EXPECT_FALSE(ResetsADrift(samples, held, 40, LevelStep(held, 40, 5), 5));
  // a drift under half the step, or the step's way, resets nothing
  std::vector<double> small = held;
  for (size_t f = 20; f < 30; ++f) small[f] = 0.7;
  EXPECT_FALSE(ResetsADrift(samples, small, 40, LevelStep(small, 40, 5), 5));
  std::vector<double> along = drift;
  for (size_t f = 40; f < 60; ++f) along[f] = 1.3;
  EXPECT_FALSE(ResetsADrift(samples, along, 40, LevelStep(along, 40, 5), 5));
  // no earlier key frame far enough back to measure from
  samples[20].keyframe = false;
  samples[0].keyframe = false;
  EXPECT_FALSE(ResetsADrift(samples, drift, 40, reset, 5));
  samples[35].keyframe = true;
  EXPECT_FALSE(ResetsADrift(samples, drift, 40, reset, 5));
}

TEST(KeyframeNoise, TheKeyFramesScatterWhereTheFramesBetweenCopyAStillPicture) {
  // 60 frames, a key frame every 10: the frames between copy their key frame exactly (no
  // noise in any window between), the key frames at 0, 0.2, -0.1, 0.1, 0.1, 0.3 px: their
  // changes 0.2, 0.3, 0.2, 0, 0.2 have the median 0.2
  const std::vector<double> keys = {0, 0.2, -0.1, 0.1, 0.1, 0.3};
  std::vector<double> height(60);
  std::vector<HeightSample> samples = Samples(height.size());
  for (size_t f = 0; f < height.size(); ++f) {
    height[f] = keys[f / 10];
    samples[f].keyframe = f % 10 == 0;
  }
  EXPECT_NEAR(KeyframeNoisePx(samples, height, 0, 60), 1.4826 * 0.2 / std::sqrt(2.0), 1e-12);
  // the window [0, 40) holds 4 key frames: 3 changes are too few
  EXPECT_EQ(KeyframeNoisePx(samples, height, 0, 40), 0.0);
  // an unmeasured key frame is skipped: changes 0.2, 0.1 (0.2 to 0.1), 0, 0.2: median 0.15
  height[20] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NEAR(KeyframeNoisePx(samples, height, 0, 60), 1.4826 * 0.15 / std::sqrt(2.0), 1e-12);
  // an intra-only clip: every frame a key frame, the copies' zero changes dominate
  for (HeightSample& sample : samples) sample.keyframe = true;
  EXPECT_EQ(KeyframeNoisePx(samples, height, 0, 60), 0.0);
}

TEST(SurelyAbove, TheFirstSustainedCrossingOfTheLevelPlusTheMargin) {
  // a two-frame excursion to 0.9 at 2..3, back to rest, then a rise: 0.5 at 6, 0.8 at 7,
  // 1.0 from 8 on
  const std::vector<double> height = {0, 0, 0.9, 0.9, 0, 0, 0.5, 0.8, 1.0, 1.0, 1.1};
  const std::vector<HeightSample> samples = Samples(height.size());
  EXPECT_NEAR(SurelyAboveS(samples, height, 0, 10, 0.5, 0.0), 6 * kFrameS, 1e-12);
  EXPECT_NEAR(SurelyAboveS(samples, height, 0, 10, 0.5, 0.3), 7 * kFrameS, 1e-12);
  // not the excursion: two frames are no sustained crossing
  EXPECT_NEAR(SurelyAboveS(samples, height, 0, 10, 0.5, 0.4), 8 * kFrameS, 1e-12);
  EXPECT_TRUE(std::isnan(SurelyAboveS(samples, height, 0, 10, 0.5, 0.7)));  // never
}

// A patch at rest, then rising 1 px a frame from frame `from`.
std::vector<double> RisingFrom(size_t from, size_t frames) {
  std::vector<double> curve(frames, 0.0);
  for (size_t f = from; f < frames; ++f) curve[f] = static_cast<double>(f - from);
  return curve;
}

TEST(PatchCrossingSpreadS, RobustSigmaOfThePatchesOwnCrossings) {
  // crossing 2.5 px at frames 12.5, 14.5 and 17.5: their median 14.5, deviations 2, 0 and
  // 3 frames, median 2 frames
  const std::vector<std::vector<double>> curves = {RisingFrom(10, 40), RisingFrom(12, 40),
                                                   RisingFrom(15, 40)};
  EXPECT_NEAR(PatchCrossingSpreadS(Samples(40), curves, 0, 2.5, 5, 3), 1.4826 * 2 * kFrameS, 1e-9);
}

TEST(PatchCrossingSpreadS, SpikesDoNotCrossLostFramesAreSkippedAndTwoPatchesGiveNone) {
  std::vector<double> spiky = RisingFrom(12, 40);
  spiky[5] = 9.0;  // one frame above: no crossing there
  std::vector<double> lost = RisingFrom(15, 40);
  lost[17] = lost[18] = kNaN;  // unmeasured frames neither break nor make a run
  const std::vector<std::vector<double>> curves = {RisingFrom(10, 40), spiky, lost};
  EXPECT_NEAR(PatchCrossingSpreadS(Samples(40), curves, 0, 2.5, 5, 3), 1.4826 * 2 * kFrameS, 1e-9);
  const std::vector<std::vector<double>> two = {RisingFrom(10, 40), RisingFrom(15, 40)};
  EXPECT_EQ(PatchCrossingSpreadS(Samples(40), two, 0, 2.5, 5, 3), 0.0);
}

TEST(PatchCrossingSpreadS, APatchLostSoonAfterItsCrossingCountsAndOneNeverCrossingDoesNot) {
  // the fast patch is lost 3 frames after crossing (short_frames 3), the fourth never rises:
  // crossings 12.5, 14.5, 17.5 as above
  std::vector<double> fast = RisingFrom(10, 40);
  std::fill(fast.begin() + 16, fast.end(), kNaN);
  const std::vector<std::vector<double>> curves = {fast, RisingFrom(12, 40), RisingFrom(15, 40),
                                                   std::vector<double>(40, 0.0)};
  EXPECT_NEAR(PatchCrossingSpreadS(Samples(40), curves, 0, 2.5, 10, 3), 1.4826 * 2 * kFrameS, 1e-9);
  // with a longer short run asked for, the fast patch does not count: two left
  EXPECT_EQ(PatchCrossingSpreadS(Samples(40), curves, 0, 2.5, 10, 5), 0.0);
}

}  // namespace
}  // namespace liftoff::video::internal
