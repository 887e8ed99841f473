#include "liftoff/capture/capture_session.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

#include "liftoff/capture/journal.h"
#include "liftoff/core/output.h"
#include "liftoff/core/file.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"

namespace liftoff::capture {
namespace {

// "115200 8N1", with " rtscts" for hardware flow control.
std::string SettingsText(const PortSettings& settings) {
  return std::to_string(settings.baud_rate) + " " + std::to_string(settings.data_bits) +
         settings.parity + std::to_string(settings.stop_bits) +
         (settings.hardware_flow_control ? " rtscts" : "");
}

int64_t RowTimeNs(const LogRow& row) {
  if (const auto* sample = std::get_if<LogSample>(&row)) return sample->device_time_ns;
  return std::get<LogEvent>(row).device_time_ns;
}

// The device's encoder constants against the calibration's.
std::vector<std::string> CompareWithCalibration(const wire::HeaderFrame& header,
                                                const Calibration& calibration) {
  std::vector<std::string> warnings;
  const auto compare = [&](std::string_view what, uint32_t device, double calibrated) {
    if (device != 0 && std::abs(static_cast<double>(device) - calibrated) > 1e-9) {
      warnings.push_back("the device reports " + std::string(what) + " " + std::to_string(device) +
                         ", calibration " + calibration.name + " says " +
                         FormatFixed(calibrated, 3) + "; angles use the calibration's");
    }
  };
  compare("encoder counts per motor revolution", header.counts_per_motor_rev,
          calibration.encoder_counts_per_motor_rev);
  compare("gearbox ratio", header.gearbox_ratio, calibration.gearbox_ratio);
  compare("spur gear ratio", header.spur_gear_ratio, calibration.spur_gear_ratio);
  return warnings;
}

// What a port's name pointed at when it was opened. A pseudo-terminal never comes back
// under its own name (a new one that gets the same number belongs to whoever opened it),
// so after a loss it is reopened only through a symlink replaced since (an emulator's
// link re-pointed at its new pty, as udev re-creates /dev/serial/by-id links on replug).
// A link counts as replaced when its inode, its target or either of its timestamps (to
// the nanosecond) differs: ext4 hands a link removed and re-created at once the same
// inode, and within the same second the same seconds-resolution times.
struct PortIdentity {
  bool pseudo_terminal = false;
  bool symlink = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string target;
  timespec modified{};
  timespec changed{};
};

bool SameTime(const timespec& a, const timespec& b) {
  return a.tv_sec == b.tv_sec && a.tv_nsec == b.tv_nsec;
}

// The identity of the name itself (not of what it points at).
PortIdentity LinkIdentity(const std::string& port) {
  PortIdentity identity;
  struct stat status {};
  if (::lstat(port.c_str(), &status) != 0) return identity;
  identity.symlink = S_ISLNK(status.st_mode);
  identity.device = status.st_dev;
  identity.inode = status.st_ino;
  identity.modified = status.st_mtim;
  identity.changed = status.st_ctim;
  std::error_code error;
  if (identity.symlink) identity.target = std::filesystem::read_symlink(port, error).string();
  return identity;
}

PortIdentity IdentifyPort(const std::string& port) {
  PortIdentity identity = LinkIdentity(port);
  identity.pseudo_terminal = IsPseudoTerminal(port);
  return identity;
}

bool LinkReplaced(const PortIdentity& before, const PortIdentity& now) {
  return now.symlink && (now.inode != before.inode || now.device != before.device ||
                         now.target != before.target ||
                         !SameTime(now.modified, before.modified) ||
                         !SameTime(now.changed, before.changed));
}

// kInvalidArgument when `path` names anything (a dangling symlink included) and may not be
// replaced: the capture's `what` ("log", "journal") would replace an earlier recording.
bool MayReopen(const std::string& port, const PortIdentity& before) {
  std::error_code error;
  if (!std::filesystem::exists(port, error)) return IsStableId(port);
  if (!before.pseudo_terminal) return true;
  return LinkReplaced(before, LinkIdentity(port));
}

}  // namespace

// ---------------------------------------------------------------------------------------
// decoding: bytes -> rows

StreamDecoder::StreamDecoder(const Calibration& calibration) : calibration_(&calibration) {}

void StreamDecoder::Feed(std::span<const uint8_t> bytes, int64_t host_time_ns,
                         std::vector<LogRow>& rows) {
  frames_.clear();
  parser_.Feed(bytes, host_time_ns, frames_);
  for (const ReceivedFrame& frame : frames_) Accept(frame, rows);
}

void StreamDecoder::LinkLost(int64_t host_time_ns) {
  parser_.Reset();
  if (!link_lost_host_ns_) link_lost_host_ns_ = host_time_ns;
}

void StreamDecoder::LinkRestored(int64_t host_time_ns) {
  ++counters_.reconnects;
  reconnect_pending_ = true;
  link_down_ns_ = link_lost_host_ns_ ? host_time_ns - *link_lost_host_ns_ : 0;
  link_lost_host_ns_.reset();
}

// Rows come out in the log's order (docs/formats.md): by device time, and at one instant
// the events before the sample. A sample is therefore held back until a row of a later
// instant arrives (samples are strictly increasing, so at most one waits).
void StreamDecoder::Emit(LogRow row, std::vector<LogRow>& rows) {
  const int64_t row_ns = RowTimeNs(row);
  last_row_ns_ = row_ns;
  if (held_sample_ && held_sample_->device_time_ns < row_ns) Finish(rows);
  if (auto* sample = std::get_if<LogSample>(&row)) {
    ++counters_.samples;
    last_sample_ns_ = row_ns;
    held_sample_ = std::move(*sample);
    return;
  }
  ++counters_.events;
  rows.push_back(std::move(row));
}

void StreamDecoder::Finish(std::vector<LogRow>& rows) {
  if (!held_sample_) return;
  rows.emplace_back(std::move(*held_sample_));
  held_sample_.reset();
}

bool StreamDecoder::IsRestart(uint32_t sequence, uint32_t device_time_us) const {
  if (!sequence_.last() || !last_device_us_) return false;
  // the sequence number went back (by the tracker's reading: more than half the number
  // space ahead) and the clock went back by more than any stale repeat could
  const uint32_t last_sequence = *sequence_.last();
  const uint32_t last_us = *last_device_us_;
  const bool sequence_back =
      sequence - (last_sequence + 1) >= (uint32_t{1} << 31) && sequence != last_sequence;
  const bool clock_back =
      device_time_us < last_us && last_us - device_time_us > kRestartClockStepUs;
  return sequence_back && clock_back;
}

namespace {

// a data frame's sequence number and device time; nullopt for a command echoed back
std::optional<std::pair<uint32_t, uint32_t>> SequenceAndTime(const wire::Frame& frame) {
  switch (frame.type) {
    case wire::FrameType::kSample:
      return std::pair{frame.sample.sequence, frame.sample.device_time_us};
    case wire::FrameType::kHeader:
      return std::pair{frame.header.sequence, frame.header.device_time_us};
    case wire::FrameType::kEvent:
      return std::pair{frame.event.sequence, frame.event.device_time_us};
    case wire::FrameType::kCommand: return std::nullopt;  // our own commands: not data
  }
  return std::nullopt;
}

}  // namespace

void StreamDecoder::Accept(const ReceivedFrame& received, std::vector<LogRow>& rows) {
  const wire::Frame& frame = received.frame;
  const int64_t host_ns = received.host_time_ns;
  const auto stamp = SequenceAndTime(frame);
  if (!stamp) return;
  const auto [sequence, device_time_us] = *stamp;

  // a controller restart (sequence and clock both start again) is recognised before the
  // stale-frame filter below, which would otherwise drop everything after it
  std::optional<std::string> restart = RebaseAfterRestart(sequence, device_time_us);

  // stale frames (device time not moving forward) are dropped before they touch the
  // sequence tracker, so a repeat after a reconnect does not fake a gap
  const int64_t device_ns = clock_.Unwrap(device_time_us) + clock_offset_ns_;
  const bool is_sample = frame.type == wire::FrameType::kSample;
  if ((is_sample && last_sample_ns_ && device_ns <= *last_sample_ns_) ||
      (last_row_ns_ && device_ns < *last_row_ns_)) {
    ++counters_.duplicates;
    return;
  }

  EmitMarkers(sequence, device_ns, host_ns, std::move(restart), rows);
  last_frame_ns_ = device_ns;
  last_device_us_ = device_time_us;
  EmitFrame(frame, device_ns, host_ns, rows);
}

// on a restart the device clock is rebased so the log's time continues just after its
// last row
std::optional<std::string> StreamDecoder::RebaseAfterRestart(uint32_t sequence,
                                                             uint32_t device_time_us) {
  if (!IsRestart(sequence, device_time_us)) return std::nullopt;
  ++counters_.restarts;
  std::string restart = "controller restarted: sequence " + std::to_string(*sequence_.last()) +
                        " -> " + std::to_string(sequence) + ", device clock " +
                        FormatFixed(static_cast<double>(*last_device_us_) * 1e-6, 3) + " s -> " +
                        FormatFixed(static_cast<double>(device_time_us) * 1e-6, 3) + " s";
  clock_.Reset();
  sequence_.Reset();
  const int64_t continue_ns =
      std::max(last_row_ns_.value_or(0), last_frame_ns_.value_or(0)) + kNanosecondsPerMicrosecond;
  clock_offset_ns_ =
      continue_ns - static_cast<int64_t>(device_time_us) * kNanosecondsPerMicrosecond;
  return restart;
}

// markers of what happened between the previous frame and this one, halfway between:
// a reconnect, a restart, a gap in the sequence
void StreamDecoder::EmitMarkers(uint32_t sequence, int64_t device_ns, int64_t host_ns,
                                std::optional<std::string> restart, std::vector<LogRow>& rows) {
  const int64_t marker_ns =
      std::max(last_frame_ns_ ? *last_frame_ns_ + (device_ns - *last_frame_ns_) / 2 : device_ns,
               last_row_ns_.value_or(device_ns));
  if (reconnect_pending_) {
    reconnect_pending_ = false;
    Emit(LogEvent{marker_ns, host_ns, LogEventKind::kReconnect,
                  "port reopened after " + FormatFixed(SecondsFromNs(link_down_ns_), 2) +
                      " s without link"},
         rows);
  }
  if (restart) Emit(LogEvent{marker_ns, host_ns, LogEventKind::kNote, std::move(*restart)}, rows);
  if (const std::optional<SequenceGap> gap = sequence_.Observe(sequence)) {
    ++counters_.gaps;
    counters_.missing_frames += gap->missing;
    const uint32_t last_missing = gap->first_missing + gap->missing - 1;
    std::string detail =
        Plural(gap->missing, "frame") + ", sequence " + std::to_string(gap->first_missing);
    if (gap->missing > 1) detail += ".." + std::to_string(last_missing);
    Emit(LogEvent{marker_ns, host_ns, LogEventKind::kGap, std::move(detail)}, rows);
  }
}

// the frame itself: a sample, the device's header (kept once), an event
void StreamDecoder::EmitFrame(const wire::Frame& frame, int64_t device_ns, int64_t host_ns,
                              std::vector<LogRow>& rows) {
  switch (frame.type) {
    case wire::FrameType::kSample: {
      LogSample sample = SampleFromFrame(frame.sample, device_ns, host_ns, *calibration_);
      led_on_ = sample.led_on;
      last_vertebra_rad_ = sample.vertebra_rad;
      Emit(std::move(sample), rows);
      break;
    }
    case wire::FrameType::kHeader:
      if (!device_header_) device_header_ = frame.header;
      break;
    case wire::FrameType::kEvent:
      if (std::optional<LogEvent> event = EventFromFrame(frame.event, device_ns, host_ns)) {
        if (event->kind == LogEventKind::kTestEnd) test_ended_ = true;
        if (event->kind == LogEventKind::kLedOn) led_on_ = true;
        if (event->kind == LogEventKind::kLedOff) led_on_ = false;
        Emit(std::move(*event), rows);
      }
      break;
    case wire::FrameType::kCommand: break;
  }
}

void AddDeviceMetadata(const wire::HeaderFrame& header, LogHeader& log_header) {
  log_header.metadata["device_protocol"] = std::to_string(header.protocol_version);
  log_header.metadata["device_counts_per_motor_rev"] = std::to_string(header.counts_per_motor_rev);
  log_header.metadata["device_gearbox_ratio"] = std::to_string(header.gearbox_ratio);
  log_header.metadata["device_spur_gear_ratio"] = std::to_string(header.spur_gear_ratio);
}

LogHeader CaptureLogHeader(const Calibration& calibration, std::string source,
                           std::string_view port_settings, std::string_view journal_name,
                           const std::optional<wire::HeaderFrame>& device,
                           const std::optional<wire::CommandFrame>& start) {
  LogHeader header;
  header.calibration = calibration.name;
  header.source = std::move(source);
  header.metadata["port_settings"] = std::string(port_settings);
  header.metadata["journal"] = std::string(journal_name);
  if (device) {
    header.device = device->firmware;
    AddDeviceMetadata(*device, header);
  }
  if (start) AddStartMetadata(*start, header);
  return header;
}

void AddStartMetadata(const wire::CommandFrame& start, LogHeader& log_header) {
  const auto group = static_cast<CableGroup>(start.args[0]);
  log_header.metadata["commanded_pulled_group"] =
      group == CableGroup::kHR || group == CableGroup::kHL ? std::string(CableGroupName(group))
                                                           : std::to_string(start.args[0]);
  log_header.metadata["commanded_bend_percent"] = FormatFixed(start.args[1] / 10.0, 1);
  log_header.metadata["commanded_ramp_deg"] = FormatFixed(start.args[2] / 1000.0, 3);
  log_header.metadata["commanded_ramp_s"] = FormatFixed(start.args[3] / 1000.0, 3);
}

// ---------------------------------------------------------------------------------------
// options and summaries

std::filesystem::path CaptureOptions::JournalPath() const {
  if (!journal_path.empty()) return journal_path;
  std::filesystem::path path = log_path;
  path += ".journal";
  return path;
}

Status CaptureOptions::Validate() const {
  if (port.empty()) return InvalidArgumentError("capture port: expected a device path or id");
  LIFTOFF_RETURN_IF_ERROR(settings.Validate());
  if (log_path.empty()) return InvalidArgumentError("capture log_path: expected a file to write");
  // the same file under two spellings ("a.csv", "./a.csv") is the same file
  std::error_code journal_error;
  std::error_code log_error;
  const std::filesystem::path journal_resolved =
      std::filesystem::weakly_canonical(JournalPath(), journal_error);
  const std::filesystem::path log_resolved = std::filesystem::weakly_canonical(log_path, log_error);
  if (JournalPath() == log_path ||
      (!journal_error && !log_error && journal_resolved == log_resolved)) {
    return InvalidArgumentError("capture journal_path: must differ from the log path " +
                                log_path.string());
  }
  const auto positive = [](std::string_view field, double value) {
    return value > 0.0 && std::isfinite(value)
               ? Status::Ok()
               : InvalidArgumentError("capture " + std::string(field) + ": expected > 0, got " +
                                      std::to_string(value));
  };
  const auto non_negative = [](std::string_view field, double value) {
    return value >= 0.0 && std::isfinite(value)
               ? Status::Ok()
               : InvalidArgumentError("capture " + std::string(field) + ": expected >= 0, got " +
                                      std::to_string(value));
  };
  LIFTOFF_RETURN_IF_ERROR(positive("reconnect_poll_s", reconnect_poll_s));
  LIFTOFF_RETURN_IF_ERROR(positive("read_timeout_ms", read_timeout_ms));
  LIFTOFF_RETURN_IF_ERROR(positive("status_interval_s", status_interval_s));
  LIFTOFF_RETURN_IF_ERROR(positive("flush_interval_ms", flush_interval_ms));
  LIFTOFF_RETURN_IF_ERROR(non_negative("max_duration_s", max_duration_s));
  LIFTOFF_RETURN_IF_ERROR(non_negative("first_frame_timeout_s", first_frame_timeout_s));
  LIFTOFF_RETURN_IF_ERROR(non_negative("header_wait_s", header_wait_s));
  if (send_start && start_command.command != wire::CommandKind::kStart) {
    return InvalidArgumentError("capture start_command: expected a START command");
  }
  return Status::Ok();
}

std::string CaptureSummary::Brief() const {
  std::string brief = Plural(frames, "frame") + " (" + Plural(samples, "sample") + ", " +
                      Plural(events, "event") + ") in " + FormatFixed(duration_s, 1) + " s, " +
                      Plural(checksum_errors, "checksum failure") + ", " + Plural(gaps, "gap");
  if (missing_frames > 0) brief += " (" + Plural(missing_frames, "frame") + " missing)";
  brief += ", " + Plural(reconnects, "reconnect");
  if (malformed_frames > 0) brief += ", " + std::to_string(malformed_frames) + " malformed";
  if (duplicates > 0) brief += ", " + Plural(duplicates, "stale frame") + " dropped";
  if (!stopped_by.empty()) brief += "; stopped by " + stopped_by;
  return brief;
}

// ---------------------------------------------------------------------------------------
// the capture loop

namespace {

// The log side of a capture: rows wait in memory until the header is known, then stream.
class LogSink {
 public:
  LogSink(const CaptureOptions& options, const Calibration& calibration)
      : options_(options), calibration_(calibration) {}

