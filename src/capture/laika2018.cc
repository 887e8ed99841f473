#include "liftoff/capture/laika2018.h"

#include "liftoff/core/file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

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

constexpr std::string_view kFormatName = "laika-2018";
constexpr std::string_view kExpectedLine = "expected `t_ms,value,`";
// One frame of the 2018 videos (30 fps), the by-eye reading's floor of uncertainty.
constexpr int64_t kVideoFrameNs = kNanosecondsPerSecond / 30;
constexpr int64_t kDifferenceToleranceNs = kNanosecondsPerMillisecond;

std::optional<int> ParsePositiveInt(std::string_view text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || value < 1) return std::nullopt;
  return value;
}

// One `t_ms,value,` line (trailing comma optional).
struct ParsedSample {
  int64_t device_time_ns = 0;
  double shaft_rad = 0.0;
  bool trailing_comma = false;
};

std::optional<ParsedSample> ParseSampleLine(std::string_view line) {
  ParsedSample sample;
  if (!line.empty() && line.back() == ',') {
    sample.trailing_comma = true;
    line.remove_suffix(1);
  }
  const size_t comma = line.find(',');
  if (comma == std::string_view::npos) return std::nullopt;
  const std::string_view time_text = line.substr(0, comma);
  const std::string_view value_text = line.substr(comma + 1);
  // time: unsigned decimal milliseconds, parsed exactly
  if (time_text.empty() || time_text.front() < '0' || time_text.front() > '9') return std::nullopt;
  const Result<int64_t> time_ns = ParseDecimalNs(time_text, kNanosecondsPerMillisecond);
  if (!time_ns.ok()) return std::nullopt;
  sample.device_time_ns = *time_ns;
  // value: the output-shaft angle, rad
  const std::optional<double> value = ParseNumber(value_text);
  if (!value) return std::nullopt;
  sample.shaft_rad = *value;
  return sample;
}

// "back left" -> "Back Left": every word capitalised.
std::string TitleCase(std::string_view text) {
  std::string title(text);
  for (size_t i = 0; i < title.size(); ++i) {
    if (i == 0 || title[i - 1] == ' ')
      title[i] = static_cast<char>(std::toupper(static_cast<unsigned char>(title[i])));
  }
  return title;
}

// The 2018 log file of a foot's test, named by the foot's position and tape colour:
// "Test3 Back Left Red.txt".
std::string LogFileName(Foot foot, int test_number) {
  return "Test" + std::to_string(test_number) + " " + TitleCase(FootPosition(foot)) + " " +
         TitleCase(FootTapeColour(foot)) + ".txt";
}

// Digits printed after the decimal point ("5.67" -> 2, "10" -> 0).
int DecimalsPrinted(std::string_view text) {
  const size_t point = text.find('.');
  return point == std::string_view::npos ? 0 : static_cast<int>(text.size() - point - 1);
}

// Half a unit of the last digit of `decimals` decimals, ns (2 -> 0.005 s).
int64_t HalfUnitNs(int decimals) {
  int64_t unit_ns = kNanosecondsPerSecond;
  for (int d = 0; d < decimals && unit_ns > 1; ++d) unit_ns /= 10;
  return unit_ns / 2;
}

// One data row of the times CSV.
struct CsvRow {
  int64_t line = 0;
  Foot foot = Foot::kA;
  int test_number = 0;
  std::string led_on_text;
  std::string liftoff_text;
  int64_t led_on_ns = 0;
  int64_t liftoff_ns = 0;
  std::optional<int64_t> difference_ns;
};

