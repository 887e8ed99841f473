// The foot's patch selection (src/video/patch_selection.h) on hand-made patch curves whose
// answers follow by hand.
#include "patch_selection.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace liftoff::video::internal {
namespace {

constexpr size_t kFrames = 200;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// curves[p][f]: patch p's rise at frame f, px
struct Curves {
  std::vector<std::vector<double>> rise;
  double operator()(size_t f, size_t p) const { return rise[p][f]; }
};

// At rest (a small alternating wobble of `wobble_px`), rising 3 px a frame over the last
// 10 frames times `gain`; lost (NaN) over the last `lost` frames.
std::vector<double> FootPatch(double gain, double wobble_px, size_t lost) {
  std::vector<double> rise(kFrames);
  for (size_t f = 0; f < kFrames; ++f) {
    const double lift = f + 10 >= kFrames ? 3.0 * static_cast<double>(f + 11 - kFrames) : 0.0;
    rise[f] = gain * lift + ((f % 2 == 0) ? wobble_px : -wobble_px);
    if (f + lost >= kFrames) rise[f] = kNaN;
  }
  return rise;
}

// Slipped `step_px` up at frame 20 and stayed there; lost over the last `lost` frames.
std::vector<double> SlippedPatch(double step_px, size_t lost) {
  std::vector<double> rise(kFrames, 0.0);
  for (size_t f = 20; f < kFrames; ++f) rise[f] = f + lost >= kFrames ? kNaN : step_px;
  return rise;
}

TEST(MovingWithTheOthers, APatchThatSlippedEarlyAndStayedHighIsNoFoot) {
  // shaped like hard3d-08's (--seed 0): two patches on the foot at rest, then rising 30 px
  // over the last 10 frames and lost; a patch that slipped 30 px up an edge early and
  // stayed there
  // the slipped patch sits where the foot ends: its offset times the foot's short rise gives
  // it a gain of about 4, which put both foot patches under half the upper quartile
  const Curves curves{{FootPatch(1.0, 0.1, 3), FootPatch(1.0, 0.15, 3), SlippedPatch(30.0, 5)}};
  EXPECT_EQ(MovingWithTheOthers({0, 1, 2}, 0, kFrames, curves), (std::vector<size_t>{0, 1}));
}

TEST(MovingWithTheOthers, APatchOnShadowMovingByAFractionIsNoFootAndNoiseLeavesNoneOut) {
  // three foot patches, one of them noisy (1.5 px: under the floor, however much noisier
  // than the others), and a patch on the foot's shadow moving by a fifth of its rise
  const Curves curves{{FootPatch(1.0, 0.1, 0), FootPatch(1.0, 1.5, 0), FootPatch(1.1, 0.1, 0),
                       FootPatch(0.2, 0.1, 0)}};
  EXPECT_EQ(MovingWithTheOthers({0, 1, 2, 3}, 0, kFrames, curves), (std::vector<size_t>{0, 1, 2}));
}

// 10 frames a second; a patch at rest, then rising 1 px a frame from frame `from`.
std::vector<double> RisingFrom(size_t from, size_t frames) {
  std::vector<double> curve(frames, 0.0);
  for (size_t f = from; f < frames; ++f) curve[f] = static_cast<double>(f - from);
  return curve;
}

std::vector<double> Times(size_t frames) {
  std::vector<double> t_s(frames);
  for (size_t f = 0; f < frames; ++f) t_s[f] = 0.1 * static_cast<double>(f);
  return t_s;
}

TEST(PatchCrossingSpreadS, RobustSigmaOfThePatchesOwnCrossingsAboutTheFoundOne) {
  // crossing 2.5 px at frames 12.5, 14.5 and 17.5 (1.25, 1.45, 1.75 s); found at 1.45 s:
  // distances 0.2, 0 and 0.3 s, median 0.2 s
  const std::vector<std::vector<double>> curves = {RisingFrom(10, 40), RisingFrom(12, 40),
                                                   RisingFrom(15, 40)};
  EXPECT_NEAR(PatchCrossingSpreadS(Times(40), curves, 0, 2.5, 1.45, 5), 1.4826 * 0.2, 1e-9);
}

TEST(PatchCrossingSpreadS, OneFrameSpikesAndLostFramesDoNotCrossAndTwoPatchesGiveNone) {
  std::vector<double> spiky = RisingFrom(12, 40);
  spiky[5] = 9.0;  // one frame above: no crossing there
  std::vector<double> lost = RisingFrom(15, 40);
  lost[17] = lost[18] = kNaN;  // unmeasured frames neither break nor make a run
  const std::vector<std::vector<double>> curves = {RisingFrom(10, 40), spiky, lost};
  EXPECT_NEAR(PatchCrossingSpreadS(Times(40), curves, 0, 2.5, 1.45, 5), 1.4826 * 0.2, 1e-9);
  const std::vector<std::vector<double>> two = {RisingFrom(10, 40), RisingFrom(15, 40)};
  EXPECT_EQ(PatchCrossingSpreadS(Times(40), two, 0, 2.5, 1.45, 5), 0.0);
}

TEST(MedianCurve, NaNWhereTooFewPatchesAreMeasured) {
  const Curves curves{{{1.0, kNaN, kNaN}, {3.0, 2.0, kNaN}, {5.0, 4.0, 7.0}}};
  const std::vector<double> curve = MedianCurve(3, {0, 1, 2}, 2, curves);
  EXPECT_DOUBLE_EQ(curve[0], 3.0);
  EXPECT_DOUBLE_EQ(curve[1], 3.0);  // the median of 2 and 4
  EXPECT_TRUE(std::isnan(curve[2]));
}

TEST(FiniteQuantile, LinearBetweenOrderStatisticsSkippingNaN) {
  std::vector<double> values = {4.0, kNaN, 1.0, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(FiniteQuantile(values, 0.75), 3.25);
  std::vector<double> none = {kNaN};
  EXPECT_TRUE(std::isnan(FiniteQuantile(none, 0.5)));
}

}  // namespace
}  // namespace liftoff::video::internal
