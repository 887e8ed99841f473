// The sync LED: where it is (given, or located automatically as the small region with
// the largest sustained brightness step) and every instant it switches on, with
// sub-frame precision where a frame caught the switch-on mid-exposure.
//
// The brightness of the LED region in a frame whose exposure [t, t + E) saw the LED on
// for the last fraction f of it is off + f (on - off): every pixel integrates the light,
// so the region's sum is linear in f, also where the lit LED clips at 255 (the on level
// is then the clipped one). The detector measures f against the levels of the frames
// before and after the step, so the switch-on instant is t + (1 - f) E. When the LED
// switched on between two exposures (f = 1), it lies between the previous exposure's end
// and this frame's start. E (the exposure) is rarely known: by default it is only bounded
// by the camera's frame interval T, and the estimate is the middle of every instant
// consistent with some exposure in (0, T] (t + (1 - f) T / 2 for a partial frame, the
// middle of the two frames' starts for a full one), which bounds the error by half a
// frame interval. With Options::exposure_s the partial-frame estimate is exact up to the
// noise of f. Each instant comes with the half-width of that interval as its uncertainty.
//
// Regions: with an ROI, the whole ROI is measured (it should hold the LED, its glow and a
// margin for camera shake). Without one, the frame is cut into cells of cell_px (every
// other row sampled) and every 2 x 2 block of cells is a candidate region; each keeps a
// few frames of its brightness and a fixed-size record per step it made, never pixels.
// The measure is the sum of B, G and R: the LED must brighten its region, not only change
// its hue.
//
// A step counts when the region's brightness jumps and holds: the 4 frames before it and
// the min_on_frames after it are flat compared with the step, it crosses threshold_frac of
// the way between the two levels in one frame (or two, with a partly lit one), the
// region's brightest channel (or its mean, if larger) steps by min_contrast_levels or
// more, the step stands out from what the rest of the frame did at that instant (codec
// key frames, lighting changes and camera shake step many regions at once), and the
// region then holds its new level, or returns to the old one, for 8 more frames (a moving
// foot does not). Mains flicker is taken out first: every frame's overall gain against a
// slow average of each cell, applied to the scene's light only. When locating, the cells
// around a step must look like a light switching (no cells stepping the other way, as an
// edge moved by shake makes them; not a row or a column of cells, as a shifted band), and
// the LED is the region with the largest step among those whose contrast is at least
// half the best one's. Limits: a small, dim LED under strong camera shake is missed
// rather than mistaken (the detector prefers kNotFound to a wrong instant); flicker is
// over-corrected where the lit LED fills much of its region.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "liftoff/core/status.h"
#include "liftoff/video/frame.h"

namespace liftoff::video {

/// One switch-on of the LED (and its switch-off, when it went off again in the clip).
struct LedPulse {
  /// Estimated switch-on instant, video clock, ns.
  int64_t on_ns = 0;
  /// Half-width of the interval that surely holds the switch-on, ns (from the exposure
  /// assumption and the noise of the partial-frame fraction).
  int64_t on_uncertainty_ns = 0;
  /// First frame that saw the LED on at all (Frame::index) and the fraction of its
  /// exposure during which it was on (1: it switched on between two exposures).
  int64_t first_lit_frame = 0;
  double first_lit_fraction = 1.0;
  /// Switch-off instant, ns, when the LED went off again within the clip.
  std::optional<int64_t> off_ns;
  /// Half-width of the interval that surely holds the switch-off, ns (0 without off_ns).
  int64_t off_uncertainty_ns = 0;
};

/// What the LED detector found in a clip.
struct LedResult {
  /// Region measured, px; whether it was located automatically.
  cv::Rect roi_px;
  bool roi_located = false;
  /// Mean brightness of the region, grey levels 0..255 (mean of B, G and R), off and on
  /// (medians of the frames around the first switch-on).
  double off_level = 0.0;
  double on_level = 0.0;
  /// The LED's own on-off contrast: the step of the region's brightest colour channel
  /// (its brightest pixel), grey levels 0..255, at the first switch-on. This is what
  /// min_contrast_levels and dim_warning_levels are compared with.
  double contrast_levels = 0.0;
  /// Every switch-on in the clip, in order (at least one: Finish fails otherwise).
  std::vector<LedPulse> pulses;
  /// For people: "LED dim: on-off contrast 9 grey levels (expected >= 20)", "LED already
  /// on in the first frame: the first switch-on may have been missed", ...
  std::vector<std::string> warnings;
  /// "LED on at 0.6167 s +- 4.2 ms (frame 37, 64 % lit), ROI 590x50+28x28 (located), 1 pulse".
  std::string Brief() const;
};

/// Streams frames in decode order; memory stays flat in the clip's length (the automatic
/// locator keeps O(1) state per image cell, never frames).
class LedDetector {
 public:
  struct Options {
    /// Region to watch, px. Empty (0 x 0): locate the LED automatically.
    cv::Rect roi_px;
    /// Automatic locating: cell size of the coarse brightness grid, px (4 .. 64; a
    /// multiple of 16 takes the fast path). The LED and its glow should fit in 2 x 2 cells.
    int cell_px = 16;
    /// A switch-on is a rise to above off + threshold_frac (on - off), 0 < x < 1 ...
    double threshold_frac = 0.5;
    /// ... held flat for at least this many frames (flicker and noise are not pulses),
    /// 1 .. 100; the step is then confirmed over 8 more frames (see above).
    int min_on_frames = 3;
    /// Smallest on-off contrast accepted as an LED (LedResult::contrast_levels), grey
    /// levels (> 0); below dim_warning_levels (>= min_contrast_levels) a warning says the
    /// LED is dim.
    double min_contrast_levels = 8.0;
    double dim_warning_levels = 20.0;
    /// Camera exposure time, s (>= 0, at most 1 s); 0 = unknown: any exposure up to the
    /// frame interval is assumed (see above).
    double exposure_s = 0.0;

    Status Validate() const;
  };

  explicit LedDetector(const Options& options);
  LedDetector(LedDetector&&) noexcept;
  LedDetector& operator=(LedDetector&&) noexcept;
  ~LedDetector();

  /// Feeds the next frame (decode order, increasing t_ns). kInvalidArgument when a given
  /// ROI is not inside the frame ("LED ROI 700x20+40x40 is outside the 640x480 frame").
  Status Process(const Frame& frame);
  /// The result. kNotFound "the LED never switches on" when no pulse was found (with the
  /// best candidate's contrast in the message); kInvalidArgument when no frame was fed.
  Result<LedResult> Finish() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
