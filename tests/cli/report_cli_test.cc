// `liftoff report` end to end on the sample trials (hand times with known answers) and a
// small simulated sweep: the table against the truth, the figures' scripts, data and
// images, the cache, the pages' links, a failing trial and an output folder holding an
// input.
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/cli/report_command.h"
#include "liftoff/core/json.h"
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

CommandRun RunReportCommand(const ReportCommand& command) {
  return liftoff::testing::RunInProcess(RunReport, command);
}

// the sample trials with a small sweep: two tension points at which every foot's test
// stands (about a second on two cores)
ReportCommand SampleReport(const fs::path& dir) {
  ReportCommand command;
  command.manifest_path = SourceDir() / "samples" / "trials" / "manifest.json";
  command.output_dir = dir;
  command.sweep.tensions = {"mean", "high"};
  command.sweep.experiment.progress = "off";
  return command;
}

bool GnuplotOnPath() {
  std::istringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string folder; std::getline(path, folder, ':');) {
    if (!folder.empty() && fs::exists(fs::path(folder) / "gnuplot")) return true;
  }
  return false;
}

// CSV rows (no quoting in these files' numeric rows), the header first
std::vector<std::vector<std::string>> CsvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
    rows.push_back(fields);
  }
  return rows;
}

void ExpectValidPng(const fs::path& path) {
  const std::string bytes = ReadFile(path);
  ASSERT_GT(bytes.size(), 1000u) << path;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  EXPECT_EQ(bytes.substr(12, 4), "IHDR") << path;
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND") << path;
}

void ExpectValidSvg(const fs::path& path) {
  const std::string text = ReadFile(path);
  EXPECT_THAT(text, HasSubstr("<svg")) << path;
  EXPECT_THAT(text, HasSubstr("</svg>")) << path;
}

// the targets of `opening`...`closing` in `text` (std::regex recurses per character: the
// inlined images would overflow its stack)
std::vector<std::string> Targets(const std::string& text, std::string_view opening,
                                 char closing) {
  std::vector<std::string> targets;
  for (size_t at = text.find(opening); at != std::string::npos; at = text.find(opening, at)) {
    at += opening.size();
    const size_t end = text.find(closing, at);
    if (end == std::string::npos) break;
    targets.push_back(text.substr(at, end - at));
  }
  return targets;
}

// every link of a page: inline data, or a file that exists beside the page
void ExpectLinksResolve(const fs::path& page, std::string_view opening, char closing,
                        size_t at_least) {
  const std::vector<std::string> targets = Targets(ReadFile(page), opening, closing);
  EXPECT_GE(targets.size(), at_least) << page;
  for (const std::string& target : targets) {
    if (target.rfind("data:", 0) == 0) continue;
    EXPECT_TRUE(fs::exists(page.parent_path() / target)) << page << " links to " << target;
  }
}

TEST(CliReport, SampleCampaignTableFiguresAndPages) {
  ScratchDir scratch;
  const fs::path dir = scratch / "report";
  const CommandRun run = RunReportCommand(SampleReport(dir));
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("report: 8 trials, 0 failed"));
  EXPECT_THAT(run.out, HasSubstr("ran and cached in"));

  // every trial's value against the generator's truth, inside its interval
  auto expected = LoadJsonFile(SourceDir() / "samples" / "trials" / "expected.json");
  ASSERT_TRUE(expected.ok()) << expected.status().ToString();
  const auto trials = CsvRows(ReadFile(dir / "trials.csv"));
  ASSERT_EQ(trials.size(), 9u);  // header + 8
  for (size_t i = 1; i < trials.size(); ++i) {
    const std::string& id = trials[i][0];
    const double truth = (*expected)["trials"][id]["liftoff_rad"];
    EXPECT_NEAR(std::stod(trials[i][2]), truth, 2e-3) << id;
    EXPECT_LE(std::stod(trials[i][3]), truth + 1e-3) << id;
    EXPECT_GE(std::stod(trials[i][4]), truth - 1e-3) << id;
  }

  // the per-foot table: two trials a foot, mean of the truths, both simulated values
  std::map<std::string, std::vector<double>> truths;
  for (const auto& [id, trial] : (*expected)["trials"].items()) {
    truths[trial["foot"].get<std::string>()].push_back(trial["liftoff_rad"].get<double>());
  }
  const auto feet = CsvRows(ReadFile(dir / "table.csv"));
  ASSERT_EQ(feet.size(), 5u);  // header + A..D
  ASSERT_EQ(feet[0][1], "sim_min_rad");
  for (size_t i = 1; i < feet.size(); ++i) {
    const std::vector<double>& foot_truths = truths[feet[i][0]];
    ASSERT_EQ(foot_truths.size(), 2u) << feet[i][0];
    EXPECT_EQ(feet[i][6], "2") << feet[i][0];
    EXPECT_NEAR(std::stod(feet[i][7]), (foot_truths[0] + foot_truths[1]) / 2, 2e-3) << feet[i][0];
    EXPECT_EQ(feet[i][3], "2") << feet[i][0] << ": both tension points simulated";
    EXPECT_LE(std::stod(feet[i][1]), std::stod(feet[i][2])) << feet[i][0];
  }

  // each figure's script and data beside it; images when gnuplot is there
  for (const std::string name : {"trials", "figure7"}) {
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".gp"))) << name;
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".dat"))) << name;
  }
  EXPECT_THAT(ReadFile(dir / "figures" / "figure7.dat"), HasSubstr("foot D, tension high"));
  if (GnuplotOnPath()) {
    for (const std::string name : {"trials", "figure7"}) {
      ExpectValidPng(dir / "figures" / (name + ".png"));
      ExpectValidSvg(dir / "figures" / (name + ".svg"));
    }
    EXPECT_THAT(ReadFile(dir / "report.html"), HasSubstr("data:image/png;base64,iVBORw0KGgo"));
  } else {
    std::cout << "[  SKIPPED ] PNG/SVG checks: gnuplot is not on the PATH\n";
  }

  // the pages: links resolve, every trial listed, provenance named
  const bool drawn = GnuplotOnPath();
  ExpectLinksResolve(dir / "report.html", "src=\"", '"', drawn ? 2 : 0);
  ExpectLinksResolve(dir / "report.md", "](", ')', drawn ? 6 : 4);
  const std::string html = ReadFile(dir / "report.html");
  for (const auto& [id, trial] : (*expected)["trials"].items()) EXPECT_THAT(html, HasSubstr(id));
  EXPECT_THAT(html, HasSubstr("laika-2018"));
  EXPECT_THAT(html, HasSubstr("laika.json"));
  EXPECT_THAT(html, HasSubstr("liftoff 0."));

  // a second run takes the sweep from the cache and writes the same table
  const std::string table_before = ReadFile(dir / "table.csv");
  const CommandRun again = RunReportCommand(SampleReport(dir));
  ASSERT_EQ(again.code, kExitOk) << again.err;
  EXPECT_THAT(again.out, HasSubstr("simulation: from the cache"));
  EXPECT_EQ(ReadFile(dir / "table.csv"), table_before);

  // another experiment option is another cache entry
  ReportCommand other = SampleReport(dir);
  other.sweep.experiment.options.liftoff_threshold_m = 0.002;
  other.sweep.tensions = {"high"};
  const CommandRun rerun = RunReportCommand(other);
  ASSERT_EQ(rerun.code, kExitOk) << rerun.err;
  EXPECT_THAT(rerun.out, HasSubstr("ran and cached in"));
}

