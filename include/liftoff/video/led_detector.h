// The sync LED: where it is (given, or located automatically as the small region with
// the largest sustained brightness step) and every instant it switches on, with
// sub-frame precision where a frame caught the switch-on mid-exposure.
//
// Exposure convention: a frame's timestamp t is the middle of its exposure [t - E/2,
// t + E/2]. A frame that saw the LED on for the fraction f of its exposure is f of the way
// from the off to the on level in every pixel that does not clip (pixels integrate light).
// The switch-on lies in the union, over every exposure allowed, of the instants consistent
// with the last dark frame and the first lit one, on their real timestamps (a dropped frame
// there widens it); the estimate is its middle and its half-width the uncertainty. E is
// rarely known: by default any exposure in (0, T] (T the usual frame interval), so a partly
// lit frame dates the switch-on to t + (1/2 - f) E for some such E (error at most T / 4), and
// a switch-on between exposures to the middle of the two frames' timestamps (T / 2 without
// drops). With Options::exposure_s a partly lit frame dates it to within the noise of f.
// A partly lit frame is always followed by a fully lit one (E <= T), which tells it from
// the light a codec's B-frame lends the frame before. Switch-offs: the same, time reversed.
//
// With an ROI the detector works on the ROI's pixels, so a 1 px LED in a region hundreds of
// times its size is found: each pixel's B + G + R against its own reference (an average of
// the frames that left the step window of the last 5 + min_on_frames, so a step is measured
// against frames before it), each row's flicker gain taken out first (measured on the same rows
// beside the ROI, in bands of 4 rows, interpolated: rolling-shutter banding), the ROI's outer 3 px
// left out (shake carries what lies just outside into them). The signal is the sum of the largest
// increases (a 256th of the ROI's pixels, at least 9) plus the largest decreases. Around a step the
// ROI's pixels that stepped clearly are the LED's: no light when pixels stepping the other way add
// up to half as much (an edge moved by shake or a passing part) or when they do not hold their
// levels; the dating sums those that do not clip when lit (all of them, marked clipped, when those
// carry less than a quarter of the step: then only the upper bound of f holds, as a clipped
// core reaches 255 even in a partly lit frame). The fraction is known to within 3 sigmas of
// the frame-to-frame noise (at least 0.08), widened downwards when the levels creep on after
// the step (a codec refining a small spot). contrast_levels is the brightest-channel step of
// the LED's third-brightest pixel.
//
// Without an ROI, the frame is cut into cells of cell_px (every other row sampled) and
// every 2 x 2 block of cells is a candidate region; each keeps a few frames of its
// brightness and a fixed-size record per step it made, never pixels. The measure is the
// sum of B, G and R; mains flicker is taken out by every frame's overall gain against a
// slow average of each cell; the cells around a step must look like a light switching (no
// cells stepping the other way, not a row or a column of cells), and the LED is the region
// with the largest step among those whose contrast is at least half the best one's.
//
// In both, a step counts when the signal jumps and holds: the 4 frames before it (the last
// may be partly lit already) and the min_on_frames after it (which may creep on by half the
// step, even after a partly lit frame: a codec building up a small spot) are flat compared
// with the step, it crosses threshold_frac of the way in one frame
// (or two), the LED's contrast reaches min_contrast_levels, the step stands out from what
// the rest of the frame did at that instant (codec key frames, lighting changes and shake
// step many regions at once; with an ROI, a step whose largest pixel step is 4 times the
// ROI's usual one stands out however the frame changed), and the signal then holds its
// new level (with an ROI, or goes on rising), or returns to the old one, for 8 more frames. A
// region's steps under half the contrast of its brightest switch-on are not pulses. With an ROI a
// switch-on a codec built up over 2 to 12 frames (held at a partial level, or wobbling) counts
// too, dated from its first frame lit for an unknown part of its exposure, with a warning. Limits:
// in an ROI where no LED ever lights, a codec's update of a still block by a few grey levels can
// pass for a dim LED; a small, dim LED under strong camera shake is missed rather than mistaken;
// located, a 1 px LED under flicker and shake loses to larger steps.
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
  /// exposure during which it was on (1: it switched on between two exposures; after a
  /// build-up, see LedResult::warnings, the level the codec showed it at, not a fraction of
  /// the exposure).
  int64_t first_lit_frame = 0;
  double first_lit_fraction = 1.0;
  /// Frames missing between the last dark frame and a fully lit first one (by the usual
  /// frame interval): on_ns then takes the first missing frame as the one that saw the
  /// switch-on, and on_uncertainty_ns still covers the whole gap. 0 without a gap, or
  /// when a partly lit first frame dates the switch-on itself.
  int missing_frames_before_on = 0;
  /// Frames in a row lit part way at the switch-on (0 or 1 normally; 2 or more a codec
  /// spread the step, which one switch-on cannot do with an exposure no longer than the
  /// frame interval: it built a small light up, or H.264's B-frames blended its step between
  /// their reference frames): on_uncertainty_ns then reaches from the last dark frame to the
  /// first wholly lit one, and first_lit_frame is the first of them. 0 after a build-up the
  /// one-step window could not see (LedResult::warnings), which has its own interval.
  int spread_frames = 0;
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
  /// The LED's own on-off contrast, grey levels 0..255, at the first switch-on: with an
  /// ROI, the brightest-channel step of the LED's third-brightest pixel; located, the step
  /// of the brightest channel (or of the mean, if larger) of the block's best cell. This
  /// is what min_contrast_levels and dim_warning_levels are compared with.
  double contrast_levels = 0.0;
  /// Every switch-on in the clip, in order (at least one: Finish fails otherwise).
  std::vector<LedPulse> pulses;
  /// The LED's brightness trace, with a given ROI: every frame's time (Frame::t_ns, video
  /// clock, ns) and the ROI's mean brightness that frame, grey levels 0..255 (mean of B, G
  /// and R, as off_level and on_level), in decode order (16 bytes a frame). Empty when the
  /// LED was located automatically: its region is known only at the end, and no frame is
  /// kept.
  std::vector<int64_t> trace_t_ns;
  std::vector<double> trace_brightness_levels;
  /// For people: "LED dim: on-off contrast 9 grey levels (expected >= 20)", "LED already
  /// on in the first frame: the first switch-on may have been missed", ...
  std::vector<std::string> warnings;
  /// "LED on at 0.6167 s +- 4.2 ms (frame 37, 64 % lit), ROI 28x28 at (590, 50) (located),
  /// 1 pulse".
  std::string Brief() const;
};

/// Streams frames in decode order; no frame is kept (with an ROI, its last 16 +
/// min_on_frames pictures and the 16-byte trace entry per frame; the automatic locator
/// keeps O(1) state per image cell, never frames).
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
  /// ROI is not inside the frame ("LED ROI 40x40 at (700, 20) is outside the 640x480 frame").
  Status Process(const Frame& frame);
  /// The parts of a `frame_px` frame that Process reads: with an ROI, the rows it spans
  /// (and the frame beside it, for the lighting) and the reference cells; without one, the
  /// whole frame. A reader need convert only these (VideoReader::ConvertOnly).
  std::vector<cv::Rect> RegionsRead(cv::Size frame_px) const;
  /// The result. kNotFound "the LED never switches on" when no pulse was found (with the
  /// best candidate's contrast in the message); kInvalidArgument when no frame was fed.
  Result<LedResult> Finish() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
