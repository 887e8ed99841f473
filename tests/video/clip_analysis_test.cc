// The one-clip pipeline, its proof images and `liftoff video`, on small clips rendered by
// synth (once per test binary) and judged against the renderer's ground truth.
#include "liftoff/video/clip_analysis.h"

#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/core/time.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "liftoff/video/verification.h"
#include "support/short_clip.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

// The tests' short clip (support/short_clip.h): the LED on at 0.61 s, foot A's 1 mm at
// about 2.05 s, 2.4 s long.
synth::TrialSpec BaseSpec() { return liftoff::testing::ShortClipSpec("clip-base"); }

// The same with the LED on 0.11 s after the recording began: 7 frames before it (the LED
// detector needs a few dark frames to see a step).
synth::TrialSpec EarlyLedSpec() {
  synth::TrialSpec spec = BaseSpec();
  spec.id = "clip-early-led";
  spec.seed = 78;
  spec.led.on_video_s = 0.11;
  spec.duration_s = 1.9;
  return spec;
}

struct Clips {
  std::unique_ptr<ScratchDir> scratch;
  synth::WrittenTrial base, early_led;
  std::filesystem::path not_a_video;
  std::string error;
};

// rendered once per test binary
const Clips& RenderedClips() {
  static Clips clips;
  static std::once_flag once;
  std::call_once(once, [] {
    clips.scratch = std::make_unique<ScratchDir>();
    auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
    if (!calibration.ok()) {
      clips.error = calibration.status().ToString();
      return;
    }
    for (auto [spec, written] :
         {std::pair{BaseSpec(), &clips.base}, std::pair{EarlyLedSpec(), &clips.early_led}}) {
      auto trial = synth::WriteTrial(spec, *calibration, clips.scratch->path());
      if (!trial.ok()) {
        clips.error = trial.status().ToString();
        return;
      }
      *written = std::move(trial).value();
    }
    clips.not_a_video = *clips.scratch / "notes.mp4";
    WriteFile(clips.not_a_video, "this is a text file, not a video\n");
  });
  return clips;
}

#define LIFTOFF_REQUIRE_CLIPS(clips)    \
  const Clips& clips = RenderedClips(); \
  ASSERT_TRUE(clips.error.empty()) << clips.error

// the trial's regions and scale as analysis options
ClipAnalysisOptions OptionsFor(const synth::WrittenTrial& trial) {
  ClipAnalysisOptions options;
  options.led.roi_px = RectFromRegion(trial.truth.led_roi_px);
  options.foot.foot_roi_px = RectFromRegion(trial.truth.foot_roi_px);
  options.foot.tape_colour = trial.truth.foot;
  options.foot.px_per_mm = trial.truth.px_per_mm;
  return options;
}

int64_t FrameIntervalNs(const synth::GroundTruth& truth) {
  return truth.frame_times_ns[1] - truth.frame_times_ns[0];
}

std::string RectFlag(const RegionPx& region) {
  return std::to_string(region.x_px) + "," + std::to_string(region.y_px) + "," +
         std::to_string(region.width_px) + "," + std::to_string(region.height_px);
}

// Every frame at the file's time; the last frames of this H.264 file (B-frames) read 0 ms
// and are extrapolated by the reader, so those are only near theirs.
void ExpectTruthTimes(const ClipAnalysis& analysis, const synth::GroundTruth& truth) {
  std::vector<bool> repaired(truth.frame_times_ns.size(), false);
  for (const TimingIrregularity& irregularity : analysis.timing.irregularities) {
    if (irregularity.kind == TimingIrregularity::Kind::kRepaired) {
      repaired.at(static_cast<size_t>(irregularity.frame_index)) = true;
    }
  }
  for (size_t i = 0; i < truth.frame_times_ns.size(); ++i) {
    const int64_t found_ns = analysis.foot->samples[i].t_ns;
    if (repaired[i]) {
      EXPECT_NEAR(static_cast<double>(found_ns), static_cast<double>(truth.frame_times_ns[i]),
                  0.1 * static_cast<double>(FrameIntervalNs(truth)))
          << "frame " << i;
    } else {
      EXPECT_EQ(found_ns, truth.frame_times_ns[i]) << "frame " << i;
    }
  }
}

