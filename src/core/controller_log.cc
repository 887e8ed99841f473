#include "liftoff/core/controller_log.h"

#include "liftoff/core/file.h"
#include "liftoff/core/text.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>
#include <system_error>

namespace liftoff {
namespace {

constexpr int kFormatVersion = 1;
constexpr std::string_view kMagic = "# liftoff-log";
// a byte-order mark an editor may put in front of the first line
constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";
constexpr std::string_view kColumnHeader =
    "device_time_ns,host_time_ns,seq,led,bend_counts,rotate_counts,bend_spool_rad,"
    "rotate_shaft_rad,vertebra_rad,event,detail";
constexpr std::array<std::string_view, 11> kColumns = {
    "device_time_ns", "host_time_ns",     "seq",          "led",   "bend_counts", "rotate_counts",
    "bend_spool_rad", "rotate_shaft_rad", "vertebra_rad", "event", "detail"};
enum Column : size_t {
  kDeviceTime,
  kHostTime,
  kSeq,
  kLed,
  kBendCounts,
  kRotateCounts,
  kBendSpool,
  kRotateShaft,
  kVertebra,
  kEvent,
  kDetail,
  kColumnCount
};
// header keys with a field of their own; every other key is metadata
constexpr std::array<std::string_view, 3> kReservedKeys = {"calibration", "source", "device"};

constexpr std::array<std::string_view, 8> kEventNames = {
    "led_on", "led_off", "test_start", "test_end", "gap", "reconnect", "fault", "note"};

// A line's text for messages: quoted, cut short, control bytes shown as \xNN.
std::string Quote(std::string_view text) {
  constexpr size_t kMax = 60;
  std::string quoted = "\"";
  for (size_t i = 0; i < text.size() && i < kMax; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte < 0x20 || byte == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      quoted += escaped;
    } else {
      quoted += text[i];
    }
  }
  if (text.size() > kMax) quoted += "...";
  return quoted + "\"";
}

std::string_view Trim(std::string_view text) {
  const size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return {};
  return text.substr(begin, text.find_last_not_of(" \t") - begin + 1);
}

bool IsKey(std::string_view key) {
  return !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

bool HasLineBreak(std::string_view text) {
  return text.find_first_of("\r\n") != std::string_view::npos;
}

// The number of line ends (LF, or CR where a file has no LF) in a file: an upper bound of
// its rows; 0 when it cannot be read (the reader then finds out why).
size_t CountLineEnds(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 1 << 16> buffer{};
  size_t line_feeds = 0, carriage_returns = 0;
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto end = buffer.begin() + in.gcount();
    line_feeds += static_cast<size_t>(std::count(buffer.begin(), end, '\n'));
    carriage_returns += static_cast<size_t>(std::count(buffer.begin(), end, '\r'));
  }
  return line_feeds > 0 ? line_feeds : carriage_returns;
}

// The longest log line read whole, bytes (a liftoff row is about 100).
constexpr size_t kMaxLineBytes = 4096;

// Lines of a stream, ending in LF, CR or CRLF; reads in blocks so memory stays flat.
class LineReader {
 public:
  explicit LineReader(std::istream& in) : in_(in) {}

  // The next line without its end; false at the end of the input.
  bool Next(std::string& line, bool& has_line_end) {
    line.clear();
    while (true) {
      if (position_ == size_ && !Fill()) {
        has_line_end = false;
        return !line.empty();
      }
      if (skip_lf_) {  // second half of a CRLF
        skip_lf_ = false;
        if (buffer_[position_] == '\n') ++position_;
        continue;
      }
      const char* begin = buffer_.data() + position_;
      const char* end = buffer_.data() + size_;
      const char* stop = std::find_if(begin, end, [](char c) { return c == '\n' || c == '\r'; });
      // a line beyond the limit keeps its first kMaxLineBytes + 1 bytes: memory stays flat
      // on a file without line ends, and the row is reported as too long
      const size_t room = kMaxLineBytes + 1 - std::min(line.size(), kMaxLineBytes + 1);
      line.append(begin, begin + std::min(room, static_cast<size_t>(stop - begin)));
      position_ = static_cast<size_t>(stop - buffer_.data());
      if (stop == end) continue;
      skip_lf_ = *stop == '\r';
      ++position_;
      ++line_number_;
      has_line_end = true;
      return true;
    }
  }
  // Number of the line Next() returned last, from 1.
  int64_t line_number(bool has_line_end) const { return line_number_ + (has_line_end ? 0 : 1); }

