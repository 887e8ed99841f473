// The LED detector against exact switch-on instants: frame streams drawn here (several
// pulses, on at the start, dim, never on) and synthetic trials rendered by synth (a
// partial-exposure frame in lossless FFV1, noise, flicker, shake, bloom and saturation),
// with the LED's region given and located automatically.
#include "liftoff/video/led_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "liftoff/video/video_reader.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

namespace fs = std::filesystem;
using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::SourceDir;
using ::testing::HasSubstr;

// ---------------------------------------------------------------------------------------
// frame streams drawn here: a textured wall, a dark bar sliding down (something that
// moves, not a pulse) and an LED disc lit by the exact fraction of each exposure it was
// on

struct LedStream {
  cv::Size size{320, 240};
  double fps = 60.0;
  double exposure_s = 1.0 / 120.0;
  cv::Point led_px{250, 50};
  int radius_px = 5;
  cv::Scalar board_bgr{30, 30, 30};
  cv::Scalar off_bgr{40, 42, 45};
  cv::Scalar on_bgr{70, 90, 250};
  /// [on, off) intervals, video clock, s.
  std::vector<std::pair<double, double>> on_s;
  int frames = 100;

  double PeriodNs() const { return 1e9 / fps; }
  int64_t FrameNs(int index) const { return std::llround(index * PeriodNs()); }
  cv::Rect LedRoi() const {
    const int half = radius_px + 6;
    return cv::Rect(led_px.x - half, led_px.y - half, 2 * half + 1, 2 * half + 1);
  }
};

// Lit fraction of the exposure [t - E/2, t + E/2) (the timestamp is its middle).
double LitFraction(const LedStream& stream, int64_t t_ns) {
  const double start_s = static_cast<double>(t_ns) * 1e-9 - 0.5 * stream.exposure_s;
  const double end_s = start_s + stream.exposure_s;
  double lit_s = 0.0;
  for (const auto& [on_s, off_s] : stream.on_s) {
    lit_s += std::max(0.0, std::min(end_s, off_s) - std::max(start_s, on_s));
  }
  return lit_s / stream.exposure_s;
}

std::vector<Frame> DrawStream(const LedStream& stream) {
  cv::Mat wall(stream.size, CV_8UC3);
  cv::RNG rng(12345);
  rng.fill(wall, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(160));
  cv::GaussianBlur(wall, wall, cv::Size(0, 0), 3.0);
  cv::rectangle(wall, cv::Rect(stream.led_px.x - 20, stream.led_px.y - 20, 41, 41),
                stream.board_bgr, cv::FILLED);
  std::vector<Frame> frames;
  for (int index = 0; index < stream.frames; ++index) {
    cv::Mat off = wall.clone();
    cv::rectangle(off, cv::Rect(40, 60 + index, 60, 30), cv::Scalar(20, 25, 30), cv::FILLED);
    cv::Mat on = off.clone();
    cv::circle(off, stream.led_px, stream.radius_px, stream.off_bgr, cv::FILLED, cv::LINE_AA);
    cv::circle(on, stream.led_px, stream.radius_px, stream.on_bgr, cv::FILLED, cv::LINE_AA);
    Frame frame;
    frame.index = index;
    frame.t_ns = stream.FrameNs(index);
    const double lit = LitFraction(stream, frame.t_ns);
    cv::addWeighted(off, 1.0 - lit, on, lit, 0.0, frame.bgr);
    frames.push_back(std::move(frame));
  }
  return frames;
}

Result<LedResult> Detect(const std::vector<Frame>& frames, const LedDetector::Options& options) {
  LedDetector detector(options);
  for (const Frame& frame : frames) LIFTOFF_RETURN_IF_ERROR(detector.Process(frame));
  return detector.Finish();
}

LedDetector::Options WithRoi(cv::Rect roi, double exposure_s = 0.0) {
  LedDetector::Options options;
  options.roi_px = roi;
  options.exposure_s = exposure_s;
  return options;
}
LedDetector::Options Located(double exposure_s = 0.0) { return WithRoi(cv::Rect(), exposure_s); }

// Half the streams' exposure (1/120 s): frame n exposes [n/60 - kHalfExposureS, n/60 +
// kHalfExposureS).
constexpr double kHalfExposureS = 1.0 / 240.0;

// Three pulses: on and off mid-exposure, then a pulse of 12 frames between exposures.
LedStream ThreePulses() {
  LedStream stream;
  stream.on_s = {{0.2041 - kHalfExposureS, 0.4503 - kHalfExposureS},
                 {0.6025 - kHalfExposureS, 0.9377 - kHalfExposureS},
                 {1.19, 1.39}};
  stream.frames = 100;
  return stream;
}

TEST(LedDetector, ReportsEveryPulseWithItsOnAndOffInstants) {
  const LedStream stream = ThreePulses();
  const std::vector<Frame> frames = DrawStream(stream);
  for (const bool located : {false, true}) {
    // exposure known: partial frames date the switch exactly, others within the gap
    // between exposures (half of 1/120 s here); unknown: within half a frame
    for (const double exposure_s : {stream.exposure_s, 0.0}) {
      SCOPED_TRACE(std::string(located ? "located" : "roi") +
                   (exposure_s > 0 ? ", exposure known" : ", exposure unknown"));
      const auto result =
          Detect(frames, located ? Located(exposure_s) : WithRoi(stream.LedRoi(), exposure_s));
      ASSERT_TRUE(result.ok()) << result.status().ToString();
      ASSERT_EQ(result->pulses.size(), 3u) << result->Brief();
      EXPECT_TRUE(result->warnings.empty()) << result->warnings.front();
      for (size_t i = 0; i < 3; ++i) {
        const LedPulse& pulse = result->pulses[i];
        const double on_ns = stream.on_s[i].first * 1e9, off_ns = stream.on_s[i].second * 1e9;
        const double bound_ns = 0.5 * stream.PeriodNs();
        EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - on_ns), bound_ns) << "pulse " << i;
        EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - on_ns),
                  static_cast<double>(pulse.on_uncertainty_ns) + 1e5)
            << "pulse " << i;
        ASSERT_TRUE(pulse.off_ns.has_value()) << "pulse " << i;
        EXPECT_LE(std::abs(static_cast<double>(*pulse.off_ns) - off_ns), bound_ns) << "pulse " << i;
        EXPECT_LE(std::abs(static_cast<double>(*pulse.off_ns) - off_ns),
                  static_cast<double>(pulse.off_uncertainty_ns) + 1e5)
            << "pulse " << i;
      }
      // partial frames: frame 12 ([0.2 - 1/240, 0.2 + 1/240) s) is lit 51 %, frame 36 70 %,
      // frame 56 (the second switch-off) 52 %; with the exposure known they date the switch
      // exactly
      EXPECT_EQ(result->pulses[0].first_lit_frame, 12);
      EXPECT_NEAR(result->pulses[0].first_lit_fraction, 0.508, 0.02);
      EXPECT_EQ(result->pulses[1].first_lit_frame, 36);
      EXPECT_NEAR(result->pulses[1].first_lit_fraction, 0.7, 0.02);
      EXPECT_EQ(result->pulses[2].first_lit_frame, 72);
      EXPECT_EQ(result->pulses[2].first_lit_fraction, 1.0);
      if (exposure_s > 0) {
        const double close_ns = 0.02 * stream.PeriodNs();
        EXPECT_NEAR(static_cast<double>(result->pulses[0].on_ns), stream.on_s[0].first * 1e9,
                    close_ns);
        EXPECT_NEAR(static_cast<double>(result->pulses[1].on_ns), stream.on_s[1].first * 1e9,
                    close_ns);
        EXPECT_NEAR(static_cast<double>(*result->pulses[1].off_ns), stream.on_s[1].second * 1e9,
                    close_ns);
      }
      EXPECT_EQ(result->roi_located, located);
      // the brightness trace, with an ROI: every frame at its time, dark, lit, and the
      // partly lit frame 12 (51 %) about half way between
      if (located) {
        EXPECT_TRUE(result->trace_t_ns.empty());
        EXPECT_TRUE(result->trace_brightness_levels.empty());
        continue;
      }
      ASSERT_EQ(result->trace_t_ns.size(), frames.size());
      ASSERT_EQ(result->trace_brightness_levels.size(), frames.size());
      for (size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(result->trace_t_ns[i], frames[i].t_ns) << "frame " << i;
      }
      const std::vector<double>& levels = result->trace_brightness_levels;
      const double off = result->off_level, contrast = result->on_level - result->off_level;
      ASSERT_GT(contrast, 10.0);
      EXPECT_NEAR(levels[5], off, 0.05 * contrast);
      EXPECT_NEAR(levels[20], result->on_level, 0.05 * contrast);
      EXPECT_NEAR((levels[12] - off) / contrast, 0.508, 0.05);
    }
  }
}

