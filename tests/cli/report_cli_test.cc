// `liftoff report` end to end on the sample trials (hand times with known answers) and a
// small simulated sweep: the table against the truth, the figures' scripts, data and
// images, the cache, the pages' links, a failing trial and an output folder holding an
// input; on a synthetic clip, each video trial's traces figure and verification image.
#include <algorithm>
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
#include "liftoff/core/time.h"
#include "support/test_support.h"
#include "video_campaign.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::ExpectLinksResolve;
using liftoff::testing::ExpectValidPng;
using liftoff::testing::ExpectValidSvg;
using liftoff::testing::LinkTargets;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::Not;

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
  // a small calibration: seven tension scales, four Monte Carlo draws
  command.fit.sigma_min = 0.0;
  command.fit.sigma_max = 3.0;
  command.fit.sigma_step = 0.5;
  command.fit.bootstrap_samples = 200;
  command.monte_carlo.samples = 4;
  return command;
}

bool GnuplotOnPath() { return liftoff::testing::FindOnPath("gnuplot").has_value(); }

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
  ExpectLinksResolve(dir / "report.html", "src=\"", '"', drawn ? 4 : 0);
  ExpectLinksResolve(dir / "report.md", "](", ')', drawn ? 12 : 8);
  const std::string html = ReadFile(dir / "report.html");
  for (const auto& [id, trial] : (*expected)["trials"].items()) EXPECT_THAT(html, HasSubstr(id));
  EXPECT_THAT(html, HasSubstr("laika-2018"));
  EXPECT_THAT(html, HasSubstr("laika.json"));
  EXPECT_THAT(html, HasSubstr("liftoff 0."));

  // the calibration: its section in both pages, calibration.md, a calibration file the
  // other commands read with the fitted point inside the searched range, its figures
  EXPECT_THAT(run.out, HasSubstr("calibration: best tension point "));
  EXPECT_THAT(run.out, HasSubstr("fitted sigma "));
  EXPECT_THAT(html, HasSubstr("<h2>Calibration</h2>"));
  EXPECT_THAT(html, HasSubstr("<h3>Tension points ranked</h3>"));
  const std::string markdown = ReadFile(dir / "report.md");
  EXPECT_THAT(markdown, HasSubstr("## Calibration"));
  const std::string section = ReadFile(dir / "calibration.md");
  for (const std::string part :
       {"# Calibration", "## Tension points ranked", "| 1 | ", "## Fitted tension scale",
        "## Monte Carlo over the spring", "4 draws (seed 2018", "chi2 = sum of z^2", "(run now)"}) {
    EXPECT_THAT(section, HasSubstr(part));
  }
  auto fitted = LoadCalibration(dir / "calibration.json");
  ASSERT_TRUE(fitted.ok()) << fitted.status().ToString();
  EXPECT_EQ(fitted->name, "laika-2018-fitted");
  const TensionPoint* point = fitted->FindTensionPoint("fitted");
  ASSERT_NE(point, nullptr);
  EXPECT_GT(point->sigma, 0.0);
  EXPECT_LT(point->sigma, 3.0);
  EXPECT_NE(point->sigma, 2.0);
  // on Table III's line: mean (0) 237 .. high (2) 258, then 10.5 N/m per sigma
  EXPECT_NEAR(
      point->silicone_n_per_m,
      point->sigma <= 2.0 ? 237.0 + 10.5 * point->sigma : 258.0 + 10.0 * (point->sigma - 2.0), 0.6);
  for (const std::string name : {"fit", "montecarlo"}) {
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".gp"))) << name;
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".dat"))) << name;
    if (GnuplotOnPath()) ExpectValidPng(dir / "figures" / (name + ".png"));
  }
  EXPECT_THAT(ReadFile(dir / "figures" / "montecarlo.dat"), HasSubstr("Monte Carlo draws"));
  EXPECT_THAT(ReadFile(dir / "figures" / "fit.dat"), HasSubstr("foot D, hardware mean"));

  // a second run takes the sweep from the cache and writes the same table
  const std::string table_before = ReadFile(dir / "table.csv");
  const std::string calibration_before = ReadFile(dir / "calibration.json");
  const CommandRun again = RunReportCommand(SampleReport(dir));
  ASSERT_EQ(again.code, kExitOk) << again.err;
  EXPECT_THAT(again.out, HasSubstr("simulation: from the cache"));
  EXPECT_EQ(ReadFile(dir / "table.csv"), table_before);
  EXPECT_THAT(ReadFile(dir / "calibration.md"), HasSubstr("(read from it)"));
  EXPECT_EQ(ReadFile(dir / "calibration.json"), calibration_before);  // seeded: the same fit

  // a fit that falls on one of the calibration's points (the grid ends at high's sigma,
  // and these trials want more tension) is that point, named in its note
  ReportCommand at_high = SampleReport(dir);
  at_high.fit.sigma_max = 2.0;
  const CommandRun at_high_run = RunReportCommand(at_high);
  ASSERT_EQ(at_high_run.code, kExitOk) << at_high_run.err;
  EXPECT_THAT(at_high_run.out, HasSubstr("fitted sigma 2.00"));
  auto on_point = LoadCalibration(dir / "calibration.json");
  ASSERT_TRUE(on_point.ok()) << on_point.status().ToString();
  EXPECT_EQ(on_point->FindTensionPoint("fitted"), nullptr);
  EXPECT_THAT(on_point->notes["/tension_points/4"], HasSubstr("falls on this point"));
  EXPECT_THAT(ReadFile(dir / "calibration.md"), HasSubstr("the fit sits at the edge"));

  // another experiment option is another cache entry
  ReportCommand other = SampleReport(dir);
  other.sweep.experiment.options.liftoff_threshold_m = 0.002;
  other.sweep.tensions = {"high"};
  const CommandRun rerun = RunReportCommand(other);
  ASSERT_EQ(rerun.code, kExitOk) << rerun.err;
  EXPECT_THAT(rerun.out, HasSubstr("ran and cached in"));
}

