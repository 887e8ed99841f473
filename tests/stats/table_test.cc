#include "liftoff/stats/table.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/stats/sim_results.h"
#include "support/test_support.h"

namespace liftoff::stats {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------
// Simulation results

Result<SimResults> LoadText(const testing::ScratchDir& dir, const std::string& text) {
  const auto path = dir / "sim.json";
  testing::WriteFile(path, text);
  return LoadSimResults(path);
}

// The error a document gives; its message must name sim.json and `pointer`.
Status LoadError(const std::string& text) {
  testing::ScratchDir dir;
  auto results = LoadText(dir, text);
  EXPECT_FALSE(results.ok());
  return results.status();
}

constexpr const char* kHeader =
    R"("format": "liftoff-sim-results", "version": 1, "model": "laika-ntrt")";

TEST(SimResults, RangesComeFromStandingRunsOnly) {
  testing::ScratchDir dir;
  auto results =
      LoadText(dir, std::string("{") + kHeader + R"(, "description": "five tension points",
    "runs": [
      {"foot": "A", "tension_point": "high", "liftoff_rad": 0.47, "stood": true, "pulled_group": "HR", "rotation": "+"},
      {"foot": "A", "tension_point": "low", "liftoff_rad": 0.33, "stood": true},
      {"foot": "A", "tension_point": "mean", "liftoff_rad": 0.40, "stood": true, "notes": "slow"},
      {"foot": "B", "tension_point": "low", "stood": false},
      {"foot": "B", "tension_point": "med-low", "liftoff_rad": 0.10, "stood": false},
      {"foot": "B", "tension_point": "high", "liftoff_rad": 0.47, "stood": true}
    ]})");
  ASSERT_TRUE(results.ok()) << results.status().ToString();
  EXPECT_EQ(results->model, "laika-ntrt");
  EXPECT_EQ(results->description, "five tension points");
  EXPECT_EQ(results->source, (dir / "sim.json").string());
  ASSERT_EQ(results->runs.size(), 6u);
  EXPECT_EQ(results->runs[0].pulled_group, CableGroup::kHR);
  EXPECT_EQ(results->runs[0].rotation, RotationSense::kPositive);
  EXPECT_EQ(results->runs[2].notes, "slow");
  EXPECT_FALSE(results->runs[3].liftoff_rad.has_value());
  EXPECT_FALSE(results->runs[3].stood);

  ASSERT_EQ(results->ranges.size(), 2u);
  const SimFootRange& a = results->ranges.at(Foot::kA);
  EXPECT_DOUBLE_EQ(a.min_rad, 0.33);
  EXPECT_DOUBLE_EQ(a.max_rad, 0.47);
  EXPECT_EQ(a.n_runs, 3);
  EXPECT_FALSE(a.from_summary);
  // the fallen runs (0.10 among them) are not part of B's range
  const SimFootRange& b = results->ranges.at(Foot::kB);
  EXPECT_DOUBLE_EQ(b.min_rad, 0.47);
  EXPECT_DOUBLE_EQ(b.max_rad, 0.47);
  EXPECT_EQ(b.n_runs, 1);
}

TEST(SimResults, SummaryWinsOverRunsForMinAndMax) {
  testing::ScratchDir dir;
  auto results = LoadText(dir, std::string("{") + kHeader + R"(,
    "runs": [{"foot": "A", "tension_point": "mean", "liftoff_rad": 0.40, "stood": true},
             {"foot": "A", "tension_point": "high", "liftoff_rad": 0.45, "stood": true}],
    "summary": {"A": {"min_rad": 0.33, "max_rad": 0.47}, "C": {"min_rad": 0.25, "max_rad": 0.44}}})");
  ASSERT_TRUE(results.ok()) << results.status().ToString();
  EXPECT_EQ(results->runs.size(), 2u);
  const SimFootRange& a = results->ranges.at(Foot::kA);
  EXPECT_DOUBLE_EQ(a.min_rad, 0.33);
  EXPECT_DOUBLE_EQ(a.max_rad, 0.47);
  EXPECT_EQ(a.n_runs, 2);
  EXPECT_TRUE(a.from_summary);
  const SimFootRange& c = results->ranges.at(Foot::kC);
  EXPECT_DOUBLE_EQ(c.min_rad, 0.25);
  EXPECT_EQ(c.n_runs, 0);
  EXPECT_TRUE(c.from_summary);
  EXPECT_FALSE(results->ranges.contains(Foot::kB));
}

