// The foot: its vertical position to sub-pixel precision, frame by frame, against the
// ground and the rest of the scene (camera shake measured on a reference region and
// removed; the foot's shadow on the ground is not the foot), and the liftoff instants:
// the onset of rise (the knee of the height curve) and the first instant the foot is
// above its rest height by a threshold (px, or mm with a pixel scale; default 1 mm).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/video/frame.h"

namespace liftoff::video {

/// The foot in one frame.
struct HeightSample {
  int64_t frame_index = 0;
  int64_t t_ns = 0;
  /// Foot's upward displacement from its position in the reference frame, image px
  /// (up positive), shake removed.
  double rise_px = 0.0;
  /// Camera shake measured on the reference region, px (image y, down positive).
  double shake_y_px = 0.0;
  /// Match quality of the foot's template, 0..1 (low: occluded, blurred, lost).
  double quality = 1.0;
};

/// An instant with its uncertainty.
struct TimedEvent {
  int64_t t_ns = 0;
  /// Half-width of the interval that holds the instant, ns.
  int64_t uncertainty_ns = 0;
  /// The frames either side of it (Frame::index).
  int64_t frame_before = 0;
  int64_t frame_after = 0;
};

/// What the foot tracker found.
struct FootTrack {
  /// Every frame's sample, in order (24 bytes a frame: the only per-frame state kept).
  std::vector<HeightSample> samples;
  /// Region tracked and the reference region used for shake, px.
  cv::Rect foot_roi_px;
  cv::Rect reference_roi_px;
  /// Rest: mean rise over the rest window, px, and its noise (standard deviation), px.
  double rest_rise_px = 0.0;
  double rest_noise_px = 0.0;
  /// Scale used, px per mm (0 when the threshold was given in px), and whether it was
  /// estimated from the foot's width rather than given.
  double px_per_mm = 0.0;
  bool px_per_mm_estimated = false;
  /// Threshold applied, px above rest.
  double threshold_px = 0.0;
  /// Onset of rise (knee of the height curve) and first instant above the threshold.
  TimedEvent onset;
  TimedEvent above_threshold;
  std::vector<std::string> warnings;
  /// "liftoff (1 mm = 1.38 px) at 2.4562 s +- 3.1 ms, onset 2.3110 s +- 12 ms".
  std::string Brief() const;
};

/// Streams frames in decode order; keeps one HeightSample per frame (no pixels beyond the
/// foot's template and the reference region's).
class FootTracker {
 public:
  struct Options {
    /// Region around the foot, px: the foot at rest and room above it to rise (required).
    cv::Rect foot_roi_px;
    /// The foot whose tape colour to use (A blue, B orange, C purple, D red); empty:
    /// use brightness edges only.
    std::optional<Foot> tape_colour;
    /// Threshold above rest: in mm with a scale (px_per_mm given, or estimated from the
    /// foot's width foot_width_mm when px_per_mm is 0), or in px when threshold_px > 0
    /// (then mm are ignored).
    double threshold_mm = 1.0;
    double threshold_px = 0.0;
    double px_per_mm = 0.0;
    double foot_width_mm = 40.0;
    /// Rest window, video clock, ns: the foot's rest height is its mean over
    /// [rest_from_ns, rest_to_ns) (the caller passes e.g. LED-on .. LED-on + 1 s). Empty
    /// window (to <= from): the first rest_frames frames.
    int64_t rest_from_ns = 0;
    int64_t rest_to_ns = 0;
    int rest_frames = 15;
    /// Region for camera shake, px; empty: chosen automatically beside the foot region.
    cv::Rect reference_roi_px;

    Status Validate() const;
  };

  explicit FootTracker(const Options& options);
  FootTracker(FootTracker&&) noexcept;
  FootTracker& operator=(FootTracker&&) noexcept;
  ~FootTracker();

  /// Feeds the next frame. kInvalidArgument when the foot region is not inside the frame
  /// ("foot ROI 600x400+80x90 is outside the 640x480 frame").
  Status Process(const Frame& frame);
  /// Sets the rest window after the fact (the LED instant is known only at the end of a
  /// single pass); overrides Options::rest_from_ns/rest_to_ns.
  void SetRestWindow(int64_t rest_from_ns, int64_t rest_to_ns);
  /// The result. kNotFound "the foot never lifts" (with its largest rise in the message)
  /// when it never exceeds the threshold after the rest window; kInvalidArgument when no
  /// frame was fed.
  Result<FootTrack> Finish() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