// the rows of a traces figure's block 0: name -> (t_s, lower_s, upper_s)
std::map<std::string, std::vector<double>> Instants(const std::string& data) {
  std::map<std::string, std::vector<double>> instants;
  std::istringstream lines(data.substr(0, data.find("\n\n")));
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name;
    double t_s = 0, lower_s = 0, upper_s = 0;
    fields >> name >> t_s >> lower_s >> upper_s;
    instants[name] = {t_s, lower_s, upper_s};
  }
  return instants;
}

TEST(CliReport, VideoTrialsGetTheirTracesAndVerificationImages) {
  ScratchDir scratch;
  const VideoCampaign campaign = WriteVideoCampaign(scratch / "campaign", 1);
  ASSERT_TRUE(campaign.error.empty()) << campaign.error;
  ReportCommand command;
  command.manifest_path = campaign.manifest_path;
  command.output_dir = scratch / "report";
  command.no_sim = true;
  command.sweep.experiment.progress = "off";
  const CommandRun run = RunReportCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("report: 3 trials, 0 failed"));
  const fs::path& dir = command.output_dir;

  // "clip/1" and "clip_1" make the same safe name: the second gets "-2"
  const synth::GroundTruth& truth = campaign.trial.truth;
  const double frame_s = SecondsFromNs(truth.frame_times_ns[1] - truth.frame_times_ns[0]);
  for (const std::string stem : {"clip_1", "clip_1-2"}) {
    SCOPED_TRACE(stem);
    const fs::path figure = dir / "figures" / ("trial-" + stem);
    ASSERT_TRUE(fs::exists(figure.string() + ".gp"));
    const std::string data = ReadFile(figure.string() + ".dat");
    // the detected instants against the renderer's truth: the LED within half a frame,
    // the 1 mm liftoff within three, each interval around its instant
    const auto instants = Instants(data);
    ASSERT_EQ(instants.count("led_on"), 1u) << data.substr(0, 600);
    ASSERT_EQ(instants.count("liftoff"), 1u);
    ASSERT_EQ(instants.count("onset"), 1u);
    EXPECT_NEAR(instants.at("led_on")[0], SecondsFromNs(*truth.led_on_video_ns), frame_s / 2);
    EXPECT_NEAR(instants.at("liftoff")[0], SecondsFromNs(*truth.liftoff_1mm_video_ns),
                3 * frame_s);
    EXPECT_LT(instants.at("onset")[0], instants.at("liftoff")[0]);
    for (const auto& [name, instant] : instants) {
      EXPECT_LE(instant[1], instant[0]) << name;
      EXPECT_GE(instant[2], instant[0]) << name;
    }
    // both traces, one row a frame
    EXPECT_THAT(data, HasSubstr("t_s brightness_levels"));
    EXPECT_THAT(data, HasSubstr("t_s height_mm"));
    EXPECT_GE(static_cast<size_t>(std::count(data.begin(), data.end(), '\n')),
              2 * truth.frame_times_ns.size());
    ExpectValidPng(dir / "trials" / (stem + ".png"));
    if (GnuplotOnPath()) {
      ExpectValidPng(figure.string() + ".png");
      ExpectValidSvg(figure.string() + ".svg");
    }
  }

  // the pages: the images linked (Markdown) and inline (HTML); the hand trial says why
  // it has none
  const std::string markdown = ReadFile(dir / "report.md");
  EXPECT_THAT(markdown, HasSubstr("verification image: [trials/clip_1.png](trials/clip_1.png)"));
  EXPECT_THAT(markdown, HasSubstr("verification image: [trials/clip_1-2.png](trials/clip_1-2.png)"));
  EXPECT_THAT(markdown, HasSubstr("no traces figure: times given by hand"));
  // the trials figure's image, script and data; each clip's traces image, script, data and
  // its verification image
  ExpectLinksResolve(dir / "report.md", "](", ')', GnuplotOnPath() ? 11 : 8);
  const std::string html = ReadFile(dir / "report.html");
  EXPECT_EQ(LinkTargets(html, "alt=\"verification image\" src=\"data:image/png;base64,", '"').size(),
            2u);
  if (GnuplotOnPath()) {
    EXPECT_EQ(LinkTargets(html, "alt=\"trial clip", '"').size(), 2u) << "both traces inline";
  } else {
    std::cout << "[  SKIPPED ] traces PNG/SVG checks: gnuplot is not on the PATH\n";
  }
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

