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

#include "liftoff/core/robust_stats.h"

namespace liftoff::video::internal {

// "80x90 at (600, 400)": size, then the top-left corner, as the messages spell a region
// (X11's 80x90+600+400 would read the other way round; "600x400+80x90" did).
inline std::string RectText(const cv::Rect& rect) {
  return std::to_string(rect.width) + "x" + std::to_string(rect.height) + " at (" +
         std::to_string(rect.x) + ", " + std::to_string(rect.y) + ")";
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
