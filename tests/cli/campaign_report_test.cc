// The README's main job end to end on a small synthetic campaign: `liftoff synth --set
// campaign` renders 3D trial videos and controller logs from the simulation at a tension
// the manifest does not reveal, `liftoff report` analyses the videos, tabulates, draws and
// calibrates; the results are checked against the campaign's truth file. Skips with a
// message where headless EGL rendering is unavailable (the synth's exit code 8).
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
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using ::testing::HasSubstr;

constexpr int kExitUnsupported = 8;
// Per-trial agreement of the report's liftoff rotation (video + log) with the truth's
// rotation at the exact 1 mm instant, rad: a third of a 30 fps frame at the campaign's
// ramp (0.1496 rad/s / 30 fps = 5.0 mrad per frame).
constexpr double kTrialToleranceRad = 0.0017;

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

void ExpectValidPng(const fs::path& path) {
  const std::string bytes = ReadFile(path);
  ASSERT_GT(bytes.size(), 1000u) << path;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  EXPECT_EQ(bytes.substr(12, 4), "IHDR") << path;
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND") << path;
}

// gnuplot's SVG: an XML declaration, one <svg> element closed at the end
void ExpectValidSvg(const fs::path& path) {
  const std::string text = ReadFile(path);
  EXPECT_THAT(text, HasSubstr("<svg")) << path;
  const size_t close = text.rfind("</svg>");
  ASSERT_NE(close, std::string::npos) << path;
  EXPECT_EQ(text.find_first_not_of(" \r\n", close + 6), std::string::npos) << path;
  EXPECT_THAT(text, HasSubstr("gnuplot")) << path;
}

// the targets of every `opening`...`closing` in `text`
std::vector<std::string> Targets(const std::string& text, std::string_view opening, char closing) {
  std::vector<std::string> targets;
  for (size_t at = text.find(opening); at != std::string::npos; at = text.find(opening, at)) {
    at += opening.size();
    const size_t end = text.find(closing, at);
    if (end == std::string::npos) break;
    targets.push_back(text.substr(at, end - at));
  }
  return targets;
}

void ExpectLinksResolve(const fs::path& page, std::string_view opening, char closing) {
  const std::vector<std::string> targets = Targets(ReadFile(page), opening, closing);
  EXPECT_GE(targets.size(), 8u) << page;
  for (const std::string& target : targets) {
    if (target.rfind("data:", 0) == 0 || target.rfind("#", 0) == 0) continue;
    EXPECT_FALSE(target.rfind("http", 0) == 0) << page << " links outside: " << target;
    EXPECT_TRUE(fs::exists(page.parent_path() / target)) << page << " links to " << target;
  }
}

// "sigma +0.712 +- 0.081 (...; 95 % [0.550, 0.850])" in calibration.md
struct StatedFit {
  double sigma = NAN, stddev = NAN, low95 = NAN, high95 = NAN;
};
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
  return fit;
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
  ASSERT_EQ(truth["report_flags"], "--ramp-s 7");
  EXPECT_THAT(ReadFile(campaign / "manifest.json"), ::testing::Not(HasSubstr("campaign-truth")));

  ReportCommand command;
  command.manifest_path = campaign / "manifest.json";
  command.output_dir = scratch / "report";
  command.sweep.experiment.options.ramp_duration_s = truth["ramp_s"].get<double>();
  command.sweep.experiment.progress = "off";
  const CommandRun run = liftoff::testing::RunInProcess(RunReport, command);
  ASSERT_EQ(run.code, kExitOk) << run.out << run.err;
  std::cout << run.out;
  const fs::path& dir = command.output_dir;

  // every trial analysed from its video, its rotation the truth's to a third of a frame
  const auto records = CsvRecords(ReadFile(dir / "trials.csv"));
  ASSERT_EQ(records.size(), 12u);
  for (const nlohmann::json& trial : truth["trials"]) {
    const std::string id = trial["id"];
    SCOPED_TRACE(id);
    const auto record = std::find_if(records.begin(), records.end(),
                                     [&](const auto& r) { return r.at("id") == id; });
    ASSERT_NE(record, records.end());
    const double measured = std::stod(record->at("liftoff_rad"));
    EXPECT_NEAR(std::abs(measured), trial["theta_at_lift_1mm_rad"].get<double>(),
                kTrialToleranceRad);
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
  ExpectLinksResolve(dir / "report.md", "](", ')');
  ExpectLinksResolve(dir / "report.html", "src=\"", '"');
  ExpectLinksResolve(dir / "report.html", "href=\"", '"');

  // the calibration recovers the hidden tension within its stated uncertainty: within two
  // bootstrap standard deviations and inside the stated 95 % interval
  const StatedFit fit = ParseFit(ReadFile(dir / "calibration.md"));
  const double hidden = truth["tension_sigma"].get<double>();
  ASSERT_TRUE(std::isfinite(fit.sigma) && std::isfinite(fit.stddev)) << ReadFile(dir / "calibration.md");
  std::cout << "hidden sigma " << hidden << ", fitted " << fit.sigma << " +- " << fit.stddev
            << " (95 % [" << fit.low95 << ", " << fit.high95 << "])\n";
  EXPECT_GT(fit.stddev, 0.0);
  EXPECT_LE(std::abs(fit.sigma - hidden), 2 * fit.stddev);
  EXPECT_GE(hidden, fit.low95);
  EXPECT_LE(hidden, fit.high95);
}

}  // namespace
}  // namespace liftoff::cli
