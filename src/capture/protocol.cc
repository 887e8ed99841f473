#include "liftoff/capture/protocol.h"

#include <sstream>

namespace liftoff::capture {

std::string ParserStats::Brief() const {
  std::ostringstream out;
  out << frames << " frames (" << samples << " samples, " << headers << " headers, " << events
      << " events, " << commands << " commands); checksum errors " << checksum_errors
      << ", malformed " << malformed_frames << ", garbage bytes " << garbage_bytes << "; " << bytes
      << " bytes";
  return out.str();
}

// ---------------------------------------------------------------------------------------
// FrameParser

void FrameParser::Feed(std::span<const uint8_t> bytes, int64_t host_time_ns,
                       std::vector<ReceivedFrame>& out) {
  for (const uint8_t byte : bytes) {
    ++stats_.bytes;
    const char c = static_cast<char>(byte);
    // '$' always starts a frame: whatever came before it is given up
    if (c == '$') {
      if (state_ != State::kBetweenFrames) AbandonLine();
      state_ = State::kInFrame;
      line_[0] = c;
      line_size_ = 1;
      continue;
    }
    switch (state_) {
      case State::kBetweenFrames: ++stats_.garbage_bytes; break;
      case State::kInFrame:
        if (c == '\n') {
          FinishLine(host_time_ns, out);
        } else if (line_size_ == sizeof(line_)) {
          // no frame is this long: drop bytes until the next '\n' or '$'
          state_ = State::kTooLong;
          too_long_bytes_ = static_cast<int64_t>(line_size_) + 1;
        } else {
          line_[line_size_++] = c;
        }
        break;
      case State::kTooLong:
        ++too_long_bytes_;
        if (c == '\n') AbandonLine();
        break;
    }
  }
}

void FrameParser::Reset() {
  if (state_ != State::kBetweenFrames) AbandonLine();
}

int64_t FrameParser::pending_bytes() const {
  switch (state_) {
    case State::kInFrame: return static_cast<int64_t>(line_size_);
    case State::kTooLong: return too_long_bytes_;
    case State::kBetweenFrames: break;
  }
  return 0;
}

void FrameParser::FinishLine(int64_t host_time_ns, std::vector<ReceivedFrame>& out) {
  const int64_t size = static_cast<int64_t>(line_size_) + 1;  // with the '\n'
  const wire::DecodeError error = wire::DecodeLine(line_, line_size_, &decoded_);
  state_ = State::kBetweenFrames;
  line_size_ = 0;
  if (error == wire::DecodeError::kBadChecksum) {
    ++stats_.checksum_errors;
    stats_.rejected_bytes += size;
    return;
  }
  if (error != wire::DecodeError::kOk) {
    ++stats_.malformed_frames;
    stats_.rejected_bytes += size;
    return;
  }
  // a frame: count it by type and hand it out
  ++stats_.frames;
  stats_.frame_bytes += size;
  switch (decoded_.type) {
    case wire::FrameType::kSample: ++stats_.samples; break;
    case wire::FrameType::kHeader: ++stats_.headers; break;
    case wire::FrameType::kEvent: ++stats_.events; break;
    case wire::FrameType::kCommand: ++stats_.commands; break;
  }
  out.push_back(ReceivedFrame{decoded_, host_time_ns});
}

void FrameParser::AbandonLine() {
  ++stats_.malformed_frames;
  stats_.rejected_bytes += pending_bytes();
  state_ = State::kBetweenFrames;
  line_size_ = 0;
  too_long_bytes_ = 0;
}

// ---------------------------------------------------------------------------------------
// DeviceClock

int64_t DeviceClock::Unwrap(uint32_t device_time_us) {
  if (last_us_) {
    // the step from the last reading, read as the nearest of the candidates mod 2^32
    const auto step_us = static_cast<int32_t>(device_time_us - *last_us_);
    if (step_us < 0) ++backward_steps_;
    if (step_us >= 0 && device_time_us < *last_us_) ++wraps_;  // forward across 2^32
    if (step_us < 0 && device_time_us > *last_us_) --wraps_;   // backward across 2^32
  }
  last_us_ = device_time_us;
  constexpr int64_t kWrapUs = int64_t{1} << 32;
  return (wraps_ * kWrapUs + static_cast<int64_t>(device_time_us)) * 1000;
}

void DeviceClock::Reset() {
  last_us_.reset();
  wraps_ = 0;
}

// ---------------------------------------------------------------------------------------
// SequenceTracker

std::optional<SequenceGap> SequenceTracker::Observe(uint32_t sequence) {
  ++observed_;
  if (!last_) {
    last_ = sequence;
    return std::nullopt;
  }
  const uint32_t expected = *last_ + 1;  // wraps at 2^32
  const uint32_t ahead = sequence - expected;
  if (ahead == 0) {
    last_ = sequence;
    return std::nullopt;
  }
  if (sequence == *last_) {
    ++duplicates_;
    return std::nullopt;
  }
  last_ = sequence;
  // more than half the number space ahead means behind: the controller restarted
  if (ahead >= (uint32_t{1} << 31)) {
    ++resets_;
    return std::nullopt;
  }
  ++gaps_;
  missing_ += ahead;
  return SequenceGap{expected, ahead};
}

// ---------------------------------------------------------------------------------------
// Frames to log rows

LogSample SampleFromFrame(const wire::SampleFrame& frame, int64_t device_time_ns,
                          int64_t host_time_ns, const Calibration& calibration) {
  LogSample sample;
  sample.device_time_ns = device_time_ns;
  sample.host_time_ns = host_time_ns;
  sample.sequence = frame.sequence;
  sample.led_on = frame.led_on != 0;
  sample.bend_counts = frame.bend_counts;
  sample.rotate_counts = frame.rotate_counts;
  sample.bend_spool_rad =
      calibration.SpoolAngleFromShaftAngle(calibration.ShaftAngleFromCounts(frame.bend_counts));
  sample.rotate_shaft_rad = calibration.ShaftAngleFromCounts(frame.rotate_counts);
  sample.vertebra_rad = calibration.VertebraAngleFromShaftAngle(sample.rotate_shaft_rad);
  return sample;
}

namespace {

// Text from the wire, safe for a one-line log field.
std::string Printable(const char* text) {
  std::string result;
  for (; *text; ++text) {
    const auto byte = static_cast<unsigned char>(*text);
    result += byte < 0x20 || byte == 0x7F ? '?' : *text;
  }
  return result;
}

std::string CommandName(int32_t code) {
  const char* name = code >= 0 && code < static_cast<int32_t>(wire::CommandKind::kCount)
                         ? wire::CommandKindName(static_cast<wire::CommandKind>(code))
                         : nullptr;
  return name ? std::string(name) : "command " + std::to_string(code);
}

}  // namespace

std::optional<LogEvent> EventFromFrame(const wire::EventFrame& frame, int64_t device_time_ns,
                                       int64_t host_time_ns) {
  if (static_cast<uint8_t>(frame.kind) >= static_cast<uint8_t>(wire::EventKind::kCount)) {
    return std::nullopt;
  }
  LogEvent event;
  event.device_time_ns = device_time_ns;
  event.host_time_ns = host_time_ns;
  const std::string text = Printable(frame.text);
  const std::string code = "code " + std::to_string(frame.arg);
  switch (frame.kind) {
    case wire::EventKind::kLedOn:
      event.kind = LogEventKind::kLedOn;
      event.detail = text;
      break;
    case wire::EventKind::kLedOff:
      event.kind = LogEventKind::kLedOff;
      event.detail = text;
      break;
    case wire::EventKind::kTestStart:
      event.kind = LogEventKind::kTestStart;
      event.detail = text;
      break;
    case wire::EventKind::kTestEnd:
      event.kind = LogEventKind::kTestEnd;
      event.detail = frame.arg == 0 ? "done" : frame.arg == 1 ? "stopped" : code;
      break;
    case wire::EventKind::kFault:
      event.kind = LogEventKind::kFault;
      event.detail = text.empty() ? code : text + " (" + code + ")";
      break;
    case wire::EventKind::kPong:
      event.kind = LogEventKind::kNote;
      event.detail = "PONG " + std::to_string(frame.arg);
      break;
    case wire::EventKind::kAck:
      event.kind = LogEventKind::kNote;
      event.detail = "ACK " + CommandName(frame.arg);
      break;
    case wire::EventKind::kNak:
      event.kind = LogEventKind::kNote;
      event.detail = "NAK " + CommandName(frame.arg) + (text.empty() ? "" : ": " + text);
      break;
    case wire::EventKind::kCount: return std::nullopt;
  }
  return event;
}

}  // namespace liftoff::capture
