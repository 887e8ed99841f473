// The command line end to end: the sample data's known answers, the 2018 reference
// values, and every kind of bad input giving a clear message and its own exit code.
#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/cli/capture_commands.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/json.h"
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

CommandRun RunTableCommand(const TableCommand& command) {
  return liftoff::testing::RunInProcess(RunTable, command);
}

CommandRun RunBinary(const std::string& arguments, const ScratchDir& scratch) {
  return liftoff::testing::RunCommand(LIFTOFF_BINARY, arguments, scratch);
}

// A manifest with one trial whose log is `log_text` in the 2018 format.
std::filesystem::path WriteOneTrial(const ScratchDir& scratch, const std::string& log_text,
                                    double led_on_s, double liftoff_s) {
  WriteFile(scratch / "trial.txt", log_text);
  nlohmann::json manifest = {{"format", "liftoff-manifest"},
                             {"version", 1},
                             {"trials",
                              {{{"id", "T1"},
                                {"foot", "A"},
                                {"log", {{"path", "trial.txt"}, {"format", "laika-2018"}}},
                                {"times", {{"led_on_s", led_on_s}, {"liftoff_s", liftoff_s}}}}}}};
  WriteFile(scratch / "manifest.json", manifest.dump(2));
  return scratch / "manifest.json";
}

// A 2018-style ramp: shaft angle = t_s, one sample every 100 ms up to `end_ms`.
std::string RampLog2018(int end_ms) {
  std::string text;
  for (int t_ms = 0; t_ms <= end_ms; t_ms += 100) {
    text += std::to_string(t_ms) + "," + std::to_string(t_ms / 1000.0) + ",\r";
  }
  return text;
}

TEST(CliTable, SampleTrialsMatchTheirKnownAnswers) {
  const std::filesystem::path samples = SourceDir() / "samples" / "trials";
  auto expected = LoadJsonFile(samples / "expected.json");
  ASSERT_TRUE(expected.ok()) << expected.status().ToString();

  TableCommand command;
  command.manifest_path = samples / "manifest.json";
  command.format = "json";
  const CommandRun run = RunTableCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  const nlohmann::json table = nlohmann::json::parse(run.out);

  // every trial of every foot: the truth lies in the reported interval, and the linear
  // lookup is within encoder quantisation (dense logs) or the 2018 two-decimal rounding
  int checked = 0;
  for (const auto& row : table.at("rows")) {
    for (const auto& trial : row.at("trials")) {
      const std::string id = trial.at("trial_id");
      const double truth = (*expected)["trials"][id]["liftoff_rad"];
      const double value = trial.at("liftoff_rad");
      EXPECT_NEAR(value, truth, 2e-3) << id;
      EXPECT_LE(trial.at("lower_rad").get<double>(), truth + 1e-9) << id;
      EXPECT_GE(trial.at("upper_rad").get<double>(), truth - 1e-9) << id;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8);
}

TEST(CliTable, PrintsBothTablesAndNamesTheCalibration) {
  TableCommand command;
  command.manifest_path = SourceDir() / "samples" / "trials" / "manifest.json";
  const CommandRun run = RunTableCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("laika-2018"));
  EXPECT_THAT(run.out, HasSubstr("A1"));
  EXPECT_THAT(run.out, HasSubstr("D2"));
  // the 2018-format sample trial falls inside a burst gap, and says so
  EXPECT_THAT(run.err, HasSubstr("D2"));
  EXPECT_THAT(run.err, HasSubstr("gap"));
}

TEST(CliTable, MissingManifestNamesTheFile) {
  TableCommand command;
  command.manifest_path = "/nonexistent/trials.json";
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kNotFound));
  EXPECT_THAT(run.err, HasSubstr("/nonexistent/trials.json"));
}

TEST(CliTable, MalformedManifestFieldNamesTheJsonPath) {
  ScratchDir scratch;
  WriteOneTrial(scratch, RampLog2018(5000), 1.0, 3.0);
  std::string text = ReadFile(scratch / "manifest.json");
  text.replace(text.find("\"A\""), 3, "\"E\"");
  WriteFile(scratch / "manifest.json", text);
  TableCommand command;
  command.manifest_path = scratch / "manifest.json";
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(run.err, HasSubstr("manifest.json: /trials/0/foot"));
  EXPECT_THAT(run.err, HasSubstr("\"E\""));
}

