// `liftoff sim` end to end through the real binary: one run (text, JSON, curves), the
// sweep and the results file the table command reads, the MJCF export, and bad flags
// giving a message that names the flag and the exit code of their class. Runs use a
// shortened timeline (ramp 60 degrees over 10 s from 2 s) to stay fast.
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/cli/commands.h"
#include "liftoff/cli/cli11.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/core/json.h"
#include "liftoff/stats/sim_results.h"
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

constexpr std::string_view kTimeline =
    " --bend-start-s 1 --reference-s 1.9 --ramp-start-s 2 --ramp-s 10";
const std::string kShort = std::string(kTimeline) + " --progress off";

CommandRun Liftoff(const std::string& arguments, const ScratchDir& scratch) {
  return liftoff::testing::RunCommand(LIFTOFF_BINARY, arguments, scratch);
}

nlohmann::json ParseOut(const CommandRun& run) {
  try {
    return nlohmann::json::parse(run.out);
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not JSON: " << error.what() << "\n" << run.out;
    return {};
  }
}

std::vector<std::vector<std::string>> CsvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) fields.push_back(cell);
    rows.push_back(fields);
  }
  return rows;
}

TEST(SimCliRun, PrintsTheTargetedFootsLiftoffAsJson) {
  ScratchDir scratch;
  const CommandRun run =
      Liftoff(std::string("sim run --foot A --tension high --json") + kShort, scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  const nlohmann::json result = ParseOut(run);
  EXPECT_EQ(result["format"], "liftoff-sim-run");
  EXPECT_EQ(result["model"], "laika-ntrt");
  EXPECT_EQ(result["foot"], "A");
  // A: the right side group pulled, positive rotation (sim::MotionFor)
  EXPECT_EQ(result["pulled_group"], "HR");
  EXPECT_EQ(result["rotation"], "+");
  // paper Table III, high point
  EXPECT_EQ(result["tension_point"]["name"], "high");
  EXPECT_EQ(result["tension_point"]["silicone_n_per_m"], 258.0);
  EXPECT_EQ(result["tension_point"]["buna_n_n_per_m"], 1073.0);
  EXPECT_EQ(result["tension_point"]["spring_n_per_m"], 187.0);
  EXPECT_EQ(result["status"], "lifted");
  EXPECT_EQ(result["stood"], true);
  EXPECT_EQ(result["first_foot"], "A");
  ASSERT_TRUE(result["liftoff_rad"].is_number()) << run.out;
  const double liftoff_rad = result["liftoff_rad"];
  EXPECT_GT(liftoff_rad, 0.2);
  EXPECT_LT(liftoff_rad, 0.7);
  EXPECT_EQ(result["feet"]["A"]["rotation_rad"], liftoff_rad);
  // the liftoff instant is on the ramp: |angle| = (t - 2) / 10 * pi/3
  const double time_s = result["feet"]["A"]["time_s"];
  EXPECT_NEAR(liftoff_rad, (time_s - 2.0) / 10.0 * std::numbers::pi / 3.0, 1e-6);
  EXPECT_EQ(result["end_time_s"], 12.0);
}

TEST(SimCliRun, PrintsATextSummaryByDefault) {
  ScratchDir scratch;
  const CommandRun run = Liftoff(std::string("sim run --foot D --tension 4") + kShort, scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("test: foot D (back left), pull HL, rotate +"));
  EXPECT_THAT(run.out, HasSubstr("tension point high (silicone 258, Buna-N 1073, spring 187 N/m)"));
  EXPECT_THAT(run.out, HasSubstr("| D (target) |"));
  EXPECT_THAT(run.err, HasSubstr("12.00 s simulated"));
}

TEST(SimCliRun, CurvesFollowTheRampAndCrossTheThresholdAtTheLiftoff) {
  ScratchDir scratch;
  const CommandRun run = Liftoff(std::string("sim run --foot C --tension mean --json --curves ") +
                                     Quoted(scratch / "curves.csv") + kShort,
                                 scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  const nlohmann::json result = ParseOut(run);
  const std::vector<std::vector<std::string>> rows = CsvRows(ReadFile(scratch / "curves.csv"));
  ASSERT_GT(rows.size(), 100u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"time_s", "rotation_rad", "A_height_m", "B_height_m",
                                               "C_height_m", "D_height_m"}));
  // C rotates negative (sim::MotionFor); the ramp reaches -pi/3 at 12 s, sampled every 0.01 s
  const std::vector<std::string>& last = rows.back();
  EXPECT_NEAR(std::stod(last[0]), 12.0, 1e-9);
  EXPECT_NEAR(std::stod(last[1]), -std::numbers::pi / 3.0, 1e-5);
  EXPECT_EQ(rows.size() - 1, 1001u);  // 2.00 .. 12.00 s
  // the liftoff rule recomputed from the curve: the first row where C is > 1 mm up
  double crossed_rad = -1.0;
  for (size_t r = 1; r < rows.size(); ++r) {
    if (std::stod(rows[r][4]) > 0.001) {
      crossed_rad = std::abs(std::stod(rows[r][1]));
      break;
    }
  }
  ASSERT_GT(crossed_rad, 0.0);
  EXPECT_NEAR(crossed_rad, result["liftoff_rad"].get<double>(), 1e-5);
  EXPECT_THAT(run.err, HasSubstr("wrote"));
}

