#include "liftoff/core/controller_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/test_support.h"

namespace liftoff {
namespace {

using ::testing::HasSubstr;
using testing::ReadFile;
using testing::ScratchDir;
using ::testing::StartsWith;
using testing::WriteFile;

constexpr char kColumns[] =
    "device_time_ns,host_time_ns,seq,led,bend_counts,rotate_counts,bend_spool_rad,rotate_shaft_rad,"
    "vertebra_rad,event,detail";

// A small log as a person would write it by hand, lines joined with `eol`.
std::string HandLog(const std::string& eol) {
  return "# liftoff-log 1" + eol + "# calibration: laika-2018" + eol +
         "# source: capture /dev/ttyACM0" + eol + "# device: laika-fw 2018.2" + eol +
         "# test_number: 3" + eol + kColumns + eol +
         "-5000000,1700000000000000000,41,0,12,-24,0.5,-0.25,-0.0625,," + eol +
         "0,,,,,,,,,led_on," + eol + "0,1700000000005000000,42,1,,-36,,-0.375,,," + eol +
         "5000000,,43,1,,,,,,," + eol;
}

TEST(ControllerLog, ReadsEveryFieldOfAHandWrittenLog) {
  ScratchDir dir;
  WriteFile(dir / "trial.csv", HandLog("\n"));
  const Result<ControllerLog> log = ReadControllerLog(dir / "trial.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();

  EXPECT_EQ(log->header.version, 1);
  EXPECT_EQ(log->header.calibration, "laika-2018");
  EXPECT_EQ(log->header.source, "capture /dev/ttyACM0");
  EXPECT_EQ(log->header.device, "laika-fw 2018.2");
  EXPECT_EQ(log->header.metadata, (std::map<std::string, std::string>{{"test_number", "3"}}));

  ASSERT_EQ(log->samples.size(), 3u);
  const LogSample& first = log->samples[0];
  EXPECT_EQ(first.device_time_ns, -5'000'000);
  EXPECT_EQ(first.host_time_ns, 1'700'000'000'000'000'000);
  EXPECT_EQ(first.sequence, 41u);
  EXPECT_EQ(first.led_on, false);
  EXPECT_EQ(first.bend_counts, 12);
  EXPECT_EQ(first.rotate_counts, -24);
  EXPECT_EQ(first.bend_spool_rad, 0.5);
  EXPECT_EQ(first.rotate_shaft_rad, -0.25);
  EXPECT_EQ(first.vertebra_rad, -0.0625);

  const LogSample& last = log->samples[2];
  EXPECT_EQ(last.device_time_ns, 5'000'000);
  EXPECT_FALSE(last.host_time_ns.has_value());
  EXPECT_EQ(last.sequence, 43u);
  EXPECT_EQ(last.led_on, true);
  EXPECT_FALSE(last.bend_counts.has_value());
  EXPECT_FALSE(last.rotate_counts.has_value());
  EXPECT_TRUE(std::isnan(last.bend_spool_rad));
  EXPECT_TRUE(std::isnan(last.rotate_shaft_rad));
  EXPECT_TRUE(std::isnan(last.vertebra_rad));

  ASSERT_EQ(log->events.size(), 1u);
  EXPECT_EQ(log->events[0].kind, LogEventKind::kLedOn);
  EXPECT_EQ(log->events[0].device_time_ns, 0);
  EXPECT_EQ(log->events[0].detail, "");

  EXPECT_EQ(log->report.format, "liftoff");
  EXPECT_EQ(log->report.lines_total, 4);
  EXPECT_EQ(log->report.samples, 3);
  EXPECT_EQ(log->report.events, 1);
  EXPECT_EQ(log->report.bad_lines, 0);
  EXPECT_FALSE(log->report.truncated_last_line);
  EXPECT_EQ(log->FirstSampleNs(), -5'000'000);
  EXPECT_EQ(log->LastSampleNs(), 5'000'000);
}

TEST(ControllerLog, AcceptsLfCrAndCrlfLineEndsAlike) {
  for (const std::string eol : {"\n", "\r", "\r\n"}) {
    SCOPED_TRACE(eol == "\n" ? "LF" : eol == "\r" ? "CR" : "CRLF");
    ScratchDir dir;
    WriteFile(dir / "trial.csv", HandLog(eol));
    const Result<ControllerLog> log = ReadControllerLog(dir / "trial.csv");
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    EXPECT_EQ(log->header.calibration, "laika-2018");
    ASSERT_EQ(log->samples.size(), 3u);
    EXPECT_EQ(log->samples[1].device_time_ns, 0);
    EXPECT_EQ(log->samples[1].rotate_shaft_rad, -0.375);
    EXPECT_EQ(log->events.size(), 1u);

    // line numbers count each line end once, whatever its style
    WriteFile(dir / "bad.csv", HandLog(eol) + "garbage" + eol);
    const Result<ControllerLog> bad = ReadControllerLog(dir / "bad.csv");
    ASSERT_FALSE(bad.ok());
    EXPECT_THAT(bad.status().message(), HasSubstr("bad.csv:11: "));
  }
}

TEST(ControllerLog, WritesTheDocumentedLayout) {
  ScratchDir dir;
  ControllerLog log;
  log.header.calibration = "laika-2018";
  log.header.source = "test";
  log.header.metadata["pulled_group"] = "HR";
  LogSample sample;
  sample.device_time_ns = 1'000'000;
  sample.sequence = 7;
  sample.led_on = true;
  sample.rotate_counts = -12000;
  sample.rotate_shaft_rad = -0.1;
  log.samples.push_back(sample);
  log.events.push_back(
      {1'000'000, 1'700'000'000'000'000'000, LogEventKind::kFault, "stall, motor 3"});
  ASSERT_TRUE(WriteControllerLog(dir / "out.csv", log).ok());

  // an event goes before the sample at its instant; a detail with a comma is quoted
  EXPECT_EQ(ReadFile(dir / "out.csv"),
            std::string("# liftoff-log 1\n"
                        "# calibration: laika-2018\n"
                        "# source: test\n"
                        "# device:\n"
                        "# pulled_group: HR\n") +
                kColumns + "\n" +
                "1000000,1700000000000000000,,,,,,,,fault,\"stall, motor 3\"\n"
                "1000000,,7,1,,-12000,,-0.1,,,\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.csv.tmp"));
}

TEST(ControllerLog, RoundTripsSamplesEventsAndMissingFieldsExactly) {
  ScratchDir dir;
  ControllerLog original;
  original.header.calibration = "laika-2018";
  original.header.source = "import laika-2018 Test1 Front Right Blue.txt";
  original.header.device = "emulator 0.1";
  original.header.metadata = {{"commanded_rad", "0.5"}, {"operator.name", "J. Doe"}};

  // angles whose shortest text is long, tiny or negative must come back bit for bit
  const double angles[] = {0.1 + 0.2, -3.141592653589793, 1e-300, 2.5e10};
  for (int i = 0; i < 4; ++i) {
    LogSample sample;
    sample.device_time_ns = int64_t{1'000'000} * i - 3;
    if (i % 2 == 0) sample.host_time_ns = int64_t{1'700'000'000'123'456'789} + i;
    if (i != 1) sample.sequence = 4'294'967'295u - static_cast<uint32_t>(i);
    if (i != 2) sample.led_on = i >= 2;
    if (i != 3) sample.bend_counts = -9'000'000'000'000 + i;
    sample.rotate_counts = i * 1000;
    sample.bend_spool_rad = i == 0 ? kNotMeasured : angles[i];
    sample.rotate_shaft_rad = angles[i];
    sample.vertebra_rad = i == 3 ? kNotMeasured : -angles[i];
    original.samples.push_back(sample);
  }
  original.events = {
      {-10, std::nullopt, LogEventKind::kTestStart, ""},
      {1'999'997, 5, LogEventKind::kLedOn, ""},
      {2'000'000, std::nullopt, LogEventKind::kGap, "3"},
      {2'500'000, std::nullopt, LogEventKind::kNote, "say \"hi\", # not a comment"},
      {9'000'000, std::nullopt, LogEventKind::kTestEnd, ""},
  };
  ASSERT_TRUE(WriteControllerLog(dir / "log.csv", original).ok());

  const Result<ControllerLog> read = ReadControllerLog(dir / "log.csv");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->header.calibration, original.header.calibration);
  EXPECT_EQ(read->header.source, original.header.source);
  EXPECT_EQ(read->header.device, original.header.device);
  EXPECT_EQ(read->header.metadata, original.header.metadata);
  ASSERT_EQ(read->samples.size(), original.samples.size());
  const auto same_angle = [](double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || a == b;
  };
  for (size_t i = 0; i < original.samples.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i));
    const LogSample& want = original.samples[i];
    const LogSample& got = read->samples[i];
    EXPECT_EQ(got.device_time_ns, want.device_time_ns);
    EXPECT_EQ(got.host_time_ns, want.host_time_ns);
    EXPECT_EQ(got.sequence, want.sequence);
    EXPECT_EQ(got.led_on, want.led_on);
    EXPECT_EQ(got.bend_counts, want.bend_counts);
    EXPECT_EQ(got.rotate_counts, want.rotate_counts);
    EXPECT_TRUE(same_angle(got.bend_spool_rad, want.bend_spool_rad)) << got.bend_spool_rad;
    EXPECT_TRUE(same_angle(got.rotate_shaft_rad, want.rotate_shaft_rad)) << got.rotate_shaft_rad;
    EXPECT_TRUE(same_angle(got.vertebra_rad, want.vertebra_rad)) << got.vertebra_rad;
  }
  ASSERT_EQ(read->events.size(), original.events.size());
  for (size_t i = 0; i < original.events.size(); ++i) {
    SCOPED_TRACE("event " + std::to_string(i));
    EXPECT_EQ(read->events[i].device_time_ns, original.events[i].device_time_ns);
    EXPECT_EQ(read->events[i].host_time_ns, original.events[i].host_time_ns);
    EXPECT_EQ(read->events[i].kind, original.events[i].kind);
    EXPECT_EQ(read->events[i].detail, original.events[i].detail);
  }
  EXPECT_EQ(read->report.bad_lines, 0);
}

