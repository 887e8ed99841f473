// The README's main job end to end on a small synthetic campaign: `liftoff synth --set
// campaign` renders 3D trial videos and controller logs from the simulation at a tension
// the manifest does not reveal, `liftoff report` analyses the videos, tabulates, draws and
// calibrates; the results are checked against the campaign's truth file. Skips with a
// message where headless EGL rendering is unavailable (the synth's exit code 8).
#include <algorithm>
#include <cmath>
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
#include "liftoff/core/manifest.h"
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ExpectLinksResolve;
using liftoff::testing::ExpectValidPng;
using liftoff::testing::ExpectValidSvg;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using ::testing::HasSubstr;

constexpr int kExitUnsupported = 8;
// Per-trial agreement of the report's liftoff rotation (video + log) with the truth's
// rotation at the exact 1 mm instant, rad: two 30 fps frames at the campaign's ramp
// (0.1496 rad/s / 30 fps = 5.0 mrad a frame). Measured on 20- and 12-trial campaigns: the
// video's instant is 10-28 ms early on this fast rise, -8 .. +2 mrad, with an occasional
// trial whose foot is not found (left out by the report) or found far off with a wide
// interval.
constexpr double kTrialToleranceRad = 0.010;

// the trials.csv rows as maps from the header's names
std::vector<std::map<std::string, std::string>> CsvRecords(const std::string& text) {
  std::vector<std::map<std::string, std::string>> records;
  std::istringstream lines(text);
  std::vector<std::string> header;
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
    if (header.empty()) {
      header = fields;
      continue;
    }
    std::map<std::string, std::string>& record = records.emplace_back();
    for (size_t i = 0; i < header.size() && i < fields.size(); ++i) record[header[i]] = fields[i];
  }
  return records;
}

// What calibration.md states ("- sigma +0.712 +- 0.081 (...; 95 % [0.550, 0.850])", then
// "- systematic +- ..."): the fit, its bootstrap (standard deviation, 95 %), its
// systematic term (a bias the trials share) and the two together.
struct StatedFit {
  double sigma = NAN, stddev = NAN, low95 = NAN, high95 = NAN, systematic = NAN, total = NAN;
};
// The number after `label` in `text`; NaN when absent.
double NumberAfter(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  if (at == std::string::npos) return NAN;
  std::istringstream in(text.substr(at + label.size()));
  double value = NAN;
  in >> value;
  return value;
}
StatedFit ParseFit(const std::string& calibration_md) {
  StatedFit fit;
  const size_t at = calibration_md.find("- sigma ");
  if (at == std::string::npos) return fit;
  std::istringstream in(calibration_md.substr(at + 8));
  std::string plus_minus;
  in >> fit.sigma >> plus_minus >> fit.stddev;
  const size_t interval = calibration_md.find("95 % [", at);
  if (interval == std::string::npos) return fit;
  std::istringstream bounds(calibration_md.substr(interval + 6));
  char comma = 0;
  bounds >> fit.low95 >> comma >> fit.high95;
  fit.systematic = NumberAfter(calibration_md, "- systematic +- ");
  fit.total = NumberAfter(calibration_md, "with the bootstrap, +- ");
  return fit;
}

// The campaign's manifest with the truth's exact LED and 1 mm instants as hand times and no
// videos: the report's chain without the video detector.
fs::path TruthTimesManifest(const fs::path& campaign, const nlohmann::json& truth) {
  auto manifest = LoadManifest(campaign / "manifest.json");
  EXPECT_TRUE(manifest.ok()) << manifest.status().ToString();
  for (TrialRecord& trial : manifest->trials) {
    for (const nlohmann::json& answer : truth["trials"]) {
      if (answer["id"] != trial.id) continue;
      EventTimes times;
      times.led_on_ns = std::llround(answer["t_led_on"].get<double>() * 1e9);
      times.liftoff_ns = std::llround(answer["t_lift_1mm"].get<double>() * 1e9);
      times.led_on_uncertainty_ns = times.liftoff_uncertainty_ns = 1'000'000;
      times.source = "synthetic (campaign truth)";
      trial.times = times;
    }
    trial.video_path.reset();
  }
  const fs::path path = campaign / "manifest-truth-times.json";
  EXPECT_TRUE(WriteManifest(path, *manifest).ok());
  return path;
}

// Recovered within the stated uncertainty: within two of its total standard deviations
// (bootstrap and systematic), and inside the bootstrap's 95 % interval widened by two
// systematic ones.
void ExpectRecovered(const StatedFit& fit, double hidden) {
  ASSERT_TRUE(std::isfinite(fit.sigma) && std::isfinite(fit.stddev) &&
              std::isfinite(fit.systematic) && std::isfinite(fit.total));
  EXPECT_GT(fit.stddev, 0.0);
  EXPECT_NEAR(fit.total, std::hypot(fit.stddev, fit.systematic), 0.002);
  EXPECT_LE(std::abs(fit.sigma - hidden), 2 * fit.total)
      << "fitted " << fit.sigma << " +- " << fit.total << ", hidden " << hidden;
  EXPECT_GE(hidden, fit.low95 - 2 * fit.systematic);
  EXPECT_LE(hidden, fit.high95 + 2 * fit.systematic);
}

