#include "log_text.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include "liftoff/core/file.h"
#include "liftoff/core/text.h"

namespace liftoff::capture::internal {

// Splits at CR LF, bare CR or bare LF (the 2018 files use all three).
std::vector<TextLine> SplitLines(std::string_view text) {
  std::vector<TextLine> lines;
  size_t start = 0;
  int64_t number = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\r' && text[i] != '\n') continue;
    lines.push_back({number++, text.substr(start, i - start), true});
    if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    start = i + 1;
  }
  if (start < text.size()) lines.push_back({number, text.substr(start), false});
  return lines;
}

// Without leading and trailing blanks.
std::string_view Trim(std::string_view text) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; };
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

// The text quoted in a message, cut short when long.
std::string Quote(std::string_view text) {
  constexpr size_t kMaxQuoted = 60;
  std::string quoted = "\"" + std::string(text.substr(0, kMaxQuoted));
  if (text.size() > kMaxQuoted) quoted += "...";
  return quoted + "\"";
}

// A finite double filling all of `text` ("-0.01", "2.24").
std::optional<double> ParseNumber(std::string_view text) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

Result<std::string> ReadLogText(const std::filesystem::path& path, const LogReadOptions& options) {
  if (Status valid = options.Validate(); !valid.ok()) return valid.WithContext(path.string());
  return ReadWholeFile(path);
}

// Records a skipped line in the report.
void AddIssue(LogReadReport& report, const LogReadOptions& options, int64_t line,
              std::string reason) {
  ++report.bad_lines;
  if (static_cast<int64_t>(report.issues.size()) < options.max_issues_kept) {
    report.issues.push_back({line, std::move(reason)});
  }
}

void BadLines::Add(LogReadReport& report, const LogReadOptions& options, int64_t line,
                   std::string reason) {
  if (count_++ == 0) {
    first_line_ = line;
    first_reason_ = reason;
  }
  AddIssue(report, options, line, std::move(reason));
}

Status BadLines::Check(const std::string& file, const LogReadOptions& options,
                       std::string_view note) const {
  if (count_ <= options.max_bad_lines) return Status::Ok();
  return ParseError(file + ":" + std::to_string(first_line_) + ": " + first_reason_ + " (" +
                    Plural(count_, "bad line") + " in all" +
                    (note.empty() ? std::string() : ", " + std::string(note)) + "; at most " +
                    std::to_string(options.max_bad_lines) + " allowed)");
}

}  // namespace liftoff::capture::internal
