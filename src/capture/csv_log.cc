#include "liftoff/capture/csv_log.h"

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/file.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "log_text.h"

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;
using internal::AddIssue;
using internal::ParseNumber;
using internal::Quote;
using internal::SplitLines;
using internal::TextLine;
using internal::Trim;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// whole encoder counts beyond this are not exact in a double
constexpr double kMaxCounts = 9007199254740992.0;  // 2^53

// The fields of a CSV line: split at commas, blanks and double quotes around each removed.
std::vector<std::string_view> Fields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    std::string_view field = Trim(line.substr(start, comma - start));
    if (field.size() >= 2 && field.front() == '"' && field.back() == '"') {
      field = field.substr(1, field.size() - 2);
    }
    fields.push_back(field);
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

int64_t NsPerUnit(const std::string& unit) {
  if (unit == "ms") return kNanosecondsPerMillisecond;
  if (unit == "us") return kNanosecondsPerMicrosecond;
  if (unit == "ns") return 1;
  return kNanosecondsPerSecond;
}

// Where each named column is in a line's fields.
struct ColumnIndex {
  size_t time = 0, angle = 0;
  std::optional<size_t> led;
  size_t needed = 0;  // fields a line must have
};

Result<ColumnIndex> FindColumns(std::string_view header, int64_t line,
                                const CsvLogColumns& columns, const std::string& file) {
  const std::vector<std::string_view> names = Fields(header);
  const auto find = [&](const std::string& name) -> std::optional<size_t> {
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == name) return i;
    }
    return std::nullopt;
  };
  ColumnIndex index;
  std::vector<std::pair<const std::string*, size_t*>> wanted = {
      {&columns.time_column, &index.time}, {&columns.angle_column, &index.angle}};
  size_t led = 0;
  if (columns.led_column) wanted.push_back({&*columns.led_column, &led});
  for (const auto& [name, at] : wanted) {
    const std::optional<size_t> found = find(*name);
    if (!found) {
      return ParseError(file + ":" + std::to_string(line) + ": no column " + Quote(*name) +
                        " in the header " + Quote(header) +
                        " (the manifest's log names the columns)");
    }
    *at = *found;
    index.needed = std::max(index.needed, *found + 1);
  }
  if (columns.led_column) index.led = led;
  return index;
}

// One sample from a line's fields; the reason it is bad otherwise.
struct ParsedLine {
  LogSample sample;
  std::string bad;
};

ParsedLine ParseLine(std::string_view content, const ColumnIndex& index,
                     const CsvLogColumns& columns) {
  ParsedLine parsed;
  const std::vector<std::string_view> fields = Fields(content);
  if (fields.size() < index.needed) {
    parsed.bad = "expected at least " + std::to_string(index.needed) + " fields, got " +
                 Quote(content);
    return parsed;
  }
  const Result<int64_t> time_ns = ParseDecimalNs(fields[index.time], NsPerUnit(columns.time_unit));
  if (!time_ns.ok()) {
    parsed.bad = columns.time_column + ": expected a decimal number of " + columns.time_unit +
                 ", got " + Quote(fields[index.time]);
    return parsed;
  }
  parsed.sample.device_time_ns = *time_ns;
  const std::optional<double> angle = ParseNumber(fields[index.angle]);
  const bool counts = columns.angle_unit == "counts";
  if (!angle || (counts && (std::trunc(*angle) != *angle || std::abs(*angle) > kMaxCounts))) {
    parsed.bad =
        columns.angle_column + ": expected " +
        (counts ? std::string("whole encoder counts") : "a finite angle in " + columns.angle_unit) +
        ", got " + Quote(fields[index.angle]);
    return parsed;
  }
  if (counts) {
    parsed.sample.rotate_counts = static_cast<int64_t>(*angle);
  } else {
    parsed.sample.vertebra_rad = columns.angle_unit == "deg" ? *angle * kRadPerDeg : *angle;
  }
  if (index.led) {
    const std::string_view led = fields[*index.led];
    if (led != "0" && led != "1") {
      parsed.bad = *columns.led_column + ": expected 0 or 1, got " + Quote(led);
      return parsed;
    }
    parsed.sample.led_on = led == "1";
  }
  return parsed;
}

}  // namespace

Result<ControllerLog> ReadCsvLog(const fs::path& path, const CsvLogColumns& columns,
                                 const LogReadOptions& options) {
  const std::string file = path.string();
  LIFTOFF_ASSIGN_OR_RETURN(const std::string text, internal::ReadLogText(path, options));
  ControllerLog log;
  log.header.source = "csv " + path.filename().string();
  log.report.source = path;
  log.report.format = "csv";

  const std::vector<TextLine> lines = SplitLines(text);
  std::optional<ColumnIndex> index;
  internal::BadLines bad_lines;
  for (const TextLine& line : lines) {
    const std::string_view content = Trim(line.text);
    if (content.empty()) continue;
    if (!index) {
      LIFTOFF_ASSIGN_OR_RETURN(index, FindColumns(content, line.number, columns, file));
      continue;
    }
    ++log.report.lines_total;
    ParsedLine parsed = ParseLine(content, *index, columns);
    if (parsed.bad.empty() && !log.samples.empty() &&
        parsed.sample.device_time_ns <= log.samples.back().device_time_ns) {
      ++log.report.out_of_order;
      parsed.bad = columns.time_column + ": expected more than the previous sample's time, got " +
                   Quote(content);
    }
    if (!parsed.bad.empty()) {
      if (!line.ended) {  // the last line, cut off by the end of the file
        log.report.truncated_last_line = true;
        AddIssue(log.report, options, line.number, "truncated last line, got " + Quote(content));
        continue;
      }
      bad_lines.Add(log.report, options, line.number, std::move(parsed.bad));
      continue;
    }
    log.samples.push_back(parsed.sample);
  }

  LIFTOFF_RETURN_IF_ERROR(bad_lines.Check(file, options));
  if (log.samples.empty()) {
    return ParseError(file + ": no samples (" + Plural(log.report.lines_total, "line") +
                      " after the header, " + Plural(log.report.bad_lines, "bad line") + ")");
  }
  if (columns.led_on_s) {
    LogEvent led;
    led.device_time_ns = NsFromSeconds(*columns.led_on_s);
    led.kind = LogEventKind::kLedOn;
    led.detail = "led_on_s in the manifest";
    log.events.push_back(led);
    log.report.events = 1;
  }
  log.report.samples = static_cast<int64_t>(log.samples.size());
  return log;
}

}  // namespace liftoff::capture
