// Small kernels over the foot's height curve (private to the video module): how far a
// codec may have held it back, where it crosses a level, and whether the rise model's
// crossing agrees with the curve's own. Heights in px, up positive, one per sample; NaN
// where a frame was not measured.
#pragma once

#include <cstddef>
#include <vector>

#include "liftoff/core/robust_stats.h"
#include "liftoff/video/foot_tracker.h"

namespace liftoff::video::internal {

/// The curve's step at frame `key`: the median of the `count` frames from it less that of
/// the `count` before it (0 where either has no finite value).
double LevelStep(const std::vector<double>& curve, size_t key, size_t count);

/// Whether key frame `key`'s step (`step`, LevelStep) undoes a drift of the predicted frames
/// before it: since the previous key frame the curve moved from its level there by at least
/// half the step, the other way (a codec's prediction errors piling up until the picture is
/// renewed), rather than holding a level the key frame changed (a new picture quality).
/// Medians of `count` frames at each end of that stretch; false when the nearest earlier key
/// frame is missing or fewer than `2 count` frames before.
bool ResetsADrift(const std::vector<HeightSample>& samples, const std::vector<double>& curve,
                  size_t key, double step, size_t count);

/// A key frame between still stretches renews the picture's quality, not the foot's place:
/// for each key frame among frames (start, cut] where the `frames` frames before it and the
/// `frames` from it on each hold within `quiet_px`, the frames from `start` to it are
/// levelled with those after (a lag-free key frame weighs as many samples, so its small
/// offset would pull the rise model's knee to it). A key frame with the rise going on after
/// it is left alone: its step may be a codec's catch-up.
void LevelQuietKeyframes(const std::vector<HeightSample>& samples, size_t start, size_t cut,
                         size_t frames, double quiet_px, std::vector<double>& levelled);

/// How much the curve's key frames scatter where the foot stands still (frames [first,
/// last)), px: kMadToSigma times the median of the absolute changes between consecutive key
/// frames, over the square root of 2 (SuccessiveDifferenceSigma: a slow drift adds only its
/// change per key frame). A lossy codec copies a still picture between key frames, so a
/// rest window without one measures no noise at all, while each key frame quantises the
/// foot's edge anew (re-drawn hard3d-07, --seed 4000).
/// 0 with fewer than kMinKeyframeChanges changes; in an intra-only clip every frame is a key
/// frame.
inline constexpr size_t kMinKeyframeChanges = 4;
double KeyframeNoisePx(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                       size_t first, size_t last);

/// The key frame soon after the fit's top (frame `cut`) that shows the foot without a
/// codec's lag, to extend the fit to: the first within reach_s of it while the running
/// median `smooth` stays within reach_tops times its value at the cut (a fast rise the model
/// cannot follow), the clip's last smooth_half frames excepted (their running median sees
/// only the past), and before the curve falls back by threshold_px from its highest since
/// the cut (a key frame renews a lagging picture upwards: a fall is the tracker losing the
/// foot). 0 for none.
size_t ReachKeyframe(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                     const std::vector<double>& smooth, size_t cut, size_t smooth_half,
                     double threshold_px, double reach_s, double reach_tops);

/// How far a codec may have held the curve back over frames [first, last], px: its largest
/// change in one frame beyond the larger of the changes either side of it (a frame held
/// back changes by nothing and the next catches up; a fast rise changes by much in every
/// frame, which is motion, not lag) and beyond `noise_px` (a noisy curve's changes stand out
/// of their neighbours' by chance), times `factor` (a catch-up may be partial), at least
/// `min_lag_px`. Needs first < last < height.size().
double LagBoundPx(const std::vector<double>& height, size_t first, size_t last, double min_lag_px,
                  double factor, double noise_px = 0.0);

/// The curve's first sustained crossing of `level` among frames [first, last]: the first of
/// three frames in a row at or above it; last + 1 for none.
size_t SustainedCrossing(const std::vector<double>& height, size_t first, size_t last,
                         double level);

/// When the curve surely stood above `level`, s: the time of its first sustained crossing
/// of level + margin_px among frames [first, last] (SustainedCrossing: three frames in a
/// row at or above it); NaN for none. A codec's lag holds a curve back, never ahead, so
/// with margin_px a few sigmas of its noise the foot was above `level` by then. (Not the
/// start of the final run above it: on re-drawn hard3d-04, --seed 2000, that moved the
/// estimate from +0.0003 to +0.0060 rad; an earlier excursion of three frames only leaves
/// the fit's interval as it was.)
double SurelyAboveS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                    size_t first, size_t last, double level, double margin_px);

