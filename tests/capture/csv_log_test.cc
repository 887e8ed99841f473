// A user's own CSV log, read through the columns a manifest names: units, the LED by column
// or by time, encoder counts through the calibration, bad and truncated lines, missing
// columns; the manifest's csv fields and their errors; and the controller.csv files of
// ../shared/video-dev (another tool's logger) against their truth's own lookups.
#include "liftoff/capture/csv_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/capture/log_loader.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/time.h"
#include "support/test_support.h"

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;
using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::WriteFile;
using ::testing::HasSubstr;

CsvLogColumns DevSetColumns() {
  CsvLogColumns columns;
  columns.time_column = "t_ms";
  columns.time_unit = "ms";
  columns.angle_column = "rotation_rad";
  columns.angle_unit = "rad";
  columns.led_on_s = 0.0;
  return columns;
}

TEST(CsvLog, ReadsNamedColumnsInTheirUnitsExactly) {
  ScratchDir scratch;
  const fs::path path = scratch / "controller.csv";
  WriteFile(path, "t_ms,rotation_rad\r\n0,0.000000000\r\n10,0.000261799\r\n\r\n21,0.000523599\r\n");
  const Result<ControllerLog> log = ReadCsvLog(path, DevSetColumns());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 3u);
  EXPECT_EQ(log->samples[1].device_time_ns, 10'000'000);
  EXPECT_EQ(log->samples[2].device_time_ns, 21'000'000);
  EXPECT_DOUBLE_EQ(log->samples[2].vertebra_rad, 0.000523599);
  ASSERT_EQ(log->LedOnTimeNs(), 0);
  EXPECT_EQ(log->report.samples, 3);
  EXPECT_EQ(log->report.bad_lines, 0);
}

TEST(CsvLog, DegreesSecondsQuotedHeadersAndExtraColumns) {
  ScratchDir scratch;
  const fs::path path = scratch / "mine.csv";
  WriteFile(path, "\"time s\", \"temperature\" ,angle\n1.5,21.0,90\n1.75,21.1,-45\n");
  CsvLogColumns columns;
  columns.time_column = "time s";
  columns.time_unit = "s";
  columns.angle_column = "angle";
  columns.angle_unit = "deg";
  const Result<ControllerLog> log = ReadCsvLog(path, columns);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 2u);
  EXPECT_EQ(log->samples[0].device_time_ns, 1'500'000'000);
  EXPECT_DOUBLE_EQ(log->samples[0].vertebra_rad, std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(log->samples[1].vertebra_rad, -std::numbers::pi / 4);
  EXPECT_FALSE(log->LedOnTimeNs().has_value()) << "neither an LED column nor a time";
}

TEST(CsvLog, TheLedColumnsFirstRiseIsTheSwitchOn) {
  ScratchDir scratch;
  const fs::path path = scratch / "led.csv";
  WriteFile(path, "us,led,counts\n0,0,0\n500,0,1\n1000,1,2\n1500,1,3\n");
  CsvLogColumns columns;
  columns.time_column = "us";
  columns.time_unit = "us";
  columns.angle_column = "counts";
  columns.angle_unit = "counts";
  columns.led_column = "led";
  const Result<ControllerLog> log = ReadCsvLog(path, columns);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->LedOnTimeNs(), 1'000'000);
  EXPECT_EQ(log->samples[3].rotate_counts, 3);
}

TEST(CsvLog, CountsBecomeTheVertebrasAngleThroughTheCalibration) {
  ScratchDir scratch;
  const fs::path path = scratch / "counts.csv";
  WriteFile(path, "t_ms,enc\n0,0\n10,12000\n");
  TrialRecord trial;
  trial.id = "A1";
  trial.log_path = path;
  trial.log_format = LogFormat::kCsv;
  CsvLogColumns columns;
  columns.time_column = "t_ms";
  columns.time_unit = "ms";
  columns.angle_column = "enc";
  columns.angle_unit = "counts";
  trial.log_columns = columns;
  const Calibration calibration = liftoff::testing::DriveChainCalibration();
  const Result<ControllerLog> log = LoadTrialLog(trial, calibration);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  // 12000 counts: 1000 motor turns, one shaft turn, a quarter turn of the vertebra
  EXPECT_NEAR(log->samples[1].vertebra_rad,
              calibration.VertebraAngleFromShaftAngle(calibration.ShaftAngleFromCounts(12000)),
              1e-15);
  EXPECT_NEAR(std::abs(log->samples[1].vertebra_rad), std::numbers::pi / 2, 1e-12);
  // LoadControllerLog cannot read a csv log without its columns
  const Result<ControllerLog> without = LoadControllerLog(path, LogFormat::kCsv, calibration);
  ASSERT_FALSE(without.ok());
  EXPECT_THAT(without.status().message(), HasSubstr("columns"));
}

TEST(CsvLog, AMissingColumnNamesTheFileTheLineAndTheHeader) {
  ScratchDir scratch;
  const fs::path path = scratch / "other.csv";
  WriteFile(path, "\n\ntime,value\n0,1\n");
  const Result<ControllerLog> log = ReadCsvLog(path, DevSetColumns());
  ASSERT_FALSE(log.ok());
  EXPECT_EQ(log.status().code(), StatusCode::kParse);
  EXPECT_THAT(log.status().message(), HasSubstr("other.csv:3: no column \"t_ms\""));
  EXPECT_THAT(log.status().message(), HasSubstr("time,value"));
}