TEST(CliReport, FailingTrialIsReportedAndLeftOut) {
  ScratchDir scratch;
  const fs::path samples = SourceDir() / "samples" / "trials";
  auto manifest = LoadJsonFile(samples / "manifest.json");
  ASSERT_TRUE(manifest.ok());
  for (auto& trial : (*manifest)["trials"]) {
    const std::string log = trial["log"]["path"];
    trial["log"]["path"] = (samples / log).string();
  }
  (*manifest)["trials"][1]["log"]["path"] = (scratch / "missing.csv").string();
  WriteFile(scratch / "manifest.json", manifest->dump(2));
  ReportCommand command;
  command.manifest_path = scratch / "manifest.json";
  command.output_dir = scratch / "report";
  command.no_sim = true;
  command.gnuplot = (scratch / "no-gnuplot").string();
  const CommandRun run = RunReportCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kNotFound)) << run.err;
  EXPECT_THAT(run.out, HasSubstr("report: 8 trials, 1 failed"));
  EXPECT_THAT(run.out, HasSubstr("figures: not drawn"));
  const std::string markdown = ReadFile(scratch / "report" / "report.md");
  EXPECT_THAT(markdown, HasSubstr("A2 (foot A): failed: "));
  EXPECT_THAT(markdown, HasSubstr("missing.csv"));
  EXPECT_THAT(markdown, HasSubstr("A1 (foot A): ok: "));
  EXPECT_EQ(CsvRows(ReadFile(scratch / "report" / "trials.csv")).size(), 8u);  // header + 7
  // without gnuplot: the scripts and data, no images, and the pages still resolve
  EXPECT_TRUE(fs::exists(scratch / "report" / "figures" / "trials.gp"));
  EXPECT_TRUE(fs::exists(scratch / "report" / "figures" / "trials.dat"));
  EXPECT_FALSE(fs::exists(scratch / "report" / "figures" / "trials.png"));
  ExpectLinksResolve(scratch / "report" / "report.html", "src=\"", '"', 0);
  ExpectLinksResolve(scratch / "report" / "report.md", "](", ')', 2);
}

TEST(CliReport, RefusesAnOutputFolderHoldingAnInput) {
  ScratchDir scratch;
  const fs::path samples = SourceDir() / "samples" / "trials";
  fs::copy(samples, scratch / "trials", fs::copy_options::recursive);
  const std::string manifest_before = ReadFile(scratch / "trials" / "manifest.json");
  ReportCommand command;
  command.manifest_path = scratch / "trials" / "manifest.json";
  command.output_dir = scratch / "trials";
  command.no_sim = true;
  const CommandRun run = RunReportCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(run.err, HasSubstr("--output: "));
  EXPECT_THAT(run.err, HasSubstr("holds the manifest"));
  EXPECT_FALSE(fs::exists(scratch / "trials" / "report.html"));
  EXPECT_EQ(ReadFile(scratch / "trials" / "manifest.json"), manifest_before);
}

}  // namespace
}  // namespace liftoff::cli
