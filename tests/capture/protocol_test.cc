// The host side of the serial protocol: the streaming frame parser under splits, garbage
// and corruption; the device clock's unwrapping; sequence gaps; frames to log rows.
#include "liftoff/capture/protocol.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"

namespace liftoff::capture {
namespace {

constexpr double kPi = std::numbers::pi;

std::string SampleText(uint32_t sequence, int32_t counts = 0) {
  wire::SampleFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = sequence * 1000u;
  frame.led_on = sequence % 2;
  frame.bend_counts = counts;
  frame.rotate_counts = -counts * 3;
  frame.bend_setpoint_counts = counts + 1;
  frame.rotate_setpoint_counts = -counts * 3 - 1;
  char out[wire::kMaxFrameBytes];
  return std::string(out, wire::EncodeSample(frame, out, sizeof(out)));
}

std::string EventText(uint32_t sequence, wire::EventKind kind, const char* text = "") {
  wire::EventFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = sequence * 1000u;
  frame.kind = kind;
  std::strcpy(frame.text, text);
  char out[wire::kMaxFrameBytes];
  return std::string(out, wire::EncodeEvent(frame, out, sizeof(out)));
}

std::string HeaderText(uint32_t sequence) {
  wire::HeaderFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = sequence * 1000u;
  std::strcpy(frame.firmware, "laika-fw 1.0");
  frame.counts_per_motor_rev = 12;
  frame.gearbox_ratio = 1000;
  frame.spur_gear_ratio = 4;
  char out[wire::kMaxFrameBytes];
  return std::string(out, wire::EncodeHeader(frame, out, sizeof(out)));
}

uint32_t SequenceOf(const wire::Frame& frame) {
  switch (frame.type) {
    case wire::FrameType::kSample: return frame.sample.sequence;
    case wire::FrameType::kHeader: return frame.header.sequence;
    case wire::FrameType::kEvent: return frame.event.sequence;
    case wire::FrameType::kCommand: break;
  }
  return UINT32_MAX;
}

std::span<const uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

std::vector<ReceivedFrame> FeedAll(FrameParser& parser, const std::string& text,
                                   int64_t host_time_ns = 0) {
  std::vector<ReceivedFrame> out;
  parser.Feed(Bytes(text), host_time_ns, out);
  return out;
}

void ExpectStatsAddUp(const FrameParser& parser) {
  const ParserStats& s = parser.stats();
  EXPECT_EQ(s.bytes, s.frame_bytes + s.rejected_bytes + s.garbage_bytes + parser.pending_bytes());
  EXPECT_EQ(s.frames, s.samples + s.headers + s.events + s.commands);
}

// ---------------------------------------------------------------------------------------
// FrameParser

TEST(FrameParser, ParsesAKnownLineIntoItsFields) {
  FrameParser parser;
  const auto out = FeedAll(parser, "$S,1042,5212000,1,-3201,18455,-3200,18460*E2A1\n", 77);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].host_time_ns, 77);
  ASSERT_EQ(out[0].frame.type, wire::FrameType::kSample);
  const wire::SampleFrame& s = out[0].frame.sample;
  EXPECT_EQ(s.sequence, 1042u);
  EXPECT_EQ(s.device_time_us, 5212000u);
  EXPECT_EQ(s.led_on, 1);
  EXPECT_EQ(s.bend_counts, -3201);
  EXPECT_EQ(s.rotate_counts, 18455);
  EXPECT_EQ(s.bend_setpoint_counts, -3200);
  EXPECT_EQ(s.rotate_setpoint_counts, 18460);
  EXPECT_EQ(parser.stats().samples, 1);
  EXPECT_EQ(parser.stats().frame_bytes, 47);
}

