// `liftoff report` beyond one core and one machine: --jobs gives what one job gives,
// `--shard i/n` runs (four at once through GNU parallel) merged with --merge give what one
// run gives, file for file, byte for byte; the merge refuses missing, duplicate, foreign
// and damaged shards naming the file; --shard is checked; the Monte Carlo's draws are the
// same whatever the number of shards.
//
// Campaigns: the sample trials (hand times) with a small sweep, calibration and Monte
// Carlo; and nine trials of the synthetic CI set (video analysis; fixture ci_set, the test
// skips with a message where the set has not been rendered), one of them failing.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/cli/commands.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/sync/trial_analysis.h"
#include "report_shards.h"
#include "support/test_support.h"

#ifdef LIFTOFF_CI_SET_DIR
constexpr char kRenderedSetDir[] = LIFTOFF_CI_SET_DIR;
#else
constexpr char kRenderedSetDir[] = "";
#endif

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::RunCommand;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

const fs::path kBinary = LIFTOFF_BINARY;

// the sample trials with the small sweep and calibration of report_cli_test, eight
// Monte Carlo draws
std::string SampleFlags() {
  return Quoted(SourceDir() / "samples" / "trials" / "manifest.json") +
         " --tensions mean,high --progress off --fit-min 0 --fit-max 3 --fit-step 0.5"
         " --bootstrap 200 --mc-samples 8";
}

// Every file under `dir` but shard files, by relative path, with the lines that carry a
// wall time left out (none of the report's files has one today).
std::map<std::string, std::string> Tree(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = fs::relative(entry.path(), dir).string();
    if (name.rfind("shard-", 0) == 0) continue;
    std::string kept;
    std::istringstream lines(ReadFile(entry.path()));
    for (std::string line; std::getline(lines, line);) {
      if (line.find(" s wall") == std::string::npos) kept += line + "\n";
    }
    files[name] = kept;
  }
  return files;
}

// the two folders hold the same files with the same bytes
void ExpectSameTree(const fs::path& expected, const fs::path& actual) {
  const auto want = Tree(expected);
  const auto got = Tree(actual);
  std::vector<std::string> want_names, got_names;
  for (const auto& [name, bytes] : want) want_names.push_back(name);
  for (const auto& [name, bytes] : got) got_names.push_back(name);
  ASSERT_EQ(got_names, want_names);
  for (const auto& [name, bytes] : want) {
    EXPECT_TRUE(got.at(name) == bytes) << name << " differs between " << expected << " and "
                                       << actual;
  }
}

// `liftoff report ARGS -o DIR`
CommandRun Report(const std::string& args, const fs::path& dir, const ScratchDir& scratch) {
  return RunCommand(kBinary, "report " + args + " -o " + Quoted(dir), scratch);
}

// four shards through GNU parallel, four at once, into DIR
CommandRun ParallelShards(const fs::path& parallel, const std::string& args, const fs::path& dir,
                          const ScratchDir& scratch) {
  return RunCommand(parallel,
                    "--will-cite --halt now,fail=1 -j 4 " + Quoted(kBinary) + " report " + args +
                        " -o " + Quoted(dir) + " --shard {}/4 ::: 1 2 3 4",
                    scratch);
}

std::string ShardFiles(const fs::path& dir, int count) {
  std::string files;
  for (int i = 1; i <= count; ++i) {
    files += " " + Quoted(dir / ("shard-" + std::to_string(i) + "-of-" + std::to_string(count) +
                                 ".json"));
  }
  return files;
}

// One run, then four shards through GNU parallel and their merge in the same folder
// (the report names its own paths): the merge's files equal the run's.
void ExpectShardedEqualsSingle(const std::string& args, const ScratchDir& scratch) {
  const auto parallel = liftoff::testing::FindOnPath("parallel");
  if (!parallel) GTEST_SKIP() << "GNU parallel is not on the PATH (Debian: parallel)";
  const fs::path dir = scratch / "report";
  const CommandRun single = Report(args, dir, scratch);
  ASSERT_TRUE(single.code == kExitOk || single.code == ExitCodeFor(StatusCode::kParse)) << single.err;
  fs::rename(dir, scratch / "single");

  const CommandRun shards = ParallelShards(*parallel, args, dir, scratch);
  ASSERT_EQ(shards.code, 0) << shards.out << shards.err;
  const CommandRun merged = Report(args + " --merge" + ShardFiles(dir, 4), dir, scratch);
  EXPECT_EQ(merged.code, single.code) << merged.err;
  EXPECT_EQ(merged.out, single.out);
  ExpectSameTree(scratch / "single", dir);
}

