// Calibration of the simulation against a hardware campaign: which tension point agrees
// best with the trials, the continuous tension scale that fits them best (with an
// uncertainty from the trials' spread), and a Monte Carlo over the cable materials'
// spring constants (paper Table I).
//
// The tension scale is `sigma`, the coordinate of the calibration's tension points (paper
// Table III: -2 low .. +2 high): the silicone and Buna-N stiffnesses at any sigma are the
// piecewise-linear line through the calibration's points, extended linearly past its ends
// (TensionAtSigma).
//
// The agreement metric, per foot f with n_f >= 2 hardware trials of mean m_f and sample
// standard deviation s_f: z_f = (sim_f - m_f) / se_f, se_f = max(s_f / sqrt(n_f),
// standard_error_floor_rad); over the feet, chi-square = sum of z_f^2. A foot whose
// simulation has no value there (the robot did not stand, the foot did not lift) makes
// the point incomplete: ranked after every complete point.
//
//   LIFTOFF_ASSIGN_OR_RETURN(auto targets, fit::TargetsFromTrials(values, {}));
//   LIFTOFF_ASSIGN_OR_RETURN(auto grid, fit::SimulateTensions(model, sweep,
//                                           fit::GridTensionPoints(calibration, options)));
//   LIFTOFF_ASSIGN_OR_RETURN(fit::TensionFit fitted, fit::FitTension(targets, grid, options));
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/calibration.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/sim/model.h"
#include "liftoff/sim/sweep.h"
#include "liftoff/stats/statistics.h"
#include "liftoff/stats/table.h"

namespace liftoff::fit {

// ---------------------------------------------------------------------------------------
// the hardware side

/// One foot's hardware trials, as the fit sees them.
struct FootTarget {
  Foot foot = Foot::kA;
  /// The trials' |liftoff rotations|, rad (finite values only), in input order.
  std::vector<double> liftoff_rad;
  /// Their summary (mean, sd, range), rad.
  stats::Summary summary;
  /// Standard error of the mean used as the foot's weight, rad (> 0).
  double standard_error_rad = 0.0;
  /// The trials' own measurement uncertainty: the median half-width of their uncertainty
  /// intervals, rad (0 when none has one). Averaging trials does not shrink a bias they
  /// share (one detector, one lookup rule), so the fit takes this as a possible common
  /// shift of every trial (TensionFit::sigma_systematic).
  double measurement_rad = 0.0;
};

struct TargetOptions {
  /// Smallest standard error a foot is given, rad (> 0): the lookup's and the
  /// simulation's resolution, so identical trials do not weigh infinitely.
  double standard_error_floor_rad = 0.001;

  Status Validate() const;
};

/// Per foot (A..D order) with at least two finite trial values; a foot with fewer is left
/// out and named in `skipped` (may be null). kInvalidArgument when no foot has two.
Result<std::vector<FootTarget>> TargetsFromTrials(const std::vector<stats::TrialValue>& values,
                                                  const TargetOptions& options,
                                                  std::vector<std::string>* skipped = nullptr);

// ---------------------------------------------------------------------------------------
// the simulated side

/// The simulation at one tension: each foot's |liftoff rotation| when its test stood and
/// the foot lifted.
struct TensionSample {
  TensionPoint tension;
  /// Indexed by Foot; nullopt: not simulated, did not stand, or no liftoff.
  std::array<std::optional<double>, 4> liftoff_rad;
};

/// The stiffnesses at tension scale `sigma` on the calibration's tension-point line
/// (piecewise linear in sigma, extended linearly past the end points; a single point: its
/// stiffnesses). The spring is interpolated the same way. Named `name`.
TensionPoint TensionAtSigma(const std::vector<TensionPoint>& points, double sigma,
                            const std::string& name);

/// Runs the sweep's feet at `points` (names unique) with liftoff's engine (sim::RunSweep,
/// options from `sweep`: experiment, feet, threads). Errors as RunSweep's.
Result<std::vector<TensionSample>> SimulateTensions(const sim::ModelDescription& model,
                                                    const sim::SweepOptions& sweep,
                                                    const std::vector<TensionPoint>& points);

/// The samples as JSON ({"samples": [...]}, for caches) and back; `source` names the data
/// in errors.
nlohmann::json TensionSamplesToJson(const std::vector<TensionSample>& samples);
Result<std::vector<TensionSample>> TensionSamplesFromJson(const nlohmann::json& document,
                                                          const std::string& source);

// ---------------------------------------------------------------------------------------
// ranking the tension points

/// One foot at one tension.
struct FootAgreement {
  Foot foot = Foot::kA;
  /// The simulated value, rad (nullopt: none there).
  std::optional<double> sim_rad;
  /// (sim - hardware mean) / standard error; NaN without a simulated value.
  double z = 0.0;
};

/// One tension point against the hardware.
struct PointAgreement {
  TensionPoint tension;
  /// One per target foot, in the targets' order.
  std::vector<FootAgreement> feet;
  /// Sum of z^2 over the feet with a value.
  double chi_square = 0.0;
  /// Whether every target foot has a simulated value here.
  bool complete = false;
};

struct Ranking {
  /// Every point, best first: complete points by chi-square, then incomplete ones by
  /// their number of missing feet and chi-square.
  std::vector<PointAgreement> overall;
  /// Per target foot (targets' order): the points' names with a value for that foot,
  /// best (smallest |z|) first.
  std::vector<std::pair<Foot, std::vector<std::string>>> per_foot;