TEST(SimCliRun, FlagsOverrideTheExperiment) {
  ScratchDir scratch;
  const std::string base = std::string("sim run --foot A --tension high --json") + kShort;
  const CommandRun plain = Liftoff(base, scratch);
  const CommandRun higher = Liftoff(base + " --threshold-mm 5", scratch);
  const CommandRun other_motion = Liftoff(base + " --pulled HL --rotation=-", scratch);
  ASSERT_EQ(plain.code, kExitOk) << plain.err;
  ASSERT_EQ(higher.code, kExitOk) << higher.err;
  ASSERT_EQ(other_motion.code, kExitOk) << other_motion.err;
  // the same trajectory, a higher bar: the foot crosses it later in the ramp
  const nlohmann::json a = ParseOut(plain);
  const nlohmann::json b = ParseOut(higher);
  ASSERT_TRUE(b["liftoff_rad"].is_number()) << higher.out;
  EXPECT_GT(b["liftoff_rad"].get<double>(), a["liftoff_rad"].get<double>());
  EXPECT_EQ(b["feet"]["A"]["reference_height_m"], a["feet"]["A"]["reference_height_m"]);
  const nlohmann::json c = ParseOut(other_motion);
  EXPECT_EQ(c["pulled_group"], "HL");
  EXPECT_EQ(c["rotation"], "-");
}

TEST(SimCliRun, BadFlagsNameTheFlagWithTheirExitCode) {
  ScratchDir scratch;
  WriteFile(scratch / "broken.json", "{\"format\": \"liftoff-sim-model\",\n");
  struct Case {
    std::string arguments;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"--threshold-mm 0", 3,
       "--threshold-mm: liftoff_threshold_m: expected a number in (0, 1], got 0"},
      {"--ramp-s 0", 3, "--ramp-s: expected a number in (0, 3600], got 0"},
      {"--tension medium", 3, "--tension: expected low, med-low, mean, med-high, high"},
      {"--foot E", 3, "--foot: expected one of A, B, C, D, got \"E\""},
      {"--attachment glue", 3, "--attachment: expected node or surface"},
      {"--collisions some", 3, "--collisions: expected feet, ground, self or all"},
      {"--rotation x", 3, "--rotation: expected + or -"},
      {"--pulled HT", 3, "--pulled: expected HR or HL"},
      {"--stiffness 1,2", 3, "--stiffness: expected SILICONE,BUNA_N,SPRING"},
      {"--ramp-start-s 4", 3, "--reference-s:"},
      {"--dt 0.003", 3, "--sample-period-s:"},
      {"--progress fancy", 3, "--progress: expected auto, live, lines or off"},
      {"--model " + Quoted(scratch / "missing.json"), 4, "missing.json"},
      {"--model " + Quoted(scratch / "broken.json"), 5, "broken.json"},
      {"--no-such-flag", 2, ""},
  };
  for (const Case& c : cases) {
    const CommandRun run = Liftoff("sim run " + c.arguments, scratch);
    EXPECT_EQ(run.code, c.code) << c.arguments << "\n" << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message)) << c.arguments;
    EXPECT_EQ(run.out, "") << c.arguments;
  }
}

