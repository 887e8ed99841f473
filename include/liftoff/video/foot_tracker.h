// The foot: its vertical position to sub-pixel precision, frame by frame, against the
// ground and the rest of the scene (camera shake measured on a reference region and
// removed; the foot's shadow on the ground is not the foot), and the liftoff instants:
// the onset of rise (the knee of the height curve) and the first instant the foot is
// above its rest height by a threshold (px, or mm with a pixel scale; default 1 mm).
//
// Method:
//   - First frame: the foot is located in its region (its width and centre from its side
//     edges, or from its tape band when the tape colour is given; its bottom edge near the
//     region's bottom). The template is the colour profile down the foot's central columns
//     (30 % of its width), averaged across them, from one foot width above the bottom edge
//     to 2 px above it: the foot, its tape band and what holds it, never the ground or the
//     shadow below the foot. Up to three textured patches of the ground beside the foot
//     (clear of the foot, its shadow and the leg above it) are the shake references.
//   - Every frame: each reference patch's translation is measured by registering its
//     column- and row-averaged profiles against the first frame's; the shake is their
//     median. The foot's profile is taken at the shake-corrected columns and registered
//     against the template along the vertical only: current(y) = gain * template(y - d)
//     + offset, the template interpolated linearly between rows, which a least-squares
//     fit solves in closed form per pixel interval (gain and offset absorb flicker). The
//     rise is the shake minus the foot's shift d.
//   - Finish: the rest level and noise over the rest window; the first sustained crossing
//     of the threshold; a hinge (flat, then rising as a power 1 .. 3 of the time since its
//     knee) fitted from the rest window to five thresholds up. The knee is the onset; the
//     hinge's crossing of the threshold is the liftoff instant (a line through the frames
//     around the crossing when the hinge does not follow the curve there). The hinge
//     averages over the stepwise updates a codec makes of slow sub-pixel motion (H.264
//     lets a slowly rising foot lag by up to ~0.4 px, then catch up). Instants are dated
//     at the frames' mid-exposure.
// Assumptions: the camera looks at the foot from the side, roughly level; the foot is
// darker or brighter than the ground beside it; whatever holds the foot (a leg) covers
// the central 30 % of the foot's width up to one foot width above its bottom; the region
// of interest ends at most a quarter of the foot's width below the foot's bottom edge.
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
  /// Foot's upward displacement from its position in the reference (first) frame, image
  /// px (up positive), shake removed.
  double rise_px = 0.0;
  /// Camera shake measured on the reference region, px (image y, down positive).
  double shake_y_px = 0.0;
  /// Match quality of the foot's template (the fraction of the profile's variance the
  /// fit explains), 0..1 (low: occluded, blurred, lost).
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
  /// Every frame's sample, in order (40 bytes a frame: the only per-frame state kept).
  std::vector<HeightSample> samples;
  /// Region tracked and the reference region used for shake, px (the bounding box of
  /// reference_patches_px; empty when no reference was found and shake is not removed).
  cv::Rect foot_roi_px;
  cv::Rect reference_roi_px;
  /// The reference patches whose median translation is the shake, px (first frame).
  std::vector<cv::Rect> reference_patches_px;
  /// The foot as located in the first frame, px: centre column, width, bottom edge row
  /// (subpixel; pixel centres at integers), and the rows of its template [first, last].
  double foot_center_x_px = 0.0;
  double foot_width_px = 0.0;
  double foot_bottom_px = 0.0;
  int template_first_row = 0;
  int template_last_row = 0;
  /// Whether the foot was located by its tape colour (Options::tape_colour).
  bool located_by_tape = false;
  /// Rest: mean rise over the rest window, px, and its noise (standard deviation), px.
  double rest_rise_px = 0.0;
  double rest_noise_px = 0.0;
  /// Scale used, px per mm (0 when the threshold was given in px), and whether it was
  /// estimated from the foot's width rather than given.
  double px_per_mm = 0.0;
  bool px_per_mm_estimated = false;
  /// Threshold applied, px above rest.
  double threshold_px = 0.0;
  /// Largest rise above rest after the start of the rest window, px.
  double max_rise_px = 0.0;
  /// Samples are dated at mid-exposure: frame t_ns + this, ns (exposure / 2; a quarter
  /// of the frame interval when the exposure is unknown).
  int64_t exposure_offset_ns = 0;
  /// Frames left out of the rest level and the instants for a poor match.
  int64_t poor_frames = 0;
  /// Onset of rise (knee of the height curve) and first instant above the threshold,
  /// video clock (mid-exposure). The onset's uncertainty spans every knee a hinge fit
  /// allows within two standard deviations, plus the time the hinge takes to rise by three
  /// times its misfit near the crossing (a smooth knee is poorly defined, and compression
  /// holds a slowly starting foot still). The threshold instant's spans the crossings of
  /// those hinges and the rest level's error, with the codec's mean sub-pixel lag over the
  /// slope in quadrature (Options::compression_error_px), plus the misfit over the slope,
  /// 3 % of the threshold when the scale is estimated, and the exposure's timing when
  /// unknown.
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
    /// (then mm are ignored). foot_width_mm is the width of the foot as seen from the
    /// camera, mm: 40 mm is the synthetic scenes' rubber block; a real foot's width must
    /// be given (or px_per_mm), or the estimated scale is wrong by their ratio.
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
    /// It must show static, textured ground (not the foot, its shadow or another foot).
    cv::Rect reference_roi_px;
    /// Camera exposure time, s; 0 = unknown (taken as half the frame interval). A frame
    /// shows the foot's mean position over its exposure, so samples are dated at
    /// mid-exposure when the instants are computed.
    double exposure_s = 0.0;
    /// The largest mean offset a lossy codec leaves in the foot's sub-pixel position while
    /// it moves slowly, px, >= 0: H.264 lets a slowly rising foot lag by 0 .. ~0.4 px,
    /// then catch up, so the curve runs late by up to ~0.2 px on average, which no fit can
    /// see. The lag is a sawtooth about the hinge whose rms is the hinge's misfit m, so the
    /// offset used is min(sqrt(3) m, this); over the slope at the crossing, it is added in
    /// quadrature to the threshold instant's spread. AnalyzeClip sets 0 for a lossless
    /// codec (FrameTimingReport::lossless_codec).
    double compression_error_px = 0.2;
    /// A crossing counts only when this many consecutive frames are above the threshold
    /// (a noise spike is not a liftoff), >= 1.
    int confirm_frames = 3;
    /// Frames whose match quality is below this are left out of the rest level and the
    /// instants, 0..1.
    double min_quality = 0.5;

    Status Validate() const;
  };

  explicit FootTracker(const Options& options);
  FootTracker(FootTracker&&) noexcept;
  FootTracker& operator=(FootTracker&&) noexcept;
  ~FootTracker();

  /// Feeds the next frame. kInvalidArgument when the foot region is not inside the frame
  /// ("foot ROI 600x400+80x90 is outside the 640x480 frame"; the reference region too),
  /// when the options do not validate, when the picture is not BGR 8-bit or changes size,
  /// or when t_ns does not increase. The first frame is the reference: the foot is
  /// located and its template taken there (~0.7 ms at 720p); each frame after costs
  /// ~0.06 ms at 720p or 1080p.
  Status Process(const Frame& frame);
  /// Sets the rest window after the fact (the LED instant is known only at the end of a
  /// single pass); overrides Options::rest_from_ns/rest_to_ns.
  void SetRestWindow(int64_t rest_from_ns, int64_t rest_to_ns);
  /// The result. kNotFound "the foot never lifts" (with its largest rise in the message)
  /// when it never stays above the threshold from the start of the rest window on;
  /// kInvalidArgument when no frame was fed, the options do not validate, or the rest
  /// window holds no frame with a clear view of the foot. May be called more than once;
  /// on an expiring tracker (std::move(tracker).Finish()) the samples move into the result
  /// instead of being copied, and the tracker is left without them.
  Result<FootTrack> Finish() const&;
  Result<FootTrack> Finish() &&;
  /// The frames fed so far (the rest window rule needs their times before Finish).
  const std::vector<HeightSample>& samples() const;

 private:
  // everything but the samples
  Result<FootTrack> FinishWithoutSamples() const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace liftoff::video