Result<CsvRow> ParseCsvRow(std::string_view line_text, int64_t line, const std::string& where) {
  // split into fields, dropping empty trailing ones (spreadsheets pad rows with commas)
  std::vector<std::string_view> fields;
  size_t start = 0;
  while (true) {
    const size_t comma = line_text.find(',', start);
    fields.push_back(Trim(line_text.substr(
        start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  while (fields.size() > 4 && fields.back().empty()) fields.pop_back();
  const std::string prefix = where + ":" + std::to_string(line) + ": ";
  if (fields.size() < 4 || fields.size() > 5) {
    return ParseError(prefix +
                      "expected `foot,test,LED-on time (s),liftoff time (s),difference (s)`, got " +
                      Quote(line_text));
  }
  CsvRow row;
  row.line = line;
  // foot and test number
  const std::optional<Foot> foot = ParseFoot(fields[0]);
  if (!foot)
    return ParseError(prefix + "column 1 (foot): expected one of A, B, C, D, got " +
                      Quote(fields[0]));
  row.foot = *foot;
  const std::optional<int> test_number = ParsePositiveInt(fields[1]);
  if (!test_number) {
    return ParseError(prefix + "column 2 (test): expected an integer >= 1, got " +
                      Quote(fields[1]));
  }
  row.test_number = *test_number;
  // times, parsed exactly
  const auto parse_seconds = [&](size_t column, std::string_view name,
                                 bool allow_negative) -> Result<int64_t> {
    const std::string_view text = fields[column];
    Result<int64_t> ns = ParseDecimalNs(text, kNanosecondsPerSecond);
    if (!ns.ok() || (*ns < 0 && !allow_negative)) {
      return ParseError(prefix + "column " + std::to_string(column + 1) + " (" + std::string(name) +
                        "): expected " + (allow_negative ? "a" : "a non-negative") +
                        " number of seconds, got " + Quote(text));
    }
    return ns;
  };
  LIFTOFF_ASSIGN_OR_RETURN(row.led_on_ns, parse_seconds(2, "LED-on time", false));
  LIFTOFF_ASSIGN_OR_RETURN(row.liftoff_ns, parse_seconds(3, "liftoff time", false));
  row.led_on_text = std::string(fields[2]);
  row.liftoff_text = std::string(fields[3]);
  if (row.liftoff_ns <= row.led_on_ns) {
    return ParseError(prefix + "liftoff time " + row.liftoff_text + " s is not after LED-on time " +
                      row.led_on_text + " s");
  }
  if (fields.size() == 5 && !fields[4].empty()) {
    LIFTOFF_ASSIGN_OR_RETURN(row.difference_ns, parse_seconds(4, "difference", true));
  }
  return row;
}

}  // namespace

Result<ControllerLog> ImportLaika2018Log(const fs::path& path, const Calibration& calibration,
                                         const LogReadOptions& options) {
  const std::string file = path.string();
  LIFTOFF_ASSIGN_OR_RETURN(const std::string text, internal::ReadLogText(path, options));

  ControllerLog log;
  log.header.calibration = calibration.name;
  log.header.source = "import laika-2018 " + path.filename().string();
  log.report.source = path;
  log.report.format = std::string(kFormatName);

  const std::vector<TextLine> lines = SplitLines(text);
  // the last non-blank line may be a fragment (a capture stopped mid-line, or the stray
  // number such as "1074.33" that ten of the 2018 files end in)
  int64_t last_content_line = 0;
  for (const TextLine& line : lines) {
    if (!Trim(line.text).empty()) last_content_line = line.number;
  }

  internal::BadLines bad_lines;
  bool seen_trailing_comma = false;
  std::string_view previous_time_text;  // of the last kept sample, for messages
  for (const TextLine& line : lines) {
    const std::string_view content = Trim(line.text);
    if (content.empty()) continue;
    ++log.report.lines_total;
    std::optional<ParsedSample> sample = ParseSampleLine(content);
    // an unended last line without the trailing comma the others carry may have lost digits
    const bool is_last = line.number == last_content_line;
    const bool cut_by_eof = !line.ended && sample && !sample->trailing_comma && seen_trailing_comma;
    if (is_last && (!sample || cut_by_eof)) {
      log.report.truncated_last_line = true;
      AddIssue(log.report, options, line.number, "truncated last line, got " + Quote(content));
      continue;
    }
    std::string reason;
    if (!sample) {
      reason = std::string(kExpectedLine) + ", got " + Quote(content);
    } else if (!log.samples.empty() &&
               sample->device_time_ns <= log.samples.back().device_time_ns) {
      ++log.report.out_of_order;
      reason = "t_ms: expected more than the previous sample's " + std::string(previous_time_text) +
               ", got " + Quote(content.substr(0, content.find(',')));
    }
    if (!reason.empty()) {
      bad_lines.Add(log.report, options, line.number, std::move(reason));
      continue;
    }
    // keep the sample
    seen_trailing_comma = seen_trailing_comma || sample->trailing_comma;
    previous_time_text = content.substr(0, content.find(','));
    LogSample& kept = log.samples.emplace_back();
    kept.device_time_ns = sample->device_time_ns;
    kept.rotate_shaft_rad = sample->shaft_rad;
    kept.vertebra_rad = calibration.VertebraAngleFromShaftAngle(sample->shaft_rad);
  }

  LIFTOFF_RETURN_IF_ERROR(bad_lines.Check(file, options, "not counting a truncated last line"));
  if (log.samples.empty()) {
    return ParseError(file + ": no samples (" + Plural(log.report.lines_total, "non-blank line") +
                      ", " + Plural(log.report.bad_lines, "bad line") + ")");
  }
  log.report.samples = static_cast<int64_t>(log.samples.size());
  return log;
}

namespace {

// three header lines: a title, a padding line, the column names
constexpr size_t kHeaderLines = 3;

Status CheckTimesHeader(const std::vector<TextLine>& lines, const std::string& where) {
  if (lines.size() < kHeaderLines) {
    return ParseError(where + ": expected three header lines and then rows, got " +
                      Plural(static_cast<int64_t>(lines.size()), "line"));
  }
  const std::string_view column_header = lines[kHeaderLines - 1].text;
  std::string lower_header(column_header);
  std::transform(lower_header.begin(), lower_header.end(), lower_header.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower_header.find("foot") == std::string::npos) {
    return ParseError(where + ":3: expected the column header `Foot,Test no,...`, got " +
                      Quote(column_header));
  }
  return Status::Ok();
}

// The times CSV's rows, and the finest digit printed in each time column.
struct TimesRows {
  std::vector<CsvRow> rows;
  int led_on_decimals = 0;
  int liftoff_decimals = 0;
};

// rows after the header, skipping blank and comma-only padding lines; one row per trial
Result<TimesRows> ReadTimesRows(const std::vector<TextLine>& lines, const std::string& where) {
  TimesRows table;
  std::map<std::string, int64_t> line_of_id;
  for (size_t i = kHeaderLines; i < lines.size(); ++i) {
    const std::string_view content = Trim(lines[i].text);
    if (content.find_first_not_of(", \t") == std::string_view::npos) continue;
    LIFTOFF_ASSIGN_OR_RETURN(CsvRow row, ParseCsvRow(content, lines[i].number, where));
    const std::string id = std::string(FootName(row.foot)) + std::to_string(row.test_number);
    if (const auto [it, inserted] = line_of_id.emplace(id, row.line); !inserted) {
      return ParseError(where + ":" + std::to_string(row.line) + ": a second row for " + id +
                        " (the first is at line " + std::to_string(it->second) + ")");
    }
    table.led_on_decimals = std::max(table.led_on_decimals, DecimalsPrinted(row.led_on_text));
    table.liftoff_decimals = std::max(table.liftoff_decimals, DecimalsPrinted(row.liftoff_text));
    table.rows.push_back(std::move(row));
  }
  if (table.rows.empty()) return ParseError(where + ": no rows after the three header lines");
  return table;
}

// A row's trial: foot and test, Table II's motion, the log and the hand-measured times.
// Warns of a missing log and of a difference column that disagrees with the times.
TrialRecord TrialFromRow(const CsvRow& row, const fs::path& folder_abs, const EventTimes& times,
                         const std::string& where, std::vector<std::string>& warnings) {
  TrialRecord trial;
  trial.id = std::string(FootName(row.foot)) + std::to_string(row.test_number);
  trial.foot = row.foot;
  trial.test_number = row.test_number;
  // group and rotation from Table II by foot letter
  const FootLiftingMotion entry = PaperTableTwoMotion(row.foot);
  trial.pulled_group = entry.pulled_group;
  trial.rotation = entry.rotation;
  trial.notes = "pulled group " + std::string(CableGroupName(entry.pulled_group)) +
                " and rotation " + std::string(RotationSenseName(entry.rotation)) +
                " from the paper's Table II as printed, by foot letter (A: HR +, B: HR -, "
                "C: HL +, D: HL -); unverified, see docs/formats.md";
  // the log, and whether it is there
  const std::string log_name = LogFileName(row.foot, row.test_number);
  trial.log_path = folder_abs / log_name;
  trial.log_format = LogFormat::kLaika2018;
  std::error_code error;
  if (!fs::is_regular_file(trial.log_path, error)) {
    warnings.push_back(trial.id + ": log \"" + log_name + "\" is missing (" + where + ":" +
                       std::to_string(row.line) + ")");
  }
  // hand-measured times
  trial.times = times;
  trial.times->led_on_ns = row.led_on_ns;
  trial.times->liftoff_ns = row.liftoff_ns;
  // the difference column, checked against the two times
  if (row.difference_ns) {
    const int64_t computed_ns = row.liftoff_ns - row.led_on_ns;
    if (std::llabs(*row.difference_ns - computed_ns) > kDifferenceToleranceNs) {
      warnings.push_back(trial.id + ": difference column says " +
                         FormatSeconds(*row.difference_ns, 3) +
                         " s but liftoff - LED-on = " + FormatSeconds(computed_ns, 3) + " s (" +
                         where + ":" + std::to_string(row.line) + ")");
    }
  }
  return trial;
}

// logs in `folder` that no row names, in name order
void WarnUnusedLogs(const fs::path& folder, const std::set<std::string>& used_logs,
                    const std::string& where, std::vector<std::string>& warnings) {
  std::error_code error;
  std::set<std::string> unused_logs;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".txt" && name.rfind("Test", 0) == 0 &&
        !used_logs.count(name)) {
      unused_logs.insert(name);
    }
  }
  for (const std::string& name : unused_logs) {
    warnings.push_back("log \"" + name + "\" has no row in " + where);
  }
}

}  // namespace

Result<Laika2018FolderImport> ImportLaika2018Folder(const fs::path& folder,
                                                    const fs::path& manifest_path) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return NotFoundError(folder.string() + ": no such folder");
  const fs::path folder_abs = fs::absolute(folder).lexically_normal();
  const fs::path csv_path = folder / kLaika2018TimesCsv;
  LIFTOFF_ASSIGN_OR_RETURN(const std::string text, ReadWholeFile(csv_path));
  const std::string where = csv_path.string();

  // the times CSV: header, then rows
  const std::vector<TextLine> lines = SplitLines(text);
  LIFTOFF_RETURN_IF_ERROR(CheckTimesHeader(lines, where));
  LIFTOFF_ASSIGN_OR_RETURN(const TimesRows table, ReadTimesRows(lines, where));

  Laika2018FolderImport result;
  TrialManifest& manifest = result.manifest;
  manifest.base_dir = fs::absolute(manifest_path).lexically_normal().parent_path();
  manifest.description =
      "2018 Laika hardware tests (IROS 2018), imported from " + folder_abs.string();

  // a spreadsheet drops trailing zeros ("10" for 10.00), so a column's resolution is the
  // finest digit printed anywhere in it
  EventTimes times;
  times.led_on_uncertainty_ns = HalfUnitNs(table.led_on_decimals) + kVideoFrameNs;
  times.liftoff_uncertainty_ns = HalfUnitNs(table.liftoff_decimals) + kVideoFrameNs;
  times.source = "hand (2018 video, by eye)";

  // a trial a row, then the logs no row names
  std::set<std::string> used_logs;
  for (const CsvRow& row : table.rows) {
    manifest.trials.push_back(TrialFromRow(row, folder_abs, times, where, result.warnings));
    used_logs.insert(LogFileName(row.foot, row.test_number));
  }
  WarnUnusedLogs(folder, used_logs, where, result.warnings);

  LIFTOFF_RETURN_IF_ERROR(manifest.Validate());
  return result;
}

}  // namespace liftoff::capture