TEST(FrameParser, KeepsFramesSplitAtEveryByteBoundaryWithTheTimeOfTheirLastChunk) {
  std::string crlf_sample = SampleText(2, -5);
  crlf_sample.insert(crlf_sample.size() - 1, "\r");
  const std::string frames[] = {HeaderText(1), crlf_sample, EventText(3, wire::EventKind::kLedOn),
                                SampleText(4, 123456)};
  // where each frame's '\n' is; a stray "\r\n" at the end is garbage
  std::string stream;
  std::vector<size_t> ends;
  for (const std::string& frame : frames) {
    stream += frame;
    ends.push_back(stream.size() - 1);
  }
  stream += "\r\n";
  ASSERT_EQ(ends.size(), 4u);
  for (size_t split = 0; split <= stream.size(); ++split) {
    FrameParser parser;
    std::vector<ReceivedFrame> out;
    parser.Feed(Bytes(stream.substr(0, split)), 1, out);
    parser.Feed(Bytes(stream.substr(split)), 2, out);
    ASSERT_EQ(out.size(), 4u) << "split at " << split;
    for (size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(SequenceOf(out[i].frame), i + 1);
      EXPECT_EQ(out[i].host_time_ns, ends[i] < split ? 1 : 2) << "split at " << split;
    }
    EXPECT_EQ(parser.stats().garbage_bytes, 2);
    ExpectStatsAddUp(parser);
  }
  // and one byte at a time, the time being the byte's index
  FrameParser parser;
  std::vector<ReceivedFrame> out;
  for (size_t i = 0; i < stream.size(); ++i) {
    parser.Feed(Bytes(stream.substr(i, 1)), static_cast<int64_t>(i), out);
  }
  ASSERT_EQ(out.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(out[i].host_time_ns, static_cast<int64_t>(ends[i]));
}

TEST(FrameParser, AcceptsCrLfLineEnds) {
  FrameParser parser;
  std::string line = SampleText(9);
  line.insert(line.size() - 1, "\r");
  const auto out = FeedAll(parser, line + line);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].frame.sample.sequence, 9u);
  EXPECT_EQ(parser.stats().frame_bytes, static_cast<int64_t>(2 * line.size()));
  EXPECT_EQ(parser.stats().garbage_bytes, 0);
}

TEST(FrameParser, CountsEveryByteAndEveryKindOfBadLine) {
  FrameParser parser;
  const std::string good = SampleText(1);  // 1 frame
  std::string corrupted = SampleText(2);   // 1 checksum error
  corrupted[5] = corrupted[5] == '7' ? '8' : '7';
  const std::string stream = "xy" + good + "$S,1,2\n" +   // malformed: no checksum
                             corrupted + "\n\n" +         // garbage
                             "$S,1,$" + good.substr(1) +  // cut off by '$', then a frame
                             "$abc";                      // pending
  const auto out = FeedAll(parser, stream);
  ASSERT_EQ(out.size(), 2u);
  const ParserStats& s = parser.stats();
  EXPECT_EQ(s.bytes, static_cast<int64_t>(stream.size()));
  EXPECT_EQ(s.frames, 2);
  EXPECT_EQ(s.samples, 2);
  EXPECT_EQ(s.checksum_errors, 1);
  EXPECT_EQ(s.malformed_frames, 2);
  EXPECT_EQ(s.garbage_bytes, 4);
  EXPECT_EQ(s.frame_bytes, static_cast<int64_t>(2 * good.size()));
  EXPECT_EQ(s.rejected_bytes, static_cast<int64_t>(7 + corrupted.size() + 5));
  EXPECT_EQ(parser.pending_bytes(), 4);
  ExpectStatsAddUp(parser);
  // a reset gives the unfinished frame up as malformed
  parser.Reset();
  EXPECT_EQ(parser.pending_bytes(), 0);
  EXPECT_EQ(parser.stats().malformed_frames, 3);
  EXPECT_EQ(parser.stats().rejected_bytes, static_cast<int64_t>(7 + corrupted.size() + 5 + 4));
  ExpectStatsAddUp(parser);
  // and the head of a frame is not joined to bytes after the reset
  EXPECT_TRUE(FeedAll(parser, good.substr(good.size() / 2)).empty());
  EXPECT_EQ(FeedAll(parser, good).size(), 1u);
  EXPECT_NE(parser.stats().Brief().find("3 frames (3 samples"), std::string::npos)
      << parser.stats().Brief();
}

