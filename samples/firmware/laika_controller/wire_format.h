// liftoff serial protocol, version 1: the frame encoder and line decoder shared by the
// host and the controller firmware (samples/firmware/ holds a byte-identical copy). It
// is freestanding C++ (no allocation, no exceptions, no standard library beyond
// <stdint.h> and <stddef.h>) so an Arduino-class controller compiles the very code the
// host's unit tests check. Specification: docs/protocol.md.
//
// One frame is one text line, readable in any serial terminal:
//   $S,1042,5212000,1,-3201,18455,-3200,18460*E2A1\n
//   ^ type, then comma-separated decimal fields, '*', CRC-16/CCITT-FALSE of the bytes
//     between '$' and '*' as 4 upper-case hex digits, '\n'.
// Controller -> host: S sample, H header, E event. Host -> controller: C command.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace liftoff {
namespace wire {

/// Protocol version carried in the header frame.
static constexpr uint32_t kProtocolVersion = 1;
/// Longest frame on the wire, '$' to '\n' inclusive, bytes. Longer lines are garbage.
static constexpr size_t kMaxFrameBytes = 120;
/// Longest text field (firmware name, fault detail), bytes.
static constexpr size_t kMaxTextBytes = 32;

/// Frame types: the character after '$'.
enum class FrameType : char {
  kSample = 'S',   ///< controller -> host: one sample of both motors and the LED
  kHeader = 'H',   ///< controller -> host: firmware identity and encoder constants
  kEvent = 'E',    ///< controller -> host: something happened (LED on, test end, fault)
  kCommand = 'C',  ///< host -> controller: start, stop, zero, ping
};

/// Controller events (the `kind` field of an E frame, on the wire as its name).
enum class EventKind : uint8_t {
  kLedOn = 0,  ///< LED_ON: the sync LED switched on
  kLedOff,     ///< LED_OFF
  kTestStart,  ///< TEST_START: the test sequence began (arg: 0)
  kTestEnd,    ///< TEST_END: the test sequence finished (arg: 0 done, 1 stopped)
  kFault,      ///< FAULT: arg is a fault code, text names it
  kPong,       ///< PONG: reply to PING, arg echoes its token
  kAck,        ///< ACK: a command was accepted, arg is its command code
  kNak,        ///< NAK: a command was refused, arg is its command code, text says why
  kCount
};

/// Host commands (the `command` field of a C frame, on the wire as its name).
enum class CommandKind : uint8_t {
  kStart = 0,  ///< START: run the foot-lifting test with the parameters below
  kStop,       ///< STOP: abort the test, motors hold, LED off
  kZero,       ///< ZERO: set both encoder counts to 0
  kPing,       ///< PING: controller answers PONG with the same token
  kCount
};

/// A sample frame: $S,seq,t_us,led,bend_counts,rotate_counts,bend_setpoint,rotate_setpoint
struct SampleFrame {
  uint32_t sequence = 0;               ///< frame counter shared by S, H and E frames; wraps
  uint32_t device_time_us = 0;         ///< controller clock, microseconds; wraps at 2^32
  uint8_t led_on = 0;                  ///< 0 or 1
  int32_t bend_counts = 0;             ///< bending motor encoder, counts
  int32_t rotate_counts = 0;           ///< rotating motor encoder, counts
  int32_t bend_setpoint_counts = 0;    ///< commanded bending position, counts
  int32_t rotate_setpoint_counts = 0;  ///< commanded rotation position, counts
};

/// A header frame: $H,seq,t_us,protocol,firmware,counts_per_motor_rev,gearbox,spur
/// Sent at boot, after every command and once a second while idle, so a host that
/// connects late still learns the constants.
struct HeaderFrame {
  uint32_t sequence = 0;
  uint32_t device_time_us = 0;
  uint32_t protocol_version = kProtocolVersion;
  char firmware[kMaxTextBytes + 1] = {0};  ///< e.g. "laika-fw 1.0"; no , * $ CR LF
  uint32_t counts_per_motor_rev = 0;       ///< encoder counts per rotor revolution
  uint32_t gearbox_ratio = 0;              ///< motor revolutions per output revolution
  uint32_t spur_gear_ratio = 0;            ///< output revolutions per vertebra revolution
};

/// An event frame: $E,seq,t_us,KIND,arg,text
struct EventFrame {
  uint32_t sequence = 0;
  uint32_t device_time_us = 0;
  EventKind kind = EventKind::kLedOn;
  int32_t arg = 0;
  char text[kMaxTextBytes + 1] = {0};  ///< may be empty; no , * $ CR LF
};

/// A command frame: $C,COMMAND,a,b,c,d (four integer arguments, 0 when unused).
/// START: a = pulled group (2 HR, 3 HL: liftoff::CableGroup), b = bend target in
/// permille of rest length (800 = 80 %), c = ramp amplitude in millidegrees, signed by
/// direction (60000 = +60 deg), d = ramp duration in milliseconds (40000).
/// PING: a = token. STOP, ZERO: no arguments.
struct CommandFrame {
  CommandKind command = CommandKind::kPing;
  int32_t args[4] = {0, 0, 0, 0};
};

/// Why a line was not a frame.
enum class DecodeError : uint8_t {
  kOk = 0,
  kNoStart,      ///< does not begin with '$'
  kTooLong,      ///< longer than kMaxFrameBytes
  kNoChecksum,   ///< no '*' followed by 4 hex digits at the end
  kBadChecksum,  ///< CRC does not match (a corrupted frame: never accepted)
  kUnknownType,  ///< type character is not S, H, E or C
  kBadField,     ///< wrong number of fields, a field out of range, or not a number
};

/// A decoded line: the type says which member is valid.
struct Frame {
  FrameType type = FrameType::kSample;
  SampleFrame sample;
  HeaderFrame header;
  EventFrame event;
  CommandFrame command;
};

// ---------------------------------------------------------------------------------------
// CRC-16/CCITT-FALSE: polynomial 0x1021, initial value 0xFFFF, no reflection, no final
// xor. Check value: Crc16("123456789") == 0x29B1.
inline uint16_t Crc16(const char* data, size_t size, uint16_t crc = 0xFFFF) {
  for (size_t i = 0; i < size; ++i) {
    crc = static_cast<uint16_t>(crc ^ (static_cast<uint16_t>(static_cast<uint8_t>(data[i])) << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x8000) ? static_cast<uint16_t>((crc << 1) ^ 0x1021)
                           : static_cast<uint16_t>(crc << 1);
    }
  }
  return crc;
}

/// Wire names of events and commands ("LED_ON", "START", ...); nullptr when out of range.
inline const char* EventKindName(EventKind kind) {
  static const char* const kNames[] = {"LED_ON", "LED_OFF", "TEST_START", "TEST_END",
                                       "FAULT",  "PONG",    "ACK",        "NAK"};
  const uint8_t index = static_cast<uint8_t>(kind);
  return index < static_cast<uint8_t>(EventKind::kCount) ? kNames[index] : nullptr;
}
inline const char* CommandKindName(CommandKind kind) {
  static const char* const kNames[] = {"START", "STOP", "ZERO", "PING"};
  const uint8_t index = static_cast<uint8_t>(kind);
  return index < static_cast<uint8_t>(CommandKind::kCount) ? kNames[index] : nullptr;
}

// ---------------------------------------------------------------------------------------
// Encoding: each Encode* writes one whole frame ('$' .. '\n', no terminating NUL) into
// `out` and returns its length, or 0 when `capacity` is too small or a text field holds a
// forbidden character. kMaxFrameBytes always suffices.

namespace detail {

// Characters a text field cannot hold: the field separator, the checksum marker and the
// frame delimiters. The encoder refuses them and the decoder rejects them, so every
// decoded frame encodes again.
inline bool ForbiddenInText(char c) {
  return c == ',' || c == '*' || c == '$' || c == '\n' || c == '\r';
}

// Appends to a fixed buffer; remembers overflow instead of writing past the end.
class Writer {
 public:
  Writer(char* out, size_t capacity) : out_(out), capacity_(capacity) {}
  void Char(char c) {
    if (size_ < capacity_) {
      out_[size_] = c;
    } else {
      failed_ = true;
    }
    ++size_;
  }
  // At most kMaxTextBytes characters, none of them forbidden.
  void Text(const char* text) {
    for (size_t n = 0; text[n]; ++n) {
      if (n == kMaxTextBytes || ForbiddenInText(text[n])) {
        failed_ = true;
        return;
      }
      Char(text[n]);
    }
  }
  void Unsigned(uint32_t value) {
    char digits[10];
    int n = 0;
    do {
      digits[n++] = static_cast<char>('0' + value % 10);
      value /= 10;
    } while (value != 0);
    while (n > 0) Char(digits[--n]);
  }
  void Signed(int32_t value) {
    if (value < 0) {
      Char('-');
      Unsigned(static_cast<uint32_t>(0) - static_cast<uint32_t>(value));
    } else {
      Unsigned(static_cast<uint32_t>(value));
    }
  }
  void Field() { Char(','); }
  // '*', the CRC of everything after '$', '\n'; returns the frame's length or 0.
  size_t Finish() {
    const size_t body = size_;
    Char('*');
    static const char kHex[] = "0123456789ABCDEF";
    const uint16_t crc = failed_ || body > capacity_ ? 0 : Crc16(out_ + 1, body - 1);
    for (int shift = 12; shift >= 0; shift -= 4) Char(kHex[(crc >> shift) & 0xF]);
    Char('\n');
    return failed_ || size_ > kMaxFrameBytes ? 0 : size_;
  }