TEST(CliTable, LogWithGarbageLinesNamesTheLine) {
  ScratchDir scratch;
  std::string log = RampLog2018(5000);
  log.insert(log.find("300,"), "12#$garbage\r");  // becomes line 4
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, log, 1.0, 3.0);
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kParse));
  EXPECT_THAT(run.err, HasSubstr("trial.txt:4"));
  EXPECT_THAT(run.err, HasSubstr("T1"));

  // tolerated when asked, and still reported with its line number
  command.lookup.max_bad_lines = 1;
  const CommandRun lenient = RunTableCommand(command);
  EXPECT_EQ(lenient.code, kExitOk) << lenient.err;
  EXPECT_THAT(lenient.err, HasSubstr("trial.txt:4"));
}

TEST(CliTable, EmptyLogIsAnError) {
  ScratchDir scratch;
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, "", 1.0, 3.0);
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kParse));
  EXPECT_THAT(run.err, HasSubstr("trial.txt"));
  EXPECT_THAT(run.err, HasSubstr("no samples"));
}

TEST(CliTable, LookupBeyondTheLogsEndIsOutOfRange) {
  ScratchDir scratch;
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, RampLog2018(2000), 1.0, 9.0);  // needs 8 s
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kOutOfRange));
  EXPECT_THAT(run.err, HasSubstr("T1"));
  EXPECT_THAT(run.err, HasSubstr("8.000"));
}

TEST(CliTable, UnknownCalibrationKeyNamesTheJsonPath) {
  ScratchDir scratch;
  auto calibration = LoadJsonFile(SourceDir() / "calib" / "laika-2018.json");
  ASSERT_TRUE(calibration.ok());
  (*calibration)["gear_ration"] = 4;
  WriteFile(scratch / "bad-calib.json", calibration->dump(2));
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, RampLog2018(5000), 1.0, 3.0);
  command.calibration.calibration_path = scratch / "bad-calib.json";
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(run.err, HasSubstr("bad-calib.json: /gear_ration"));
  EXPECT_THAT(run.err, HasSubstr("unknown key"));
}

TEST(CliTable, OneBadTrialDoesNotLoseTheOthers) {
  ScratchDir scratch;
  WriteFile(scratch / "good.txt", RampLog2018(5000));
  nlohmann::json manifest = {{"format", "liftoff-manifest"},
                             {"version", 1},
                             {"trials",
                              {{{"id", "good"},
                                {"foot", "A"},
                                {"log", {{"path", "good.txt"}, {"format", "laika-2018"}}},
                                {"times", {{"led_on_s", 1.0}, {"liftoff_s", 3.0}}}},
                               {{"id", "lost"},
                                {"foot", "B"},
                                {"log", {{"path", "missing.txt"}, {"format", "laika-2018"}}},
                                {"times", {{"led_on_s", 1.0}, {"liftoff_s", 3.0}}}}}}};
  WriteFile(scratch / "manifest.json", manifest.dump());
  TableCommand command;
  command.manifest_path = scratch / "manifest.json";
  command.format = "csv";
  command.tables = "trials";
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kNotFound));
  EXPECT_THAT(run.err, HasSubstr("missing.txt"));
  EXPECT_THAT(run.out, HasSubstr("good"));
  EXPECT_THAT(run.out, HasSubstr("0.500"));  // shaft 2 rad at log time 2 s, over the 4:1 spur gear
}

TEST(CliTable, SimulationResultsFillTheSimColumns) {
  ScratchDir scratch;
  const nlohmann::json sim = {{"format", "liftoff-sim-results"},
                              {"version", 1},
                              {"model", "test"},
                              {"summary", {{"A", {{"min_rad", 0.123}, {"max_rad", 0.456}}}}}};
  WriteFile(scratch / "sim.json", sim.dump());
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, RampLog2018(5000), 1.0, 3.0);
  command.sim_path = scratch / "sim.json";
  command.format = "csv";
  command.tables = "feet";
  const CommandRun run = RunTableCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("0.123"));
  EXPECT_THAT(run.out, HasSubstr("0.456"));
  EXPECT_THAT(run.out, HasSubstr("0.500"));  // the hardware value beside them

  // a bad simulation file is named with its JSON path
  WriteFile(scratch / "sim.json", R"({"format": "liftoff-sim-results", "version": 1, "model": "m",
      "summary": {"E": {"min_rad": 0.1, "max_rad": 0.2}}})");
  const CommandRun bad = RunTableCommand(command);
  EXPECT_EQ(bad.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(bad.err, HasSubstr("sim.json: /summary"));
}