// The packed fields (LogSample is 64 bytes) keep every value the file format allows:
// the ends of each integer's range, false apart from absent, a host time at the limit.
TEST(ControllerLog, PackedSampleFieldsKeepTheirWholeRange) {
  ScratchDir dir;
  ControllerLog original;
  const int64_t kMin = std::numeric_limits<int64_t>::min();
  const int64_t kMax = std::numeric_limits<int64_t>::max();
  for (int i = 0; i < 3; ++i) {
    LogSample sample;
    sample.device_time_ns = i;
    if (i == 0) sample.host_time_ns = -kMaxLogTimeNs;
    if (i == 1) sample.host_time_ns = kMaxLogTimeNs;
    if (i != 2) sample.sequence = i == 0 ? 0u : 4'294'967'295u;
    if (i != 2) sample.led_on = i == 1;
    if (i != 2) sample.bend_counts = i == 0 ? kMin : kMax;
    if (i != 2) sample.rotate_counts = i == 0 ? kMax : kMin;
    original.samples.push_back(sample);
  }
  ASSERT_TRUE(WriteControllerLog(dir / "log.csv", original).ok());
  EXPECT_THAT(ReadFile(dir / "log.csv"),
              HasSubstr("\n0,-4000000000000000000,0,0,-9223372036854775808,9223372036854775807,"));

  const Result<ControllerLog> read = ReadControllerLog(dir / "log.csv");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  ASSERT_EQ(read->samples.size(), 3u);
  const LogSample& low = read->samples[0];
  EXPECT_EQ(low.host_time_ns, -kMaxLogTimeNs);
  EXPECT_EQ(low.sequence, 0u);
  ASSERT_TRUE(low.led_on.has_value());
  EXPECT_FALSE(*low.led_on);
  EXPECT_EQ(low.bend_counts, kMin);
  EXPECT_EQ(low.rotate_counts, kMax);
  const LogSample& high = read->samples[1];
  EXPECT_EQ(high.host_time_ns, kMaxLogTimeNs);
  EXPECT_EQ(high.sequence, 4'294'967'295u);
  EXPECT_EQ(high.led_on, true);
  EXPECT_EQ(high.bend_counts, kMax);
  EXPECT_EQ(high.rotate_counts, kMin);
  const LogSample& none = read->samples[2];
  EXPECT_FALSE(none.host_time_ns.has_value());
  EXPECT_FALSE(none.sequence.has_value());
  EXPECT_FALSE(none.led_on.has_value());
  EXPECT_EQ(none.bend_counts, std::nullopt);
  EXPECT_EQ(std::optional<int64_t>(none.rotate_counts), std::nullopt);

  // the host time's "absent" is INT64_MIN, beyond any time a log may hold
  LogSample corrupt;
  corrupt.host_time_ns = kMin;
  EXPECT_FALSE(corrupt.host_time_ns.has_value());
}

TEST(ControllerLog, ToleratesAndReportsATruncatedLastLine) {
  ScratchDir dir;
  // a capture stopped mid-line: no line end, too few fields
  WriteFile(dir / "cut.csv", HandLog("\n") + "10000000,,44,1,,-4");
  const Result<ControllerLog> log = ReadControllerLog(dir / "cut.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 3u);
  EXPECT_TRUE(log->report.truncated_last_line);
  EXPECT_EQ(log->report.bad_lines, 1);
  EXPECT_EQ(log->report.lines_total, 5);
  ASSERT_EQ(log->report.issues.size(), 1u);
  EXPECT_EQ(log->report.issues[0].line, 11);
  EXPECT_THAT(log->report.issues[0].reason, StartsWith("truncated last line"));
  EXPECT_EQ(log->report.Brief(),
            "cut.csv: 3 samples, 1 event, 1 bad line (line 11: truncated last line, got "
            "\"10000000,,44,1,,-4\")");
}

TEST(ControllerLog, KeepsACompleteLastLineWithoutLineEnd) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", HandLog("\n") + "10000000,,44,1,,-4,,,,,");
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 4u);
  EXPECT_EQ(log->samples[3].rotate_counts, -4);
  EXPECT_FALSE(log->report.truncated_last_line);
  EXPECT_EQ(log->report.bad_lines, 0);
}