// ---------------------------------------------------------------------------------------
// a tiny LED in a big region: 1 px radius, its core saturating, a faint glow, inside a
// 64 x 64 px region of a bright textured wall under row-banded mains flicker (each row's
// brightness swings with a phase that walks from frame to frame: not the frame-wide gain
// the detector takes out) and sensor noise. The sensor adds the LED's light times its lit
// fraction before clipping, so a partly lit frame's core clips too: not the linear
// blend the detector's dating assumes.

struct TinyLedStream {
  double fps = 30.0;
  double exposure_s = 0.7 / 30.0;  // not told to the detector
  std::optional<double> on_s;      // switch-on, video clock
  std::vector<int> dropped;        // frames left out of the stream (a variable frame rate)
  int frames = 90;
  double noise_sigma = 4.0;  // sensor noise, levels
  // From the first lit frame on, the 16 x 16 block around the LED renewed by a codec: each
  // pixel of the wall there moves by this many levels up or down (a fixed random pattern).
  double renew_block_levels = 0.0;
  // Frames [first, last) during which a highlight just left of the ROI (a blurred spot of
  // +150 levels, 4 px outside) is carried 3 px right, its edge into the ROI's first
  // columns: a shaken camera or a moving part showing something bright at the border.
  std::optional<std::pair<int, int>> border_highlight_frames;
  // From this frame on, a faint still glint (3 px, +glint_levels in every channel) 12 px
  // left of the LED: a codec's update of a block, a reflection that came and stayed.
  std::optional<int> glint_from_frame;
  double glint_levels = 9.0;
  // A frozen picture (H.264 skipping a still, noiseless scene): no flicker. A faint LED:
  // its light times light_scale. From the first lit frame on, every pixel moved by
  // +-refresh_levels (a fixed random pattern: the codec renewed the whole picture then),
  // and brighten_after_frames later the LED's light brighten_factor times as strong (the
  // codec refining its spot).
  bool flicker = true;
  // The flicker's amplitude, and whether it scales the LED's light with the picture (a
  // renderer's flicker applied to the whole image) or only the wall (a lamp's).
  double flicker_amplitude = 0.08;
  bool flicker_scales_led = false;
  double light_scale = 1.0;
  double wall_scale = 1.0;  // the wall's brightness (90 .. 200 levels) times this
  double refresh_levels = 0.0;
  int brighten_after_frames = 0;
  double brighten_factor = 1.0;
  // The light of the first lit frames shown at these fractions of what they saw (a codec
  // building a small spot up over a few frames), from the first lit frame on.
  std::vector<double> build_up;
  cv::Point led_px{212, 96};
  cv::Rect Roi() const { return cv::Rect(led_px.x - 30, led_px.y - 34, 64, 64); }
  double PeriodNs() const { return 1e9 / fps; }
};