  Status Add(std::vector<LogRow>& rows) {
    if (!writer_.is_open()) {
      for (LogRow& row : rows) pending_.push_back(std::move(row));
      rows.clear();
      return Status::Ok();
    }
    for (const LogRow& row : rows) LIFTOFF_RETURN_IF_ERROR(Write(row));
    rows.clear();
    return Status::Ok();
  }

  // Opens the log with what is known of the device, and writes the rows that waited.
  Status Open(const StreamDecoder& decoder) {
    const LogHeader header = CaptureLogHeader(
        calibration_, "capture " + options_.port, SettingsText(options_.settings),
        options_.JournalPath().filename().string(), decoder.device_header(),
        options_.send_start ? std::optional(options_.start_command) : std::nullopt);
    // the log appears once the device is known: it must still be new then
    LIFTOFF_RETURN_IF_ERROR(
        RefuseToReplace(options_.log_path, "the log of an earlier recording?",
                        options_.replace_existing));
    LIFTOFF_RETURN_IF_ERROR(CreateParentFolder(options_.log_path));
    LIFTOFF_RETURN_IF_ERROR(writer_.Open(options_.log_path, header));
    for (const LogRow& row : pending_) LIFTOFF_RETURN_IF_ERROR(Write(row));
    pending_.clear();
    pending_.shrink_to_fit();
    return Status::Ok();
  }

