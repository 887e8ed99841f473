// The protocol v1 frame encoder and decoder shared by host and firmware. Expected wire
// texts and CRCs were computed independently (Python's binascii.crc_hqx with initial
// value 0xFFFF, which is CRC-16/CCITT-FALSE).
#include "liftoff/capture/wire_format.h"

#include <climits>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"

namespace liftoff::wire {
namespace {

std::string EncodeToString(const Frame& frame) {
  char out[kMaxFrameBytes];
  size_t size = 0;
  switch (frame.type) {
    case FrameType::kSample: size = EncodeSample(frame.sample, out, sizeof(out)); break;
    case FrameType::kHeader: size = EncodeHeader(frame.header, out, sizeof(out)); break;
    case FrameType::kEvent: size = EncodeEvent(frame.event, out, sizeof(out)); break;
    case FrameType::kCommand: size = EncodeCommand(frame.command, out, sizeof(out)); break;
  }
  return std::string(out, size);
}

// Decodes a whole frame text (with its '\n').
DecodeError Decode(const std::string& text, Frame* frame) {
  std::string line = text;
  if (!line.empty() && line.back() == '\n') line.pop_back();
  return DecodeLine(line.data(), line.size(), frame);
}

// "$body*CRC" for a body, with the CRC this header computes (its check value is tested).
std::string WithCrc(const std::string& body) {
  char crc[5];
  std::snprintf(crc, sizeof(crc), "%04X", Crc16(body.data(), body.size()));
  return "$" + body + "*" + crc;
}

Frame KnownSample() {
  Frame frame;
  frame.type = FrameType::kSample;
  frame.sample = {1042, 5212000, 1, -3201, 18455, -3200, 18460};
  return frame;
}

Frame KnownHeader() {
  Frame frame;
  frame.type = FrameType::kHeader;
  frame.header.sequence = 0;
  frame.header.device_time_us = 1000;
  std::strcpy(frame.header.firmware, "laika-fw 1.0");
  frame.header.counts_per_motor_rev = 12;
  frame.header.gearbox_ratio = 1000;
  frame.header.spur_gear_ratio = 4;
  return frame;
}

Frame KnownEvent() {
  Frame frame;
  frame.type = FrameType::kEvent;
  frame.event.sequence = 7;
  frame.event.device_time_us = 2000000;
  frame.event.kind = EventKind::kFault;
  frame.event.arg = 3;
  std::strcpy(frame.event.text, "bend stall");
  return frame;
}

Frame KnownCommand() {
  Frame frame;
  frame.type = FrameType::kCommand;
  frame.command.command = CommandKind::kStart;
  frame.command.args[0] = 2;
  frame.command.args[1] = 800;
  frame.command.args[2] = 60000;
  frame.command.args[3] = 40000;
  return frame;
}

void ExpectSameFrame(const Frame& expected, const Frame& actual) {
  ASSERT_EQ(expected.type, actual.type);
  switch (expected.type) {
    case FrameType::kSample:
      EXPECT_EQ(expected.sample.sequence, actual.sample.sequence);
      EXPECT_EQ(expected.sample.device_time_us, actual.sample.device_time_us);
      EXPECT_EQ(expected.sample.led_on, actual.sample.led_on);
      EXPECT_EQ(expected.sample.bend_counts, actual.sample.bend_counts);
      EXPECT_EQ(expected.sample.rotate_counts, actual.sample.rotate_counts);
      EXPECT_EQ(expected.sample.bend_setpoint_counts, actual.sample.bend_setpoint_counts);
      EXPECT_EQ(expected.sample.rotate_setpoint_counts, actual.sample.rotate_setpoint_counts);
      break;
    case FrameType::kHeader:
      EXPECT_EQ(expected.header.sequence, actual.header.sequence);
      EXPECT_EQ(expected.header.device_time_us, actual.header.device_time_us);
      EXPECT_EQ(expected.header.protocol_version, actual.header.protocol_version);
      EXPECT_STREQ(expected.header.firmware, actual.header.firmware);
      EXPECT_EQ(expected.header.counts_per_motor_rev, actual.header.counts_per_motor_rev);
      EXPECT_EQ(expected.header.gearbox_ratio, actual.header.gearbox_ratio);
      EXPECT_EQ(expected.header.spur_gear_ratio, actual.header.spur_gear_ratio);
      break;
    case FrameType::kEvent:
      EXPECT_EQ(expected.event.sequence, actual.event.sequence);
      EXPECT_EQ(expected.event.device_time_us, actual.event.device_time_us);
      EXPECT_EQ(expected.event.kind, actual.event.kind);
      EXPECT_EQ(expected.event.arg, actual.event.arg);
      EXPECT_STREQ(expected.event.text, actual.event.text);
      break;
    case FrameType::kCommand:
      EXPECT_EQ(expected.command.command, actual.command.command);
      for (int i = 0; i < 4; ++i) EXPECT_EQ(expected.command.args[i], actual.command.args[i]);
      break;
  }
}

void ExpectRoundTrip(const Frame& frame) {
  const std::string text = EncodeToString(frame);
  ASSERT_FALSE(text.empty());
  EXPECT_LE(text.size(), kMaxFrameBytes);
  EXPECT_EQ(text.front(), '$');
  EXPECT_EQ(text.back(), '\n');
  Frame decoded;
  ASSERT_EQ(Decode(text, &decoded), DecodeError::kOk) << text;
  ExpectSameFrame(frame, decoded);
}

// ---------------------------------------------------------------------------------------
// CRC and names

TEST(WireFormat, Crc16MatchesTheCcittFalseCheckValue) {
  EXPECT_EQ(Crc16("123456789", 9), 0x29B1);
  EXPECT_EQ(Crc16("", 0), 0xFFFF);
  // continuing a CRC over a second piece equals one pass over both
  EXPECT_EQ(Crc16("56789", 5, Crc16("1234", 4)), 0x29B1);
}

TEST(WireFormat, NamesEveryEventAndCommandAndNothingElse) {
  const char* events[] = {"LED_ON", "LED_OFF", "TEST_START", "TEST_END",
                          "FAULT",  "PONG",    "ACK",        "NAK"};
  for (uint8_t k = 0; k < static_cast<uint8_t>(EventKind::kCount); ++k) {
    EXPECT_STREQ(EventKindName(static_cast<EventKind>(k)), events[k]);
  }
  EXPECT_EQ(EventKindName(EventKind::kCount), nullptr);
  const char* commands[] = {"START", "STOP", "ZERO", "PING"};
  for (uint8_t k = 0; k < static_cast<uint8_t>(CommandKind::kCount); ++k) {
    EXPECT_STREQ(CommandKindName(static_cast<CommandKind>(k)), commands[k]);
  }
  EXPECT_EQ(CommandKindName(static_cast<CommandKind>(200)), nullptr);
}

// ---------------------------------------------------------------------------------------
// Encoding

TEST(WireFormat, EncodesKnownFramesToTheExactWireText) {
  EXPECT_EQ(EncodeToString(KnownSample()), "$S,1042,5212000,1,-3201,18455,-3200,18460*E2A1\n");
  EXPECT_EQ(EncodeToString(KnownHeader()), "$H,0,1000,1,laika-fw 1.0,12,1000,4*586B\n");
  EXPECT_EQ(EncodeToString(KnownEvent()), "$E,7,2000000,FAULT,3,bend stall*7F5C\n");
  EXPECT_EQ(EncodeToString(KnownCommand()), "$C,START,2,800,60000,40000*6D1C\n");
}

TEST(WireFormat, EncodesExtremeValuesToTheExactWireText) {
  Frame sample;
  sample.type = FrameType::kSample;
  sample.sample = {UINT32_MAX, UINT32_MAX, 0, INT32_MIN, INT32_MAX, 0, -1};
  EXPECT_EQ(EncodeToString(sample),
            "$S,4294967295,4294967295,0,-2147483648,2147483647,0,-1*C348\n");
  Frame command;
  command.type = FrameType::kCommand;
  command.command = {CommandKind::kPing, {INT32_MIN, INT32_MAX, 0, -1}};
  EXPECT_EQ(EncodeToString(command), "$C,PING,-2147483648,2147483647,0,-1*C31B\n");
  Frame event;
  event.type = FrameType::kEvent;
  event.event.sequence = UINT32_MAX;
  event.event.kind = EventKind::kTestEnd;
  event.event.arg = 1;
  EXPECT_EQ(EncodeToString(event), "$E,4294967295,0,TEST_END,1,*BBD7\n");
}

TEST(WireFormat, RoundTripsEveryFrameTypeWithExtremeValues) {
  ExpectRoundTrip(KnownSample());
  ExpectRoundTrip(KnownHeader());
  ExpectRoundTrip(KnownEvent());
  ExpectRoundTrip(KnownCommand());

  const int32_t values[] = {INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX};
  for (const int32_t v : values) {
    Frame sample;
    sample.type = FrameType::kSample;
    sample.sample = {static_cast<uint32_t>(v), static_cast<uint32_t>(v), v < 0, v, -(v + 1), v, v};
    ExpectRoundTrip(sample);
    for (uint8_t k = 0; k < static_cast<uint8_t>(CommandKind::kCount); ++k) {
      Frame command;
      command.type = FrameType::kCommand;
      command.command = {static_cast<CommandKind>(k), {v, v, -(v + 1), v}};
      ExpectRoundTrip(command);
    }
    for (uint8_t k = 0; k < static_cast<uint8_t>(EventKind::kCount); ++k) {
      Frame event;
      event.type = FrameType::kEvent;
      event.event.sequence = UINT32_MAX;
      event.event.device_time_us = static_cast<uint32_t>(v);
      event.event.kind = static_cast<EventKind>(k);
      event.event.arg = v;
      std::strcpy(event.event.text, k % 2 ? "" : "motor 2 over current: 0123456789");
      ExpectRoundTrip(event);
    }
  }
  // the longest frame there is: a header with every number at its maximum and a full name
  Frame header = KnownHeader();
  header.header.sequence = header.header.device_time_us = UINT32_MAX;
  header.header.protocol_version = header.header.counts_per_motor_rev = UINT32_MAX;
  header.header.gearbox_ratio = header.header.spur_gear_ratio = UINT32_MAX;
  std::memset(header.header.firmware, '~', kMaxTextBytes);
  header.header.firmware[kMaxTextBytes] = '\0';
  // "$H," + 3 numbers with commas + name and comma + 2 numbers with commas + 1 number + "*XXXX\n"
  EXPECT_EQ(EncodeToString(header).size(), 3 + 3 * 11 + 33 + 2 * 11 + 10 + 6u);
  ExpectRoundTrip(header);
}

TEST(WireFormat, RefusesTextWithFrameCharactersOrTooLong) {
  for (const char bad : {',', '*', '$', '\n', '\r'}) {
    Frame header = KnownHeader();
    header.header.firmware[3] = bad;
    EXPECT_EQ(EncodeToString(header), "") << int{bad};
    Frame event = KnownEvent();
    event.event.text[0] = bad;
    EXPECT_EQ(EncodeToString(event), "") << int{bad};
  }
  // 33 characters and no terminator: refused, and nothing past the array is read
  Frame event = KnownEvent();
  std::memset(event.event.text, 'a', sizeof(event.event.text));
  EXPECT_EQ(EncodeToString(event), "");
  // kinds outside the enums
  event = KnownEvent();
  event.event.kind = EventKind::kCount;
  EXPECT_EQ(EncodeToString(event), "");
  Frame command = KnownCommand();
  command.command.command = CommandKind::kCount;
  EXPECT_EQ(EncodeToString(command), "");
}

TEST(WireFormat, ReturnsZeroAndWritesNothingPastCapacityWhenTooSmall) {
  for (const Frame& frame : {KnownSample(), KnownHeader(), KnownEvent(), KnownCommand()}) {
    const std::string full = EncodeToString(frame);
    for (size_t capacity = 0; capacity <= full.size(); ++capacity) {
      std::vector<char> buffer(full.size() + 8, '#');
      size_t size = 0;
      switch (frame.type) {
        case FrameType::kSample: size = EncodeSample(frame.sample, buffer.data(), capacity); break;
        case FrameType::kHeader: size = EncodeHeader(frame.header, buffer.data(), capacity); break;
        case FrameType::kEvent: size = EncodeEvent(frame.event, buffer.data(), capacity); break;
        case FrameType::kCommand:
          size = EncodeCommand(frame.command, buffer.data(), capacity);
          break;
      }
      EXPECT_EQ(size, capacity == full.size() ? full.size() : 0u) << full << " in " << capacity;
      for (size_t i = capacity; i < buffer.size(); ++i) ASSERT_EQ(buffer[i], '#');
    }
  }
}

// ---------------------------------------------------------------------------------------
// Decoding

TEST(WireFormat, DecodesALineEndingInCarriageReturn) {
  Frame frame;
  ASSERT_EQ(Decode("$S,1042,5212000,1,-3201,18455,-3200,18460*E2A1\r\n", &frame), DecodeError::kOk);
  ExpectSameFrame(KnownSample(), frame);
}

TEST(WireFormat, ReportsEveryDecodeError) {
  Frame frame;
  EXPECT_EQ(Decode("", &frame), DecodeError::kNoStart);
  EXPECT_EQ(Decode("S,1042,5212000,1,-3201,18455,-3200,18460*E2A1", &frame), DecodeError::kNoStart);
  EXPECT_EQ(Decode(" $S,1,2,1,3,4,5,6*C945", &frame), DecodeError::kNoStart);
  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6*C945", &frame), DecodeError::kOk);

  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6", &frame), DecodeError::kNoChecksum);
  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6*C94", &frame), DecodeError::kNoChecksum);
  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6*c945", &frame), DecodeError::kNoChecksum);  // lower case
  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6*C9G5", &frame), DecodeError::kNoChecksum);
  EXPECT_EQ(Decode("$*FFFF", &frame), DecodeError::kNoChecksum);  // shorter than any frame

  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,6*C946", &frame), DecodeError::kBadChecksum);
  EXPECT_EQ(Decode("$S,1,2,1,3,4,5,7*C945", &frame), DecodeError::kBadChecksum);

  EXPECT_EQ(Decode("$X,1,2*D960", &frame), DecodeError::kUnknownType);
  EXPECT_EQ(Decode(WithCrc("s,1,2,1,3,4,5,6"), &frame), DecodeError::kUnknownType);

  const std::string bad_fields[] = {
      "S,1,2,1,3,4,5",              // a field missing
      "S,1,2,1,3,4,5,6,7",          // one too many
      "S,1,2,2,3,4,5,6",            // LED neither 0 nor 1
      "S,4294967296,2,1,3,4,5,6",   // sequence beyond 2^32 - 1
      "S,-1,2,1,3,4,5,6",           // negative unsigned
      "S,+1,2,1,3,4,5,6",           // no '+'
      "S,1,2,1,2147483648,4,5,6",   // beyond INT32_MAX
      "S,1,2,1,-2147483649,4,5,6",  // beyond INT32_MIN
      "S,1,2,1,,4,5,6",             // empty number
      "S,1,2,1,3x,4,5,6",           // not a number
      "S,1,2,1,3.5,4,5,6",          // not an integer
      "S,1,2,1,3,4,5,6,",           // trailing comma
      "S 1,2,1,3,4,5,6",            // no comma after the type
      "E,1,2,LED_ONX,0,",           // unknown event
      "E,1,2,LED_ON,0",             // text field missing
      "E,1,2,,0,",                  // no event name
      "C,JUMP,0,0,0,0",             // unknown command
      "C,PING,1,2,3",               // an argument missing
      "H,1,2,1,fw,12,1000",         // a constant missing
  };
  for (const std::string& body : bad_fields) {
    EXPECT_EQ(Decode(WithCrc(body), &frame), DecodeError::kBadField) << body;
  }
}

// docs/protocol.md section 3: an event's arg is a signed 32-bit integer.
TEST(WireFormat, EventArgIsASignedThirtyTwoBitInteger) {
  Frame frame;
  ASSERT_EQ(Decode(WithCrc("E,5,6,PONG,-42,"), &frame), DecodeError::kOk);
  EXPECT_EQ(frame.event.arg, -42);
  ASSERT_EQ(Decode(WithCrc("E,5,6,PONG,-2147483648,"), &frame), DecodeError::kOk);
  EXPECT_EQ(frame.event.arg, INT32_MIN);
  ASSERT_EQ(Decode(WithCrc("E,5,6,PONG,2147483647,"), &frame), DecodeError::kOk);
  EXPECT_EQ(frame.event.arg, INT32_MAX);
  EXPECT_EQ(Decode(WithCrc("E,5,6,PONG,2147483648,"), &frame), DecodeError::kBadField);
  EXPECT_EQ(Decode(WithCrc("E,5,6,PONG,-2147483649,"), &frame), DecodeError::kBadField);
  EXPECT_EQ(Decode(WithCrc("E,5,6,PONG,+1,"), &frame), DecodeError::kBadField);
}

TEST(WireFormat, RejectsTextWithFrameCharactersEvenWithAValidChecksum) {
  // found by the fuzzer: the decoder took characters the encoder refuses, so a decoded
  // frame could not be sent again
  Frame frame;
  EXPECT_EQ(Decode("$E,1,2,FAULT,3,a*b*B6FE", &frame), DecodeError::kBadField);
  EXPECT_EQ(Decode("$E,1,2,FAULT,3,a\rb*298F", &frame), DecodeError::kBadField);
  EXPECT_EQ(Decode("$E,1,2,FAULT,3,a$b*95F1", &frame), DecodeError::kBadField);
  EXPECT_EQ(Decode(WithCrc("H,100,1000,1,laika-fw 1\r.0,12,1000,4"), &frame),
            DecodeError::kBadField);
  // 32 characters are the most a text field holds
  const std::string longest(kMaxTextBytes, 'x');
  ASSERT_EQ(Decode(WithCrc("E,1,2,FAULT,3," + longest), &frame), DecodeError::kOk);
  EXPECT_EQ(frame.event.text, longest);
  EXPECT_EQ(Decode(WithCrc("E,1,2,FAULT,3," + longest + "x"), &frame), DecodeError::kBadField);
}

TEST(WireFormat, AcceptsLinesUpToTheMaximumFrameLength) {
  // leading zeros pad a frame to any length
  const std::string body = "S,1,2,1,3,4,5,6";
  const size_t frame_overhead = 1 + 5 + 1;  // '$', "*XXXX", '\n'
  const std::string longest =
      "S," + std::string(kMaxFrameBytes - frame_overhead - body.size(), '0') + body.substr(2);
  Frame frame;
  ASSERT_EQ(WithCrc(longest).size() + 1, kMaxFrameBytes);
  EXPECT_EQ(Decode(WithCrc(longest), &frame), DecodeError::kOk);
  EXPECT_EQ(frame.sample.sequence, 1u);
  EXPECT_EQ(Decode(WithCrc("S,0" + longest.substr(2)), &frame), DecodeError::kTooLong);
}

// Every single-byte corruption (all 255 values XORed into every position of a known
// frame of each type) is refused: CRC-16 catches any error burst of 16 bits or less in
// the body, and the '$', '*' and hex digits are checked by form.
TEST(WireFormat, NoSingleByteCorruptionOfAFrameIsAccepted) {
  int64_t tried = 0;
  for (const Frame& original : {KnownSample(), KnownHeader(), KnownEvent(), KnownCommand()}) {
    std::string line = EncodeToString(original);
    line.pop_back();  // the '\n' ends the line; the parser tests cover its corruption
    for (size_t at = 0; at < line.size(); ++at) {
      for (int flip = 1; flip < 256; ++flip) {
        std::string corrupted = line;
        corrupted[at] = static_cast<char>(corrupted[at] ^ flip);
        Frame frame;
        ASSERT_NE(DecodeLine(corrupted.data(), corrupted.size(), &frame), DecodeError::kOk)
            << "accepted " << corrupted;
        ++tried;
      }
    }
  }
  EXPECT_GT(tried, 35000);
}

// ---------------------------------------------------------------------------------------
// The firmware compiles the very header the host tests.

TEST(WireFormat, FirmwareCopyIsByteIdenticalToTheHostHeader) {
  const std::string host =
      testing::ReadFile(testing::SourceDir() / "include/liftoff/capture/wire_format.h");
  const std::string firmware =
      testing::ReadFile(testing::SourceDir() / "samples/firmware/laika_controller/wire_format.h");
  ASSERT_FALSE(host.empty());
  EXPECT_EQ(firmware, host) << "copy include/liftoff/capture/wire_format.h to "
                               "samples/firmware/laika_controller/";
}

}  // namespace
}  // namespace liftoff::wire