/// The first frame of the run at or above `level` that ends at frame `last` (unmeasured
/// frames join it); last + 1 when the curve ends below it.
size_t FinalRunStart(const std::vector<double>& height, size_t first, size_t last, double level);

/// Where a line through the 5 frames around frame `at` (those among [first, last]) crosses
/// `level`, s; NaN when `at` has fewer than two frames before it or the line does not rise.
double LineCrossingS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                     size_t at, size_t first, size_t last, double level);

/// LineCrossingS around the curve's first sustained crossing of `level`.
double LocalCrossingS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                      size_t first, size_t last, double level);

/// Whether the curve sank before frame `at`, and since when.
struct Sinking {
  bool sank = false;
  double depth_px = 0.0;  ///< how far below the rest level it went
  double rest_s = 0.0;    ///< its last frame within threshold_px of rest before sinking, s
};

/// A foot does not sink into the ground: a curve that goes below `rest_level` by more than
/// sunk_px among frames [first, at) measures more than the foot (a leg tilting as the robot
/// starts to tip, a shadow on the foot's patches), and the liftoff is only known to lie
/// after its last frame within threshold_px of rest before the deepest one.
Sinking SankBefore(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                   size_t first, size_t at, double rest_level, double threshold_px,
                   double sunk_px);

/// The liftoff of a curve that sank: it lies between the last rest frame before the sinking
/// (rest_s) and the crossing found, as uncertain as `uncertainty_s` (a curve held down
/// crosses late, but the crossing keeps its own uncertainty: re-drawn hard3d-04, --seed
/// 3000, at 0.25 px per mm, crossed 65 ms before the truth). Returns the middle of
/// [min(rest_s, crossing - uncertainty), crossing + uncertainty] and its half-width.
struct Instant {
  double t_s = 0.0;
  double uncertainty_s = 0.0;
};
Instant SunkCrossing(double rest_s, double crossing_s, double uncertainty_s);

/// The model's crossing of `level` checked against the curve over frames [first, last].
struct CurveCheck {
  bool disagreed = false;
  double crossing_s = 0.0;     ///< the curve's crossing, s (when disagreed)
  double uncertainty_s = 0.0;  ///< its half-width, s (when disagreed)
};

/// A codec's lag holds the curve back, never ahead: a model whose crossing (model_s +-
/// model_uncertainty_s) lies wholly after the first frame of the curve's final run above
/// `level` missed the rise (a shape it cannot follow, a step taken for the rise's start).
/// The curve's own crossing is the answer then: the line through the frames around that
/// frame (or the straight line between it and the frame before), as uncertain as the model's
/// instant or the interval between those two frames.
CurveCheck CheckCrossing(const std::vector<HeightSample>& samples,
                         const std::vector<double>& height, size_t first, size_t last,
                         double level, double model_s, double model_uncertainty_s);

/// How much the foot's own patches disagree on the crossing of `level_px`, s: kMadToSigma times
/// the median absolute deviation of the patches' own crossings (a robust sigma), with three
/// patches crossing or more, else 0. A patch crosses before the first of `sustain_frames`
/// measured frames in a row above the level from frame `first` on (or of at least
/// `short_frames` up to its last measured frame: a fast foot outruns its patches),
/// interpolated from its last measured frame at or below the level (strictly above, so the
/// two frames differ and the line is never flat); one above from `first` on has none.
/// `curves_px` holds each patch's height per sample (px, NaN where unmeasured).
double PatchCrossingSpreadS(const std::vector<HeightSample>& samples,
                            const std::vector<std::vector<double>>& curves_px, size_t first,
                            double level_px, size_t sustain_frames, size_t short_frames);

}  // namespace liftoff::video::internal
