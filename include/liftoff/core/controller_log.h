// The controller log: what the test controller streamed during one trial, in liftoff's
// own file format (docs/formats.md, "controller log"). Written by live capture and by
// importers of older formats; read by sync.
//
// In memory: samples in device-time order, events (LED on, test start/end, gaps,
// reconnects, faults), a header, and a report of every line the reader skipped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/manifest.h"
#include "liftoff/core/packed_optional.h"
#include "liftoff/core/status.h"

namespace liftoff {

inline constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

/// The largest |time| a log may hold, device or host clock, ns (4e18 ns, about 127 years):
/// the difference of any two such times fits in int64, so no interval computed from a
/// log can overflow. Readers reject larger times naming file:line.
inline constexpr int64_t kMaxLogTimeNs = 4'000'000'000'000'000'000;

/// A host time that may be absent, in 8 bytes: absent is INT64_MIN, which no log time
/// takes (|time| <= kMaxLogTimeNs); storing INT64_MIN (a corrupt journal's time) leaves it
/// absent.
using OptionalLogTimeNs = SentinelOptional<int64_t, std::numeric_limits<int64_t>::min()>;

/// One sample of the controller's stream. Fields the source did not provide are absent
/// (integers, which read like std::optional) or NaN (angles). Packed into 64 bytes, as a
/// long capture keeps millions (a 10-million-line log is 0.4-0.6 GB on disk).
struct LogSample {
  /// Controller clock, nanoseconds from the controller's origin (the 2018 firmware's
  /// origin is the LED switch-on).
  int64_t device_time_ns = 0;
  /// Host clock when the bytes arrived, nanoseconds since the Unix epoch.
  OptionalLogTimeNs host_time_ns;
  /// Controller's frame sequence number (wraps at 2^32).
  PackedOptional<uint32_t> sequence;
  /// Sync LED state.
  PackedOptional<bool> led_on;
  /// Raw encoder counts of the bending motor (the pulled group's spool).
  PackedOptional<int64_t> bend_counts;
  /// Raw encoder counts of the rotating vertebra's motor.
  PackedOptional<int64_t> rotate_counts;
  /// Bending spool angle, rad.
  double bend_spool_rad = kNotMeasured;
  /// Rotating motor's output-shaft angle, rad.
  double rotate_shaft_rad = kNotMeasured;
  /// Rotating vertebra angle (driven half relative to driving half), rad.
  double vertebra_rad = kNotMeasured;
};
static_assert(sizeof(LogSample) == 64, "a sample's fields pack into 64 bytes");

enum class LogEventKind {
  kLedOn,      ///< the sync LED switched on
  kLedOff,     ///< the sync LED switched off
  kTestStart,  ///< the controller began the test sequence
  kTestEnd,    ///< the controller finished the test sequence
  kGap,        ///< frames are missing here (sequence jump or link loss); detail says how many
  kReconnect,  ///< the host reopened the port after losing it
  kFault,      ///< the controller reported a fault; detail says which
  kNote,       ///< free text from the writer
};

/// "led_on", "led_off", "test_start", "test_end", "gap", "reconnect", "fault", "note".
std::string_view LogEventKindName(LogEventKind kind);
std::optional<LogEventKind> ParseLogEventKind(std::string_view text);

struct LogEvent {
  /// Controller clock, ns (as LogSample::device_time_ns).
  int64_t device_time_ns = 0;
  /// Host clock, ns since the Unix epoch, when known.
  std::optional<int64_t> host_time_ns;
  LogEventKind kind = LogEventKind::kNote;
  /// Free text (no newlines): fault name, number of missing frames, ...
  std::string detail;
};

/// A line a reader skipped, and why.
struct LogIssue {
  /// Line number in the file, from 1.
  int64_t line = 0;
  /// What was wrong: "expected `t_ms,value,`, got \"1074.33\"".
  std::string reason;
};

/// What a reader made of a file: counts of everything, the first few skipped lines.
struct LogReadReport {
  /// File read.
  std::filesystem::path source;
  /// Format read ("liftoff", "laika-2018").
  std::string format;
  /// Non-empty lines seen (blank lines and comments are not counted).
  int64_t lines_total = 0;
  /// Samples kept.
  int64_t samples = 0;
  /// Events kept.
  int64_t events = 0;
  /// Lines skipped as malformed (including a truncated last line).
  int64_t bad_lines = 0;
  /// Whether the last line was cut off mid-way (a capture stopped mid-line).
  bool truncated_last_line = false;
  /// Samples dropped because their device time did not increase (counted as bad lines
  /// too, and listed in `issues`).
  int64_t out_of_order = 0;
  /// The first `LogReadOptions::max_issues_kept` skipped lines.
  std::vector<LogIssue> issues;