TEST(CampaignReport, VideosToTableFiguresPagesAndTheHiddenTension) {
  ScratchDir scratch;
  const fs::path campaign = scratch / "campaign";
  const CommandRun synth =
      liftoff::testing::RunCommand(LIFTOFF_BINARY,
                                   "synth --set campaign --per-foot 3 -q -o " + Quoted(campaign),
                                   scratch);
  if (synth.code == kExitUnsupported) {
    GTEST_SKIP() << "no headless 3D rendering here (liftoff synth exit 8): " << synth.err;
  }
  ASSERT_EQ(synth.code, 0) << synth.err;
  const nlohmann::json truth = nlohmann::json::parse(ReadFile(campaign / "campaign-truth.json"));
  ASSERT_EQ(truth["trials"].size(), 12u);
  EXPECT_EQ(truth["report_flags"], "--ramp-s 7");
  EXPECT_THAT(ReadFile(campaign / "manifest.json"), ::testing::Not(HasSubstr("campaign-truth")));

  ReportCommand command;
  command.manifest_path = campaign / "manifest.json";
  command.output_dir = scratch / "report";
  command.sweep.experiment.options.ramp_duration_s = truth["ramp_s"].get<double>();
  command.sweep.experiment.progress = "off";
  const CommandRun run = liftoff::testing::RunInProcess(RunReport, command);
  // a trial whose video analysis fails is reported and left out (exit code its error's);
  // on this campaign the foot tracker loses 2 of the 12 (B1, D3: "the foot never lifts",
  // the robot's moving shadow filling the margin its ground is taken from)
  if (run.code != kExitOk) {
    ASSERT_THAT(run.err, ::testing::ContainsRegex("liftoff: [12] of 12 trials failed; the report "
                                                  "holds the others"))
        << run.out << run.err;
  }
  std::cout << run.out;
  const fs::path& dir = command.output_dir;

  // the trials analysed from their videos (at most two of twelve left out), each within two
  // frames' rotation of the truth or with the truth inside its reported interval
  const auto records = CsvRecords(ReadFile(dir / "trials.csv"));
  EXPECT_GE(records.size(), 10u);
  for (const nlohmann::json& trial : truth["trials"]) {
    const std::string id = trial["id"];
    SCOPED_TRACE(id);
    const auto record = std::find_if(records.begin(), records.end(),
                                     [&](const auto& r) { return r.at("trial_id") == id; });
    if (record == records.end()) {
      EXPECT_THAT(run.err, HasSubstr("error: not found: " + id + ": ")) << "missing without a reason";
      continue;
    }
    const double measured = std::stod(record->at("liftoff_rad"));
    const double lower = std::stod(record->at("lower_rad")), upper = std::stod(record->at("upper_rad"));
    const double expected = trial["theta_at_lift_1mm_rad"].get<double>();
    std::cout << id << ": " << measured << " rad [" << lower << ", " << upper << "], truth " << expected
              << ", error " << (measured - expected) * 1e3 << " mrad\n";
    EXPECT_TRUE(std::abs(measured - expected) <= kTrialToleranceRad ||
                (expected >= lower && expected <= upper))
        << measured << " [" << lower << ", " << upper << "] against the truth's " << expected;
  }

  // the figures: script, data and, with gnuplot, a valid PNG and SVG each
  for (const std::string name : {"trials", "figure7", "fit", "montecarlo"}) {
    SCOPED_TRACE(name);
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".gp")));
    EXPECT_TRUE(fs::exists(dir / "figures" / (name + ".dat")));
    if (liftoff::testing::FindOnPath("gnuplot")) {
      ExpectValidPng(dir / "figures" / (name + ".png"));
      ExpectValidSvg(dir / "figures" / (name + ".svg"));
    }
  }
  if (!liftoff::testing::FindOnPath("gnuplot")) {
    std::cout << "[  SKIPPED ] PNG/SVG checks: gnuplot is not on the PATH\n";
  }

  // the pages' links resolve
  // (the Markdown links its figures, their scripts and data; the page inlines its figures)
  ExpectLinksResolve(dir / "report.md", "](", ')', 8);
  ExpectLinksResolve(dir / "report.html", "src=\"", '"', 4);
  ExpectLinksResolve(dir / "report.html", "href=\"", '"', 0);

  // the calibration recovers the hidden tension within its stated uncertainty: within two
  // bootstrap standard deviations and inside the stated 95 % interval; first from the
  // truth's instants (the chain without the video detector: the logs, the simulation at the
  // same ramp, the fit), then from the videos
  const double hidden = truth["tension_sigma"].get<double>();
  ReportCommand exact = command;
  exact.manifest_path = TruthTimesManifest(campaign, truth);
  exact.output_dir = scratch / "report-truth-times";
  exact.cache_dir = dir / "sim-cache";
  const CommandRun exact_run = liftoff::testing::RunInProcess(RunReport, exact);
  ASSERT_EQ(exact_run.code, kExitOk) << exact_run.out << exact_run.err;
  const StatedFit from_truth = ParseFit(ReadFile(exact.output_dir / "calibration.md"));
  std::cout << "hidden sigma " << hidden << "; from the truth's instants " << from_truth.sigma
            << " +- " << from_truth.stddev << " (95 % [" << from_truth.low95 << ", "
            << from_truth.high95 << "]) +- " << from_truth.systematic << " systematic\n";
  {
    SCOPED_TRACE("from the truth's instants");
    ExpectRecovered(from_truth, hidden);
  }
  const StatedFit from_videos = ParseFit(ReadFile(dir / "calibration.md"));
  std::cout << "from the videos " << from_videos.sigma << " +- " << from_videos.stddev
            << " (95 % [" << from_videos.low95 << ", " << from_videos.high95 << "]) +- "
            << from_videos.systematic << " systematic, " << from_videos.total << " in all\n";
  {
    SCOPED_TRACE("from the videos");
    ExpectRecovered(from_videos, hidden);
  }
}

}  // namespace
}  // namespace liftoff::cli
