// Live capture: reads the controller's serial stream, writes every byte to the raw
// journal before parsing it, and writes the parsed controller log (samples, events,
// sequence gaps, reconnects) as it goes. Survives unplugging (waits for the port to come
// back and marks the gap), and stops cleanly on request, at the controller's end-of-test
// event or after a maximum duration, with every received byte on disk.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "liftoff/capture/protocol.h"
#include "liftoff/capture/serial_port.h"
#include "liftoff/capture/wire_format.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/status.h"

namespace liftoff::capture {

/// One row of a controller log: a sample or an event.
using LogRow = std::variant<LogSample, LogEvent>;

/// Turns received bytes into controller-log rows: the parsing of live capture, shared by
/// ReplayJournal so a log can always be rebuilt from its journal. Frames are split and
/// checked by FrameParser; the device clock is unwrapped (DeviceClock); a jump in the
/// sequence numbers becomes a `gap` event ("3 frames, sequence 44..46") halfway between
/// the frames around it; a reopened port becomes a `reconnect` event before the first
/// frame after it. Frames whose device time does not move forward (a sample not later than
/// the last sample, an event earlier than the last row: stale frames repeated after a
/// reconnect) are dropped and counted, so the log's samples stay strictly increasing.
/// A controller restart (its sequence number goes back and its clock goes back by more
/// than kRestartClockStepUs) is not stale: the device clock is rebased so time continues
/// just after the last row, a `note` event "controller restarted: ..." marks it, and
/// rows (TEST_END included) keep coming.
class StreamDecoder {
 public:
  /// Counters beyond the parser's own (parser_stats()).
  struct Counters {
    /// Samples and events emitted as rows (gap and reconnect markers included in events).
    int64_t samples = 0;
    int64_t events = 0;
    /// Sequence gaps and the frames missing in them.
    int64_t gaps = 0;
    int64_t missing_frames = 0;
    /// Frames dropped because their device time did not move forward.
    int64_t duplicates = 0;
    /// Times the link came back after being lost.
    int64_t reconnects = 0;
    /// Times the controller restarted (sequence and clock started again).
    int64_t restarts = 0;
  };

  /// A step back of the device clock longer than this, us, together with a step back of
  /// the sequence number, is a controller restart rather than a stale repeat.
  static constexpr uint32_t kRestartClockStepUs = 1'000'000;

  /// `calibration` converts counts into angles; it must outlive the decoder.
  explicit StreamDecoder(const Calibration& calibration);

  /// Parses `bytes` received at `host_time_ns` and appends the resulting rows to `rows`,
  /// in the log's order (docs/formats.md): by device time, and the events of an instant
  /// before its sample, whatever order they arrived in. The last sample is therefore held
  /// back until a row of a later instant arrives, or Finish.
  void Feed(std::span<const uint8_t> bytes, int64_t host_time_ns, std::vector<LogRow>& rows);
  /// The end of the stream: appends the sample held back, if any.
  void Finish(std::vector<LogRow>& rows);
  /// The link went away at `host_time_ns`: a frame cut in half is dropped.
  void LinkLost(int64_t host_time_ns);
  /// The link is back at `host_time_ns`: the next frame is preceded by a reconnect event
  /// saying how long the link was down.
  void LinkRestored(int64_t host_time_ns);

  const ParserStats& parser_stats() const { return parser_.stats(); }
  const Counters& counters() const { return counters_; }
  /// The controller's first header frame (firmware, encoder constants), once seen.
  const std::optional<wire::HeaderFrame>& device_header() const { return device_header_; }
  /// Whether a TEST_END event has arrived.
  bool test_ended() const { return test_ended_; }
  /// LED state and vertebra angle of the last sample, when any.
  std::optional<bool> led_on() const { return led_on_; }
  double last_vertebra_rad() const { return last_vertebra_rad_; }
  /// Device time of the last row emitted, ns.
  std::optional<int64_t> last_row_time_ns() const { return last_row_ns_; }