TEST(SimCliSweep, WritesResultsTheTableCommandReads) {
  ScratchDir scratch;
  const std::filesystem::path results_path = scratch / "results.json";
  const CommandRun run =
      Liftoff(std::string("sim sweep --feet C,A --tensions high,mean --threads 2 -o ") +
                  Quoted(results_path) + kShort,
              scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.err, HasSubstr("4 runs in"));
  EXPECT_THAT(run.out, HasSubstr("| Foot | Motion | high | mean | Sim min | Sim max |"));

  auto results = stats::LoadSimResults(results_path);
  ASSERT_TRUE(results.ok()) << results.status().ToString();
  EXPECT_EQ(results->model, "laika-ntrt");
  ASSERT_EQ(results->runs.size(), 4u);
  // foot-major in the order asked for
  const std::vector<std::pair<Foot, std::string>> order = {
      {Foot::kC, "high"}, {Foot::kC, "mean"}, {Foot::kA, "high"}, {Foot::kA, "mean"}};
  for (size_t i = 0; i < order.size(); ++i) {
    const stats::SimRun& sim_run = results->runs[i];
    EXPECT_EQ(sim_run.foot, order[i].first);
    EXPECT_EQ(sim_run.tension_point, order[i].second);
    ASSERT_TRUE(sim_run.pulled_group && sim_run.rotation);
    EXPECT_EQ(*sim_run.pulled_group, CableGroup::kHR);  // A and C both pull the right side
    EXPECT_EQ(*sim_run.rotation,
              order[i].first == Foot::kA ? RotationSense::kPositive : RotationSense::kNegative);
    // the same test as a single run (whole timeline, no sweep) gives the same value
    const CommandRun single =
        Liftoff("sim run --json --foot " + std::string(FootName(order[i].first)) + " --tension " +
                    order[i].second + kShort,
                scratch);
    ASSERT_EQ(single.code, kExitOk) << single.err;
    const nlohmann::json alone = ParseOut(single);
    EXPECT_EQ(sim_run.stood, alone["stood"].get<bool>());
    if (sim_run.stood) {
      ASSERT_TRUE(sim_run.liftoff_rad);
      EXPECT_EQ(*sim_run.liftoff_rad, alone["liftoff_rad"].get<double>());
    }
  }
}

TEST(SimCliSweep, ReportsEachRunOnStderrAndCanPrintTheJson) {
  ScratchDir scratch;
  const CommandRun run = Liftoff(std::string("sim sweep --feet B --tensions 0,4 --json") +
                                     std::string(kTimeline) + " --progress lines",
                                 scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.err, HasSubstr("sim: [1/2] B HL- "));
  EXPECT_THAT(run.err, HasSubstr("sim: [2/2] B HL- "));
  const nlohmann::json document = ParseOut(run);
  auto results = stats::SimResultsFromJson(document, "stdout");
  ASSERT_TRUE(results.ok()) << results.status().ToString();
  ASSERT_EQ(results->runs.size(), 2u);
  EXPECT_EQ(results->runs[0].tension_point, "low");
  EXPECT_EQ(results->runs[1].tension_point, "high");
}