 private:
  bool Fill() {
    in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    size_ = static_cast<size_t>(in_.gcount());
    position_ = 0;
    return size_ > 0;
  }

  std::istream& in_;
  std::array<char, 1 << 16> buffer_{};
  size_t size_ = 0;
  size_t position_ = 0;
  bool skip_lf_ = false;
  int64_t line_number_ = 0;
};

// CSV fields; a field may be quoted ("a,b" and "say ""hi""").
bool SplitFields(std::string_view line, std::vector<std::string>& fields) {
  fields.clear();
  size_t i = 0;
  while (true) {
    std::string& field = fields.emplace_back();
    if (i < line.size() && line[i] == '"') {
      // quoted: up to the closing quote, "" is a quote
      ++i;
      while (true) {
        if (i >= line.size()) return false;  // no closing quote
        if (line[i] == '"') {
          if (i + 1 < line.size() && line[i + 1] == '"') {
            field += '"';
            i += 2;
            continue;
          }
          ++i;
          break;
        }
        field += line[i++];
      }
      if (i < line.size() && line[i] != ',') return false;  // text after the closing quote
    } else {
      const size_t comma = std::min(line.find(',', i), line.size());
      field.assign(line.substr(i, comma - i));
      i = comma;
    }
    if (i >= line.size()) return true;
    ++i;  // the comma
  }
}

template <typename Integer>
bool ParseInteger(std::string_view text, Integer& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// a finite number ("inf" and "nan" are not angles)
bool ParseAngle(std::string_view text, double& value) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && std::isfinite(value);
}

// nanoseconds within +-kMaxLogTimeNs, so differences of two times cannot overflow
bool ParseTimeNs(std::string_view text, int64_t& value) {
  return ParseInteger(text, value) && value >= -kMaxLogTimeNs && value <= kMaxLogTimeNs;
}

// One data row, as a sample or an event; `expected` says what was wrong when neither.
struct ParsedRow {
  bool is_event = false;
  LogSample sample;
  LogEvent event;
  std::string expected;  // "<what was expected>, got <text>"
};

void ParseRow(std::string_view line, std::vector<std::string>& fields, ParsedRow& row) {
  row = ParsedRow{};
  const auto fail = [&](std::string_view what, std::string_view got) {
    row.expected = std::string(what) + ", got " + Quote(got);
  };
  if (!SplitFields(line, fields) || fields.size() != kColumnCount) {
    fail("expected " + std::to_string(kColumnCount) + " comma-separated fields (" +
             std::string(kColumnHeader) + ")",
         line);
    return;
  }
  const auto bad_field = [&](Column column, std::string_view what) {
    fail(std::string(kColumns[column]) + ": expected " + std::string(what), fields[column]);
  };

  // times: the device's required, the host's optional
  int64_t device_time_ns = 0;
  std::optional<int64_t> host_time_ns;
  if (!ParseTimeNs(fields[kDeviceTime], device_time_ns)) {
    return bad_field(kDeviceTime, "an integer number of nanoseconds within +-4e18");
  }
  if (!fields[kHostTime].empty()) {
    int64_t value = 0;
    if (!ParseTimeNs(fields[kHostTime], value)) {
      return bad_field(kHostTime, "an integer number of nanoseconds within +-4e18, or nothing");
    }
    host_time_ns = value;
  }

  // an event: its kind and detail, nothing measured
  if (!fields[kEvent].empty()) {
    const std::optional<LogEventKind> kind = ParseLogEventKind(fields[kEvent]);
    if (!kind) {
      std::string names;
      for (std::string_view name : kEventNames)
        names += (names.empty() ? "" : ", ") + std::string(name);
      return bad_field(kEvent, "one of " + names);
    }
    for (size_t column = kSeq; column <= kVertebra; ++column) {
      if (!fields[column].empty()) {
        return bad_field(static_cast<Column>(column), "nothing on an event row");
      }
    }
    row.is_event = true;
    row.event = {device_time_ns, host_time_ns, *kind, std::move(fields[kDetail])};
    return;
  }

  // a sample: every measured field may be empty (not measured)
  LogSample& sample = row.sample;
  sample.device_time_ns = device_time_ns;
  sample.host_time_ns = host_time_ns;
  if (!fields[kSeq].empty()) {
    uint32_t sequence = 0;
    if (!ParseInteger(fields[kSeq], sequence))
      return bad_field(kSeq, "an integer in [0, 4294967295]");
    sample.sequence = sequence;
  }
  if (!fields[kLed].empty()) {
    if (fields[kLed] != "0" && fields[kLed] != "1") return bad_field(kLed, "0, 1 or nothing");
    sample.led_on = fields[kLed] == "1";
  }
  for (const auto& [column, counts] : {std::pair{kBendCounts, &sample.bend_counts},
                                       std::pair{kRotateCounts, &sample.rotate_counts}}) {
    if (fields[column].empty()) continue;
    int64_t value = 0;
    if (!ParseInteger(fields[column], value))
      return bad_field(column, "an integer number of counts");
    *counts = value;
  }
  for (const auto& [column, angle] : {std::pair{kBendSpool, &sample.bend_spool_rad},
                                      std::pair{kRotateShaft, &sample.rotate_shaft_rad},
                                      std::pair{kVertebra, &sample.vertebra_rad}}) {
    if (fields[column].empty()) continue;
    if (!ParseAngle(fields[column], *angle)) {
      return bad_field(column, "a finite number of radians");
    }
  }
  if (!fields[kDetail].empty()) return bad_field(kDetail, "nothing on a sample row");
}

// Formatting, with std::to_chars: no locale, shortest text that reads back exactly.
void AppendInteger(std::string& out, int64_t value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void AppendAngle(std::string& out, double value) {
  if (std::isnan(value)) return;  // not measured
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

// Quotes text that a CSV reader (or pandas' comment='#') would otherwise split.
void AppendText(std::string& out, std::string_view text) {
  if (text.find_first_of(",\"#") == std::string_view::npos) {
    out += text;
    return;
  }
  out += '"';
  for (char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  out += '"';
}

std::string FormatSample(const LogSample& sample) {
  std::string line;
  AppendInteger(line, sample.device_time_ns);
  line += ',';
  if (sample.host_time_ns) AppendInteger(line, *sample.host_time_ns);
  line += ',';
  if (sample.sequence) AppendInteger(line, *sample.sequence);
  line += ',';
  if (sample.led_on) line += *sample.led_on ? '1' : '0';
  line += ',';
  if (sample.bend_counts) AppendInteger(line, *sample.bend_counts);
  line += ',';
  if (sample.rotate_counts) AppendInteger(line, *sample.rotate_counts);
  line += ',';
  AppendAngle(line, sample.bend_spool_rad);
  line += ',';
  AppendAngle(line, sample.rotate_shaft_rad);
  line += ',';
  AppendAngle(line, sample.vertebra_rad);
  line += ",,\n";
  return line;
}

std::string FormatEvent(const LogEvent& event) {
  std::string line;
  AppendInteger(line, event.device_time_ns);
  line += ',';
  if (event.host_time_ns) AppendInteger(line, *event.host_time_ns);
  line += ",,,,,,,,";
  line += LogEventKindName(event.kind);
  line += ',';
  AppendText(line, event.detail);
  line += '\n';
  return line;
}

Status CheckHeader(const std::filesystem::path& path, const LogHeader& header) {
  const auto where = [&](std::string_view key) {
    return path.string() + ": header " + std::string(key);
  };
  for (const auto& [key, value] :
       {std::pair<std::string_view, const std::string&>{"calibration", header.calibration},
        {"source", header.source},
        {"device", header.device}}) {
    if (HasLineBreak(value))
      return InvalidArgumentError(where(key) + ": expected one line, got " + Quote(value));
  }
  for (const auto& [key, value] : header.metadata) {
    if (!IsKey(key)) {
      return InvalidArgumentError(where("metadata key " + Quote(key)) +
                                  ": expected letters, digits, '_', '-' and '.' only");
    }
    if (std::find(kReservedKeys.begin(), kReservedKeys.end(), key) != kReservedKeys.end()) {
      return InvalidArgumentError(where("metadata key " + Quote(key)) +
                                  ": reserved for LogHeader's own field");
    }
    if (HasLineBreak(value))
      return InvalidArgumentError(where(key) + ": expected one line, got " + Quote(value));
  }
  return Status::Ok();
}

std::string HeaderText(const LogHeader& header) {
  std::string text = std::string(kMagic) + " " + std::to_string(kFormatVersion) + "\n";
  const auto line = [&](std::string_view key, std::string_view value) {
    text += "# " + std::string(key) + ":" + (value.empty() ? "" : " ") + std::string(value) + "\n";
  };
  line("calibration", header.calibration);
  line("source", header.source);
  line("device", header.device);
  for (const auto& [key, value] : header.metadata) line(key, value);
  return text + std::string(kColumnHeader) + "\n";
}

// Refuses an event detail the format cannot hold (one line per row).
Status CheckEventDetail(const std::filesystem::path& path, const LogEvent& event) {
  if (!HasLineBreak(event.detail)) return Status::Ok();
  return InvalidArgumentError(path.string() + ": event detail: expected one line, got " +
                              Quote(event.detail));
}

}  // namespace

// ---------------------------------------------------------------------------------------
// vocabulary

std::string_view LogEventKindName(LogEventKind kind) {
  return kEventNames[static_cast<size_t>(kind)];
}

std::optional<LogEventKind> ParseLogEventKind(std::string_view text) {
  for (size_t i = 0; i < kEventNames.size(); ++i) {
    if (text == kEventNames[i]) return static_cast<LogEventKind>(i);
  }
  return std::nullopt;
}

std::string LogReadReport::Brief() const {
  std::string brief = source.filename().string() + ": " + Plural(samples, "sample");
  if (events > 0) brief += ", " + Plural(events, "event");
  if (bad_lines == 0) return brief;
  brief += ", " + Plural(bad_lines, "bad line");
  if (!issues.empty()) {
    brief += " (line " + std::to_string(issues.front().line) + ": " + issues.front().reason;
    if (bad_lines > 1) brief += "; " + std::to_string(bad_lines - 1) + " more";
    brief += ")";
  }
  return brief;
}

std::optional<int64_t> ControllerLog::LedOnTimeNs() const {
  // an explicit event wins
  for (const LogEvent& event : events) {
    if (event.kind == LogEventKind::kLedOn) return event.device_time_ns;
  }
  // else the first off-to-on step of the samples' LED field
  bool seen_off = false;
  for (const LogSample& sample : samples) {
    if (!sample.led_on) continue;
    if (!*sample.led_on) seen_off = true;
    if (*sample.led_on && seen_off) return sample.device_time_ns;
  }
  return std::nullopt;
}

int64_t ControllerLog::FirstSampleNs() const {
  assert(!samples.empty());
  return samples.front().device_time_ns;
}

int64_t ControllerLog::LastSampleNs() const {
  assert(!samples.empty());
  return samples.back().device_time_ns;
}

Status LogReadOptions::Validate() const {
  if (max_bad_lines < 0) {
    return InvalidArgumentError("LogReadOptions.max_bad_lines: expected an integer >= 0, got " +
                                std::to_string(max_bad_lines));
  }
  if (max_issues_kept < 0) {
    return InvalidArgumentError("LogReadOptions.max_issues_kept: expected an integer >= 0, got " +
                                std::to_string(max_issues_kept));
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// reading

namespace {

// Reads a liftoff log's text into `log` in the file's order: the version line, the header,
// the rows. Errors name file:line; a file cut off before its first row is an empty log.
class LogParser {
 public:
  LogParser(std::string name, std::istream& in, const LogReadOptions& options, ControllerLog& log)
      : name_(std::move(name)), lines_(in), options_(options), log_(log) {}

  // "liftoff-log 1" (after an optional UTF-8 byte order mark)
  Status ReadVersionLine() {
    if (!lines_.Next(line_, has_line_end_)) return EmptyLog();
    if (line_.starts_with(kUtf8ByteOrderMark)) line_.erase(0, kUtf8ByteOrderMark.size());
    if (!has_line_end_ && std::string_view(kMagic).starts_with(line_)) return EmptyLog();
    const std::string_view first = line_;
    const std::string_view version_text =
        first.starts_with(kMagic) ? Trim(first.substr(kMagic.size())) : "";
    int version = 0;
    if (!first.starts_with(std::string(kMagic) + " ") || !ParseInteger(version_text, version)) {
      return ParseError(Where() + ": expected \"" + std::string(kMagic) + " " +
                        std::to_string(kFormatVersion) + "\" as the first line, got " +
                        Quote(line_));
    }
    if (version != kFormatVersion) {
      return UnsupportedError(Where() + ": liftoff-log version " + std::to_string(version) +
                              " is not supported; this build reads version " +
                              std::to_string(kFormatVersion));
    }
    log_.header.version = version;
    return Status::Ok();
  }

  // header lines "# key: value" up to the column header; other '#' lines are comments
  Status ReadHeader() {
    while (lines_.Next(line_, has_line_end_)) {
      const std::string_view text = Trim(line_);
      if (text.empty()) continue;
      if (text.front() == '#') {
        LIFTOFF_RETURN_IF_ERROR(ReadHeaderKey(Trim(text.substr(1))));
        continue;
      }
      if (text == kColumnHeader) return Status::Ok();
      if (!has_line_end_ && kColumnHeader.starts_with(text)) return EmptyLog();
      return ParseError(Where() + ": expected the column header \"" + std::string(kColumnHeader) +
                        "\", got " + Quote(line_));
    }
    return EmptyLog();
  }

  // rows: samples and events; bad ones skipped, counted and remembered
  void ReadRows() {
    while (lines_.Next(line_, has_line_end_)) {
      if (Trim(line_).empty() || Trim(line_).front() == '#') continue;
      ++log_.report.lines_total;
      ReadRow(lines_.line_number(has_line_end_));
    }
  }

  // too many bad lines, or nothing to work with
  Status CheckVerdict() const {
    const LogReadReport& report = log_.report;
    const int64_t counted_bad = report.bad_lines - (report.truncated_last_line ? 1 : 0);
    if (counted_bad > options_.max_bad_lines) {
      return ParseError(first_bad_ + " (" + Plural(counted_bad, "bad line") +
                        " in all, not counting a " + "truncated last line; at most " +
                        std::to_string(options_.max_bad_lines) + " allowed)");
    }
    if (log_.samples.empty()) return EmptyLog();
    return Status::Ok();
  }

 private:
  std::string Where() const {
    return name_ + ":" + std::to_string(lines_.line_number(has_line_end_));
  }
  Status EmptyLog() const { return ParseError(name_ + ": no samples (empty log)"); }

  // the body of a '#' line: a "key: value" pair, or a comment
  Status ReadHeaderKey(std::string_view body) {
    const size_t colon = body.find(':');
    if (colon == std::string_view::npos || !IsKey(body.substr(0, colon))) return Status::Ok();
    const std::string key(body.substr(0, colon));
    const std::string value(Trim(body.substr(colon + 1)));
    if (!seen_keys_.insert(key).second) {
      return ParseError(Where() + ": header key \"" + key + "\" appears twice");
    }
    if (key == "calibration") {
      log_.header.calibration = value;
    } else if (key == "source") {
      log_.header.source = value;
    } else if (key == "device") {
      log_.header.device = value;
    } else {
      log_.header.metadata[key] = value;
    }
    return Status::Ok();
  }

  // the current line as a sample or an event, or skipped
  void ReadRow(int64_t line_number) {
    if (line_.size() > kMaxLineBytes) {
      Skip(line_number,
           "expected a line of at most " + std::to_string(kMaxLineBytes) +
               " bytes, got a longer one",
           false);
      return;
    }
    ParseRow(line_, fields_, row_);
    if (!row_.expected.empty()) {
      Skip(line_number, row_.expected, !has_line_end_);
      return;
    }
    if (row_.is_event) {
      log_.events.push_back(std::move(row_.event));
      return;
    }
    // samples run forward in device time; one that does not is dropped
    std::vector<LogSample>& samples = log_.samples;
    if (!samples.empty() && row_.sample.device_time_ns <= samples.back().device_time_ns) {
      ++log_.report.out_of_order;
      Skip(line_number,
           "device_time_ns: expected more than the previous sample's " +
               std::to_string(samples.back().device_time_ns) + ", got " +
               Quote(std::to_string(row_.sample.device_time_ns)),
           false);
      return;
    }
    samples.push_back(row_.sample);
  }

  void Skip(int64_t line_number, std::string reason, bool truncated) {
    LogReadReport& report = log_.report;
    ++report.bad_lines;
    if (truncated) report.truncated_last_line = true;
    if (!truncated && first_bad_.empty())
      first_bad_ = name_ + ":" + std::to_string(line_number) + ": " + reason;
    if (std::ssize(report.issues) < options_.max_issues_kept) {
      report.issues.push_back(
          {line_number, truncated ? "truncated last line, got " + Quote(line_) : reason});
    }
  }

  const std::string name_;
  LineReader lines_;
  const LogReadOptions& options_;
  ControllerLog& log_;
  std::string line_;
  bool has_line_end_ = false;
  std::set<std::string> seen_keys_;
  std::string first_bad_;  // "file:line: expected ..., got ..." of the first bad line
  std::vector<std::string> fields_;
  ParsedRow row_;
};

}  // namespace

Result<ControllerLog> ReadControllerLog(const std::filesystem::path& path,
                                        const LogReadOptions& options) {
  const std::string name = path.string();
  if (Status valid = options.Validate(); !valid.ok()) return valid.WithContext(name);
  LIFTOFF_RETURN_IF_ERROR(CheckRegularFile(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(name + ": cannot open for reading");

  ControllerLog log;
  log.report.source = path;
  log.report.format = "liftoff";
  LogParser parser(name, in, options, log);
  LIFTOFF_RETURN_IF_ERROR(parser.ReadVersionLine());
  LIFTOFF_RETURN_IF_ERROR(parser.ReadHeader());
  // the samples are reserved once for every line ahead (a cheap pass over the file), so the
  // vector never holds an old and a doubled copy at once
  log.samples.reserve(CountLineEnds(path));
  parser.ReadRows();
  if (in.bad()) return IoError(name + ": read failed");
  LIFTOFF_RETURN_IF_ERROR(parser.CheckVerdict());

  std::stable_sort(log.events.begin(), log.events.end(), [](const LogEvent& a, const LogEvent& b) {
    return a.device_time_ns < b.device_time_ns;
  });
  log.report.samples = std::ssize(log.samples);
  log.report.events = std::ssize(log.events);
  return log;
}

// ---------------------------------------------------------------------------------------
// writing

ControllerLogWriter::~ControllerLogWriter() {
  if (is_open()) (void)Close();
}

Status ControllerLogWriter::Open(const std::filesystem::path& path, const LogHeader& header) {
  if (is_open()) LIFTOFF_RETURN_IF_ERROR(Close());
  LIFTOFF_RETURN_IF_ERROR(CheckHeader(path, header));
  path_ = path;
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) return IoError(path.string() + ": cannot open for writing");
  // the header reaches the disk at once: a capture that dies early still leaves a log
  out_ << HeaderText(header);
  return Flush();
}

Status ControllerLogWriter::Append(const LogSample& sample) {
  assert(is_open() && "Append on a writer that is not open");
  if (!is_open()) return IoError(path_.string() + ": log writer is not open");
  out_ << FormatSample(sample);
  if (!out_) return IoError(path_.string() + ": write failed");
  return Status::Ok();
}

Status ControllerLogWriter::Append(const LogEvent& event) {
  assert(is_open() && "Append on a writer that is not open");
  if (!is_open()) return IoError(path_.string() + ": log writer is not open");
  LIFTOFF_RETURN_IF_ERROR(CheckEventDetail(path_, event));
  out_ << FormatEvent(event);
  if (!out_) return IoError(path_.string() + ": write failed");
  return Status::Ok();
}

Status ControllerLogWriter::Flush() {
  if (!is_open()) return Status::Ok();
  out_.flush();
  if (!out_) return IoError(path_.string() + ": write failed");
  return Status::Ok();
}

Status ControllerLogWriter::Close() {
  if (!is_open()) return Status::Ok();
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  if (!written || !out_) return IoError(path_.string() + ": write failed");
  return Status::Ok();
}

Status WriteControllerLog(const std::filesystem::path& path, const ControllerLog& log) {
  // what a writer would refuse
  LIFTOFF_RETURN_IF_ERROR(CheckHeader(path, log.header));
  for (const LogEvent& event : log.events) LIFTOFF_RETURN_IF_ERROR(CheckEventDetail(path, event));

  // samples and events merged in device time; an event goes before a sample at its instant
  std::string text = HeaderText(log.header);
  auto sample = log.samples.begin();
  auto event = log.events.begin();
  while (sample != log.samples.end() || event != log.events.end()) {
    if (event != log.events.end() &&
        (sample == log.samples.end() || event->device_time_ns <= sample->device_time_ns)) {
      text += FormatEvent(*event++);
    } else {
      text += FormatSample(*sample++);
    }
  }
  return WriteFileAtomically(path, text);
}

Result<LogFormat> DetectLogFormat(const std::filesystem::path& path) {
  const std::string name = path.string();
  LIFTOFF_RETURN_IF_ERROR(CheckRegularFile(path));
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(name + ": cannot open for reading");
  // enough bytes for a byte-order mark and the magic
  std::string first(kUtf8ByteOrderMark.size() + kMagic.size(), '\0');
  in.read(first.data(), static_cast<std::streamsize>(first.size()));
  if (in.bad()) return IoError(name + ": read failed");
  first.resize(static_cast<size_t>(in.gcount()));
  std::string_view start = first;
  if (start.starts_with(kUtf8ByteOrderMark)) start.remove_prefix(kUtf8ByteOrderMark.size());
  return start.starts_with(kMagic) ? LogFormat::kLiftoff : LogFormat::kLaika2018;
}

}  // namespace liftoff