TEST(ReportShards, FourShardsThroughGnuParallelEqualOneRun) {
  ScratchDir scratch;
  ExpectShardedEqualsSingle(SampleFlags(), scratch);
  if (HasFailure() || IsSkipped()) return;
  // the Monte Carlo was cut into shares: 8 draws, 2 a shard, draw k in shard k % 4 + 1
  auto shard = LoadJsonFile(scratch / "report" / "shard-3-of-4.json");
  ASSERT_TRUE(shard.ok()) << shard.status().ToString();
  EXPECT_EQ((*shard)["monte_carlo"]["draws"], nlohmann::json({2, 6}));
  EXPECT_EQ((*shard)["trials"].size(), 2u);
  EXPECT_TRUE(fs::exists(scratch / "single" / "figures" / "montecarlo.dat"));
}

// The Monte Carlo's draws and simulated values are the same in one shard and in three.
TEST(ReportShards, MonteCarloDrawsAreTheSameWhateverTheShards) {
  ScratchDir scratch;
  const fs::path dir = scratch / "shards";
  ASSERT_EQ(Report(SampleFlags() + " --shard 1/1", dir, scratch).code, kExitOk);
  for (int i = 1; i <= 3; ++i) {
    const CommandRun run = Report(SampleFlags() + " --shard " + std::to_string(i) + "/3", dir, scratch);
    ASSERT_EQ(run.code, kExitOk) << run.err;
  }
  auto whole = LoadJsonFile(dir / "shard-1-of-1.json");
  ASSERT_TRUE(whole.ok()) << whole.status().ToString();
  const nlohmann::json& all = (*whole)["monte_carlo"]["results"]["samples"];
  ASSERT_EQ(all.size(), 8u);
  std::set<size_t> seen;
  for (int i = 1; i <= 3; ++i) {
    auto part = LoadJsonFile(dir / ("shard-" + std::to_string(i) + "-of-3.json"));
    ASSERT_TRUE(part.ok()) << part.status().ToString();
    const nlohmann::json& draws = (*part)["monte_carlo"]["draws"];
    const nlohmann::json& samples = (*part)["monte_carlo"]["results"]["samples"];
    ASSERT_EQ(draws.size(), samples.size());
    for (size_t j = 0; j < draws.size(); ++j) {
      const size_t k = draws[j].get<size_t>();
      EXPECT_EQ(k % 3, static_cast<size_t>(i - 1));
      EXPECT_EQ(samples[j], all[k]) << "draw " << k << " in shard " << i << "/3";
      seen.insert(k);
    }
  }
  EXPECT_EQ(seen.size(), 8u);
}