TEST(ControllerLog, GarbageLineIsAParseErrorNamingFileAndLine) {
  ScratchDir dir;
  std::string text = HandLog("\n");
  text.insert(text.find("0,,,,,,,,,led_on"), "garbage\n");  // becomes line 8
  WriteFile(dir / "log.csv", text);
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kParse);
  EXPECT_THAT(log.status().message(),
              StartsWith((dir / "log.csv").string() + ":8: expected 11 comma-separated fields"));
  EXPECT_THAT(log.status().message(), HasSubstr("got \"garbage\""));
  EXPECT_THAT(log.status().message(), HasSubstr("1 bad line in all"));
}

TEST(ControllerLog, BadFieldErrorNamesTheColumnAndTheText) {
  struct Case {
    std::string row;
    std::string expected;
  };
  const Case cases[] = {
      {"1.5,,,,,,,,,,",
       "device_time_ns: expected an integer number of nanoseconds within +-4e18, got \"1.5\""},
      {",,,,,,,,,,", "device_time_ns: expected an integer number of nanoseconds within +-4e18, got \"\""},
      {"10, 5,,,,,,,,,",
       "host_time_ns: expected an integer number of nanoseconds within +-4e18, or nothing, got "
       "\" 5\""},
      // times whose differences could overflow int64
      {"4000000000000000001,,,,,,,,,,",
       "device_time_ns: expected an integer number of nanoseconds within +-4e18, got "
       "\"4000000000000000001\""},
      {"-9223372036854775808,,,,,,,,,,", "device_time_ns: expected an integer number of "
                                          "nanoseconds within +-4e18"},
      {"10,9223372036854775807,,,,,,,,,", "host_time_ns: expected an integer number of "
                                          "nanoseconds within +-4e18"},
      {"10,,-1,,,,,,,,", "seq: expected an integer in [0, 4294967295], got \"-1\""},
      {"10,,4294967296,,,,,,,,", "seq: expected an integer in [0, 4294967295], got \"4294967296\""},
      {"10,,,2,,,,,,,", "led: expected 0, 1 or nothing, got \"2\""},
      {"10,,,,1e3,,,,,,", "bend_counts: expected an integer number of counts, got \"1e3\""},
      {"10,,,,,,,0.5rad,,,",
       "rotate_shaft_rad: expected a finite number of radians, got \"0.5rad\""},
      // non-finite angles are not measurements
      {"10,,,,,,,,inf,,", "vertebra_rad: expected a finite number of radians, got \"inf\""},
      {"10,,,,,,-nan,,,,", "bend_spool_rad: expected a finite number of radians, got \"-nan\""},
      {"10,,,,,,,1e999,,,", "rotate_shaft_rad: expected a finite number of radians"},
      {"10,,,,,,,,infinity,,", "vertebra_rad: expected a finite number of radians"},
      {"10,,,,,,,,0,5,,", "expected 11 comma-separated fields"},
      {"10,,,,,,,,,blink,",
       "event: expected one of led_on, led_off, test_start, test_end, gap, reconnect, fault, "
       "note, got \"blink\""},
      {"10,,,1,,,,,,led_on,", "led: expected nothing on an event row, got \"1\""},
      {"10,,,,,,,,,,why", "detail: expected nothing on a sample row, got \"why\""},
      {"10,,,,,,,,,note,\"open", "expected 11 comma-separated fields"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.row);
    ScratchDir dir;
    WriteFile(dir / "log.csv", HandLog("\n") + c.row + "\n");
    const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
    ASSERT_FALSE(log.ok());
    EXPECT_EQ(log.status().code(), StatusCode::kParse);
    EXPECT_THAT(log.status().message(),
                StartsWith((dir / "log.csv").string() + ":11: " + c.expected));
  }
}

