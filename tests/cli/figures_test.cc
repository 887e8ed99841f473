// The one plotting path (figures.h): figure scripts that gnuplot runs (when it is there;
// skipped with a message where it is not), the traces figure's data against a hand-made
// analysis, and the trial ids made file names.
#include "liftoff/cli/figures.h"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/cli/video_commands.h"
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

bool GnuplotOnPath() { return liftoff::testing::FindOnPath("gnuplot").has_value(); }

// gnuplot draws the figure's PNG and SVG from its script, when it is there
void ExpectDrawn(const Figure& figure, const fs::path& dir) {
  Status drawn;
  ASSERT_TRUE(WriteFigure(figure, dir, "gnuplot", drawn).ok());
  EXPECT_TRUE(fs::exists(dir / (figure.name + ".gp")));
  EXPECT_TRUE(fs::exists(dir / (figure.name + ".dat")));
  if (!GnuplotOnPath()) {
    std::cout << "[  SKIPPED ] " << figure.name << ": gnuplot is not on the PATH\n";
    return;
  }
  ASSERT_TRUE(drawn.ok()) << drawn.ToString();
  const std::string png = ReadFile(dir / (figure.name + ".png"));
  ASSERT_GT(png.size(), 1000u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(png.size() - 8, 4), "IEND");
  const std::string svg = ReadFile(dir / (figure.name + ".svg"));
  EXPECT_THAT(svg, HasSubstr("<svg"));
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  EXPECT_FALSE(fs::exists(dir / (figure.name + ".log"))) << ReadFile(dir / (figure.name + ".log"));
}

// 100 frames at 10 ms: the LED (grey 20) on at 0.305 s (frame 30 half lit, grey 120 from
// 31), the foot (2 px per mm, rest noise none) rising 0.1 px a frame from frame 60
video::ClipAnalysis HandMadeClip(bool led_traced, bool with_foot) {
  video::ClipAnalysis clip;
  clip.video_path = "/videos/clip \"one\".mp4";
  clip.led.roi_px = cv::Rect(10, 10, 8, 8);
  clip.led.pulses.push_back({});
  clip.led.pulses.back().on_ns = 305'000'000;
  clip.led.pulses.back().on_uncertainty_ns = 2'500'000;
  for (int i = 0; led_traced && i < 100; ++i) {
    clip.led.trace_t_ns.push_back(int64_t{i} * 10'000'000);
    clip.led.trace_brightness_levels.push_back(i < 30 ? 20.0 : i == 30 ? 70.0 : 120.0);
  }
  if (!with_foot) return clip;
  video::FootTrack& foot = clip.foot.emplace();
  for (int i = 0; i < 100; ++i) {
    foot.samples.push_back({.frame_index = i,
                            .t_ns = int64_t{i} * 10'000'000,
                            .rise_px = 0.5 + (i > 60 ? 0.1 * (i - 60) : 0.0)});
  }
  foot.rest_rise_px = 0.5;
  foot.px_per_mm = 2.0;
  foot.threshold_px = 2.0;  // 1 mm
  foot.onset = {.t_ns = 600'000'000, .uncertainty_ns = 15'000'000};
  foot.above_threshold = {.t_ns = 800'000'000, .uncertainty_ns = 4'000'000};
  clip.rest_from_ns = -195'000'000;
  clip.rest_to_ns = 305'000'000;
  return clip;
}

TEST(TraceFigure, DataHoldTheInstantsAndBothTracesAndGnuplotDrawsThem) {
  const auto figure = TraceFigure("trial-A1", "A1", HandMadeClip(true, true));
  ASSERT_TRUE(figure.has_value());
  // the instants with their intervals, video clock, s; the liftoff at 1 mm
  EXPECT_THAT(figure->data, HasSubstr("led_on 0.305000 0.302500 0.307500 0.0000\n"));
  EXPECT_THAT(figure->data, HasSubstr("liftoff 0.800000 0.796000 0.804000 1.0000\n"));
  EXPECT_THAT(figure->data, HasSubstr("onset 0.600000 0.585000 0.615000 0.0000\n"));
  // the traces: the half-lit frame, the foot's height above rest in mm (frame 80: 2 px)
  EXPECT_THAT(figure->data, HasSubstr("\n0.300000 70.00\n"));
  EXPECT_THAT(figure->data, HasSubstr("\n0.800000 1.0000\n"));
  EXPECT_THAT(figure->data, HasSubstr("t_s height_mm"));
  EXPECT_THAT(figure->body, HasSubstr("index 2 using 1:2"));  // the foot's block
  EXPECT_THAT(figure->body, Not(HasSubstr("clip \"one\"")));   // quotes made safe
  ScratchDir scratch;
  ExpectDrawn(*figure, scratch.path());
}