  bool is_open() const { return writer_.is_open(); }
  Status Flush() { return writer_.Flush(); }
  Status Close() { return writer_.Close(); }

 private:
  Status Write(const LogRow& row) {
    if (const auto* sample = std::get_if<LogSample>(&row)) return writer_.Append(*sample);
    return writer_.Append(std::get<LogEvent>(row));
  }

  const CaptureOptions& options_;
  const Calibration& calibration_;
  ControllerLogWriter writer_;
  std::vector<LogRow> pending_;
};

class Capture {
 public:
  Capture(const CaptureOptions& options, const Calibration& calibration,
          const std::atomic<bool>& stop, const std::function<void(const CaptureStatus&)>& on_status)
      : options_(options),
        calibration_(calibration),
        stop_(stop),
        on_status_(on_status),
        decoder_(calibration),
        log_(options, calibration) {}

  Result<CaptureSummary> Run() {
    started_ns_ = MonotonicNowNs();
    // an earlier recording is never replaced unless asked: checked before anything is touched
    LIFTOFF_RETURN_IF_ERROR(
        RefuseToReplace(options_.log_path, "the log of an earlier recording?",
                        options_.replace_existing));
    LIFTOFF_RETURN_IF_ERROR(
        RefuseToReplace(options_.JournalPath(), "the journal of an earlier recording?",
                        options_.replace_existing));
    // the port first: a wrong name fails before any file is made
    auto port = OpenSerialPort(options_.port, options_.settings);
    if (!port.ok()) return port.status();
    port_ = std::move(port).value();
    port_identity_ = IdentifyPort(options_.port);

    JournalHeader header;
    header.port = options_.port;
    header.settings = SettingsText(options_.settings);
    header.start_time_ns = HostNowNs();
    JournalWriter::Options journal_options;
    journal_options.replace_existing = options_.replace_existing;
    LIFTOFF_RETURN_IF_ERROR(journal_.Open(options_.JournalPath(), header, journal_options));

    const Status looped = Loop();
    // whatever happened, everything received reaches the disk
    Status finished = looped;
    std::vector<LogRow> last_rows;
    decoder_.Finish(last_rows);
    const Status added = log_.Add(last_rows);
    if (finished.ok()) finished = added;
    if (!log_.is_open()) {
      const Status opened = log_.Open(decoder_);
      if (finished.ok()) finished = opened;
    }
    const Status log_closed = log_.Close();
    const Status journal_closed = journal_.Close();
    if (port_) port_->Close();
    if (finished.ok()) finished = log_closed;
    if (finished.ok()) finished = journal_closed;
    if (!finished.ok()) return finished;
    return Summary();
  }

