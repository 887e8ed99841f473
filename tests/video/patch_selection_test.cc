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
  // shaped like hard3d-08's (--seed 0): two patches on the foot at rest, then rising 3 px a
  // frame and lost after 4 frames of it (a fast foot outruns them); a patch that slipped
  // 30 px up an edge early and stayed there. Against their median curve the slipped patch's
  // gain is 30 * 30 / 270 = 3.3 and the foot's 1, under half the upper quartile (2.2): the
  // gain test alone keeps the slipped patch alone.
  const Curves curves{{FootPatch(1.0, 0.1, 6), FootPatch(1.0, 0.1, 6), SlippedPatch(30.0, 6)}};
  EXPECT_EQ(MovingWithTheOthers({0, 1, 2}, 0, kFrames, curves), (std::vector<size_t>{0, 1}));
}

TEST(MovingWithTheOthers, APatchOnShadowMovingByAFractionIsNoFootAndNoiseLeavesNoneOut) {
  // three foot patches, one of them noisy (1.5 px: under the floor, however much noisier
  // than the others), and a patch on the foot's shadow moving by a fifth of its rise
  const Curves curves{{FootPatch(1.0, 0.1, 0), FootPatch(1.0, 1.5, 0), FootPatch(1.1, 0.1, 0),
                       FootPatch(0.2, 0.1, 0)}};
  EXPECT_EQ(MovingWithTheOthers({0, 1, 2, 3}, 0, kFrames, curves), (std::vector<size_t>{0, 1, 2}));
}

TEST(MedianCurve, NaNWhereTooFewPatchesAreMeasured) {
  const Curves curves{{{1.0, kNaN, kNaN}, {3.0, 2.0, kNaN}, {5.0, 4.0, 7.0}}};
  const std::vector<double> curve = MedianCurve(3, {0, 1, 2}, 2, curves);
  EXPECT_DOUBLE_EQ(curve[0], 3.0);
  EXPECT_DOUBLE_EQ(curve[1], 3.0);  // the median of 2 and 4
  EXPECT_TRUE(std::isnan(curve[2]));
}

}  // namespace
}  // namespace liftoff::video::internal
