#include "liftoff/video/foot_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/synth/scene.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

// 640 x 480 at 60 fps, exposure 1/120 s (the CI baseline's camera, scale 0.69 px/mm), foot A
// (blue): LED at 0.2 s, a 0.2 rad/s ramp from 0.2 s after it, liftoff at 0.25 rad, so the
// foot leaves the ground at 1.65 s and is 1 mm up 0.126 s later; 2.2 s, 132 frames.
synth::TrialSpec BaseSpec() {
  synth::TrialSpec spec;
  spec.id = "foot-tracker";
  spec.seed = 11;
  spec.duration_s = 2.2;
  spec.camera.width_px = 640;
  spec.camera.height_px = 480;
  spec.camera.fps = 60;
  spec.camera.exposure_s = 1.0 / 120;
  spec.led.on_video_s = 0.2;
  spec.motion.foot = Foot::kA;
  spec.motion.bend_start_s = 0;
  spec.motion.bend_end_s = 0.1;
  spec.motion.ramp_start_s = 0.2;
  spec.motion.ramp_rate_rad_per_s = 0.2;
  spec.motion.height.liftoff_rad = 0.25;
  return spec;
}

struct Scene {
  synth::Timeline timeline;
  synth::SceneRenderer renderer;
  int64_t exposure_ns = 0;
  int64_t frame_ns = 0;

  // The frame stamped t_ns: its exposure centred there, as the tracker dates frames.
  cv::Mat Render(int64_t index, int64_t t_ns) { return renderer.RenderFrame(index, t_ns); }
  // The truth a frame stamped t_ns shows: the foot's rise at mid-exposure, px.
  double TrueRisePx(int64_t t_ns) const {
    return renderer.foot_rest_bottom_px() - renderer.FootBottomPxAt(t_ns);
  }
  cv::Rect FootRoi() const {
    const RegionPx roi = renderer.foot_roi_px();
    return {roi.x_px, roi.y_px, roi.width_px, roi.height_px};
  }
};

Scene MakeScene(const synth::TrialSpec& spec) {
  Result<synth::Timeline> timeline = synth::Timeline::Create(spec);
  EXPECT_TRUE(timeline.ok()) << timeline.status().ToString();
  Result<synth::SceneRenderer> renderer = synth::SceneRenderer::Create(*timeline);
  EXPECT_TRUE(renderer.ok()) << renderer.status().ToString();
  return {*timeline, std::move(*renderer), synth::ExposureNs(spec.camera),
          static_cast<int64_t>(std::llround(1e9 / spec.camera.fps))};
}

// Options for a scene: its foot region, its true scale, the rest window LED .. LED + 0.2 s.
FootTracker::Options OptionsFor(const Scene& scene) {
  FootTracker::Options options;
  options.foot_roi_px = scene.FootRoi();
  options.px_per_mm = scene.renderer.px_per_mm();
  options.rest_from_ns = *scene.timeline.LedOnVideoNs();
  options.rest_to_ns = options.rest_from_ns + 200'000'000;
  options.compression_error_px = 0;  // exact pixels: no codec
  return options;
}

// Feeds every frame of the clip, rendered in memory (exact pixels), optionally changed by
// `edit`, and returns the result.
Result<FootTrack> TrackClip(Scene& scene, const FootTracker::Options& options,
                            const std::function<void(cv::Mat&)>& edit = {}) {
  FootTracker tracker(options);
  const int64_t count = scene.timeline.duration_ns() / scene.frame_ns;
  for (int64_t k = 0; k < count; ++k) {
    Frame frame;
    frame.index = k;
    frame.t_ns = k * scene.frame_ns;
    frame.bgr = scene.Render(k, frame.t_ns);
    if (edit) edit(frame.bgr);
    const Status status = tracker.Process(frame);
    if (!status.ok()) return status;
  }
  return tracker.Finish();
}

int64_t TruthNsAboveMm(const Scene& scene, double height_mm) {
  const std::optional<int64_t> t_ns = scene.timeline.FirstVideoNsAbove(height_mm / 1000);
  EXPECT_TRUE(t_ns.has_value());
  return t_ns.value_or(0);
}

// The 2018 drive chain and a spool, enough to write a trial's log.
Calibration TestCalibration() {
  Calibration calibration = liftoff::testing::DriveChainCalibration();
  calibration.spool_groove_radii_m = {0.004, 0.004, 0.008, 0.012};
  calibration.cable_lengths_m = {0.088, 0.088, 0.088, 0.088};
  return calibration;
}

// ---------------------------------------------------------------------------------------
// the height curve

TEST(FootTracker, RiseMatchesTheRendererTruthToSubPixelAtSeveralHeights) {
  synth::TrialSpec spec = BaseSpec();
  spec.duration_s = 3.0;  // the foot 35 mm (24 px) up at the end
  Scene scene = MakeScene(spec);
  FootTracker::Options options = OptionsFor(scene);
  options.rest_from_ns = options.rest_to_ns = 0;  // the first frames
  options.rest_frames = 3;
  FootTracker tracker(options);
  // six frames at rest (the first four make the templates), then frames whose mid-exposure
  // shows the foot at these heights
  std::vector<double> heights_px = {0, 0, 0, 0, 0, 0, 0.05, 0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9,
                                    1.0, 1.3, 1.7, 2.0,  2.5, 3.0,  3.5, 4.0, 4.5, 5.0, 6.0};
  const double px_per_mm = scene.renderer.px_per_mm();
  std::vector<int64_t> times_ns;
  for (size_t i = 0; i < heights_px.size(); ++i) {
    int64_t t_ns = static_cast<int64_t>(i) * scene.frame_ns;
    if (heights_px[i] > 0) {
      t_ns = TruthNsAboveMm(scene, heights_px[i] / px_per_mm);
    }
    times_ns.push_back(t_ns);
    Frame frame{static_cast<int64_t>(i), t_ns, false,
                scene.Render(static_cast<int64_t>(i), t_ns)};
    ASSERT_TRUE(tracker.Process(frame).ok());
  }
  Result<FootTrack> track = tracker.Finish();
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  ASSERT_EQ(track->samples.size(), heights_px.size());
  for (size_t i = 0; i < heights_px.size(); ++i) {
    const double truth_px = scene.TrueRisePx(times_ns[i]);
    // (0.06 px: the region, under 48 px, is enlarged by cubic interpolation, which costs
    // up to 0.053 px here; 0.05 held at its own size)
    EXPECT_NEAR(track->samples[i].rise_px, truth_px, 0.06) << "at " << heights_px[i] << " px";
    if (i >= 3) {
      EXPECT_GT(track->samples[i].quality, 0.95) << "frame " << i;
    }
  }
  // the foot as located: its bottom edge and width against the renderer's placement
  const auto& place = scene.renderer.placement(Foot::kA);
  // (the box of the patches that moved with it: the foot, the leg above, its edges)
  EXPECT_NEAR(track->foot_bottom_px, place.bottom_px, 0.25 * place.width_px);
  EXPECT_NEAR(track->foot_center_x_px, place.center_x_px, 0.25 * place.width_px);
  EXPECT_NEAR(track->foot_width_px, place.width_px, 0.3 * place.width_px);
}