// The 2018 hardware (hand times, the authors' hold rule) against the bundled model with the
// default calibration grid: the paper's conclusion (the highest tension agrees best) holds
// for the ranking; the fitted tension lies beyond it and the fit is poor, because feet B
// and C lift later on the hardware than at any simulated tension (docs/cli.md quotes this).
TEST(CliReport, Hardware2018RanksTheHighestTensionFirstAndSaysTheFitIsPoor) {
  LIFTOFF_REQUIRE_REFERENCE(reference);
  ScratchDir scratch;
  ReportCommand command;
  command.manifest_path = reference / "laika-2018-hardware";
  command.output_dir = scratch / "report";
  command.lookup.rule = "hold";
  command.sweep.experiment.progress = "off";
  command.monte_carlo.samples = 0;  // not part of what is checked here
  command.fit_ratio = true;         // the default ratios
  const CommandRun run = RunReportCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("calibration: best tension point high (chi2 282.7); fitted sigma "
                                 "2.50 +- 0.09 (95 % [2.25, 2.50]), +- 0.00 systematic, "
                                 "chi2/dof 90.9 (poor)"));
  // a stiffer Buna-N lattice brings feet B and C later, but not far enough
  EXPECT_THAT(run.out, HasSubstr("stiffness ratio x2.00 (68 % [1.41, 2.00]), sigma 0.00, "
                                 "chi2 89.9, 2 dof; not determined by these trials (poor)"));
  const std::string section = ReadFile(scratch / "report" / "calibration.md");
  for (const std::string part :
       {"The highest tension point, high, ranks 1 of 5.", "- A: high, med-high, mean",
        "- D: mean, med-high, high, med-low",
        "foot B: the hardware mean 0.572 rad lies above every simulated value",
        "foot C: the hardware mean 0.516 rad lies above every simulated value",
        "stiffnesses: silicone 263.0 N/m, Buna-N 1139.0 N/m", "Not run (--mc-samples 0)",
        "| 0.50 | +4.000 (edge) | 799.56 |", "| 1.00 | +2.500 | 272.75 |",
        "| 2.00 | +0.000 | 89.89 |",
        "the least chi-square lies at the end of the ratios fitted (x2.00"}) {
    EXPECT_THAT(section, HasSubstr(part));
  }
}