TEST(SimResults, RoundTripsThroughJson) {
  SimResults original;
  original.model = "laika-ntrt";
  original.description = "test";
  original.runs = {{Foot::kC, "high", 0.44, true, CableGroup::kHR, RotationSense::kNegative, "n"},
                   {Foot::kD, "low", std::nullopt, false, std::nullopt, std::nullopt, ""}};
  original.ranges = SimRangesFromRuns(original.runs);
  original.ranges[Foot::kA] = {0.33, 0.47, 0, true};

  auto loaded = SimResultsFromJson(SimResultsToJson(original), "memory");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->model, "laika-ntrt");
  EXPECT_EQ(loaded->description, "test");
  ASSERT_EQ(loaded->runs.size(), 2u);
  EXPECT_EQ(loaded->runs[0].foot, Foot::kC);
  EXPECT_EQ(loaded->runs[0].liftoff_rad, 0.44);
  EXPECT_EQ(loaded->runs[0].pulled_group, CableGroup::kHR);
  EXPECT_EQ(loaded->runs[0].rotation, RotationSense::kNegative);
  EXPECT_EQ(loaded->runs[0].notes, "n");
  EXPECT_FALSE(loaded->runs[1].stood);
  EXPECT_FALSE(loaded->runs[1].liftoff_rad.has_value());
  ASSERT_EQ(loaded->ranges.size(), 2u);
  EXPECT_TRUE(loaded->ranges.at(Foot::kA).from_summary);
  EXPECT_DOUBLE_EQ(loaded->ranges.at(Foot::kA).max_rad, 0.47);
  EXPECT_FALSE(loaded->ranges.at(Foot::kC).from_summary);
  EXPECT_EQ(loaded->ranges.at(Foot::kC).n_runs, 1);
}

TEST(SimResults, MissingFileIsNotFoundNamingThePath) {
  testing::ScratchDir dir;
  auto results = LoadSimResults(dir / "absent.json");
  ASSERT_FALSE(results.ok());
  EXPECT_EQ(results.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(results.status().message(), HasSubstr("absent.json"));
}

TEST(SimResults, SyntaxErrorIsParseErrorNamingFileAndLine) {
  const Status status = LoadError("{\n  \"format\": \"liftoff-sim-results\",\n  oops\n}");
  EXPECT_EQ(status.code(), StatusCode::kParse);
  EXPECT_THAT(status.message(), HasSubstr("sim.json:3:"));
}

TEST(SimResults, BadFootNamesItsPointer) {
  const Status status = LoadError(std::string("{") + kHeader + R"(, "runs": [
    {"foot": "A", "tension_point": "high", "liftoff_rad": 0.47, "stood": true},
    {"foot": "E", "tension_point": "high", "liftoff_rad": 0.47, "stood": true}]})");
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /runs/1/foot: expected one of A, B, C, D"));
  EXPECT_THAT(status.message(), HasSubstr("\"E\""));
}

TEST(SimResults, NegativeLiftoffNamesItsPointer) {
  const Status status = LoadError(
      std::string("{") + kHeader +
      R"(, "runs": [{"foot": "A", "tension_point": "high", "liftoff_rad": -0.1, "stood": true}]})");
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              HasSubstr("sim.json: /runs/0/liftoff_rad: expected a number >= 0, got -0.1"));
}

TEST(SimResults, UnknownKeyNamesItsPointer) {
  const Status status = LoadError(
      std::string("{") + kHeader +
      R"(, "runs": [{"foot": "A", "tension_point": "high", "liftof_rad": 0.4, "liftoff_rad": 0.4, "stood": true}]})");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /runs/0/liftof_rad: unknown key"));
}

TEST(SimResults, UnknownTopLevelKeyIsRejected) {
  const Status status = LoadError(std::string("{") + kHeader + R"(, "sumary": {}, "runs": []})");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /sumary: unknown key"));
}

TEST(SimResults, StandingRunWithoutLiftoffNamesItsPointer) {
  const Status status =
      LoadError(std::string("{") + kHeader +
                R"(, "runs": [{"foot": "B", "tension_point": "mean", "stood": true}]})");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /runs/0/liftoff_rad: missing required field"));
}