TEST(ReportShards, ShardFlagIsChecked) {
  ScratchDir scratch;
  for (const std::string bad : {"0/4", "5/4", "a/b", "1/4x", "4", "1/0", "1/100001"}) {
    const CommandRun run =
        Report(Quoted(SourceDir() / "samples" / "trials" / "manifest.json") +
                   " --no-sim --progress off --shard " + bad,
               scratch / "out", scratch);
    EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument)) << bad;
    EXPECT_THAT(run.err, HasSubstr("--shard: expected i/n with 1 <= i <= n <= 100000, got \"" +
                                   bad + "\""));
  }
  const CommandRun both = Report(Quoted(SourceDir() / "samples" / "trials" / "manifest.json") +
                                     " --no-sim --shard 1/2 --merge x.json",
                                 scratch / "out", scratch);
  EXPECT_EQ(both.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(both.err, HasSubstr("--shard, --merge"));
  const CommandRun jobs = Report(Quoted(SourceDir() / "samples" / "trials" / "manifest.json") +
                                     " --no-sim --jobs=-1",
                                 scratch / "out", scratch);
  EXPECT_EQ(jobs.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(jobs.err, HasSubstr("--jobs: expected an integer in [0, 1024], got -1"));
  EXPECT_FALSE(fs::exists(scratch / "out"));
}

TEST(ReportShards, MergeRefusesMissingDuplicateForeignAndDamagedShards) {
  ScratchDir scratch;
  const std::string args =
      Quoted(SourceDir() / "samples" / "trials" / "manifest.json") + " --no-sim --progress off";
  const fs::path dir = scratch / "report";
  for (const char* shard : {"1/2", "2/2", "1/3"}) {
    ASSERT_EQ(Report(args + " --shard " + shard, dir, scratch).code, kExitOk) << shard;
  }
  ASSERT_EQ(Report(args + " --rule hold --shard 2/2", scratch / "other", scratch).code, kExitOk);
  fs::copy_file(dir / "shard-1-of-2.json", scratch / "copy.json");
  WriteFile(scratch / "damaged.json", "{\"format\": \"liftoff-report-shard\", \"version\": 1,");
  WriteFile(scratch / "alien.json", "{\"format\": \"liftoff-sim-cache\", \"version\": 1}");
  const std::string one = Quoted(dir / "shard-1-of-2.json");
  const std::string two = Quoted(dir / "shard-2-of-2.json");

  struct Case {
    std::string merge;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {one, ExitCodeFor(StatusCode::kInvalidArgument), "shard 2/2 missing"},
      {one + " " + Quoted(scratch / "copy.json"), ExitCodeFor(StatusCode::kInvalidArgument),
       (scratch / "copy.json").string() + " and " + (dir / "shard-1-of-2.json").string() +
           " are both shard 1/2"},
      {one + " " + Quoted(scratch / "other" / "shard-2-of-2.json"), ExitCodeFor(StatusCode::kInvalidArgument),
       (scratch / "other" / "shard-2-of-2.json").string() +
           ": made from other inputs or options"},
      {one + " " + Quoted(dir / "shard-1-of-3.json"), ExitCodeFor(StatusCode::kInvalidArgument),
       (dir / "shard-1-of-3.json").string() + " is shard 1/3 but"},
      {one + " " + Quoted(scratch / "damaged.json"), ExitCodeFor(StatusCode::kParse),
       (scratch / "damaged.json").string()},
      {one + " " + Quoted(scratch / "alien.json"), ExitCodeFor(StatusCode::kInvalidArgument),
       (scratch / "alien.json").string() + ": not a liftoff report shard"},
      {one + " " + Quoted(scratch / "missing.json"), ExitCodeFor(StatusCode::kNotFound),
       (scratch / "missing.json").string()},
  };
  for (const Case& c : cases) {
    const CommandRun run = Report(args + " --merge " + c.merge, dir, scratch);
    EXPECT_EQ(run.code, c.code) << c.merge << "\n" << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message)) << c.merge;
    EXPECT_FALSE(fs::exists(dir / "report.md")) << c.merge;
  }
  // the complete pair merges
  const CommandRun merged = Report(args + " --merge " + two + " " + one, dir, scratch);
  EXPECT_EQ(merged.code, kExitOk) << merged.err;
  EXPECT_THAT(merged.out, HasSubstr("report: 8 trials, 0 failed"));
}

// The synthetic CI set's trials with videos: nine of them (one whose video is no video),
// so the video analysis goes through the shard files.
fs::path CiSubsetManifest(const fs::path& set_dir, const ScratchDir& scratch) {
  auto document = LoadJsonFile(set_dir / "manifest.json");
  EXPECT_TRUE(document.ok()) << document.status().ToString();
  nlohmann::json manifest = *document;
  manifest["calibration"] = (SourceDir() / "calib" / "laika-2018.json").string();
  const std::set<std::string> keep = {"ci-02-h264-bframes-30fps", "ci-04-foot-d-30fps",
                                      "ci-10-vfr-drops",          "ci-11-vfr-jitter",
                                      "ci-13-motion-blur",        "ci-17-no-shadow",
                                      "ci-22-csv-curve",          "ci-23-log-2018-bursty-origin"};
  nlohmann::json trials = nlohmann::json::array();
  for (nlohmann::json trial : manifest["trials"]) {
    if (keep.count(trial["id"].get<std::string>()) == 0) continue;
    trial["log"]["path"] = (set_dir / trial["log"]["path"].get<std::string>()).string();
    trial["video"]["path"] = (set_dir / trial["video"]["path"].get<std::string>()).string();
    trials.push_back(trial);
  }
  nlohmann::json broken = trials.front();
  broken["id"] = "broken";
  broken["video"]["path"] = (set_dir / "invalid-not-a-video.mp4").string();
  trials.insert(trials.begin() + 3, broken);
  manifest["trials"] = trials;
  const fs::path path = scratch / "ci-manifest.json";
  WriteFile(path, manifest.dump(2));
  return path;
}