 private:
  char* out_;
  size_t capacity_;
  size_t size_ = 0;
  bool failed_ = false;
};

}  // namespace detail

inline size_t EncodeSample(const SampleFrame& s, char* out, size_t capacity) {
  detail::Writer w(out, capacity);
  w.Char('$');
  w.Char('S');
  w.Field();
  w.Unsigned(s.sequence);
  w.Field();
  w.Unsigned(s.device_time_us);
  w.Field();
  w.Unsigned(s.led_on ? 1 : 0);
  w.Field();
  w.Signed(s.bend_counts);
  w.Field();
  w.Signed(s.rotate_counts);
  w.Field();
  w.Signed(s.bend_setpoint_counts);
  w.Field();
  w.Signed(s.rotate_setpoint_counts);
  return w.Finish();
}

inline size_t EncodeHeader(const HeaderFrame& h, char* out, size_t capacity) {
  detail::Writer w(out, capacity);
  w.Char('$');
  w.Char('H');
  w.Field();
  w.Unsigned(h.sequence);
  w.Field();
  w.Unsigned(h.device_time_us);
  w.Field();
  w.Unsigned(h.protocol_version);
  w.Field();
  w.Text(h.firmware);
  w.Field();
  w.Unsigned(h.counts_per_motor_rev);
  w.Field();
  w.Unsigned(h.gearbox_ratio);
  w.Field();
  w.Unsigned(h.spur_gear_ratio);
  return w.Finish();
}

inline size_t EncodeEvent(const EventFrame& e, char* out, size_t capacity) {
  const char* name = EventKindName(e.kind);
  if (name == nullptr) return 0;
  detail::Writer w(out, capacity);
  w.Char('$');
  w.Char('E');
  w.Field();
  w.Unsigned(e.sequence);
  w.Field();
  w.Unsigned(e.device_time_us);
  w.Field();
  w.Text(name);
  w.Field();
  w.Signed(e.arg);
  w.Field();
  w.Text(e.text);
  return w.Finish();
}

inline size_t EncodeCommand(const CommandFrame& c, char* out, size_t capacity) {
  const char* name = CommandKindName(c.command);
  if (name == nullptr) return 0;
  detail::Writer w(out, capacity);
  w.Char('$');
  w.Char('C');
  w.Field();
  w.Text(name);
  for (int i = 0; i < 4; ++i) {
    w.Field();
    w.Signed(c.args[i]);
  }
  return w.Finish();
}

/// Encodes whichever frame `frame.type` names (the other members are ignored).
inline size_t EncodeFrame(const Frame& frame, char* out, size_t capacity) {
  switch (frame.type) {
    case FrameType::kSample: return EncodeSample(frame.sample, out, capacity);
    case FrameType::kHeader: return EncodeHeader(frame.header, out, capacity);
    case FrameType::kEvent: return EncodeEvent(frame.event, out, capacity);
    case FrameType::kCommand: return EncodeCommand(frame.command, out, capacity);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------
// Decoding one line: `line` holds one frame without its '\n' (a trailing '\r' is
// ignored). Fills `frame` and returns kOk, or says why the line is not a frame. A frame
// whose CRC does not match is never decoded.

namespace detail {

// Reads comma-separated fields of a checked frame body.
class Reader {
 public:
  Reader(const char* begin, const char* end) : at_(begin), end_(end) {}
  bool AtEnd() const { return at_ == end_; }
  // Moves past the ',' that must come next.
  bool Comma() {
    if (at_ == end_ || *at_ != ',') return false;
    ++at_;
    return true;
  }
  bool Unsigned(uint32_t& value) {
    uint64_t v = 0;
    const char* start = at_;
    while (at_ != end_ && *at_ >= '0' && *at_ <= '9') {
      v = v * 10 + static_cast<uint64_t>(*at_ - '0');
      if (v > 0xFFFFFFFFull) return false;
      ++at_;
    }
    value = static_cast<uint32_t>(v);
    return at_ != start;
  }
  bool Signed(int32_t& value) {
    bool negative = false;
    if (at_ != end_ && *at_ == '-') {
      negative = true;
      ++at_;
    }
    uint32_t magnitude = 0;
    if (!Unsigned(magnitude)) return false;
    if (negative ? magnitude > 0x80000000u : magnitude > 0x7FFFFFFFu) return false;
    value = negative ? static_cast<int32_t>(0u - magnitude) : static_cast<int32_t>(magnitude);
    return true;
  }
  // Text up to the next ',' or the end; at most kMaxTextBytes, none forbidden.
  bool Text(char* out) {
    size_t n = 0;
    while (at_ != end_ && *at_ != ',') {
      if (n == kMaxTextBytes || ForbiddenInText(*at_)) return false;
      out[n++] = *at_++;
    }
    out[n] = '\0';
    return true;
  }
  bool Word(const char* word) {
    const char* p = at_;
    for (; *word; ++word, ++p) {
      if (p == end_ || *p != *word) return false;
    }
    if (p != end_ && *p != ',') return false;
    at_ = p;
    return true;
  }

 private:
  const char* at_;
  const char* end_;
};

inline int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace detail

inline DecodeError DecodeLine(const char* line, size_t size, Frame* frame) {
  if (size > 0 && line[size - 1] == '\r') --size;
  if (size + 1 > kMaxFrameBytes) return DecodeError::kTooLong;
  if (size == 0 || line[0] != '$') return DecodeError::kNoStart;
  // "...*XXXX": the checksum first, so no corrupted field is ever looked at
  if (size < 7 || line[size - 5] != '*') return DecodeError::kNoChecksum;
  uint16_t sent = 0;
  for (size_t i = size - 4; i < size; ++i) {
    const int digit = detail::HexValue(line[i]);
    if (digit < 0) return DecodeError::kNoChecksum;
    sent = static_cast<uint16_t>((sent << 4) | digit);
  }
  const char* body = line + 1;
  const char* body_end = line + size - 5;
  if (Crc16(body, static_cast<size_t>(body_end - body)) != sent) return DecodeError::kBadChecksum;

  detail::Reader r(body + 1, body_end);
  const char type = body[0];
  bool ok = r.Comma();
  switch (type) {
    case 'S': {
      frame->type = FrameType::kSample;
      SampleFrame& s = frame->sample;
      uint32_t led = 0;
      ok = ok && r.Unsigned(s.sequence) && r.Comma() && r.Unsigned(s.device_time_us) && r.Comma() &&
           r.Unsigned(led) && led <= 1 && r.Comma() && r.Signed(s.bend_counts) && r.Comma() &&
           r.Signed(s.rotate_counts) && r.Comma() && r.Signed(s.bend_setpoint_counts) &&
           r.Comma() && r.Signed(s.rotate_setpoint_counts);
      s.led_on = static_cast<uint8_t>(led);
      break;
    }
    case 'H': {
      frame->type = FrameType::kHeader;
      HeaderFrame& h = frame->header;
      ok = ok && r.Unsigned(h.sequence) && r.Comma() && r.Unsigned(h.device_time_us) && r.Comma() &&
           r.Unsigned(h.protocol_version) && r.Comma() && r.Text(h.firmware) && r.Comma() &&
           r.Unsigned(h.counts_per_motor_rev) && r.Comma() && r.Unsigned(h.gearbox_ratio) &&
           r.Comma() && r.Unsigned(h.spur_gear_ratio);
      break;
    }
    case 'E': {
      frame->type = FrameType::kEvent;
      EventFrame& e = frame->event;
      ok = ok && r.Unsigned(e.sequence) && r.Comma() && r.Unsigned(e.device_time_us) && r.Comma();
      bool known = false;
      for (uint8_t k = 0; ok && !known && k < static_cast<uint8_t>(EventKind::kCount); ++k) {
        if (r.Word(EventKindName(static_cast<EventKind>(k)))) {
          e.kind = static_cast<EventKind>(k);
          known = true;
        }
      }
      ok = ok && known && r.Comma() && r.Signed(e.arg) && r.Comma() && r.Text(e.text);
      break;
    }
    case 'C': {
      frame->type = FrameType::kCommand;
      CommandFrame& c = frame->command;
      bool known = false;
      for (uint8_t k = 0; ok && !known && k < static_cast<uint8_t>(CommandKind::kCount); ++k) {
        if (r.Word(CommandKindName(static_cast<CommandKind>(k)))) {
          c.command = static_cast<CommandKind>(k);
          known = true;
        }
      }
      ok = ok && known;
      for (int i = 0; ok && i < 4; ++i) ok = r.Comma() && r.Signed(c.args[i]);
      break;
    }
    default: return DecodeError::kUnknownType;
  }
  return ok && r.AtEnd() ? DecodeError::kOk : DecodeError::kBadField;
}

}  // namespace wire
}  // namespace liftoff
