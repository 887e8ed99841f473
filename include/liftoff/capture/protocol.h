// The host side of the serial protocol v1 (docs/protocol.md): a streaming frame parser
// that survives any byte sequence, the unwrapping of the controller's 32-bit microsecond
// clock, sequence-gap detection, and the conversion of frames into controller-log rows.
// The frame format itself lives in wire_format.h, shared with the firmware.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liftoff/capture/wire_format.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"

namespace liftoff::capture {

/// What a FrameParser has seen. Every byte fed lands in exactly one of frame_bytes,
/// rejected_bytes, garbage_bytes or FrameParser::pending_bytes():
///   bytes == frame_bytes + rejected_bytes + garbage_bytes + pending_bytes()
/// and frames == samples + headers + events + commands.
struct ParserStats {
  /// Bytes fed.
  int64_t bytes = 0;
  /// Frames accepted (CRC correct, every field valid) and emitted.
  int64_t frames = 0;
  /// Accepted frames by type.
  int64_t samples = 0;
  int64_t headers = 0;
  int64_t events = 0;
  int64_t commands = 0;
  /// Complete lines whose CRC did not match: corrupted frames, never emitted.
  int64_t checksum_errors = 0;
  /// Lines that began with '$' but are not frames: no checksum, a bad field, an unknown
  /// type, longer than wire::kMaxFrameBytes, or cut off by the next '$' before their '\n'.
  int64_t malformed_frames = 0;
  /// Bytes outside any frame: before a '$', or between a '\n' and the next '$'.
  int64_t garbage_bytes = 0;
  /// Bytes of accepted frames, '$' to '\n' inclusive.
  int64_t frame_bytes = 0;
  /// Bytes of rejected lines (checksum errors and malformed frames), '$' to the end.
  int64_t rejected_bytes = 0;

  /// "1200 frames (1190 samples, 2 headers, 8 events, 0 commands); checksum errors 1,
  /// malformed 0, garbage bytes 17; 84211 bytes".
  std::string Brief() const;
};

/// A frame and the host time of its arrival.
struct ReceivedFrame {
  wire::Frame frame;
  /// Host clock (ns, as passed to Feed) of the chunk that held the frame's '\n'.
  int64_t host_time_ns = 0;
};

/// Splits a byte stream into frames. A frame starts at '$' and ends at '\n' (a '\r'
/// before it is ignored); a '$' inside a line abandons it and starts a new frame, so the
/// parser resynchronises at the first intact frame after any corruption. Lines longer
/// than wire::kMaxFrameBytes are dropped. Frames whose CRC does not match are never
/// emitted. Memory is one fixed line buffer; every byte costs O(1) (a line end costs one
/// decode), so no byte sequence can stall it.
class FrameParser {
 public:
  /// Parses `bytes` (any split: a frame may straddle calls) and appends every complete,
  /// valid frame to `out`, stamped with `host_time_ns`.
  void Feed(std::span<const uint8_t> bytes, int64_t host_time_ns, std::vector<ReceivedFrame>& out);
  /// Drops a partly received frame (e.g. after the link was lost, so its head is not
  /// joined to bytes from after the gap); it counts as malformed.
  void Reset();

  const ParserStats& stats() const { return stats_; }
  /// Bytes of a frame begun but not yet ended (0 between frames).
  int64_t pending_bytes() const;

 private:
  enum class State { kBetweenFrames, kInFrame, kTooLong };
  // Ends the current line: decodes it, counts it, emits it when valid.
  void FinishLine(int64_t host_time_ns, std::vector<ReceivedFrame>& out);
  // Abandons the current line (cut off or too long) as malformed.
  void AbandonLine();

  State state_ = State::kBetweenFrames;
  char line_[wire::kMaxFrameBytes] = {};
  size_t line_size_ = 0;
  // bytes of an over-long line seen so far (all dropped)
  int64_t too_long_bytes_ = 0;
  wire::Frame decoded_;
  ParserStats stats_;
};

/// Unwraps the controller's 32-bit microsecond clock (wraps every 2^32 us, 71.6 minutes)
/// into int64 nanoseconds. Each reading is placed within +-2^31 us (35.8 minutes) of the
/// previous one: a step back by more than 2^31 us is a wrap (so is a controller reset to
/// a small time after a large one), a step back by less is reported as a backward step
/// and the time returned is then earlier than the previous one. Unambiguous as long as
/// consecutive readings are less than 35.8 minutes apart (the controller sends a frame at
/// least once a second).
class DeviceClock {
 public:
  /// The unwrapped time of `device_time_us`, ns. The first reading defines the epoch:
  /// it returns device_time_us * 1000.
  int64_t Unwrap(uint32_t device_time_us);
  /// Forgets the history (the next reading starts a new epoch).
  void Reset();

  /// Wraps seen (net: a backward step across a wrap point undoes one).
  int64_t wraps() const { return wraps_; }
  /// Readings earlier than the one before (controller reset, or a stale frame).
  int64_t backward_steps() const { return backward_steps_; }

 private:
  std::optional<uint32_t> last_us_;
  int64_t wraps_ = 0;
  int64_t backward_steps_ = 0;
};

/// Frames missing before the frame just observed.
struct SequenceGap {
  /// Sequence number of the first missing frame.
  uint32_t first_missing = 0;
  /// How many frames are missing (first_missing .. first_missing + missing - 1, mod 2^32).
  uint32_t missing = 0;
};

/// Detects lost frames from the controller's sequence numbers (shared by S, H and E
/// frames, wrapping at 2^32).
class SequenceTracker {
 public:
  /// Observes the next frame's sequence number. Returns the gap before it when frames
  /// are missing (a jump forward by less than 2^31, across the wrap too). A repeat of the
  /// last number counts as a duplicate; a jump backwards (a controller reset) counts as a
  /// reset and restarts tracking from `sequence`; both return nullopt.
  std::optional<SequenceGap> Observe(uint32_t sequence);
  /// Forgets the last number (the next one starts tracking afresh, no gap reported).
  void Reset() { last_.reset(); }

  /// Sequence numbers observed.
  int64_t observed() const { return observed_; }
  /// Gaps reported, and the frames missing in them.
  int64_t gaps() const { return gaps_; }
  int64_t missing() const { return missing_; }
  int64_t duplicates() const { return duplicates_; }
  int64_t resets() const { return resets_; }
  std::optional<uint32_t> last() const { return last_; }

 private:
  std::optional<uint32_t> last_;
  int64_t observed_ = 0;
  int64_t gaps_ = 0;
  int64_t missing_ = 0;
  int64_t duplicates_ = 0;
  int64_t resets_ = 0;
};

/// A controller-log sample from a sample frame: sequence, LED, raw counts, and the angles
/// through `calibration` (bend spool = bending motor's shaft angle, rotate shaft, vertebra
/// = shaft / spur gear). The setpoints are not part of a log sample.
LogSample SampleFromFrame(const wire::SampleFrame& frame, int64_t device_time_ns,
                          int64_t host_time_ns, const Calibration& calibration);

/// A controller-log event from an event frame: LED_ON, LED_OFF, TEST_START, TEST_END
/// (detail "done", "stopped" or "code N") and FAULT (detail "text (code N)") map to their
/// kinds; PONG, ACK and NAK become notes ("PONG 42", "ACK START", "NAK START: busy").
/// nullopt for a kind outside the enum. Control characters in text become '?'.
std::optional<LogEvent> EventFromFrame(const wire::EventFrame& frame, int64_t device_time_ns,
                                       int64_t host_time_ns);

}  // namespace liftoff::capture