TEST(SimResults, MissingStoodNamesItsPointer) {
  const Status status =
      LoadError(std::string("{") + kHeader +
                R"(, "runs": [{"foot": "B", "tension_point": "mean", "liftoff_rad": 0.4}]})");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /runs/0/stood: missing required field"));
}

TEST(SimResults, BadSummaryFootNamesItsPointer) {
  const Status status = LoadError(std::string("{") + kHeader +
                                  R"(, "summary": {"E": {"min_rad": 0.1, "max_rad": 0.2}}})");
  EXPECT_THAT(status.message(),
              HasSubstr("sim.json: /summary/E: unknown foot; expected one of A, B, C, D"));
}

TEST(SimResults, SummaryMaxBelowMinNamesItsPointer) {
  const Status status = LoadError(std::string("{") + kHeader +
                                  R"(, "summary": {"A": {"min_rad": 0.5, "max_rad": 0.2}}})");
  EXPECT_THAT(
      status.message(),
      HasSubstr("sim.json: /summary/A/max_rad: expected a number >= min_rad (0.5), got 0.2"));
}

TEST(SimResults, NegativeSummaryValueNamesItsPointer) {
  const Status status = LoadError(std::string("{") + kHeader +
                                  R"(, "summary": {"D": {"min_rad": -0.25, "max_rad": 0.43}}})");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /summary/D/min_rad: expected a number >= 0"));
}

TEST(SimResults, NeitherRunsNorSummaryIsAnError) {
  const Status status = LoadError(std::string("{") + kHeader + "}");
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /: expected \"runs\" or \"summary\""));
}

TEST(SimResults, WrongFormatNamesItsPointer) {
  const Status status =
      LoadError(R"({"format": "liftoff-log", "version": 1, "model": "m", "runs": []})");
  EXPECT_THAT(status.message(),
              HasSubstr("sim.json: /format: expected one of liftoff-sim-results"));
}

TEST(SimResults, NewerVersionIsUnsupported) {
  const Status status =
      LoadError(R"({"format": "liftoff-sim-results", "version": 2, "model": "m", "runs": []})");
  EXPECT_EQ(status.code(), StatusCode::kUnsupported);
  EXPECT_THAT(status.message(), HasSubstr("sim.json: /version: version 2"));
}

// ---------------------------------------------------------------------------------------
// Results table

constexpr const char* kCalibration = "laika-2018 (calib/laika-2018.json)";
constexpr const char* kLookupRule = "sample-and-hold, last sample at or before the instant";

// Feet A and D of the 2018 data (laika-model.md section 7), sample-and-hold.
std::vector<TrialValue> Trials2018AD() {
  std::vector<TrialValue> trials;
  const double a[] = {0.460, 0.385, 0.432, 0.502, 0.455};
  const double d[] = {0.422, 0.357, 0.435, 0.407, 0.438};
  for (int i = 0; i < 5; ++i) {
    trials.push_back({"A" + std::to_string(i + 1), Foot::kA, a[i], a[i] - 0.01, a[i] + 0.01, ""});
  }
  for (int i = 0; i < 5; ++i) {
    trials.push_back({"D" + std::to_string(i + 1), Foot::kD, d[i], d[i] - 0.01, d[i] + 0.01, ""});
  }
  trials[1].flags = "gap 0.93 s";
  return trials;
}

// Paper Table IV's sim columns for A, B, C, typed in as a summary; no D.
SimResults PublishedSimABC() {
  SimResults sim;
  sim.source = "table4.json";
  sim.model = "laika-ntrt";
  sim.ranges[Foot::kA] = {0.33, 0.47, 0, true};
  sim.ranges[Foot::kB] = {0.35, 0.47, 0, true};
  sim.ranges[Foot::kC] = {0.25, 0.44, 0, true};
  return sim;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < text.size()) {
    const size_t end = text.find('\n', start);
    lines.push_back(text.substr(start, end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return lines;
}

bool HasLine(const std::string& text, const std::string& line) {
  for (const std::string& candidate : Lines(text)) {
    if (candidate == line) return true;
  }
  return false;
}

// A strict RFC 4180 reader: CRLF records, quoted fields with doubled quotes.
std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      EXPECT_TRUE(field.empty()) << "quote inside an unquoted field at byte " << i;
      quoted = true;
    } else if (c == ',') {
      record.push_back(std::move(field));
      field.clear();
    } else if (c == '\r') {
      EXPECT_TRUE(i + 1 < text.size() && text[i + 1] == '\n') << "bare CR at byte " << i;
      record.push_back(std::move(field));
      field.clear();
      records.push_back(std::move(record));
      record.clear();
      ++i;
    } else {
      EXPECT_NE(c, '\n') << "bare LF at byte " << i;
      field += c;
    }
  }
  EXPECT_FALSE(quoted);
  EXPECT_TRUE(record.empty() && field.empty()) << "last record not ended by CRLF";
  return records;
}