// the rendered CI set's folder; empty when it is not there
fs::path CiSetDir() {
  const char* kept = std::getenv("LIFTOFF_CI_SET_DIR");
  const fs::path dir = kept != nullptr && *kept != '\0' ? fs::path(kept) : fs::path(kRenderedSetDir);
  return !dir.empty() && fs::exists(dir / "manifest.json") ? dir : fs::path();
}

// A trial's outcome through a shard file and back is the same outcome: every field of
// its video analysis that `liftoff video --json` shows, its measurement, its notes; and
// written again, the same entry.
TEST(ReportShards, TrialOutcomeSurvivesTheShardFile) {
  const fs::path set_dir = CiSetDir();
  if (set_dir.empty()) GTEST_SKIP() << "the synthetic CI set is not rendered (fixture ci_set)";
  ScratchDir scratch;
  auto manifest = LoadManifest(CiSubsetManifest(set_dir, scratch));
  auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
  ASSERT_TRUE(manifest.ok() && calibration.ok());
  for (const size_t index : {size_t{1}, size_t{3}, size_t{4}}) {  // ci-04, broken, ci-11
    const sync::TrialOutcome outcome =
        sync::AnalyzeManifestTrial(*manifest, *calibration, {}, index);
    ASSERT_TRUE(outcome.video || index == 3) << outcome.status.ToString();
    const std::vector<std::string> notes = OutcomeNotes(outcome);
    const nlohmann::json entry = TrialOutcomeToJson(index, outcome, notes);
    sync::TrialOutcome back;
    back.trial = outcome.trial;
    std::vector<std::string> back_notes;
    TrialOutcomeFromJson(nlohmann::json::parse(entry.dump()), back, back_notes);
    EXPECT_EQ(TrialOutcomeToJson(index, back, back_notes), entry);
    EXPECT_EQ(back_notes, notes);
    EXPECT_EQ(OutcomeNotes(back), notes);
    EXPECT_EQ(back.status.ToString(), outcome.status.ToString());
    ASSERT_EQ(back.video.has_value(), outcome.video.has_value());
    if (outcome.video) {
      EXPECT_EQ(back.video->ToJson(), outcome.video->ToJson());
      ASSERT_TRUE(back.video->foot.has_value());
      EXPECT_EQ(back.video->foot->samples.size(), outcome.video->foot->samples.size());
      EXPECT_EQ(back.video->foot->samples.back().rise_px, outcome.video->foot->samples.back().rise_px);
    }
    ASSERT_EQ(back.measurement.has_value(), outcome.measurement.has_value());
    if (outcome.measurement) {
      EXPECT_EQ(back.measurement->liftoff_rad, outcome.measurement->liftoff_rad);
      EXPECT_EQ(back.measurement->lookup.Brief(), outcome.measurement->lookup.Brief());
    }
  }
}

TEST(ReportShards, VideoCampaignJobsAndShardsEqualOneSerialRun) {
  const fs::path set_dir = CiSetDir();
  if (set_dir.empty()) {
    GTEST_SKIP() << "the synthetic CI set is not rendered (ctest renders it: fixture ci_set)";
  }
  ScratchDir scratch;
  const std::string args = Quoted(CiSubsetManifest(set_dir, scratch)) + " --no-sim --progress off";
  // one job, then three at once: the same files
  const fs::path dir = scratch / "report";
  const CommandRun serial = Report(args + " --jobs 1", dir, scratch);
  ASSERT_EQ(serial.code, ExitCodeFor(StatusCode::kParse)) << serial.err;  // the broken trial
  EXPECT_THAT(serial.out, HasSubstr("report: 9 trials, 1 failed"));
  EXPECT_THAT(ReadFile(dir / "report.md"), HasSubstr("broken (foot B): failed: "));
  fs::rename(dir, scratch / "serial");
  const CommandRun jobs = Report(args + " --jobs 3", dir, scratch);
  EXPECT_EQ(jobs.code, serial.code) << jobs.err;
  EXPECT_EQ(jobs.out, serial.out);
  EXPECT_EQ(jobs.err, serial.err);
  ExpectSameTree(scratch / "serial", dir);
  fs::remove_all(dir);

  // four shards through GNU parallel, merged
  ExpectShardedEqualsSingle(args + " --jobs 2", scratch);
}

}  // namespace
}  // namespace liftoff::cli
