// Synthetic trials: the scene renderer. Draws what a fixed camera sees of a foot-lifting
// test, frame by frame, exactly as the trial's Timeline says it happened.
//
// The view: a side view from the robot's right, camera 0.62 m beside the feet's centre
// line, level with the gap between front and back feet, pitched ~8 degrees down. Front is
// to the right of the image. Left to right: C (back right, near), D (back left, far),
// B (front left, far), A (front right, near); the far feet sit 0.151 m further away, so
// they stand higher in the image and are drawn ~20 % smaller. The near feet (C, A) are
// 0.648 m apart and span 70 % of the image width, so the near feet's scale is
// 0.70 * width_px / 648 px per mm (1.38 px/mm at 1280 x 720, 0.69 at 640 x 360).
// Below: a test bed of plywood sheets (procedural from the seed: flat-sawn grain drawn as
// wavy nested arches, blotches, speckle, dark seams where sheets meet) with a white tape
// ruler (ticks every 10 mm) in front of the feet; above it a dark cloth backdrop carrying
// the sync LED on a small board. Each leg is a grey rod from the top of the frame to its
// foot, a rounded rubber block (40 x 30 mm) with a 10 mm band of the foot's tape colour
// (A blue, B orange, C purple, D red); rubber, collar and leg are neutral greys. A soft
// shadow ellipse lies under each foot; as the foot rises by h it shrinks (by up to 30 %,
// 1 - exp(-h / 15 mm)) and fades (depth 0.65 exp(-h / 12 mm)).
//
// Pixel coordinates: pixel centres at integers, so a row index r covers [r - 0.5, r + 0.5);
// an edge between rows 299 and 300 lies at 299.5.
//
// How a frame is made (RenderFrame):
//   1. a copy of the static scene, pre-rendered once (everything that never moves, with
//      the moving feet at rest);
//   2. the moving feet (the lifting one and, with diagonal_lag_rad > 0, its diagonal
//      partner) are recomposited only where they can differ from rest: the foot and leg
//      sprite (anti-aliased once at build time) translated by height * px_per_mm with
//      linear row interpolation (exact area coverage for the horizontal bottom edge),
//      over the bed darkened by the foot's soft shadow, averaged over
//      nuisance.motion_blur_samples sub-samples at the midpoints of the exposure's
//      equal parts (the exposure is centred on the frame's timestamp: ExposureStartNs);
//   3. flicker: the scene is scaled by the lamp's brightness averaged analytically over
//      the exposure, 1 + a * sin(2 pi f t);
//   4. the LED, self-lit (no flicker): the frame's "on" picture (disc of colour *
//      intensity, a white core above intensity 1, Gaussian bloom; each channel clipped at
//      255) is blended over the "off" picture (a dim grey disc) by the exact fraction of
//      the exposure during which the LED was on, computed from the switch-on instant, so
//      a partial frame's brightness is off + fraction * (on - off) in every pixel;
//   5. camera shake: the whole picture translated by a subpixel offset (bilinear), a
//      reflected random walk at +-4 px whose per-frame step has standard deviation
//      nuisance.shake_px, drawn from the seed (frame k's offset depends only on the seed
//      and k);
//   6. sensor noise: Gaussian values of standard deviation noise_sigma, rounded to grey
//      levels, come from a table drawn once from the seed that is one frame plus 65536
//      values long; each frame reads it from an offset (and with a sign) drawn from
//      (seed, frame index). This costs two saturating byte additions per pixel instead
//      of millions of Gaussian draws. Caveat: the noise of two frames are shifted copies
//      of the same table, uncorrelated pixel by pixel but not as whole patterns.
// Rendering frame k alone gives the same pixels as rendering every frame in order.
//
// Cost (one core): building ~45 ms at 640 x 360, ~200 ms at 1280 x 720, ~370 ms at
// 1920 x 1080; a frame ~0.6 ms at 720p and ~1.1 ms at 1080p with the default nuisances,
// ~2.7 ms and ~5.9 ms with noise, flicker, shake and 4 blur sub-samples.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "liftoff/core/manifest.h"
#include "liftoff/core/random.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/spec.h"

namespace liftoff::synth {

/// Renders a trial's frames. Build once per trial (the static scene, textures and noise
/// table are made here); RenderFrame is not thread-safe (it reuses buffers), use one
/// renderer per thread.
class SceneRenderer {
 public:
  /// Builds the static scene for `timeline`'s spec. kInvalidArgument when the spec does
  /// not validate; OpenCV failures come back as kInvalidArgument too.
  static Result<SceneRenderer> Create(const Timeline& timeline);