TEST(ControllerLog, ToleratesUpToMaxBadLinesAndReportsThem) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", HandLog("\n") + "junk\n20000000,,,,,,,,,,\n\x01\x02zz\n");
  LogReadOptions options;
  options.max_bad_lines = 2;
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv", options);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 4u);
  EXPECT_EQ(log->report.bad_lines, 2);
  EXPECT_EQ(log->report.lines_total, 7);
  ASSERT_EQ(log->report.issues.size(), 2u);
  EXPECT_EQ(log->report.issues[0].line, 11);
  EXPECT_THAT(log->report.issues[0].reason, HasSubstr("got \"junk\""));
  EXPECT_EQ(log->report.issues[1].line, 13);
  EXPECT_THAT(log->report.issues[1].reason, HasSubstr("got \"\\x01\\x02zz\""));
  EXPECT_THAT(log->report.Brief(),
              StartsWith("log.csv: 4 samples, 1 event, 2 bad lines (line 11: "));
  EXPECT_THAT(log->report.Brief(), HasSubstr("; 1 more)"));

  // one more than allowed: the error names the first and counts them all
  options.max_bad_lines = 1;
  const Result<ControllerLog> strict = ReadControllerLog(dir / "log.csv", options);
  ASSERT_FALSE(strict.ok());
  EXPECT_THAT(strict.status().message(), StartsWith((dir / "log.csv").string() + ":11: "));
  EXPECT_THAT(strict.status().message(), HasSubstr("2 bad lines in all"));
  EXPECT_THAT(strict.status().message(), HasSubstr("at most 1 allowed"));
}