TEST(CsvLog, BadAndOutOfOrderLinesAreNamedOrSkippedWithinTheAllowance) {
  ScratchDir scratch;
  const fs::path path = scratch / "bad.csv";
  WriteFile(path, "t_ms,rotation_rad\n0,0.1\n10,inf\n20,0.3\n15,0.4\n30,0.5\n40,0.");
  const Result<ControllerLog> strict = ReadCsvLog(path, DevSetColumns());
  ASSERT_FALSE(strict.ok());
  EXPECT_THAT(strict.status().message(), HasSubstr("bad.csv:3: rotation_rad: expected a finite"));
  EXPECT_THAT(strict.status().message(), HasSubstr("2 bad lines"));

  LogReadOptions lenient;
  lenient.max_bad_lines = 2;
  const Result<ControllerLog> log = ReadCsvLog(path, DevSetColumns(), lenient);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 4u) << "0, 20, 30 and the last line's 40 (\"0.\" parses)";
  EXPECT_EQ(log->report.out_of_order, 1);
  EXPECT_EQ(log->report.bad_lines, 2);
}

TEST(CsvLog, ALastLineCutByTheEndOfTheFileIsTolerated) {
  ScratchDir scratch;
  const fs::path path = scratch / "cut.csv";
  WriteFile(path, "t_ms,rotation_rad\n0,0.1\n10,0.2\n2");
  const Result<ControllerLog> log = ReadCsvLog(path, DevSetColumns());
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->samples.size(), 2u);
  EXPECT_TRUE(log->report.truncated_last_line);
}

TEST(CsvLog, NoSamplesIsAnError) {
  ScratchDir scratch;
  const fs::path path = scratch / "empty.csv";
  WriteFile(path, "t_ms,rotation_rad\n");
  const Result<ControllerLog> log = ReadCsvLog(path, DevSetColumns());
  ASSERT_FALSE(log.ok());
  EXPECT_THAT(log.status().message(), HasSubstr("empty.csv: no samples"));
}

TEST(CsvLogManifest, ColumnsRoundTripAndTheirErrorsNameTheField) {
  const nlohmann::json document = {
      {"format", "liftoff-manifest"},
      {"version", 1},
      {"trials",
       {{{"id", "d02"},
         {"foot", "A"},
         {"log",
          {{"path", "controller.csv"},
           {"format", "csv"},
           {"time_column", "t_ms"},
           {"time_unit", "ms"},
           {"angle_column", "rotation_rad"},
           {"led_on_s", 0}}}}}}};
  const Result<TrialManifest> manifest = ManifestFromJson(document, "m.json", "/data");
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  const TrialRecord& trial = manifest->trials[0];
  EXPECT_EQ(trial.log_format, LogFormat::kCsv);
  ASSERT_TRUE(trial.log_columns.has_value());
  EXPECT_EQ(trial.log_columns->time_unit, "ms");
  EXPECT_EQ(trial.log_columns->angle_unit, "rad");
  EXPECT_EQ(trial.log_columns->led_on_s, 0.0);
  const nlohmann::json written = ManifestToJson(*manifest, "/data");
  EXPECT_EQ(written["trials"][0]["log"]["angle_column"], "rotation_rad");
  const Result<TrialManifest> again = ManifestFromJson(written, "again.json", "/data");
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(again->trials[0].log_columns->time_column, "t_ms");

  nlohmann::json no_time = document;
  no_time["trials"][0]["log"].erase("time_column");
  const Result<TrialManifest> missing = ManifestFromJson(no_time, "m.json", "/data");
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.status().message(), HasSubstr("/trials/0/log/time_column"));

  nlohmann::json both = document;
  both["trials"][0]["log"]["led_column"] = "led";
  const Result<TrialManifest> twice = ManifestFromJson(both, "m.json", "/data");
  ASSERT_FALSE(twice.ok());
  EXPECT_THAT(twice.status().message(), HasSubstr("led_on_s"));

  nlohmann::json unit = document;
  unit["trials"][0]["log"]["angle_unit"] = "grad";
  EXPECT_FALSE(ManifestFromJson(unit, "m.json", "/data").ok());
}

// The rotation at the truth's liftoff instant, read linearly from each dev clip's
// controller.csv through the reader, equals the truth's own lookup.
TEST(CsvLogDevSet, ControllerLogsGiveTheTruthsLookups) {
  const fs::path root = fs::path(LIFTOFF_SHARED_DIR) / "video-dev";
  if (!fs::exists(root)) GTEST_SKIP() << root << " is absent (a fresh clone has no ../shared)";
  int checked = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
    const fs::path csv = entry.path() / "controller.csv";
    if (!fs::exists(csv)) continue;
    std::ifstream truth_file(entry.path() / "truth.json");
    const nlohmann::json truth = nlohmann::json::parse(truth_file);
    if (!truth.contains("theta_at_lift_log_interp") ||
        !truth["theta_at_lift_log_interp"].is_number()) {
      continue;
    }
    const Result<ControllerLog> log = ReadCsvLog(csv, DevSetColumns());
    ASSERT_TRUE(log.ok()) << log.status().ToString();
    const double t_s = truth["t_lift"].get<double>() - truth["t_led_on"].get<double>();
    const auto& samples = log->samples;
    size_t after = 0;
    const auto seconds = [](const LogSample& sample) { return SecondsFromNs(sample.device_time_ns); };
    while (after < samples.size() && seconds(samples[after]) < t_s) ++after;
    ASSERT_GT(after, 0u);
    ASSERT_LT(after, samples.size());
    const LogSample& a = samples[after - 1];
    const LogSample& b = samples[after];
    const double f = (t_s - seconds(a)) / (seconds(b) - seconds(a));
    const double rotation = a.vertebra_rad + f * (b.vertebra_rad - a.vertebra_rad);
    EXPECT_NEAR(std::abs(rotation), std::abs(truth["theta_at_lift_log_interp"].get<double>()),
                1e-6)
        << entry.path().filename();
    ++checked;
  }
  EXPECT_GE(checked, 11);
}

}  // namespace
}  // namespace liftoff::capture
