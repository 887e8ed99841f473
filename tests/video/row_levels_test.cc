#include "row_levels.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "liftoff/core/robust_stats.h"

namespace liftoff::video::internal {
namespace {

// A textured picture (levels 40 .. 200) and the same under bands: row r times
// 1 + a sin(2 pi r / period + phase).
cv::Mat Texture(cv::Size size) {
  cv::Mat picture(size, CV_32F);
  cv::RNG rng(5);
  rng.fill(picture, cv::RNG::UNIFORM, 40.0, 200.0);
  return picture;
}

cv::Mat Banded(const cv::Mat& picture, double amplitude, double period_rows, double phase) {
  cv::Mat banded = picture.clone();
  for (int r = 0; r < banded.rows; ++r) {
    banded.row(r) *= 1.0 + amplitude * std::sin(2 * CV_PI * r / period_rows + phase);
  }
  return banded;
}

TEST(RowGains, MeasuresBandsAgainstTheReferenceAndLevelsThemAway) {
  const cv::Mat reference = Texture(cv::Size(80, 64));
  cv::Mat frame = Banded(reference, 0.3, 150.0, 0.4);
  const std::vector<float> gains = RowGains(frame, reference, 3, 10.0f);
  ASSERT_EQ(gains.size(), 64u);
  // relative to their median: the band's shape, its level gone
  std::vector<double> band;
  for (int r = 0; r < 64; ++r) band.push_back(1.0 + 0.3 * std::sin(2 * CV_PI * r / 150.0 + 0.4));
  const double middle = MedianOf(band);
  for (int r = 3; r < 61; ++r) {  // (a running mean of 7 rows bends a slow band little)
    EXPECT_NEAR(gains[static_cast<size_t>(r)], band[static_cast<size_t>(r)] / middle, 0.01) << r;
  }
  EXPECT_GT(GainRange(gains), 0.2f);
  LevelRows(frame, gains);
  // levelled: every row within a percent of the reference's times one level
  const double level = cv::sum(frame)[0] / cv::sum(reference)[0];
  for (int r = 3; r < 61; ++r) {
    EXPECT_NEAR(cv::sum(frame.row(r))[0] / cv::sum(reference.row(r))[0], level, 0.01 * level) << r;
  }
}

TEST(RowGains, AnObjectOverAFewColumnsAndAGlobalGainAreNoBand) {
  const cv::Mat reference = Texture(cv::Size(80, 64));
  cv::Mat frame = reference * 1.4;                // a global shutter's flicker: one gain
  frame(cv::Rect(20, 10, 25, 30)).setTo(250.0f);  // a bright object over 25 of 80 columns
  const std::vector<float> gains = RowGains(frame, reference, 3, 10.0f);
  ASSERT_EQ(gains.size(), 64u);
  EXPECT_LT(GainRange(gains), 0.03f);
}

TEST(RowGains, DarkRowsTakeTheNearestMeasuredRowsGain) {
  const cv::Mat reference = Texture(cv::Size(40, 20));
  reference.rowRange(0, 5).setTo(2.0f);  // below the level: not measured
  const cv::Mat frame = Banded(reference, 0.2, 40.0, 0.0);
  const std::vector<float> gains = RowGains(frame, reference, 0, 10.0f);
  ASSERT_EQ(gains.size(), 20u);
  for (int r = 0; r < 5; ++r) EXPECT_EQ(gains[static_cast<size_t>(r)], gains[5]) << r;
  const cv::Mat dark(cv::Size(40, 20), CV_32F, cv::Scalar(1.0f));
  EXPECT_TRUE(RowGains(dark, dark, 3, 10.0f).empty());
}

}  // namespace
}  // namespace liftoff::video::internal