TEST(ControllerLog, KeepsOnlyMaxIssuesButCountsEveryBadLine) {
  ScratchDir dir;
  std::string text = HandLog("\n");
  for (int i = 0; i < 5; ++i) text += "bad" + std::to_string(i) + "\n";
  WriteFile(dir / "log.csv", text);
  LogReadOptions options;
  options.max_bad_lines = 10;
  options.max_issues_kept = 2;
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv", options);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->report.bad_lines, 5);
  ASSERT_EQ(log->report.issues.size(), 2u);
  EXPECT_EQ(log->report.issues[1].line, 12);
}

TEST(ControllerLog, TruncatedLastLineDoesNotCountAgainstMaxBadLines) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", HandLog("\n") + "junk\n123,4");
  LogReadOptions options;
  options.max_bad_lines = 1;
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv", options);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->report.bad_lines, 2);
  EXPECT_TRUE(log->report.truncated_last_line);

  // with no bad lines allowed, the error names the garbage, not the cut-off line
  const Result<ControllerLog> strict = ReadControllerLog(dir / "log.csv");
  ASSERT_FALSE(strict.ok());
  EXPECT_THAT(strict.status().message(), StartsWith((dir / "log.csv").string() + ":11: "));
  EXPECT_THAT(strict.status().message(), HasSubstr("1 bad line in all"));
}

TEST(ControllerLog, EmptyLogIsAParseError) {
  ScratchDir dir;
  const std::string header = "# liftoff-log 1\n# source: capture\n" + std::string(kColumns) + "\n";
  const std::pair<std::string, std::string> cases[] = {
      {"zero bytes", ""},
      {"header only", header},
      {"header cut off", "# liftoff-log 1\n# source: capture\ndevice_time_ns,host_ti"},
      {"events only", header + "0,,,,,,,,,led_on,\n"},
  };
  for (const auto& [name, text] : cases) {
    SCOPED_TRACE(name);
    WriteFile(dir / "empty.csv", text);
    const Result<ControllerLog> log = ReadControllerLog(dir / "empty.csv");
    ASSERT_FALSE(log.ok());
    EXPECT_EQ(log.status().code(), StatusCode::kParse);
    EXPECT_EQ(log.status().message(), (dir / "empty.csv").string() + ": no samples (empty log)");
  }
}

TEST(ControllerLog, DropsAndCountsASampleThatDoesNotMoveForward) {
  ScratchDir dir;
  // line 11 repeats the time of line 10, line 12 goes back before it
  WriteFile(dir / "log.csv",
            HandLog("\n") + "5000000,,44,1,,,,,,,\n4000000,,45,1,,,,,,,\n6000000,,46,1,,,,,,,\n");
  LogReadOptions options;
  options.max_bad_lines = 2;
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv", options);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 4u);
  EXPECT_EQ(log->samples[2].sequence, 43u);  // the first at 5 ms is kept
  EXPECT_EQ(log->samples[3].device_time_ns, 6'000'000);
  EXPECT_EQ(log->report.out_of_order, 2);
  EXPECT_EQ(log->report.bad_lines, 2);
  ASSERT_EQ(log->report.issues.size(), 2u);
  EXPECT_EQ(log->report.issues[0].line, 11);
  EXPECT_EQ(log->report.issues[1].line, 12);
  EXPECT_EQ(log->report.issues[1].reason,
            "device_time_ns: expected more than the previous sample's 5000000, got \"4000000\"");

  const Result<ControllerLog> strict = ReadControllerLog(dir / "log.csv");
  ASSERT_FALSE(strict.ok());
  EXPECT_THAT(strict.status().message(),
              StartsWith((dir / "log.csv").string() + ":11: device_time_ns: expected more"));
}

