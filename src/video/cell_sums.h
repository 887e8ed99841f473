// The LED locator's per-frame kernel (private to the video module): over a grid of square
// cells, the sum of B + G + R and the brightest channel value of each cell, every
// kCellRowStep-th row. SSE2 where the cell's row is a whole number of 16-byte chunks, a
// plain loop otherwise; both give the same numbers (tests/video/cell_sums_test.cc checks
// them against OpenCV's cv::sum and cv::minMaxLoc on random images).
#pragma once

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/core.hpp>

namespace liftoff::video::internal {

// Cells sample every other row: half the work, and a light covers several rows.
constexpr int kCellRowStep = 2;

// The cells: origins of every cell column and row (the last one flush with the frame's
// edge, so the whole frame is covered).
struct CellGrid {
  int cell_px = 16;
  int columns = 0, rows = 0;
  std::vector<int> x0_px, y0_px;
  int sampled_px_per_cell = 0;

  // every `stride`-th cell of the full grid
  static CellGrid Make(int width_px, int height_px, int cell_px, int stride) {
    CellGrid grid;
    grid.cell_px = cell_px;
    const int columns = (width_px + cell_px - 1) / cell_px;
    const int rows = (height_px + cell_px - 1) / cell_px;
    for (int i = 0; i < columns; i += stride) {
      grid.x0_px.push_back(std::min(i * cell_px, width_px - cell_px));
    }
    for (int i = 0; i < rows; i += stride) {
      grid.y0_px.push_back(std::min(i * cell_px, height_px - cell_px));
    }
    grid.columns = static_cast<int>(grid.x0_px.size());
    grid.rows = static_cast<int>(grid.y0_px.size());
    grid.sampled_px_per_cell = cell_px * ((cell_px + kCellRowStep - 1) / kCellRowStep);
    return grid;
  }
  int cells() const { return columns * rows; }
};

// Sum and brightest channel of every cell of an 8-bit BGR image, row by row of cells,
// a plain loop.
inline void MeasureCellsPlain(const cv::Mat& bgr, const CellGrid& grid, float* sums,
                              uint8_t* peaks) {
  const int bytes_per_cell = grid.cell_px * 3;
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      uint32_t sum = 0;
      uint8_t peak = 0;
      for (int y = 0; y < grid.cell_px; y += kCellRowStep) {
        const uint8_t* pixel = bgr.ptr<uint8_t>(grid.y0_px[static_cast<size_t>(row)] + y) +
                               grid.x0_px[static_cast<size_t>(column)] * 3;
        for (int u = 0; u < bytes_per_cell; ++u) {
          sum += pixel[u];
          peak = std::max(peak, pixel[u]);
        }
      }
      const size_t cell = static_cast<size_t>(row * grid.columns + column);
      sums[cell] = static_cast<float>(sum);
      peaks[cell] = peak;
    }
  }
}

#if defined(__SSE2__)
// The same, one cell at a time, its sampled rows 16 bytes per instruction, the sum and
// the maximum kept in registers. Needs cell_px * 3 to be a multiple of 16.
inline void MeasureCellsSse2(const cv::Mat& bgr, const CellGrid& grid, float* sums,
                             uint8_t* peaks) {
  const int chunks = grid.cell_px * 3 / 16;
  const size_t row_stride = bgr.step[0] * static_cast<size_t>(kCellRowStep);
  const __m128i zero = _mm_setzero_si128();
  for (int row = 0; row < grid.rows; ++row) {
    const uint8_t* band = bgr.ptr<uint8_t>(grid.y0_px[static_cast<size_t>(row)]);
    for (int column = 0; column < grid.columns; ++column) {
      __m128i sum = zero, peak = zero;
      const uint8_t* line = band + grid.x0_px[static_cast<size_t>(column)] * 3;
      for (int y = 0; y < grid.cell_px; y += kCellRowStep, line += row_stride) {
        for (int chunk = 0; chunk < chunks; ++chunk) {
          __m128i value;
          std::memcpy(&value, line + 16 * chunk, sizeof value);
          sum = _mm_add_epi64(sum, _mm_sad_epu8(value, zero));
          peak = _mm_max_epu8(peak, value);
        }
      }
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 8));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 4));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 2));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 1));
      std::array<uint64_t, 2> halves{};
      std::memcpy(halves.data(), &sum, sizeof halves);
      const auto cell = static_cast<size_t>(row * grid.columns + column);
      sums[cell] = static_cast<float>(halves[0] + halves[1]);
      peaks[cell] = static_cast<uint8_t>(_mm_cvtsi128_si32(peak) & 0xff);
    }
  }
}
#endif

// Whether MeasureCells takes the SSE2 path for this grid.
inline bool CellsUseSse2(const CellGrid& grid) {
#if defined(__SSE2__)
  return grid.cell_px * 3 % 16 == 0;
#else
  (void)grid;
  return false;
#endif
}

// Sum of B + G + R and the brightest channel value of every cell, every
// kCellRowStep-th row: sums and peaks hold grid.cells() values each.
inline void MeasureCells(const cv::Mat& bgr, const CellGrid& grid, float* sums, uint8_t* peaks) {
#if defined(__SSE2__)
  if (CellsUseSse2(grid)) {
    MeasureCellsSse2(bgr, grid, sums, peaks);
    return;
  }
#endif
  MeasureCellsPlain(bgr, grid, sums, peaks);
}

}  // namespace liftoff::video::internal
