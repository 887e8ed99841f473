#include "liftoff/synth/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "support/test_support.h"

namespace liftoff::synth {
namespace {

constexpr int64_t kFrameNs60 = 1'000'000'000 / 60;

// Frame k's exposure start at 60 fps, video clock (frame 60 at exactly 1 s).
int64_t FrameNs(int64_t k) { return k * 1'000'000'000 / 60; }

// A small, fast clip: 640 x 360 at 60 fps, exposure 1/120 s, the LED at 0.5 s and a fast
// ramp so the foot lifts early: 0.45 rad at 0.2 rad/s from 1 s after the LED, so liftoff
// at 0.5 + 1 + 2.25 = 3.75 s of video.
TrialSpec SmallSpec() {
  TrialSpec spec;
  spec.id = "scene-test";
  spec.seed = 7;
  spec.duration_s = 6.0;
  spec.camera.width_px = 640;
  spec.camera.height_px = 360;
  spec.camera.fps = 60;
  spec.camera.exposure_s = 1.0 / 120;
  spec.led.on_video_s = 0.5;
  spec.motion.foot = Foot::kA;
  spec.motion.ramp_start_s = 1.0;
  spec.motion.ramp_rate_rad_per_s = 0.2;
  spec.nuisance.shadow = false;
  return spec;
}

TrialSpec WithNuisances(TrialSpec spec) {
  spec.nuisance.noise_sigma = 3;
  spec.nuisance.flicker_amplitude = 0.15;
  spec.nuisance.shake_px = 1.5;
  spec.nuisance.motion_blur_samples = 4;
  spec.nuisance.shadow = true;
  return spec;
}

struct Rendered {
  Timeline timeline;
  SceneRenderer renderer;
};

Rendered Make(const TrialSpec& spec) {
  Result<Timeline> timeline = Timeline::Create(spec);
  EXPECT_TRUE(timeline.ok()) << timeline.status().ToString();
  Result<SceneRenderer> renderer = SceneRenderer::Create(*timeline);
  EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
  return {*timeline, std::move(*renderer)};
}

uint64_t Fnv1a(const cv::Mat& image) {
  uint64_t hash = 0xcbf29ce484222325ull;
  for (int row = 0; row < image.rows; ++row) {
    const uint8_t* p = image.ptr<uint8_t>(row);
    for (size_t i = 0; i < static_cast<size_t>(image.cols) * image.elemSize(); ++i)
      hash = (hash ^ p[i]) * 0x100000001b3ull;
  }
  return hash;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && Fnv1a(a) == Fnv1a(b) &&
         cv::norm(a, b, cv::NORM_INF) == 0;
}

cv::Rect Rect(const RegionPx& region) {
  return {region.x_px, region.y_px, region.width_px, region.height_px};
}

// Mean grey level (mean of B, G, R) over a region.
double MeanGrey(const cv::Mat& image, const cv::Rect& region) {
  const cv::Scalar mean = cv::mean(image(region));
  return (mean[0] + mean[1] + mean[2]) / 3;
}

// ---------------------------------------------------------------------------------------
// determinism

TEST(SceneRenderer, SameSpecRendersIdenticalFrames) {
  const TrialSpec spec = WithNuisances(SmallSpec());
  Rendered first = Make(spec), second = Make(spec);
  for (int64_t k : {0, 1, 2, 31, 32}) {
    const cv::Mat a = first.renderer.RenderFrame(k, FrameNs(k));
    const cv::Mat b = second.renderer.RenderFrame(k, FrameNs(k));
    ASSERT_EQ(a.type(), CV_8UC3);
    ASSERT_EQ(a.cols, 640);
    ASSERT_EQ(a.rows, 360);
    EXPECT_EQ(Fnv1a(a), Fnv1a(b)) << "frame " << k;
  }
}

TEST(SceneRenderer, FrameRenderedAloneEqualsFrameRenderedInSequence) {
  TrialSpec spec = WithNuisances(SmallSpec());
  spec.led.on_video_s = 0.05;  // the LED switches on within the frames compared
  Rendered sequence = Make(spec), alone = Make(spec);
  std::vector<cv::Mat> frames;
  for (int64_t k = 0; k < 10; ++k) frames.push_back(sequence.renderer.RenderFrame(k, FrameNs(k)));
  // out of order, each on its own
  EXPECT_TRUE(Identical(alone.renderer.RenderFrame(7, FrameNs(7)), frames[7]));
  EXPECT_TRUE(Identical(alone.renderer.RenderFrame(3, FrameNs(3)), frames[3]));
  EXPECT_TRUE(Identical(alone.renderer.RenderFrame(9, FrameNs(9)), frames[9]));
  // and the frames do differ from each other (noise, shake, flicker, LED)
  EXPECT_FALSE(Identical(frames[3], frames[7]));
}

TEST(SceneRenderer, DifferentSeedRendersDifferentFrames) {
  TrialSpec spec = SmallSpec();
  Rendered one = Make(spec);
  spec.seed = 8;
  Rendered other = Make(spec);
  const cv::Mat a = one.renderer.RenderFrame(0, 0), b = other.renderer.RenderFrame(0, 0);
  // the bed's texture differs
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1) / (640.0 * 360 * 3), 1.0);

