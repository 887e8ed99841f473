// libFuzzer target for the serial protocol's host side: arbitrary bytes through
// FrameParser (in chunks whose sizes come from the first input byte) and through
// wire::DecodeLine. Any crash, sanitizer report or broken invariant is a finding.
// Build and run: scripts/fuzz [seconds].
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "liftoff/capture/protocol.h"
#include "liftoff/capture/wire_format.h"

#include "fuzz_check.h"

namespace {

using liftoff::capture::FrameParser;
using liftoff::capture::ParserStats;
using liftoff::capture::ReceivedFrame;
namespace wire = liftoff::wire;

bool SameFrame(const wire::Frame& a, const wire::Frame& b) {
  if (a.type != b.type) return false;
  switch (a.type) {
    case wire::FrameType::kSample: {
      const wire::SampleFrame& x = a.sample;
      const wire::SampleFrame& y = b.sample;
      return x.sequence == y.sequence && x.device_time_us == y.device_time_us &&
             x.led_on == y.led_on && x.bend_counts == y.bend_counts &&
             x.rotate_counts == y.rotate_counts &&
             x.bend_setpoint_counts == y.bend_setpoint_counts &&
             x.rotate_setpoint_counts == y.rotate_setpoint_counts;
    }
    case wire::FrameType::kHeader: {
      const wire::HeaderFrame& x = a.header;
      const wire::HeaderFrame& y = b.header;
      return x.sequence == y.sequence && x.device_time_us == y.device_time_us &&
             x.protocol_version == y.protocol_version && std::strcmp(x.firmware, y.firmware) == 0 &&
             x.counts_per_motor_rev == y.counts_per_motor_rev &&
             x.gearbox_ratio == y.gearbox_ratio && x.spur_gear_ratio == y.spur_gear_ratio;
    }
    case wire::FrameType::kEvent: {
      const wire::EventFrame& x = a.event;
      const wire::EventFrame& y = b.event;
      return x.sequence == y.sequence && x.device_time_us == y.device_time_us && x.kind == y.kind &&
             x.arg == y.arg && std::strcmp(x.text, y.text) == 0;
    }
    case wire::FrameType::kCommand:
      return a.command.command == b.command.command &&
             std::memcmp(a.command.args, b.command.args, sizeof(a.command.args)) == 0;
  }
  return false;
}

// A decoded frame re-encodes (canonically) to a line that decodes to the same frame, and
// that line alone through a fresh parser yields exactly that frame.
void CheckRoundTrip(const wire::Frame& frame) {
  char text[wire::kMaxFrameBytes];
  const size_t size = wire::EncodeFrame(frame, text, sizeof(text));
  FUZZ_CHECK(size > 0 && size <= wire::kMaxFrameBytes);
  FUZZ_CHECK(text[0] == '$' && text[size - 1] == '\n');
  wire::Frame again;
  FUZZ_CHECK(wire::DecodeLine(text, size - 1, &again) == wire::DecodeError::kOk);
  FUZZ_CHECK(SameFrame(frame, again));
  FrameParser parser;
  std::vector<ReceivedFrame> out;
  parser.Feed({reinterpret_cast<const uint8_t*>(text), size}, 7, out);
  FUZZ_CHECK(out.size() == 1 && SameFrame(out[0].frame, frame) && out[0].host_time_ns == 7);
}

void CheckStats(const FrameParser& parser, size_t emitted, size_t fed) {
  const ParserStats& s = parser.stats();
  FUZZ_CHECK(s.bytes == static_cast<int64_t>(fed));
  FUZZ_CHECK(s.frames == static_cast<int64_t>(emitted));
  FUZZ_CHECK(s.frames == s.samples + s.headers + s.events + s.commands);
  FUZZ_CHECK(s.bytes ==
             s.frame_bytes + s.rejected_bytes + s.garbage_bytes + parser.pending_bytes());
  FUZZ_CHECK(parser.pending_bytes() >= 0);
}

bool SameStats(const ParserStats& a, const ParserStats& b) {
  return a.bytes == b.bytes && a.frames == b.frames && a.samples == b.samples &&
         a.headers == b.headers && a.events == b.events && a.commands == b.commands &&
         a.checksum_errors == b.checksum_errors && a.malformed_frames == b.malformed_frames &&
         a.garbage_bytes == b.garbage_bytes && a.frame_bytes == b.frame_bytes &&
         a.rejected_bytes == b.rejected_bytes;
}

liftoff::Calibration TestCalibration() {
  liftoff::Calibration calibration;
  calibration.encoder_counts_per_motor_rev = 12;
  calibration.gearbox_ratio = 1000;
  calibration.spur_gear_ratio = 4;
  return calibration;
}

// Writes the correct CRC after every "$...*" that has 4 bytes after its '*', so the
// fuzzer gets past the checksum and into the fields.
void RepairChecksums(std::vector<uint8_t>& bytes) {
  size_t start = bytes.size();  // index of the current '$', or size() when none
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (bytes[i] == '$') {
      start = i;
    } else if (bytes[i] == '\n') {
      start = bytes.size();
    } else if (bytes[i] == '*' && start < i && i + 4 < bytes.size()) {
      const uint16_t crc =
          wire::Crc16(reinterpret_cast<const char*>(bytes.data() + start + 1), i - start - 1);
      static const char kHex[] = "0123456789ABCDEF";
      for (size_t k = 0; k < 4; ++k) {
        bytes[i + 1 + k] = static_cast<uint8_t>(kHex[(crc >> (12 - 4 * k)) & 0xF]);
      }
      start = bytes.size();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  // first byte: bit 7 repairs checksums, bits 0..6 seed the chunk sizes
  std::vector<uint8_t> bytes(data + 1, data + size);
  if (data[0] & 0x80) RepairChecksums(bytes);
  const std::span<const uint8_t> input(bytes);

  // the whole input (and its first line) as one line
  wire::Frame frame;
  if (wire::DecodeLine(reinterpret_cast<const char*>(input.data()), input.size(), &frame) ==
      wire::DecodeError::kOk) {
    CheckRoundTrip(frame);
  }

  // the parser, in chunks of 1..64 bytes drawn from a generator seeded by the first byte
  FrameParser chunked;
  std::vector<ReceivedFrame> chunked_out;
  uint32_t state = (data[0] & 0x7Fu) * 2654435761u + 1;
  int64_t host_time_ns = 0;
  for (size_t at = 0; at < input.size();) {
    state = state * 1664525u + 1013904223u;
    const size_t chunk = std::min<size_t>(1 + (state >> 26), input.size() - at);
    const size_t before = chunked_out.size();
    chunked.Feed(input.subspan(at, chunk), ++host_time_ns, chunked_out);
    for (size_t i = before; i < chunked_out.size(); ++i) {
      FUZZ_CHECK(chunked_out[i].host_time_ns == host_time_ns);
    }
    at += chunk;
    CheckStats(chunked, chunked_out.size(), at);
  }

  // the same bytes in one piece give the same frames and the same counts
  FrameParser whole;
  std::vector<ReceivedFrame> whole_out;
  whole.Feed(input, 0, whole_out);
  CheckStats(whole, whole_out.size(), input.size());
  FUZZ_CHECK(SameStats(whole.stats(), chunked.stats()));
  FUZZ_CHECK(whole.pending_bytes() == chunked.pending_bytes());
  FUZZ_CHECK(whole_out.size() == chunked_out.size());
  for (size_t i = 0; i < whole_out.size(); ++i) {
    FUZZ_CHECK(SameFrame(whole_out[i].frame, chunked_out[i].frame));
  }

  // every emitted frame round-trips, and the rest of the host side takes it
  static const liftoff::Calibration calibration = TestCalibration();
  liftoff::capture::DeviceClock clock;
  liftoff::capture::SequenceTracker tracker;
  for (const ReceivedFrame& received : whole_out) {
    CheckRoundTrip(received.frame);
    const wire::Frame& f = received.frame;
    if (f.type == wire::FrameType::kCommand) continue;
    const uint32_t sequence = f.type == wire::FrameType::kSample   ? f.sample.sequence
                              : f.type == wire::FrameType::kHeader ? f.header.sequence
                                                                   : f.event.sequence;
    const uint32_t time_us = f.type == wire::FrameType::kSample   ? f.sample.device_time_us
                             : f.type == wire::FrameType::kHeader ? f.header.device_time_us
                                                                  : f.event.device_time_us;
    const std::optional<uint32_t> last = tracker.last();
    if (const auto gap = tracker.Observe(sequence)) {
      FUZZ_CHECK(last && gap->first_missing == *last + 1 && gap->missing >= 1);
      FUZZ_CHECK(static_cast<uint32_t>(gap->first_missing + gap->missing) == sequence);
    }
    const int64_t time_ns = clock.Unwrap(time_us);
    FUZZ_CHECK(time_ns % 1000 == 0);
    FUZZ_CHECK(static_cast<uint32_t>((time_ns / 1000) & 0xFFFFFFFF) == time_us);
    if (f.type == wire::FrameType::kSample) {
      const liftoff::LogSample sample =
          liftoff::capture::SampleFromFrame(f.sample, time_ns, 0, calibration);
      FUZZ_CHECK(std::isfinite(sample.bend_spool_rad) && std::isfinite(sample.vertebra_rad));
    } else if (f.type == wire::FrameType::kEvent) {
      const auto event = liftoff::capture::EventFromFrame(f.event, time_ns, 0);
      FUZZ_CHECK(event.has_value());
      for (const char c : event->detail) FUZZ_CHECK(c != '\n' && c != '\r');
    }
  }
  return 0;
}
