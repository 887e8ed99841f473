// The LED locator's cell sums (src/video/cell_sums.h), both paths, against OpenCV's
// cv::sum and cv::minMaxLoc over the same sampled rows, on seeded random images of even
// and odd sizes (the last cell column and row flush with the frame's edge) and on
// sub-images (a row stride wider than the picture).
#include "cell_sums.h"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace liftoff::video::internal {
namespace {

struct Expected {
  std::vector<float> sums;
  std::vector<uint8_t> peaks;
};

// Sum over channels and maximum channel of each cell's sampled rows, with OpenCV.
Expected Reference(const cv::Mat& bgr, const CellGrid& grid) {
  Expected expected;
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      double sum = 0.0, peak = 0.0;
      for (int y = 0; y < grid.cell_px; y += kCellRowStep) {
        const cv::Mat line =
            bgr(cv::Rect(grid.x0_px[static_cast<size_t>(column)],
                         grid.y0_px[static_cast<size_t>(row)] + y, grid.cell_px, 1));
        const cv::Scalar channel_sums = cv::sum(line);
        sum += channel_sums[0] + channel_sums[1] + channel_sums[2];
        double line_peak = 0.0;
        cv::minMaxLoc(line.reshape(1), nullptr, &line_peak);
        peak = std::max(peak, line_peak);
      }
      expected.sums.push_back(static_cast<float>(sum));
      expected.peaks.push_back(static_cast<uint8_t>(peak));
    }
  }
  return expected;
}

cv::Mat RandomImage(int width, int height, uint64_t seed) {
  cv::Mat image(height, width, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

void ExpectCellsMatch(const cv::Mat& bgr, int cell_px, int stride) {
  const CellGrid grid = CellGrid::Make(bgr.cols, bgr.rows, cell_px, stride);
  const Expected expected = Reference(bgr, grid);
  const auto cells = static_cast<size_t>(grid.cells());
  ASSERT_EQ(expected.sums.size(), cells);
  std::vector<float> sums(cells, -1.0f);
  std::vector<uint8_t> peaks(cells, 0);
  MeasureCells(bgr, grid, sums.data(), peaks.data());
  std::vector<float> plain_sums(cells, -1.0f);
  std::vector<uint8_t> plain_peaks(cells, 0);
  MeasureCellsPlain(bgr, grid, plain_sums.data(), plain_peaks.data());
  for (size_t i = 0; i < cells; ++i) {
    EXPECT_EQ(sums[i], expected.sums[i]) << bgr.cols << "x" << bgr.rows << " cell " << i;
    EXPECT_EQ(peaks[i], expected.peaks[i]) << bgr.cols << "x" << bgr.rows << " cell " << i;
    EXPECT_EQ(plain_sums[i], expected.sums[i]) << "plain, cell " << i;
    EXPECT_EQ(plain_peaks[i], expected.peaks[i]) << "plain, cell " << i;
  }
}

TEST(CellGrid, CoversTheFrameWithTheLastCellsFlushWithItsEdges) {
  const CellGrid grid = CellGrid::Make(101, 37, 16, 1);
  EXPECT_EQ(grid.columns, 7);
  EXPECT_EQ(grid.rows, 3);
  EXPECT_EQ(grid.x0_px.back(), 101 - 16);
  EXPECT_EQ(grid.y0_px.back(), 37 - 16);
  EXPECT_EQ(grid.x0_px[1], 16);
  EXPECT_EQ(grid.sampled_px_per_cell, 16 * 8);
  const CellGrid every_fourth = CellGrid::Make(640, 480, 16, 4);
  EXPECT_EQ(every_fourth.columns, 10);
  EXPECT_EQ(every_fourth.rows, 8);
  EXPECT_EQ(every_fourth.x0_px[1], 64);
}

// cell_px 16 and 32 take the SSE2 path (48 and 96 bytes a row), 8 and 5 the plain loop
TEST(MeasureCells, MatchesOpenCvOnRandomImages) {
  EXPECT_EQ(CellsUseSse2(CellGrid::Make(64, 64, 8, 1)), false);
  uint64_t seed = 1;
  for (const cv::Size size : {cv::Size(64, 48), cv::Size(101, 37), cv::Size(33, 65),
                              cv::Size(640, 360), cv::Size(17, 17)}) {
    for (const int cell_px : {5, 8, 16, 32}) {
      if (cell_px > size.width || cell_px > size.height) continue;
      for (const int stride : {1, 4}) {
        SCOPED_TRACE(testing::Message() << size << " cell " << cell_px << " stride " << stride);
        ExpectCellsMatch(RandomImage(size.width, size.height, seed++), cell_px, stride);
      }
    }
  }
}

// bright pixels at the cells' corners and on their last sampled row; unsampled (odd)
// rows never count
TEST(MeasureCells, SeesCornersAndSkipsUnsampledRows) {
  cv::Mat image(48, 48, CV_8UC3, cv::Scalar(1, 1, 1));
  image.at<cv::Vec3b>(0, 0) = cv::Vec3b(0, 0, 200);        // first cell, top left, red
  image.at<cv::Vec3b>(14, 47) = cv::Vec3b(250, 0, 0);      // right column, last sampled row
  image.at<cv::Vec3b>(33, 20) = cv::Vec3b(255, 255, 255);  // odd row: not sampled
  for (const int cell_px : {8, 16}) {
    const CellGrid grid = CellGrid::Make(48, 48, cell_px, 1);
    std::vector<float> sums(static_cast<size_t>(grid.cells()));
    std::vector<uint8_t> peaks(sums.size());
    MeasureCells(image, grid, sums.data(), peaks.data());
    const size_t last_column = static_cast<size_t>(grid.columns - 1);
    const size_t row_of_14 = static_cast<size_t>(14 / cell_px);
    const auto cell = [&](size_t row, size_t column) {
      return row * static_cast<size_t>(grid.columns) + column;
    };
    const float plain = 3.0f * static_cast<float>(grid.sampled_px_per_cell);
    EXPECT_EQ(peaks[0], 200) << cell_px;
    EXPECT_EQ(sums[0], plain - 3 + 200) << cell_px;
    EXPECT_EQ(peaks[cell(row_of_14, last_column)], 250) << cell_px;
    EXPECT_EQ(sums[cell(row_of_14, last_column)], plain - 3 + 250) << cell_px;
    const size_t row_of_33 = static_cast<size_t>(33 / cell_px);
    EXPECT_EQ(peaks[cell(row_of_33, static_cast<size_t>(20 / cell_px))], 1) << cell_px;
    EXPECT_EQ(sums[cell(row_of_33, static_cast<size_t>(20 / cell_px))], plain) << cell_px;
  }
}

TEST(MeasureCells, ReadsSubImagesThroughTheirRowStride) {
  const cv::Mat whole = RandomImage(200, 120, 99);
  ExpectCellsMatch(whole(cv::Rect(13, 7, 150, 90)), 16, 1);
  ExpectCellsMatch(whole(cv::Rect(13, 7, 150, 90)), 8, 1);
}

}  // namespace
}  // namespace liftoff::video::internal