// docs/protocol.md section 2: the CRC is upper-case hex; a line whose CRC is right but
// written in lower case is malformed, never accepted.
TEST(FrameParser, RejectsALowerCaseChecksumAsMalformed) {
  FrameParser parser;
  const std::string line = "$S,1,2,1,3,4,5,6*c945\n";
  EXPECT_TRUE(FeedAll(parser, line + "$S,1,2,1,3,4,5,6*C945\n").size() == 1);
  EXPECT_EQ(parser.stats().malformed_frames, 1);
  EXPECT_EQ(parser.stats().checksum_errors, 0);
  EXPECT_EQ(parser.stats().rejected_bytes, static_cast<int64_t>(line.size()));
  ExpectStatsAddUp(parser);
}

TEST(FrameParser, DropsOverLongLinesAndResynchronises) {
  FrameParser parser;
  const std::string good = SampleText(5);
  const std::string long_line = "$" + std::string(500, 'A') + "\n";
  auto out = FeedAll(parser, long_line + good + "$" + std::string(300, '7') + good);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(parser.stats().malformed_frames, 2);
  EXPECT_EQ(parser.stats().rejected_bytes, 502 + 301);
  ExpectStatsAddUp(parser);

  // a valid frame padded with leading zeros: 120 bytes pass, 121 do not
  const std::string body = "S,1,2,1,3,4,5,6";
  auto padded = [&](size_t zeros) {
    const std::string padded_body = "S," + std::string(zeros, '0') + body.substr(2);
    char crc[5];
    std::snprintf(crc, sizeof(crc), "%04X", wire::Crc16(padded_body.data(), padded_body.size()));
    return "$" + padded_body + "*" + crc + "\n";
  };
  const size_t zeros = wire::kMaxFrameBytes - 7 - body.size();
  ASSERT_EQ(padded(zeros).size(), wire::kMaxFrameBytes);
  FrameParser limits;
  out = FeedAll(limits, padded(zeros) + padded(zeros + 1) + padded(zeros + 400));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].frame.sample.sequence, 1u);
  EXPECT_EQ(limits.stats().malformed_frames, 2);
  ExpectStatsAddUp(limits);
}

// Every corruption of any single byte of a frame, '\n' included: the frame is refused and
// the intact frame after it is kept.
TEST(FrameParser, RefusesEverySingleByteCorruptionAndKeepsTheNextFrame) {
  const std::string victim = EventText(41, wire::EventKind::kFault, "stall");
  const std::string next = SampleText(42, 777);
  for (size_t at = 0; at < victim.size(); ++at) {
    for (int flip = 1; flip < 256; ++flip) {
      std::string corrupted = victim;
      corrupted[at] = static_cast<char>(corrupted[at] ^ flip);
      FrameParser parser;
      const auto out = FeedAll(parser, corrupted + next);
      ASSERT_EQ(out.size(), 1u) << "byte " << at << " ^ " << flip;
      ASSERT_EQ(out[0].frame.sample.sequence, 42u);
    }
  }
}