 private:
  double ElapsedS() const { return SecondsFromNs(MonotonicNowNs() - started_ns_); }

  Status Loop() {
    if (options_.send_start) LIFTOFF_RETURN_IF_ERROR(SendStart());
    std::array<uint8_t, 16 * 1024> buffer;
    std::vector<LogRow> rows;
    int64_t last_flush_ns = MonotonicNowNs();
    next_status_s_ = options_.status_interval_s;
    while (true) {
      // reasons to stop
      if (stop_.load()) {
        stopped_by_ = "stop request";
        return Status::Ok();
      }
      if (options_.max_duration_s > 0 && ElapsedS() >= options_.max_duration_s) {
        stopped_by_ = "max duration";
        return Status::Ok();
      }
      if (options_.first_frame_timeout_s > 0 && decoder_.parser_stats().frames == 0 &&
          ElapsedS() >= options_.first_frame_timeout_s) {
        stopped_by_ = "first-frame timeout";
        return TimeoutError(options_.port + ": no frame arrived within " +
                            FormatFixed(options_.first_frame_timeout_s, 1) + " s (" +
                            Plural(decoder_.parser_stats().bytes, "byte") +
                            " received; is the baud rate right and the controller running?)");
      }

      // read, or wait for the port to come back
      if (port_) {
        Result<size_t> read = port_->Read(buffer, ReadTimeoutMs());
        if (!read.ok()) {
          LIFTOFF_RETURN_IF_ERROR(LinkLost(read.status()));
        } else if (*read > 0) {
          // journal first: every byte is on its way to disk before it is parsed
          const int64_t host_ns = HostNowNs();
          const std::span<const uint8_t> bytes(buffer.data(), *read);
          LIFTOFF_RETURN_IF_ERROR(journal_.Append(bytes, host_ns));
          decoder_.Feed(bytes, host_ns, rows);
          if (first_frame_s_ < 0 && decoder_.parser_stats().frames > 0) first_frame_s_ = ElapsedS();
        }
      } else {
        LIFTOFF_RETURN_IF_ERROR(TryReopen());
      }

      // rows to the log (which opens once the device is known)
      if (!log_.is_open() &&
          (decoder_.device_header() ||
           (first_frame_s_ >= 0 && ElapsedS() - first_frame_s_ >= options_.header_wait_s))) {
        LIFTOFF_RETURN_IF_ERROR(log_.Open(decoder_));
      }
      LIFTOFF_RETURN_IF_ERROR(log_.Add(rows));
      if (MonotonicNowNs() - last_flush_ns >= NsFromSeconds(options_.flush_interval_ms / 1000.0)) {
        last_flush_ns = MonotonicNowNs();
        LIFTOFF_RETURN_IF_ERROR(journal_.Flush());
        LIFTOFF_RETURN_IF_ERROR(log_.Flush());
      }
      ReportStatus();
      if (options_.stop_on_test_end && decoder_.test_ended()) {
        stopped_by_ = "test end";
        return Status::Ok();
      }
    }
  }