TEST(ControllerLog, MissingFileIsNotFound) {
  ScratchDir dir;
  const Result<ControllerLog> log = ReadControllerLog(dir / "nope.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(log.status().message(), HasSubstr("nope.csv"));
}

TEST(ControllerLog, RejectsOtherVersionsAndOtherFiles) {
  ScratchDir dir;
  WriteFile(dir / "v2.csv", "# liftoff-log 2\n" + std::string(kColumns) + "\n0,,,,,,,,,,\n");
  const Result<ControllerLog> v2 = ReadControllerLog(dir / "v2.csv");
  ASSERT_FALSE(v2.ok());
  EXPECT_EQ(v2.status().code(), StatusCode::kUnsupported);
  EXPECT_THAT(v2.status().message(), HasSubstr("v2.csv:1: liftoff-log version 2 is not supported"));

  WriteFile(dir / "laika.txt", "1074.33,0.5,\r1080.1,0.6,\r");
  const Result<ControllerLog> laika = ReadControllerLog(dir / "laika.txt");
  ASSERT_FALSE(laika.ok());
  EXPECT_EQ(laika.status().code(), StatusCode::kParse);
  EXPECT_EQ(laika.status().message(),
            (dir / "laika.txt").string() +
                ":1: expected \"# liftoff-log 1\" as the first line, got \"1074.33,0.5,\"");

  WriteFile(dir / "columns.csv", "# liftoff-log 1\n# source: x\ntime,angle\n0,1\n");
  const Result<ControllerLog> columns = ReadControllerLog(dir / "columns.csv");
  ASSERT_FALSE(columns.ok());
  EXPECT_THAT(columns.status().message(), HasSubstr("columns.csv:3: expected the column header"));
  EXPECT_THAT(columns.status().message(), HasSubstr("got \"time,angle\""));
}

TEST(ControllerLog, DuplicateHeaderKeyIsAnError) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", "# liftoff-log 1\n# source: a\n# source: b\n" + std::string(kColumns) +
                                 "\n0,,,,,,,,,,\n");
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
  ASSERT_FALSE(log.ok());
  EXPECT_THAT(log.status().message(), HasSubstr("log.csv:3: header key \"source\" appears twice"));
}

TEST(ControllerLog, IgnoresBlankLinesCommentsAndAByteOrderMark) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", "\xEF\xBB\xBF# liftoff-log 1\n## free comment\n# source: bench\n\n" +
                                 std::string(kColumns) +
                                 "\n\n# a comment among rows\n7,,,,,,,,,,\n   \n");
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->header.source, "bench");
  EXPECT_TRUE(log->header.metadata.empty());
  ASSERT_EQ(log->samples.size(), 1u);
  EXPECT_EQ(log->samples[0].device_time_ns, 7);
  EXPECT_EQ(log->report.lines_total, 1);
}