CommandRun RunBinary(const std::string& arguments, const ScratchDir& scratch) {
  return liftoff::testing::RunCommand(LIFTOFF_BINARY, arguments, scratch);
}

// ---------------------------------------------------------------------------------------
// options

TEST(ClipAnalysisOptions, DefaultsAreValidAndBadValuesNameTheirField) {
  EXPECT_TRUE(ClipAnalysisOptions{}.Validate().ok());
  ClipAnalysisOptions options;
  options.rest_from_led_s = 0.2;
  options.rest_to_led_s = 0.1;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(options.Validate().message(), HasSubstr("rest_to_led_s"));
  options = {};
  options.rest_from_led_s = -61.0;
  EXPECT_THAT(options.Validate().message(),
              HasSubstr("rest_from_led_s: expected a number in [-60, 60]"));
  options = {};
  options.queue_frames = 17;
  EXPECT_THAT(options.Validate().message(), HasSubstr("queue_frames"));
  options = {};
  options.rest_min_frames = 0;
  EXPECT_THAT(options.Validate().message(), HasSubstr("rest_min_frames"));
  options = {};
  options.led.threshold_frac = 1.5;
  EXPECT_THAT(options.Validate().message(), HasSubstr("led: "));
}

TEST(LiftoffInstant, NamesRoundTrip) {
  for (const LiftoffInstant instant : {LiftoffInstant::kThreshold, LiftoffInstant::kOnset}) {
    EXPECT_EQ(ParseLiftoffInstant(LiftoffInstantName(instant)), instant);
  }
  EXPECT_FALSE(ParseLiftoffInstant("knee").has_value());
}

// ---------------------------------------------------------------------------------------
// the pass

TEST(AnalyzeClip, FindsTheLedAndTheLiftoffOfARenderedClip) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  const synth::GroundTruth& truth = clips.base.truth;
  auto analysis = AnalyzeClip(clips.base.video_path, OptionsFor(clips.base));
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();

  // every frame, with the file's times
  EXPECT_EQ(analysis->timing.frames, static_cast<int64_t>(truth.frame_times_ns.size()));
  EXPECT_EQ(analysis->width_px, 640);
  EXPECT_EQ(analysis->height_px, 480);
  ASSERT_TRUE(analysis->foot.has_value());
  ASSERT_EQ(analysis->foot->samples.size(), truth.frame_times_ns.size());
  ExpectTruthTimes(*analysis, truth);

  // the LED within half a frame, the 1 mm liftoff within three frames
  const int64_t frame_ns = FrameIntervalNs(truth);
  ASSERT_FALSE(analysis->led.pulses.empty());
  EXPECT_LE(std::abs(analysis->led_on().on_ns - *truth.led_on_video_ns), frame_ns / 2);
  EXPECT_EQ(analysis->led_on().first_lit_frame, *truth.led_first_frame);
  const TimedEvent* liftoff = analysis->liftoff();
  ASSERT_NE(liftoff, nullptr);
  EXPECT_LE(std::abs(liftoff->t_ns - *truth.liftoff_1mm_video_ns), 3 * frame_ns)
      << "liftoff at " << FormatSeconds(liftoff->t_ns, 4) << " s, truth "
      << FormatSeconds(*truth.liftoff_1mm_video_ns, 4) << " s";
  EXPECT_NEAR(analysis->foot->px_per_mm, truth.px_per_mm, 1e-9);
  EXPECT_NEAR(analysis->foot->threshold_px, truth.px_per_mm, 1e-6);  // 1 mm

  // the rest window: the 0.5 s before the LED (30 frames at 60 fps)
  EXPECT_EQ(analysis->rest_to_ns, analysis->led_on().on_ns);
  EXPECT_EQ(analysis->rest_from_ns, analysis->led_on().on_ns - NsFromSeconds(0.5));
  int64_t in_window = 0;
  for (const int64_t t_ns : truth.frame_times_ns) {
    if (t_ns >= analysis->rest_from_ns && t_ns < analysis->rest_to_ns) ++in_window;
  }
  EXPECT_EQ(analysis->rest_frames, in_window);
  EXPECT_GE(in_window, 29);
}