// Random garbage (with plenty of '$' and '\n') between frames: every frame is kept, and
// nothing else comes out.
TEST(FrameParser, KeepsEveryFrameAcrossGarbageBursts) {
  std::mt19937 random(20240611);
  std::string stream;
  const uint32_t frames = 3000;
  for (uint32_t sequence = 0; sequence < frames; ++sequence) {
    stream += SampleText(sequence, static_cast<int32_t>(sequence) * 7 - 9000);
    const int burst = std::uniform_int_distribution<int>(0, 3)(random) == 0
                          ? std::uniform_int_distribution<int>(1, 400)(random)
                          : 0;
    for (int i = 0; i < burst; ++i) {
      const int pick = std::uniform_int_distribution<int>(0, 15)(random);
      stream += pick == 0   ? '$'
                : pick == 1 ? '\n'
                : pick == 2 ? '*'
                : pick == 3 ? ','
                            : static_cast<char>(std::uniform_int_distribution<int>(0, 255)(random));
    }
  }
  FrameParser parser;
  std::vector<ReceivedFrame> out;
  for (size_t at = 0; at < stream.size();) {
    const size_t chunk = std::uniform_int_distribution<size_t>(1, 700)(random);
    parser.Feed(Bytes(stream.substr(at, chunk)), 0, out);
    at += chunk;
  }
  ASSERT_EQ(out.size(), frames);
  for (uint32_t i = 0; i < frames; ++i) {
    ASSERT_EQ(out[i].frame.sample.sequence, i);
    ASSERT_EQ(out[i].frame.sample.bend_counts, static_cast<int32_t>(i) * 7 - 9000);
  }
  EXPECT_GT(parser.stats().garbage_bytes + parser.stats().rejected_bytes, 100000);
  ExpectStatsAddUp(parser);
}

TEST(FrameParser, NeverStallsOnAMegabyteOfGarbage) {
  std::mt19937 random(7);
  std::string garbage(1 << 20, '\0');
  for (char& c : garbage) c = static_cast<char>(random());
  FrameParser parser;
  FeedAll(parser, garbage);
  FeedAll(parser, std::string(200000, '$'));
  FeedAll(parser, std::string(200000, 'S'));
  const auto out = FeedAll(parser, SampleText(1) + SampleText(2));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].frame.sample.sequence, 2u);
  ExpectStatsAddUp(parser);
}

// The criterion: a 100,000-frame stream with 1 byte in 1000 corrupted at random.
// Which frames are intact is worked out from the corrupted positions, not by the parser.
TEST(FrameParser, WithOneByteInAThousandCorruptedKeepsEveryIntactFrameAndNoOther) {
  std::mt19937_64 random(5);
  std::string stream;
  std::vector<size_t> starts;  // each frame's first byte; frame i is [starts[i], starts[i+1])
  std::vector<std::string> texts;
  const uint32_t frames = 100000;
  for (uint32_t sequence = 0; sequence < frames; ++sequence) {
    starts.push_back(stream.size());
    texts.push_back(sequence % 1000 == 0  ? HeaderText(sequence)
                    : sequence % 997 == 0 ? EventText(sequence, wire::EventKind::kLedOn)
                                          : SampleText(sequence, static_cast<int32_t>(sequence)));
    stream += texts.back();
  }
  starts.push_back(stream.size());

  // corrupt: each byte, with probability 1/1000, XORed with a random non-zero value
  std::vector<bool> intact(frames, true);
  std::bernoulli_distribution corrupt(0.001);
  std::uniform_int_distribution<int> flip(1, 255);
  size_t frame = 0;
  int64_t corrupted_bytes = 0;
  for (size_t at = 0; at < stream.size(); ++at) {
    while (at >= starts[frame + 1]) ++frame;
    if (corrupt(random)) {
      stream[at] = static_cast<char>(stream[at] ^ flip(random));
      intact[frame] = false;
      ++corrupted_bytes;
    }
  }
  std::set<uint32_t> expected;
  for (uint32_t i = 0; i < frames; ++i) {
    if (intact[i]) expected.insert(i);
  }
  ASSERT_GT(corrupted_bytes, 3000);
  ASSERT_LT(expected.size(), frames - 2500u);

  // parse in serial-port-sized chunks
  FrameParser parser;
  std::vector<ReceivedFrame> out;
  for (size_t at = 0; at < stream.size(); at += 4096) {
    parser.Feed(Bytes(stream.substr(at, 4096)), 0, out);
  }
  std::set<uint32_t> kept;
  for (const ReceivedFrame& received : out) {
    const uint32_t sequence = SequenceOf(received.frame);
    ASSERT_LT(sequence, frames);
    kept.insert(sequence);
    // exactly the frame that was sent
    char text[wire::kMaxFrameBytes];
    size_t size = 0;
    switch (received.frame.type) {
      case wire::FrameType::kSample:
        size = wire::EncodeSample(received.frame.sample, text, sizeof(text));
        break;
      case wire::FrameType::kHeader:
        size = wire::EncodeHeader(received.frame.header, text, sizeof(text));
        break;
      case wire::FrameType::kEvent:
        size = wire::EncodeEvent(received.frame.event, text, sizeof(text));
        break;
      case wire::FrameType::kCommand: break;
    }
    ASSERT_EQ(std::string(text, size), texts[sequence]);
  }
  EXPECT_EQ(out.size(), expected.size());
  EXPECT_EQ(kept, expected);
  EXPECT_EQ(parser.stats().frames, static_cast<int64_t>(expected.size()));
  EXPECT_GT(parser.stats().checksum_errors, 0);
  ExpectStatsAddUp(parser);
}

