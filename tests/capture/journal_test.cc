// The raw capture journal: byte-exact round trips, a cut-off last record tolerated and
// reported, clear errors for what is not a journal, and a replay that rebuilds the log
// live capture would have written (checked against hand-computed samples).
#include "liftoff/capture/journal.h"

#include <cmath>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/capture/capture_session.h"
#include "liftoff/capture/wire_format.h"
#include "support/test_support.h"

namespace liftoff::capture {
namespace {

using liftoff::testing::DriveChainCalibration;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

constexpr int64_t kStartNs = 1'700'000'000'000'000'000;

std::span<const uint8_t> Bytes(const std::string& text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

std::string Sample(uint32_t sequence, uint32_t t_us, bool led, int32_t bend, int32_t rotate) {
  wire::SampleFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = t_us;
  frame.led_on = led ? 1 : 0;
  frame.bend_counts = bend;
  frame.rotate_counts = rotate;
  char out[wire::kMaxFrameBytes];
  const size_t size = wire::EncodeSample(frame, out, sizeof out);
  EXPECT_GT(size, 0u);
  return std::string(out, size);
}

std::string Event(uint32_t sequence, uint32_t t_us, wire::EventKind kind, int32_t arg) {
  wire::EventFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = t_us;
  frame.kind = kind;
  frame.arg = arg;
  char out[wire::kMaxFrameBytes];
  const size_t size = wire::EncodeEvent(frame, out, sizeof out);
  EXPECT_GT(size, 0u);
  return std::string(out, size);
}

std::string Header(uint32_t sequence, uint32_t t_us) {
  wire::HeaderFrame frame;
  frame.sequence = sequence;
  frame.device_time_us = t_us;
  std::snprintf(frame.firmware, sizeof frame.firmware, "test-fw 2.1");
  frame.counts_per_motor_rev = 12;
  frame.gearbox_ratio = 1000;
  frame.spur_gear_ratio = 4;
  char out[wire::kMaxFrameBytes];
  const size_t size = wire::EncodeHeader(frame, out, sizeof out);
  EXPECT_GT(size, 0u);
  return std::string(out, size);
}

JournalHeader TestHeader() {
  JournalHeader header;
  header.port = "/dev/ttyACM7";
  header.settings = "115200 8N1";
  header.start_time_ns = kStartNs;
  header.writer = "liftoff test";
  return header;
}

// Writes `chunks` as received records, 1 ms apart.
void WriteJournal(const std::filesystem::path& path, const std::vector<std::string>& chunks) {
  JournalWriter writer;
  ASSERT_TRUE(writer.Open(path, TestHeader()).ok());
  int64_t t_ns = kStartNs;
  for (const std::string& chunk : chunks) {
    ASSERT_TRUE(writer.Append(Bytes(chunk), t_ns += 1'000'000).ok());
  }
  ASSERT_TRUE(writer.Close().ok());
}

std::vector<JournalChunk> ReadAll(const std::filesystem::path& path, JournalReader& reader) {
  std::vector<JournalChunk> chunks;
  EXPECT_TRUE(reader.Open(path).ok());
  JournalChunk chunk;
  while (reader.Next(chunk)) chunks.push_back(chunk);
  EXPECT_TRUE(reader.status().ok()) << reader.status().ToString();
  return chunks;
}

// ---------------------------------------------------------------------------------------
// writing and reading

TEST(Journal, RoundTripsEveryByteWithTimesAndKinds) {
  ScratchDir dir;
  std::string binary;
  for (int byte = 0; byte < 256; ++byte) binary += static_cast<char>(byte);
  {
    JournalWriter writer;
    ASSERT_TRUE(writer.Open(dir / "sub" / "a.journal", TestHeader()).ok());
    ASSERT_TRUE(writer.Append(Bytes("$S,1,2*0000\n"), kStartNs + 5).ok());
    ASSERT_TRUE(writer.Append(Bytes(binary), kStartNs + 6).ok());
    ASSERT_TRUE(
        writer.Append(Bytes("$C,PING,1,0,0,0*ABCD\n"), kStartNs + 7, JournalRecordKind::kSent)
            .ok());
    ASSERT_TRUE(writer.AppendNote(JournalRecordKind::kLinkLost, "gone", kStartNs + 8).ok());
    ASSERT_TRUE(writer.AppendNote(JournalRecordKind::kLinkRestored, "back", kStartNs + 9).ok());
    EXPECT_EQ(writer.bytes_received(), 12 + 256);
    ASSERT_TRUE(writer.Close().ok());
  }
  JournalReader reader;
  const std::vector<JournalChunk> chunks = ReadAll(dir / "sub" / "a.journal", reader);
  EXPECT_EQ(reader.header().port, "/dev/ttyACM7");
  EXPECT_EQ(reader.header().settings, "115200 8N1");
  EXPECT_EQ(reader.header().start_time_ns, kStartNs);
  EXPECT_EQ(reader.header().writer, "liftoff test");
  ASSERT_EQ(chunks.size(), 5u);
  EXPECT_EQ(chunks[0].bytes, "$S,1,2*0000\n");
  EXPECT_EQ(chunks[0].host_time_ns, kStartNs + 5);
  EXPECT_EQ(chunks[0].kind, JournalRecordKind::kReceived);
  EXPECT_EQ(chunks[1].bytes, binary);
  EXPECT_EQ(chunks[2].kind, JournalRecordKind::kSent);
  EXPECT_EQ(chunks[3].kind, JournalRecordKind::kLinkLost);
  EXPECT_EQ(chunks[3].bytes, "gone");
  EXPECT_EQ(chunks[4].kind, JournalRecordKind::kLinkRestored);
  EXPECT_EQ(chunks[4].host_time_ns, kStartNs + 9);
  EXPECT_FALSE(reader.truncated());
}

TEST(Journal, FileLayoutIsMagicHeaderThenTimeLengthBytes) {
  ScratchDir dir;
  WriteJournal(dir / "a.journal", {"AB"});
  const std::string file = ReadFile(dir / "a.journal");
  const std::string header_text =
      "port: /dev/ttyACM7\nsettings: 115200 8N1\nstart_time_ns: 1700000000000000000\n"
      "writer: liftoff test\n";
  ASSERT_EQ(file.size(), 4 + 4 + header_text.size() + 8 + 4 + 2);
  EXPECT_EQ(file.substr(0, 4), "LFJ1");
  EXPECT_EQ(static_cast<uint8_t>(file[4]), header_text.size());  // little-endian length
  EXPECT_EQ(file.substr(8, header_text.size()), header_text);
  const std::string record = file.substr(8 + header_text.size());
  // host time kStartNs + 1 ms, little-endian
  const int64_t t_ns = kStartNs + 1'000'000;
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(static_cast<uint8_t>(record[static_cast<size_t>(i)]),
              (static_cast<uint64_t>(t_ns) >> (8 * i)) & 0xFF);
  }
  EXPECT_EQ(record.substr(8, 4), std::string("\x02\x00\x00\x00", 4));  // length 2, kind 0
  EXPECT_EQ(record.substr(12), "AB");
}

TEST(Journal, HandsBytesToTheOperatingSystemOnceEnoughAreBuffered) {
  ScratchDir dir;
  JournalWriter writer;
  JournalWriter::Options options;
  options.flush_bytes = 100;
  ASSERT_TRUE(writer.Open(dir / "a.journal", TestHeader(), options).ok());
  const size_t header_size = ReadFile(dir / "a.journal").size();
  ASSERT_TRUE(writer.Append(Bytes(std::string(40, 'x')), kStartNs).ok());
  EXPECT_EQ(ReadFile(dir / "a.journal").size(), header_size) << "40 + 12 bytes stay buffered";
  ASSERT_TRUE(writer.Append(Bytes(std::string(60, 'y')), kStartNs).ok());
  // both records are in the file while the writer is still open: a crash loses neither
  EXPECT_EQ(ReadFile(dir / "a.journal").size(), header_size + 12 + 40 + 12 + 60);
  ASSERT_TRUE(writer.Close().ok());
}

TEST(Journal, ToleratesAndReportsACutOffLastRecord) {
  ScratchDir dir;
  WriteJournal(dir / "a.journal", {"first\n", "second\n", "third record\n"});
  const std::string whole = ReadFile(dir / "a.journal");
  // cut inside the last payload: 12-byte record header + 5 of its 13 bytes remain
  WriteFile(dir / "cut.journal", whole.substr(0, whole.size() - 8));
  JournalReader reader;
  const std::vector<JournalChunk> chunks = ReadAll(dir / "cut.journal", reader);
  ASSERT_EQ(chunks.size(), 2u);
  EXPECT_EQ(chunks[1].bytes, "second\n");
  EXPECT_TRUE(reader.truncated());
  EXPECT_EQ(reader.truncated_bytes(), 12 + 5);

  // cut inside the last record's own header
  WriteFile(dir / "cut2.journal", whole.substr(0, whole.size() - 13 - 9));
  JournalReader reader2;
  EXPECT_EQ(ReadAll(dir / "cut2.journal", reader2).size(), 2u);
  EXPECT_TRUE(reader2.truncated());
  EXPECT_EQ(reader2.truncated_bytes(), 3);
}

TEST(Journal, ReplayReportsACutOffLastRecordAndKeepsTheRest) {
  ScratchDir dir;
  WriteJournal(dir / "a.journal", {Sample(0, 1000, false, 0, 0), Sample(1, 2000, false, 0, 12)});
  const std::string whole = ReadFile(dir / "a.journal");
  WriteFile(dir / "cut.journal", whole.substr(0, whole.size() - 4));
  auto replay = ReplayJournal(dir / "cut.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  EXPECT_TRUE(replay->truncated);
  ASSERT_EQ(replay->log.samples.size(), 1u);
  EXPECT_EQ(replay->log.samples[0].sequence, 0u);
  EXPECT_THAT(replay->Brief(), HasSubstr("last record cut off"));
}

TEST(Journal, ErrorsNameTheFileAndWhere) {
  ScratchDir dir;
  JournalReader reader;
  Status status = reader.Open(dir / "missing.journal");
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_THAT(status.message(), HasSubstr("missing.journal: no such file"));

  WriteFile(dir / "text.csv", "# liftoff-log 1\n");
  status = reader.Open(dir / "text.csv");
  EXPECT_EQ(status.code(), StatusCode::kParse);
  EXPECT_THAT(status.message(),
              HasSubstr("text.csv: byte 0: expected the journal magic \"LFJ1\", got \"# li\""));

  WriteFile(dir / "v2.journal", std::string("LFJ2\0\0\0\0", 8));
  status = reader.Open(dir / "v2.journal");
  EXPECT_EQ(status.code(), StatusCode::kUnsupported);
  EXPECT_THAT(status.message(), HasSubstr("v2.journal: journal version \"LFJ2\""));

  WriteFile(dir / "short.journal", std::string("LFJ1\x40\0\0\0port", 12));
  status = reader.Open(dir / "short.journal");
  EXPECT_EQ(status.code(), StatusCode::kParse);
  EXPECT_THAT(status.message(), HasSubstr("short.journal: byte 8: header cut off"));

  // a record of kind 9 at byte 8 + 0 (empty header)
  std::string bad("LFJ1\0\0\0\0", 8);
  bad += std::string(8, '\0') + std::string("\x01\x00\x00\x90", 4) + "x";
  WriteFile(dir / "kind.journal", bad);
  ASSERT_TRUE(reader.Open(dir / "kind.journal").ok());
  JournalChunk chunk;
  EXPECT_FALSE(reader.Next(chunk));
  EXPECT_EQ(reader.status().code(), StatusCode::kParse);
  EXPECT_THAT(reader.status().message(), HasSubstr("kind.journal: byte 8: unknown record kind 9"));
  EXPECT_EQ(ReplayJournal(dir / "kind.journal", DriveChainCalibration()).status().code(),
            StatusCode::kParse);
}

TEST(Journal, ReaderReopenedAfterAFailedOpenClosesItsFileOnce) {
  ScratchDir dir;
  WriteJournal(dir / "a.journal", {"first\n"});
  JournalReader reader;
  ASSERT_TRUE(reader.Open(dir / "a.journal").ok());
  // the valid file is closed here; the failed opens must not close it again (a double
  // fclose, which ASan reports as a double free), nor must the destructor
  EXPECT_EQ(reader.Open(dir / "missing.journal").code(), StatusCode::kNotFound);
  EXPECT_EQ(reader.Open(dir / "missing2.journal").code(), StatusCode::kNotFound);
  JournalChunk chunk;
  EXPECT_FALSE(reader.Next(chunk));
  // and it still reads a journal afterwards
  ASSERT_TRUE(reader.Open(dir / "a.journal").ok());
  ASSERT_TRUE(reader.Next(chunk));
  EXPECT_EQ(chunk.bytes, "first\n");
}

TEST(Journal, CorruptRecordLengthIsAParseErrorNamingTheByte) {
  ScratchDir dir;
  WriteJournal(dir / "a.journal", {"first\n", "second\n"});
  std::string whole = ReadFile(dir / "a.journal");
  // the second record's length field: 0x0FFFFFFF (256 MiB), far past the 16 MiB cap
  JournalReader probe;
  ASSERT_TRUE(probe.Open(dir / "a.journal").ok());
  JournalChunk chunk;
  ASSERT_TRUE(probe.Next(chunk));
  const auto second = static_cast<size_t>(probe.offset());
  whole.replace(second + 8, 4, std::string("\xff\xff\xff\x0f", 4));
  WriteFile(dir / "corrupt.journal", whole);

  JournalReader reader;
  ASSERT_TRUE(reader.Open(dir / "corrupt.journal").ok());
  ASSERT_TRUE(reader.Next(chunk));
  EXPECT_EQ(chunk.bytes, "first\n");
  EXPECT_FALSE(reader.Next(chunk));
  EXPECT_FALSE(reader.truncated());
  EXPECT_EQ(reader.status().code(), StatusCode::kParse);
  EXPECT_THAT(reader.status().message(),
              HasSubstr("corrupt.journal: byte " + std::to_string(second) +
                        ": record length 268435455 exceeds 16777216"));
  EXPECT_EQ(ReplayJournal(dir / "corrupt.journal", DriveChainCalibration()).status().code(),
            StatusCode::kParse);
}

// ---------------------------------------------------------------------------------------
// replay

TEST(Journal, ReplayRebuildsSamplesFromFramesSplitAcrossChunks) {
  ScratchDir dir;
  // header, LED on, three samples; chunks cut mid-frame
  const std::string stream = Header(0, 500) + Event(1, 1000, wire::EventKind::kLedOn, 0) +
                             Sample(2, 1000, true, 6000, 12000) +
                             Sample(3, 2000, true, 6000, -3000) + Sample(4, 3000, true, -1, 1);
  std::vector<std::string> chunks;
  for (size_t at = 0; at < stream.size(); at += 37) chunks.push_back(stream.substr(at, 37));
  WriteJournal(dir / "a.journal", chunks);

  auto replay = ReplayJournal(dir / "a.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  const ControllerLog& log = replay->log;
  EXPECT_EQ(log.header.calibration, "test");
  EXPECT_EQ(log.header.device, "test-fw 2.1");
  EXPECT_THAT(log.header.source, HasSubstr("a.journal"));
  EXPECT_THAT(log.header.source, HasSubstr("/dev/ttyACM7"));
  EXPECT_EQ(log.header.metadata.at("device_counts_per_motor_rev"), "12");
  ASSERT_EQ(log.samples.size(), 3u);
  ASSERT_EQ(log.events.size(), 1u);
  EXPECT_EQ(log.events[0].kind, LogEventKind::kLedOn);
  EXPECT_EQ(log.events[0].device_time_ns, 1'000'000);

  // 12000 counts = 1000 rotor revolutions = 1 output-shaft revolution = a quarter turn
  // of the vertebra; 6000 counts = half a spool turn
  const LogSample& first = log.samples[0];
  EXPECT_EQ(first.device_time_ns, 1'000'000);
  EXPECT_EQ(first.sequence, 2u);
  EXPECT_EQ(first.led_on, true);
  EXPECT_EQ(first.bend_counts, 6000);
  EXPECT_EQ(first.rotate_counts, 12000);
  EXPECT_NEAR(first.bend_spool_rad, std::numbers::pi, 1e-12);
  EXPECT_NEAR(first.rotate_shaft_rad, 2 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(first.vertebra_rad, std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(log.samples[1].vertebra_rad, -std::numbers::pi / 8, 1e-12);
  EXPECT_EQ(log.samples[2].device_time_ns, 3'000'000);
  // each sample carries the host time of the chunk that held its line end
  const size_t end_of_first = stream.find('\n', stream.find("$S")) + 1;
  EXPECT_EQ(first.host_time_ns,
            kStartNs + static_cast<int64_t>((end_of_first + 36) / 37) * 1'000'000);
  EXPECT_EQ(replay->frames, 5);
  EXPECT_EQ(replay->bytes, static_cast<int64_t>(stream.size()));
}

TEST(Journal, ReplayMarksGapsSkipsCorruptionAndDropsStaleFrames) {
  ScratchDir dir;
  std::string corrupted = Sample(2, 3000, false, 0, 24);
  corrupted[10] ^= 0x04;  // one bit flipped in a digit: the CRC no longer matches
  const std::string stream = Sample(0, 1000, false, 0, 0) + Sample(1, 2000, false, 0, 12) +
                             corrupted + Sample(3, 4000, false, 0, 36) + "noise\n" +
                             Sample(6, 7000, false, 0, 72) + Sample(6, 7000, false, 0, 72) +
                             Sample(7, 8000, false, 0, 84);
  WriteJournal(dir / "a.journal", {stream});
  auto replay = ReplayJournal(dir / "a.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  const ControllerLog& log = replay->log;
  std::vector<uint32_t> sequences;
  for (const LogSample& sample : log.samples) sequences.push_back(*sample.sequence);
  EXPECT_THAT(sequences, ::testing::ElementsAre(0u, 1u, 3u, 6u, 7u));
  EXPECT_EQ(replay->checksum_errors, 1);
  EXPECT_EQ(replay->garbage_bytes, 6);
  EXPECT_EQ(replay->duplicates, 1);
  EXPECT_EQ(replay->gaps, 2);
  EXPECT_EQ(replay->missing_frames, 3);
  ASSERT_EQ(log.events.size(), 2u);
  // gaps sit halfway between the frames around them
  EXPECT_EQ(log.events[0].kind, LogEventKind::kGap);
  EXPECT_EQ(log.events[0].detail, "1 frame, sequence 2");
  EXPECT_EQ(log.events[0].device_time_ns, 3'000'000);
  EXPECT_EQ(log.events[1].detail, "2 frames, sequence 4..5");
  EXPECT_EQ(log.events[1].device_time_ns, 5'500'000);
}

TEST(Journal, ReplayMarksTheReconnectAndRecordsTheStartCommand) {
  ScratchDir dir;
  {
    JournalWriter writer;
    ASSERT_TRUE(writer.Open(dir / "a.journal", TestHeader()).ok());
    wire::CommandFrame start;
    start.command = wire::CommandKind::kStart;
    start.args[0] = 3;  // HL
    start.args[1] = 750;
    start.args[2] = -45000;
    start.args[3] = 20000;
    char out[wire::kMaxFrameBytes];
    const size_t size = wire::EncodeCommand(start, out, sizeof out);
    ASSERT_TRUE(
        writer.Append(Bytes(std::string(out, size)), kStartNs, JournalRecordKind::kSent).ok());
    ASSERT_TRUE(
        writer.Append(Bytes(Sample(0, 1000, false, 0, 0) + "$S,1,20"), kStartNs + 1'000'000).ok());
    ASSERT_TRUE(
        writer.AppendNote(JournalRecordKind::kLinkLost, "hang-up", kStartNs + 2'000'000).ok());
    ASSERT_TRUE(
        writer.AppendNote(JournalRecordKind::kLinkRestored, "reopened", kStartNs + 1'502'000'000)
            .ok());
    // the half frame before the loss is not glued to this one
    ASSERT_TRUE(writer
                    .Append(Bytes("00,0,0,0,0,0*1234\n" + Sample(5, 6000, false, 0, 0)),
                            kStartNs + 1'600'000'000)
                    .ok());
    ASSERT_TRUE(writer.Close().ok());
  }
  auto replay = ReplayJournal(dir / "a.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  const ControllerLog& log = replay->log;
  ASSERT_EQ(log.samples.size(), 2u);
  ASSERT_EQ(log.events.size(), 2u);
  EXPECT_EQ(log.events[0].kind, LogEventKind::kReconnect);
  EXPECT_EQ(log.events[0].detail, "port reopened after 1.50 s without link");
  EXPECT_EQ(log.events[1].kind, LogEventKind::kGap);
  EXPECT_EQ(log.events[1].detail, "4 frames, sequence 1..4");
  EXPECT_EQ(log.events[1].device_time_ns, 3'500'000);
  EXPECT_EQ(log.header.metadata.at("commanded_pulled_group"), "HL");
  EXPECT_EQ(log.header.metadata.at("commanded_bend_percent"), "75.0");
  EXPECT_EQ(log.header.metadata.at("commanded_ramp_deg"), "-45.000");
  EXPECT_EQ(log.header.metadata.at("commanded_ramp_s"), "20.000");
}

TEST(Journal, ReplayKeepsRowsComingAfterAControllerRestart) {
  ScratchDir dir;
  // the controller runs for 5 s, restarts (sequence and clock from 0), runs its test to
  // the end; a stale repeat of the last frame before the restart is still dropped
  const std::string before = Header(0, 100) + Sample(1, 4'000'000, false, 0, 0) +
                             Sample(2, 5'000'000, true, 0, 0) + Sample(2, 5'000'000, true, 0, 0);
  const std::string after = Header(0, 50) + Sample(1, 1000, false, 0, 0) +
                            Event(2, 1500, wire::EventKind::kTestStart, 0) +
                            Sample(3, 2000, true, 0, 0) + Sample(5, 4000, true, 0, 0) +
                            Event(6, 4500, wire::EventKind::kTestEnd, 0);
  WriteJournal(dir / "a.journal", {before, after});
  auto replay = ReplayJournal(dir / "a.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  const ControllerLog& log = replay->log;
  std::vector<uint32_t> sequences;
  for (const LogSample& sample : log.samples) sequences.push_back(*sample.sequence);
  ASSERT_THAT(sequences, ::testing::ElementsAre(1u, 2u, 1u, 3u, 5u));
  EXPECT_EQ(replay->duplicates, 1);
  // time continues after the last row: the restart's header frame lands 1 us after it
  const int64_t restart_ns = 5'000'000'000 + 1'000;
  EXPECT_EQ(log.samples[2].device_time_ns, restart_ns + 950'000);
  EXPECT_EQ(log.samples[4].device_time_ns, restart_ns + 3'950'000);
  for (size_t i = 1; i < log.samples.size(); ++i) {
    EXPECT_GT(log.samples[i].device_time_ns, log.samples[i - 1].device_time_ns);
  }
  // a note marks the restart; the gap after it is counted from the new sequence
  std::vector<LogEventKind> kinds;
  for (const LogEvent& event : log.events) kinds.push_back(event.kind);
  ASSERT_THAT(kinds, ::testing::ElementsAre(LogEventKind::kNote, LogEventKind::kTestStart,
                                            LogEventKind::kGap, LogEventKind::kTestEnd));
  EXPECT_EQ(log.events[0].detail,
            "controller restarted: sequence 2 -> 0, device clock 5.000 s -> 0.000 s");
  EXPECT_EQ(log.events[2].detail, "1 frame, sequence 4");
  EXPECT_EQ(replay->gaps, 1);
  EXPECT_EQ(log.events[3].device_time_ns, restart_ns + 4'450'000);

  // the live decoder sees the test end after the restart (a capture stops there)
  const Calibration calibration = DriveChainCalibration();
  StreamDecoder decoder(calibration);
  std::vector<LogRow> rows;
  decoder.Feed(Bytes(before), kStartNs, rows);
  EXPECT_FALSE(decoder.test_ended());
  decoder.Feed(Bytes(after), kStartNs + 1'000'000, rows);
  EXPECT_TRUE(decoder.test_ended());
  EXPECT_EQ(decoder.counters().restarts, 1);
  EXPECT_EQ(rows.size(), log.samples.size() + log.events.size());
}

TEST(Journal, ReplayHeaderMatchesTheLiveCapturesHeader) {
  ScratchDir dir;
  WriteJournal(dir / "cap.journal", {Header(0, 100) + Sample(1, 1000, false, 0, 0)});
  auto replay = ReplayJournal(dir / "cap.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  const LogHeader& header = replay->log.header;
  EXPECT_EQ(header.metadata.at("port_settings"), "115200 8N1");
  EXPECT_EQ(header.metadata.at("journal"), "cap.journal");
  EXPECT_EQ(header.device, "test-fw 2.1");
  EXPECT_EQ(header.metadata.at("device_gearbox_ratio"), "1000");
}

TEST(Journal, ReplayEqualsTheLogOfTheSameBytesFedAtOnce) {
  ScratchDir dir;
  std::string stream = Header(0, 0);
  for (uint32_t i = 1; i <= 500; ++i) {
    stream += Sample(i, i * 1000, i > 100, static_cast<int32_t>(i), -static_cast<int32_t>(3 * i));
  }
  // the journal in uneven chunks; the direct parse in one piece
  std::vector<std::string> chunks;
  for (size_t at = 0, size = 1; at < stream.size(); at += size, size = size * 7 % 97 + 1) {
    chunks.push_back(stream.substr(at, size));
  }
  WriteJournal(dir / "a.journal", chunks);
  auto replay = ReplayJournal(dir / "a.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();

  const Calibration calibration = DriveChainCalibration();
  StreamDecoder decoder(calibration);
  std::vector<LogRow> rows;
  decoder.Feed(Bytes(stream), 0, rows);
  decoder.Finish(rows);  // the last sample waits for its instant to end
  ASSERT_EQ(rows.size(), 500u);
  ASSERT_EQ(replay->log.samples.size(), 500u);
  for (size_t i = 0; i < rows.size(); ++i) {
    const LogSample& direct = std::get<LogSample>(rows[i]);
    const LogSample& replayed = replay->log.samples[i];
    EXPECT_EQ(replayed.device_time_ns, direct.device_time_ns);
    EXPECT_EQ(replayed.sequence, direct.sequence);
    EXPECT_EQ(replayed.led_on, direct.led_on);
    EXPECT_EQ(replayed.bend_counts, direct.bend_counts);
    EXPECT_EQ(replayed.rotate_counts, direct.rotate_counts);
    EXPECT_EQ(replayed.vertebra_rad, direct.vertebra_rad);
    // and both equal what was sent
    EXPECT_EQ(replayed.device_time_ns, static_cast<int64_t>(i + 1) * 1'000'000);
    EXPECT_EQ(replayed.rotate_counts, -3 * static_cast<int64_t>(i + 1));
  }
}

// ---------------------------------------------------------------------------------------
// dump

TEST(Journal, DumpShowsFramesAsTextWithTimesAndReportsACutOffEnd) {
  ScratchDir dir;
  const std::string frame = Sample(0, 1000, false, 0, 0);
  WriteJournal(dir / "a.journal", {frame + "\x01zz", "tail\n"});
  const std::string whole = ReadFile(dir / "a.journal");
  WriteFile(dir / "cut.journal", whole.substr(0, whole.size() - 2));
  std::ostringstream out;
  ASSERT_TRUE(DumpJournal(dir / "cut.journal", {}, out).ok());
  const std::string text = out.str();
  EXPECT_THAT(text, HasSubstr("port: /dev/ttyACM7"));
  const std::string size = std::to_string(frame.size() + 3);
  EXPECT_THAT(text,
              HasSubstr("+0.001000 s  received " + size + " bytes\n  " + frame + "  \\x01zz\n"));
  EXPECT_THAT(text, HasSubstr("1 record, " + size +
                              " bytes received; the last record is cut off (15 bytes"));

  std::ostringstream hex;
  JournalDumpOptions options;
  options.text = false;
  ASSERT_TRUE(DumpJournal(dir / "a.journal", options, hex).ok());
  EXPECT_THAT(hex.str(), HasSubstr("  24 53 2c 30"));  // "$S,0"
}

TEST(Journal, DumpOptionsRefuseANegativeRecordCount) {
  JournalDumpOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.max_records = -1;
  const Status valid = options.Validate();
  EXPECT_EQ(valid.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(valid.message(), "max_records: expected >= 0, got -1");
  // checked before the file is opened
  std::ostringstream out;
  EXPECT_EQ(DumpJournal("no-such.journal", options, out).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace liftoff::capture