TEST(AnalyzeClip, DecodingOnASecondThreadGivesTheSameAnswer) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ClipAnalysisOptions threaded = OptionsFor(clips.base);
  threaded.queue_frames = 2;
  ClipAnalysisOptions inline_options = OptionsFor(clips.base);
  inline_options.queue_frames = 0;
  auto a = AnalyzeClip(clips.base.video_path, threaded);
  auto b = AnalyzeClip(clips.base.video_path, inline_options);
  ASSERT_TRUE(a.ok()) << a.status().ToString();
  ASSERT_TRUE(b.ok()) << b.status().ToString();
  EXPECT_EQ(a->led_on().on_ns, b->led_on().on_ns);
  EXPECT_EQ(a->liftoff()->t_ns, b->liftoff()->t_ns);
  EXPECT_EQ(a->foot->onset.t_ns, b->foot->onset.t_ns);
  ASSERT_EQ(a->foot->samples.size(), b->foot->samples.size());
  for (size_t i = 0; i < a->foot->samples.size(); ++i) {
    EXPECT_EQ(a->foot->samples[i].rise_px, b->foot->samples[i].rise_px) << "frame " << i;
  }
}

TEST(AnalyzeClip, ReportsProgressAfterEveryFrame) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  const std::vector<int64_t>& times = clips.base.truth.frame_times_ns;
  std::vector<std::pair<int64_t, int64_t>> calls;
  auto analysis =
      AnalyzeClip(clips.base.video_path, OptionsFor(clips.base),
                  [&](int64_t frames, int64_t t_ns) { calls.emplace_back(frames, t_ns); });
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  ASSERT_EQ(calls.size(), times.size());
  for (size_t i = 0; i < calls.size(); ++i) {
    EXPECT_EQ(calls[i].first, static_cast<int64_t>(i + 1));
    EXPECT_EQ(calls[i].second, analysis->foot->samples[i].t_ns);
  }
  ExpectTruthTimes(*analysis, clips.base.truth);
}

TEST(AnalyzeClip, ARestWindowWithTooFewFramesIsExtendedAndSaysSo) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  const synth::GroundTruth& truth = clips.early_led.truth;
  ClipAnalysisOptions options = OptionsFor(clips.early_led);
  options.rest_min_frames = 8;
  auto analysis = AnalyzeClip(clips.early_led.video_path, options);
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  // frames 0..6 are before the LED at 0.11 s; the window takes frames 0..7
  EXPECT_EQ(analysis->rest_frames, 8);
  EXPECT_EQ(analysis->rest_to_ns, truth.frame_times_ns[7] + 1);
  EXPECT_THAT(::testing::PrintToString(analysis->warnings), HasSubstr("rest window extended to"));
  EXPECT_LE(std::abs(analysis->liftoff()->t_ns - *truth.liftoff_1mm_video_ns),
            3 * FrameIntervalNs(truth));
}

TEST(AnalyzeClip, WithoutAFootRegionOnlyTheLedIsAnalysed) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ClipAnalysisOptions options = OptionsFor(clips.base);
  options.foot.foot_roi_px = cv::Rect();
  auto analysis = AnalyzeClip(clips.base.video_path, options);
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  EXPECT_FALSE(analysis->foot.has_value());
  EXPECT_EQ(analysis->liftoff(), nullptr);
  EXPECT_EQ(analysis->Events().status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(analysis->ToJson()["foot"].is_null());
  EXPECT_TRUE(analysis->ToJson()["events"].is_null());
}

