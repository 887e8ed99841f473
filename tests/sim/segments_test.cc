// Closest points of two segments (src/sim/segments.h), the engine's rod-rod contacts:
// cases with known answers (crossing, clamped at the ends, parallel, degenerate), and on
// seeded random segments a distance no larger than a fine search finds.
#include "segments.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace liftoff::sim::internal {
namespace {

void ExpectNear(const Vec3& actual, const Vec3& expected) {
  EXPECT_LT((actual - expected).norm(), 1e-12)
      << actual.transpose() << " vs " << expected.transpose();
}

// distance from x to the segment p-q
double DistanceToSegment(const Vec3& x, const Vec3& p, const Vec3& q) {
  const Vec3 d = q - p;
  const double length2 = d.squaredNorm();
  const double t = length2 > 0 ? std::clamp((x - p).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (p + t * d - x).norm();
}

// whether x lies on the segment p-q
bool OnSegment(const Vec3& x, const Vec3& p, const Vec3& q) {
  return DistanceToSegment(x, p, q) < 1e-9;
}

TEST(ClosestPointsOfSegments, CrossingSegments) {
  Vec3 c1, c2;
  ClosestPointsOfSegments(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 1), Vec3(0, 1, 1), c1, c2);
  ExpectNear(c1, Vec3(0, 0, 0));
  ExpectNear(c2, Vec3(0, 0, 1));
}

TEST(ClosestPointsOfSegments, ClampsToTheEnds) {
  Vec3 c1, c2;
  ClosestPointsOfSegments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 1, 0), Vec3(3, 5, 0), c1, c2);
  ExpectNear(c1, Vec3(1, 0, 0));
  ExpectNear(c2, Vec3(2, 1, 0));
  // the second segment's interior against the first's end
  ClosestPointsOfSegments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, -1, 0), Vec3(3, 1, 0), c1, c2);
  ExpectNear(c1, Vec3(1, 0, 0));
  ExpectNear(c2, Vec3(3, 0, 0));
}

TEST(ClosestPointsOfSegments, ParallelSegmentsGiveAPairAtTheirDistance) {
  const Vec3 p1(0, 0, 0), q1(2, 0, 0), p2(1, 1, 0), q2(3, 1, 0);
  Vec3 c1, c2;
  ClosestPointsOfSegments(p1, q1, p2, q2, c1, c2);
  EXPECT_NEAR((c2 - c1).norm(), 1.0, 1e-12);
  EXPECT_TRUE(OnSegment(c1, p1, q1));
  EXPECT_TRUE(OnSegment(c2, p2, q2));
}

TEST(ClosestPointsOfSegments, HandlesSegmentsOfZeroLength) {
  Vec3 c1, c2;
  ClosestPointsOfSegments(Vec3(0.5, 2, 0), Vec3(0.5, 2, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), c1, c2);
  ExpectNear(c1, Vec3(0.5, 2, 0));
  ExpectNear(c2, Vec3(0.5, 0, 0));
  ClosestPointsOfSegments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, 1, 0), Vec3(3, 1, 0), c1, c2);
  ExpectNear(c1, Vec3(1, 0, 0));
  ExpectNear(c2, Vec3(3, 1, 0));
  ClosestPointsOfSegments(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(4, 5, 6), c1, c2);
  ExpectNear(c1, Vec3(1, 2, 3));
  ExpectNear(c2, Vec3(4, 5, 6));
}

// a fine search over the first segment, the second's closest point exact
TEST(ClosestPointsOfSegments, FindsTheLeastDistanceOnRandomSegments) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  const auto point = [&] { return Vec3(coordinate(rng), coordinate(rng), coordinate(rng)); };
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 p1 = point(), q1 = point(), p2 = point(), q2 = point();
    Vec3 c1, c2;
    ClosestPointsOfSegments(p1, q1, p2, q2, c1, c2);
    ASSERT_TRUE(OnSegment(c1, p1, q1)) << trial;
    ASSERT_TRUE(OnSegment(c2, p2, q2)) << trial;
    double least = std::numeric_limits<double>::infinity();
    constexpr int kSteps = 20000;
    for (int i = 0; i <= kSteps; ++i) {
      const Vec3 x = p1 + (static_cast<double>(i) / kSteps) * (q1 - p1);
      least = std::min(least, DistanceToSegment(x, p2, q2));
    }
    EXPECT_LE((c2 - c1).norm(), least + 1e-12) << trial;
    EXPECT_GE((c2 - c1).norm(), least - 1e-3) << trial;
  }
}

}  // namespace
}  // namespace liftoff::sim::internal
