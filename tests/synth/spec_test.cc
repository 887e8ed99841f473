#include "liftoff/synth/spec.h"

#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace liftoff::synth {
namespace {

using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::WriteFile;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kPi = std::numbers::pi;

Status FromJsonStatus(const json& document) {
  return TrialSpecFromJson(document, "t.json", "").status();
}

// --- codecs ----------------------------------------------------------------------------

TEST(VideoCodec, NamesParseAndExtensions) {
  EXPECT_EQ(VideoCodecName(VideoCodec::kH264), "h264");
  EXPECT_EQ(VideoCodecName(VideoCodec::kMjpeg), "mjpeg");
  EXPECT_EQ(VideoCodecName(VideoCodec::kFfv1), "ffv1");
  EXPECT_EQ(ParseVideoCodec("h264"), VideoCodec::kH264);
  EXPECT_EQ(ParseVideoCodec("mjpeg"), VideoCodec::kMjpeg);
  EXPECT_EQ(ParseVideoCodec("ffv1"), VideoCodec::kFfv1);
  EXPECT_EQ(ParseVideoCodec("H264"), std::nullopt);
  EXPECT_EQ(ParseVideoCodec(""), std::nullopt);
  EXPECT_EQ(VideoCodecExtension(VideoCodec::kH264), ".mp4");
  EXPECT_EQ(VideoCodecExtension(VideoCodec::kMjpeg), ".avi");
  EXPECT_EQ(VideoCodecExtension(VideoCodec::kFfv1), ".mkv");
}

// --- validation ------------------------------------------------------------------------

TEST(TrialSpec, DefaultsValidate) { EXPECT_TRUE(TrialSpec{}.Validate().ok()); }

TEST(TrialSpec, OutOfRangeFieldIsNamedWithRangeAndValue) {
  TrialSpec spec;
  spec.camera.fps = 0;
  const Status status = spec.Validate();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), "camera.fps: expected a number in [1, 1000], got 0");
}

struct BadField {
  std::function<void(TrialSpec&)> breaks;
  std::string message_prefix;
};

