// Small kernels over the foot's height curve (private to the video module): how far a
// codec may have held it back, where it crosses a level, and whether the rise model's
// crossing agrees with the curve's own. Heights in px, up positive, one per sample; NaN
// where a frame was not measured.
#pragma once

#include <cstddef>
#include <vector>

#include "liftoff/video/foot_tracker.h"

namespace liftoff::video::internal {

/// How far a codec may have held the curve back over frames [first, last], px: its largest
/// change in one frame beyond the larger of the changes either side of it (a frame held
/// back changes by nothing and the next catches up; a fast rise changes by much in every
/// frame, which is motion, not lag), times `factor` (a catch-up may be partial), at least
/// `min_lag_px`. Needs first < last < height.size().
double LagBoundPx(const std::vector<double>& height, size_t first, size_t last,
                  double min_lag_px, double factor);

/// The curve's first sustained crossing of `level` among frames [first, last]: the first of
/// three frames in a row at or above it; last + 1 for none.
size_t SustainedCrossing(const std::vector<double>& height, size_t first, size_t last,
                         double level);

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

}  // namespace liftoff::video::internal