 private:
  void Accept(const ReceivedFrame& received, std::vector<LogRow>& rows);
  bool IsRestart(uint32_t sequence, uint32_t device_time_us) const;
  // steps of Accept: the clock rebased after a restart (returns the note to log), the
  // markers of what happened since the previous frame, then the frame's own row
  std::optional<std::string> RebaseAfterRestart(uint32_t sequence, uint32_t device_time_us);
  void EmitMarkers(uint32_t sequence, int64_t device_ns, int64_t host_ns,
                   std::optional<std::string> restart, std::vector<LogRow>& rows);
  void EmitFrame(const wire::Frame& frame, int64_t device_ns, int64_t host_ns,
                 std::vector<LogRow>& rows);
  void Emit(LogRow row, std::vector<LogRow>& rows);

  const Calibration* calibration_;
  FrameParser parser_;
  DeviceClock clock_;
  SequenceTracker sequence_;
  std::vector<ReceivedFrame> frames_;  // scratch, reused
  Counters counters_;
  std::optional<wire::HeaderFrame> device_header_;
  std::optional<int64_t> last_frame_ns_;    // device time of the last accepted frame
  std::optional<int64_t> last_sample_ns_;   // ... of the last sample row
  std::optional<int64_t> last_row_ns_;      // ... of the last row of any kind
  std::optional<uint32_t> last_device_us_;  // raw device clock of the last accepted frame
  int64_t clock_offset_ns_ = 0;             // added to the device clock since a restart
  std::optional<int64_t> link_lost_host_ns_;
  bool reconnect_pending_ = false;
  int64_t link_down_ns_ = 0;
  bool test_ended_ = false;
  std::optional<bool> led_on_;
  double last_vertebra_rad_ = kNotMeasured;
  std::optional<LogSample> held_sample_;  // the last sample, until its instant is over
};

/// Header metadata of a capture's log: the device's header frame as device_* keys and
/// the commanded start parameters as commanded_* keys (when a start was sent).
void AddDeviceMetadata(const wire::HeaderFrame& header, LogHeader& log_header);
void AddStartMetadata(const wire::CommandFrame& start, LogHeader& log_header);

/// The header of a capture's log, built alike by live capture and ReplayJournal (so a
/// replayed log's header matches the live one but for its source): the calibration's
/// name, `source`, the port settings ("115200 8N1") and journal file name as metadata,
/// the device's header frame (firmware, device_* keys) and the start command
/// (commanded_* keys) when known.
LogHeader CaptureLogHeader(const Calibration& calibration, std::string source,
                           std::string_view port_settings, std::string_view journal_name,
                           const std::optional<wire::HeaderFrame>& device,
                           const std::optional<wire::CommandFrame>& start);

struct CaptureOptions {
  /// Port to read: a device path ("/dev/ttyACM0"), a stable symlink
  /// ("/dev/serial/by-id/..."), or a pseudo-terminal. Reopened by this same name after
  /// the device goes away; a pseudo-terminal only through a symlink that has been
  /// replaced since (a pty never returns under its own name: a new one with the same
  /// number belongs to someone else). Never /dev/ttyS0 on the development machine.
  std::string port;
  /// Baud rate and framing.
  PortSettings settings;
  /// Controller log to write (liftoff-log v1).
  std::filesystem::path log_path;
  /// Raw journal to write; empty: log_path + ".journal".
  std::filesystem::path journal_path;
  /// Send `start_command` once the port is open (and record its parameters in the log's
  /// header).
  bool send_start = false;
  wire::CommandFrame start_command;
  /// How often to look for the port again after it went away, s (> 0).
  double reconnect_poll_s = 0.2;
  /// Longest wait of one read, ms (> 0): bounds how late a stop request is noticed.
  double read_timeout_ms = 50.0;
  /// Stop after this long, s (0: no limit).
  double max_duration_s = 0.0;
  /// Fail with kTimeout when no frame has arrived this long after opening, s (0: wait
  /// for ever).
  double first_frame_timeout_s = 0.0;
  /// Stop at the controller's TEST_END event.
  bool stop_on_test_end = true;
  /// How often on_status is called, s (> 0).
  double status_interval_s = 0.25;
  /// The log is opened once the controller's header frame has arrived (so the log names
  /// the firmware), or this long after the first frame without one, s (>= 0). Rows
  /// wait in memory meanwhile; the journal is on disk from the first byte.
  double header_wait_s = 1.5;
  /// Journal and log lines reach the operating system at least this often, ms (> 0).
  double flush_interval_ms = 100.0;
  /// Replace an existing log or journal (an earlier recording). Off: RunCapture refuses
  /// with kInvalidArgument before it touches the port or any file.
  bool replace_existing = false;