  // with noise and shake on, a different seed changes those too
  TrialSpec noisy = WithNuisances(SmallSpec());
  Rendered noisy_one = Make(noisy);
  noisy.seed = 8;
  Rendered noisy_other = Make(noisy);
  EXPECT_NE(Fnv1a(noisy_one.renderer.RenderFrame(5, FrameNs(5))),
            Fnv1a(noisy_other.renderer.RenderFrame(5, FrameNs(5))));
}

TEST(SceneRenderer, ShakeIsABoundedWalkAndNoiseHasTheAskedSigma) {
  TrialSpec spec = SmallSpec();
  spec.nuisance.shake_px = 2;
  Rendered shaky = Make(spec);
  double largest = 0;
  bool moved = false;
  for (int64_t k = 0; k < 400; ++k) {
    const cv::Point2d offset = shaky.renderer.ShakeOffsetPx(k);
    largest = std::max({largest, std::abs(offset.x), std::abs(offset.y)});
    moved = moved || offset.x != 0;
  }
  EXPECT_TRUE(moved);
  EXPECT_LE(largest, 4.0);

  // noise: the difference to the clean frame has standard deviation ~ sigma, mean ~ 0
  TrialSpec clean_spec = SmallSpec();
  TrialSpec noisy_spec = clean_spec;
  noisy_spec.nuisance.noise_sigma = 5;
  Rendered clean = Make(clean_spec), noisy = Make(noisy_spec);
  cv::Mat a, b;
  clean.renderer.RenderFrame(3, FrameNs(3)).convertTo(a, CV_32F);
  noisy.renderer.RenderFrame(3, FrameNs(3)).convertTo(b, CV_32F);
  cv::Scalar mean, stddev;
  const cv::Mat difference = b - a;
  cv::meanStdDev(difference.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 0.1);
  EXPECT_NEAR(stddev[0], 5.0, 0.3);  // sqrt(25 + 1/12) with rounding, a few clipped pixels
}

// ---------------------------------------------------------------------------------------
// the LED

// fps 60, exposure 1/120 s = 8333333 ns, centred on the frame's timestamp: frame 60 (1 s)
// exposes [995833334, 1004166667) ns.
TEST(SceneRenderer, LedRegionBrightensByTheExposureFractionInThePartialFrame) {
  TrialSpec spec = SmallSpec();
  spec.led.on_video_s = 1.003 - 1.0 / 240;  // 998833333 ns: 3 ms into frame 60's exposure
  Rendered scene = Make(spec);
  // by hand: on for 1004166667 - 998833333 ns of 8333333 ns
  const double fraction = (1004166667.0 - 998833333.0) / 8333333.0;  // 0.64
  EXPECT_NEAR(scene.renderer.LedOnFraction(FrameNs(60)), fraction, 1e-9);
  EXPECT_EQ(scene.renderer.LedOnFraction(FrameNs(59)), 0.0);
  EXPECT_EQ(scene.renderer.LedOnFraction(FrameNs(61)), 1.0);

  const cv::Rect roi = Rect(scene.renderer.led_roi_px());
  std::vector<double> mean(64);
  for (int64_t k = 56; k < 64; ++k) {
    mean[static_cast<size_t>(k)] = MeanGrey(scene.renderer.RenderFrame(k, FrameNs(k)), roi);
  }
  const double off = mean[56], on = mean[63];
  EXPECT_GT(on - off, 20.0) << "the lit LED is clearly brighter";
  for (int64_t k : {57, 58, 59}) EXPECT_EQ(mean[static_cast<size_t>(k)], off) << k;
  for (int64_t k : {61, 62}) EXPECT_EQ(mean[static_cast<size_t>(k)], on) << k;
  EXPECT_NEAR(mean[60], off + fraction * (on - off), 0.05) << "off " << off << " on " << on;
}

TEST(SceneRenderer, LedSwitchingOnBetweenExposuresGivesNoPartialFrame) {
  TrialSpec spec = SmallSpec();
  spec.led.on_video_s = 1.012;  // after frame 60's exposure ends (1.00417 s), before 61's (1.0125)
  Rendered scene = Make(spec);
  const cv::Rect roi = Rect(scene.renderer.led_roi_px());
  const double off = MeanGrey(scene.renderer.RenderFrame(55, FrameNs(55)), roi);
  const double on = MeanGrey(scene.renderer.RenderFrame(66, FrameNs(66)), roi);
  EXPECT_GT(on - off, 20.0);
  EXPECT_EQ(MeanGrey(scene.renderer.RenderFrame(60, FrameNs(60)), roi), off);
  EXPECT_EQ(MeanGrey(scene.renderer.RenderFrame(61, FrameNs(61)), roi), on);
}

TEST(SceneRenderer, LedStepIsFoundAtTheTrueFrameUnderNoiseFlickerAndShake) {
  TrialSpec spec = WithNuisances(SmallSpec());
  spec.led.on_video_s = 1.002 - 1.0 / 240;  // 2 ms into frame 60's exposure: lit 76 %
  Rendered scene = Make(spec);
  const cv::Rect roi = Rect(scene.renderer.led_roi_px());
  std::vector<double> mean;
  for (int64_t k = 40; k < 80; ++k)
    mean.push_back(MeanGrey(scene.renderer.RenderFrame(k, FrameNs(k)), roi));
  // off and on levels from the frames well before and after
  std::vector<double> before(mean.begin(), mean.begin() + 15), after(mean.end() - 15, mean.end());
  std::sort(before.begin(), before.end());
  std::sort(after.begin(), after.end());
  const double threshold = (before[7] + after[7]) / 2;
  const auto first =
      std::find_if(mean.begin(), mean.end(), [&](double m) { return m > threshold; });
  ASSERT_NE(first, mean.end());
  EXPECT_EQ(40 + (first - mean.begin()), 60);
}

TEST(SceneRenderer, LedNeverOnLeavesTheRegionDark) {
  // the reference: the same clip with the LED switching on at 0.5 s, off in frame 10 and
  // on in frame 300
  Rendered reference = Make(SmallSpec());
  const cv::Rect roi = Rect(reference.renderer.led_roi_px());
  const double off = MeanGrey(reference.renderer.RenderFrame(10, FrameNs(10)), roi);
  const double on = MeanGrey(reference.renderer.RenderFrame(300, FrameNs(300)), roi);
  ASSERT_GT(on - off, 20.0) << "the reference tells the lit LED from the dark one";

  TrialSpec spec = SmallSpec();
  spec.led.on_video_s = -1;  // never on (an invalid input for the video pipeline)
  Rendered scene = Make(spec);
  ASSERT_EQ(Rect(scene.renderer.led_roi_px()), roi);
  EXPECT_EQ(MeanGrey(scene.renderer.RenderFrame(10, FrameNs(10)), roi), off);
  EXPECT_EQ(MeanGrey(scene.renderer.RenderFrame(300, FrameNs(300)), roi), off);
  EXPECT_EQ(scene.renderer.LedOnFraction(FrameNs(300)), 0.0);
}

// ---------------------------------------------------------------------------------------
// the feet

TEST(SceneRenderer, NearFeetSpanSeventyPercentOfTheWidthInASideView) {
  TrialSpec spec;  // 1280 x 720
  Rendered scene = Make(spec);
  const auto& a = scene.renderer.placement(Foot::kA);
  const auto& b = scene.renderer.placement(Foot::kB);
  const auto& c = scene.renderer.placement(Foot::kC);
  const auto& d = scene.renderer.placement(Foot::kD);
  // 0.70 * 1280 px over 648 mm between the near (right) feet C and A
  EXPECT_NEAR(a.center_x_px - c.center_x_px, 896.0, 1e-6);
  EXPECT_NEAR(a.px_per_mm, 896.0 / 648.0, 1e-9);
  EXPECT_NEAR(scene.renderer.px_per_mm(), 896.0 / 648.0, 1e-9);
  // left to right: C, D, B, A; the far feet smaller and higher in the image
  EXPECT_LT(c.center_x_px + c.width_px / 2, d.center_x_px - d.width_px / 2);
  EXPECT_LT(d.center_x_px, b.center_x_px);
  EXPECT_LT(b.center_x_px + b.width_px / 2, a.center_x_px - a.width_px / 2);
  EXPECT_LT(d.px_per_mm, c.px_per_mm);
  EXPECT_LT(d.bottom_px, c.bottom_px);
  EXPECT_EQ(b.px_per_mm, d.px_per_mm);

  // each foot's tape has its colour: A blue, B orange, C purple, D red
  const cv::Mat frame = scene.renderer.RenderFrame(0, 0);
  const auto tape = [&](Foot foot) {
    const auto& place = scene.renderer.placement(foot);
    return frame.at<cv::Vec3b>(static_cast<int>((place.tape_top_px + place.tape_bottom_px) / 2),
                               static_cast<int>(place.center_x_px));
  };
  const cv::Vec3b blue = tape(Foot::kA), orange = tape(Foot::kB), purple = tape(Foot::kC),
                  red = tape(Foot::kD);
  EXPECT_GT(blue[0], 150);
  EXPECT_LT(blue[2], 60);
  EXPECT_GT(orange[2], 200);
  EXPECT_GT(orange[1], 100);
  EXPECT_LT(orange[0], 60);
  EXPECT_GT(purple[0], 110);
  EXPECT_GT(purple[2], 90);
  EXPECT_LT(purple[1], 60);
  EXPECT_GT(red[2], 150);
  EXPECT_LT(red[0], 60);

  // the regions of interest hold the LED and the lifting foot
  const cv::Rect led = Rect(scene.renderer.led_roi_px());
  EXPECT_TRUE(led.contains(cv::Point(static_cast<int>(0.9 * 1280), static_cast<int>(0.12 * 720))));
  const cv::Rect foot = Rect(scene.renderer.foot_roi_px());
  EXPECT_TRUE(
      foot.contains(cv::Point(static_cast<int>(a.center_x_px), static_cast<int>(a.bottom_px))));
  EXPECT_GE(foot.height, static_cast<int>((30 + 40) * a.px_per_mm));
}

// The lifting foot's bottom edge in column `col`, measured from the picture alone: the
// coverage of each pixel between the foot's colour (a row just inside it) and the bare bed
// (the same row with the foot lifted far away), summed down the column. `near_row` only
// places the window (within a few px).
double MeasureBottomEdge(const cv::Mat& frame, const cv::Mat& bare_bed, int col, double near_row) {
  const int inside = static_cast<int>(std::floor(near_row - 0.5)) - 2;  // fully foot
  const auto grey = [&](const cv::Mat& image, int row) {
    const cv::Vec3b p = image.at<cv::Vec3b>(row, col);
    return static_cast<double>(p[0]) + p[1] + p[2];
  };
  const double foot = grey(frame, inside);
  double edge = inside + 0.5;
  for (int row = inside + 1; row <= inside + 8; ++row) {
    edge += (grey(bare_bed, row) - grey(frame, row)) / (grey(bare_bed, row) - foot);
  }
  return edge;
}

// Centroid row of foot A's blue tape (blue minus red, clipped at 0) in a column window.
double TapeCentroid(const cv::Mat& frame, int col, int row_begin, int row_end) {
  double sum = 0, weighted = 0;
  for (int row = row_begin; row < row_end; ++row) {
    const cv::Vec3b p = frame.at<cv::Vec3b>(row, col);
    const double blue = std::max(0.0, static_cast<double>(p[0]) - p[2]);
    sum += blue;
    weighted += blue * row;
  }
  return weighted / sum;
}

TEST(SceneRenderer, FootBottomEdgeFollowsTheTrueHeightCurve) {
  TrialSpec spec = SmallSpec();
  spec.camera.exposure_s = 1e-5;  // a sharp instant: the foot moves < 1e-4 px in it
  Rendered scene = Make(spec);
  const SceneRenderer::FootPlacement place = scene.renderer.placement(Foot::kA);
  const double rest = scene.renderer.foot_rest_bottom_px();
  const double px_per_mm = scene.renderer.px_per_mm();
  EXPECT_NEAR(px_per_mm, 0.7 * 640 / 648, 1e-9);

  // the bare bed: the foot 40 mm up (27.7 px) leaves the rows around its rest edge free
  const std::optional<int64_t> high_ns = scene.timeline.FirstVideoNsAbove(0.040);
  ASSERT_TRUE(high_ns.has_value());
  const cv::Mat bare_bed = scene.renderer.RenderFrame(0, *high_ns);
  const cv::Mat at_rest = scene.renderer.RenderFrame(0, 0);

  const int center = static_cast<int>(std::lround(place.center_x_px));
  const int tape_begin = static_cast<int>(place.tape_top_px) - 12;
  const int tape_end = static_cast<int>(place.tape_bottom_px) + 3;
  for (double height_mm : {0.0, 0.5, 2.0, 10.0}) {
    SCOPED_TRACE(height_mm);
    int64_t t_ns = 0;
    if (height_mm > 0) {
      const std::optional<int64_t> above = scene.timeline.FirstVideoNsAbove(height_mm / 1000);
      ASSERT_TRUE(above.has_value());
      t_ns = *above;
    }
    const double true_height_mm = scene.timeline.FootHeightMAt(Foot::kA, t_ns) * 1000;
    ASSERT_NEAR(true_height_mm, height_mm, 1e-6);
    const double truth = scene.renderer.FootBottomPxAt(t_ns);
    EXPECT_NEAR(truth, rest - height_mm * 0.7 * 640 / 648, 1e-6);

    const cv::Mat frame = scene.renderer.RenderFrame(0, t_ns);
    // the bottom edge, over five columns of the foot's flat bottom
    double measured = 0;
    for (int col = center - 2; col <= center + 2; ++col) {
      measured += MeasureBottomEdge(frame, bare_bed, col, truth) / 5;
    }
    EXPECT_NEAR(measured, truth, 0.25);
    // the tape band moves up by exactly the same amount
    const double shift = TapeCentroid(at_rest, center, tape_begin, tape_end) -
                         TapeCentroid(frame, center, tape_begin, tape_end);
    EXPECT_NEAR(shift, height_mm * px_per_mm, 0.05);

    // the other feet do not move
    for (Foot other : {Foot::kB, Foot::kC, Foot::kD}) {
      const auto& o = scene.renderer.placement(other);
      const cv::Rect box(static_cast<int>(o.center_x_px - o.width_px), 0,
                         static_cast<int>(2 * o.width_px), static_cast<int>(o.bottom_px + 6));
      EXPECT_EQ(cv::norm(frame(box), at_rest(box), cv::NORM_INF), 0.0) << FootName(other);
    }
  }
}

TEST(SceneRenderer, MotionBlurAveragesTheFootOverTheExposure) {
  // a long exposure while the foot rises fast: the tape's centroid shift is the mean of
  // the lift over the exposure, not the lift at its start (or its middle)
  TrialSpec spec = SmallSpec();
  spec.camera.exposure_s = 1.0 / 60;
  spec.nuisance.motion_blur_samples = 16;
  spec.motion.ramp_rate_rad_per_s = 4.0;  // liftoff at 0.5 + 1 + 0.1125 s
  Rendered scene = Make(spec);
  const auto& place = scene.renderer.placement(Foot::kA);
  const int center = static_cast<int>(std::lround(place.center_x_px));
  const int tape_begin = static_cast<int>(place.tape_top_px) - 30;
  const int tape_end = static_cast<int>(place.tape_bottom_px) + 3;
  const int64_t start_ns = *scene.timeline.FirstVideoNsAbove(0.005);
  // the frame whose exposure (centred on its timestamp) starts when the foot is 5 mm up
  const int64_t t_ns = start_ns - ExposureStartNs(spec.camera, 0);
  const cv::Mat frame = scene.renderer.RenderFrame(0, t_ns);
  const cv::Mat at_rest = scene.renderer.RenderFrame(0, 0);
  // the mean lift over the exposure, analytically: height = gain * u^1.5 with u the
  // rotation past liftoff, rising at the ramp rate from u0 (5 mm) by rate * exposure, so
  // mean = gain / (rate * exposure) * (u1^2.5 - u0^2.5) / 2.5. The renderer's 16 midpoint
  // sub-samples stay within 0.01 px of it (midpoint rule error ~ h^2 / 24 * height'').
  const double gain_m = spec.motion.height.gain_m, rate = spec.motion.ramp_rate_rad_per_s;
  ASSERT_EQ(spec.motion.height.exponent, 1.5);
  const double exposure_s = SecondsFromNs(NsFromSeconds(spec.camera.exposure_s));
  const double u0 = std::pow(0.005 / gain_m, 1.0 / 1.5);
  const double u1 = u0 + rate * exposure_s;
  const double mean_height_m =
      gain_m / (rate * exposure_s) * (std::pow(u1, 2.5) - std::pow(u0, 2.5)) / 2.5;
  const double mean_lift_px = mean_height_m * 1000 * place.px_per_mm;
  const double start_lift_px = 5 * place.px_per_mm;
  ASSERT_GT(mean_lift_px - start_lift_px, 2.0) << "the foot moves several px in the exposure";
  const double shift = TapeCentroid(at_rest, center, tape_begin, tape_end) -
                       TapeCentroid(frame, center, tape_begin, tape_end);
  EXPECT_NEAR(shift, mean_lift_px, 0.1);
}

TEST(SceneRenderer, DiagonalPartnerRisesWhenLagged) {
  TrialSpec spec = SmallSpec();
  spec.motion.diagonal_lag_rad = 0.03;
  Rendered scene = Make(spec);
  // when A is 10 mm up, D (A's diagonal) is up by the curve 0.03 rad later
  const int64_t t_ns = *scene.timeline.FirstVideoNsAbove(0.010);
  const double d_height_mm = scene.timeline.FootHeightMAt(Foot::kD, t_ns) * 1000;
  ASSERT_GT(d_height_mm, 1.0);
  ASSERT_LT(d_height_mm, 9.0);
  const auto& d = scene.renderer.placement(Foot::kD);
  const int center = static_cast<int>(std::lround(d.center_x_px));
  // rows from above the tape to just below it at rest: no bed even with D lifted
  const int begin = static_cast<int>(d.tape_top_px) - 12,
            end = static_cast<int>(d.tape_bottom_px) + 1;
  // D's red tape: red minus blue
  const auto centroid = [&](const cv::Mat& frame) {
    double sum = 0, weighted = 0;
    for (int row = begin; row < end; ++row) {
      const cv::Vec3b p = frame.at<cv::Vec3b>(row, center);
      const double red = std::max(0.0, static_cast<double>(p[2]) - p[0]);
      sum += red;
      weighted += red * row;
    }
    return weighted / sum;
  };
  const double shift =
      centroid(scene.renderer.RenderFrame(0, 0)) - centroid(scene.renderer.RenderFrame(0, t_ns));
  EXPECT_NEAR(shift, d_height_mm * d.px_per_mm, 0.1);
}

TEST(SceneRenderer, FlickerScalesTheSceneByTheLampsMeanOverTheExposure) {
  // 100 Hz flicker of amplitude 0.2, exposure 1/200 s: half a period, centred on the
  // frame's timestamp. By hand, the mean of sin over the first half period is 2/pi, over
  // the second -2/pi; over a whole period 0.
  TrialSpec steady = SmallSpec();
  steady.camera.fps = 30;
  steady.camera.exposure_s = 1.0 / 200;
  TrialSpec flickering = steady;
  flickering.nuisance.flicker_amplitude = 0.2;
  flickering.nuisance.flicker_hz = 100;
  Rendered plain = Make(steady), lit = Make(flickering);
  // the bed's blue channel between the feet (red would clip at 255 in the bright phase)
  const cv::Rect bed(300, 262, 40, 20);
  const auto ratio = [&](int64_t t_ns) {
    return cv::mean(lit.renderer.RenderFrame(0, t_ns)(bed))[0] /
           cv::mean(plain.renderer.RenderFrame(0, t_ns)(bed))[0];
  };
  EXPECT_NEAR(ratio(2'500'000), 1 + 0.2 * 2 / std::numbers::pi, 0.005);  // [0, 5) ms
  EXPECT_NEAR(ratio(7'500'000), 1 - 0.2 * 2 / std::numbers::pi, 0.005);  // [5, 10) ms
  EXPECT_NEAR(ratio(5'000'000), 1.0, 0.005);  // [2.5, 7.5) ms: about the zero crossing
  // the LED is self-lit: flicker does not dim it
  const cv::Rect led = Rect(lit.renderer.led_roi_px());
  const cv::Point centre(led.x + led.width / 2, led.y + led.height / 2);
  EXPECT_EQ(lit.renderer.RenderFrame(0, NsFromSeconds(1.0)).at<cv::Vec3b>(centre),
            plain.renderer.RenderFrame(0, NsFromSeconds(1.0)).at<cv::Vec3b>(centre));
}

// ---------------------------------------------------------------------------------------
// the shadow

TEST(SceneRenderer, ShadowDarkensTheBedUnderTheFootAndFadesAsItRises) {
  TrialSpec lit = SmallSpec();
  TrialSpec shadowed = lit;
  shadowed.nuisance.shadow = true;
  Rendered without = Make(lit), with = Make(shadowed);
  const auto& place = with.renderer.placement(Foot::kA);
  // the bed just below the foot's rest edge and beside its bottom corners
  const int bottom_row = static_cast<int>(std::ceil(place.bottom_px));
  const cv::Rect below(static_cast<int>(place.center_x_px - place.width_px / 2), bottom_row,
                       static_cast<int>(place.width_px), 3);
  const auto darkening = [&](int64_t t_ns) {
    const double plain = MeanGrey(without.renderer.RenderFrame(0, t_ns), below);
    return 1 - MeanGrey(with.renderer.RenderFrame(0, t_ns), below) / plain;
  };
  const double at_rest = darkening(0);
  const double at_5mm = darkening(*with.timeline.FirstVideoNsAbove(0.005));
  const double at_20mm = darkening(*with.timeline.FirstVideoNsAbove(0.020));
  EXPECT_GT(at_rest, 0.2);
  EXPECT_LT(at_5mm, at_rest);
  EXPECT_LT(at_20mm, at_5mm);
  EXPECT_LT(at_20mm, 0.1);
  EXPECT_GE(at_20mm, 0.0);
}

// ---------------------------------------------------------------------------------------
// sample frames for docs/synth.md: run once by hand with --gtest_also_run_disabled_tests
// --gtest_filter=SceneRenderer.DISABLED_WriteDocFrames

TEST(SceneRenderer, DISABLED_WriteDocFrames) {
  const std::filesystem::path dir = liftoff::testing::SourceDir() / "docs" / "images";
  std::filesystem::create_directories(dir);
  const std::vector<int> png = {cv::IMWRITE_PNG_COMPRESSION, 9};
  TrialSpec base = SmallSpec();
  base.camera.width_px = 960;
  base.camera.height_px = 540;
  base.nuisance.shadow = true;
  base.led.on_video_s = 1.003 - 1.0 / 240;  // 3 ms into frame 60's exposure

  {  // default nuisances, LED off, feet at rest
    Rendered scene = Make(base);
    cv::imwrite((dir / "synth-frame-default.png").string(), scene.renderer.RenderFrame(0, 0), png);
  }
  {  // the partial frame: the LED on for 64 % of frame 60's exposure
    Rendered scene = Make(base);
    cv::imwrite((dir / "synth-frame-led-partial.png").string(),
                scene.renderer.RenderFrame(60, FrameNs(60)), png);
  }
  {  // foot A 15 mm up, its diagonal D rising later, the LED on
    TrialSpec spec = base;
    spec.motion.diagonal_lag_rad = 0.02;
    Rendered scene = Make(spec);
    const int64_t t_ns = *scene.timeline.FirstVideoNsAbove(0.015);
    cv::imwrite((dir / "synth-frame-lifted.png").string(), scene.renderer.RenderFrame(200, t_ns),
                png);
  }
  {  // every nuisance: noise, flicker, shake, motion blur of a fast lift, a saturated LED
     // with bloom (480 x 270: noise does not compress, the PNG stays small)
    TrialSpec spec = base;
    spec.camera.width_px = 480;
    spec.camera.height_px = 270;
    spec.camera.exposure_s = 1.0 / 60;
    spec.nuisance.noise_sigma = 3;
    spec.nuisance.flicker_amplitude = 0.3;
    spec.nuisance.shake_px = 2;
    spec.nuisance.motion_blur_samples = 16;
    spec.motion.ramp_rate_rad_per_s = 6;
    spec.led.intensity = 3;
    spec.led.bloom = 4;
    spec.led.blue = 255;
    spec.led.green = 60;
    spec.led.red = 40;
    Rendered scene = Make(spec);
    const int64_t t_ns = *scene.timeline.FirstVideoNsAbove(0.015);
    cv::imwrite((dir / "synth-frame-nuisances.png").string(), scene.renderer.RenderFrame(131, t_ns),
                png);
  }
}

}  // namespace
}  // namespace liftoff::synth
