// The one progress display of the command line (`sim`, `video`, `table`, `sync --video`,
// `report`, `capture`): a line on stderr rewritten in place ("live"), a line of its own
// every few seconds ("lines"), or nothing ("off"); "auto" is live when the stream is the
// process' standard error and a terminal, else lines.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>

#include "liftoff/core/status.h"

namespace liftoff::cli {

class ProgressLine {
 public:
  /// `mode` as the flag `flag` gave it; kInvalidArgument "--progress: expected auto, live,
  /// lines or off, got ..." for another. Lines are printed as "<prefix>: <text>".
  static Result<ProgressLine> Create(std::string_view mode, std::string_view flag,
                                     std::string prefix, std::ostream& err);

  bool live() const { return live_; }
  bool off() const { return off_; }
  /// Whether an update is due (live: 200 ms after the last shown, lines: 5 s); when it is,
  /// the clock restarts.
  bool Due();
  /// Shows `text`: rewrites the live line, or prints it as a line (nothing when off).
  void Show(const std::string& text);
  /// Prints `text` as a line of its own below a live line (nothing when off).
  void Line(const std::string& text);
  /// Clears a live line (call before printing anything else).
  void Clear();
  /// Ends a live line where it stands, keeping its last text.
  void Keep();

 private:
  ProgressLine(std::ostream& err, std::string prefix, bool live, bool off);
  std::ostream* err_;
  std::string prefix_;
  bool live_ = false;
  bool off_ = false;
  int64_t last_shown_ns_ = 0;
  size_t last_width_ = 0;
};

}  // namespace liftoff::cli