TEST(ResultsTable, RowsCoverFeetWithTrialsOrSimInOrder) {
  const auto trials = Trials2018AD();
  const SimResults sim = PublishedSimABC();
  const ResultsTable table = BuildResultsTable(trials, &sim, kCalibration, kLookupRule);
  ASSERT_EQ(table.rows.size(), 4u);
  EXPECT_EQ(table.rows[0].foot, Foot::kA);
  EXPECT_EQ(table.rows[1].foot, Foot::kB);
  EXPECT_EQ(table.rows[2].foot, Foot::kC);
  EXPECT_EQ(table.rows[3].foot, Foot::kD);
  EXPECT_EQ(table.rows[0].hardware.n, 5);
  EXPECT_NEAR(table.rows[0].hardware.mean, 0.4468, 1e-12);
  EXPECT_EQ(table.rows[0].trials.size(), 5u);
  EXPECT_EQ(table.rows[0].trials[1].trial_id, "A2");
  EXPECT_EQ(table.rows[1].hardware.n, 0);
  ASSERT_TRUE(table.rows[1].sim.has_value());
  EXPECT_DOUBLE_EQ(table.rows[1].sim->min_rad, 0.35);
  EXPECT_FALSE(table.rows[3].sim.has_value());
  // D: sum 2.059 over 5, sorted 0.357 0.407 0.422 0.435 0.438
  EXPECT_NEAR(table.rows[3].hardware.mean, 0.4118, 1e-12);
  EXPECT_DOUBLE_EQ(table.rows[3].hardware.median, 0.422);
  EXPECT_EQ(table.calibration, kCalibration);
  EXPECT_EQ(table.lookup_rule, kLookupRule);
}

TEST(ResultsTable, WithoutSimOnlyFeetWithTrialsAppear) {
  const auto trials = Trials2018AD();
  const ResultsTable table = BuildResultsTable(trials, nullptr, kCalibration, kLookupRule);
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.rows[0].foot, Foot::kA);
  EXPECT_EQ(table.rows[1].foot, Foot::kD);
  EXPECT_FALSE(table.rows[0].sim.has_value());
  EXPECT_TRUE(table.notes.empty());
}

TEST(ResultsTable, NotesReportFallenRunsSummariesAndTrialsWithoutValue) {
  std::vector<TrialValue> trials = Trials2018AD();
  trials[2].liftoff_rad = kNaN;
  trials[2].flags = "liftoff after log end";
  SimResults sim = PublishedSimABC();
  sim.runs.push_back({Foot::kB, "low", std::nullopt, false, std::nullopt, std::nullopt, ""});
  const ResultsTable table = BuildResultsTable(trials, &sim, kCalibration, kLookupRule);
  // A3 is listed but not counted
  EXPECT_EQ(table.rows[0].hardware.n, 4);
  EXPECT_EQ(table.rows[0].trials.size(), 5u);
  std::string notes;
  for (const std::string& note : table.notes) notes += note + "\n";
  EXPECT_THAT(notes, HasSubstr("laika-ntrt"));
  EXPECT_THAT(notes, HasSubstr("table4.json"));
  EXPECT_THAT(notes, HasSubstr("foot B at tension point low did not stand"));
  EXPECT_THAT(notes, HasSubstr("Sim range of foot A from the results' summary"));
  EXPECT_THAT(notes, HasSubstr("Trial A3 gave no liftoff value (liftoff after log end)"));
}