std::vector<Frame> DrawTinyLedStream(const TinyLedStream& stream) {
  const cv::Size size(320, 240);
  cv::Mat wall(size, CV_32FC3);
  cv::RNG rng(777);
  rng.fill(wall, cv::RNG::UNIFORM, cv::Scalar::all(90), cv::Scalar::all(200));
  cv::GaussianBlur(wall, wall, cv::Size(0, 0), 2.0);
  wall *= stream.wall_scale;
  // the LED's light when fully lit (B, G, R): a core far beyond the sensor's range on its
  // centre pixel, half of it on the four neighbours, and a glow of sigma 1.2 px
  cv::Mat light(size, CV_32FC3, cv::Scalar::all(0));
  for (int dy = -4; dy <= 4; ++dy) {
    for (int dx = -4; dx <= 4; ++dx) {
      const double glow = std::exp(-(dx * dx + dy * dy) / (2 * 1.2 * 1.2));
      const double core = (dx == 0 && dy == 0) ? 1.0 : (std::abs(dx) + std::abs(dy) == 1 ? 0.5 : 0.0);
      light.at<cv::Vec3f>(stream.led_px + cv::Point(dx, dy)) =
          cv::Vec3f(static_cast<float>(10 * glow), static_cast<float>(25 * glow + 60 * core),
                    static_cast<float>(90 * glow + 600 * core));
    }
  }
  std::vector<Frame> frames;
  cv::RNG noise(4242);
  for (int index = 0; index < stream.frames; ++index) {
    if (std::find(stream.dropped.begin(), stream.dropped.end(), index) != stream.dropped.end()) {
      continue;
    }
    const double t_s = index / stream.fps;
    // lit fraction of the exposure centred on t
    double lit = 0.0;
    if (stream.on_s) {
      const double start_s = t_s - 0.5 * stream.exposure_s;
      lit = std::clamp((start_s + stream.exposure_s - *stream.on_s) / stream.exposure_s, 0.0, 1.0);
    }
    cv::Mat picture = wall.clone();
    const double phase = 0.37 * index;
    const auto scale_rows = [&](cv::Mat& image) {
      for (int y = 0; y < size.height && stream.flicker; ++y) {
        image.row(y) *= 1.0 + stream.flicker_amplitude * std::sin(2 * CV_PI * (y / 90.0 + phase));
      }
    };
    if (!stream.flicker_scales_led) scale_rows(picture);
    const double on_frames = stream.on_s ? t_s * stream.fps - *stream.on_s * stream.fps : -1.0;
    const bool refined = stream.brighten_after_frames > 0 && on_frames >= stream.brighten_after_frames;
    // (the how-manieth lit frame this is, 1 for the first)
    const double lit_frames = std::ceil(on_frames + 0.5 * stream.exposure_s * stream.fps);
    const double shown = lit > 0 && lit_frames >= 1 &&
                                 lit_frames <= static_cast<double>(stream.build_up.size())
                             ? stream.build_up[static_cast<size_t>(lit_frames) - 1]
                             : 1.0;
    picture += lit * shown * stream.light_scale * (refined ? stream.brighten_factor : 1.0) * light;
    if (stream.flicker_scales_led) scale_rows(picture);
    if (lit > 0 && stream.refresh_levels > 0) {
      cv::Mat pattern(size, CV_32FC3);
      cv::RNG(555).fill(pattern, cv::RNG::UNIFORM, cv::Scalar::all(-stream.refresh_levels),
                        cv::Scalar::all(stream.refresh_levels));
      picture += pattern;
    }
    if (stream.glint_from_frame && index >= *stream.glint_from_frame) {
      for (int dx = 0; dx < 3; ++dx) {
        picture.at<cv::Vec3f>(stream.led_px + cv::Point(-12 + dx, 0)) +=
            cv::Vec3f::all(static_cast<float>(stream.glint_levels));
      }
    }
    if (stream.border_highlight_frames) {
      const auto [first, last] = *stream.border_highlight_frames;
      const bool in = index >= first && index < last;
      const cv::Point centre(stream.Roi().x - (in ? 1 : 4), stream.Roi().y + 30);
      for (int dy = -6; dy <= 6; ++dy) {
        for (int dx = -6; dx <= 6; ++dx) {
          const auto level = static_cast<float>(150 * std::exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5)));
          picture.at<cv::Vec3f>(centre + cv::Point(dx, dy)) += cv::Vec3f(level, level, level);
        }
      }
    }
    if (lit > 0 && stream.renew_block_levels > 0) {
      const cv::Rect block(stream.led_px.x / 16 * 16, stream.led_px.y / 16 * 16, 16, 16);
      cv::RNG signs(99);
      for (int y = block.y; y < block.y + 16; ++y) {
        for (int x = block.x; x < block.x + 16; ++x) {
          const float change = static_cast<float>(
              (signs.uniform(0, 2) == 0 ? -1 : 1) * stream.renew_block_levels);
          picture.at<cv::Vec3f>(y, x) += cv::Vec3f(change, change, change);
        }
      }
    }
    cv::Mat grain(size, CV_32FC3);
    noise.fill(grain, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(stream.noise_sigma));
    picture += grain;
    Frame frame;
    frame.index = static_cast<int64_t>(frames.size());
    frame.t_ns = std::llround(t_s * 1e9);
    picture.convertTo(frame.bgr, CV_8UC3);  // rounds and clips at 0 and 255
    frames.push_back(std::move(frame));
  }
  return frames;
}

// The stream's ROI gives one pulse, its switch-on within half a frame of the truth.
void ExpectOnePulseWithinHalfAFrame(const TinyLedStream& stream) {
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
  EXPECT_LE(std::abs(static_cast<double>(result->pulses[0].on_ns) - *stream.on_s * 1e9),
            0.5 * stream.PeriodNs())
      << result->Brief();
}

// The stream's ROI gives one pulse, its switch-on within half a frame of the truth and
// inside its interval: the result, or nullopt (with a failure) when it is not one pulse.
std::optional<LedResult> DetectOnePulseAroundTheTruth(const TinyLedStream& stream) {
  auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  if (!result.ok()) return std::nullopt;
  EXPECT_EQ(result->pulses.size(), 1u) << result->Brief();
  if (result->pulses.size() != 1) return std::nullopt;
  const LedPulse& pulse = result->pulses[0];
  const double error_ns = static_cast<double>(pulse.on_ns) - *stream.on_s * 1e9;
  EXPECT_LE(std::abs(error_ns), 0.5 * stream.PeriodNs()) << result->Brief();
  EXPECT_LE(std::abs(error_ns), static_cast<double>(pulse.on_uncertainty_ns)) << result->Brief();
  return std::move(result).value();
}

// Whether the result says the switch-on was built up over frames by a codec.
bool SaysBuiltUp(const LedResult& result) {
  return std::any_of(result.warnings.begin(), result.warnings.end(),
                     [](const std::string& w) { return w.find("built up over ") == 0; });
}

TEST(LedDetector, FindsATinySaturatingLedInABigFlickeringNoisyRegion) {
  TinyLedStream stream;
  // frame 45 (1.5 s) exposes [1.5 - 0.35 T, 1.5 + 0.35 T): on 30 % of the way into it
  const double exposure_s = stream.exposure_s;
  stream.on_s = 1.5 - 0.5 * exposure_s + 0.3 * exposure_s;
  const std::optional<LedResult> result = DetectOnePulseAroundTheTruth(stream);
  ASSERT_TRUE(result);
  EXPECT_GE(result->contrast_levels, 100.0);
  EXPECT_FALSE(SaysBuiltUp(*result)) << result->Brief();
}

// Rolling bands of +-amplitude over a dimmed wall and a faint LED switching on 40 % into
// frame 45's exposure (nothing clips, not even at the flicker's brightest up to +-50 %).
TinyLedStream BandedStream(double amplitude, bool flicker_scales_led) {
  TinyLedStream stream;
  stream.flicker_amplitude = amplitude;
  stream.flicker_scales_led = flicker_scales_led;
  stream.wall_scale = 0.5;
  stream.light_scale = 0.4;
  stream.noise_sigma = 1.0;
  stream.on_s = 1.5 - 0.5 * stream.exposure_s + 0.4 * stream.exposure_s;
  return stream;
}

// Bands of +-25 %: the partly lit frame measured 60 % lit, the instant within a quarter frame.
void ExpectABandedLedDatedFromItsPartlyLitFrame(bool flicker_scales_led) {
  const TinyLedStream stream = BandedStream(0.25, flicker_scales_led);
  const std::optional<LedResult> result = DetectOnePulseAroundTheTruth(stream);
  ASSERT_TRUE(result);
  EXPECT_NEAR(result->pulses[0].first_lit_fraction, 0.6, 0.05) << result->Brief();
  EXPECT_LE(result->pulses[0].on_uncertainty_ns, 0.25 * stream.PeriodNs()) << result->Brief();
}

// A renderer's flicker scales the whole picture, the LED's light too: its lit frames swing
// with the bands, but its light over its row's gain holds.
TEST(LedDetector, ALedTheFlickerScalesWithThePictureIsDatedByItsLightOverTheGain) {
  ExpectABandedLedDatedFromItsPartlyLitFrame(true);
}

// The same bands over an LED on its own supply (the flicker scales the wall, not its light):
// its light with the scene's flicker taken out holds.
TEST(LedDetector, ALedOnItsOwnSupplyUnderTheSameBandsIsDatedByItsOwnLight) {
  ExpectABandedLedDatedFromItsPartlyLitFrame(false);
}

