#include "liftoff/stats/statistics.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace liftoff::stats {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Foot A of the 2018 hardware, tests 1..5, sample-and-hold lookup (laika-model.md section 7).
const std::vector<double> kFootA2018 = {0.460, 0.385, 0.432, 0.502, 0.455};

// Student's t quantiles from printed tables.
TEST(StudentTQuantile, MatchesPublishedTableValues) {
  EXPECT_NEAR(StudentTQuantile(0.975, 4), 2.776445105, 1e-8);
  EXPECT_NEAR(StudentTQuantile(0.975, 1), 12.70620474, 1e-7);
  EXPECT_NEAR(StudentTQuantile(0.95, 10), 1.812461123, 1e-8);
  EXPECT_NEAR(StudentTQuantile(0.995, 30), 2.749995654, 1e-8);
  EXPECT_NEAR(StudentTQuantile(0.95, 4), 2.131846786, 1e-8);
}

TEST(StudentTQuantile, IsSymmetricAboutZero) {
  EXPECT_NEAR(StudentTQuantile(0.025, 4), -2.776445105, 1e-8);
  EXPECT_NEAR(StudentTQuantile(0.5, 7), 0.0, 1e-12);
}

TEST(StudentTQuantile, IsNaNOutsideItsDomain) {
  EXPECT_TRUE(std::isnan(StudentTQuantile(0.0, 4)));
  EXPECT_TRUE(std::isnan(StudentTQuantile(1.0, 4)));
  EXPECT_TRUE(std::isnan(StudentTQuantile(1.5, 4)));
  EXPECT_TRUE(std::isnan(StudentTQuantile(0.975, 0)));
  EXPECT_TRUE(std::isnan(StudentTQuantile(0.975, -3)));
  EXPECT_TRUE(std::isnan(StudentTQuantile(kNaN, 4)));
}

TEST(Summarize, FootA2018MatchesHandComputedValues) {
  const Summary summary = Summarize(kFootA2018);
  EXPECT_EQ(summary.n, 5);
  EXPECT_DOUBLE_EQ(summary.min, 0.385);
  EXPECT_DOUBLE_EQ(summary.max, 0.502);
  // sum 2.234 over 5
  EXPECT_NEAR(summary.mean, 0.4468, 1e-12);
  // squared deviations from 0.4468: 0.00017424 + 0.00381924 + 0.00021904 + 0.00304704
  // + 0.00006724 = 0.0073268, over n - 1 = 4
  const double stddev = std::sqrt(0.0073268 / 4.0);
  EXPECT_NEAR(summary.stddev, stddev, 1e-12);
  EXPECT_NEAR(summary.stddev, 0.042798, 1e-6);
  // sorted 0.385 0.432 0.455 0.460 0.502
  EXPECT_DOUBLE_EQ(summary.median, 0.455);
  // mean -/+ t(0.975, 4) sd / sqrt(5)
  const double half_width = 2.776445105 * stddev / std::sqrt(5.0);
  EXPECT_NEAR(summary.ci_low, 0.4468 - half_width, 1e-8);
  EXPECT_NEAR(summary.ci_high, 0.4468 + half_width, 1e-8);
  EXPECT_NEAR(summary.ci_low, 0.39366, 1e-5);
  EXPECT_NEAR(summary.ci_high, 0.49994, 1e-5);
  EXPECT_DOUBLE_EQ(summary.confidence, 0.95);
}

TEST(Summarize, OtherConfidenceLevelsUseTheirQuantile) {
  const Summary summary = Summarize(kFootA2018, 0.90);
  const double half_width = 2.131846786 * std::sqrt(0.0073268 / 4.0) / std::sqrt(5.0);
  EXPECT_NEAR(summary.ci_low, 0.4468 - half_width, 1e-8);
  EXPECT_NEAR(summary.ci_high, 0.4468 + half_width, 1e-8);
  EXPECT_DOUBLE_EQ(summary.confidence, 0.90);
}

TEST(Summarize, ConfidenceOutsideZeroToOneLeavesIntervalNaN) {
  for (double confidence : {0.0, 1.0, 1.2, -0.5}) {
    const Summary summary = Summarize(kFootA2018, confidence);
    EXPECT_TRUE(std::isnan(summary.ci_low)) << confidence;
    EXPECT_TRUE(std::isnan(summary.ci_high)) << confidence;
    EXPECT_NEAR(summary.mean, 0.4468, 1e-12);
  }
}

TEST(Summarize, MedianOfEvenCountIsMeanOfMiddlePair) {
  const std::vector<double> values = {0.3, 0.1, 0.4, 0.2};
  EXPECT_DOUBLE_EQ(Summarize(values).median, 0.25);
}

TEST(Summarize, EmptySampleIsAllNaN) {
  const Summary summary = Summarize(std::vector<double>{});
  EXPECT_EQ(summary.n, 0);
  for (double value : {summary.min, summary.max, summary.mean, summary.stddev, summary.median,
                       summary.ci_low, summary.ci_high}) {
    EXPECT_TRUE(std::isnan(value));
  }
  EXPECT_EQ(summary.Brief(), "n 0");
}

TEST(Summarize, SingleValueHasNoSpreadOrInterval) {
  const std::vector<double> values = {0.422};
  const Summary summary = Summarize(values);
  EXPECT_EQ(summary.n, 1);
  EXPECT_DOUBLE_EQ(summary.min, 0.422);
  EXPECT_DOUBLE_EQ(summary.max, 0.422);
  EXPECT_DOUBLE_EQ(summary.mean, 0.422);
  EXPECT_DOUBLE_EQ(summary.median, 0.422);
  EXPECT_TRUE(std::isnan(summary.stddev));
  EXPECT_TRUE(std::isnan(summary.ci_low));
  EXPECT_TRUE(std::isnan(summary.ci_high));
}

TEST(Summarize, SkipsNonFiniteValues) {
  const std::vector<double> values = {0.5, kNaN, 0.7, std::numeric_limits<double>::infinity()};
  const Summary summary = Summarize(values);
  EXPECT_EQ(summary.n, 2);
  EXPECT_NEAR(summary.mean, 0.6, 1e-12);
  // deviations 0.1 and -0.1: sqrt(0.02 / 1)
  EXPECT_NEAR(summary.stddev, std::sqrt(0.02), 1e-12);
  // t(0.975, 1) = 12.7062047, sd / sqrt(2) = 0.1
  EXPECT_NEAR(summary.ci_low, 0.6 - 1.270620474, 1e-8);
  EXPECT_NEAR(summary.ci_high, 0.6 + 1.270620474, 1e-8);
}

TEST(Summary, BriefNamesCountMeanSpreadAndInterval) {
  const std::string brief = Summarize(kFootA2018).Brief();
  EXPECT_EQ(
      brief,
      "n 5, mean 0.4468, sd 0.0428, median 0.455, 95 % CI [0.3937, 0.4999], range [0.385, 0.502]");
}

TEST(Summary, BriefOfOneValueLeavesOutSpread) {
  const std::vector<double> values = {0.422};
  EXPECT_EQ(Summarize(values).Brief(), "n 1, mean 0.422, median 0.422, range [0.422, 0.422]");
}

}  // namespace
}  // namespace liftoff::stats