TEST(ResultsTable, MarkdownHasHeaderRowValuesAndCalibrationLine) {
  const auto trials = Trials2018AD();
  const SimResults sim = PublishedSimABC();
  const std::string md = RenderResultsTable(
      BuildResultsTable(trials, &sim, kCalibration, kLookupRule), TableFormat::kMarkdown);
  EXPECT_TRUE(HasLine(md,
                      "| Foot | Sim min | Sim max | HW min | HW max | HW n | HW mean | HW sd | "
                      "HW median | HW 95 % CI of mean |"))
      << md;
  EXPECT_TRUE(
      HasLine(md, "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | :---: |"))
      << md;
  // A: mean 0.4468, sd 0.0428, CI 0.3937 .. 0.4999 (statistics_test), 3 decimals
  EXPECT_TRUE(HasLine(
      md, "| A | 0.330 | 0.470 | 0.385 | 0.502 | 5 | 0.447 | 0.043 | 0.455 | [0.394, 0.500] |"))
      << md;
  EXPECT_TRUE(HasLine(md, "| B | 0.350 | 0.470 | – | – | 0 | – | – | – | – |")) << md;
  EXPECT_THAT(md, HasSubstr("| D | – | – | 0.357 | 0.438 | 5 | 0.412 |"));
  EXPECT_TRUE(
      HasLine(md, std::string("Calibration: ") + kCalibration + ". Lookup: " + kLookupRule + "."))
      << md;
}

TEST(ResultsTable, CsvParsesBackWithHeaderAndBlankSimCells) {
  const auto trials = Trials2018AD();
  const SimResults sim = PublishedSimABC();
  const std::string csv = RenderResultsTable(
      BuildResultsTable(trials, &sim, kCalibration, kLookupRule), TableFormat::kCsv);
  const auto records = ParseCsv(csv);
  ASSERT_EQ(records.size(), 5u);
  const std::vector<std::string> header = {"foot",          "sim_min_rad",     "sim_max_rad",
                                           "sim_n_runs",    "hw_min_rad",      "hw_max_rad",
                                           "hw_n",          "hw_mean_rad",     "hw_sd_rad",
                                           "hw_median_rad", "hw_ci95_low_rad", "hw_ci95_high_rad",
                                           "calibration",   "lookup_rule"};
  EXPECT_EQ(records[0], header);
  for (const auto& record : records) ASSERT_EQ(record.size(), header.size());
  const std::vector<std::string> a = {"A",     "0.330", "0.470",      "0",        "0.385",
                                      "0.502", "5",     "0.447",      "0.043",    "0.455",
                                      "0.394", "0.500", kCalibration, kLookupRule};
  EXPECT_EQ(records[1], a);
  // B has no hardware values, D no simulation: empty fields
  EXPECT_EQ(records[2][4], "");
  EXPECT_EQ(records[2][7], "");
  EXPECT_EQ(records[2][6], "0");
  EXPECT_EQ(records[4][0], "D");
  EXPECT_EQ(records[4][1], "");
  EXPECT_EQ(records[4][2], "");
  EXPECT_EQ(records[4][3], "");
  EXPECT_EQ(records[4][4], "0.357");
}

TEST(ResultsTable, CsvWithoutSimLeavesSimColumnsBlank) {
  const auto trials = Trials2018AD();
  const auto records = ParseCsv(RenderResultsTable(
      BuildResultsTable(trials, nullptr, kCalibration, kLookupRule), TableFormat::kCsv));
  ASSERT_EQ(records.size(), 3u);
  for (size_t row = 1; row < records.size(); ++row) {
    EXPECT_EQ(records[row][1], "");
    EXPECT_EQ(records[row][2], "");
    EXPECT_EQ(records[row][3], "");
  }
}

TEST(ResultsTable, MarkdownWithoutSimShowsDashes) {
  const auto trials = Trials2018AD();
  const std::string md = RenderResultsTable(
      BuildResultsTable(trials, nullptr, kCalibration, kLookupRule), TableFormat::kMarkdown);
  EXPECT_THAT(md, HasSubstr("| A | – | – | 0.385 | 0.502 |"));
}