TEST(TrialSpec, EachBadFieldNamesItsPath) {
  const std::vector<BadField> cases = {
      {[](TrialSpec& s) { s.id = ""; }, "id: expected 1 to 100"},
      {[](TrialSpec& s) { s.id = "a/b"; }, "id: expected 1 to 100"},
      {[](TrialSpec& s) { s.duration_s = 0; }, "duration_s: expected a number in (0, 3600], got 0"},
      {[](TrialSpec& s) { s.camera.width_px = 100; },
       "camera.width_px: expected an integer in [320, 1920], got 100"},
      {[](TrialSpec& s) { s.camera.width_px = 321; }, "camera.width_px: expected an even width"},
      {[](TrialSpec& s) { s.camera.height_px = 1081; },
       "camera.height_px: expected an integer in [240, 1080], got 1081"},
      {[](TrialSpec& s) { s.camera.height_px = 241; }, "camera.height_px: expected an even height"},
      {[](TrialSpec& s) { s.camera.exposure_s = 0.02; },
       "camera.exposure_s: expected a number in (0, 0.0166667], got 0.02"},
      {[](TrialSpec& s) { s.camera.exposure_s = 0; },
       "camera.exposure_s: expected a number in (0,"},
      {[](TrialSpec& s) { s.camera.drop_probability = 0.6; },
       "camera.drop_probability: expected a number in [0, 0.5], got 0.6"},
      {[](TrialSpec& s) { s.camera.timestamp_jitter_s = 0.01; },
       "camera.timestamp_jitter_s: expected a number in [0, 0.00666667], got 0.01"},
      {[](TrialSpec& s) {
         s.camera.codec = VideoCodec::kH264;
         s.camera.quality = 52;
       },
       "camera.quality: expected an integer in [0, 51], got 52"},
      {[](TrialSpec& s) {
         s.camera.codec = VideoCodec::kMjpeg;
         s.camera.quality = 1;
       },
       "camera.quality: expected an integer in [2, 31], got 1"},
      {[](TrialSpec& s) { s.nuisance.noise_sigma = 31; },
       "nuisance.noise_sigma: expected a number in [0, 30], got 31"},
      {[](TrialSpec& s) { s.nuisance.motion_blur_samples = 0; },
       "nuisance.motion_blur_samples: expected an integer in [1, 16], got 0"},
      {[](TrialSpec& s) { s.nuisance.flicker_amplitude = 0.6; },
       "nuisance.flicker_amplitude: expected a number in [0, 0.5], got 0.6"},
      {[](TrialSpec& s) { s.nuisance.flicker_hz = 50; },
       "nuisance.flicker_hz: expected 100 or 120 (50 or 60 Hz mains), got 50"},
      {[](TrialSpec& s) { s.nuisance.shake_px = 2.5; },
       "nuisance.shake_px: expected a number in [0, 2], got 2.5"},
      {[](TrialSpec& s) { s.led.x_frac = 1.5; },
       "led.x_frac: expected a number in [0, 1], got 1.5"},
      {[](TrialSpec& s) { s.led.y_frac = -0.1; },
       "led.y_frac: expected a number in [0, 1], got -0.1"},
      {[](TrialSpec& s) { s.led.radius_px = 0.5; },
       "led.radius_px: expected a number in [1, 40], got 0.5"},
      {[](TrialSpec& s) { s.led.blue = -1; }, "led.blue: expected an integer in [0, 255], got -1"},
      {[](TrialSpec& s) { s.led.green = 256; },
       "led.green: expected an integer in [0, 255], got 256"},
      {[](TrialSpec& s) { s.led.red = 300; }, "led.red: expected an integer in [0, 255], got 300"},
      {[](TrialSpec& s) { s.led.intensity = 0.05; },
       "led.intensity: expected a number in [0.1, 4], got 0.05"},
      {[](TrialSpec& s) { s.led.bloom = 7; }, "led.bloom: expected a number in [0, 6], got 7"},
      {[](TrialSpec& s) { s.led.on_video_s = NAN; }, "led.on_video_s: expected a number in"},
      {[](TrialSpec& s) { s.motion.height.kind = "spline"; },
       "motion.height.kind: expected one of parametric, csv, got \"spline\""},
      {[](TrialSpec& s) { s.motion.height.kind = "csv"; },
       "motion.height.csv_path: expected the path of a height CSV"},
      {[](TrialSpec& s) { s.motion.height.liftoff_rad = -0.1; },
       "motion.height.liftoff_rad: expected a number in [0, 3.14159], got -0.1"},
      {[](TrialSpec& s) { s.motion.height.gain_m = 0; },
       "motion.height.gain_m: expected a number in (0, 10], got 0"},
      {[](TrialSpec& s) { s.motion.height.exponent = 0; },
       "motion.height.exponent: expected a number in (0, 5], got 0"},
      {[](TrialSpec& s) { s.motion.bend_start_s = -1; },
       "motion.bend_start_s: expected a number in [0, 3600], got -1"},
      {[](TrialSpec& s) { s.motion.bend_end_s = 0.2; },
       "motion.bend_end_s: expected at least bend_start_s (0.5), got 0.2"},
      {[](TrialSpec& s) { s.motion.ramp_start_s = -2; },
       "motion.ramp_start_s: expected a number in [0, 3600], got -2"},
      {[](TrialSpec& s) { s.motion.ramp_rate_rad_per_s = 0; },
       "motion.ramp_rate_rad_per_s: expected a number in (0, 10], got 0"},
      {[](TrialSpec& s) { s.motion.diagonal_lag_rad = 4; },
       "motion.diagonal_lag_rad: expected a number in [-3.14159, 3.14159], got 4"},
      {[](TrialSpec& s) { s.log.led_on_device_ns = -1; },
       "log.led_on_device_ns: expected an integer in [0, 1e+15], got -1"},
      {[](TrialSpec& s) {
         s.log.led_event = false;
         s.log.led_on_device_ns = 7;
       },
       "log.led_on_device_ns: expected 0 when log.led_event is false"},
      {[](TrialSpec& s) { s.log.clock_drift_ppm = 2000; },
       "log.clock_drift_ppm: expected a number in [-1000, 1000], got 2000"},
      {[](TrialSpec& s) { s.log.rate_hz = 0; },
       "log.rate_hz: expected a number in [1, 10000], got 0"},
      {[](TrialSpec& s) { s.log.jitter_s = 0.01; },
       "log.jitter_s: expected a number in [0, 0.005], got 0.01"},
      {[](TrialSpec& s) { s.log.burst_period_s = 61; },
       "log.burst_period_s: expected a number in [0, 60], got 61"},
      {[](TrialSpec& s) {
         s.log.burst_period_s = 0.05;
         s.log.burst_length_s = 0.06;
       },
       "log.burst_length_s: expected a number in (0, 0.05], got 0.06"},
      {[](TrialSpec& s) { s.log.lead_s = -1; }, "log.lead_s: expected a number in [0, 60], got -1"},
      {[](TrialSpec& s) { s.log.tail_s = 61; }, "log.tail_s: expected a number in [0, 60], got 61"},
  };
  for (const BadField& bad : cases) {
    TrialSpec spec;
    bad.breaks(spec);
    const Status status = spec.Validate();
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << bad.message_prefix;
    EXPECT_THAT(status.message(), StartsWith(bad.message_prefix));
  }
}

TEST(TrialSpec, FfvIgnoresQualityAndLedMayNeverSwitchOn) {
  TrialSpec spec;
  spec.camera.codec = VideoCodec::kFfv1;
  spec.camera.quality = 99;
  spec.led.on_video_s = -1;
  EXPECT_TRUE(spec.Validate().ok());
  spec.led.on_video_s = spec.duration_s + 5;
  EXPECT_TRUE(spec.Validate().ok());
}

TEST(TrialSpec, ExposureOfAWholeFrameIsAllowed) {
  TrialSpec spec;
  spec.camera.fps = 30;
  spec.camera.exposure_s = 1.0 / 30.0;
  EXPECT_TRUE(spec.Validate().ok());
}

// --- JSON ------------------------------------------------------------------------------

TEST(TrialSpecJson, EmptyObjectGivesDefaults) {
  const Result<TrialSpec> spec = TrialSpecFromJson(json::object(), "t.json", "");
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(spec->id, "synthetic");
  EXPECT_EQ(spec->seed, 1u);
  EXPECT_EQ(spec->duration_s, 24.0);
  EXPECT_EQ(spec->camera.width_px, 1280);
  EXPECT_EQ(spec->camera.codec, VideoCodec::kFfv1);
  EXPECT_EQ(spec->motion.foot, Foot::kA);
  EXPECT_EQ(spec->motion.height.kind, "parametric");
  EXPECT_EQ(spec->log.rate_hz, 100.0);
}