TEST(AnalyzeClip, ErrorsSayWhatAndWhere) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  // no such file, not a video
  auto missing = AnalyzeClip(scratch / "absent.mp4", OptionsFor(clips.base));
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("absent.mp4"));
  auto text = AnalyzeClip(clips.not_a_video, OptionsFor(clips.base));
  EXPECT_EQ(text.status().code(), StatusCode::kParse);
  EXPECT_THAT(text.status().message(), HasSubstr("notes.mp4"));
  // a foot region partly outside the 640x480 frame, then an LED region
  ClipAnalysisOptions outside = OptionsFor(clips.base);
  outside.foot.foot_roi_px = cv::Rect(600, 400, 100, 100);
  auto foot_outside = AnalyzeClip(clips.base.video_path, outside);
  EXPECT_EQ(foot_outside.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(foot_outside.status().message(), HasSubstr("clip-base.mp4"));
  outside = OptionsFor(clips.base);
  outside.led.roi_px = cv::Rect(630, 10, 20, 20);
  auto led_outside = AnalyzeClip(clips.base.video_path, outside);
  EXPECT_EQ(led_outside.status().code(), StatusCode::kInvalidArgument);
  // an exposure longer than the frame interval (16.7 ms at 60 fps), for the LED or the foot
  for (const bool led : {true, false}) {
    ClipAnalysisOptions long_exposure = OptionsFor(clips.base);
    (led ? long_exposure.led.exposure_s : long_exposure.foot.exposure_s) = 0.018;
    auto analysis = AnalyzeClip(clips.base.video_path, long_exposure);
    EXPECT_EQ(analysis.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(analysis.status().message(), HasSubstr(led ? "led.exposure_s" : "foot.exposure_s"));
    EXPECT_THAT(analysis.status().message(), HasSubstr("--exposure-ms"));
    EXPECT_THAT(analysis.status().message(), HasSubstr("clip-base.mp4"));
  }
  // bad options before any decoding
  ClipAnalysisOptions bad = OptionsFor(clips.base);
  bad.queue_frames = -1;
  EXPECT_EQ(AnalyzeClip(clips.base.video_path, bad).status().code(), StatusCode::kInvalidArgument);
}

// ---------------------------------------------------------------------------------------
// what the analysis hands on

TEST(ClipAnalysis, EventsAreTheFirstSwitchOnAndTheChosenFootInstant) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  auto analysis = AnalyzeClip(clips.base.video_path, OptionsFor(clips.base));
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  auto events = analysis->Events();
  ASSERT_TRUE(events.ok()) << events.status().ToString();
  EXPECT_EQ(events->source, "video");
  EXPECT_EQ(events->led_on_ns, analysis->led.pulses.front().on_ns);
  EXPECT_EQ(events->led_on_uncertainty_ns, analysis->led.pulses.front().on_uncertainty_ns);
  EXPECT_EQ(events->liftoff_ns, analysis->foot->above_threshold.t_ns);
  EXPECT_EQ(events->liftoff_uncertainty_ns, analysis->foot->above_threshold.uncertainty_ns);
  EXPECT_GT(events->led_on_uncertainty_ns, 0);

  analysis->liftoff_instant = LiftoffInstant::kOnset;
  auto onset = analysis->Events();
  ASSERT_TRUE(onset.ok());
  EXPECT_EQ(onset->liftoff_ns, analysis->foot->onset.t_ns);
  EXPECT_LE(onset->liftoff_ns, events->liftoff_ns);
}