  int ReadTimeoutMs() const {
    return std::max(1, static_cast<int>(std::lround(options_.read_timeout_ms)));
  }

  Status SendStart() {
    char frame[wire::kMaxFrameBytes];
    const size_t size = wire::EncodeCommand(options_.start_command, frame, sizeof frame);
    if (size == 0) return InvalidArgumentError("capture start_command: cannot be encoded");
    const std::span bytes(reinterpret_cast<const uint8_t*>(frame), size);
    LIFTOFF_RETURN_IF_ERROR(journal_.Append(bytes, HostNowNs(), JournalRecordKind::kSent));
    const Status sent = port_->Write(bytes, 1000);
    if (!sent.ok()) return sent.WithContext(options_.port + ": sending the start command");
    return Status::Ok();
  }

  // The device went away: mark it, close the port and start looking for it.
  Status LinkLost(const Status& why) {
    const int64_t host_ns = HostNowNs();
    LIFTOFF_RETURN_IF_ERROR(
        journal_.AppendNote(JournalRecordKind::kLinkLost, why.message(), host_ns));
    LIFTOFF_RETURN_IF_ERROR(journal_.Flush());
    decoder_.LinkLost(host_ns);
    port_->Close();
    port_.reset();
    next_reopen_s_ = ElapsedS();
    return Status::Ok();
  }