TEST(CliTable, PlotDrawsTheTrialAndTheSimulatedRangeThroughGnuplot) {
  ScratchDir scratch;
  const nlohmann::json sim = {{"format", "liftoff-sim-results"},
                              {"version", 1},
                              {"model", "test"},
                              {"summary", {{"A", {{"min_rad", 0.123}, {"max_rad", 0.456}}}}}};
  WriteFile(scratch / "sim.json", sim.dump());
  TableCommand command;
  command.manifest_path = WriteOneTrial(scratch, RampLog2018(5000), 1.0, 3.0);
  command.sim_path = scratch / "sim.json";
  command.plot_path = scratch / "plot.svg";
  const bool gnuplot = liftoff::testing::FindOnPath("gnuplot").has_value();
  const CommandRun run = RunTableCommand(command);
  // the script and data always; the images when gnuplot is there, else kNotFound
  const std::string data = ReadFile(scratch / "plot.dat");
  EXPECT_THAT(data, HasSubstr("0 0.5 "));  // the one trial, at 0.500 rad
  EXPECT_THAT(data, HasSubstr(" 0.123 \"min\"\n"));
  EXPECT_THAT(data, HasSubstr(" 0.456 \"max\"\n"));
  EXPECT_THAT(ReadFile(scratch / "plot.gp"), HasSubstr("\"plot.dat\""));
  if (!gnuplot) {
    EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kNotFound)) << run.err;
    EXPECT_THAT(run.err, HasSubstr("gnuplot-nox"));
    std::cout << "[  SKIPPED ] PNG/SVG checks: gnuplot is not on the PATH\n";
    return;
  }
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(ReadFile(scratch / "plot.svg"), HasSubstr("</svg>"));
  EXPECT_EQ(ReadFile(scratch / "plot.png").substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_THAT(run.err, HasSubstr("wrote " + (scratch / "plot.svg").string()));
}

TEST(CliTable, AFolderThatIsNotA2018FolderIsRejected) {
  ScratchDir scratch;
  TableCommand command;
  command.manifest_path = scratch.path();
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(run.err, HasSubstr("foot lifting times from hw videos.csv"));
}

TEST(CliTable, BadFlagValuesAreRejected) {
  TableCommand command;
  command.manifest_path = SourceDir() / "samples" / "trials" / "manifest.json";
  command.format = "xlsx";
  EXPECT_EQ(RunTableCommand(command).code, ExitCodeFor(StatusCode::kInvalidArgument));
  command.format = "md";
  command.lookup.rule = "nearest";
  const CommandRun run = RunTableCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(run.err, HasSubstr("--rule"));
}

TEST(CliBinary, HelpUsageAndSampleRun) {
  ScratchDir scratch;
  EXPECT_EQ(RunBinary("--help", scratch).code, 0);
  EXPECT_EQ(RunBinary("table --no-such-flag x", scratch).code, kExitUsage);
  EXPECT_EQ(RunBinary("", scratch).code, kExitUsage);
  const CommandRun run =
      RunBinary("table " + Quoted(SourceDir() / "samples" / "trials" / "manifest.json"), scratch);
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("laika-2018"));
  const CommandRun missing = RunBinary("table /nonexistent.json", scratch);
  EXPECT_EQ(missing.code, 4);
  EXPECT_THAT(missing.err, HasSubstr("/nonexistent.json"));
}

TEST(CliBinary, CalibAndLogCommands) {
  ScratchDir scratch;
  const CommandRun calib = RunBinary("calib", scratch);
  EXPECT_EQ(calib.code, 0) << calib.err;
  EXPECT_THAT(calib.out, HasSubstr("48000 per vertebra revolution"));
  WriteFile(scratch / "ramp.txt", RampLog2018(3000));
  const CommandRun log = RunBinary(
      "log " + Quoted(scratch / "ramp.txt") + " --convert " + Quoted(scratch / "ramp.csv"),
      scratch);
  EXPECT_EQ(log.code, 0) << log.err;
  EXPECT_THAT(log.out, HasSubstr("samples: 31"));
  // the converted log reads back as liftoff's format with the same samples
  const CommandRun again = RunBinary("log " + Quoted(scratch / "ramp.csv"), scratch);
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_THAT(again.out, HasSubstr("(liftoff)"));
  EXPECT_THAT(again.out, HasSubstr("samples: 31"));
}