TEST(SimCliSweep, PrintsTheHardwareTableBesideTheSimulation) {
  ScratchDir scratch;
  const std::filesystem::path manifest = SourceDir() / "samples" / "trials" / "manifest.json";
  const CommandRun run =
      Liftoff(std::string("sim sweep --feet A --tensions high --json --hardware ") +
                  Quoted(manifest) + " -f json" + kShort,
              scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  // two JSON documents: the results, then the table
  const size_t split = run.out.find("\n{");
  ASSERT_NE(split, std::string::npos) << run.out;
  const nlohmann::json results = nlohmann::json::parse(run.out.substr(0, split));
  const nlohmann::json table = nlohmann::json::parse(run.out.substr(split + 1));
  const double simulated = results["runs"][0]["liftoff_rad"];
  EXPECT_EQ(table["format"], "liftoff-results-table");
  bool found = false;
  for (const nlohmann::json& row : table["rows"]) {
    if (row["foot"] != "A") continue;
    found = true;
    EXPECT_EQ(row["sim"]["min_rad"], simulated);
    EXPECT_EQ(row["sim"]["max_rad"], simulated);
    EXPECT_EQ(row["sim"]["n_runs"], 1);
    EXPECT_GT(row["hardware"]["n"].get<int>(), 0);
  }
  EXPECT_TRUE(found) << run.out;
}

TEST(SimCliSweep, BadListsNameTheFlag) {
  ScratchDir scratch;
  const CommandRun feet = Liftoff("sim sweep --feet A,E --progress off", scratch);
  EXPECT_EQ(feet.code, 3);
  EXPECT_THAT(feet.err, HasSubstr("--feet: expected one of A, B, C, D, got \"E\""));
  const CommandRun twice = Liftoff("sim sweep --feet A,A --progress off", scratch);
  EXPECT_EQ(twice.code, 3);
  EXPECT_THAT(twice.err, HasSubstr("--feet: foot A appears twice"));
  const CommandRun tensions = Liftoff("sim sweep --tensions high,highest --progress off", scratch);
  EXPECT_EQ(tensions.code, 3);
  EXPECT_THAT(tensions.err, HasSubstr("--tensions:"));
  EXPECT_THAT(tensions.err, HasSubstr("\"highest\""));
  const CommandRun format = Liftoff("sim sweep --format xml --progress off", scratch);
  EXPECT_EQ(format.code, 3);
  EXPECT_THAT(format.err, HasSubstr("--format"));
}

TEST(SimCliExport, WritesTheModelAsMjcf) {
  ScratchDir scratch;
  const CommandRun run = Liftoff("sim export-mjcf -o " + Quoted(scratch / "laika.xml"), scratch);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  const std::string xml = ReadFile(scratch / "laika.xml");
  EXPECT_THAT(xml, HasSubstr("<mujoco"));
  // the reference model: 32 cables, one marker per foot
  size_t tendons = 0;
  for (size_t at = xml.find("<spatial"); at != std::string::npos;
       at = xml.find("<spatial", at + 1)) {
    ++tendons;
  }
  EXPECT_EQ(tendons, 32u);
  for (const char* marker : {"marker_A", "marker_B", "marker_C", "marker_D"}) {
    EXPECT_THAT(xml, HasSubstr(marker));
  }
  const CommandRun to_stdout = Liftoff("sim export-mjcf -o -", scratch);
  ASSERT_EQ(to_stdout.code, kExitOk) << to_stdout.err;
  EXPECT_EQ(to_stdout.out, xml);
  const CommandRun as_is = Liftoff("sim export-mjcf --as-is --friction 0.5 -o -", scratch);
  EXPECT_EQ(as_is.code, 3);
  EXPECT_THAT(as_is.err, HasSubstr("--as-is"));
  EXPECT_THAT(as_is.err, HasSubstr("--friction 0.5"));
}

// ---------------------------------------------------------------------------------------
// the conversion, on a sweep built by hand

sim::SweepRun HandRun(Foot foot, const std::string& tension, sim::RunStatus status,
                      std::optional<double> target_rad, std::optional<Foot> first) {
  sim::SweepRun run;
  run.foot = foot;
  run.tension_point.name = tension;
  run.result.foot = foot;
  run.result.motion = sim::MotionFor(foot);
  run.result.tension_point = tension;
  run.result.status = status;
  run.result.first_foot = first;
  if (status == sim::RunStatus::kDidNotStand) run.result.not_standing_reason = "sagged";
  if (target_rad) {
    run.result.feet[static_cast<size_t>(foot)] = {true, 20.0, *target_rad};
  }
  return run;
}

TEST(SimResultsFromSweep, RoundTripsThroughLoadSimResults) {
  sim::SweepResult sweep;
  sweep.model_name = "hand";
  sweep.runs = {
      HandRun(Foot::kA, "low", sim::RunStatus::kDidNotStand, std::nullopt, std::nullopt),
      HandRun(Foot::kA, "high", sim::RunStatus::kLifted, 0.45, Foot::kA),
      HandRun(Foot::kA, "mean", sim::RunStatus::kLifted, 0.41, Foot::kA),
      HandRun(Foot::kB, "high", sim::RunStatus::kNoLiftoff, std::nullopt, std::nullopt),
      HandRun(Foot::kC, "high", sim::RunStatus::kLifted, 0.30, Foot::kD),
  };
  const stats::SimResults converted = SimResultsFromSweep(sweep, "by hand");
  ScratchDir scratch;
  ASSERT_TRUE(WriteJsonFile(scratch / "sim.json", stats::SimResultsToJson(converted)).ok());
  auto loaded = stats::LoadSimResults(scratch / "sim.json");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();

  EXPECT_EQ(loaded->model, "hand");
  EXPECT_THAT(loaded->description, HasSubstr("by hand"));
  EXPECT_THAT(loaded->description, HasSubstr("did not lift (left out): B high"));
  // B high stood without a liftoff: the format has no place for it
  ASSERT_EQ(loaded->runs.size(), 4u);
  EXPECT_EQ(loaded->runs[0].tension_point, "low");
  EXPECT_FALSE(loaded->runs[0].stood);
  EXPECT_FALSE(loaded->runs[0].liftoff_rad);
  EXPECT_THAT(loaded->runs[0].notes, HasSubstr("sagged"));
  EXPECT_TRUE(loaded->runs[1].stood);
  EXPECT_EQ(loaded->runs[1].liftoff_rad, 0.45);
  EXPECT_EQ(loaded->runs[1].pulled_group, CableGroup::kHR);
  EXPECT_EQ(loaded->runs[1].rotation, RotationSense::kPositive);
  EXPECT_EQ(loaded->runs[3].foot, Foot::kC);
  EXPECT_EQ(loaded->runs[3].liftoff_rad, 0.30);
  EXPECT_THAT(loaded->runs[3].notes, HasSubstr("first D"));
  // ranges from the standing runs only, not typed in
  ASSERT_EQ(loaded->ranges.count(Foot::kA), 1u);
  EXPECT_EQ(loaded->ranges.at(Foot::kA).min_rad, 0.41);
  EXPECT_EQ(loaded->ranges.at(Foot::kA).max_rad, 0.45);
  EXPECT_EQ(loaded->ranges.at(Foot::kA).n_runs, 2);
  EXPECT_FALSE(loaded->ranges.at(Foot::kA).from_summary);
  EXPECT_EQ(loaded->ranges.count(Foot::kB), 0u);
  EXPECT_EQ(loaded->ranges.at(Foot::kC).n_runs, 1);
}

TEST(ExperimentFlags, ConvertUnitsAndDescribeWhatDiffersFromTheDefaults) {
  SimExperimentChoice choice;
  CLI::App app;
  Command root(&app);
  AddExperimentFlags(root, choice);
  EXPECT_EQ(DescribeOverrides(choice), "");
  app.parse(
      "--ramp-deg 30 --threshold-mm 2 --ground-clearance-mm 0.5 --rotation=- --friction 0.25 "
      "--attachment node --damping-cap off --pretension-ratios 0.01,0.02,0.03,0.004 "
      "--collisions ground",
      false);
  const sim::ExperimentOptions& options = choice.options;
  EXPECT_NEAR(options.ramp_angle_rad, std::numbers::pi / 6.0, 1e-15);
  EXPECT_NEAR(options.liftoff_threshold_m, 0.002, 1e-15);
  EXPECT_NEAR(options.ground_clearance_m, 0.0005, 1e-15);
  EXPECT_EQ(options.rotation, RotationSense::kNegative);
  EXPECT_EQ(options.friction, 0.25);
  EXPECT_EQ(options.spine_ground_collisions, true);
  EXPECT_EQ(options.spine_self_collisions, false);
  EXPECT_EQ(options.cable_attachment, sim::CableAttachment::kNode);
  EXPECT_EQ(options.damping_cap, false);
  EXPECT_EQ(options.pretension_ratios.saddle_m, 0.03);
  // untouched fields keep the struct's defaults
  EXPECT_EQ(options.bend_fraction, sim::ExperimentOptions().bend_fraction);
  EXPECT_FALSE(options.spine_friction);
  ASSERT_TRUE(ExperimentOptionsFrom(choice).ok());
  EXPECT_EQ(DescribeOverrides(choice),
            "--rotation=- --ramp-deg 30 --threshold-mm 2 --ground-clearance-mm 0.5 "
            "--pretension-ratios 0.01,0.02,0.03,0.004 --friction 0.25 --attachment node "
            "--collisions ground --damping-cap off");
}

TEST(ExperimentFlags, ValidateMessagesNameTheFlag) {
  SimExperimentChoice choice;
  choice.options.engine.solver_iterations = 0;
  auto options = ExperimentOptionsFrom(choice);
  ASSERT_FALSE(options.ok());
  EXPECT_THAT(options.status().message(), ::testing::StartsWith("--solver-iterations: expected"));
  choice = {};
  choice.options.pretension_ratios.side_m = 2.0;
  options = ExperimentOptionsFrom(choice);
  ASSERT_FALSE(options.ok());
  EXPECT_THAT(options.status().message(),
              ::testing::StartsWith("--pretension-ratios: pretension_ratios.side_m: expected"));
}

}  // namespace
}  // namespace liftoff::cli
