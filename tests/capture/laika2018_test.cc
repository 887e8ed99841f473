#include "liftoff/capture/laika2018.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/capture/log_loader.h"
#include "liftoff/core/time.h"
#include "support/test_support.h"

namespace liftoff::capture {
namespace {

using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::WriteFile;
using ::testing::HasSubstr;

// ---------------------------------------------------------------------------------------
// ImportLaika2018Log on small synthetic files

TEST(Laika2018Log, ReadsBareCrLinesWithTrailingCommas) {
  ScratchDir dir;
  WriteFile(dir / "Test1 Front Right Blue.txt", "4,-0.01,\r13,-0.02,\r1074,-0.40,\r");
  const auto log = ImportLaika2018Log(dir / "Test1 Front Right Blue.txt",
                                      liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_EQ(log->samples[0].device_time_ns, 4'000'000);
  EXPECT_EQ(log->samples[1].device_time_ns, 13'000'000);
  EXPECT_EQ(log->samples[2].device_time_ns, 1'074'000'000);
  EXPECT_DOUBLE_EQ(log->samples[0].rotate_shaft_rad, -0.01);
  EXPECT_DOUBLE_EQ(log->samples[2].rotate_shaft_rad, -0.40);
  // vertebra = shaft / 4
  EXPECT_DOUBLE_EQ(log->samples[0].vertebra_rad, -0.0025);
  EXPECT_DOUBLE_EQ(log->samples[2].vertebra_rad, -0.10);
  // nothing else was measured
  EXPECT_TRUE(std::isnan(log->samples[0].bend_spool_rad));
  EXPECT_FALSE(log->samples[0].rotate_counts.has_value());
  EXPECT_FALSE(log->samples[0].led_on.has_value());
  EXPECT_EQ(log->header.calibration, "test");
  EXPECT_EQ(log->header.source, "import laika-2018 Test1 Front Right Blue.txt");
  EXPECT_EQ(log->report.format, "laika-2018");
  EXPECT_EQ(log->report.source, dir / "Test1 Front Right Blue.txt");
  EXPECT_EQ(log->report.lines_total, 3);
  EXPECT_EQ(log->report.samples, 3);
  EXPECT_EQ(log->report.bad_lines, 0);
  EXPECT_FALSE(log->report.truncated_last_line);
  EXPECT_TRUE(log->events.empty());
}

TEST(Laika2018Log, ReadsCrLfLinesAndIgnoresBlankOnes) {
  ScratchDir dir;
  WriteFile(dir / "crlf.txt", "11,-0.01,\r\n\r\n17,-0.02,\r\n\r\n");
  const auto log = ImportLaika2018Log(dir / "crlf.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 2u);
  EXPECT_EQ(log->samples[1].device_time_ns, 17'000'000);
  EXPECT_DOUBLE_EQ(log->samples[1].rotate_shaft_rad, -0.02);
  EXPECT_EQ(log->report.lines_total, 2);  // blank lines are not counted
  EXPECT_EQ(log->report.bad_lines, 0);
}

TEST(Laika2018Log, ReadsLfLinesWithoutTrailingComma) {
  ScratchDir dir;
  // no line end after the last line: complete, since no line carries a trailing comma
  WriteFile(dir / "lf.txt", "1,0.5\n2,0.75\n3,2.5e-1");
  const auto log = ImportLaika2018Log(dir / "lf.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_EQ(log->samples[2].device_time_ns, 3'000'000);
  EXPECT_DOUBLE_EQ(log->samples[1].vertebra_rad, 0.1875);
  EXPECT_DOUBLE_EQ(log->samples[2].rotate_shaft_rad, 0.25);
  EXPECT_FALSE(log->report.truncated_last_line);
}

TEST(Laika2018Log, ParsesFractionalMillisecondsExactly) {
  ScratchDir dir;
  WriteFile(dir / "fraction.txt", "1074.33,0.1,\r");
  const auto log =
      ImportLaika2018Log(dir / "fraction.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples[0].device_time_ns, 1'074'330'000);
}

TEST(Laika2018Log, ToleratesTruncatedLastLineWithoutLineEnd) {
  ScratchDir dir;
  WriteFile(dir / "cut.txt", "1,0.5,\r2,0.6,\r1074.33");
  const auto log = ImportLaika2018Log(dir / "cut.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 2u);
  EXPECT_TRUE(log->report.truncated_last_line);
  EXPECT_EQ(log->report.bad_lines, 1);
  EXPECT_EQ(log->report.lines_total, 3);
  ASSERT_EQ(log->report.issues.size(), 1u);
  EXPECT_EQ(log->report.issues[0].line, 3);
  EXPECT_THAT(log->report.issues[0].reason, HasSubstr("truncated last line"));
  EXPECT_THAT(log->report.issues[0].reason, HasSubstr("\"1074.33\""));
}

TEST(Laika2018Log, ToleratesMalformedLastLineFollowedByBlankLines) {
  // as in the real files: "...\r1074.33\r\r"
  ScratchDir dir;
  WriteFile(dir / "tail.txt", "1,0.5,\r2,0.6,\r1074.33\r\r");
  const auto log = ImportLaika2018Log(dir / "tail.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 2u);
  EXPECT_TRUE(log->report.truncated_last_line);
  ASSERT_EQ(log->report.issues.size(), 1u);
  EXPECT_EQ(log->report.issues[0].line, 3);
}

TEST(Laika2018Log, UnendedLastLineMissingItsTrailingCommaMayHaveLostDigits) {
  // "3,0.8" may be the start of "3,0.85,": every other line carries the comma
  ScratchDir dir;
  WriteFile(dir / "cut.txt", "1,0.5,\r2,0.6,\r3,0.8");
  const auto log = ImportLaika2018Log(dir / "cut.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 2u);
  EXPECT_TRUE(log->report.truncated_last_line);
  // an unended last line that is complete is kept
  WriteFile(dir / "whole.txt", "1,0.5,\r2,0.6,\r3,0.8,");
  const auto whole =
      ImportLaika2018Log(dir / "whole.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(whole.ok()) << whole.status().ToString();
  EXPECT_EQ(whole->samples.size(), 3u);
  EXPECT_FALSE(whole->report.truncated_last_line);
}

TEST(Laika2018Log, GarbageMiddleLineIsAnErrorNamingFileAndLine) {
  ScratchDir dir;
  WriteFile(dir / "bad.txt", "1,0.1,\r\n2,0.2,\r\n\r\n2x,0.3,\r\n4,0.4,\r\n");
  const auto log = ImportLaika2018Log(dir / "bad.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kParse);
  // line 3 is blank; the garbage is on line 4
  EXPECT_THAT(log.status().message(),
              HasSubstr("bad.txt:4: expected `t_ms,value,`, got \"2x,0.3,\""));
  EXPECT_THAT(log.status().message(), HasSubstr("(1 bad line in all"));
}

TEST(Laika2018Log, GarbageMiddleLineIsToleratedWithMaxBadLines) {
  ScratchDir dir;
  WriteFile(dir / "bad.txt", "1,0.1,\r2,0.2,\rmotor fault\r4,0.4,\r");
  const auto log = ImportLaika2018Log(dir / "bad.txt", liftoff::testing::DriveChainCalibration(),
                                      {.max_bad_lines = 1});
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_EQ(log->samples[2].device_time_ns, 4'000'000);
  EXPECT_EQ(log->report.bad_lines, 1);
  EXPECT_EQ(log->report.lines_total, 4);
  EXPECT_FALSE(log->report.truncated_last_line);
  ASSERT_EQ(log->report.issues.size(), 1u);
  EXPECT_EQ(log->report.issues[0].line, 3);
  EXPECT_THAT(log->report.issues[0].reason, HasSubstr("\"motor fault\""));
}

TEST(Laika2018Log, MoreBadLinesThanAllowedNamesTheFirstAndTheCount) {
  ScratchDir dir;
  WriteFile(dir / "bad.txt", "1,0.1,\r2,,\r3,0.3,\rabc\r,0.5,\r6,0.6,\r");
  const auto log = ImportLaika2018Log(dir / "bad.txt", liftoff::testing::DriveChainCalibration(),
                                      {.max_bad_lines = 2});
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kParse);
  EXPECT_THAT(log.status().message(), HasSubstr("bad.txt:2: expected `t_ms,value,`, got \"2,,\""));
  EXPECT_THAT(
      log.status().message(),
      HasSubstr("(3 bad lines in all, not counting a truncated last line; at most 2 allowed)"));
}

TEST(Laika2018Log, KeepsOnlyTheFirstIssuesButCountsAll) {
  ScratchDir dir;
  WriteFile(dir / "bad.txt", "x\ry\rz\r1,0.1,\r");
  const auto log = ImportLaika2018Log(dir / "bad.txt", liftoff::testing::DriveChainCalibration(),
                                      {.max_bad_lines = 5, .max_issues_kept = 2});
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->report.bad_lines, 3);
  ASSERT_EQ(log->report.issues.size(), 2u);
  EXPECT_EQ(log->report.issues[1].line, 2);
}

TEST(Laika2018Log, EmptyFileHasNoSamples) {
  ScratchDir dir;
  WriteFile(dir / "empty.txt", "");
  WriteFile(dir / "blank.txt", "\r\r\n\n");
  for (const char* name : {"empty.txt", "blank.txt"}) {
    const auto log = ImportLaika2018Log(dir / name, liftoff::testing::DriveChainCalibration());
    ASSERT_FALSE(log.ok()) << name;
    EXPECT_EQ(log.status().code(), StatusCode::kParse);
    EXPECT_THAT(log.status().message(), HasSubstr(name));
    EXPECT_THAT(log.status().message(), HasSubstr("no samples"));
  }
}

TEST(Laika2018Log, FileOfOnlyATruncatedLineHasNoSamples) {
  ScratchDir dir;
  WriteFile(dir / "stub.txt", "107");
  const auto log = ImportLaika2018Log(dir / "stub.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kParse);
  EXPECT_THAT(log.status().message(), HasSubstr("stub.txt: no samples"));
}

TEST(Laika2018Log, MissingFileIsNotFound) {
  ScratchDir dir;
  const auto log =
      ImportLaika2018Log(dir / "absent.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(log.status().message(), HasSubstr("absent.txt"));
}

TEST(Laika2018Log, NonIncreasingTimeIsDroppedAndCounted) {
  ScratchDir dir;
  WriteFile(dir / "order.txt", "1,0.1,\r5,0.2,\r4,0.3,\r5,0.4,\r6,0.5,\r");
  const auto log = ImportLaika2018Log(dir / "order.txt", liftoff::testing::DriveChainCalibration(),
                                      {.max_bad_lines = 2});
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_EQ(log->samples[1].device_time_ns, 5'000'000);
  EXPECT_DOUBLE_EQ(log->samples[1].rotate_shaft_rad, 0.2);  // the first 5 ms sample stays
  EXPECT_EQ(log->samples[2].device_time_ns, 6'000'000);
  EXPECT_EQ(log->report.out_of_order, 2);
  EXPECT_EQ(log->report.bad_lines, 2);
  ASSERT_EQ(log->report.issues.size(), 2u);
  EXPECT_EQ(log->report.issues[0].line, 3);
  EXPECT_EQ(log->report.issues[1].line, 4);

  const auto strict =
      ImportLaika2018Log(dir / "order.txt", liftoff::testing::DriveChainCalibration());
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.status().code(), StatusCode::kParse);
  EXPECT_THAT(
      strict.status().message(),
      HasSubstr("order.txt:3: t_ms: expected more than the previous sample's 5, got \"4\""));
}

TEST(Laika2018Log, InvalidOptionsAreRejected) {
  ScratchDir dir;
  WriteFile(dir / "ok.txt", "1,0.1,\r");
  const auto log = ImportLaika2018Log(dir / "ok.txt", liftoff::testing::DriveChainCalibration(),
                                      {.max_bad_lines = -1});
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(log.status().message(), HasSubstr("max_bad_lines"));
}

// ---------------------------------------------------------------------------------------
// LoadControllerLog

TEST(LoadControllerLog, DispatchesLaika2018ToTheImporter) {
  ScratchDir dir;
  WriteFile(dir / "old.txt", "10,2.0,\r");
  const auto log = LoadControllerLog(dir / "old.txt", LogFormat::kLaika2018,
                                     liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->report.format, "laika-2018");
  EXPECT_DOUBLE_EQ(log->samples[0].vertebra_rad, 0.5);
}

TEST(LoadControllerLog, FillsAnglesOfALiftoffLogFromCounts) {
  ScratchDir dir;
  ControllerLog written;
  written.header.calibration = "test";
  written.header.source = "test";
  // 12000 counts = 1000 rotor revs = 1 shaft rev (2 pi) = a quarter vertebra rev (pi/2)
  LogSample& counts_only = written.samples.emplace_back();
  counts_only.device_time_ns = 1'000'000;
  counts_only.rotate_counts = 12000;
  counts_only.bend_counts = -6000;  // half a spool rev backwards
  // a shaft angle without a vertebra angle
  LogSample& shaft_only = written.samples.emplace_back();
  shaft_only.device_time_ns = 2'000'000;
  shaft_only.rotate_shaft_rad = 1.0;
  // angles already present are kept
  LogSample& complete = written.samples.emplace_back();
  complete.device_time_ns = 3'000'000;
  complete.rotate_counts = 12000;
  complete.rotate_shaft_rad = 7.0;
  complete.vertebra_rad = 0.125;
  complete.bend_spool_rad = 0.5;
  ASSERT_TRUE(WriteControllerLog(dir / "new.log", written).ok());

  const auto log = LoadControllerLog(dir / "new.log", LogFormat::kLiftoff,
                                     liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_NEAR(log->samples[0].rotate_shaft_rad, 2 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(log->samples[0].vertebra_rad, std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(log->samples[0].bend_spool_rad, -std::numbers::pi, 1e-12);
  EXPECT_NEAR(log->samples[1].vertebra_rad, 0.25, 1e-12);
  EXPECT_TRUE(std::isnan(log->samples[1].bend_spool_rad));
  EXPECT_DOUBLE_EQ(log->samples[2].rotate_shaft_rad, 7.0);
  EXPECT_DOUBLE_EQ(log->samples[2].vertebra_rad, 0.125);
  EXPECT_DOUBLE_EQ(log->samples[2].bend_spool_rad, 0.5);
}

TEST(LoadControllerLog, ErrorsNameTheFile) {
  ScratchDir dir;
  for (LogFormat format : {LogFormat::kLiftoff, LogFormat::kLaika2018}) {
    const auto log =
        LoadControllerLog(dir / "nowhere.log", format, liftoff::testing::DriveChainCalibration());
    ASSERT_FALSE(log.ok());
    EXPECT_EQ(log.status().code(), StatusCode::kNotFound);
    EXPECT_THAT(log.status().message(), HasSubstr("nowhere.log"));
  }
  WriteFile(dir / "garbage.log", "this is not a log\n");
  const auto log = LoadControllerLog(dir / "garbage.log", LogFormat::kLiftoff,
                                     liftoff::testing::DriveChainCalibration());
  ASSERT_FALSE(log.ok());
  EXPECT_THAT(log.status().message(), HasSubstr("garbage.log"));
}

// ---------------------------------------------------------------------------------------
// ImportLaika2018Folder on a small synthetic folder

constexpr const char* kCsvHeader =
    "Times for foot lifting from hardware experiment videos for IROS 2018,,,,\n"
    ",,,,\n"
    "Foot,Test no,Begin time (s),Foot lift time (s),Total time index for experiment\n";

// 1/30 s, rounded down to the nanosecond.
constexpr int64_t kFrameNs = 33'333'333;

TEST(Laika2018Folder, BuildsOneTrialPerRow) {
  ScratchDir dir;
  const auto folder = dir / "data";
  // CR LF line ends here, to show the CSV reader does not care
  WriteFile(folder / kLaika2018TimesCsv,
            "Times,,,,\r\n,,,,\r\nFoot,Test no,Begin,Lift,Total\r\nA,1,5.67,11.8,6.13\r\n"
            "B,2,9.3,17.5,8.2\r\n,,,,\r\n");
  WriteFile(folder / "Test1 Front Right Blue.txt", "1,0.1,\r");
  WriteFile(folder / "Test2 Front Left Orange.txt", "1,0.1,\r");
  const auto manifest_path = dir / "out" / "trials.json";

  const auto imported = ImportLaika2018Folder(folder, manifest_path);
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  EXPECT_TRUE(imported->warnings.empty()) << ::testing::PrintToString(imported->warnings);
  const TrialManifest& manifest = imported->manifest;
  EXPECT_EQ(manifest.base_dir, std::filesystem::absolute(dir / "out"));
  EXPECT_THAT(manifest.description, HasSubstr(std::filesystem::absolute(folder).string()));
  ASSERT_EQ(manifest.trials.size(), 2u);

  const TrialRecord& a1 = manifest.trials[0];
  EXPECT_EQ(a1.id, "A1");
  EXPECT_EQ(a1.foot, Foot::kA);
  EXPECT_EQ(a1.test_number, 1);
  EXPECT_EQ(a1.pulled_group, CableGroup::kHR);
  EXPECT_EQ(a1.rotation, RotationSense::kPositive);
  EXPECT_THAT(a1.notes, HasSubstr("Table II"));
  EXPECT_EQ(a1.log_path, std::filesystem::absolute(folder / "Test1 Front Right Blue.txt"));
  EXPECT_TRUE(a1.log_path.is_absolute());
  EXPECT_EQ(a1.log_format, LogFormat::kLaika2018);
  EXPECT_FALSE(a1.video_path.has_value());
  ASSERT_TRUE(a1.times.has_value());
  EXPECT_EQ(a1.times->led_on_ns, 5'670'000'000);
  EXPECT_EQ(a1.times->liftoff_ns, 11'800'000'000);
  // LED column printed to 0.01 s, liftoff column to 0.1 s; plus one frame
  EXPECT_EQ(a1.times->led_on_uncertainty_ns, 5'000'000 + kFrameNs);
  EXPECT_EQ(a1.times->liftoff_uncertainty_ns, 50'000'000 + kFrameNs);
  EXPECT_EQ(a1.times->source, "hand (2018 video, by eye)");

  const TrialRecord& b2 = manifest.trials[1];
  EXPECT_EQ(b2.id, "B2");
  EXPECT_EQ(b2.foot, Foot::kB);
  EXPECT_EQ(b2.pulled_group, CableGroup::kHR);
  EXPECT_EQ(b2.rotation, RotationSense::kNegative);
  EXPECT_EQ(b2.log_path.filename(), "Test2 Front Left Orange.txt");
  EXPECT_EQ(b2.times->led_on_ns, 9'300'000'000);
  // "9.3" sits in a column printed to 0.01 s: the spreadsheet dropped a zero
  EXPECT_EQ(b2.times->led_on_uncertainty_ns, 5'000'000 + kFrameNs);
}

TEST(Laika2018Folder, ManifestWrittenAtItsPathHasRelativeLogsAndLoadsBack) {
  ScratchDir dir;
  const auto folder = dir / "data";
  WriteFile(folder / kLaika2018TimesCsv, std::string(kCsvHeader) + "D,5,7.42,14.5,7.08\n");
  WriteFile(folder / "Test5 Back Left Red.txt", "1,0.1,\r");
  const auto manifest_path = dir / "out" / "trials.json";
  const auto imported = ImportLaika2018Folder(folder, manifest_path);
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  std::filesystem::create_directories(manifest_path.parent_path());
  const Status written = WriteManifest(manifest_path, imported->manifest);
  ASSERT_TRUE(written.ok()) << written.ToString();

  EXPECT_THAT(liftoff::testing::ReadFile(manifest_path),
              HasSubstr("\"../data/Test5 Back Left Red.txt\""));
  const auto loaded = LoadManifest(manifest_path);
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  ASSERT_EQ(loaded->trials.size(), 1u);
  const TrialRecord& d5 = loaded->trials[0];
  EXPECT_EQ(d5.id, "D5");
  EXPECT_EQ(std::filesystem::weakly_canonical(d5.log_path),
            std::filesystem::weakly_canonical(folder / "Test5 Back Left Red.txt"));
  EXPECT_EQ(d5.log_format, LogFormat::kLaika2018);
  EXPECT_EQ(d5.pulled_group, CableGroup::kHL);
  EXPECT_EQ(d5.rotation, RotationSense::kNegative);
  ASSERT_TRUE(d5.times.has_value());
  EXPECT_EQ(d5.times->led_on_ns, 7'420'000'000);
  EXPECT_EQ(d5.times->liftoff_ns, 14'500'000'000);
  EXPECT_EQ(d5.times->led_on_uncertainty_ns, 5'000'000 + kFrameNs);
  EXPECT_EQ(d5.times->liftoff_uncertainty_ns, 50'000'000 + kFrameNs);
  EXPECT_EQ(d5.times->source, "hand (2018 video, by eye)");
}

TEST(Laika2018Folder, MapsBackFeetToTheLeftGroupPerTableTwo) {
  ScratchDir dir;
  WriteFile(dir / kLaika2018TimesCsv,
            std::string(kCsvHeader) + "C,3,8.09,17.1,9.01\nD,4,8.34,15.5,7.16\n");
  WriteFile(dir / "Test3 Back Right Purple.txt", "1,0.1,\r");
  WriteFile(dir / "Test4 Back Left Red.txt", "1,0.1,\r");
  const auto imported = ImportLaika2018Folder(dir.path(), dir / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  EXPECT_TRUE(imported->warnings.empty()) << ::testing::PrintToString(imported->warnings);
  const auto& trials = imported->manifest.trials;
  ASSERT_EQ(trials.size(), 2u);
  EXPECT_EQ(trials[0].id, "C3");
  EXPECT_EQ(trials[0].pulled_group, CableGroup::kHL);
  EXPECT_EQ(trials[0].rotation, RotationSense::kPositive);
  EXPECT_EQ(trials[1].id, "D4");
  EXPECT_EQ(trials[1].pulled_group, CableGroup::kHL);
  EXPECT_EQ(trials[1].rotation, RotationSense::kNegative);
  EXPECT_EQ(trials[1].log_path.filename(), "Test4 Back Left Red.txt");
}

TEST(Laika2018Folder, WarnsAboutDisagreeingDifferenceAndMissingOrUnlistedLogs) {
  ScratchDir dir;
  // C1: 18.1 - 10 = 8.1, not 8.2; no log for C1; a log no row names
  WriteFile(dir / kLaika2018TimesCsv, std::string(kCsvHeader) + "C,1,10,18.1,8.2\n");
  WriteFile(dir / "Test9 Back Left Red.txt", "1,0.1,\r");
  const auto imported = ImportLaika2018Folder(dir.path(), dir / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  ASSERT_EQ(imported->warnings.size(), 3u) << ::testing::PrintToString(imported->warnings);
  std::string all;
  for (const std::string& warning : imported->warnings) all += warning + "\n";
  EXPECT_THAT(all, HasSubstr("C1: log \"Test1 Back Right Purple.txt\" is missing"));
  EXPECT_THAT(all, HasSubstr("C1: difference column says 8.200 s but liftoff - LED-on = 8.100 s"));
  EXPECT_THAT(all, HasSubstr("log \"Test9 Back Left Red.txt\" has no row"));
  // the row is still a trial
  ASSERT_EQ(imported->manifest.trials.size(), 1u);
  EXPECT_EQ(imported->manifest.trials[0].times->led_on_ns, 10'000'000'000);
}

TEST(Laika2018Folder, DifferenceWithinAMillisecondIsNotAWarning) {
  ScratchDir dir;
  WriteFile(dir / kLaika2018TimesCsv, std::string(kCsvHeader) + "A,1,5.67,11.8,6.131\n");
  WriteFile(dir / "Test1 Front Right Blue.txt", "1,0.1,\r");
  const auto imported = ImportLaika2018Folder(dir.path(), dir / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  EXPECT_TRUE(imported->warnings.empty()) << ::testing::PrintToString(imported->warnings);
}

TEST(Laika2018Folder, MissingFolderOrCsvIsNotFound) {
  ScratchDir dir;
  const auto no_folder = ImportLaika2018Folder(dir / "absent", dir / "trials.json");
  ASSERT_FALSE(no_folder.ok());
  EXPECT_EQ(no_folder.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(no_folder.status().message(), HasSubstr("absent"));

  const auto no_csv = ImportLaika2018Folder(dir.path(), dir / "trials.json");
  ASSERT_FALSE(no_csv.ok());
  EXPECT_EQ(no_csv.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(no_csv.status().message(), HasSubstr(kLaika2018TimesCsv));
}

TEST(Laika2018Folder, MalformedRowsAreErrorsNamingCsvLineAndColumn) {
  struct Case {
    std::string rows;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"A,1,5.67,11.8,6.13\nE,1,5.67,11.8,6.13\n",
       "videos.csv:5: column 1 (foot): expected one of A, B, C, D, got \"E\""},
      {"A,x,5.67,11.8,6.13\n",
       "videos.csv:4: column 2 (test): expected an integer >= 1, got \"x\""},
      {"A,1,5,67,11.8,6.13\n", "videos.csv:4: expected `foot,test,"},
      {"A,1,5.67s,11.8,6.13\n", "videos.csv:4: column 3 (LED-on time): expected a non-negative"},
      {"A,1,11.8,5.67,-6.13\n",
       "videos.csv:4: liftoff time 5.67 s is not after LED-on time 11.8 s"},
      {"A,1,5.67,11.8,6.13\nA,1,5.68,11.8,6.12\n",
       "videos.csv:5: a second row for A1 (the first is at line 4)"},
      {"", "videos.csv: no rows"},
  };
  for (const Case& c : cases) {
    ScratchDir dir;
    WriteFile(dir / kLaika2018TimesCsv, kCsvHeader + c.rows);
    const auto imported = ImportLaika2018Folder(dir.path(), dir / "trials.json");
    ASSERT_FALSE(imported.ok()) << c.rows;
    EXPECT_EQ(imported.status().code(), StatusCode::kParse) << c.rows;
    EXPECT_THAT(imported.status().message(), HasSubstr(c.expected));
  }
}

TEST(Laika2018Folder, ColumnHeaderMustNameTheFoot) {
  ScratchDir dir;
  WriteFile(dir / kLaika2018TimesCsv, "Times,,,,\n,,,,\nA,1,5.67,11.8,6.13\nA,2,13.4,19.4,6\n");
  const auto imported = ImportLaika2018Folder(dir.path(), dir / "trials.json");
  ASSERT_FALSE(imported.ok());
  EXPECT_EQ(imported.status().code(), StatusCode::kParse);
  EXPECT_THAT(imported.status().message(), HasSubstr("videos.csv:3: expected the column header"));
}

// ---------------------------------------------------------------------------------------
// The real 2018 data

TEST(Laika2018Reference, AllTwentyLogsImportWithOnlyTruncatedLastLinesSkipped) {
  LIFTOFF_REQUIRE_REFERENCE(ref);
  const auto folder = ref / "laika-2018-hardware";
  const Calibration calibration = liftoff::testing::DriveChainCalibration();
  std::set<std::string> truncated;
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".txt") continue;
    ++files;
    const std::string name = entry.path().filename().string();
    const auto log = ImportLaika2018Log(entry.path(), calibration);  // max_bad_lines = 0
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    EXPECT_EQ(log->report.out_of_order, 0) << name;
    EXPECT_EQ(log->report.bad_lines, log->report.truncated_last_line ? 1 : 0) << name;
    EXPECT_EQ(log->report.lines_total, log->report.samples + log->report.bad_lines) << name;
    if (log->report.truncated_last_line) truncated.insert(name);
  }
  EXPECT_EQ(files, 20);
  // every front-left and back-right log ends in a stray number such as "1074.33"
  const std::set<std::string> expected_truncated = {
      "Test1 Back Right Purple.txt", "Test2 Back Right Purple.txt", "Test3 Back Right Purple.txt",
      "Test4 Back Right Purple.txt", "Test5 Back Right Purple.txt", "Test1 Front Left Orange.txt",
      "Test2 Front Left Orange.txt", "Test3 Front Left Orange.txt", "Test4 Front Left Orange.txt",
      "Test5 Front Left Orange.txt"};
  EXPECT_EQ(truncated, expected_truncated);
}

TEST(Laika2018Reference, LogsMatchTheirFirstAndLastLines) {
  LIFTOFF_REQUIRE_REFERENCE(ref);
  const auto folder = ref / "laika-2018-hardware";
  // counted with `tr '\r' '\n' | grep -c` and read with `od -c`
  const auto front_left = ImportLaika2018Log(folder / "Test1 Front Left Orange.txt",
                                             liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(front_left.ok()) << front_left.status().ToString();
  EXPECT_EQ(front_left->samples.size(), 169u);
  EXPECT_EQ(front_left->samples.front().device_time_ns, 10'000'000);
  EXPECT_DOUBLE_EQ(front_left->samples.front().rotate_shaft_rad, 0.01);
  EXPECT_EQ(front_left->samples.back().device_time_ns, 9'079'000'000);
  EXPECT_DOUBLE_EQ(front_left->samples.back().vertebra_rad, 0.56);
  ASSERT_EQ(front_left->report.issues.size(), 1u);
  EXPECT_EQ(front_left->report.issues[0].line, 170);
  EXPECT_THAT(front_left->report.issues[0].reason, HasSubstr("\"1074.33\""));

  // the one CR LF file
  const auto crlf = ImportLaika2018Log(folder / "Test3 Back Left Red.txt",
                                       liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(crlf.ok()) << crlf.status().ToString();
  EXPECT_EQ(crlf->samples.size(), 152u);
  EXPECT_EQ(crlf->report.lines_total, 152);
  EXPECT_EQ(crlf->samples.front().device_time_ns, 11'000'000);
  EXPECT_EQ(crlf->samples.back().device_time_ns, 8'078'000'000);
  EXPECT_DOUBLE_EQ(crlf->samples.back().rotate_shaft_rad, -1.83);

  const auto back_left = ImportLaika2018Log(folder / "Test1 Back Left Red.txt",
                                            liftoff::testing::DriveChainCalibration());
  ASSERT_TRUE(back_left.ok()) << back_left.status().ToString();
  EXPECT_EQ(back_left->samples.size(), 187u);
  EXPECT_EQ(back_left->samples.back().device_time_ns, 10'073'000'000);
  EXPECT_DOUBLE_EQ(back_left->samples.back().vertebra_rad, -0.5475);
}

TEST(Laika2018Reference, FolderImportYieldsTwentyTrialsWithExactTimes) {
  LIFTOFF_REQUIRE_REFERENCE(ref);
  const auto folder = ref / "laika-2018-hardware";
  ScratchDir out;
  const auto imported = ImportLaika2018Folder(folder, out / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  // every difference in the CSV equals liftoff - LED-on to the printed digit (checked by
  // hand, row by row), and every row has its log
  EXPECT_TRUE(imported->warnings.empty()) << ::testing::PrintToString(imported->warnings);
  const auto& trials = imported->manifest.trials;
  ASSERT_EQ(trials.size(), 20u);
  const std::vector<std::string> expected_ids = {"A1", "A2", "A3", "A4", "A5", "B1", "B2",
                                                 "B3", "B4", "B5", "C1", "C2", "C3", "C4",
                                                 "C5", "D1", "D2", "D3", "D4", "D5"};
  for (size_t i = 0; i < trials.size(); ++i) {
    EXPECT_EQ(trials[i].id, expected_ids[i]);
    EXPECT_TRUE(std::filesystem::is_regular_file(trials[i].log_path)) << trials[i].log_path;
    EXPECT_EQ(trials[i].log_format, LogFormat::kLaika2018);
  }
  EXPECT_EQ(trials[0].times->led_on_ns, 5'670'000'000);
  EXPECT_EQ(trials[0].times->liftoff_ns, 11'800'000'000);
  EXPECT_EQ(trials[0].log_path.filename(), "Test1 Front Right Blue.txt");
  // C1 is printed "10,18.1": 10.00 s in a column of hundredths
  EXPECT_EQ(trials[10].times->led_on_ns, 10'000'000'000);
  EXPECT_EQ(trials[10].times->led_on_uncertainty_ns, 5'000'000 + kFrameNs);
  EXPECT_EQ(trials[10].times->liftoff_uncertainty_ns, 50'000'000 + kFrameNs);
  EXPECT_EQ(trials[19].times->liftoff_ns, 14'500'000'000);
  EXPECT_EQ(trials[19].log_path.filename(), "Test5 Back Left Red.txt");
}

TEST(Laika2018Reference, EveryTrialsLogImportsWithVertebraAnglesFromTheShaft) {
  // the authors' angles themselves are sync's to reproduce (trial_analysis_test); here only
  // what the importer owes them: each named log reads, and its angles are shaft / 4
  LIFTOFF_REQUIRE_REFERENCE(ref);
  const auto folder = ref / "laika-2018-hardware";
  ScratchDir out;
  const auto imported = ImportLaika2018Folder(folder, out / "trials.json");
  ASSERT_TRUE(imported.ok()) << imported.status().ToString();
  for (const TrialRecord& trial : imported->manifest.trials) {
    SCOPED_TRACE(trial.id);
    const auto log = LoadControllerLog(trial.log_path, trial.log_format,
                                       liftoff::testing::DriveChainCalibration());
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    ASSERT_FALSE(log->samples.empty());
    for (const LogSample& sample : log->samples) {
      ASSERT_DOUBLE_EQ(sample.vertebra_rad, sample.rotate_shaft_rad / 4);
    }
  }
}

}  // namespace
}  // namespace liftoff::capture
