// The sync LED: where it is (given, or located automatically as the small region with
// the largest sustained brightness step) and every instant it switches on, with
// sub-frame precision where a frame caught the switch-on mid-exposure.
//
// The brightness of the LED region in a frame whose exposure [t, t + E) saw the LED on
// for the last fraction f of it is off + f (on - off) (linear in every unsaturated pixel
// and in a clipped one too, since the camera integrates light that is then clipped
// identically in the on and off parts only when neither saturates: the detector measures
// f against the frame after and before it, which works under saturation because the
// region's mean is taken over pixels that reach the same clip in every lit frame). So
// the switch-on instant is t + (1 - f) E. E (the exposure) is rarely known: by default it
// is taken as the frame interval, which bounds the error by half an interval.
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
};

/// What the LED detector found in a clip.
struct LedResult {
  /// Region measured, px; whether it was located automatically.
  cv::Rect roi_px;
  bool roi_located = false;
  /// Mean brightness of the region, grey levels 0..255, off and on (medians).
  double off_level = 0.0;
  double on_level = 0.0;
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
    /// Automatic locating: cell size of the coarse brightness grid, px (4 .. 64).
    int cell_px = 16;
    /// A switch-on is a rise to above off + threshold_frac (on - off), 0 < x < 1 ...
    double threshold_frac = 0.5;
    /// ... held for at least this many frames (flicker and noise are not pulses), >= 1.
    int min_on_frames = 3;
    /// Smallest on-off contrast accepted as an LED, grey levels (> 0); below
    /// dim_warning_levels a warning says the LED is dim.
    double min_contrast_levels = 8.0;
    double dim_warning_levels = 20.0;
    /// Camera exposure time, s; 0 = unknown (taken as the frame interval).
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