  /// "Test1 Front Right Blue.txt: 135 samples, 1 bad line (line 136: truncated last line)".
  std::string Brief() const;
};

/// Metadata at the top of a log.
struct LogHeader {
  /// Format version of the file (1).
  int version = 1;
  /// Name of the calibration used to convert counts into angles ("laika-2018").
  std::string calibration;
  /// Where the data came from: "capture /dev/ttyACM0", "import laika-2018 <file>", ...
  std::string source;
  /// Firmware or emulator identification, when known.
  std::string device;
  /// Further key/value pairs (commanded test parameters, ...), written in key order.
  std::map<std::string, std::string> metadata;
};

struct ControllerLog {
  LogHeader header;
  /// Samples, strictly increasing device time.
  std::vector<LogSample> samples;
  /// Events, non-decreasing device time.
  std::vector<LogEvent> events;
  /// What the reader skipped (empty for logs built in memory).
  LogReadReport report;

  /// Device time of the LED switch-on: the first kLedOn event, else the first sample with
  /// led_on after one without, else nullopt (the origin is then taken as the LED time).
  std::optional<int64_t> LedOnTimeNs() const;
  /// Device time of the first and last sample; asserts there is one.
  int64_t FirstSampleNs() const;
  int64_t LastSampleNs() const;
};

struct LogReadOptions {
  /// Malformed lines tolerated (skipped and reported) before the read fails. A truncated
  /// last line is always tolerated and reported. 0: any other bad line is an error.
  int64_t max_bad_lines = 0;
  /// How many skipped lines to keep in the report (all are counted).
  int max_issues_kept = 20;

  Status Validate() const;
};

/// Reads a log in liftoff's format. kNotFound for a missing file, kParse for a bad header
/// or more bad lines than allowed (message: "file:line: what was expected, got ..." for the
/// first, and the count), kParse "no samples" for an empty log, kInvalidArgument for bad
/// options. Every error message starts with the file's name.
Result<ControllerLog> ReadControllerLog(const std::filesystem::path& path,
                                        const LogReadOptions& options = {});

/// The format of the log at `path` by its first bytes: kLiftoff when it starts with
/// "# liftoff-log" (after an optional UTF-8 byte-order mark, as ReadControllerLog
/// accepts), else kLaika2018. kNotFound for a missing file, kInvalidArgument for a folder,
/// kIo when it cannot be read; every message names the file.
Result<LogFormat> DetectLogFormat(const std::filesystem::path& path);

/// Writes a whole log (samples and events merged in time order) through a temporary file
/// renamed into place.
Status WriteControllerLog(const std::filesystem::path& path, const ControllerLog& log);

/// Streaming writer for live capture: each Append is one line, flushed by Flush(); memory
/// stays flat in the length of the capture.
class ControllerLogWriter {
 public:
  ControllerLogWriter() = default;
  ControllerLogWriter(const ControllerLogWriter&) = delete;
  ControllerLogWriter& operator=(const ControllerLogWriter&) = delete;
  ~ControllerLogWriter();

  /// Creates (truncates) `path` and writes the header. kIo on failure.
  Status Open(const std::filesystem::path& path, const LogHeader& header);
  Status Append(const LogSample& sample);
  Status Append(const LogEvent& event);
  /// Pushes buffered lines to the operating system.
  Status Flush();
  Status Close();
  bool is_open() const { return out_.is_open(); }

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

}  // namespace liftoff