TEST(ClipAnalysis, JsonHoldsTheDocumentedFields) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  auto analysis = AnalyzeClip(clips.base.video_path, OptionsFor(clips.base));
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  const nlohmann::json document = analysis->ToJson();
  EXPECT_EQ(document["format"], "liftoff-video-analysis");
  EXPECT_EQ(document["version"], 1);
  EXPECT_EQ(document["timing"]["frames"], analysis->timing.frames);
  EXPECT_EQ(document["led"]["pulses"][0]["on_ns"], analysis->led_on().on_ns);
  EXPECT_EQ(document["led"]["roi_px"]["x_px"], clips.base.truth.led_roi_px.x_px);
  EXPECT_EQ(document["foot"]["above_threshold"]["t_ns"], analysis->foot->above_threshold.t_ns);
  EXPECT_NEAR(document["foot"]["threshold_mm"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(document["events"]["source"], "video");
  EXPECT_EQ(document["events"]["liftoff_instant"], "threshold");
  EXPECT_EQ(document["events"]["led_on_ns"], analysis->led_on().on_ns);
  EXPECT_NEAR(document["events"]["interval_s"].get<double>(),
              SecondsFromNs(analysis->liftoff()->t_ns - analysis->led_on().on_ns), 1e-9);
  for (const char* key : {"video", "width_px", "height_px", "warnings", "wall_s"}) {
    EXPECT_TRUE(document.contains(key)) << key;
  }
  EXPECT_THAT(analysis->Brief(), HasSubstr("clip-base.mp4: LED on "));
}

// ---------------------------------------------------------------------------------------
// proof

TEST(WriteVerification, TheImageNeedsOnlyTheFramesUpToLiftoff) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  auto analysis = AnalyzeClip(clips.base.video_path, OptionsFor(clips.base));
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  VerificationOptions options;
  options.image_path = scratch / "proof" / "base.png";
  auto report = WriteVerification(*analysis, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->image_path, options.image_path);
  EXPECT_EQ(report->clip_frames, analysis->timing.frames);
  // the second decode stopped at the last frame shown: about 0.2 s after liftoff
  EXPECT_LT(report->frames_decoded, report->clip_frames);
  EXPECT_GT(report->frames_decoded, analysis->foot->above_threshold.frame_after);
  // the foot's bottom for the drawing (the box of the patches that moved with it, a quarter
  // patch beyond their centres) within half a 9 px patch of where the renderer put it
  EXPECT_NEAR(report->foot_rest_bottom_px, clips.base.truth.foot_rest_bottom_px, 4.5);
  const cv::Mat image = cv::imread(options.image_path.string());
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, options.image_width_px);
  EXPECT_GT(image.rows, 2 * options.crop_height_px);
}

TEST(WriteVerification, TheAnnotatedVideoHasEveryFrame) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  auto analysis = AnalyzeClip(clips.base.video_path, OptionsFor(clips.base));
  ASSERT_TRUE(analysis.ok()) << analysis.status().ToString();
  VerificationOptions options;
  options.video_path = scratch / "annotated.avi";
  auto report = WriteVerification(*analysis, options);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->frames_decoded, analysis->timing.frames);
  cv::VideoCapture capture(options.video_path.string());
  ASSERT_TRUE(capture.isOpened());
  int64_t frames = 0;
  cv::Mat frame;
  while (capture.read(frame)) {
    EXPECT_EQ(frame.cols, 640);
    ++frames;
  }
  EXPECT_EQ(frames, analysis->timing.frames);
}

TEST(WriteVerification, OptionsNeedAFileAndSaneSizes) {
  VerificationOptions options;
  EXPECT_EQ(options.Validate().code(), StatusCode::kInvalidArgument);
  options.image_path = "x.png";
  EXPECT_TRUE(options.Validate().ok());
  options.crop_height_px = 10;
  EXPECT_THAT(options.Validate().message(), HasSubstr("crop_height_px"));
}

// ---------------------------------------------------------------------------------------
// liftoff video

TEST(CliVideo, PrintsTheAnalysisAsJson) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  const synth::GroundTruth& truth = clips.base.truth;
  const CommandRun run = RunBinary(
      "video " + Quoted(clips.base.video_path) + " --led-roi " + RectFlag(truth.led_roi_px) +
          " --foot-roi " + RectFlag(truth.foot_roi_px) + " --foot A --px-per-mm " +
          std::to_string(truth.px_per_mm) + " --json --verify " + Quoted(scratch / "v.png"),
      scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json document = nlohmann::json::parse(run.out);
  const double frame_s = SecondsFromNs(FrameIntervalNs(truth));
  EXPECT_NEAR(document["events"]["led_on_s"].get<double>(), SecondsFromNs(*truth.led_on_video_ns),
              frame_s / 2);
  EXPECT_NEAR(document["events"]["liftoff_s"].get<double>(),
              SecondsFromNs(*truth.liftoff_1mm_video_ns), 3 * frame_s);
  EXPECT_EQ(document["verification"]["image"], (scratch / "v.png").string());
  EXPECT_FALSE(cv::imread((scratch / "v.png").string()).empty());
}

TEST(CliVideo, TextOutputNamesEveryPart) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  const synth::GroundTruth& truth = clips.base.truth;
  const CommandRun run = RunBinary("video " + Quoted(clips.base.video_path) + " --foot-roi " +
                                       RectFlag(truth.foot_roi_px) + " --threshold-px 1.5",
                                   scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("LED: "));
  EXPECT_THAT(run.out, HasSubstr("foot: "));
  EXPECT_THAT(run.out, HasSubstr("rest window: "));
  EXPECT_THAT(run.out, HasSubstr("threshold 1.500 px"));
  EXPECT_THAT(run.out, HasSubstr("events: LED on "));
}