TEST(TrialSpecJson, ReadsEveryKeyOfTheDocumentedShape) {
  json document = json::parse(R"({
    "id": "ci-007-mjpeg", "seed": 18446744073709551615, "duration_s": 3.5,
    "camera": {"width_px": 640, "height_px": 480, "fps": 120, "exposure_s": 0.005,
               "drop_probability": 0.1, "timestamp_jitter_s": 0.001, "codec": "mjpeg",
               "quality": 5},
    "nuisance": {"noise_sigma": 3, "motion_blur_samples": 4, "flicker_amplitude": 0.2,
                 "flicker_hz": 120, "shake_px": 1.5, "shadow": false},
    "led": {"x_frac": 0.2, "y_frac": 0.3, "radius_px": 8, "color_bgr": [10, 20, 30],
            "intensity": 3, "bloom": 1, "on_video_s": 0.25},
    "motion": {"foot": "C", "rotation": "-",
               "height": {"kind": "csv", "liftoff_rad": 0.5, "gain_m": 0.5, "exponent": 2,
                          "csv": "curves/../curves/c.csv"},
               "bend_start_s": 0.1, "bend_end_s": 0.2, "ramp_start_s": 0.3,
               "ramp_rate_rad_per_s": 0.9, "diagonal_lag_rad": 0.05},
    "log": {"led_on_device_ns": 123456789, "clock_drift_ppm": -40, "rate_hz": 250,
            "jitter_s": 0.0005, "burst_period_s": 1, "burst_length_s": 0.1,
            "led_event": false, "lead_s": 2, "tail_s": 3}
  })");
  // a log without an led_on event starts its device clock at the LED: a non-zero
  // led_on_device_ns contradicts it
  const Result<TrialSpec> contradictory = TrialSpecFromJson(document, "t.json", "/data/specs");
  ASSERT_FALSE(contradictory.ok());
  EXPECT_EQ(contradictory.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(contradictory.status().message(),
              StartsWith("t.json: /log/led_on_device_ns: expected 0 when log.led_event is false"));
  const Result<TrialSpec> without_event =
      TrialSpecFromJson(json::parse(R"({"log": {"led_event": false}})"), "t.json", "");
  ASSERT_TRUE(without_event.ok()) << without_event.status().ToString();
  EXPECT_FALSE(without_event->log.led_event);

  document["log"]["led_event"] = true;
  const Result<TrialSpec> read = TrialSpecFromJson(document, "t.json", "/data/specs");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  const TrialSpec& spec = *read;
  EXPECT_EQ(spec.id, "ci-007-mjpeg");
  EXPECT_EQ(spec.seed, 18446744073709551615u);
  EXPECT_EQ(spec.duration_s, 3.5);
  EXPECT_EQ(spec.camera.width_px, 640);
  EXPECT_EQ(spec.camera.height_px, 480);
  EXPECT_EQ(spec.camera.fps, 120.0);
  EXPECT_EQ(spec.camera.exposure_s, 0.005);
  EXPECT_EQ(spec.camera.drop_probability, 0.1);
  EXPECT_EQ(spec.camera.timestamp_jitter_s, 0.001);
  EXPECT_EQ(spec.camera.codec, VideoCodec::kMjpeg);
  EXPECT_EQ(spec.camera.quality, 5);
  EXPECT_EQ(spec.nuisance.noise_sigma, 3.0);
  EXPECT_EQ(spec.nuisance.motion_blur_samples, 4);
  EXPECT_EQ(spec.nuisance.flicker_amplitude, 0.2);
  EXPECT_EQ(spec.nuisance.flicker_hz, 120.0);
  EXPECT_EQ(spec.nuisance.shake_px, 1.5);
  EXPECT_FALSE(spec.nuisance.shadow);
  EXPECT_EQ(spec.led.x_frac, 0.2);
  EXPECT_EQ(spec.led.y_frac, 0.3);
  EXPECT_EQ(spec.led.radius_px, 8.0);
  EXPECT_EQ(spec.led.blue, 10);
  EXPECT_EQ(spec.led.green, 20);
  EXPECT_EQ(spec.led.red, 30);
  EXPECT_EQ(spec.led.intensity, 3.0);
  EXPECT_EQ(spec.led.bloom, 1.0);
  EXPECT_EQ(spec.led.on_video_s, 0.25);
  EXPECT_EQ(spec.motion.foot, Foot::kC);
  EXPECT_EQ(spec.motion.rotation, RotationSense::kNegative);
  EXPECT_EQ(spec.motion.height.kind, "csv");
  EXPECT_EQ(spec.motion.height.liftoff_rad, 0.5);
  EXPECT_EQ(spec.motion.height.gain_m, 0.5);
  EXPECT_EQ(spec.motion.height.exponent, 2.0);
  EXPECT_EQ(spec.motion.height.csv_path, std::filesystem::path("/data/specs/curves/c.csv"));
  EXPECT_EQ(spec.motion.bend_start_s, 0.1);
  EXPECT_EQ(spec.motion.bend_end_s, 0.2);
  EXPECT_EQ(spec.motion.ramp_start_s, 0.3);
  EXPECT_EQ(spec.motion.ramp_rate_rad_per_s, 0.9);
  EXPECT_EQ(spec.motion.diagonal_lag_rad, 0.05);
  EXPECT_EQ(spec.log.led_on_device_ns, 123456789);
  EXPECT_EQ(spec.log.clock_drift_ppm, -40.0);
  EXPECT_EQ(spec.log.rate_hz, 250.0);
  EXPECT_EQ(spec.log.jitter_s, 0.0005);
  EXPECT_EQ(spec.log.burst_period_s, 1.0);
  EXPECT_EQ(spec.log.burst_length_s, 0.1);
  EXPECT_TRUE(spec.log.led_event);
  EXPECT_EQ(spec.log.lead_s, 2.0);
  EXPECT_EQ(spec.log.tail_s, 3.0);

  // and writing it gives back the same document (the path as resolved)
  json expected = document;
  expected["motion"]["height"]["csv"] = "/data/specs/curves/c.csv";
  EXPECT_EQ(TrialSpecToJson(spec), expected);
}