TEST(ControllerLog, SortsEventsByDeviceTime) {
  ScratchDir dir;
  WriteFile(dir / "log.csv", "# liftoff-log 1\n" + std::string(kColumns) +
                                 "\n10,,,,,,,,,gap,2\n20,,,,,,,,,,\n5,,,,,,,,,reconnect,\n");
  const Result<ControllerLog> log = ReadControllerLog(dir / "log.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->events.size(), 2u);
  EXPECT_EQ(log->events[0].kind, LogEventKind::kReconnect);
  EXPECT_EQ(log->events[1].kind, LogEventKind::kGap);
  EXPECT_EQ(log->events[1].detail, "2");
}

LogSample SampleAt(int64_t t_ns, std::optional<bool> led_on) {
  LogSample sample;
  sample.device_time_ns = t_ns;
  sample.led_on = led_on;
  return sample;
}

TEST(ControllerLog, LedOnTimePrefersTheFirstLedOnEvent) {
  ControllerLog log;
  log.samples = {SampleAt(0, false), SampleAt(10, true)};
  log.events = {{3, std::nullopt, LogEventKind::kLedOff, ""},
                {7, std::nullopt, LogEventKind::kLedOn, ""},
                {9, std::nullopt, LogEventKind::kLedOn, ""}};
  EXPECT_EQ(log.LedOnTimeNs(), 7);
}

TEST(ControllerLog, LedOnTimeFallsBackToTheFirstOffToOnSample) {
  ControllerLog log;
  log.samples = {SampleAt(0, std::nullopt), SampleAt(10, false), SampleAt(20, std::nullopt),
                 SampleAt(30, true),        SampleAt(40, false), SampleAt(50, true)};
  EXPECT_EQ(log.LedOnTimeNs(), 30);
}

TEST(ControllerLog, LedOnTimeIsUnknownWhenTheLedIsNeverSeenSwitchingOn) {
  ControllerLog already_on;
  already_on.samples = {SampleAt(0, true), SampleAt(10, true)};
  EXPECT_EQ(already_on.LedOnTimeNs(), std::nullopt);

  ControllerLog unknown;
  unknown.samples = {SampleAt(0, std::nullopt), SampleAt(10, std::nullopt)};
  EXPECT_EQ(unknown.LedOnTimeNs(), std::nullopt);

  ControllerLog always_off;
  always_off.samples = {SampleAt(0, false)};
  EXPECT_EQ(always_off.LedOnTimeNs(), std::nullopt);
}

TEST(ControllerLog, StreamingWriterOutputIsReadableWhileOpenAndAfterClose) {
  ScratchDir dir;
  LogHeader header;
  header.calibration = "laika-2018";
  header.source = "capture /dev/ttyACM0";
  ControllerLogWriter writer;
  ASSERT_TRUE(writer.Open(dir / "live.csv", header).ok());
  EXPECT_TRUE(writer.is_open());
  for (int i = 0; i < 1000; ++i) {
    LogSample sample;
    sample.device_time_ns = int64_t{1'000'000} * i;  // 1 kHz
    sample.sequence = static_cast<uint32_t>(i);
    sample.led_on = i >= 500;
    sample.rotate_shaft_rad = 0.001 * i;
    ASSERT_TRUE(writer.Append(sample).ok());
    if (i == 500) {
      ASSERT_TRUE(
          writer.Append(LogEvent{500'000'000, std::nullopt, LogEventKind::kLedOn, ""}).ok());
    }
  }
  ASSERT_TRUE(writer.Flush().ok());

  // a reader sees everything flushed so far, while the capture goes on
  const Result<ControllerLog> live = ReadControllerLog(dir / "live.csv");
  ASSERT_TRUE(live.ok()) << live.status().ToString();
  EXPECT_EQ(live->samples.size(), 1000u);
  EXPECT_EQ(live->LedOnTimeNs(), 500'000'000);
  EXPECT_EQ(live->samples[999].rotate_shaft_rad, 0.001 * 999);  // bit for bit

  ASSERT_TRUE(
      writer.Append(LogEvent{999'000'001, std::nullopt, LogEventKind::kTestEnd, "done"}).ok());
  ASSERT_TRUE(writer.Close().ok());
  EXPECT_FALSE(writer.is_open());
  const Result<ControllerLog> done = ReadControllerLog(dir / "live.csv");
  ASSERT_TRUE(done.ok()) << done.status().ToString();
  EXPECT_EQ(done->header.source, "capture /dev/ttyACM0");
  ASSERT_EQ(done->events.size(), 2u);
  EXPECT_EQ(done->events[1].detail, "done");
}

TEST(ControllerLog, HeaderAloneReachesTheDiskOnOpen) {
  ScratchDir dir;
  ControllerLogWriter writer;
  ASSERT_TRUE(writer.Open(dir / "live.csv", LogHeader{}).ok());
  EXPECT_THAT(ReadFile(dir / "live.csv"), StartsWith("# liftoff-log 1\n"));
  EXPECT_THAT(ReadFile(dir / "live.csv"), HasSubstr(std::string(kColumns) + "\n"));
}

TEST(ControllerLog, WriterRefusesWhatWouldBreakTheFile) {
  ScratchDir dir;
  ControllerLogWriter writer;
  LogHeader header;
  header.metadata["source"] = "clash";
  Status status = writer.Open(dir / "a.csv", header);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("metadata key \"source\": reserved"));

  header.metadata = {{"bad key", "x"}};
  status = writer.Open(dir / "a.csv", header);
  EXPECT_THAT(status.message(), HasSubstr("metadata key \"bad key\": expected letters"));

  header.metadata = {};
  header.device = "two\nlines";
  status = writer.Open(dir / "a.csv", header);
  EXPECT_THAT(status.message(), HasSubstr("header device: expected one line"));

  ASSERT_TRUE(writer.Open(dir / "a.csv", LogHeader{}).ok());
  status = writer.Append(LogEvent{0, std::nullopt, LogEventKind::kFault, "a\nb"});
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("event detail: expected one line"));

  ControllerLog log;
  log.samples = {SampleAt(0, std::nullopt)};
  log.events = {{0, std::nullopt, LogEventKind::kNote, "x\ry"}};
  status = WriteControllerLog(dir / "b.csv", log);
  EXPECT_THAT(status.message(), HasSubstr("b.csv: event detail: expected one line"));
  EXPECT_FALSE(std::filesystem::exists(dir / "b.csv"));
}