TEST(CliVideo, EachErrorHasItsExitCode) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  const std::string clip = Quoted(clips.base.video_path);
  struct Case {
    std::string arguments;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"video " + Quoted(clips.not_a_video) + " --foot-roi 10,10,20,20", 5, "not a video"},
      {"video " + Quoted(scratch / "absent.mp4"), 4, "absent.mp4"},
      {"video " + clip + " --foot-roi 600,400,100,100", 3, "outside"},
      {"video " + clip + " --foot-roi 1,2,3", 3, "--foot-roi: expected x,y,w,h"},
      {"video " + clip + " --foot E", 3, "--foot: expected A, B, C or D"},
      {"video " + clip + " --rest-window=0.5,0", 3, "--rest-window"},
      {"video " + clip + " --rest-window=a,0", 3, "--rest-window: expected FROM,TO"},
      {"video " + clip + " --liftoff knee", 3, "--liftoff: expected threshold or onset"},
      {"video " + clip + " --progress loud", 3, "--progress"},
      {"video " + clip + " --px-per-mm -1", 3, "--px-per-mm"},
      {"video " + clip + " --foot-roi " + RectFlag(clips.base.truth.foot_roi_px) +
           " --threshold-px 0",
       3, "--threshold-px"},
      {"video " + clip + " --exposure-ms 1000", 3, "--exposure-ms"},
      {"video " + clip + " --threshold-mm 1 --threshold-px 2", 2, "excludes"},
  };
  for (const Case& c : cases) {
    const CommandRun run = RunBinary(c.arguments, scratch);
    EXPECT_EQ(run.code, c.code) << c.arguments << "\n" << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message)) << c.arguments;
  }
}

TEST(CliSync, VideoModeFindsTheRotationAtLiftoffFromTheClip) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  const synth::GroundTruth& truth = clips.base.truth;
  ASSERT_TRUE(truth.liftoff_1mm_rad.has_value());
  const CommandRun run =
      RunBinary("sync " + Quoted(clips.base.log_path) + " -c " +
                    Quoted(SourceDir() / "calib" / "laika-2018.json") + " --video " +
                    Quoted(clips.base.video_path) + " --led-roi " + RectFlag(truth.led_roi_px) +
                    " --foot-roi " + RectFlag(truth.foot_roi_px) + " --foot A --px-per-mm " +
                    std::to_string(truth.px_per_mm) + " --progress off --json",
                scratch);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json document = nlohmann::json::parse(run.out);
  EXPECT_NEAR(document["liftoff_rad"].get<double>(), *truth.liftoff_1mm_rad, 0.01);
  // the instants are the clip's, within the analysis' tolerance of the truth
  const double frame_s = SecondsFromNs(FrameIntervalNs(truth));
  EXPECT_EQ(document["times"]["source"], "video");
  EXPECT_NEAR(document["times"]["led_on_s"].get<double>(), SecondsFromNs(*truth.led_on_video_ns),
              frame_s / 2);
  EXPECT_NEAR(document["times"]["liftoff_s"].get<double>(),
              SecondsFromNs(*truth.liftoff_1mm_video_ns), 3 * frame_s);
  EXPECT_GT(document["times"]["liftoff_uncertainty_s"].get<double>(), 0.0);
  EXPECT_EQ(document["video"]["events"]["liftoff_s"], document["times"]["liftoff_s"]);
}

