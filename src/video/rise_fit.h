// The liftoff model fitted to a height curve (private to the video module).
//
// A foot at rest, then lifted: h(t) = level for t < knee, and
//   h(t) = level + slope (t - knee) + curvature (t - knee)^2      for t >= knee,
// slope and curvature >= 0 (a lift goes on rising). The knee is searched over a grid (every
// sample time in the window, and the midpoints between them); for each
// knee the other three are a linear least-squares fit with the sign constraints, weighted
// by a Huber loss (iteratively reweighted) so that a few frames off the curve (a codec's
// step, a one-frame bump) do not move it, and optionally asymmetric after the knee (a
// codec's lag: RiseFitOptions::lag_weight). The crossing of level + threshold follows from
// the model; its interval spans the crossings of every knee whose fit is within a
// two-sigma increase of the best (the noise taken from the residuals, inflated by their
// lag-one correlation, as a codec's stepwise updates are correlated).
#pragma once

#include <vector>

namespace liftoff::video::internal {

struct RiseFitOptions {
  /// Rise above the level whose first crossing is wanted (> 0), same unit as the heights.
  double threshold = 1.0;
  /// Huber's constant, in units of the residuals' robust standard deviation.
  double huber_k = 1.5;
  /// Reweighting passes (1: plain least squares).
  int passes = 4;
  /// A codec with temporal prediction holds a slowly moving picture still between key
  /// frames and catches up later, so while the foot rises its decoded height lags by up to
  /// lag_bound, never leads. A sample that may lag (not lag-free) lying below the rising
  /// model by at most lag_bound weighs lag_weight (0..1]; further below, it counts from the
  /// bound's edge. 0: no lag. Before the knee nothing moves and every sample weighs the same.
  double lag_bound = 0.0;
  double lag_weight = 1.0;
  /// Weight of a lag-free sample (a key frame) against a plain one (>= 1).
  double lag_free_weight = 50.0;
};

struct RiseFit {
  bool ok = false;
  /// Best model: knee time (s), level, slope (per s), curvature (per s^2).
  double knee_s = 0.0;
  double level = 0.0;
  double slope = 0.0;
  double curvature = 0.0;
  /// Robust standard deviation of the residuals, and their lag-one correlation (0..1).
  double noise = 0.0;
  double correlation = 0.0;
  /// The model's crossing of level + threshold, s, and the interval of crossings of the
  /// knees that fit about as well [low, high], s.
  double crossing_s = 0.0;
  double crossing_low_s = 0.0;
  double crossing_high_s = 0.0;
  /// Knees that fit about as well, s.
  double knee_low_s = 0.0;
  double knee_high_s = 0.0;
  /// Model's rate of rise at the crossing, per s.
  double rate_at_crossing = 0.0;
  /// The middle of [crossing_low_s, crossing_high_s]: the estimate when samples may lag
  /// (the fit then only bounds the instant), s.
  double crossing_middle_s = 0.0;
};

/// The model's height at t (s).
double RiseModel(const RiseFit& fit, double t_s);

/// Fits the model to (t_s[i], height[i]); times increasing. lag_free[i]: sample i cannot
/// lag (empty: none can lag). Not ok with fewer than 8 samples or when no knee gives a
/// rising fit.
RiseFit FitRise(const std::vector<double>& t_s, const std::vector<double>& height,
                const std::vector<bool>& lag_free, const RiseFitOptions& options);

}  // namespace liftoff::video::internal
