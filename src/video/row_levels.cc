#include "row_levels.h"

#include <algorithm>
#include <cstddef>

#include "liftoff/core/robust_stats.h"

namespace liftoff::video::internal {

std::vector<float> RowGains(const cv::Mat& grey, const cv::Mat& reference, int smooth_rows,
                            float min_level) {
  CV_Assert(grey.type() == CV_32F && reference.type() == CV_32F &&
            grey.size() == reference.size() && smooth_rows >= 0);
  const int rows = grey.rows, columns = grey.cols;
  std::vector<float> measured(static_cast<size_t>(rows), 0.0f);
  std::vector<bool> known(static_cast<size_t>(rows), false);
  std::vector<float> ratios;
  ratios.reserve(static_cast<size_t>(columns));
  for (int r = 0; r < rows; ++r) {
    const float* now = grey.ptr<float>(r);
    const float* then = reference.ptr<float>(r);
    ratios.clear();
    for (int c = 0; c < columns; ++c) {
      if (then[c] >= min_level) ratios.push_back(now[c] / then[c]);
    }
    if (2 * ratios.size() < static_cast<size_t>(columns)) continue;
    measured[static_cast<size_t>(r)] = MedianOf(ratios);
    known[static_cast<size_t>(r)] = true;
  }
  // rows not measured take the nearest measured row's
  int last = -1;
  for (int r = 0; r < rows; ++r) {
    if (known[static_cast<size_t>(r)]) {
      for (int fill = last + 1; fill < r; ++fill) {
        const bool nearer_next = last < 0 || r - fill < fill - last;
        measured[static_cast<size_t>(fill)] = measured[static_cast<size_t>(nearer_next ? r : last)];
      }
      last = r;
    }
  }
  if (last < 0) return {};
  for (int fill = last + 1; fill < rows; ++fill) {
    measured[static_cast<size_t>(fill)] = measured[static_cast<size_t>(last)];
  }
  // a running mean over the rows, then relative to the median
  std::vector<float> gains(static_cast<size_t>(rows));
  for (int r = 0; r < rows; ++r) {
    const int from = std::max(0, r - smooth_rows), to = std::min(rows - 1, r + smooth_rows);
    float sum = 0.0f;
    for (int i = from; i <= to; ++i) sum += measured[static_cast<size_t>(i)];
    gains[static_cast<size_t>(r)] = sum / static_cast<float>(to - from + 1);
  }
  const float middle = MedianOf(gains);
  if (middle > 0) {
    for (float& gain : gains) gain /= middle;
  }
  return gains;
}

float GainRange(const std::vector<float>& gains) {
  if (gains.empty()) return 0.0f;
  const auto [low, high] = std::minmax_element(gains.begin(), gains.end());
  return *high - *low;
}

void LevelRows(cv::Mat& image, const std::vector<float>& gains) {
  CV_Assert(image.depth() == CV_32F && static_cast<size_t>(image.rows) == gains.size());
  for (int r = 0; r < image.rows; ++r) {
    const float gain = gains[static_cast<size_t>(r)];
    if (gain > 0) image.row(r) /= gain;
  }
}

}  // namespace liftoff::video::internal