TEST(CliReport, RefusesBadCalibrationOptionsBeforeWritingAnything) {
  ScratchDir scratch;
  ReportCommand command = SampleReport(scratch / "report");
  command.monte_carlo.samples = -1;
  const CommandRun run = RunReportCommand(command);
  EXPECT_EQ(run.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(
      run.err,
      HasSubstr(
          "--mc-samples/--mc-sd-scale: samples: expected an integer in [0, 1000000], got -1"));
  command = SampleReport(scratch / "report");
  command.fit.sigma_step = 0.0;
  const CommandRun step = RunReportCommand(command);
  EXPECT_EQ(step.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(step.err, HasSubstr("--fit-step"));
  EXPECT_FALSE(fs::exists(scratch / "report"));
}

TEST(CliReport, FitRatioProfilesTheStiffnessRatioInCalibrationMd) {
  ScratchDir scratch;
  ReportCommand command = SampleReport(scratch / "report");
  command.fit_ratio = true;
  command.ratio.ratios = {0.5, 1.0, 2.0};
  command.monte_carlo.samples = 0;
  const CommandRun run = RunReportCommand(command);
  ASSERT_EQ(run.code, kExitOk) << run.err;
  EXPECT_THAT(run.out, HasSubstr("; stiffness ratio x"));
  const std::string markdown = ReadFile(scratch / "report" / "calibration.md");
  EXPECT_THAT(markdown, HasSubstr("# Stiffness ratio"));
  EXPECT_THAT(markdown, HasSubstr("| Buna-N x | sigma | chi2 |"));
  for (const char* row : {"| 0.50 | ", "| 1.00 | ", "| 2.00 | "}) {
    EXPECT_THAT(markdown, HasSubstr(row)) << row;
  }

  // the ratios' grids are cached beside the grid's: a second run simulates none, and one
  // more ratio is the only one simulated
  std::vector<fs::path> caches;
  for (const auto& entry : fs::directory_iterator(scratch / "report" / "sim-cache")) {
    if (entry.path().string().ends_with(".calibration.json")) caches.push_back(entry.path());
  }
  ASSERT_EQ(caches.size(), 1u);
  auto cache = LoadJsonFile(caches.front());
  ASSERT_TRUE(cache.ok()) << cache.status().ToString();
  ASSERT_EQ((*cache)["ratio_grids"].size(), 2u);
  EXPECT_EQ((*cache)["ratio_grids"][0]["ratio"], 0.5);
  EXPECT_EQ((*cache)["ratio_grids"][1]["ratio"], 2.0);
  command.sweep.experiment.progress = "lines";
  const CommandRun cached = RunReportCommand(command);
  ASSERT_EQ(cached.code, kExitOk) << cached.err;
  EXPECT_THAT(cached.err, Not(HasSubstr("stiffness ratio")));
  // (the same page but for where its runs came from)
  std::string again = ReadFile(scratch / "report" / "calibration.md");
  const std::string read = "(read from it)";
  ASSERT_NE(again.find(read), std::string::npos);
  EXPECT_EQ(again.replace(again.find(read), read.size(), "(run now)"), markdown);
  command.ratio.ratios = {0.5, 1.0, 2.0, 4.0};
  const CommandRun one_more = RunReportCommand(command);
  ASSERT_EQ(one_more.code, kExitOk) << one_more.err;
  EXPECT_THAT(one_more.err, HasSubstr("calibration: simulating the grid at 1 stiffness ratio\n"));
  EXPECT_THAT(ReadFile(scratch / "report" / "calibration.md"), HasSubstr("| 4.00 | "));
  EXPECT_THAT(ReadFile(scratch / "report" / "calibration.md"),
              HasSubstr("(read from it; the grid at 1 stiffness ratio run now)"));
  // a damaged ratio's grid costs that grid only: the grid and the Monte Carlo are kept
  cache = LoadJsonFile(caches.front());
  ASSERT_TRUE(cache.ok()) << cache.status().ToString();
  ASSERT_EQ((*cache)["ratio_grids"].size(), 3u);
  (*cache)["ratio_grids"][0]["grid"] = "damaged";
  WriteFile(caches.front(), cache->dump());
  const CommandRun mended = RunReportCommand(command);
  ASSERT_EQ(mended.code, kExitOk) << mended.err;
  EXPECT_THAT(mended.err, HasSubstr("calibration: simulating the grid at 1 stiffness ratio\n"));
  EXPECT_THAT(ReadFile(scratch / "report" / "calibration.md"), HasSubstr("(read from it; "));

  command = SampleReport(scratch / "refused");
  command.fit_ratio = true;
  command.ratio.ratios = {0.5, 2.0, 4.0};
  const CommandRun refused = RunReportCommand(command);
  EXPECT_EQ(refused.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(refused.err, HasSubstr("--ratios: ratios: expected 3 .. 100 increasing"));
  EXPECT_FALSE(fs::exists(scratch / "refused"));
  command.fit_ratio = false;
  command.ratio.ratios = {0.5, 1.0, 3.0};
  const CommandRun alone = RunReportCommand(command);
  EXPECT_EQ(alone.code, ExitCodeFor(StatusCode::kInvalidArgument));
  EXPECT_THAT(alone.err, HasSubstr("--ratios: given without --fit-ratio"));
  EXPECT_FALSE(fs::exists(scratch / "refused"));
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