TEST(TrialSpecJson, RoundTripKeepsEveryValueExactly) {
  TrialSpec spec;
  spec.id = "round.trip_1";
  spec.seed = 0x8000000000000001u;
  spec.duration_s = 1.0 / 3.0;
  spec.camera.fps = 59.94;
  spec.camera.exposure_s = 1.0 / 240.0;
  spec.camera.codec = VideoCodec::kH264;
  spec.camera.quality = 0;
  spec.nuisance.noise_sigma = 0.1;
  spec.led.on_video_s = -0.7;
  spec.led.blue = 255;
  spec.motion.foot = Foot::kD;
  spec.motion.height.kind = "csv";
  spec.motion.height.csv_path = "rel/curve.csv";
  spec.motion.ramp_rate_rad_per_s = kPi / 7;
  spec.log.led_on_device_ns = 999'999'999'999;
  spec.log.clock_drift_ppm = 12.345678901234567;
  const Result<TrialSpec> back = TrialSpecFromJson(TrialSpecToJson(spec), "t.json", "");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->id, spec.id);
  EXPECT_EQ(back->seed, spec.seed);
  EXPECT_EQ(back->duration_s, spec.duration_s);
  EXPECT_EQ(back->camera.fps, spec.camera.fps);
  EXPECT_EQ(back->camera.exposure_s, spec.camera.exposure_s);
  EXPECT_EQ(back->camera.codec, VideoCodec::kH264);
  EXPECT_EQ(back->camera.quality, 0);
  EXPECT_EQ(back->nuisance.noise_sigma, 0.1);
  EXPECT_EQ(back->led.on_video_s, -0.7);
  EXPECT_EQ(back->led.blue, 255);
  EXPECT_EQ(back->motion.foot, Foot::kD);
  EXPECT_EQ(back->motion.height.kind, "csv");
  EXPECT_EQ(back->motion.height.csv_path, std::filesystem::path("rel/curve.csv"));
  EXPECT_EQ(back->motion.ramp_rate_rad_per_s, kPi / 7);
  EXPECT_EQ(back->log.led_on_device_ns, 999'999'999'999);
  EXPECT_EQ(back->log.clock_drift_ppm, 12.345678901234567);
  EXPECT_EQ(TrialSpecToJson(*back), TrialSpecToJson(spec));
}

TEST(TrialSpecJson, UnknownKeyIsNamedByPointer) {
  const Status status = FromJsonStatus({{"camera", {{"fsp", 60}}}});
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), StartsWith("t.json: /camera/fsp: unknown key"));

  const Status top = FromJsonStatus({{"durationS", 3}});
  EXPECT_THAT(top.message(), StartsWith("t.json: /durationS: unknown key"));
}

