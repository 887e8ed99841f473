#include "liftoff/cli/progress_line.h"

#include <unistd.h>

#include <iostream>
#include <ostream>

#include "liftoff/core/time.h"

namespace liftoff::cli {

Result<ProgressLine> ProgressLine::Create(std::string_view mode, std::string_view flag,
                                          std::string prefix, std::ostream& err) {
  if (mode != "auto" && mode != "live" && mode != "lines" && mode != "off") {
    return InvalidArgumentError(std::string(flag) + ": expected auto, live, lines or off, got \"" +
                                std::string(mode) + "\"");
  }
  const bool live = mode == "live" || (mode == "auto" && err.rdbuf() == std::cerr.rdbuf() &&
                                       ::isatty(STDERR_FILENO) == 1);
  return ProgressLine(err, std::move(prefix), live, mode == "off");
}

ProgressLine::ProgressLine(std::ostream& err, std::string prefix, bool live, bool off)
    : err_(&err),
      prefix_(std::move(prefix)),
      live_(live),
      off_(off),
      last_shown_ns_(MonotonicNowNs()) {}

bool ProgressLine::Due() {
  const int64_t now_ns = MonotonicNowNs();
  const int64_t every_ns = live_ ? NsFromMilliseconds(200) : NsFromSeconds(5.0);
  if (now_ns - last_shown_ns_ < every_ns) return false;
  last_shown_ns_ = now_ns;
  return true;
}

void ProgressLine::Show(const std::string& text) {
  if (off_) return;
  if (!live_) {
    *err_ << prefix_ << ": " << text << std::endl;
    return;
  }
  *err_ << '\r' << text
        << std::string(last_width_ > text.size() ? last_width_ - text.size() : 0, ' ')
        << std::flush;
  last_width_ = text.size();
}

void ProgressLine::Line(const std::string& text) {
  if (off_) return;
  Clear();
  *err_ << prefix_ << ": " << text << std::endl;
}

void ProgressLine::Clear() {
  if (live_ && last_width_ > 0)
    *err_ << '\r' << std::string(last_width_, ' ') << '\r' << std::flush;
  last_width_ = 0;
}

void ProgressLine::Keep() {
  if (live_ && last_width_ > 0) *err_ << '\n';
  last_width_ = 0;
}

}  // namespace liftoff::cli