// Bands of +-50 % that scale the LED's light with the picture: its lit frames with the
// scene's flicker taken out swing by half the step either way, beyond any step's flatness,
// so only its light over its row's gain finds it (`liftoff synth --set hard3d --seed 27000
// --flicker 0.4 --exposure-ms 2`: 4 of the 9 LEDs found without it, 8 with it).
TEST(LedDetector, ALedStrongFlickerScalesWithThePictureIsFoundByItsLightOverTheGain) {
  ASSERT_TRUE(DetectOnePulseAroundTheTruth(BandedStream(0.5, true)));
}

// The same, and a glint on its own light (3 px, 28 levels) that came 25 frames before the
// LED: the first reading finds the glint and not the LED, the second the LED, far brighter,
// which wins (with the first reading's switch-on preferred whatever its contrast, the glint
// was the LED, 25 frames early).
TEST(LedDetector, UnderStrongFlickerAFaintRiseOfTheFirstReadingLosesToTheLed) {
  TinyLedStream stream = BandedStream(0.5, true);
  stream.glint_from_frame = 20;
  stream.glint_levels = 28.0;
  ASSERT_TRUE(DetectOnePulseAroundTheTruth(stream));
}

// The same bands over the same wall with the LED never lit: no switch-on either way.
TEST(LedDetector, StrongFlickerWithNoLedLitIsNoSwitchOn) {
  TinyLedStream stream = BandedStream(0.5, true);
  stream.on_s.reset();
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_FALSE(result.ok()) << result->Brief();
  EXPECT_NE(result.status().message().find("never switches on"), std::string::npos)
      << result.status().ToString();
}

// A codec that renews the LED's block when the LED lights moves every pixel of that block
// a little, half of them down; on a frozen (noiseless) picture those are clear steps. Only
// strong opposite steps make an edge, so the switch-on is still found.
TEST(LedDetector, FindsTheSwitchOnWhenACodecRenewsTheLedsBlockAroundIt) {
  TinyLedStream stream;
  stream.noise_sigma = 0.0;
  stream.renew_block_levels = 12.0;
  stream.on_s = 1.5;
  ExpectOnePulseWithinHalfAFrame(stream);
}

// Low light and shake (hard3d-02): a highlight carried across the ROI's border for six
// frames just before the switch-on is no pulse, and does not hide the switch-on.
TEST(LedDetector, AHighlightCarriedIntoTheRoisBorderIsNoSwitchOn) {
  TinyLedStream stream;
  stream.on_s = 1.5;
  stream.border_highlight_frames = std::make_pair(38, 44);
  ExpectOnePulseWithinHalfAFrame(stream);
  // ... nor a switch-on of its own, with no LED at all
  stream.on_s.reset();
  const auto without = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  EXPECT_FALSE(without.ok()) << without->Brief();
}

// A faint LED whose contrast does not stand out from what the frame's noise and flicker do
// to its cells' brightest pixels, but whose pixels stand out from the ROI's (hard3d-06
// re-drawn with --seed 2000: switched on as H.264 renewed the whole still picture).
TEST(LedDetector, AFaintLedIsFoundByItsPixelsStandingOutInTheRoi) {
  TinyLedStream stream;
  stream.light_scale = 0.15;
  stream.on_s = 1.5 - 0.5 * stream.exposure_s;  // frame 45 is the first lit, wholly
  ExpectOnePulseWithinHalfAFrame(stream);
}

// A codec refines a small LED's spot over several frames (the same clip: 8 frames after the
// switch-on, by more than its step): the light going on brightening, not a second switch-on.
TEST(LedDetector, ALedThatGoesOnBrighteningIsOneSwitchOn) {
  TinyLedStream stream;
  stream.light_scale = 0.3;
  stream.brighten_after_frames = 8;
  stream.brighten_factor = 4;
  stream.on_s = 1.5 - 0.5 * stream.exposure_s;
  ExpectOnePulseWithinHalfAFrame(stream);
}

// A faint tiny LED on a frozen (noiseless, flicker-free) picture, switched on half way into
// frame 45's exposure, its first lit frames shown at `build_up` of what they saw.
TinyLedStream FrozenFaintLed(std::vector<double> build_up) {
  TinyLedStream stream;
  stream.noise_sigma = 0.0;
  stream.flicker = false;
  stream.light_scale = 0.05;
  stream.build_up = std::move(build_up);
  stream.on_s = 1.5;
  return stream;
}

// A faint tiny LED on a frozen picture, half lit in frame 45 and built up by H.264 over
// three frames (hard3d-06 re-drawn with --seed 4000: its brightest pixel shown 0.67, 0.80,
// 0.93 of its level, the ROI's signal 0.40, 0.60, 0.88; here 0.6, 0.7, 0.9): the frame
// after a partly lit one still short of the level is the codec, not a transition to come.
TEST(LedDetector, AFaintLedACodecBuildsUpOverFramesIsFound) {
  const std::optional<LedResult> result =
      DetectOnePulseAroundTheTruth(FrozenFaintLed({1.2, 0.7, 0.9}));
  ASSERT_TRUE(result);
  // a step whose frames after it creep up: dated by its partly lit frame, no build-up, and
  // the two frames lit part way widen the interval over both
  EXPECT_FALSE(SaysBuiltUp(*result)) << result->Brief();
  EXPECT_GE(result->pulses[0].spread_frames, 2) << result->Brief();
}

// H.264's B-frames blend a faint tiny LED's step between their reference frames (hard3d-06
// with --seed 20000 --keyframe-interval 250 --led-on-spread 1: P-frame 87 dark, B-frames 88
// and 89 at 0.29 and 0.68 of the step, P-frame 90 whole; 88 was half lit). Two frames in a
// row lit part way is no switch-on's: it is dated where the two cross half lit (here half a
// frame late: the blend put more of the step after the switch-on than before), and its
// interval reaches from the last dark frame to the first whole one and says so.
TEST(LedDetector, AStepACodecBlendsOverTwoFramesWidensItsIntervalOverBoth) {
  TinyLedStream stream = FrozenFaintLed({0.66, 0.67});
  const double t45_ns = 45 * stream.PeriodNs();
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
  const LedPulse& pulse = result->pulses[0];
  EXPECT_EQ(pulse.spread_frames, 2) << result->Brief();
  const double error_ns = static_cast<double>(pulse.on_ns) - *stream.on_s * 1e9;
  EXPECT_LE(std::abs(error_ns), static_cast<double>(pulse.on_uncertainty_ns)) << result->Brief();
  // the exposure not told: from frame 44's timestamp to frame 47's at least
  EXPECT_LE(static_cast<double>(pulse.on_ns - pulse.on_uncertainty_ns),
            t45_ns - stream.PeriodNs() + 1e3);
  EXPECT_GE(static_cast<double>(pulse.on_ns + pulse.on_uncertainty_ns),
            t45_ns + 2 * stream.PeriodNs() - 1e3);
  EXPECT_EQ(pulse.first_lit_frame, 45) << result->Brief();
  EXPECT_TRUE(std::any_of(result->warnings.begin(), result->warnings.end(),
                          [](const std::string& w) {
                            return w.find("part way over 2 frames in a row from frame 45") !=
                                   std::string::npos;
                          }))
      << ::testing::PrintToString(result->warnings);
  // one half-lit frame is the light's own: no spread
  const std::optional<LedResult> plain = DetectOnePulseAroundTheTruth(FrozenFaintLed({}));
  ASSERT_TRUE(plain);
  EXPECT_LE(plain->pulses[0].spread_frames, 1) << plain->Brief();
}

