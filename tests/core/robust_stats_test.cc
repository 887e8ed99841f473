// The robust statistics (liftoff/core/robust_stats.h) against sorting, on seeded random
// samples of odd and even sizes, against analytic cases, and on the cases that take a
// branch of their own.
#include "liftoff/core/robust_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace liftoff {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

double SortedMedian(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

TEST(MedianOf, MatchesSortingOnRandomSamples) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> value(-100.0, 100.0);
  for (size_t n = 1; n <= 40; ++n) {
    std::vector<double> values(n);
    for (double& v : values) v = value(rng);
    const std::vector<double> original = values;
    EXPECT_EQ(MedianOf(values), SortedMedian(values)) << n;
    EXPECT_EQ(values, original) << "the vector overload keeps the caller's order";
    EXPECT_EQ(MedianOf(values.data(), static_cast<std::ptrdiff_t>(n)), SortedMedian(original)) << n;
  }
}

TEST(MedianOf, AveragesTheMiddleTwoAndHandlesEdges) {
  EXPECT_EQ(MedianOf(std::vector<double>{}), 0.0);
  EXPECT_EQ(MedianOf(std::vector<double>{4.0, 1.0}), 2.5);
  EXPECT_EQ(MedianOf(std::vector<double>{3.0, 1.0, 2.0, 10.0}), 2.5);
  EXPECT_EQ(MedianOf(std::vector<float>{5.0f, 5.0f, 1.0f}), 5.0f);
  // integers: the mean of the middle two rounds toward zero
  EXPECT_EQ(MedianOf(std::vector<int64_t>{1, 2, 3, 4}), 2);
  std::vector<double> part = {9.0, 1.0, 5.0, -7.0, 100.0};
  EXPECT_EQ(MedianOf(part.data(), 3), 5.0) << "only the first `count` values count";
}

TEST(SuccessiveDifferenceSigma, TheMedianChangeScaledToAGaussiansSigma) {
  // changes 1, 1, 3, 1: median 1
  EXPECT_NEAR(SuccessiveDifferenceSigma({0, 1, 0, 3, 2}), kMadToSigma / std::sqrt(2.0), 1e-12);
  // a steady drift of 0.5 a step: only its step counts, not its 1.5 course
  EXPECT_EQ(SuccessiveDifferenceSigma({0, 0.5, 1.0, 1.5}), kMadToSigma * 0.5 / std::sqrt(2.0));
  EXPECT_EQ(SuccessiveDifferenceSigma({7}), 0.0);
  EXPECT_EQ(SuccessiveDifferenceSigma({}), 0.0);
  // unit Gaussian noise: within 5 % with 20,000 samples
  std::mt19937 rng(5);
  std::normal_distribution<double> gaussian;
  std::vector<double> noise(20000);
  for (double& value : noise) value = gaussian(rng);
  EXPECT_NEAR(SuccessiveDifferenceSigma(noise), 1.0, 0.05);
}

TEST(UpperMedianOf, TheUpperMiddleForAnEvenCount) {
  EXPECT_EQ(UpperMedianOf({}), 0.0);
  EXPECT_EQ(UpperMedianOf({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(UpperMedianOf({4.0, 1.0, 3.0, 2.0}), 3.0);
}

TEST(FiniteMedian, SkipsNaNAndIsNaNForNone) {
  std::vector<double> values = {3.0, kNaN, 1.0, 2.0, -kInf};
  EXPECT_EQ(FiniteMedian(values), 2.0);
  EXPECT_EQ(values.size(), 3u) << "the non-finite values are dropped";
  std::vector<double> none = {kNaN, kInf};
  EXPECT_TRUE(std::isnan(FiniteMedian(none)));
}

TEST(FiniteQuantile, LinearBetweenOrderStatisticsSkippingNaN) {
  std::vector<double> values = {4.0, kNaN, 1.0, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(FiniteQuantile(values, 0.75), 3.25);
  EXPECT_DOUBLE_EQ(FiniteQuantile(values, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(FiniteQuantile(values, 1.0), 4.0);
  std::vector<double> one = {7.0};
  EXPECT_DOUBLE_EQ(FiniteQuantile(one, 0.3), 7.0);
  std::vector<double> none = {kNaN};
  EXPECT_TRUE(std::isnan(FiniteQuantile(none, 0.5)));
}

TEST(OrderQuantileOf, TheOrderStatisticRoundedDown) {
  std::vector<double> values = {5.0, 1.0, 4.0, 2.0, 3.0};
  EXPECT_EQ(OrderQuantileOf(values, 0.0), 1.0);
  EXPECT_EQ(OrderQuantileOf(values, 0.6), 3.0);  // position floor(0.6 * 4) = 2
  EXPECT_EQ(OrderQuantileOf(values, 0.99), 4.0);
  EXPECT_EQ(OrderQuantileOf(values, 1.0), 5.0);
}

TEST(MadSigma, TheMedianAbsoluteDeviationScaledToAGaussiansSigma) {
  // median 3; deviations 2, 1, 0, 1, 97: median 1
  EXPECT_DOUBLE_EQ(MadSigma({1.0, 2.0, 3.0, 4.0, 100.0}), kMadToSigma);
  EXPECT_DOUBLE_EQ(MadSigma({kNaN, 5.0, 5.0}), 0.0);
  EXPECT_EQ(MadSigma({}), 0.0);
  EXPECT_EQ(MadSigma({kNaN}), 0.0);
  // Gaussian noise of sigma 2 about 10: within 5 % with 20,000 samples, and an outlier
  // fraction of 5 % moves it little
  std::mt19937 rng(11);
  std::normal_distribution<double> gaussian(10.0, 2.0);
  std::vector<double> noise(20000);
  for (double& value : noise) value = gaussian(rng);
  EXPECT_NEAR(MadSigma(noise), 2.0, 0.1);
  for (size_t i = 0; i < noise.size(); i += 20) noise[i] = 1e6;
  EXPECT_NEAR(MadSigma(noise), 2.0, 0.25);
}

}  // namespace
}  // namespace liftoff
