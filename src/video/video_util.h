// Small helpers the video module's sources share (private: not installed, not for other
// modules).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

namespace liftoff::video::internal {

// "80x90 at (600, 400)": size, then the top-left corner, as the messages spell a region
// (X11's 80x90+600+400 would read the other way round; "600x400+80x90" did).
inline std::string RectText(const cv::Rect& rect) {
  return std::to_string(rect.width) + "x" + std::to_string(rect.height) + " at (" +
         std::to_string(rect.x) + ", " + std::to_string(rect.y) + ")";
}

// The median of values[0, count) (reordered; the mean of the middle two for an even
// count); 0 for none.
template <typename T>
T MedianOf(T* values, std::ptrdiff_t count) {
  if (count <= 0) return T{};
  const std::ptrdiff_t mid = count / 2;
  std::nth_element(values, values + mid, values + count);
  T middle = values[mid];
  if (count % 2 == 0) {
    const T below = *std::max_element(values, values + mid);
    middle = static_cast<T>((middle + below) / 2);
  }
  return middle;
}

// The median of a copy of `values` (the caller's order is kept).
template <typename T>
T MedianOf(std::vector<T> values) {
  return MedianOf(values.data(), static_cast<std::ptrdiff_t>(values.size()));
}

// A series' noise, robustly, from its successive differences: 1.4826 times their median
// absolute value over the square root of 2 (a Gaussian noise's standard deviation; a slow
// drift adds only its change per step, not its whole course); 0 for fewer than two values.
inline double SuccessiveDifferenceSigma(const std::vector<double>& series) {
  if (series.size() < 2) return 0.0;
  std::vector<double> changes(series.size() - 1);
  for (size_t i = 1; i < series.size(); ++i) changes[i - 1] = std::abs(series[i] - series[i - 1]);
  return 1.4826 * MedianOf(std::move(changes)) / std::sqrt(2.0);
}

// While alive, OpenCV's own log is silent (it reports failed opens and missing backends as
// errors on stderr; liftoff reports them itself). Nests across threads: the first one in
// saves OpenCV's level, the last one out puts it back.
class QuietOpenCvLog {
 public:
  QuietOpenCvLog() {
    const std::lock_guard<std::mutex> lock(Mutex());
    if (Count()++ == 0) {
      SavedLevel() = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    }
  }
  ~QuietOpenCvLog() {
    const std::lock_guard<std::mutex> lock(Mutex());
    if (--Count() == 0) cv::utils::logging::setLogLevel(SavedLevel());
  }
  QuietOpenCvLog(const QuietOpenCvLog&) = delete;
  QuietOpenCvLog& operator=(const QuietOpenCvLog&) = delete;

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  static int& Count() {
    static int count = 0;
    return count;
  }
  static cv::utils::logging::LogLevel& SavedLevel() {
    static cv::utils::logging::LogLevel level = cv::utils::logging::LOG_LEVEL_WARNING;
    return level;
  }
};

}  // namespace liftoff::video::internal