TEST(CliSync, VideoModeAndHandInstantsExcludeEachOtherAndOneIsNeeded) {
  LIFTOFF_REQUIRE_CLIPS(clips);
  ScratchDir scratch;
  const std::string log = Quoted(clips.base.log_path);
  const std::string clip = Quoted(clips.base.video_path);
  const std::string foot_roi = " --foot-roi " + RectFlag(clips.base.truth.foot_roi_px);
  struct Case {
    std::string arguments;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"sync " + log + " --video " + clip + foot_roi + " --led-on 0.6 --liftoff 2", 2, "excludes"},
      {"sync " + log + " --video " + clip + foot_roi + " --uncertainty 0.01", 2, "excludes"},
      {"sync " + log, 3, "--led-on S --liftoff S, or --video CLIP"},
      {"sync " + log + " --led-on 0.6", 2, "requires"},
      {"sync " + log + " --led-on 0.6 --liftoff 2" + foot_roi, 2, "requires"},
      {"sync " + log + " --video " + clip, 3, "--video needs --foot-roi"},
      // the video analysis' errors keep their exit codes
      {"sync " + log + " --video " + Quoted(clips.not_a_video) + foot_roi, 5, "not a video"},
      {"sync " + log + " --video " + clip + " --foot-roi 600,400,100,100", 3, "outside"},
      {"sync " + log + " --video " + clip + foot_roi + " --progress loud", 3, "--progress"},
  };
  for (const Case& c : cases) {
    const CommandRun run = RunBinary(c.arguments, scratch);
    EXPECT_EQ(run.code, c.code) << c.arguments << "\n" << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message)) << c.arguments;
  }
}

// The LED of a lossless crop of a hard3d-06 clip (tests/video/data/README.md): its ROI is
// 98,12,24,24 and it switches on at 0.8 s.
void ExpectTinyLedFound(const std::string& clip, double on_s = 0.8, double within_frames = 0.5) {
  ClipAnalysisOptions options;
  options.led.roi_px = cv::Rect(98, 12, 24, 24);
  const auto analysis = AnalyzeClip(SourceDir() / "tests" / "video" / "data" / clip, options);
  ASSERT_TRUE(analysis.ok()) << clip << ": " << analysis.status().ToString();
  ASSERT_EQ(analysis->led.pulses.size(), 1u) << clip << ": " << analysis->led.Brief();
  const LedPulse& pulse = analysis->led.pulses.front();
  const double error_ns = static_cast<double>(pulse.on_ns) - on_s * 1e9;
  EXPECT_LE(std::abs(error_ns), within_frames * 1e9 / 30.0)
      << clip << ": " << analysis->led.Brief();
  EXPECT_LE(std::abs(error_ns), static_cast<double>(pulse.on_uncertainty_ns))
      << clip << ": " << analysis->led.Brief();
}

}  // namespace

// A 0.6 px LED on its real pixels (tests/video/data/README.md: a lossless crop of an H.264
// clip liftoff rendered): H.264 builds the spot up over four frames and shows the half-lit
// frame above half of the step, and the frame before the step's is still dark. Found, within
// half a frame, the truth inside its interval (before kPartlyLitBeforeFrac: not found).
TEST(ClipAnalysis, ATinyLedACodecBuildsUpIsFoundOnItsRealPixels) {
  ExpectTinyLedFound("hard3d-06-seed6000-led.mkv");
}

// H.264 renewed the block around the LED as it switched on: many pixels stepped a little
// either way, one 4 px from the LED by a third of its step.
TEST(ClipAnalysis, ATinyLedInABlockTheCodecRenewedIsFoundOnItsRealPixels) {
  ExpectTinyLedFound("hard3d-06-seed5000-led.mkv");
}

// A 0.79 px LED (--led-radius-mm 2) that H.264 built up from its half-lit frame over three
// frames: dated where the frames cross half lit, +0.197 frame here (+0.908 by the first frame
// past one half, as before).
TEST(ClipAnalysis, ASmallLedBuiltUpFromItsHalfLitFrameIsDatedWhereItCrossesHalfLit) {
  ExpectTinyLedFound("hard3d-06-r2mm-seed34000-led.mkv", 0.8, 0.25);
}

// A 0.6 px LED that H.264's B-frames blended over two frames (0.29 and 0.68 of the step in
// its brightest pixel, the first 0.53 lit): +0.382 frame here (+1.105 before).
TEST(ClipAnalysis, ATinyLedBlendedOverBFramesIsDatedWhereItCrossesHalfLit) {
  ExpectTinyLedFound("hard3d-06-seed20000-led.mkv", 2.9328037921144423 - 64 / 30.0);
}

}  // namespace liftoff::video