  /// "high (chi2 812.4), med-high (chi2 1032.0), ..."
  std::string Brief() const;
};

/// Ranks `samples` (names unique) by agreement with `targets`.
Ranking RankTensionPoints(const std::vector<FootTarget>& targets,
                          const std::vector<TensionSample>& samples);

// ---------------------------------------------------------------------------------------
// fitting the tension scale

struct FitOptions {
  /// The simulated grid of tension scales: from sigma_min to sigma_max (inclusive) every
  /// sigma_step. Default: the paper's points' -2 .. +2 and two SDs beyond the high one,
  /// so a fit that wants more tension says so rather than stopping at the paper's end.
  double sigma_min = -2.0;
  double sigma_max = 4.0;
  double sigma_step = 0.25;
  /// Bootstrap resamples of the trials (>= 10) and their seed.
  int bootstrap_samples = 1000;
  uint64_t seed = 2018;
  /// Goodness-of-fit threshold: the fit is called poor when chi-square exceeds its
  /// (1 - poor_fit_p) quantile for the degrees of freedom (0 < p < 1).
  double poor_fit_p = 0.01;

  /// kInvalidArgument naming the field.
  Status Validate() const;
};

/// The grid's tension points ("sigma=-2.00" .. ), TensionAtSigma on `points`.
std::vector<TensionPoint> GridTensionPoints(const std::vector<TensionPoint>& points,
                                            const FitOptions& options);

struct TensionFit {
  /// Best tension scale on the simulated curves (linear between grid points), and its
  /// stiffnesses (named "fitted").
  double sigma = 0.0;
  TensionPoint tension;
  /// Bootstrap over each foot's trials (resampled with replacement, weights kept):
  /// standard deviation of the refitted sigma and its 2.5 % and 97.5 % quantiles.
  double sigma_stddev = 0.0;
  double sigma_low95 = 0.0;
  double sigma_high95 = 0.0;
  /// chi-square at the fit, degrees of freedom (feet - 1), chi-square / dof (NaN when
  /// dof = 0), and whether that is poor (FitOptions::poor_fit_p).
  double chi_square = 0.0;
  int degrees_of_freedom = 0;
  double chi_square_per_dof = 0.0;
  bool poor = false;
  /// sigma_stddev scaled by sqrt(chi-square / dof) when that is above 1 (the spread the
  /// misfit implies; the bootstrap alone only knows the trials' spread).
  double sigma_stddev_scaled = 0.0;
  /// What a bias shared by every trial moves the fit by: every foot's trials shifted by
  /// +-FootTarget::measurement_rad together and refitted, the larger move of sigma (0
  /// when the trials state no uncertainty). The bootstrap cannot see such a bias.
  double sigma_systematic = 0.0;
  /// sqrt(sigma_stddev^2 + sigma_systematic^2): the uncertainty to judge the fit by.
  double sigma_total = 0.0;
  /// Each target foot at the fit (interpolated).
  std::vector<FootAgreement> feet;
  /// The contiguous range of grid sigmas where every target foot has a value, which the
  /// fit searched.
  double searched_sigma_min = 0.0;
  double searched_sigma_max = 0.0;
  /// Things that make the fit less than it seems: at the edge of the searched range, a
  /// foot whose hardware mean no simulated tension reaches, a poor chi-square.
  std::vector<std::string> warnings;

  /// "sigma 2.31 +- 0.12 (95 % [2.10, 2.55]), +- 0.05 systematic, chi2/dof 311.2 (poor)"
  std::string Brief() const;
};

/// Fits the tension scale to `targets` on `grid` (samples at increasing sigma, as
/// GridTensionPoints gives). kInvalidArgument for bad options; kNotFound when no two
/// neighbouring grid points have a value for every target foot.
Result<TensionFit> FitTension(const std::vector<FootTarget>& targets,
                              const std::vector<TensionSample>& grid,
                              const std::vector<TensionPoint>& points, const FitOptions& options);

// ---------------------------------------------------------------------------------------
// the ratio of the two lattice stiffnesses (a second parameter)

/// The calibration's tension points with every Buna-N stiffness times `ratio` (> 0): the
/// Buna-N / silicone ratio scaled by `ratio`, the silicone and the spring as they were.
std::vector<TensionPoint> ScaledBunaN(const std::vector<TensionPoint>& points, double ratio);

struct RatioFitOptions {
  /// Multipliers of the Buna-N / silicone ratio tried (each a full tension-scale grid
  /// of runs): increasing, > 0, at least three, holding 1 (the calibration's own ratio).
  std::vector<double> ratios = {0.5, 0.71, 1.0, 1.41, 2.0};