// docs/protocol.md: every line that starts with '$' is a valid frame, and the one
// indented example of a corrupted frame is refused for its CRC.
TEST(FrameParser, ReadsEveryExampleInTheProtocolDocument) {
  const std::string doc = testing::ReadFile(testing::SourceDir() / "docs/protocol.md");
  ASSERT_FALSE(doc.empty());
  int64_t frame_lines = 0;
  for (size_t at = 0; at < doc.size(); at = doc.find('\n', at) + 1) {
    if (doc[at] == '$') ++frame_lines;
    if (doc.find('\n', at) == std::string::npos) break;
  }
  FrameParser parser;
  const auto out = FeedAll(parser, doc);
  EXPECT_GT(frame_lines, 20);
  EXPECT_EQ(static_cast<int64_t>(out.size()), frame_lines);
  EXPECT_EQ(parser.stats().checksum_errors, 1);
}

// ---------------------------------------------------------------------------------------
// DeviceClock

constexpr int64_t kWrapUs = int64_t{1} << 32;

TEST(DeviceClock, StartsAtTheFirstReading) {
  DeviceClock clock;
  EXPECT_EQ(clock.Unwrap(5212000), 5212000000);
  EXPECT_EQ(clock.Unwrap(5213000), 5213000000);
  EXPECT_EQ(clock.wraps(), 0);
}

TEST(DeviceClock, StaysMonotonicAcrossManyWraps) {
  DeviceClock clock;
  // 1000 s steps for 5 hours: four wraps of the 71.6-minute clock
  for (int64_t i = 0; i <= 18; ++i) {
    const int64_t true_us = i * 1000000000;
    EXPECT_EQ(clock.Unwrap(static_cast<uint32_t>(true_us % kWrapUs)), true_us * 1000) << i;
  }
  EXPECT_EQ(clock.wraps(), 4);
  EXPECT_EQ(clock.backward_steps(), 0);
}

TEST(DeviceClock, UnwrapsTheStepOverTwoToTheThirtyTwo) {
  DeviceClock clock;
  EXPECT_EQ(clock.Unwrap(4294967000u), 4294967000000);
  EXPECT_EQ(clock.Unwrap(200), (kWrapUs + 200) * 1000);
  EXPECT_EQ(clock.wraps(), 1);
}

TEST(DeviceClock, TakesAResetToSmallAfterLargeAsAWrap) {
  // back by more than 2^31 us: the documented rule reads it as a wrap
  DeviceClock clock;
  clock.Unwrap(3000000000u);
  EXPECT_EQ(clock.Unwrap(5), (kWrapUs + 5) * 1000);
  EXPECT_EQ(clock.wraps(), 1);
  EXPECT_EQ(clock.backward_steps(), 0);
}