TEST(ControllerLog, WriteCreatesAMissingFolder) {
  ScratchDir dir;
  ControllerLog log;
  log.samples = {SampleAt(0, std::nullopt)};
  ASSERT_TRUE(WriteControllerLog(dir / "no" / "such" / "log.csv", log).ok());
  EXPECT_TRUE(ReadControllerLog(dir / "no" / "such" / "log.csv").ok());
}

TEST(ControllerLog, WriteBelowAFileIsAnIoError) {
  ScratchDir dir;
  liftoff::testing::WriteFile(dir / "plain-file", "x");
  ControllerLog log;
  log.samples = {SampleAt(0, std::nullopt)};
  const Status status = WriteControllerLog(dir / "plain-file" / "log.csv", log);
  EXPECT_EQ(status.code(), StatusCode::kIo);
  EXPECT_THAT(status.message(), HasSubstr("plain-file"));
}

TEST(ControllerLog, EventKindNamesRoundTrip) {
  const std::pair<LogEventKind, std::string_view> names[] = {
      {LogEventKind::kLedOn, "led_on"},
      {LogEventKind::kLedOff, "led_off"},
      {LogEventKind::kTestStart, "test_start"},
      {LogEventKind::kTestEnd, "test_end"},
      {LogEventKind::kGap, "gap"},
      {LogEventKind::kReconnect, "reconnect"},
      {LogEventKind::kFault, "fault"},
      {LogEventKind::kNote, "note"}};
  for (const auto& [kind, name] : names) {
    EXPECT_EQ(LogEventKindName(kind), name);
    EXPECT_EQ(ParseLogEventKind(name), kind);
  }
  EXPECT_EQ(ParseLogEventKind("LED_ON"), std::nullopt);
}

TEST(ControllerLog, ReadOptionsRejectNegativeLimits) {
  LogReadOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.max_bad_lines = -1;
  EXPECT_THAT(options.Validate().message(),
              HasSubstr("max_bad_lines: expected an integer >= 0, got -1"));
  options = {};
  options.max_issues_kept = -2;
  EXPECT_THAT(options.Validate().message(), HasSubstr("max_issues_kept"));
  ScratchDir dir;
  const Status read = ReadControllerLog(dir / "x.csv", options).status();
  EXPECT_EQ(read.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(read.message(), StartsWith((dir / "x.csv").string() + ": "));  // names the file
}

TEST(ControllerLog, DetectsItsFormatPastAByteOrderMark) {
  ScratchDir dir;
  const std::string body = "# liftoff-log 1\n" + std::string(kColumns) + "\n7,,,,,,,,,,\n";
  WriteFile(dir / "plain.csv", body);
  WriteFile(dir / "bom.csv", "\xEF\xBB\xBF" + body);  // as ReadControllerLog accepts
  WriteFile(dir / "2018.txt", "0,0.01,\r100,0.02,\r");
  WriteFile(dir / "short.txt", "# lift");
  EXPECT_EQ(DetectLogFormat(dir / "plain.csv").value(), LogFormat::kLiftoff);
  EXPECT_EQ(DetectLogFormat(dir / "bom.csv").value(), LogFormat::kLiftoff);
  EXPECT_EQ(DetectLogFormat(dir / "2018.txt").value(), LogFormat::kLaika2018);
  EXPECT_EQ(DetectLogFormat(dir / "short.txt").value(), LogFormat::kLaika2018);
  const Status missing = DetectLogFormat(dir / "none.csv").status();
  EXPECT_EQ(missing.code(), StatusCode::kNotFound);
  EXPECT_THAT(missing.message(), HasSubstr("none.csv"));
  EXPECT_EQ(DetectLogFormat(dir.path()).status().code(), StatusCode::kInvalidArgument);
}

TEST(ControllerLog, BriefOfACleanReadCountsSamples) {
  LogReadReport report;
  report.source = "/data/Test1 Front Right Blue.txt";
  report.samples = 135;
  EXPECT_EQ(report.Brief(), "Test1 Front Right Blue.txt: 135 samples");
  report.samples = 1;
  report.events = 2;
  EXPECT_EQ(report.Brief(), "Test1 Front Right Blue.txt: 1 sample, 2 events");
}

}  // namespace
}  // namespace liftoff