TEST(TrialSpecJson, OutOfRangeValueIsNamedByPointer) {
  const Status fps = FromJsonStatus({{"camera", {{"fps", 0}}}});
  EXPECT_EQ(fps.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(fps.message(), "t.json: /camera/fps: expected a number in [1, 1000], got 0");

  const Status red = FromJsonStatus({{"led", {{"color_bgr", {0, 0, 300}}}}});
  EXPECT_EQ(red.message(), "t.json: /led/color_bgr/2: expected an integer in [0, 255], got 300");

  const Status lag = FromJsonStatus({{"motion", {{"diagonal_lag_rad", 9}}}});
  EXPECT_THAT(lag.message(), StartsWith("t.json: /motion/diagonal_lag_rad: expected a number in"));

  const Status csv = FromJsonStatus({{"motion", {{"height", {{"kind", "csv"}}}}}});
  EXPECT_THAT(csv.message(), StartsWith("t.json: /motion/height/csv: expected the path"));
}

TEST(TrialSpecJson, WrongTypesAndEnumsAreNamedByPointer) {
  EXPECT_EQ(FromJsonStatus({{"motion", {{"foot", "E"}}}}).message(),
            "t.json: /motion/foot: expected one of A, B, C, D, got \"E\"");
  EXPECT_THAT(FromJsonStatus({{"camera", {{"codec", "vp9"}}}}).message(),
              StartsWith("t.json: /camera/codec: expected one of h264, mjpeg, ffv1"));
  EXPECT_THAT(FromJsonStatus({{"motion", {{"rotation", 1}}}}).message(),
              StartsWith("t.json: /motion/rotation: expected one of +, -"));
  EXPECT_THAT(FromJsonStatus({{"camera", {{"width_px", 640.5}}}}).message(),
              StartsWith("t.json: /camera/width_px: expected an integer"));
  EXPECT_THAT(FromJsonStatus({{"seed", -3}}).message(),
              StartsWith("t.json: /seed: expected an integer"));
  EXPECT_THAT(FromJsonStatus({{"led", {{"color_bgr", {1, 2}}}}}).message(),
              StartsWith("t.json: /led/color_bgr"));
  EXPECT_THAT(FromJsonStatus({{"led", {{"color_bgr", {1, 2.5, 3}}}}}).message(),
              StartsWith("t.json: /led/color_bgr: expected 3 integers"));
  EXPECT_THAT(FromJsonStatus({{"motion", {{"height", {{"csv", ""}}}}}}).message(),
              StartsWith("t.json: /motion/height/csv: expected a non-empty path"));
  EXPECT_THAT(FromJsonStatus({{"log", "fast"}}).message(), StartsWith("t.json: /log"));
}

// --- ground truth ----------------------------------------------------------------------

GroundTruth SampleTruth() {
  GroundTruth truth;
  truth.trial_id = "ci-001";
  truth.foot = Foot::kB;
  truth.led_on_video_ns = 1'000'000'000;
  truth.led_first_frame = 60;
  truth.led_first_frame_fraction = 0.25;
  truth.liftoff_0mm_video_ns = 2'500'000'001;
  truth.liftoff_0mm_rad = 0.45;
  truth.frame_times_ns = {0, 16'666'667, 33'333'333};
  truth.px_per_mm = 1.5;
  truth.led_roi_px = {10, 20, 30, 40};
  truth.foot_roi_px = {100, 200, 50, 60};
  truth.foot_rest_bottom_px = 210.5;
  return truth;
}

TEST(GroundTruth, JsonWritesNanosecondsAndSecondsAndNulls) {
  const json document = SampleTruth().ToJson();
  EXPECT_EQ(document["format"], "liftoff-synth-truth");
  EXPECT_EQ(document["trial_id"], "ci-001");
  EXPECT_EQ(document["foot"], "B");
  EXPECT_EQ(document["led_on_video_ns"], 1'000'000'000);
  EXPECT_EQ(document["led_on_video_s"], 1.0);
  EXPECT_EQ(document["liftoff_0mm_video_ns"], 2'500'000'001);
  EXPECT_DOUBLE_EQ(document["liftoff_0mm_video_s"].get<double>(), 2.500000001);
  EXPECT_TRUE(document["liftoff_1mm_video_ns"].is_null());
  EXPECT_TRUE(document["liftoff_1mm_video_s"].is_null());
  EXPECT_TRUE(document["liftoff_1mm_rad"].is_null());
  EXPECT_EQ(document["frame_count"], 3);
  EXPECT_EQ(document["frame_times_ns"], json({0, 16'666'667, 33'333'333}));
  EXPECT_EQ(document["led_roi_px"],
            json({{"x_px", 10}, {"y_px", 20}, {"width_px", 30}, {"height_px", 40}}));
}

TEST(GroundTruth, JsonRoundTrip) {
  const GroundTruth truth = SampleTruth();
  const Result<GroundTruth> back = GroundTruthFromJson(truth.ToJson(), "truth.json");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->trial_id, "ci-001");
  EXPECT_EQ(back->foot, Foot::kB);
  EXPECT_EQ(back->led_on_video_ns, 1'000'000'000);
  EXPECT_EQ(back->led_first_frame, 60);
  EXPECT_EQ(back->led_first_frame_fraction, 0.25);
  EXPECT_EQ(back->liftoff_0mm_video_ns, 2'500'000'001);
  EXPECT_EQ(back->liftoff_1mm_video_ns, std::nullopt);
  EXPECT_EQ(back->liftoff_0mm_rad, 0.45);
  EXPECT_EQ(back->liftoff_1mm_rad, std::nullopt);
  EXPECT_EQ(back->frame_times_ns, truth.frame_times_ns);
  EXPECT_EQ(back->px_per_mm, 1.5);
  EXPECT_EQ(back->led_roi_px.x_px, 10);
  EXPECT_EQ(back->led_roi_px.height_px, 40);
  EXPECT_EQ(back->foot_roi_px.y_px, 200);
  EXPECT_EQ(back->foot_roi_px.width_px, 50);
  EXPECT_EQ(back->foot_rest_bottom_px, 210.5);
}

TEST(GroundTruth, ErrorsNameThePointer) {
  json seconds = SampleTruth().ToJson();
  seconds["liftoff_0mm_video_s"] = 2.6;
  EXPECT_THAT(GroundTruthFromJson(seconds, "truth.json").status().message(),
              StartsWith("truth.json: /liftoff_0mm_video_s: disagrees with liftoff_0mm_video_ns"));

  json order = SampleTruth().ToJson();
  order["frame_times_ns"] = {0, 5, 5};
  EXPECT_THAT(GroundTruthFromJson(order, "truth.json").status().message(),
              StartsWith("truth.json: /frame_times_ns: expected strictly increasing times"));

  json count = SampleTruth().ToJson();
  count["frame_count"] = 4;
  EXPECT_THAT(GroundTruthFromJson(count, "truth.json").status().message(),
              StartsWith("truth.json: /frame_count: expected the number of frame_times_ns (3)"));

  json unknown = SampleTruth().ToJson();
  unknown["led_on_ns"] = 3;
  EXPECT_THAT(GroundTruthFromJson(unknown, "truth.json").status().message(),
              StartsWith("truth.json: /led_on_ns: unknown key"));

  json format = SampleTruth().ToJson();
  format["format"] = "liftoff-manifest";
  EXPECT_THAT(GroundTruthFromJson(format, "truth.json").status().message(),
              StartsWith("truth.json: /format: expected one of liftoff-synth-truth"));

  json roi = SampleTruth().ToJson();
  roi["foot_roi_px"].erase("width_px");
  EXPECT_THAT(GroundTruthFromJson(roi, "truth.json").status().message(),
              StartsWith("truth.json: /foot_roi_px/width_px"));
}

// --- timeline: clocks ------------------------------------------------------------------

Timeline MakeTimeline(const TrialSpec& spec) {
  Result<Timeline> timeline = Timeline::Create(spec);
  EXPECT_TRUE(timeline.ok()) << timeline.status().ToString();
  return std::move(timeline).value();
}

TEST(Timeline, CreateRejectsAnInvalidSpec) {
  TrialSpec spec;
  spec.camera.fps = 0;
  EXPECT_THAT(Timeline::Create(spec).status().message(), StartsWith("camera.fps:"));
}

TEST(Timeline, TestClockStartsAtTheLed) {
  TrialSpec spec;
  spec.led.on_video_s = 1.25;
  const Timeline timeline = MakeTimeline(spec);
  EXPECT_EQ(timeline.led_on_origin_video_ns(), 1'250'000'000);
  EXPECT_EQ(timeline.LedOnVideoNs(), 1'250'000'000);
  EXPECT_DOUBLE_EQ(timeline.TestSecondsFromVideoNs(3'750'000'000), 2.5);
  EXPECT_DOUBLE_EQ(timeline.TestSecondsFromVideoNs(0), -1.25);
  EXPECT_FALSE(timeline.LedOnAt(1'249'999'999));
  EXPECT_TRUE(timeline.LedOnAt(1'250'000'000));
  EXPECT_TRUE(timeline.LedOnAt(20'000'000'000));
}

TEST(Timeline, LedOutsideTheClipNeverSwitchesOn) {
  TrialSpec spec;
  spec.led.on_video_s = -0.5;
  const Timeline before = MakeTimeline(spec);
  EXPECT_EQ(before.LedOnVideoNs(), std::nullopt);
  EXPECT_FALSE(before.LedOnAt(0));
  EXPECT_FALSE(before.LedOnAt(10'000'000'000));
  spec.led.on_video_s = 30;  // the clip lasts 24 s
  const Timeline after = MakeTimeline(spec);
  EXPECT_EQ(after.LedOnVideoNs(), std::nullopt);
  EXPECT_FALSE(after.LedOnAt(23'000'000'000));
  // the test clock keeps its origin even so
  EXPECT_DOUBLE_EQ(after.TestSecondsFromVideoNs(0), -30.0);
}

TEST(Timeline, DeviceClockWithoutDriftIsAnOffset) {
  TrialSpec spec;
  spec.led.on_video_s = 1.0;
  spec.log.led_on_device_ns = 5'000'000'000;
  const Timeline timeline = MakeTimeline(spec);
  EXPECT_EQ(timeline.DeviceNsFromVideoNs(1'000'000'000), 5'000'000'000);
  EXPECT_EQ(timeline.DeviceNsFromVideoNs(1'000'000'007), 5'000'000'007);
  EXPECT_EQ(timeline.DeviceNsFromVideoNs(0), 4'000'000'000);
  EXPECT_EQ(timeline.VideoNsFromDeviceNs(5'000'000'123), 1'000'000'123);
}

TEST(Timeline, DeviceClockDriftsAndMapsBack) {
  TrialSpec spec;
  spec.led.on_video_s = 1.0;
  spec.log.led_on_device_ns = 5'000'000'000;
  spec.log.clock_drift_ppm = 100;
  const Timeline timeline = MakeTimeline(spec);
  // 10 s after the LED the device has counted 10 s * 1.0001
  EXPECT_EQ(timeline.DeviceNsFromVideoNs(11'000'000'000), 15'001'000'000);
  // 1 s before it, 1 s * 1.0001 less
  EXPECT_EQ(timeline.DeviceNsFromVideoNs(0), 3'999'900'000);
  EXPECT_EQ(timeline.VideoNsFromDeviceNs(15'001'000'000), 11'000'000'000);
  EXPECT_EQ(timeline.VideoNsFromDeviceNs(3'999'900'000), 0);
  for (int64_t t_video_ns : {0L, 1L, 999'999'999L, 7'123'456'789L, 23'999'999'999L}) {
    const int64_t back_ns = timeline.VideoNsFromDeviceNs(timeline.DeviceNsFromVideoNs(t_video_ns));
    EXPECT_LE(std::abs(back_ns - t_video_ns), 1) << t_video_ns;
  }

  spec.log.clock_drift_ppm = -250;
  const Timeline slow = MakeTimeline(spec);
  EXPECT_EQ(slow.DeviceNsFromVideoNs(11'000'000'000), 5'000'000'000 + 9'997'500'000);
}

// --- timeline: motion ------------------------------------------------------------------

TEST(Timeline, VertebraRampsFromRampStartWithTheSense) {
  TrialSpec spec;  // the paper: (pi/3)/40 rad/s from 4 s
  const Timeline positive = MakeTimeline(spec);
  EXPECT_EQ(positive.VertebraRadAt(0.0), 0.0);
  EXPECT_EQ(positive.VertebraRadAt(3.999), 0.0);
  EXPECT_NEAR(positive.VertebraRadAt(44.0), kPi / 3, 1e-12);
  EXPECT_NEAR(positive.VertebraRadAt(24.0), kPi / 6, 1e-12);
  spec.motion.rotation = RotationSense::kNegative;
  const Timeline negative = MakeTimeline(spec);
  EXPECT_NEAR(negative.VertebraRadAt(44.0), -kPi / 3, 1e-12);
}

TEST(Timeline, BendSpoolIsLinearOverTheBend) {
  const Timeline timeline = MakeTimeline(TrialSpec{});  // bend 0.5 .. 3.5 s
  EXPECT_EQ(timeline.BendSpoolRadAt(-1.0, 2.0), 0.0);
  EXPECT_EQ(timeline.BendSpoolRadAt(0.5, 2.0), 0.0);
  EXPECT_DOUBLE_EQ(timeline.BendSpoolRadAt(2.0, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(timeline.BendSpoolRadAt(1.25, 2.0), 0.5);
  EXPECT_EQ(timeline.BendSpoolRadAt(3.5, 2.0), 2.0);
  EXPECT_EQ(timeline.BendSpoolRadAt(10.0, 2.0), 2.0);
}

TEST(Timeline, ParametricHeightOfTheLiftingFoot) {
  TrialSpec spec;
  spec.led.on_video_s = 1.0;
  spec.motion.ramp_start_s = 4.0;
  spec.motion.ramp_rate_rad_per_s = 0.1;
  spec.duration_s = 12;
  const Timeline timeline = MakeTimeline(spec);
  // 0.45 rad at test 8.5 s (video 9.5 s): just touching
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 9'500'000'000), 0.0, 1e-12);
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kA, 9'000'000'000), 0.0);
  // 0.6 rad at video 11 s: 0.25 * 0.15^1.5
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 11'000'000'000), 0.01452368754827778, 1e-12);
  // without a lag the others stay down
  for (Foot foot : {Foot::kB, Foot::kC, Foot::kD}) {
    EXPECT_EQ(timeline.FootHeightMAt(foot, 11'000'000'000), 0.0);
  }
}

TEST(Timeline, DiagonalPartnerRisesLaterByTheLag) {
  TrialSpec spec;
  spec.led.on_video_s = 1.0;
  spec.motion.ramp_rate_rad_per_s = 0.1;
  spec.motion.diagonal_lag_rad = 0.1;
  spec.duration_s = 12;
  const Timeline timeline = MakeTimeline(spec);
  // 0.6 rad: A at 0.25 * 0.15^1.5, its diagonal D at 0.25 * 0.05^1.5
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 11'000'000'000), 0.01452368754827778, 1e-12);
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kD, 11'000'000'000), 0.0027950849718747373, 1e-12);
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kB, 11'000'000'000), 0.0);
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kC, 11'000'000'000), 0.0);
  // 0.5 rad: A is up, D (0.4 rad after the lag) still down
  EXPECT_GT(timeline.FootHeightMAt(Foot::kA, 10'000'000'000), 0.0);
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kD, 10'000'000'000), 0.0);

  // B lifting pairs with C
  spec.motion.foot = Foot::kB;
  const Timeline b = MakeTimeline(spec);
  EXPECT_NEAR(b.FootHeightMAt(Foot::kC, 11'000'000'000), 0.0027950849718747373, 1e-12);
  EXPECT_EQ(b.FootHeightMAt(Foot::kA, 11'000'000'000), 0.0);
  EXPECT_EQ(b.FootHeightMAt(Foot::kD, 11'000'000'000), 0.0);
}

TEST(Timeline, PaperRampLiftsOffAtTheFirstNanosecondPastTheThreshold) {
  // LED at 1 s, ramp from test 4 s at (pi/3)/40 rad/s, liftoff at 0.45 rad:
  // 1 + 4 + 0.45 / ((pi/3)/40) = 5 + 54/pi = 22.188733853924695... s
  const Timeline timeline = MakeTimeline(TrialSpec{});
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.0), 22'188'733'854);
  // 1 mm: 0.25 * (theta - 0.45)^1.5 = 0.001 at theta = 0.45 + 0.004^(2/3)
  // = 0.475198420997897..., so 5 + theta * 120/pi = 23.151242636306933... s
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.001), 23'151'242'637);
  // the instants bracket the threshold
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kA, 22'188'733'853), 0.0);
  EXPECT_GT(timeline.FootHeightMAt(Foot::kA, 22'188'733'854), 0.0);
  EXPECT_LE(timeline.FootHeightMAt(Foot::kA, 23'151'242'636), 0.001);
  EXPECT_GT(timeline.FootHeightMAt(Foot::kA, 23'151'242'637), 0.001);
}

TEST(Timeline, NegativeSenseLiftsOffAtTheSameInstant) {
  TrialSpec spec;
  spec.motion.rotation = RotationSense::kNegative;
  EXPECT_EQ(MakeTimeline(spec).FirstVideoNsAbove(0.0), 22'188'733'854);
}

TEST(Timeline, NoLiftoffWithinTheClip) {
  TrialSpec spec;
  spec.duration_s = 22.0;  // liftoff would be at 22.19 s
  const Timeline timeline = MakeTimeline(spec);
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.0), std::nullopt);
  EXPECT_EQ(MakeTimeline(TrialSpec{}).FirstVideoNsAbove(1.0), std::nullopt);
}

// --- timeline: CSV curves --------------------------------------------------------------

// rotation 0 .. 0.6 rad; A dips below the ground first (clamped), leaves it at 0.4 rad
constexpr char kCurveCsv[] =
    "# simulated foot heights\n"
    "rotation_rad,A_height_m,D_height_m\n"
    "0.0,-0.0005,0\n"
    "0.4,0.0,0\n"
    "\n"
    "0.5,0.002,0.001\n"
    "0.6,0.010,0.004\n";

TrialSpec CsvSpec(const std::filesystem::path& csv) {
  TrialSpec spec;
  spec.duration_s = 10;
  spec.led.on_video_s = 0.5;
  spec.motion.ramp_start_s = 1.0;
  spec.motion.ramp_rate_rad_per_s = 0.07;
  spec.motion.height.kind = "csv";
  spec.motion.height.csv_path = csv;
  return spec;
}

TEST(Timeline, CsvCurveInterpolatesAndClamps) {
  ScratchDir scratch;
  WriteFile(scratch / "curve.csv", kCurveCsv);
  TrialSpec spec = CsvSpec(scratch / "curve.csv");
  spec.motion.ramp_rate_rad_per_s = 0.1;  // rotation = 0.1 * (video s - 1.5)
  const Timeline timeline = MakeTimeline(spec);
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kA, 1'500'000'000), 0.0);             // -0.0005 clamps
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kA, 3'500'000'000), 0.0);             // 0.2 rad: -0.00025
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 6'000'000'000), 0.001, 1e-12);  // 0.45 rad
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 7'000'000'000), 0.006, 1e-12);  // 0.55 rad
  EXPECT_NEAR(timeline.FootHeightMAt(Foot::kA, 9'500'000'000), 0.010, 1e-12);  // held at 0.8
  EXPECT_EQ(timeline.FootHeightMAt(Foot::kD, 7'000'000'000), 0.0);             // no lag: down
}

TEST(Timeline, CsvCurveLiftoffIsExact) {
  ScratchDir scratch;
  WriteFile(scratch / "curve.csv", kCurveCsv);
  const Timeline timeline = MakeTimeline(CsvSpec(scratch / "curve.csv"));
  // height > 0 past 0.4 rad: 0.5 + 1 + 0.4/0.07 = 7.2142857142857... s
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.0), 7'214'285'715);
  // 1 mm at 0.45 rad: 1.5 + 0.45/0.07 = 7.9285714285714... s
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.001), 7'928'571'429);
  // 6 mm at 0.55 rad: 1.5 + 0.55/0.07 = 9.3571428571428... s
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.006), 9'357'142'858);
  // never 1 cm or more within the curve's reach
  EXPECT_EQ(timeline.FirstVideoNsAbove(0.010), std::nullopt);
}

TEST(Timeline, CsvCurveOfANegativeSimulationReadsAbsoluteRotation) {
  ScratchDir scratch;
  WriteFile(scratch / "curve.csv",
            "D_height_m,rotation_rad\n"
            "0,-0.0\n0.0,-0.4\n0.002,-0.5\n0.010,-0.6\n");
  TrialSpec spec = CsvSpec(scratch / "curve.csv");
  spec.motion.foot = Foot::kD;
  spec.motion.rotation = RotationSense::kNegative;
  EXPECT_EQ(MakeTimeline(spec).FirstVideoNsAbove(0.001), 7'928'571'429);
}

TEST(Timeline, CsvCurveLoadsRelativeToTheSpecFile) {
  ScratchDir scratch;
  WriteFile(scratch / "curves" / "a.csv", kCurveCsv);
  const json document = {{"motion", {{"height", {{"kind", "csv"}, {"csv", "curves/a.csv"}}}}},
                         {"duration_s", 10},
                         {"led", {{"on_video_s", 0.5}}},
                         {"motion_unused", 0}};
  // an unknown key first, then the valid document
  EXPECT_FALSE(TrialSpecFromJson(document, "t.json", scratch.path()).ok());
  json valid = document;
  valid.erase("motion_unused");
  valid["motion"]["ramp_start_s"] = 1.0;
  valid["motion"]["ramp_rate_rad_per_s"] = 0.07;
  const Result<TrialSpec> spec = TrialSpecFromJson(valid, "t.json", scratch.path());
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(MakeTimeline(*spec).FirstVideoNsAbove(0.0), 7'214'285'715);
}

struct BadCsv {
  std::string contents;
  std::string message;  // after "<file>:"
};

TEST(Timeline, CsvErrorsNameFileAndLine) {
  const std::vector<BadCsv> cases = {
      {"rotation_rad,B_height_m\n0,0\n1,1\n",
       "1: expected a header with columns rotation_rad and A_height_m, got "
       "\"rotation_rad,B_height_m\""},
      {"# comment\nrotation_rad,A_height_m\n0,0\n0.5,abc\n",
       "4: A_height_m: expected a number, got \"abc\""},
      {"rotation_rad,A_height_m\n0,0\nx,1\n", "3: rotation_rad: expected a number, got \"x\""},
      {"rotation_rad,A_height_m\n0,0\n0.5\n", "3: expected 2 columns, got 1"},
      {"rotation_rad,A_height_m\n0,0\n0.5,1\n0.5,2\n",
       "4: rotation_rad: expected |rotation| to increase from row to row, got 0.5 after 0.5"},
      {"rotation_rad,A_height_m\n0,0\n",
       " expected at least two rows of rotation_rad and A_height_m, got 1"},
      {"", " expected a header line, got an empty file"},
  };
  for (const BadCsv& bad : cases) {
    ScratchDir scratch;
    const std::filesystem::path path = scratch / "bad.csv";
    WriteFile(path, bad.contents);
    const Status status = Timeline::Create(CsvSpec(path)).status();
    EXPECT_EQ(status.code(), StatusCode::kParse) << bad.message;
    EXPECT_THAT(status.message(), HasSubstr("bad.csv:" + bad.message));
  }
}

TEST(Timeline, MissingCsvIsNotFound) {
  ScratchDir scratch;
  const Status status = Timeline::Create(CsvSpec(scratch / "absent.csv")).status();
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_THAT(status.message(), HasSubstr("absent.csv"));
}

}  // namespace
}  // namespace liftoff::synth