  // Reopens the port by the name the user gave, once it exists again.
  Status TryReopen() {
    const double now_s = ElapsedS();
    if (now_s < next_reopen_s_) {
      const double wait_s = std::min({next_reopen_s_ - now_s, options_.read_timeout_ms / 1000.0});
      std::this_thread::sleep_for(std::chrono::nanoseconds(NsFromSeconds(wait_s)));
      return Status::Ok();
    }
    next_reopen_s_ = now_s + options_.reconnect_poll_s;
    if (!MayReopen(options_.port, port_identity_)) {
      reopen_problem_ = options_.port + " has not come back";
      return Status::Ok();
    }
    auto port = OpenSerialPort(options_.port, options_.settings);
    if (!port.ok()) {  // not back yet, or not ready: keep polling
      reopen_problem_ = port.status().message();
      return Status::Ok();
    }
    port_ = std::move(port).value();
    port_identity_ = IdentifyPort(options_.port);
    const int64_t host_ns = HostNowNs();
    LIFTOFF_RETURN_IF_ERROR(journal_.AppendNote(JournalRecordKind::kLinkRestored,
                                                "reopened " + port_->name(), host_ns));
    decoder_.LinkRestored(host_ns);
    return Status::Ok();
  }

  void ReportStatus() {
    if (!on_status_) return;
    const double now_s = ElapsedS();
    if (now_s < next_status_s_) return;
    const ParserStats& parser = decoder_.parser_stats();
    CaptureStatus status;
    status.bytes = parser.bytes;
    status.frames = parser.frames;
    const double interval_s = now_s - last_status_s_;
    status.rate_hz = interval_s > 0
                         ? static_cast<double>(parser.frames - last_status_frames_) / interval_s
                         : 0.0;
    status.checksum_errors = parser.checksum_errors;
    status.gaps = decoder_.counters().gaps;
    status.led_on = decoder_.led_on();
    status.last_vertebra_rad = decoder_.last_vertebra_rad();
    status.connected = port_ != nullptr;
    status.elapsed_s = now_s;
    last_status_s_ = now_s;
    last_status_frames_ = parser.frames;
    next_status_s_ = now_s + options_.status_interval_s;
    on_status_(status);
  }

