#include "liftoff/stats/plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <regex>
#include <string>
#include <vector>

namespace liftoff::stats {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

ResultsTable TwoFootTable() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<TrialValue> trials = {
      {"A1", Foot::kA, 0.40, 0.39, 0.41, ""},
      {"A2", Foot::kA, 0.50, 0.49, 0.51, ""},
      {"A3", Foot::kA, nan, nan, nan, "no value"},
      {"C1", Foot::kC, 0.45, nan, nan, ""},
  };
  SimResults sim;
  sim.source = "sim.json";
  sim.ranges[Foot::kA] = {.min_rad = 0.30, .max_rad = 0.35, .n_runs = 5, .from_summary = false};
  return BuildResultsTable(trials, &sim, "laika-2018 <test>", "linear");
}

// Vertical pixel of a value on the fixed axis used below: plot area rows 50 .. 350
// (height 420 - 70), axis 0.2 .. 0.6 rad.
double ExpectedY(double rad) { return 350.0 - (rad - 0.2) / 0.4 * 300.0; }

std::vector<double> CircleRows(const std::string& svg) {
  std::vector<double> rows;
  const std::regex circle(R"re(<circle cx="[0-9.]+" cy="([0-9.]+)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator();
       ++it) {
    rows.push_back(std::stod((*it)[1]));
  }
  return rows;
}

TEST(ResultsPlot, DrawsEachFiniteTrialAtItsValue) {
  const auto svg = RenderResultsPlotSvg(TwoFootTable(), {.min_rad = 0.2, .max_rad = 0.6});
  ASSERT_TRUE(svg.ok()) << svg.status().ToString();
  const std::vector<double> rows = CircleRows(*svg);
  ASSERT_EQ(rows.size(), 3u);  // A3 has no value
  EXPECT_NEAR(rows[0], ExpectedY(0.40), 0.06);
  EXPECT_NEAR(rows[1], ExpectedY(0.50), 0.06);
  EXPECT_NEAR(rows[2], ExpectedY(0.45), 0.06);
  EXPECT_THAT(*svg, HasSubstr("<title>A1: 0.400 rad</title>"));
}

TEST(ResultsPlot, SimRangeIsABandFromMinToMax) {
  const auto svg = RenderResultsPlotSvg(TwoFootTable(), {.min_rad = 0.2, .max_rad = 0.6});
  ASSERT_TRUE(svg.ok());
  const std::regex band(R"re(<rect x="[0-9.]+" y="([0-9.]+)" width="24" height="([0-9.]+)")re");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(*svg, match, band));
  EXPECT_NEAR(std::stod(match[1]), ExpectedY(0.35), 0.06);
  EXPECT_NEAR(std::stod(match[1]) + std::stod(match[2]), ExpectedY(0.30), 0.11);
  EXPECT_THAT(*svg, HasSubstr("sim A: 0.300 .. 0.350 rad"));
}

TEST(ResultsPlot, CaptionNamesCalibrationAndRuleEscaped) {
  const auto svg = RenderResultsPlotSvg(TwoFootTable());
  ASSERT_TRUE(svg.ok());
  EXPECT_THAT(*svg, HasSubstr("calibration: laika-2018 &lt;test&gt;; lookup: linear"));
  EXPECT_THAT(*svg, Not(HasSubstr("<test>")));
  EXPECT_THAT(*svg, HasSubstr("</svg>"));
}

TEST(ResultsPlot, FittedAxisHoldsEveryValue) {
  const auto svg = RenderResultsPlotSvg(TwoFootTable());
  ASSERT_TRUE(svg.ok());
  for (double row : CircleRows(*svg)) {
    EXPECT_GE(row, 50.0);
    EXPECT_LE(row, 350.0);
  }
  // fitted: 0.30 .. 0.51 rounded out to 0.25 .. 0.60
  EXPECT_THAT(*svg, HasSubstr(">0.25</text>"));
  EXPECT_THAT(*svg, HasSubstr(">0.60</text>"));
}

TEST(ResultsPlot, RejectsBadOptions) {
  const auto small = RenderResultsPlotSvg(TwoFootTable(), {.width_px = 10});
  ASSERT_FALSE(small.ok());
  EXPECT_THAT(small.status().message(), HasSubstr("plot size"));
  const auto inverted = RenderResultsPlotSvg(TwoFootTable(), {.min_rad = 0.6, .max_rad = 0.2});
  ASSERT_FALSE(inverted.ok());
  EXPECT_THAT(inverted.status().message(), HasSubstr("min_rad < max_rad"));
}

TEST(ResultsPlot, SameTableGivesTheSameBytes) {
  EXPECT_EQ(RenderResultsPlotSvg(TwoFootTable()).value(),
            RenderResultsPlotSvg(TwoFootTable()).value());
}

}  // namespace
}  // namespace liftoff::stats