TEST(FootTracker, CameraShakeIsMeasuredAndRemoved) {
  synth::TrialSpec spec = BaseSpec();
  spec.nuisance.shake_px = 1.0;
  Scene scene = MakeScene(spec);
  Result<FootTrack> track = TrackClip(scene, OptionsFor(scene));
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  EXPECT_FALSE(track->reference_patches_px.empty());
  // the shake is measured from the rest window's (its median there), the truth from frame 0
  std::vector<double> offsets;
  for (const HeightSample& sample : track->samples) {
    if (sample.t_ns >= OptionsFor(scene).rest_from_ns && sample.t_ns < OptionsFor(scene).rest_to_ns) {
      offsets.push_back(scene.renderer.ShakeOffsetPx(sample.frame_index).y - sample.shake_y_px);
    }
  }
  ASSERT_FALSE(offsets.empty());
  std::nth_element(offsets.begin(), offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2), offsets.end());
  const double first_shake_y = offsets[offsets.size() / 2];
  double shake_span = 0, sum_sq = 0, worst = 0;
  for (const HeightSample& sample : track->samples) {
    if (sample.frame_index < 3) continue;  // the templates' frames are not measured
    const double true_shake = scene.renderer.ShakeOffsetPx(sample.frame_index).y - first_shake_y;
    shake_span = std::max(shake_span, std::abs(true_shake));
    EXPECT_NEAR(sample.shake_y_px, true_shake, 0.25) << "frame " << sample.frame_index;
    const double error = sample.rise_px - scene.TrueRisePx(sample.t_ns);
    sum_sq += error * error;
    worst = std::max(worst, std::abs(error));
  }
  EXPECT_GT(shake_span, 2.0);  // the shake is far larger than the threshold ...
  EXPECT_LT(std::sqrt(sum_sq / static_cast<double>(track->samples.size())), 0.2);  // ... gone
  EXPECT_LT(worst, 0.8);
  const int64_t truth_ns = TruthNsAboveMm(scene, 1.0);
  EXPECT_NEAR(static_cast<double>(track->above_threshold.t_ns), static_cast<double>(truth_ns),
              3.0 * static_cast<double>(scene.frame_ns));
  // (its uncertainty, 29 ms, does not hold this 35 ms error: the shake's own estimation error
  // is not in it; the encoded CI clip ci-16-shake holds its truth)

}

TEST(FootTracker, ShadowChangeAloneIsNotALift) {
  // the same scene with and without shadows, the foot at rest: the frames fade from one to
  // the other, so only the shadows change (under the foot too)
  synth::TrialSpec spec = BaseSpec();
  spec.duration_s = 1.0;
  Scene shaded = MakeScene(spec);
  spec.nuisance.shadow = false;
  Scene bare = MakeScene(spec);
  const cv::Mat with_shadow = shaded.renderer.RenderFrame(0, 0).clone();
  const cv::Mat without_shadow = bare.renderer.RenderFrame(0, 0).clone();
  ASSERT_GT(cv::norm(with_shadow, without_shadow, cv::NORM_INF), 40);

  // at 1 mm, and even at a twentieth of a pixel
  for (const std::optional<double> threshold_px : {std::optional<double>(), std::optional(0.05)}) {
    FootTracker::Options options = OptionsFor(shaded);
    options.threshold_px = threshold_px;
    FootTracker tracker(options);
    for (int64_t k = 0; k < 60; ++k) {
      const double fade = std::clamp((static_cast<double>(k) - 20) / 30, 0.0, 1.0);
      Frame frame;
      frame.index = k;
      frame.t_ns = k * shaded.frame_ns;
      cv::addWeighted(with_shadow, 1 - fade, without_shadow, fade, 0, frame.bgr);
      ASSERT_TRUE(tracker.Process(frame).ok());
    }
    Result<FootTrack> track = tracker.Finish();
    ASSERT_FALSE(track.ok()) << track->Brief();
    EXPECT_EQ(track.status().code(), StatusCode::kNotFound);
    EXPECT_NE(track.status().message().find("the foot never lifts"), std::string::npos)
        << track.status().message();
  }
}