// A build-up the one-step window cannot see (hard3d-06 drawn with --rise-slowdown 3): the
// detector dates the first frame that changed, lit for an unknown part of its exposure, and
// says so.
void ExpectABuiltUpSwitchOn(const TinyLedStream& stream) {
  const std::optional<LedResult> result = DetectOnePulseAroundTheTruth(stream);
  ASSERT_TRUE(result);
  const LedPulse& pulse = result->pulses[0];
  EXPECT_EQ(pulse.first_lit_frame, 45) << result->Brief();
  // with the exposure unknown: from frame 44's timestamp to half a frame after frame 45's
  const double t45_ns = 45 * stream.PeriodNs();
  EXPECT_NEAR(static_cast<double>(pulse.on_ns), t45_ns - 0.25 * stream.PeriodNs(), 1e3);
  EXPECT_NEAR(static_cast<double>(pulse.on_uncertainty_ns), 0.75 * stream.PeriodNs(), 1e3);
  EXPECT_TRUE(SaysBuiltUp(*result))
      << result->Brief() << "; " << ::testing::PrintToString(result->warnings);
}

// H.264 showed the half-lit switch-on frame at 61 % of the step in the LED's pixels, held
// that for 7 frames and caught up over 3 (seed 10000, where the switch-on also came with a
// renewal of the whole picture): the catch-up alone is a clean step, 8 frames late.
TEST(LedDetector, ALedACodecHoldsAtAPartialLevelIsDatedFromItsFirstFrame) {
  TinyLedStream stream = FrozenFaintLed({1.2, 0.6, 0.6, 0.6, 0.6, 0.6, 0.6, 0.75, 0.9});
  stream.refresh_levels = 2.0;
  ExpectABuiltUpSwitchOn(stream);
}

// The LED's pixels wobbled by a third of the step for 6 frames after a half-lit switch-on
// frame (seed 11000): no window of one step frame is flat after it.
TEST(LedDetector, ALedThatWobblesAfterItsSwitchOnIsDatedFromItsFirstFrame) {
  ExpectABuiltUpSwitchOn(FrozenFaintLed({1.0, 0.9, 0.75, 0.6, 0.7, 0.9}));
}

// A faint glint that came and stayed 25 frames before (its contrast under half the LED's,
// so no pulse, but a level the ROI holds) does not stop a build-up 3 times its step.
TEST(LedDetector, AFainterRiseBeforeABuildUpDoesNotHideIt) {
  TinyLedStream stream = FrozenFaintLed({1.0, 0.9, 0.75, 0.6, 0.7, 0.9});
  stream.light_scale = 0.15;
  stream.glint_from_frame = 20;
  ExpectABuiltUpSwitchOn(stream);
}

TEST(LedDetector, ADroppedFrameAtTheSwitchOnWidensTheIntervalToTheRealTimestamps) {
  TinyLedStream stream;
  stream.on_s = 1.5 - 0.2 * stream.exposure_s;  // inside frame 45's exposure, which is dropped
  stream.dropped = {45};
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
  const LedPulse& pulse = result->pulses[0];
  // the last dark frame is at 44 T, the first lit one at 46 T: the switch-on lies between
  // them; taking the missing frame 45 T as the first lit ([44 T, 45.5 T] over every
  // exposure up to T) dates it at 44.75 T, and the uncertainty reaches both frames seen
  const double error_ns = static_cast<double>(pulse.on_ns) - *stream.on_s * 1e9;
  EXPECT_LE(std::abs(error_ns), static_cast<double>(pulse.on_uncertainty_ns)) << result->Brief();
  EXPECT_LE(std::abs(error_ns), 0.5 * stream.PeriodNs()) << result->Brief();
  EXPECT_EQ(pulse.missing_frames_before_on, 1);
  EXPECT_NEAR(static_cast<double>(pulse.on_ns), 44.75 * stream.PeriodNs(), 1e3);
  EXPECT_NEAR(static_cast<double>(pulse.on_uncertainty_ns), 1.25 * stream.PeriodNs(), 1e3);
}

TEST(LedDetector, FramesDroppedFromTheSwitchOnAreDatedAtTheFirstMissingFrame) {
  TinyLedStream stream;
  stream.on_s = 1.5 - 0.2 * stream.exposure_s;  // inside frame 45's exposure
  stream.dropped = {45, 46};                    // the first lit frame and the next
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
  const LedPulse& pulse = result->pulses[0];
  // dark at 44 T, lit at 47 T; frame 45 T taken as the first lit, for an exposure of up to
  // T (not told): [44 T, 45.5 T], dated at 44.75 T, within half a frame of the truth
  // (44.86 T); the uncertainty still reaches both frames seen (2.25 T)
  EXPECT_EQ(pulse.missing_frames_before_on, 2);
  EXPECT_NEAR(static_cast<double>(pulse.on_ns), 44.75 * stream.PeriodNs(), 1e3);
  EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - *stream.on_s * 1e9),
            0.5 * stream.PeriodNs());
  EXPECT_NEAR(static_cast<double>(pulse.on_uncertainty_ns), 2.25 * stream.PeriodNs(), 1e3);
  ASSERT_EQ(result->warnings.size(), 1u) << result->Brief();
  EXPECT_NE(result->warnings[0].find("2 frames missing just before the switch-on"),
            std::string::npos)
      << result->warnings[0];
}

TEST(LedDetector, FramesDroppedBeforeTheSwitchOnStillHoldTheTruthInTheInterval) {
  // the drop begins a frame before the one that saw the switch-on: the estimate (the first
  // missing frame) is a frame early, and the interval still holds the truth
  TinyLedStream stream;
  stream.on_s = 1.5 - 0.2 * stream.exposure_s;
  stream.dropped = {44, 45};
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
  const LedPulse& pulse = result->pulses[0];
  EXPECT_EQ(pulse.missing_frames_before_on, 2);
  EXPECT_NEAR(static_cast<double>(pulse.on_ns), 43.75 * stream.PeriodNs(), 1e3);
  EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - *stream.on_s * 1e9),
            static_cast<double>(pulse.on_uncertainty_ns));
}

TEST(LedDetector, TinyLedNeverOnInAFlickeringNoisyRegionIsNotFound) {
  TinyLedStream stream;  // no switch-on
  const auto result = Detect(DrawTinyLedStream(stream), WithRoi(stream.Roi()));
  ASSERT_FALSE(result.ok()) << result->Brief();
  EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(result.status().message(), HasSubstr("the LED never switches on"));
}