TEST(ResultsTable, LatexUsesBooktabsAndCaptionNamesCalibration) {
  const auto trials = Trials2018AD();
  const SimResults sim = PublishedSimABC();
  const std::string tex =
      RenderResultsTable(BuildResultsTable(trials, &sim, "laika_2018 #2", "hold & 100% of {step}"),
                         TableFormat::kLatex);
  EXPECT_THAT(tex, HasSubstr("\\toprule"));
  EXPECT_THAT(tex, HasSubstr("\\midrule"));
  EXPECT_THAT(tex, HasSubstr("\\bottomrule"));
  EXPECT_LT(tex.find("\\toprule"), tex.find("\\midrule"));
  EXPECT_LT(tex.find("\\midrule"), tex.find("\\bottomrule"));
  // the caption names the calibration and the lookup rule, escaped
  const size_t caption = tex.find("\\caption{");
  ASSERT_NE(caption, std::string::npos);
  const std::string caption_line = tex.substr(caption, tex.find('\n', caption) - caption);
  EXPECT_THAT(caption_line, HasSubstr("laika\\_2018 \\#2"));
  EXPECT_THAT(caption_line, HasSubstr("hold \\& 100\\% of \\{step\\}"));
  EXPECT_THAT(
      tex,
      HasSubstr(
          "A & 0.330 & 0.470 & 0.385 & 0.502 & 5 & 0.447 & 0.043 & 0.455 & [0.394, 0.500] \\\\"));
  EXPECT_THAT(tex, HasSubstr("D & -- & -- & 0.357 & 0.438 & 5 & 0.412"));
}

TEST(ResultsTable, JsonHoldsValuesTrialsAndCalibration) {
  const auto trials = Trials2018AD();
  const SimResults sim = PublishedSimABC();
  const std::string text = RenderResultsTable(
      BuildResultsTable(trials, &sim, kCalibration, kLookupRule), TableFormat::kJson);
  const json document = json::parse(text);
  EXPECT_EQ(document["calibration"], kCalibration);
  EXPECT_EQ(document["lookup_rule"], kLookupRule);
  ASSERT_EQ(document["rows"].size(), 4u);
  const json& a = document["rows"][0];
  EXPECT_EQ(a["foot"], "A");
  EXPECT_EQ(a["hardware"]["n"], 5);
  // full precision, not 3 decimals
  EXPECT_NEAR(a["hardware"]["mean_rad"].get<double>(), 0.4468, 1e-12);
  EXPECT_NEAR(a["hardware"]["stddev_rad"].get<double>(), std::sqrt(0.0073268 / 4.0), 1e-12);
  EXPECT_DOUBLE_EQ(a["hardware"]["median_rad"].get<double>(), 0.455);
  EXPECT_DOUBLE_EQ(a["sim"]["min_rad"].get<double>(), 0.33);
  ASSERT_EQ(a["trials"].size(), 5u);
  EXPECT_EQ(a["trials"][1]["trial_id"], "A2");
  EXPECT_DOUBLE_EQ(a["trials"][1]["liftoff_rad"].get<double>(), 0.385);
  EXPECT_DOUBLE_EQ(a["trials"][1]["upper_rad"].get<double>(), 0.395);
  EXPECT_EQ(a["trials"][1]["flags"], "gap 0.93 s");
  // missing values are null
  EXPECT_TRUE(document["rows"][3]["sim"].is_null());
  EXPECT_TRUE(document["rows"][1]["hardware"]["mean_rad"].is_null());
}

TEST(TrialTable, MarkdownListsEveryTrialWithInterval) {
  auto trials = Trials2018AD();
  trials[2].liftoff_rad = kNaN;
  trials[2].lower_rad = kNaN;
  const std::string md =
      RenderTrialTable(trials, TableFormat::kMarkdown, kCalibration, kLookupRule);
  EXPECT_TRUE(HasLine(md, "| Trial | Foot | Liftoff | Interval | Flags |")) << md;
  EXPECT_TRUE(HasLine(md, "| A2 | A | 0.385 | [0.375, 0.395] | gap 0.93 s |")) << md;
  EXPECT_TRUE(HasLine(md, "| A3 | A | – | – |  |")) << md;
  EXPECT_TRUE(HasLine(md, "| D5 | D | 0.438 | [0.428, 0.448] |  |")) << md;
  EXPECT_THAT(md, HasSubstr(kCalibration));
  EXPECT_THAT(md, HasSubstr(kLookupRule));
}