TEST(TraceFigure, WithoutTheLedTraceTheFootIsTheSecondBlock) {
  const auto figure = TraceFigure("trial-B1", "B1", HandMadeClip(false, true));
  ASSERT_TRUE(figure.has_value());
  EXPECT_THAT(figure->data, Not(HasSubstr("brightness_levels\n")));
  EXPECT_THAT(figure->body, HasSubstr("index 1 using 1:2"));
  EXPECT_THAT(figure->body, HasSubstr("layout 1,1"));
  EXPECT_THAT(figure->body, HasSubstr("LED located automatically"));
  ScratchDir scratch;
  ExpectDrawn(*figure, scratch.path());
  // the LED alone, traced: one panel; neither trace: no figure
  const auto led_only = TraceFigure("trial-C1", "C1", HandMadeClip(true, false));
  ASSERT_TRUE(led_only.has_value());
  EXPECT_THAT(led_only->data, Not(HasSubstr("liftoff ")));
  ExpectDrawn(*led_only, scratch.path());
  EXPECT_FALSE(TraceFigure("trial-D1", "D1", HandMadeClip(false, false)).has_value());
}

TEST(TrialsFigure, DrawsTrialsAndTheSimulationEvenFromASummaryAlone) {
  // A"1 with its interval, A2 without a value (left out), B1 without an interval
  std::vector<stats::TrialValue> values(3);
  values[0].trial_id = "A\"1";
  values[0].liftoff_rad = 0.5;
  values[0].lower_rad = 0.49;
  values[0].upper_rad = 0.51;
  values[1].trial_id = "A2";
  values[2].trial_id = "B1";
  values[2].foot = Foot::kB;
  values[2].liftoff_rad = 0.4;
  stats::SimResults sim;
  stats::SimRun& run = sim.runs.emplace_back();
  run.foot = Foot::kA;
  run.tension_point = "high";
  run.liftoff_rad = 0.45;
  sim.ranges[Foot::kB] = {.min_rad = 0.3, .max_rad = 0.35, .from_summary = true};
  const Figure figure = TrialsFigure("plot", values, &sim);
  EXPECT_THAT(figure.data, HasSubstr("0 0.5 0.49 0.51 \"A'1\" A\n"));
  EXPECT_THAT(figure.data, Not(HasSubstr("\"A2\"")));
  EXPECT_THAT(figure.data, HasSubstr("2 0.4 0.4 0.4 \"B1\" B\n"));
  EXPECT_THAT(figure.data, HasSubstr("-0.4 0.4 0.45 \"high\"\n"));
  EXPECT_THAT(figure.data, HasSubstr("1.6 2.4 0.3 \"min\"\n"));
  EXPECT_THAT(figure.data, HasSubstr("1.6 2.4 0.35 \"max\"\n"));
  EXPECT_THAT(figure.body, HasSubstr("\"plot.dat\""));
  ScratchDir scratch;
  ExpectDrawn(figure, scratch.path());
}

TEST(DrawFigure, AMissingProgramIsNotFoundNamingThePackage) {
  ScratchDir scratch;
  Status drawn;
  const Figure figure = TrialsFigure("plot", {}, nullptr);
  ASSERT_TRUE(WriteFigure(figure, scratch.path(), (scratch / "no-gnuplot").string(), drawn).ok());
  EXPECT_EQ(drawn.code(), StatusCode::kNotFound);
  EXPECT_THAT(drawn.message(), HasSubstr("gnuplot-nox"));
  EXPECT_TRUE(fs::exists(scratch / "plot.gp"));
}

TEST(TrialFileStems, SafeAndUniqueEvenIgnoringCase) {
  EXPECT_THAT(TrialFileStems({"A1", "clip/1", "clip_1", "a1", ".hidden", "", "clip_1-2", "x y"}),
              ElementsAre("A1", "clip_1", "clip_1-2", "a1-2", "_hidden", "trial", "clip_1-2-2",
                          "x_y"));
}

}  // namespace
}  // namespace liftoff::cli