TEST(LedDetector, WarnsWhenTheLedIsAlreadyOnAtTheStart) {
  LedStream stream;
  stream.on_s = {{0.0, 0.3}, {0.6, 2.0}};
  const std::vector<Frame> frames = DrawStream(stream);
  for (const LedDetector::Options& options : {WithRoi(stream.LedRoi()), Located()}) {
    const auto result = Detect(frames, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_EQ(result->pulses.size(), 1u);
    EXPECT_NEAR(static_cast<double>(result->pulses[0].on_ns), 0.6e9, 0.5 * stream.PeriodNs());
    ASSERT_EQ(result->warnings.size(), 1u);
    EXPECT_THAT(result->warnings[0], HasSubstr("already on"));
  }
}

TEST(LedDetector, OnAllAlongAndOffOnceIsNotASwitchOn) {
  LedStream stream;
  stream.on_s = {{0.0, 0.5}};
  const auto result = Detect(DrawStream(stream), Located());
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(result.status().message(), HasSubstr("already on"));
}

TEST(LedDetector, WarnsWhenTheLedIsDim) {
  // the brightest channel rises by 14 grey levels (red 45 -> 59)
  LedStream stream;
  stream.on_bgr = cv::Scalar(40, 42, 59);
  stream.radius_px = 6;
  stream.on_s = {{0.5, 2.0}};
  const std::vector<Frame> frames = DrawStream(stream);
  for (const LedDetector::Options& options : {WithRoi(stream.LedRoi()), Located()}) {
    const auto result = Detect(frames, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    EXPECT_NEAR(result->contrast_levels, 14.0, 1.0);
    EXPECT_NEAR(static_cast<double>(result->pulses.at(0).on_ns), 0.5e9, 0.5 * stream.PeriodNs());
    ASSERT_EQ(result->warnings.size(), 1u);
    EXPECT_THAT(result->warnings[0], HasSubstr("dim: on-off contrast 14 grey levels"));
  }
}

// A dim LED's step (14 levels) switched on half way into frame 30's exposure, that frame
// shown as the frame `shown_as` (a lossy codec copies or drops a step of a few grey levels
// whole), the exposure not told: the result's switch-on.
std::optional<LedPulse> DimStepShownAs(int shown_as, bool clipped) {
  LedStream stream;
  stream.on_bgr = cv::Scalar(40, 42, 59);
  if (clipped) {  // the lit LED at 255 in its brightest channel
    stream.off_bgr = cv::Scalar(230, 232, 241);
    stream.on_bgr = cv::Scalar(230, 232, 255);
  }
  stream.radius_px = 6;
  stream.on_s = {{0.5, 2.0}};
  std::vector<Frame> frames = DrawStream(stream);
  EXPECT_NEAR(LitFraction(stream, frames[30].t_ns), 0.5, 1e-9);
  frames[static_cast<size_t>(shown_as)]
      .bgr(stream.LedRoi())
      .copyTo(frames[30].bgr(stream.LedRoi()));
  const auto result = Detect(frames, WithRoi(stream.LedRoi(), clipped ? stream.exposure_s : 0.0));
  EXPECT_TRUE(result.ok()) << result.status().ToString();
  if (!result.ok() || result->pulses.size() != 1) return std::nullopt;
  return result->pulses[0];
}

// Both ways (hard3d-06's 0.6 px LED half lit at 2.0 s: --seed 0, and --seed 1000
// --keyframe-interval 250 --rise-slowdown 3): the
// switch-on is dated half way between the last frame shown dark and the first shown lit,
// half a frame from the truth either way, and its interval holds the truth. When the lit
// LED clips its first lit frame may have been lit for any part of its exposure (a clipped
// core looks lit whole), so the estimate is later, but with the exposure told the interval
// still holds the truth (before, with the last dark frame lit at most 0.15, it did not).
TEST(LedDetector, ADimStepsHalfLitFrameShownDarkOrLitIsDatedBetweenTheTwo) {
  const double period_ns = 1e9 / 60.0;
  for (const bool clipped : {false, true}) {
    for (const int shown_as : {29, 31}) {
      SCOPED_TRACE(std::string(shown_as == 29 ? "shown dark" : "shown lit") +
                   (clipped ? ", clipped" : ""));
      const std::optional<LedPulse> pulse = DimStepShownAs(shown_as, clipped);
      ASSERT_TRUE(pulse);
      const double middle_ns = (shown_as == 29 ? 30.5 : 29.5) * period_ns;
      if (!clipped) {
        EXPECT_NEAR(static_cast<double>(pulse->on_ns), middle_ns, 0.05 * period_ns);
      }
      EXPECT_LE(std::abs(static_cast<double>(pulse->on_ns) - 0.5e9),
                static_cast<double>(pulse->on_uncertainty_ns) + 1e3);
    }
  }
}

TEST(LedDetector, ADimLedsPartlyLitFrameShownFullyLitStillHoldsTheTruth) {
  // a 14-level step half lit in frame 30 (0.5 s mid-exposure), but shown as lit as the
  // next frame, as a lossy codec copies a step of a few grey levels whole (hard3d-06), the
  // exposure told: each frame's fraction is known to within half the step either way, so
  // the switch-on is dated half way between frames 29 and 30, the truth at the interval's
  // end (before, only the upper bound was widened: 0.29 frame early)
  LedStream stream;
  stream.on_bgr = cv::Scalar(40, 42, 59);
  stream.radius_px = 6;
  stream.on_s = {{0.5, 2.0}};
  std::vector<Frame> frames = DrawStream(stream);
  ASSERT_NEAR(LitFraction(stream, frames[30].t_ns), 0.5, 1e-9);
  frames[31].bgr(stream.LedRoi()).copyTo(frames[30].bgr(stream.LedRoi()));
  const auto result = Detect(frames, WithRoi(stream.LedRoi(), stream.exposure_s));
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  const LedPulse& pulse = result->pulses.at(0);
  EXPECT_EQ(pulse.first_lit_frame, 30);
  EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - 0.5e9),
            static_cast<double>(pulse.on_uncertainty_ns) + 1e3);
  EXPECT_NEAR(static_cast<double>(pulse.on_ns), 29.5 * stream.PeriodNs(), 0.05 * stream.PeriodNs());
}

