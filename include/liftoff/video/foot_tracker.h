// The foot: its vertical motion to sub-pixel precision, frame by frame, against the static
// ground around it, and the liftoff instants: the onset of rise (the knee of the height
// curve) and the first instant the foot is above its rest height by a threshold (px, or mm
// with a pixel scale; default 1 mm). Nothing is assumed of the foot's shape, colour or of
// the view: the foot is whatever in its region rises against the ground.
//
// Method:
//   - The work image: the foot region with a margin of 30 % of its size on every side,
//     scaled down so that the region's smaller side is at most 64 px, as float BGR.
//   - Patches: the mean of the first 4 frames is cut into 9 x 9 px candidate patches (work
//     px, every 3 px); those with the strongest vertical texture are kept, none overlapping
//     another by more than half: up to 56 inside the region, 24 in the margin.
//   - Every frame: each patch is registered against its template (translation, gain and
//     offset, Gauss-Newton from the previous frame's position: src/video/patch_registration.h).
//     A patch whose residual jumps (occlusion, the foot leaving it) is not measured in that
//     frame and is dropped after 8 such frames in a row. Per frame only the patches' vertical
//     positions are kept (4 bytes a patch).
//   - Finish: each patch's rest level is its median over the rest window. The ground is
//     the patches that end (median of the last 0.5 s) within 0.5 px of where they rested;
//     their median per frame is the camera's shake. The foot is the region's patches that
//     end highest (at least 60 % of the second highest's rise) and move with one another;
//     its height is their median per frame less the shake. A shadow changes but does not
//     rise with the foot, a reflection in a glossy floor moves down, the ground stays:
//     none of them is the foot.
//   - The liftoff: the height curve's running median (0.15 s either side) must stay above
//     the threshold for 0.5 s (at least 5 frames) and reach five thresholds (at least 3 px):
//     a rise that goes on rising; no single frame decides. From there back to where the
//     curve rests (at most 3 s of rest; a step within the rest ends it), the model "flat,
//     then level + slope t + curvature t^2, both >= 0" is fitted with a robust (Huber) loss
//     over a grid of knees (src/video/rise_fit.h). The crossing of the fitted level plus
//     the threshold is the liftoff instant; the knee is the onset. Uncertainty: the spread
//     of crossings of every knee that fits within a two-sigma loss increase (the noise
//     inflated by its frame-to-frame correlation, as codecs update slow motion in steps),
//     with a codec's sub-pixel lag (compression_error_px) over the rise rate, and 3 % of
//     the threshold when the scale is estimated, in quadrature.
//   - A frame's time is the middle of its exposure (the frame shows the foot there).
// Limits: the foot region must show the foot at rest with room above it to rise and some
// static ground; the clip must go on for about 0.5 s after the foot is five thresholds up;
// a foot that rises less than about 1.5 px in all is "never lifts".
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
  /// The frame's time (Frame::t_ns: the start of its exposure), video clock, ns.
  int64_t t_ns = 0;
  /// Foot's upward displacement from its rest, image px (up positive), shake removed
  /// (a frame where the foot was not measured holds the previous value, quality 0).
  double rise_px = 0.0;
  /// Camera shake measured on the reference region, px (image y, down positive).
  double shake_y_px = 0.0;
  /// Fraction of the foot's patches measured in this frame, 0..1 (low: occluded, lost).
  double quality = 1.0;
  /// Frame::keyframe: the frame shows the foot where it is (no codec lag).
  bool keyframe = true;
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
  /// Every frame's sample, in order (40 bytes a frame: the only per-frame state kept).
  std::vector<HeightSample> samples;
  /// Region tracked and the bounding box of the ground patches, px (empty when no static
  /// ground was found and shake is not removed).
  cv::Rect foot_roi_px;
  cv::Rect reference_roi_px;
  /// The ground patches whose median motion is the shake, px (at rest).
  std::vector<cv::Rect> reference_patches_px;
  /// The patches that moved with the foot, px (at rest).
  std::vector<cv::Rect> foot_patches_px;
  /// The foot's patches' bounding box at rest, px: centre column, width, bottom row
  /// (pixel centres at integers).
  double foot_center_x_px = 0.0;
  double foot_width_px = 0.0;
  double foot_bottom_px = 0.0;
  /// Whether the tracked foot shows the tape colour of Options::tape_colour (false without
  /// one): a check, never a requirement.
  bool located_by_tape = false;
  /// Rest: mean rise over the rest window, px, and its noise (standard deviation), px.
  double rest_rise_px = 0.0;
  double rest_noise_px = 0.0;
  /// The still foot's noise the liftoff's uncertainty counts, px: rest_noise_px, or the key
  /// frames' scatter before the rise when larger (a lossy codec's copied frames show none).
  double still_noise_px = 0.0;
  /// Scale used, px per mm (0 when the threshold was given in px), and whether it was
  /// estimated from the foot's width rather than given.
  double px_per_mm = 0.0;
  bool px_per_mm_estimated = false;
  /// Threshold applied, px above rest.
  double threshold_px = 0.0;
  /// Largest rise above rest after the start of the rest window, px.
  double max_rise_px = 0.0;
  /// Samples are dated at frame t_ns + this, ns: 0, a frame's time being the middle of its
  /// exposure.
  int64_t exposure_offset_ns = 0;
  /// Frames the liftoff model was fitted over [first, last] (Frame::index), and the
  /// robust standard deviation of its residuals, px.
  int64_t fit_first_frame = 0;
  int64_t fit_last_frame = 0;
  double fit_noise_px = 0.0;
  /// True when the evidence is weak (few foot patches, a noisy curve, a wide interval, a
  /// clip that ends soon after the liftoff): the warnings say which.
  bool low_confidence = false;
  /// Frames left out of the rest level and the instants for a poor match.
  int64_t poor_frames = 0;
  /// Onset of rise (the fitted model's knee) and first instant above the threshold (its
  /// crossing), video clock, with the uncertainties described above.
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
    /// The foot whose tape colour the tracked foot should show (A blue, B orange, C purple,
    /// D red): a check reported as FootTrack::located_by_tape, never used to find it.
    std::optional<Foot> tape_colour;
    /// Threshold above rest: in mm with a scale (px_per_mm given, or estimated from the
    /// foot's width foot_width_mm when px_per_mm is 0), or in px when threshold_px is set
    /// (then mm are ignored). foot_width_mm is the width of the foot as seen from the
    /// camera, mm (a parameter of the robot, not of liftoff's synthetic block): give the
    /// real foot's width, or better px_per_mm, else the estimated scale is wrong by their
    /// ratio.
    /// Ranges: threshold_mm (0, 100], threshold_px (0, 1000], px_per_mm 0 .. 1000,
    /// foot_width_mm (0, 10000].
    double threshold_mm = 1.0;
    std::optional<double> threshold_px;
    double px_per_mm = 0.0;
    double foot_width_mm = 40.0;
    /// Rest window, video clock, ns: the foot's rest height is its mean over
    /// [rest_from_ns, rest_to_ns) (the caller passes e.g. LED-on .. LED-on + 1 s). Empty
    /// window (to <= from): the first rest_frames frames.
    int64_t rest_from_ns = 0;
    int64_t rest_to_ns = 0;
    int rest_frames = 15;
    /// Camera exposure time, s; 0 = unknown. Only checked (at most the frame interval): a
    /// frame's time is the middle of its exposure, where it shows the foot.
    double exposure_s = 0.0;
    /// The largest mean offset a lossy codec leaves in the foot's sub-pixel position while
    /// it moves slowly, px, >= 0 (H.264 lets a slowly rising foot lag, then catch up):
    /// over the rise rate at the crossing, added in quadrature to the liftoff instant's
    /// uncertainty. AnalyzeClip sets 0 for a lossless codec
    /// (FrameTimingReport::lossless_codec).
    double compression_error_px = 0.2;
    /// Frames where fewer than this fraction of the foot's patches were measured count as
    /// poor frames (FootTrack::poor_frames), 0..1.
    double min_quality = 0.5;

    Status Validate() const;
    /// Validate() but for the region (a clip analysed without a foot region still checks
    /// the rest).
    Status ValidateAllButRegion() const;
  };

  explicit FootTracker(const Options& options);
  FootTracker(FootTracker&&) noexcept;
  FootTracker& operator=(FootTracker&&) noexcept;
  ~FootTracker();

  /// Feeds the next frame. kInvalidArgument when the foot region is not inside the frame
  /// ("foot ROI 80x90 at (600, 400) is outside the 640x480 frame"), when the options do not
  /// validate, when the picture is not BGR 8-bit or changes size, or when t_ns does not
  /// increase. The first 4 frames make the templates; every frame after registers the
  /// patches (bench/video_bench prints the cost).
  Status Process(const Frame& frame);
  /// The part of a `frame_px` frame that Process reads: the foot region with a margin
  /// around it, and its rows three times its width either side (they measure a rolling
  /// shutter's flicker bands). A reader need convert only this (VideoReader::ConvertOnly).
  cv::Rect RegionRead(cv::Size frame_px) const;
  /// Sets the rest window after the fact (the LED instant is known only at the end of a
  /// single pass); overrides Options::rest_from_ns/rest_to_ns.
  void SetRestWindow(int64_t rest_from_ns, int64_t rest_to_ns);
  /// The result. kNotFound "the foot never lifts" (with its largest rise in the message)
  /// when nothing in the region rises for good above the threshold, or when the region
  /// shows nothing to track; kInvalidArgument when no frame was fed, the options do not
  /// validate, or the rest window holds no measured frame. May be called more than once;
  /// on an expiring tracker (std::move(tracker).Finish()) the samples move into the result
  /// instead of being copied, and the tracker is left without them.
  Result<FootTrack> Finish() const&;
  Result<FootTrack> Finish() &&;
  /// The frames fed so far (the rest window rule needs their times before Finish).
  const std::vector<HeightSample>& samples() const;

 private:
  // the result around `samples` (the tracker's, copied or moved)
  Result<FootTrack> FinishWith(std::vector<HeightSample> samples) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