  /// kInvalidArgument naming the field.
  Status Validate() const;
};

/// The tension scale fitted at one ratio.
struct RatioProfileRow {
  double ratio = 1.0;
  /// Whether the tension scale could be fitted there (every foot's curve searchable).
  bool fitted = false;
  double sigma = 0.0;
  double chi_square = 0.0;
  /// The fitted sigma at an end of the range searched at this ratio (its chi-square then
  /// only bounds the ratio's: the best tension may lie beyond).
  bool at_edge = false;
};

struct RatioFit {
  /// The grid's ratio with the least chi-square, and the tension scale fitted there.
  double ratio = 1.0;
  double sigma = 0.0;
  double chi_square = 0.0;
  /// feet - 2 (the scale and the ratio).
  int degrees_of_freedom = 0;
  /// Every ratio tried, in order.
  std::vector<RatioProfileRow> profile;
  /// The ratios whose chi-square lies within `delta_chi_square` of the least, a 68 %
  /// profile interval (delta_chi_square = 1, times chi-square / dof when that is above 1:
  /// the misfit's spread), bounded by the first ratios tried outside it on either side (as
  /// coarse as the ratios tried), or, where the profile does not leave it on that side, by
  /// the last ratio fitted before the end of the ratios or one that could not be fitted.
  double delta_chi_square = 1.0;
  double ratio_low = 1.0;
  double ratio_high = 1.0;
  /// Whether the trials pin the ratio: the interval ends inside the grid on both sides.
  bool determined = false;
  /// chi-square above its (1 - FitOptions::poor_fit_p) quantile for the degrees of freedom.
  bool poor = false;
  /// Why the ratio is not determined, or what else makes the fit less than it seems.
  std::vector<std::string> warnings;

  /// "ratio x1.41 (68 % [1.00, 2.00]), sigma 0.85, chi2 2.3, 2 dof", with "; not
  /// determined by these trials" and " (poor)" where they apply.
  std::string Brief() const;
};

/// Fits the tension scale at each of options.ratios as FitTension does (`grids[i]`: the
/// runs of GridTensionPoints(ScaledBunaN(points, ratios[i]), fit_options)) and profiles
/// chi-square over the ratio. kInvalidArgument for bad options, no targets or a grid count
/// that does not match; kNotFound when no ratio could be fitted.
Result<RatioFit> FitStiffnessRatio(const std::vector<FootTarget>& targets,
                                   const std::vector<std::vector<TensionSample>>& grids,
                                   const FitOptions& fit_options, const RatioFitOptions& options);

// ---------------------------------------------------------------------------------------
// Monte Carlo over the spring constants

struct MonteCarloOptions {
  /// Draws (>= 0; 0: no Monte Carlo). Each draw runs every foot.
  int samples = 16;
  uint64_t seed = 2018;
  /// Multiplies every material's standard deviation (>= 0; 1: paper Table I).
  double stddev_scale = 1.0;

  Status Validate() const;
};

/// The draws: each material's constant from a normal distribution with its Table I mean
/// and standard deviation (times stddev_scale), drawn independently per draw and material
/// and applied to every cable of that material (lattice-wide, not per cable); values
/// below 1 % of the mean are drawn again. Named "mc-0001" ..; sigma is the draw's index.
/// Draw i has its own random stream seeded by (seed, i): the first k draws of n are the
/// draws of k, and any subset can be drawn alone (the report's shards).
/// kInvalidArgument when the calibration lacks silicone, buna_n or spring.
Result<std::vector<TensionPoint>> MonteCarloDraws(const Calibration& calibration,
                                                  const MonteCarloOptions& options);

/// One foot's simulated liftoff distribution.
struct FootDistribution {
  Foot foot = Foot::kA;
  /// Draws where the foot lifted, rad, in draw order.
  std::vector<double> liftoff_rad;
  /// Draws without a value (the robot did not stand, or the foot did not lift).
  int missing = 0;
  stats::Summary summary;
};

/// Per foot of the samples (A..D, feet without any value left out).
std::vector<FootDistribution> Distributions(const std::vector<TensionSample>& samples);

}  // namespace liftoff::fit
