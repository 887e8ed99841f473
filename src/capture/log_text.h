// Line-oriented text of the log readers (private to the capture module): lines split at
// any line end, trimming, quoting for messages, exact numbers, the skipped-line report.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/controller_log.h"
#include "liftoff/core/status.h"

namespace liftoff::capture::internal {

/// A line of text without its line end; `ended` is false for a last line cut off by EOF.
struct TextLine {
  int64_t number = 0;
  std::string_view text;
  bool ended = true;
};

/// Splits at CR LF, bare CR or bare LF (the 2018 files use all three).
std::vector<TextLine> SplitLines(std::string_view text);

/// Without leading and trailing blanks (spaces, tabs).
std::string_view Trim(std::string_view text);

/// The text quoted in a message, cut short when long.
std::string Quote(std::string_view text);

/// A finite double filling all of `text` ("-0.01", "2.24"); nullopt otherwise.
std::optional<double> ParseNumber(std::string_view text);

/// The whole of a log file, once the read options are checked (errors name the file).
Result<std::string> ReadLogText(const std::filesystem::path& path, const LogReadOptions& options);

/// Records a skipped line in the report (counted always, kept up to
/// options.max_issues_kept).
void AddIssue(LogReadReport& report, const LogReadOptions& options, int64_t line,
              std::string reason);

/// The bad lines that count against LogReadOptions::max_bad_lines: each is recorded in
/// the report, the first is kept for the error.
class BadLines {
 public:
  void Add(LogReadReport& report, const LogReadOptions& options, int64_t line, std::string reason);
  /// kParse "file:line: reason (N bad lines in all[, note]; at most M allowed)" naming the
  /// first, when there are more than allowed.
  Status Check(const std::string& file, const LogReadOptions& options,
               std::string_view note = {}) const;

 private:
  int64_t count_ = 0;
  int64_t first_line_ = 0;
  std::string first_reason_;
};

}  // namespace liftoff::capture::internal