  CaptureSummary Summary() const {
    const ParserStats& parser = decoder_.parser_stats();
    const StreamDecoder::Counters& counters = decoder_.counters();
    CaptureSummary summary;
    summary.log_path = options_.log_path;
    summary.journal_path = options_.JournalPath();
    if (decoder_.device_header()) {
      summary.device = decoder_.device_header()->firmware;
      summary.warnings = CompareWithCalibration(*decoder_.device_header(), calibration_);
    }
    summary.bytes = parser.bytes;
    summary.frames = parser.frames;
    summary.samples = counters.samples;
    summary.events = counters.events;
    summary.checksum_errors = parser.checksum_errors;
    summary.malformed_frames = parser.malformed_frames;
    summary.garbage_bytes = parser.garbage_bytes;
    summary.gaps = counters.gaps;
    summary.missing_frames = counters.missing_frames;
    summary.duplicates = counters.duplicates;
    summary.reconnects = counters.reconnects;
    summary.duration_s = ElapsedS();
    summary.stopped_by = stopped_by_;
    if (!port_)
      summary.warnings.push_back("the port was lost and not reopened: " + reopen_problem_);
    return summary;
  }

  const CaptureOptions& options_;
  const Calibration& calibration_;
  const std::atomic<bool>& stop_;
  const std::function<void(const CaptureStatus&)>& on_status_;
  StreamDecoder decoder_;
  LogSink log_;
  JournalWriter journal_;
  std::unique_ptr<SerialPort> port_;
  PortIdentity port_identity_;
  std::string reopen_problem_;  // why the last reopen attempt failed
  int64_t started_ns_ = 0;
  double first_frame_s_ = -1.0;
  double next_reopen_s_ = 0.0;
  double next_status_s_ = 0.0;
  double last_status_s_ = 0.0;
  int64_t last_status_frames_ = 0;
  std::string stopped_by_;
};

}  // namespace

Result<CaptureSummary> RunCapture(const CaptureOptions& options, const Calibration& calibration,
                                  const std::atomic<bool>& stop,
                                  const std::function<void(const CaptureStatus&)>& on_status) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  Capture capture(options, calibration, stop, on_status);
  return capture.Run();
}

}  // namespace liftoff::capture