// A textured picture shifted up by rise_px (bilinear: sub-pixel motion).
cv::Mat ShiftedUp(const cv::Mat& picture, double rise_px) {
  const cv::Matx23d shift(1, 0, 0, 0, 1, -rise_px);
  cv::Mat out;
  cv::warpAffine(picture, out, shift, picture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

cv::Mat Texture(cv::Size size, uint64_t seed, double low, double high) {
  cv::Mat texture(size, CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(texture, cv::RNG::UNIFORM, low, high);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.5);
  return texture;
}

// Options for a hand-drawn scene: its region, a 0.5 px threshold, rest 1.0 .. 1.5 s.
FootTracker::Options DrawnOptions(cv::Rect foot_roi_px) {
  FootTracker::Options options;
  options.foot_roi_px = foot_roi_px;
  options.threshold_px = 0.5;
  options.rest_from_ns = 1'000'000'000;
  options.rest_to_ns = 1'500'000'000;
  options.compression_error_px = 0;
  return options;
}

// Tracks `count` hand-drawn 30 fps frames (`draw(t_s)`: float grey levels; key frames where
// `is_key(index)`, every frame without it).
Result<FootTrack> TrackDrawn(const FootTracker::Options& options, int64_t count,
                             const std::function<cv::Mat(double)>& draw,
                             const std::function<bool(int64_t)>& is_key = {}) {
  FootTracker tracker(options);
  constexpr int64_t kFrameNs = 33'333'333;
  for (int64_t k = 0; k < count; ++k) {
    Frame frame;
    frame.index = k;
    frame.t_ns = k * kFrameNs;
    frame.keyframe = !is_key || is_key(k);
    cv::Mat grey8;
    draw(static_cast<double>(frame.t_ns) * 1e-9).convertTo(grey8, CV_8UC1);
    cv::cvtColor(grey8, frame.bgr, cv::COLOR_GRAY2BGR);
    LIFTOFF_RETURN_IF_ERROR(tracker.Process(frame));
  }
  return tracker.Finish();
}

// TrackDrawn, the 0.5 px instant checked against truth_s: within two frames and inside its
// interval.
void ExpectDrawnLiftoff(const FootTracker::Options& options, int64_t count,
                        const std::function<cv::Mat(double)>& draw, double truth_s) {
  const Result<FootTrack> track = TrackDrawn(options, count, draw);
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double found_s = static_cast<double>(track->above_threshold.t_ns) * 1e-9;
  EXPECT_NEAR(found_s, truth_s, 2.0 / 30) << track->Brief();
  EXPECT_LE(std::abs(found_s - truth_s),
            static_cast<double>(track->above_threshold.uncertainty_ns) * 1e-9 + 1e-3);
}

TEST(FootTracker, ARobotFillingTheRegionsMarginAndRisingWithTheFootIsNoGround) {
  // hand-drawn, not the renderer: a small robot whose body and other legs fill the
  // region's margin down to 8 px above the foot's bottom, rising at 0.8 times the foot's
  // rise as it tips (re-drawn hard3d-06, --seed 2000); the floor below is still. Measured
  // against the body, the foot would cross 0.5 px at 3.5 s instead of 3.224 s.
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 1, 90, 200), body = Texture(size, 2, 20, 110),
                foot = Texture(size, 3, 0, 60);
  cv::Mat body_mask(size, CV_32FC1, cv::Scalar(0)), foot_mask(size, CV_32FC1, cv::Scalar(0));
  body_mask.rowRange(0, 96).setTo(1.0);
  cv::circle(foot_mask, cv::Point(100, 88), 10, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto rise_px = [](double t_s) { return t_s > 3.0 ? 10 * (t_s - 3.0) * (t_s - 3.0) : 0.0; };
  const auto draw = [&](double t_s) {
    const cv::Mat b = ShiftedUp(body_mask, 0.8 * rise_px(t_s));
    const cv::Mat f = ShiftedUp(foot_mask, rise_px(t_s));
    const cv::Mat grey = floor.mul(1 - b) + ShiftedUp(body, 0.8 * rise_px(t_s)).mul(b);
    return cv::Mat(grey.mul(1 - f) + ShiftedUp(foot, rise_px(t_s)).mul(f));
  };
  ExpectDrawnLiftoff(DrawnOptions(cv::Rect(75, 55, 50, 50)), 120, draw, 3.0 + std::sqrt(0.05));
}

TEST(FootTracker, APartMovedByTheBendAndLostLongBeforeTheLiftoffIsNoFoot) {
  // hand-drawn: a textured part of the leg in the region's top rises 8 px as the test
  // begins (the bend, 2-3 s) and is covered at 4 s (its patches lost, their last level
  // 8 px up); the foot rises from 8 s and is carried off 0.5 s later, 25 px up (its patches
  // lost a few frames into the rise, as a tipping robot's foot is: re-drawn hard3d-07,
  // --seed 3000)
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 4, 90, 200), leg = Texture(size, 5, 20, 110),
                foot = Texture(size, 6, 0, 60);
  cv::Mat leg_mask(size, CV_32FC1, cv::Scalar(0)), foot_mask(size, CV_32FC1, cv::Scalar(0));
  leg_mask(cv::Rect(80, 58, 40, 14)).setTo(1.0);
  cv::circle(foot_mask, cv::Point(100, 92), 10, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto bend_px = [](double t_s) { return 8.0 * std::clamp(t_s - 2.0, 0.0, 1.0); };
  const auto rise_px = [](double t_s) { return t_s > 8.0 ? 100 * (t_s - 8.0) * (t_s - 8.0) : 0.0; };
  cv::RNG rng(7);
  cv::Mat covered(size, CV_32FC1);
  const auto draw = [&](double t_s) {
    const cv::Mat l = ShiftedUp(leg_mask, bend_px(t_s)), f = ShiftedUp(foot_mask, rise_px(t_s));
    rng.fill(covered, cv::RNG::UNIFORM, 0, 255);  // what covers them: unlike anything
    const cv::Mat leg_now = t_s < 4.0 ? ShiftedUp(leg, bend_px(t_s)) : covered;
    const cv::Mat foot_now = t_s < 8.5 ? ShiftedUp(foot, rise_px(t_s)) : covered;
    const cv::Mat grey = floor.mul(1 - l) + leg_now.mul(l);
    return cv::Mat(grey.mul(1 - f) + foot_now.mul(f));
  };
  ExpectDrawnLiftoff(DrawnOptions(cv::Rect(70, 50, 60, 52)), 300, draw, 8.0 + std::sqrt(0.005));
}

TEST(FootTracker, APartThatMovedLongBeforeTheLiftoffAndStayedUpIsNoFoot) {
  // hand-drawn: a small textured part in the region's top slips 8 px up at 2-2.2 s and
  // stays there to the clip's end; the foot rises from 8 s and is carried off 0.5 s later,
  // 25 px up (its patches lost a few frames into the rise), so the part ends higher than
  // the foot's patches' last levels (re-drawn hard3d-02, --seed 7000, took such a patch for
  // the foot alone, 12 s early)
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 14, 90, 200), part = Texture(size, 15, 20, 110),
                foot = Texture(size, 16, 0, 60);
  cv::Mat part_mask(size, CV_32FC1, cv::Scalar(0)), foot_mask(size, CV_32FC1, cv::Scalar(0));
  part_mask(cv::Rect(108, 60, 10, 8)).setTo(1.0);
  cv::circle(foot_mask, cv::Point(96, 90), 12, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto slip_px = [](double t_s) { return 8.0 * std::clamp((t_s - 2.0) / 0.2, 0.0, 1.0); };
  const auto rise_px = [](double t_s) { return t_s > 8.0 ? 100 * (t_s - 8.0) * (t_s - 8.0) : 0.0; };
  cv::RNG rng(17);
  cv::Mat covered(size, CV_32FC1);
  const auto draw = [&](double t_s) {
    const cv::Mat m = ShiftedUp(part_mask, slip_px(t_s)), f = ShiftedUp(foot_mask, rise_px(t_s));
    rng.fill(covered, cv::RNG::UNIFORM, 0, 255);
    const cv::Mat foot_now = t_s < 8.5 ? ShiftedUp(foot, rise_px(t_s)) : covered;
    const cv::Mat grey = floor.mul(1 - m) + ShiftedUp(part, slip_px(t_s)).mul(m);
    return cv::Mat(grey.mul(1 - f) + foot_now.mul(f));
  };
  ExpectDrawnLiftoff(DrawnOptions(cv::Rect(70, 55, 56, 52)), 300, draw, 8.0 + std::sqrt(0.005));
}

TEST(FootTracker, AFootOutrunningItsPatchesWidensTheIntervalToTheirCrossing) {
  // hand-drawn: a small foot rises fast from 3 s and is carried off 0.3 s later, 9 px up
  // (its patches lost a few frames into the rise); its shadow on the floor beside it rises
  // later and slower and is followed to the clip's end, so it ends highest and is taken for
  // the foot (hard3d-06, a side view at 0.44 px a mm, was 0.24 s late so). The foot's own
  // patches crossed first: the interval must reach down to them.
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 8, 90, 200), foot = Texture(size, 9, 0, 60),
                shadow = Texture(size, 10, 20, 80);
  cv::Mat foot_mask(size, CV_32FC1, cv::Scalar(0)), shadow_mask(size, CV_32FC1, cv::Scalar(0));
  cv::circle(foot_mask, cv::Point(92, 80), 7, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  cv::circle(shadow_mask, cv::Point(110, 92), 5, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto rise_px = [](double t_s) { return t_s > 3.0 ? 100 * (t_s - 3.0) * (t_s - 3.0) : 0.0; };
  const auto shadow_px = [](double t_s) { return t_s > 3.3 ? 6 * (t_s - 3.3) : 0.0; };
  cv::RNG rng(11);
  cv::Mat covered(size, CV_32FC1);
  const auto draw = [&](double t_s) {
    const cv::Mat f = ShiftedUp(foot_mask, rise_px(t_s)),
                  d = ShiftedUp(shadow_mask, shadow_px(t_s));
    rng.fill(covered, cv::RNG::UNIFORM, 0, 255);
    const cv::Mat foot_now = t_s < 3.3 ? ShiftedUp(foot, rise_px(t_s)) : covered;
    const cv::Mat grey = floor.mul(1 - d) + ShiftedUp(shadow, shadow_px(t_s)).mul(d);
    return cv::Mat(grey.mul(1 - f) + foot_now.mul(f));
  };
  const Result<FootTrack> track = TrackDrawn(DrawnOptions(cv::Rect(75, 60, 50, 50)), 150, draw);
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double truth_s = 3.0 + std::sqrt(0.005);
  const double found_s = static_cast<double>(track->above_threshold.t_ns) * 1e-9;
  const double uncertainty_s = static_cast<double>(track->above_threshold.uncertainty_ns) * 1e-9;
  EXPECT_LE(std::abs(found_s - truth_s), uncertainty_s + 1e-3) << track->Brief();
  // widened down to the foot's own crossing, no further: its lower end within two frames
  // before the truth, and the whole interval well under the 0.5 s reach
  EXPECT_GE(found_s - uncertainty_s, truth_s - 2.0 / 30) << track->Brief();
  EXPECT_LT(uncertainty_s, 0.25) << track->Brief();
  EXPECT_TRUE(track->low_confidence);
  const bool said =
      std::any_of(track->warnings.begin(), track->warnings.end(), [](const std::string& w) {
        return w.find("patches lost during the rise") != std::string::npos;
      });
  EXPECT_TRUE(said) << track->Brief();
}

TEST(FootTracker, PatchesDisagreeingOnTheCrossingWidenTheInterval) {
  // hand-drawn: a foot in three parts side by side that leave the floor 0.3 s apart (a tiny
  // tumbling foot whose patches partly hold the ground lag it: re-drawn hard3d-04, --seed
  // 5000), all ending 12 px up; the first part's crossing is the truth, the found one
  // follows the middle part.
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 12, 90, 200);
  std::vector<cv::Mat> parts, looks;
  for (int k = 0; k < 3; ++k) {
    cv::Mat mask(size, CV_32FC1, cv::Scalar(0));
    mask(cv::Rect(76 + 16 * k, 70, 16, 20)).setTo(1.0);
    parts.push_back(mask);
    looks.push_back(Texture(size, 13 + static_cast<uint64_t>(k), 0, 60));
  }
  const auto rise_px = [](double t_s, int k) {
    const double from_s = 3.0 + 0.3 * k;
    return t_s > from_s ? std::min(12.0, 20 * (t_s - from_s) * (t_s - from_s)) : 0.0;
  };
  const auto draw = [&](double t_s) {
    cv::Mat grey = floor.clone();
    for (int k = 0; k < 3; ++k) {
      const cv::Mat m = ShiftedUp(parts[static_cast<size_t>(k)], rise_px(t_s, k));
      grey = grey.mul(1 - m) + ShiftedUp(looks[static_cast<size_t>(k)], rise_px(t_s, k)).mul(m);
    }
    return grey;
  };
  const Result<FootTrack> track = TrackDrawn(DrawnOptions(cv::Rect(70, 55, 60, 50)), 150, draw);
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double truth_s = 3.0 + std::sqrt(0.5 / 20);
  const double found_s = static_cast<double>(track->above_threshold.t_ns) * 1e-9;
  const double uncertainty_s = static_cast<double>(track->above_threshold.uncertainty_ns) * 1e-9;
  EXPECT_GT(found_s - truth_s, 0.15) << track->Brief();  // the parts' median is late
  EXPECT_LE(found_s - truth_s, uncertainty_s + 1e-3) << track->Brief();
  // the parts cross 0.3 s apart: a robust sigma of about 0.3 s, not a run-away interval
  EXPECT_LT(uncertainty_s, 0.6) << track->Brief();
}

// A round textured foot (10 px radius, centred at `centre_px`) on a textured floor (seeds
// `seed` and `seed` + 1), shown `shown_px(t_s)` px up, tracked as TrackDrawn does.
Result<FootTrack> TrackDrawnRoundFoot(const FootTracker::Options& options, int64_t count,
                                      const std::function<double(double)>& shown_px, uint64_t seed,
                                      cv::Point centre_px,
                                      const std::function<bool(int64_t)>& is_key = {}) {
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, seed, 90, 200), foot = Texture(size, seed + 1, 0, 60);
  cv::Mat foot_mask(size, CV_32FC1, cv::Scalar(0));
  cv::circle(foot_mask, centre_px, 10, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto draw = [&](double t_s) {
    const double up_px = shown_px(t_s);
    const cv::Mat f = ShiftedUp(foot_mask, up_px);
    return cv::Mat(floor.mul(1 - f) + ShiftedUp(foot, up_px).mul(f));
  };
  return TrackDrawn(options, count, draw, is_key);
}

// A lamp's +-40 % flicker through a rolling shutter: bands 120 rows apart that roll by 0.37
// of a band every frame, over the whole picture (each row times 1 + 0.4 sin(...)). A patch
// registered with one gain and offset takes the band's change across its rows partly for
// motion; levelled against the rows beside the region, the foot is found as without bands
// (`liftoff synth --set hard3d --flicker 0.5 --flicker-readout-ms 30 --exposure-ms 4`: 4 of
// 8 within 0.005 rad unlevelled, liftoffs up to 15.9 s early).
TEST(FootTracker, AFootUnderRollingBandsIsFoundAsWithout) {
  const auto shown_px = [](double t_s) {
    const double x = t_s - 3.0;
    return x > 0 ? 1.0 * x + 2.0 * x * x : 0.0;  // 0.5 px up at 3.309 s
  };
  const cv::Size size(200, 150);
  const cv::Mat floor = Texture(size, 21, 90, 200), foot = Texture(size, 22, 0, 60);
  cv::Mat foot_mask(size, CV_32FC1, cv::Scalar(0));
  cv::circle(foot_mask, cv::Point(100, 88), 10, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const auto draw = [&](double t_s) {
    const cv::Mat f = ShiftedUp(foot_mask, shown_px(t_s));
    cv::Mat picture = floor.mul(1 - f) + ShiftedUp(foot, shown_px(t_s)).mul(f);
    const double frame = std::round(t_s * 30);
    for (int y = 0; y < picture.rows; ++y) {
      picture.row(y) *= 1.0 + 0.4 * std::sin(2 * CV_PI * (y / 120.0 + 0.37 * frame));
    }
    return picture;
  };
  ExpectDrawnLiftoff(DrawnOptions(cv::Rect(75, 55, 50, 50)), 150, draw,
                     3.0 + (-1.0 + std::sqrt(1.0 + 4 * 2.0 * 0.5)) / (2 * 2.0));
}

// A still foot as H.264 shows it (shared/video-dev's d12 encoded again by OpenCV's H.264
// writer): a key frame every 2 s, the frames between copy it; the key frame at 6 s renews
// the picture with the foot's edge `step_px` higher, and it stays there to the end, 4 s on.
// Tracked through a lossy codec with `threshold_px`.
Result<FootTrack> TrackStillFootAKeyFrameMoved(double step_px, double threshold_px) {
  FootTracker::Options options = DrawnOptions(cv::Rect(75, 55, 50, 50));
  options.threshold_px = threshold_px;
  options.compression_error_px = 0.2;  // a lossy codec
  return TrackDrawnRoundFoot(
      options, 300, [step_px](double t_s) { return t_s >= 6.0 - 1e-6 ? step_px : 0.0; }, 10,
      cv::Point(100, 88), [](int64_t index) { return index % 60 == 0; });
}

TEST(FootTracker, AStillFootAKeyFrameMovedThreeThresholdsIsNoLift) {
  // 1.5 px, 3 thresholds of 0.5 px: a lift goes on rising, this is none
  const Result<FootTrack> track = TrackStillFootAKeyFrameMoved(1.5, 0.5);
  ASSERT_FALSE(track.ok()) << track->Brief();
  EXPECT_EQ(track.status().code(), StatusCode::kNotFound);
  EXPECT_NE(track.status().message().find("the foot never lifts"), std::string::npos)
      << track.status().message();
  EXPECT_NE(track.status().message().find("4 times the 0.50 px threshold"), std::string::npos)
      << track.status().message();
}

TEST(FootTracker, ASmallRobotsStillFootAKeyFrameMovedUnderTwoPxIsNoLift) {
  // a small robot's (a 0.2 px threshold: 1 mm at 0.2 px a mm, d12 of shared/video-dev at
  // half size): 1.2 px, six thresholds. Four thresholds are not enough here: under 2 px is
  // no lift through a lossy codec.
  const Result<FootTrack> track = TrackStillFootAKeyFrameMoved(1.2, 0.2);
  ASSERT_FALSE(track.ok()) << track->Brief();
  EXPECT_EQ(track.status().code(), StatusCode::kNotFound);
  EXPECT_NE(track.status().message().find("under 2.00 px"), std::string::npos)
      << track.status().message();
}

// A foot whose predicted frames drift, as H.264 showed re-drawn hard3d-07 (--seed 21000
// --led-on-spread 1): a key frame a second; in the one from 4 s the shown edge creeps up by
// 0.3 px in three codec steps, and the key frame at 5 s shows it 0.55 px lower, where it
// stays. The foot lifts at 5.78 s (2 px/s + 2 px/s^2 from -0.25 px: 0.5 px up at 5.987 s),
// held still by the codec until the key frame at 6 s. Levelled as a new picture quality,
// the drift became a rise into the rest, and with the lag-free key frames rising one after
// another the knee came early.
TEST(FootTracker, AKeyFrameThatUndoesADriftBeginsTheRest) {
  const auto shown_px = [](double t_s) {
    const double x = t_s - 5.78;
    if (t_s >= 6.0 - 1e-6) return -0.25 + 2.0 * x + 2.0 * x * x;
    if (t_s >= 5.0 - 1e-6) return -0.25;
    if (t_s >= 4.75) return 0.3;
    if (t_s >= 4.5) return 0.2;
    return t_s >= 4.3 ? 0.1 : 0.0;
  };
  FootTracker::Options options = DrawnOptions(cv::Rect(70, 50, 60, 60));
  options.compression_error_px = 0.2;  // a lossy codec
  const Result<FootTrack> track =
      TrackDrawnRoundFoot(options, 240, shown_px, 12, cv::Point(100, 95),
                          [](int64_t index) { return index % 30 == 0; });
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double found_s = static_cast<double>(track->above_threshold.t_ns) * 1e-9;
  const double truth_s = 5.78 + (-2.0 + std::sqrt(4.0 + 4 * 2.0 * 0.5)) / (2 * 2.0);
  // (levelled: 106 ms early, inside its +-325 ms)
  EXPECT_NEAR(found_s, truth_s, 2.0 / 30) << track->Brief();
  EXPECT_LE(std::abs(found_s - truth_s),
            static_cast<double>(track->above_threshold.uncertainty_ns) * 1e-9 + 1e-3)
      << track->Brief();
}

// Three frames 2.6 thresholds below rest a second before the lift (re-drawn hard3d-02,
// --seed 23000 --keyframe-interval 250 --led-on-spread 1: a noisy curve, 0.25 px rms, dipped
// 2.2 thresholds for three frames 1.8 s before its rise) are noise, not a curve that sank:
// the crossing stands (taken for a sinking, the instant moved to the middle of the dip and
// the crossing, 0.8 s early).
TEST(FootTracker, AFewFramesBelowRestAreNoSinking) {
  const auto shown_px = [](double t_s) {
    const double x = t_s - 5.0;
    if (t_s >= 5.0) return x + x * x;
    return t_s >= 4.0 - 1e-6 && t_s < 4.09 ? -1.3 : 0.0;
  };
  const Result<FootTrack> track = TrackDrawnRoundFoot(DrawnOptions(cv::Rect(70, 50, 60, 60)), 210,
                                                      shown_px, 14, cv::Point(100, 95));
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double found_s = static_cast<double>(track->above_threshold.t_ns) * 1e-9;
  const double truth_s = 5.0 + (-1.0 + std::sqrt(1.0 + 4 * 0.5)) / 2;
  EXPECT_NEAR(found_s, truth_s, 2.0 / 30) << track->Brief();
  for (const std::string& warning : track->warnings) {
    EXPECT_EQ(warning.find("sank"), std::string::npos) << warning;
  }
}

TEST(FootTracker, FootThatNeverLiftsIsNotFound) {
  synth::TrialSpec spec = BaseSpec();
  spec.motion.ramp_rate_rad_per_s = 0.05;  // 0.05 rad by the end: far from 0.25
  Scene scene = MakeScene(spec);
  Result<FootTrack> track = TrackClip(scene, OptionsFor(scene));
  ASSERT_FALSE(track.ok());
  EXPECT_EQ(track.status().code(), StatusCode::kNotFound);
  EXPECT_NE(track.status().message().find("the foot never lifts"), std::string::npos)
      << track.status().message();
}

// ---------------------------------------------------------------------------------------
// the instants

TEST(FootTracker, ThresholdInstantIsWithinTwoFramesAndItsUncertainty) {
  Scene scene = MakeScene(BaseSpec());
  Result<FootTrack> track = TrackClip(scene, OptionsFor(scene));
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const int64_t truth_ns = TruthNsAboveMm(scene, 1.0);
  const int64_t error_ns = track->above_threshold.t_ns - truth_ns;
  // (the renderer lifts its sprite by blending two rows, which a registration reads with a
  // sawtooth error of up to ~0.1 px: about 2 frames at 1 mm here)
  EXPECT_LT(std::abs(error_ns), 2 * scene.frame_ns) << track->Brief();
  EXPECT_LE(std::abs(error_ns), track->above_threshold.uncertainty_ns);
  EXPECT_LT(track->above_threshold.uncertainty_ns, 3 * scene.frame_ns);
  // the frames either side of the instant bracket it
  EXPECT_LE(track->above_threshold.frame_before * scene.frame_ns, track->above_threshold.t_ns);
  EXPECT_GE(track->above_threshold.frame_after * scene.frame_ns, track->above_threshold.t_ns);
  EXPECT_NEAR(track->threshold_px, scene.renderer.px_per_mm(), 1e-9);
  EXPECT_NEAR(track->rest_rise_px, 0.0, 0.01);
  // the onset: the knee of the curve, where the foot leaves the ground
  const int64_t leaves_ns = *scene.timeline.FirstVideoNsAbove(0.0);
  EXPECT_LE(std::abs(track->onset.t_ns - leaves_ns), track->onset.uncertainty_ns) << track->Brief();
  EXPECT_LT(std::abs(track->onset.t_ns - leaves_ns), 3 * scene.frame_ns);
  EXPECT_LT(track->onset.t_ns, track->above_threshold.t_ns);
}

TEST(FootTracker, ThresholdInPixelsOrInMillimetres) {
  Scene scene = MakeScene(BaseSpec());
  const double px_per_mm = scene.renderer.px_per_mm();

  FootTracker::Options in_px = OptionsFor(scene);
  in_px.threshold_px = 2.0;  // ignores threshold_mm
  Result<FootTrack> by_px = TrackClip(scene, in_px);
  ASSERT_TRUE(by_px.ok()) << by_px.status().ToString();
  EXPECT_DOUBLE_EQ(by_px->threshold_px, 2.0);
  EXPECT_LT(std::abs(by_px->above_threshold.t_ns - TruthNsAboveMm(scene, 2.0 / px_per_mm)),
            2 * scene.frame_ns);

  FootTracker::Options in_mm = OptionsFor(scene);
  in_mm.threshold_mm = 3.0;
  Result<FootTrack> by_mm = TrackClip(scene, in_mm);
  ASSERT_TRUE(by_mm.ok()) << by_mm.status().ToString();
  EXPECT_NEAR(by_mm->threshold_px, 3.0 * px_per_mm, 1e-9);
  EXPECT_LT(std::abs(by_mm->above_threshold.t_ns - TruthNsAboveMm(scene, 3.0)), 2 * scene.frame_ns);
  EXPECT_GT(by_mm->above_threshold.t_ns, by_px->above_threshold.t_ns);  // 2 px < 3 mm
}

TEST(FootTracker, EstimatesTheScaleFromTheFootWidth) {
  for (const int width_px : {640, 1280}) {
    synth::TrialSpec spec = BaseSpec();
    spec.camera.width_px = width_px;
    spec.camera.height_px = width_px * 9 / 16;
    // a fast ramp: a short clip at 720p (the foot up for its last 0.6 s)
    spec.duration_s = 1.2;
    spec.motion.height.liftoff_rad = 0.1;
    spec.motion.ramp_rate_rad_per_s = 0.5;
    Scene scene = MakeScene(spec);
    for (const bool tape : {false, true}) {
      FootTracker::Options options = OptionsFor(scene);
      options.px_per_mm = 0;
      if (tape) options.tape_colour = Foot::kA;
      Result<FootTrack> track = TrackClip(scene, options);
      ASSERT_TRUE(track.ok()) << track.status().ToString();
      EXPECT_TRUE(track->px_per_mm_estimated);
      // coarse: the width of the patches that moved with the foot
      EXPECT_NEAR(track->px_per_mm / scene.renderer.px_per_mm(), 1.0, 0.25)
          << width_px << " px wide, tape " << tape;
      EXPECT_EQ(track->located_by_tape, tape);
      EXPECT_NE(track->Brief().find("scale estimated"), std::string::npos) << track->Brief();
      ASSERT_FALSE(track->warnings.empty());
      EXPECT_NE(track->warnings[0].find("scale estimated"), std::string::npos);
    }
  }
}

TEST(FootTracker, FindsAFootOffCentreInAWideRegionByItsMotionAndChecksItsTapeColour) {
  Scene scene = MakeScene(BaseSpec());
  FootTracker::Options options = OptionsFor(scene);
  // a region three feet wide with the foot at its right end: its centre is not the foot's
  const double foot_width_px = scene.renderer.placement(Foot::kA).width_px;
  const int extra = static_cast<int>(std::lround(2 * foot_width_px));
  options.foot_roi_px.x -= extra;
  options.foot_roi_px.width += extra;
  options.tape_colour = Foot::kA;
  Result<FootTrack> track = TrackClip(scene, options);
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  EXPECT_TRUE(track->located_by_tape);
  EXPECT_NEAR(track->foot_center_x_px, scene.renderer.placement(Foot::kA).center_x_px,
              foot_width_px / 2);
  EXPECT_LT(std::abs(track->above_threshold.t_ns - TruthNsAboveMm(scene, 1.0)), 2 * scene.frame_ns);

  // another foot's colour is not there: said, and the foot tracked all the same (C, purple:
  // B's orange is also the wooden floor's hue, which the foot's patches partly hold)
  options.foot_roi_px = scene.FootRoi();
  options.tape_colour = Foot::kC;
  Result<FootTrack> wrong = TrackClip(scene, options);
  ASSERT_TRUE(wrong.ok()) << wrong.status().ToString();
  EXPECT_FALSE(wrong->located_by_tape);
  const bool said = std::any_of(wrong->warnings.begin(), wrong->warnings.end(), [](const std::string& w) {
    return w.find("does not show foot C's tape colour") != std::string::npos;
  });
  EXPECT_TRUE(said);
  EXPECT_LT(std::abs(wrong->above_threshold.t_ns - TruthNsAboveMm(scene, 1.0)), 2 * scene.frame_ns);
}

TEST(FootTracker, NoiseFlickerAndMotionBlurKeepTheInstantWithinThreeFramesAndItsUncertainty) {
  synth::TrialSpec spec = BaseSpec();
  spec.nuisance.noise_sigma = 4;
  spec.nuisance.flicker_amplitude = 0.2;
  spec.nuisance.flicker_hz = 100;
  spec.nuisance.motion_blur_samples = 4;
  Scene scene = MakeScene(spec);
  Result<FootTrack> track = TrackClip(scene, OptionsFor(scene));
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  EXPECT_LT(track->rest_noise_px, 0.05);
  // every frame lossless, a key frame: their scatter is the frames' own noise
  EXPECT_GE(track->still_noise_px, track->rest_noise_px);
  EXPECT_LT(track->still_noise_px, 0.05);
  EXPECT_LT(std::abs(track->above_threshold.t_ns - TruthNsAboveMm(scene, 1.0)),
            3 * scene.frame_ns)
      << track->Brief();
  EXPECT_LE(std::abs(track->above_threshold.t_ns - TruthNsAboveMm(scene, 1.0)),
            track->above_threshold.uncertainty_ns);
}

TEST(FootTracker, EncodedH264ClipGivesTheLiftoffRotationWithinTolerance) {
  // the whole way a camera file goes: rendered, encoded with B-frames, decoded
  synth::TrialSpec spec = BaseSpec();
  spec.camera.codec = synth::VideoCodec::kH264;
  liftoff::testing::ScratchDir scratch;
  Result<synth::WrittenTrial> written = synth::WriteTrial(spec, TestCalibration(), scratch.path());
  ASSERT_TRUE(written.ok()) << written.status().ToString();
  const synth::GroundTruth& truth = written->truth;

  FootTracker::Options options;
  options.foot_roi_px = {truth.foot_roi_px.x_px, truth.foot_roi_px.y_px, truth.foot_roi_px.width_px,
                         truth.foot_roi_px.height_px};
  options.px_per_mm = truth.px_per_mm;
  options.tape_colour = truth.foot;
  FootTracker tracker(options);
  cv::VideoCapture capture(written->video_path.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  Frame frame;
  while (capture.read(frame.bgr)) {
    ASSERT_LT(static_cast<size_t>(frame.index), truth.frame_times_ns.size());
    frame.t_ns = truth.frame_times_ns[static_cast<size_t>(frame.index)];
    ASSERT_TRUE(tracker.Process(frame).ok());
    ++frame.index;
  }
  EXPECT_EQ(static_cast<size_t>(frame.index), truth.frame_times_ns.size());
  tracker.SetRestWindow(*truth.led_on_video_ns, *truth.led_on_video_ns + 200'000'000);
  Result<FootTrack> track = tracker.Finish();
  ASSERT_TRUE(track.ok()) << track.status().ToString();
  const double error_s =
      static_cast<double>(track->above_threshold.t_ns - *truth.liftoff_1mm_video_ns) / 1e9;
  EXPECT_LT(std::abs(error_s * spec.motion.ramp_rate_rad_per_s), 0.01) << track->Brief();
}

// ---------------------------------------------------------------------------------------
// invalid input

TEST(FootTracker, RegionOutsideTheFrameIsInvalidArgument) {
  FootTracker::Options options;
  options.foot_roi_px = cv::Rect(600, 400, 80, 90);
  FootTracker tracker(options);
  Frame frame;
  frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(90));
  const Status status = tracker.Process(frame);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), "foot ROI 80x90 at (600, 400) is outside the 640x480 frame");

  options.foot_roi_px = cv::Rect(-5, 100, 40, 60);
  FootTracker left_of_it(options);
  EXPECT_EQ(left_of_it.Process(frame).message(),
            "foot ROI 40x60 at (-5, 100) is outside the 640x480 frame");

}

TEST(FootTracker, InvalidOptionsAreRejectedNamingTheField) {
  const auto message = [](const std::function<void(FootTracker::Options&)>& change) {
    FootTracker::Options options;
    options.foot_roi_px = cv::Rect(10, 10, 40, 60);
    change(options);
    return options.Validate().message();
  };
  EXPECT_EQ(message([](auto&) {}), "");
  EXPECT_NE(message([](auto& o) { o.foot_roi_px = {}; }).find("foot_roi_px"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.threshold_mm = 0; }).find("threshold_mm"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.threshold_px = -1; }).find("threshold_px"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.px_per_mm = -1; }).find("px_per_mm"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.foot_width_mm = 0; }).find("foot_width_mm"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.rest_frames = 1; }).find("rest_frames"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.exposure_s = -1; }).find("exposure_s"), std::string::npos);
  EXPECT_NE(message([](auto& o) { o.min_quality = 2; }).find("min_quality"), std::string::npos);

  // the tracker reports its options' error
  FootTracker::Options bad;
  FootTracker tracker(bad);
  Frame frame;
  frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(90));
  EXPECT_EQ(tracker.Process(frame).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(tracker.Finish().status().code(), StatusCode::kInvalidArgument);
}

TEST(FootTracker, NoFramesOrFramesOutOfOrderAreInvalidArgument) {
  FootTracker::Options options;
  options.foot_roi_px = cv::Rect(100, 100, 40, 60);
  FootTracker tracker(options);
  EXPECT_EQ(tracker.Finish().status().code(), StatusCode::kInvalidArgument);

  Frame frame;
  frame.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(90));
  frame.t_ns = 1'000'000'000;
  ASSERT_TRUE(tracker.Process(frame).ok());
  frame.index = 1;
  frame.t_ns = 900'000'000;
  EXPECT_EQ(tracker.Process(frame).code(), StatusCode::kInvalidArgument);
  frame.t_ns = 1'100'000'000;
  frame.bgr = cv::Mat(240, 320, CV_8UC3, cv::Scalar::all(90));
  EXPECT_EQ(tracker.Process(frame).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace liftoff::video