TEST(DeviceClock, ReportsABackwardStepOfLessThanHalfTheRange) {
  DeviceClock clock;
  clock.Unwrap(1000000000u);
  EXPECT_EQ(clock.Unwrap(500000000u), 500000000000);
  EXPECT_EQ(clock.backward_steps(), 1);
  EXPECT_EQ(clock.wraps(), 0);
  // a stale reading from before a wrap point undoes the wrap
  DeviceClock across;
  across.Unwrap(4294967000u);
  across.Unwrap(100);
  EXPECT_EQ(across.Unwrap(4294967100u), 4294967100000);
  EXPECT_EQ(across.wraps(), 0);
  EXPECT_EQ(across.backward_steps(), 1);
  // a reset starts a new epoch
  across.Reset();
  EXPECT_EQ(across.Unwrap(7), 7000);
}

// ---------------------------------------------------------------------------------------
// SequenceTracker

TEST(SequenceTracker, ReportsNothingForConsecutiveNumbers) {
  SequenceTracker tracker;
  for (uint32_t s = 10; s < 20; ++s) EXPECT_FALSE(tracker.Observe(s).has_value());
  EXPECT_EQ(tracker.observed(), 10);
  EXPECT_EQ(tracker.gaps(), 0);
  EXPECT_EQ(tracker.last(), 19u);
}

TEST(SequenceTracker, ReportsTheFirstMissingNumberAndHowMany) {
  SequenceTracker tracker;
  tracker.Observe(1);
  tracker.Observe(2);
  const auto gap = tracker.Observe(5);
  ASSERT_TRUE(gap.has_value());
  EXPECT_EQ(gap->first_missing, 3u);
  EXPECT_EQ(gap->missing, 2u);
  EXPECT_FALSE(tracker.Observe(6).has_value());
  EXPECT_EQ(tracker.gaps(), 1);
  EXPECT_EQ(tracker.missing(), 2);
}

TEST(SequenceTracker, FollowsTheWrapAtTwoToTheThirtyTwo) {
  SequenceTracker tracker;
  tracker.Observe(4294967294u);
  EXPECT_FALSE(tracker.Observe(4294967295u).has_value());
  EXPECT_FALSE(tracker.Observe(0).has_value());
  SequenceTracker gapped;
  gapped.Observe(4294967294u);
  const auto gap = gapped.Observe(1);
  ASSERT_TRUE(gap.has_value());
  EXPECT_EQ(gap->first_missing, 4294967295u);
  EXPECT_EQ(gap->missing, 2u);  // 4294967295 and 0
  EXPECT_EQ(gapped.resets(), 0);
}

TEST(SequenceTracker, CountsDuplicatesAndResetsWithoutReportingGaps) {
  SequenceTracker tracker;
  tracker.Observe(5);
  EXPECT_FALSE(tracker.Observe(5).has_value());
  EXPECT_EQ(tracker.duplicates(), 1);
  EXPECT_FALSE(tracker.Observe(6).has_value());
  // the controller restarted: numbering begins again
  EXPECT_FALSE(tracker.Observe(0).has_value());
  EXPECT_EQ(tracker.resets(), 1);
  EXPECT_FALSE(tracker.Observe(1).has_value());
  EXPECT_EQ(tracker.gaps(), 0);
  // after Reset() the next number is taken as it comes
  tracker.Reset();
  EXPECT_FALSE(tracker.Observe(1000).has_value());
  EXPECT_EQ(tracker.gaps(), 0);
}

// ---------------------------------------------------------------------------------------
// Frames to log rows