TEST(LedDetector, FindsAnLedOnABrightBoard) {
  // the board is brighter than the lit LED in two channels: the brightest pixel barely
  // changes, the LED's mean does
  LedStream stream;
  stream.board_bgr = cv::Scalar(225, 225, 225);
  stream.on_s = {{0.5, 2.0}};
  const std::vector<Frame> frames = DrawStream(stream);
  for (const LedDetector::Options& options : {WithRoi(stream.LedRoi()), Located()}) {
    const auto result = Detect(frames, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_EQ(result->pulses.size(), 1u);
    EXPECT_NEAR(static_cast<double>(result->pulses[0].on_ns), 0.5e9, 0.5 * stream.PeriodNs());
    EXPECT_GE(result->contrast_levels, 20.0);
  }
}

TEST(LedDetector, LedFainterThanTheMinimumContrastIsNotFound) {
  LedStream stream;
  stream.on_bgr = cv::Scalar(40, 42, 50);  // +5 grey levels
  stream.radius_px = 6;
  stream.on_s = {{0.5, 2.0}};
  const std::vector<Frame> frames = DrawStream(stream);
  for (const LedDetector::Options& options : {WithRoi(stream.LedRoi()), Located()}) {
    const auto result = Detect(frames, options);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
    EXPECT_THAT(result.status().message(), HasSubstr("never switches on"));
    EXPECT_THAT(result.status().message(), HasSubstr("5 grey levels"));
  }
  // a lower minimum accepts it, with a warning
  LedDetector::Options options = Located();
  options.min_contrast_levels = 3.0;
  const auto result = Detect(frames, options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_FALSE(result->warnings.empty());
}

TEST(LedDetector, LedNeverOnIsNotFound) {
  LedStream stream;  // nothing lit; only the bar moves
  const std::vector<Frame> frames = DrawStream(stream);
  for (const LedDetector::Options& options : {WithRoi(stream.LedRoi()), Located()}) {
    const auto result = Detect(frames, options);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
    EXPECT_THAT(result.status().message(), HasSubstr("the LED never switches on"));
  }
}

TEST(LedDetector, RoiOutsideTheFrameIsInvalidArgument) {
  LedStream stream;
  stream.frames = 2;
  const std::vector<Frame> frames = DrawStream(stream);
  LedDetector detector(WithRoi(cv::Rect(300, 200, 40, 60)));
  const Status status = detector.Process(frames[0]);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), "LED ROI 40x60 at (300, 200) is outside the 320x240 frame");
}

TEST(LedDetector, FramesOutOfOrderOrOfAnotherSizeAreInvalidArgument) {
  LedStream stream;
  stream.frames = 3;
  std::vector<Frame> frames = DrawStream(stream);
  LedDetector detector(Located());
  ASSERT_TRUE(detector.Process(frames[1]).ok());
  EXPECT_EQ(detector.Process(frames[0]).code(), StatusCode::kInvalidArgument);
  cv::resize(frames[2].bgr, frames[2].bgr, cv::Size(160, 120));
  EXPECT_EQ(detector.Process(frames[2]).code(), StatusCode::kInvalidArgument);
}

TEST(LedDetector, NoFrameIsInvalidArgument) {
  LedDetector detector(Located());
  EXPECT_EQ(detector.Finish().status().code(), StatusCode::kInvalidArgument);
}

TEST(LedDetector, OptionsOutOfRangeAreNamed) {
  const auto message = [](auto change) {
    LedDetector::Options options;
    change(options);
    return options.Validate().message();
  };
  EXPECT_TRUE(LedDetector::Options{}.Validate().ok());
  EXPECT_THAT(message([](auto& o) { o.cell_px = 2; }), HasSubstr("cell_px"));
  EXPECT_THAT(message([](auto& o) { o.threshold_frac = 1.0; }), HasSubstr("threshold_frac"));
  EXPECT_THAT(message([](auto& o) { o.min_on_frames = 0; }), HasSubstr("min_on_frames"));
  EXPECT_THAT(message([](auto& o) { o.min_contrast_levels = 0; }),
              HasSubstr("min_contrast_levels"));
  EXPECT_THAT(message([](auto& o) { o.dim_warning_levels = 4; }), HasSubstr("dim_warning_levels"));
  EXPECT_THAT(message([](auto& o) { o.exposure_s = -1; }), HasSubstr("exposure_s"));
  EXPECT_THAT(message([](auto& o) { o.roi_px = cv::Rect(0, 0, 10, 0); }), HasSubstr("roi_px"));
  // a detector with bad options says so when fed
  LedDetector::Options options;
  options.min_on_frames = 0;
  LedDetector detector(options);
  LedStream stream;
  stream.frames = 1;
  EXPECT_EQ(detector.Process(DrawStream(stream)[0]).code(), StatusCode::kInvalidArgument);
}

TEST(LedResult, BriefSaysWhenWhereAndHowMany) {
  LedResult result;
  result.roi_px = cv::Rect(590, 50, 28, 28);
  result.roi_located = true;
  LedPulse pulse;
  pulse.on_ns = 616'700'000;
  pulse.on_uncertainty_ns = 4'200'000;
  pulse.first_lit_frame = 37;
  pulse.first_lit_fraction = 0.64;
  result.pulses = {pulse};
  EXPECT_EQ(
      result.Brief(),
      "LED on at 0.6167 s +- 4.2 ms (frame 37, 64 % lit), ROI 28x28 at (590, 50) (located), "
      "1 pulse");
}

// ---------------------------------------------------------------------------------------
// synthetic trials rendered by synth, once for the suite

synth::TrialSpec SmallTrial(const std::string& id) {
  synth::TrialSpec spec;
  spec.id = id;
  spec.seed = 11;
  spec.duration_s = 1.2;
  spec.camera.width_px = 320;
  spec.camera.height_px = 240;
  spec.camera.fps = 60.0;
  spec.camera.exposure_s = 0.008;
  spec.camera.codec = synth::VideoCodec::kH264;
  spec.led.on_video_s = 0.5;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.2;
  spec.motion.ramp_start_s = 0.3;
  spec.motion.ramp_rate_rad_per_s = 0.3;
  return spec;
}

class LedDetectorTrials : public ::testing::Test {
 protected:
  struct Trial {
    fs::path video;
    synth::GroundTruth truth;
    double period_ns = 0.0;
  };

  static void SetUpTestSuite() {
    scratch_ = std::make_unique<ScratchDir>();
    auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
    ASSERT_TRUE(calibration.ok()) << calibration.status().ToString();
    const auto add = [&](const synth::TrialSpec& spec) {
      auto written = synth::WriteTrial(spec, *calibration, scratch_->path());
      ASSERT_TRUE(written.ok()) << written.status().ToString();
      trials_[spec.id] = Trial{written->video_path, written->truth, 1e9 / spec.camera.fps};
    };
    {
      // lossless, a full-frame exposure, on 40 % into frame 12's exposure (centred on
      // 0.4 s): lit 60 %
      synth::TrialSpec spec = SmallTrial("partial-ffv1");
      spec.camera.codec = synth::VideoCodec::kFfv1;
      spec.camera.fps = 30.0;
      spec.camera.exposure_s = 1.0 / 30.0;
      spec.led.on_video_s = 0.4 - 0.1 / 30.0;
      add(spec);
    }
    {
      synth::TrialSpec spec = SmallTrial("noise");
      spec.nuisance.noise_sigma = 12.0;
      add(spec);
    }
    {
      // 100 Hz flicker seen through a 4 ms exposure at 30 fps: the scene's brightness
      // swings by a third from frame to frame
      synth::TrialSpec spec = SmallTrial("flicker");
      spec.camera.codec = synth::VideoCodec::kMjpeg;
      spec.camera.quality = 5;
      spec.camera.fps = 30.0;
      spec.camera.exposure_s = 0.004;
      spec.nuisance.flicker_amplitude = 0.4;
      spec.nuisance.flicker_hz = 100.0;
      add(spec);
    }
    {
      synth::TrialSpec spec = SmallTrial("shake");
      spec.nuisance.shake_px = 1.5;
      add(spec);
    }
    {
      // a large white LED far brighter than the sensor's range, with a wide glow
      synth::TrialSpec spec = SmallTrial("bloom-saturated");
      spec.nuisance.noise_sigma = 2.0;
      spec.led.blue = spec.led.green = spec.led.red = 255;
      spec.led.intensity = 3.0;
      spec.led.bloom = 4.0;
      spec.led.radius_px = 8.0;
      add(spec);
    }
    {
      // never on, with everything else that changes: shake, noise, a strong codec
      synth::TrialSpec spec = SmallTrial("never-on-shake");
      spec.camera.quality = 30;
      spec.nuisance.shake_px = 2.0;
      spec.nuisance.noise_sigma = 8.0;
      spec.led.on_video_s = -1.0;
      add(spec);
    }
  }
  static void TearDownTestSuite() {
    trials_.clear();
    scratch_.reset();
  }
  static const Trial& Get(const std::string& id) { return trials_.at(id); }