TEST(TrialTable, MarkdownKeepsAnIdWithALineBreakOnItsRow) {
  auto trials = Trials2018AD();
  trials[1].trial_id = "A2\n| x | y |";
  trials[1].flags = "gap\r\n0.93 s";
  const std::string md =
      RenderTrialTable(trials, TableFormat::kMarkdown, kCalibration, kLookupRule);
  EXPECT_TRUE(HasLine(md, "| A2 \\| x \\| y \\| | A | 0.385 | [0.375, 0.395] | gap  0.93 s |"))
      << md;
}

TEST(TrialTable, CsvParsesBackIncludingQuotedFlags) {
  auto trials = Trials2018AD();
  trials[0].flags = "gap 0.93 s, \"burst\"";
  trials[2].liftoff_rad = kNaN;
  const auto records =
      ParseCsv(RenderTrialTable(trials, TableFormat::kCsv, kCalibration, kLookupRule));
  ASSERT_EQ(records.size(), 11u);
  const std::vector<std::string> header = {"trial_id",  "foot",  "liftoff_rad", "lower_rad",
                                           "upper_rad", "flags", "calibration", "lookup_rule"};
  EXPECT_EQ(records[0], header);
  const std::vector<std::string> first = {
      "A1", "A", "0.460", "0.450", "0.470", "gap 0.93 s, \"burst\"", kCalibration, kLookupRule};
  EXPECT_EQ(records[1], first);
  EXPECT_EQ(records[3][2], "");
  EXPECT_EQ(records[10][0], "D5");
}

TEST(TrialTable, LatexUsesBooktabsAndDashesForMissing) {
  auto trials = Trials2018AD();
  trials[2].liftoff_rad = kNaN;
  const std::string tex = RenderTrialTable(trials, TableFormat::kLatex, kCalibration, kLookupRule);
  EXPECT_THAT(tex, HasSubstr("\\toprule"));
  EXPECT_THAT(tex, HasSubstr("\\midrule"));
  EXPECT_THAT(tex, HasSubstr("\\bottomrule"));
  EXPECT_THAT(tex, HasSubstr("A3 & A & -- & [0.422, 0.442]"));
  const size_t caption = tex.find("\\caption{");
  ASSERT_NE(caption, std::string::npos);
  EXPECT_THAT(tex.substr(caption, tex.find('\n', caption) - caption), HasSubstr("laika-2018"));
}

TEST(TrialTable, JsonHoldsFullPrecisionAndNulls) {
  auto trials = Trials2018AD();
  trials[2].liftoff_rad = kNaN;
  trials[0].liftoff_rad = 0.4601234567891;
  const json document =
      json::parse(RenderTrialTable(trials, TableFormat::kJson, kCalibration, kLookupRule));
  EXPECT_EQ(document["calibration"], kCalibration);
  EXPECT_EQ(document["lookup_rule"], kLookupRule);
  ASSERT_EQ(document["trials"].size(), 10u);
  EXPECT_DOUBLE_EQ(document["trials"][0]["liftoff_rad"].get<double>(), 0.4601234567891);
  EXPECT_TRUE(document["trials"][2]["liftoff_rad"].is_null());
  EXPECT_EQ(document["trials"][9]["foot"], "D");
}

TEST(TableFormat, ParsesEveryNameAndRejectsOthers) {
  EXPECT_EQ(ParseTableFormat("md"), TableFormat::kMarkdown);
  EXPECT_EQ(ParseTableFormat("markdown"), TableFormat::kMarkdown);
  EXPECT_EQ(ParseTableFormat("csv"), TableFormat::kCsv);
  EXPECT_EQ(ParseTableFormat("latex"), TableFormat::kLatex);
  EXPECT_EQ(ParseTableFormat("tex"), TableFormat::kLatex);
  EXPECT_EQ(ParseTableFormat("json"), TableFormat::kJson);
  EXPECT_EQ(ParseTableFormat("html"), std::nullopt);
  EXPECT_EQ(ParseTableFormat("CSV"), std::nullopt);
  EXPECT_EQ(ParseTableFormat(""), std::nullopt);
  for (TableFormat format :
       {TableFormat::kMarkdown, TableFormat::kCsv, TableFormat::kLatex, TableFormat::kJson}) {
    EXPECT_EQ(ParseTableFormat(TableFormatName(format)), format);
  }
}

}  // namespace
}  // namespace liftoff::stats