TEST(SampleFromFrame, ConvertsCountsToAnglesThroughTheCalibration) {
  // 12 counts per rotor turn x 1000:1 = 12000 counts per output-shaft turn; 4:1 spur gear
  wire::SampleFrame frame;
  frame.sequence = 99;
  frame.device_time_us = 123;
  frame.led_on = 1;
  frame.bend_counts = 3000;     // a quarter turn of the spool: pi/2
  frame.rotate_counts = -6000;  // half a shaft turn back: -pi; vertebra -pi/4
  frame.bend_setpoint_counts = 1;
  const LogSample sample =
      SampleFromFrame(frame, 5000000, 1700000000000000000, testing::DriveChainCalibration());
  EXPECT_EQ(sample.device_time_ns, 5000000);
  EXPECT_EQ(sample.host_time_ns, 1700000000000000000);
  EXPECT_EQ(sample.sequence, 99u);
  EXPECT_EQ(sample.led_on, true);
  EXPECT_EQ(sample.bend_counts, 3000);
  EXPECT_EQ(sample.rotate_counts, -6000);
  EXPECT_NEAR(sample.bend_spool_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(sample.rotate_shaft_rad, -kPi, 1e-12);
  EXPECT_NEAR(sample.vertebra_rad, -kPi / 4, 1e-12);

  frame.led_on = 0;
  frame.rotate_counts = 1600;  // 2 pi / 7.5 of the shaft, 2 pi / 30 of the vertebra
  const LogSample off = SampleFromFrame(frame, 0, 0, testing::DriveChainCalibration());
  EXPECT_EQ(off.led_on, false);
  EXPECT_NEAR(off.vertebra_rad, 2 * kPi / 30, 1e-12);  // 0.2094 rad
}

wire::EventFrame Event(wire::EventKind kind, int32_t arg, const char* text) {
  wire::EventFrame frame;
  frame.kind = kind;
  frame.arg = arg;
  std::strcpy(frame.text, text);
  return frame;
}

TEST(EventFromFrame, MapsEveryEventKindWithItsDetail) {
  struct Case {
    wire::EventFrame frame;
    LogEventKind kind;
    std::string detail;
  };
  const Case cases[] = {
      {Event(wire::EventKind::kLedOn, 0, ""), LogEventKind::kLedOn, ""},
      {Event(wire::EventKind::kLedOff, 0, ""), LogEventKind::kLedOff, ""},
      {Event(wire::EventKind::kTestStart, 0, ""), LogEventKind::kTestStart, ""},
      {Event(wire::EventKind::kTestEnd, 0, ""), LogEventKind::kTestEnd, "done"},
      {Event(wire::EventKind::kTestEnd, 1, ""), LogEventKind::kTestEnd, "stopped"},
      {Event(wire::EventKind::kTestEnd, 9, ""), LogEventKind::kTestEnd, "code 9"},
      {Event(wire::EventKind::kFault, 3, "bend stall"), LogEventKind::kFault,
       "bend stall (code 3)"},
      {Event(wire::EventKind::kFault, 4, ""), LogEventKind::kFault, "code 4"},
      {Event(wire::EventKind::kPong, 42, ""), LogEventKind::kNote, "PONG 42"},
      {Event(wire::EventKind::kAck, 0, ""), LogEventKind::kNote, "ACK START"},
      {Event(wire::EventKind::kAck, 2, ""), LogEventKind::kNote, "ACK ZERO"},
      {Event(wire::EventKind::kNak, 0, "busy"), LogEventKind::kNote, "NAK START: busy"},
      {Event(wire::EventKind::kNak, 17, ""), LogEventKind::kNote, "NAK command 17"},
      {Event(wire::EventKind::kFault, 1, "tab\there"), LogEventKind::kFault, "tab?here (code 1)"},
  };
  for (const Case& c : cases) {
    const auto event = EventFromFrame(c.frame, 8000, 9000);
    ASSERT_TRUE(event.has_value()) << c.detail;
    EXPECT_EQ(event->kind, c.kind) << c.detail;
    EXPECT_EQ(event->detail, c.detail);
    EXPECT_EQ(event->device_time_ns, 8000);
    EXPECT_EQ(event->host_time_ns, 9000);
  }
  EXPECT_FALSE(EventFromFrame(Event(wire::EventKind::kCount, 0, ""), 0, 0).has_value());
}

}  // namespace
}  // namespace liftoff::capture