  /// The frame with timestamp `t_video_ns` (video clock; the middle of its exposure), BGR 8-bit,
  /// camera.width_px x camera.height_px. `frame_index` seeds the shake and the noise.
  cv::Mat RenderFrame(int64_t frame_index, int64_t t_video_ns);

  /// Image scale at the lifting foot, px per mm (vertical motion of the foot).
  double px_per_mm() const;
  /// The LED's region of interest: its disc with room for +-4 px of shake, clipped to
  /// the image.
  RegionPx led_roi_px() const { return led_roi_px_; }
  /// The lifting foot's region of interest: the foot block at rest and 40 mm above it,
  /// clipped to the image.
  RegionPx foot_roi_px() const { return foot_roi_px_; }
  /// Row of the lifting foot's bottom edge at rest, at zero shake (subpixel; see the
  /// pixel convention above).
  double foot_rest_bottom_px() const;
  /// Row of the lifting foot's bottom edge at a video instant, at zero shake:
  /// foot_rest_bottom_px() - height_mm * px_per_mm() (the truth tests compare against).
  double FootBottomPxAt(int64_t t_video_ns) const;
  /// Fraction of the exposure of the frame with timestamp t_video_ns (centred on it)
  /// during which the LED is on, 0 .. 1 (Timeline::LedOnFractionOfExposure, as the truth counts
  /// it).
  double LedOnFraction(int64_t t_video_ns) const;
  /// Camera shake of frame `frame_index`: the picture's translation, px (x right,
  /// y down); 0 without shake.
  cv::Point2d ShakeOffsetPx(int64_t frame_index);

  /// Placement of one foot in the image at rest and zero shake, for tests and tools.
  struct FootPlacement {
    double center_x_px = 0;  ///< column of the foot's centre
    double bottom_px = 0;    ///< row of its bottom edge
    double px_per_mm = 0;    ///< its scale
    double width_px = 0;     ///< foot block width
    double height_px = 0;    ///< foot block height
    double tape_top_px = 0;  ///< tape band, rows (top < bottom)
    double tape_bottom_px = 0;
  };
  const FootPlacement& placement(Foot foot) const { return placements_[static_cast<size_t>(foot)]; }

 private:
  SceneRenderer() = default;
  void Build(const Timeline& timeline);  // throws cv::Exception
  RegionPx ClippedRegion(double x0_px, double y0_px, double x1_px, double y1_px) const;
  // The LED's light (disc and bloom, per unit of its on-fraction) around its centre at
  // (led_x, led_y) canvas px: led_patch_, led_disc_alpha_, led_emission_.
  void BuildLedLight(const LedSpec& led, double led_x, double led_y);
  // The noise table (noise_positive_, noise_negative_); empty without noise.
  void BuildNoiseTable(const TrialSpec& spec);

  // A foot that moves: its sprite (premultiplied BGR and coverage, rows from canvas row
  // 0) and the scene behind it, over the region it can touch (canvas px, from row 0).
  struct MovingFoot {
    Foot foot = Foot::kA;
    cv::Rect region;
    cv::Mat background;         // CV_32FC3 over region: the scene without this foot
    cv::Mat sprite_colour;      // CV_32FC3, region columns, last row empty
    cv::Mat sprite_alpha;       // CV_32FC1
    int first_varying_row = 0;  // rows above it are all leg, the same as row 0
  };
  // Writes the foot averaged over the sub-samples' heights into the canvas (skipped when
  // all are 0, unless `force`: the static canvas already holds the foot at rest).
  void ComposeMovingFoot(const MovingFoot& moving, const std::vector<double>& heights_m, bool force,
                         cv::Mat& canvas) const;
  void ComposeLed(double fraction, cv::Mat& canvas) const;

  Timeline timeline_;
  int width_px_ = 0, height_px_ = 0;         // the image; the canvas has a margin around it
  std::array<FootPlacement, 4> placements_;  // image px
  cv::Mat static_canvas_;                    // CV_8UC3: everything, moving feet at rest
  std::vector<MovingFoot> moving_;
  cv::Rect led_patch_;      // canvas px: the LED's light
  cv::Mat led_disc_alpha_;  // CV_32FC1 over led_patch_
  cv::Mat led_emission_;    // CV_32FC3 over led_patch_
  int64_t exposure_ns_ = 1;
  RegionPx led_roi_px_, foot_roi_px_;
  std::vector<uint8_t> noise_positive_, noise_negative_;  // the noise table, split by sign
  std::vector<cv::Point2d> shake_px_;                     // the shake walk so far, from frame 0
  SplitMix64 shake_rng_{0};
  cv::Mat canvas_, shifted_;  // reused per frame
};

}  // namespace liftoff::synth
