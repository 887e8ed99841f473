// The height curve's kernels (src/video/height_curve.h) on hand-made curves whose answers
// follow by hand.
#include "height_curve.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace liftoff::video::internal {
namespace {

constexpr double kFrameS = 0.04;  // 25 fps

std::vector<HeightSample> Samples(size_t count) {
  std::vector<HeightSample> samples(count);
  for (size_t i = 0; i < count; ++i) {
    samples[i].frame_index = static_cast<int64_t>(i);
    samples[i].t_ns = static_cast<int64_t>(std::llround(static_cast<double>(i) * kFrameS * 1e9));
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

}  // namespace
}  // namespace liftoff::video::internal