  /// The journal path in use: journal_path, or log_path + ".journal".
  std::filesystem::path JournalPath() const;
  /// kInvalidArgument naming the field: empty port or log path, a journal that is the log
  /// (compared as resolved paths), non-positive intervals, negative durations, a start
  /// command that is not START.
  Status Validate() const;
};

/// What a capture received, at its end.
struct CaptureSummary {
  std::filesystem::path log_path;
  std::filesystem::path journal_path;
  /// Firmware named by the controller's header frame ("" when none arrived).
  std::string device;
  /// Bytes received (all in the journal).
  int64_t bytes = 0;
  /// Frames accepted, and the rows they gave.
  int64_t frames = 0;
  int64_t samples = 0;
  int64_t events = 0;
  /// Frames rejected: CRC mismatch, or malformed; bytes outside any frame.
  int64_t checksum_errors = 0;
  int64_t malformed_frames = 0;
  int64_t garbage_bytes = 0;
  /// Sequence gaps and the frames missing in them.
  int64_t gaps = 0;
  int64_t missing_frames = 0;
  /// Stale frames dropped (device time not moving forward).
  int64_t duplicates = 0;
  /// Times the port was reopened after going away.
  int64_t reconnects = 0;
  /// Wall-clock length of the capture, s.
  double duration_s = 0.0;
  /// Why it stopped: "test end", "stop request", "max duration".
  std::string stopped_by;
  /// Things a person should know (the device's encoder constants disagree with the
  /// calibration, ...).
  std::vector<std::string> warnings;

  /// "12001 frames (12000 samples, 5 events) in 12.3 s, 0 checksum failures, 0 gaps,
  /// 0 reconnects; stopped by test end".
  std::string Brief() const;
};

/// A live view of the capture, for a status line.
struct CaptureStatus {
  /// Bytes received so far (all in the journal).
  int64_t bytes = 0;
  /// Frames accepted so far.
  int64_t frames = 0;
  /// Frames per second over the last status interval.
  double rate_hz = 0.0;
  int64_t checksum_errors = 0;
  int64_t gaps = 0;
  /// LED state of the last sample (nullopt before the first).
  std::optional<bool> led_on;
  /// Vertebra angle of the last sample, rad (NaN before the first).
  double last_vertebra_rad = kNotMeasured;
  /// Whether the port is open (false while waiting for it to come back).
  bool connected = false;
  /// Seconds since the capture began.
  double elapsed_s = 0.0;
};

/// Runs a capture until `stop` is set, the test ends (stop_on_test_end), or
/// max_duration_s passes; calls `on_status` (when set) every status_interval_s from the
/// calling thread. Errors: kInvalidArgument for bad options, and for a log or journal that
/// exists already unless replace_existing (nothing is touched then); the port's errors when it
/// cannot be opened at the start (kNotFound, kIo); kIo when the journal or log cannot be
/// written; kTimeout when first_frame_timeout_s passes without a frame. The journal and
/// the log are flushed and closed on every path.
Result<CaptureSummary> RunCapture(const CaptureOptions& options, const Calibration& calibration,
                                  const std::atomic<bool>& stop,
                                  const std::function<void(const CaptureStatus&)>& on_status = {});

}  // namespace liftoff::capture