  static cv::Rect TruthRoi(const Trial& trial) {
    const RegionPx& roi = trial.truth.led_roi_px;
    return cv::Rect(roi.x_px, roi.y_px, roi.width_px, roi.height_px);
  }

  static Result<LedResult> DetectInVideo(const Trial& trial, const LedDetector::Options& options) {
    LIFTOFF_ASSIGN_OR_RETURN(VideoReader reader, VideoReader::Open(trial.video));
    LedDetector detector(options);
    Frame frame;
    for (;;) {
      LIFTOFF_ASSIGN_OR_RETURN(const bool more, reader.Next(frame));
      if (!more) break;
      LIFTOFF_RETURN_IF_ERROR(detector.Process(frame));
    }
    return detector.Finish();
  }

  // the switch-on within half a frame of truth, and inside the reported uncertainty, with
  // the truth's ROI and located automatically
  static void ExpectSwitchOnWithinHalfAFrame(const std::string& id) {
    const Trial& trial = Get(id);
    ASSERT_TRUE(trial.truth.led_on_video_ns.has_value());
    const auto truth_ns = static_cast<double>(*trial.truth.led_on_video_ns);
    for (const bool located : {false, true}) {
      SCOPED_TRACE(id + (located ? " located" : " with the truth's ROI"));
      const auto result = DetectInVideo(trial, located ? Located() : WithRoi(TruthRoi(trial)));
      ASSERT_TRUE(result.ok()) << result.status().ToString();
      ASSERT_EQ(result->pulses.size(), 1u) << result->Brief();
      const LedPulse& pulse = result->pulses[0];
      const double error_ns = static_cast<double>(pulse.on_ns) - truth_ns;
      EXPECT_LE(std::abs(error_ns), 0.5 * trial.period_ns) << result->Brief();
      EXPECT_LE(std::abs(error_ns), static_cast<double>(pulse.on_uncertainty_ns) + 1e5);
      EXPECT_FALSE(pulse.off_ns.has_value());
      EXPECT_TRUE(result->warnings.empty()) << result->warnings.front();
      if (located) {
        // the located region holds the LED's centre
        const cv::Rect truth_roi = TruthRoi(trial);
        const cv::Point centre(truth_roi.x + truth_roi.width / 2,
                               truth_roi.y + truth_roi.height / 2);
        EXPECT_TRUE(result->roi_px.contains(centre)) << result->Brief();
      }
    }
  }

 private:
  static inline std::unique_ptr<ScratchDir> scratch_;
  static inline std::map<std::string, Trial> trials_;
};

TEST_F(LedDetectorTrials, PartialFrameGivesTheExactInstantWhenTheExposureIsKnown) {
  const Trial& trial = Get("partial-ffv1");
  ASSERT_EQ(trial.truth.led_first_frame, 12);
  ASSERT_NEAR(trial.truth.led_first_frame_fraction, 0.6, 1e-6);
  const auto truth_ns = static_cast<double>(*trial.truth.led_on_video_ns);
  for (const LedDetector::Options& options :
       {WithRoi(TruthRoi(trial), 1.0 / 30.0), Located(1.0 / 30.0)}) {
    const auto result = DetectInVideo(trial, options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    const LedPulse& pulse = result->pulses.at(0);
    EXPECT_EQ(pulse.first_lit_frame, 12);
    EXPECT_NEAR(pulse.first_lit_fraction, 0.6, 0.01);
    EXPECT_NEAR(static_cast<double>(pulse.on_ns), truth_ns, 0.01 * trial.period_ns);
    EXPECT_LE(std::abs(static_cast<double>(pulse.on_ns) - truth_ns),
              static_cast<double>(pulse.on_uncertainty_ns) + 1e5);
  }
}

TEST_F(LedDetectorTrials, PartialFrameWithUnknownExposureIsWithinHalfAFrame) {
  ExpectSwitchOnWithinHalfAFrame("partial-ffv1");
}

TEST_F(LedDetectorTrials, AutomaticLocatingFindsTheTruthRoi) {
  for (const std::string id : {"partial-ffv1", "noise", "flicker", "shake", "bloom-saturated"}) {
    const Trial& trial = Get(id);
    const auto result = DetectInVideo(trial, Located());
    ASSERT_TRUE(result.ok()) << id << ": " << result.status().ToString();
    EXPECT_TRUE(result->roi_located);
    const cv::Rect truth = TruthRoi(trial);
    const cv::Point2d truth_centre(truth.x + 0.5 * truth.width, truth.y + 0.5 * truth.height);
    const cv::Point2d centre(result->roi_px.x + 0.5 * result->roi_px.width,
                             result->roi_px.y + 0.5 * result->roi_px.height);
    EXPECT_LE(cv::norm(centre - truth_centre), 6.0) << id << ": " << result->Brief();
    EXPECT_GT((result->roi_px & truth).area(), truth.area() / 2) << id << ": " << result->Brief();
  }
}

TEST_F(LedDetectorTrials, FindsTheSwitchOnUnderSensorNoise) {
  ExpectSwitchOnWithinHalfAFrame("noise");
}

TEST_F(LedDetectorTrials, FindsTheSwitchOnUnderMainsFlicker) {
  ExpectSwitchOnWithinHalfAFrame("flicker");
}

TEST_F(LedDetectorTrials, FindsTheSwitchOnUnderCameraShake) {
  ExpectSwitchOnWithinHalfAFrame("shake");
}

TEST_F(LedDetectorTrials, FindsTheSwitchOnOfASaturatedLedWithBloom) {
  ExpectSwitchOnWithinHalfAFrame("bloom-saturated");
}

TEST_F(LedDetectorTrials, LedNeverOnIsNotFoundDespiteShakeAndNoise) {
  const Trial& trial = Get("never-on-shake");
  for (const LedDetector::Options& options : {WithRoi(TruthRoi(trial)), Located()}) {
    const auto result = DetectInVideo(trial, options);
    ASSERT_FALSE(result.ok()) << result->Brief();
    EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
    EXPECT_THAT(result.status().message(), HasSubstr("the LED never switches on"));
  }
}

}  // namespace
}  // namespace liftoff::video