TEST(CliSync, OneLookupHoldVersusLinear) {
  ScratchDir scratch;
  WriteFile(scratch / "ramp.txt", RampLog2018(5000));
  SyncCommand command;
  command.log_path = scratch / "ramp.txt";
  command.led_on_s = 1.0;
  command.liftoff_s = 3.25;  // log instant 2.25 s: shaft 2.25 rad, vertebra 0.5625 rad
  command.json = true;
  std::ostringstream out, err;
  ASSERT_EQ(RunSync(command, out, err), kExitOk) << err.str();
  const auto linear = nlohmann::json::parse(out.str());
  EXPECT_NEAR(linear["liftoff_rad"].get<double>(), 2.25 / 4, 1e-9);

  command.lookup.rule = "hold";
  std::ostringstream out2, err2;
  ASSERT_EQ(RunSync(command, out2, err2), kExitOk) << err2.str();
  const auto hold = nlohmann::json::parse(out2.str());
  EXPECT_NEAR(hold["liftoff_rad"].get<double>(), 2.2 / 4, 1e-9);  // sample at 2.2 s
}

TEST(CliSync, SecondsBeyondTheLimitAreRejectedNamingTheFlag) {
  // 1e10 s once overflowed to INT64_MIN ns: the lookup answered far past the log's end
  ScratchDir scratch;
  WriteFile(scratch / "ramp.txt", RampLog2018(5000));
  const auto run = [](const SyncCommand& command) {
    std::ostringstream out, err;
    CommandRun result;
    result.code = RunSync(command, out, err);
    result.err = err.str();
    return result;
  };
  SyncCommand command;
  command.log_path = scratch / "ramp.txt";
  command.led_on_s = 1.0;
  command.liftoff_s = 3.25;
  command.lookup.max_past_end_s = 1e10;
  CommandRun result = run(command);
  EXPECT_EQ(result.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(result.err,
              HasSubstr("--max-past-end: expected a number in [0, 1e+06] s, got 1e+10"));
  command.lookup.max_past_end_s = 1.0;
  command.liftoff_s = 1e10;
  result = run(command);
  EXPECT_EQ(result.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(result.err, HasSubstr("--liftoff: expected a number in [0, 1e+06] s, got 1e+10"));
  // and through the binary's own flag parsing
  const CommandRun binary = RunBinary(
      "sync " + Quoted(scratch / "ramp.txt") + " --led-on 1 --liftoff 3.25 --max-past-end 1e10",
      scratch);
  EXPECT_EQ(binary.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(binary.err, HasSubstr("--max-past-end"));
  LogCommand log;
  log.log_path = scratch / "ramp.txt";
  log.gap_threshold_s = 1e10;
  std::ostringstream out, err;
  EXPECT_EQ(RunLog(log, out, err), ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(err.str(), HasSubstr("--gap-threshold"));
}

// The lookup, log-reading and journal flags are range-checked by their option struct's
// Validate() alone; the message names the flag as the user typed it.
TEST(CliFlags, OptionStructValidateNamesTheFlag) {
  ScratchDir scratch;
  WriteFile(scratch / "ramp.txt", RampLog2018(5000));
  const auto sync_error = [&](const LookupChoice& lookup) {
    SyncCommand command;
    command.log_path = scratch / "ramp.txt";
    command.led_on_s = 1.0;
    command.liftoff_s = 3.25;
    command.lookup = lookup;
    std::ostringstream out, err;
    EXPECT_EQ(RunSync(command, out, err), ExitCodeFor(StatusCode::kInvalidArgument));
    return err.str();
  };
  LookupChoice lookup;
  lookup.gap_threshold_s = 0.0;
  EXPECT_THAT(sync_error(lookup),
              HasSubstr("--gap-threshold: expected a number in (0, 1e+06] s, got 0\n"));
  lookup = {};
  lookup.max_past_end_s = -1.0;
  EXPECT_THAT(sync_error(lookup),
              HasSubstr("--max-past-end: expected a number in [0, 1e+06] s, got -1\n"));
  lookup = {};
  lookup.max_bad_lines = -2;
  EXPECT_THAT(sync_error(lookup),
              HasSubstr("--max-bad-lines: expected an integer >= 0, got -2\n"));

  LogCommand log;
  log.log_path = scratch / "ramp.txt";
  log.gap_threshold_s = -0.5;
  std::ostringstream out, err;
  EXPECT_EQ(RunLog(log, out, err), ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(err.str(),
              HasSubstr("--gap-threshold: expected a number in (0, 1e+06] s, got -0.5\n"));

  JournalCommand journal;
  journal.journal_path = scratch / "none.journal";
  journal.max_records = -1;
  std::ostringstream journal_out, journal_err;
  EXPECT_EQ(RunJournal(journal, journal_out, journal_err),
            ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(journal_err.str(), HasSubstr("--max-records: expected >= 0, got -1\n"));
}

TEST(CliLog, AutoFormatRecognisesALiftoffLogBehindAByteOrderMark) {
  ScratchDir scratch;
  WriteFile(scratch / "bom.csv",
            "\xEF\xBB\xBF# liftoff-log 1\n"
            "device_time_ns,host_time_ns,seq,led,bend_counts,rotate_counts,bend_spool_rad,"
            "rotate_shaft_rad,vertebra_rad,event,detail\n"
            "0,,,,,,,,0.5,,\n100000000,,,,,,,,0.6,,\n");
  LogCommand command;
  command.log_path = scratch / "bom.csv";  // log_format "auto"
  std::ostringstream out, err;
  ASSERT_EQ(RunLog(command, out, err), kExitOk) << err.str();
  EXPECT_THAT(out.str(), HasSubstr("(liftoff)"));
  EXPECT_THAT(out.str(), HasSubstr("samples: 2"));
}

TEST(Samples, RegenerateByteForByte) {
  ScratchDir scratch;
  const std::string command =
      std::string("\"") + SAMPLE_GENERATOR + "\" " + Quoted(scratch / "trials") + " >/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::filesystem::path committed = SourceDir() / "samples" / "trials";
  int compared = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(committed)) {
    if (!entry.is_regular_file()) continue;
    const auto relative = entry.path().lexically_relative(committed);
    EXPECT_EQ(ReadFile(scratch / "trials" / relative.string()), ReadFile(entry.path()))
        << relative << " differs from what make_sample_trials writes";
    ++compared;
  }
  EXPECT_EQ(compared, 10);  // manifest, expected values and eight logs
}

TEST(CliImport2018, ReferenceDataGivesThePublishedSampleAndHoldValues) {
  LIFTOFF_REQUIRE_REFERENCE(reference);
  ScratchDir scratch;
  const std::filesystem::path manifest = scratch / "laika-2018.json";
  const CommandRun imported = RunBinary(
      "import-2018 " + Quoted(reference / "laika-2018-hardware") + " -o " + Quoted(manifest),
      scratch);
  ASSERT_EQ(imported.code, 0) << imported.err;
  EXPECT_THAT(imported.out, HasSubstr("20 trials"));

  const CommandRun table =
      RunBinary("table " + Quoted(manifest) + " --rule hold --format json", scratch);
  // the folder itself, imported on the fly, gives the very same table
  const CommandRun direct = RunBinary(
      "table " + Quoted(reference / "laika-2018-hardware") + " --rule hold --format json", scratch);
  EXPECT_EQ(direct.code, 0) << direct.err;
  EXPECT_EQ(direct.out, table.out);
  ASSERT_EQ(table.code, 0) << table.err;
  const nlohmann::json document = nlohmann::json::parse(table.out);
  // laika-model.md section 7: the authors' rule on the 20 tests
  const std::map<std::string, std::array<double, 5>> published = {
      {"A", {0.460, 0.385, 0.432, 0.502, 0.455}},
      {"B", {0.560, 0.552, 0.600, 0.557, 0.590}},
      {"C", {0.525, 0.512, 0.510, 0.540, 0.495}},
      {"D", {0.422, 0.357, 0.435, 0.407, 0.438}}};
  int checked = 0;
  for (const auto& row : document.at("rows")) {
    const std::string foot = row.at("foot");
    for (const auto& trial : row.at("trials")) {
      const std::string id = trial.at("trial_id");
      const auto test = static_cast<size_t>(id.back() - '0');
      EXPECT_NEAR(trial.at("liftoff_rad").get<double>(), published.at(foot)[test - 1], 1e-3) << id;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 20);
  EXPECT_THAT(table.out, HasSubstr("laika-2018"));
}

}  // namespace
}  // namespace liftoff::cli
