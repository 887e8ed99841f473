#include "liftoff/fit/tension_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <utility>

#include <boost/math/distributions/chi_squared.hpp>
#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"
#include "liftoff/core/random.h"
#include "liftoff/core/robust_stats.h"
#include "liftoff/core/text.h"

namespace liftoff::fit {
namespace {

using nlohmann::json;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

size_t FootIndex(Foot foot) { return static_cast<size_t>(foot); }

double Lerp(double a, double b, double t) { return a + (b - a) * t; }

double StandardDeviation(const std::vector<double>& values) {
  if (values.size() < 2) return 0.0;
  const double mean =
      std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
  double sum = 0.0;
  for (const double value : values) sum += (value - mean) * (value - mean);
  return std::sqrt(sum / static_cast<double>(values.size() - 1));
}

// ---------------------------------------------------------------------------------------
// the fit on the interpolated curves

// the simulated curves the fit searches: grid sigmas and, per target foot, the values
struct Curves {
  std::vector<double> sigma;
  std::vector<std::vector<double>> value_rad;  // [foot][grid point]
};

struct CurveFit {
  double sigma = 0.0;
  double chi_square = 0.0;
};

// chi-square of the curves at point i of a segment, weight 1/se^2 per foot
double ChiSquareAt(const Curves& curves, const std::vector<double>& means,
                   const std::vector<double>& errors, size_t segment, double t) {
  double chi_square = 0.0;
  for (size_t f = 0; f < means.size(); ++f) {
    const double sim = Lerp(curves.value_rad[f][segment], curves.value_rad[f][segment + 1], t);
    const double z = (sim - means[f]) / errors[f];
    chi_square += z * z;
  }
  return chi_square;
}

// each target foot's hardware mean and the standard error that weighs it
void MeansAndErrors(const std::vector<FootTarget>& targets, std::vector<double>& means,
                    std::vector<double>& errors) {
  for (const FootTarget& target : targets) {
    means.push_back(target.summary.mean);
    errors.push_back(target.standard_error_rad);
  }
}

// chi-square is quadratic in t on each segment of the piecewise-linear curves: its
// minimum there is closed-form, clamped to the segment
CurveFit FitCurves(const Curves& curves, const std::vector<double>& means,
                   const std::vector<double>& errors) {
  CurveFit best{curves.sigma.front(), std::numeric_limits<double>::infinity()};
  for (size_t s = 0; s + 1 < curves.sigma.size(); ++s) {
    double slope_sum = 0.0;
    double cross_sum = 0.0;
    for (size_t f = 0; f < means.size(); ++f) {
      const double start = curves.value_rad[f][s] - means[f];
      const double rise = curves.value_rad[f][s + 1] - curves.value_rad[f][s];
      const double weight = 1.0 / (errors[f] * errors[f]);
      slope_sum += weight * rise * rise;
      cross_sum += weight * start * rise;
    }
    const double t = slope_sum > 0.0 ? std::clamp(-cross_sum / slope_sum, 0.0, 1.0) : 0.0;
    const double chi_square = ChiSquareAt(curves, means, errors, s, t);
    if (chi_square < best.chi_square) {
      best = {Lerp(curves.sigma[s], curves.sigma[s + 1], t), chi_square};
    }
  }
  return best;
}

// the value of foot f's curve at sigma (inside the curves' range)
double CurveValue(const Curves& curves, size_t f, double sigma) {
  size_t s = 0;
  while (s + 2 < curves.sigma.size() && sigma > curves.sigma[s + 1]) ++s;
  const double t = (sigma - curves.sigma[s]) / (curves.sigma[s + 1] - curves.sigma[s]);
  return Lerp(curves.value_rad[f][s], curves.value_rad[f][s + 1], t);
}

// the longest run of neighbouring grid points where every target foot has a value
Result<Curves> SearchableCurves(const std::vector<FootTarget>& targets,
                                const std::vector<TensionSample>& grid) {
  auto complete = [&](const TensionSample& sample) {
    return std::all_of(targets.begin(), targets.end(), [&](const FootTarget& target) {
      return sample.liftoff_rad[FootIndex(target.foot)].has_value();
    });
  };
  size_t best_start = 0, best_length = 0;
  for (size_t start = 0; start < grid.size();) {
    size_t end = start;
    while (end < grid.size() && complete(grid[end])) ++end;
    if (end - start > best_length) best_start = start, best_length = end - start;
    start = end + 1;
  }
  if (best_length < 2) {
    return NotFoundError(
        "the simulation has no two neighbouring tension scales at which every foot of the "
        "campaign stood and lifted; nothing to fit");
  }
  Curves curves;
  curves.value_rad.resize(targets.size());
  for (size_t i = best_start; i < best_start + best_length; ++i) {
    curves.sigma.push_back(grid[i].tension.sigma);
    for (size_t f = 0; f < targets.size(); ++f) {
      curves.value_rad[f].push_back(*grid[i].liftoff_rad[FootIndex(targets[f].foot)]);
    }
  }
  return curves;
}

// refits with each foot's trials resampled (weights kept): the fitted sigmas, sorted
std::vector<double> BootstrapSigmas(const std::vector<FootTarget>& targets, const Curves& curves,
                                    const std::vector<double>& errors, const FitOptions& options) {
  SplitMix64 random(options.seed);
  std::vector<double> sigmas;
  std::vector<double> means(targets.size());
  for (int b = 0; b < options.bootstrap_samples; ++b) {
    for (size_t f = 0; f < targets.size(); ++f) {
      const std::vector<double>& trials = targets[f].liftoff_rad;
      double sum = 0.0;
      for (size_t i = 0; i < trials.size(); ++i) {
        sum += trials[static_cast<size_t>(random.Next() % trials.size())];
      }
      means[f] = sum / static_cast<double>(trials.size());
    }
    sigmas.push_back(FitCurves(curves, means, errors).sigma);
  }
  std::sort(sigmas.begin(), sigmas.end());
  return sigmas;
}

// feet whose hardware mean lies outside everything the searched curves reach
void AddReachWarnings(const std::vector<FootTarget>& targets, const Curves& curves,
                      std::vector<std::string>& warnings) {
  for (size_t f = 0; f < targets.size(); ++f) {
    const auto [low, high] =
        std::minmax_element(curves.value_rad[f].begin(), curves.value_rad[f].end());
    const double mean = targets[f].summary.mean;
    if (mean >= *low && mean <= *high) continue;
    warnings.push_back("foot " + std::string(FootName(targets[f].foot)) + ": the hardware mean " +
                       FormatFixed(mean, 3) + " rad lies " + (mean > *high ? "above" : "below") +
                       " every simulated value for sigma " + FormatFixed(curves.sigma.front(), 2) +
                       " .. " + FormatFixed(curves.sigma.back(), 2) + " (" + FormatFixed(*low, 3) +
                       " .. " + FormatFixed(*high, 3) + " rad)");
  }
}

// The chi-square above which a fit with `degrees_of_freedom` (> 0) is poor: its
// (1 - poor_fit_p) quantile.
double PoorFitLimit(int degrees_of_freedom, const FitOptions& options) {
  const boost::math::chi_squared distribution(degrees_of_freedom);
  return boost::math::quantile(distribution, 1.0 - options.poor_fit_p);
}

// chi-square per degree of freedom, and whether it is poor at the options' p
void JudgeGoodness(TensionFit& fit, const FitOptions& options) {
  if (fit.degrees_of_freedom <= 0) {
    fit.chi_square_per_dof = kNaN;
    fit.sigma_stddev_scaled = fit.sigma_stddev;
    fit.warnings.push_back("one foot only: no degree of freedom left to judge the fit");
    return;
  }
  fit.chi_square_per_dof = fit.chi_square / fit.degrees_of_freedom;
  const double limit = PoorFitLimit(fit.degrees_of_freedom, options);
  fit.poor = fit.chi_square > limit;
  fit.sigma_stddev_scaled = fit.sigma_stddev * std::sqrt(std::max(1.0, fit.chi_square_per_dof));
  if (fit.poor) {
    fit.warnings.push_back(
        "poor fit: chi2 " + FormatFixed(fit.chi_square, 1) + " for " +
        Plural(fit.degrees_of_freedom, "degree") + " of freedom (chi2/dof " +
        FormatFixed(fit.chi_square_per_dof, 1) + "; above " + FormatFixed(limit, 1) + ", p < " +
        FormatNumber(options.poor_fit_p) +
        "): no tension of this model matches every foot within the trials' spread; the "
        "bootstrap interval knows only that spread (scaled by sqrt(chi2/dof): +- " +
        FormatFixed(fit.sigma_stddev_scaled, 2) + ")");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// the hardware side

Status TargetOptions::Validate() const {
  if (!(standard_error_floor_rad > 0.0 && standard_error_floor_rad < 1.0)) {
    return InvalidArgumentError("standard_error_floor_rad: expected a number in (0, 1) rad, got " +
                                FormatNumber(standard_error_floor_rad));
  }
  return Status::Ok();
}

namespace {

// The median half-width of `foot`'s finite trials' uncertainty intervals, rad; 0 for none.
double MedianHalfWidth(const std::vector<stats::TrialValue>& values, Foot foot) {
  std::vector<double> half_widths;
  for (const stats::TrialValue& value : values) {
    const double half_width = 0.5 * (value.upper_rad - value.lower_rad);
    if (value.foot == foot && std::isfinite(value.liftoff_rad) && std::isfinite(half_width)) {
      half_widths.push_back(half_width);
    }
  }
  if (half_widths.empty()) return 0.0;
  return stats::Summarize(half_widths).median;
}

}  // namespace

Result<std::vector<FootTarget>> TargetsFromTrials(const std::vector<stats::TrialValue>& values,
                                                  const TargetOptions& options,
                                                  std::vector<std::string>* skipped) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  std::vector<FootTarget> targets;
  for (const Foot foot : kAllFeet) {
    FootTarget target;
    target.foot = foot;
    for (const stats::TrialValue& value : values) {
      if (value.foot == foot && std::isfinite(value.liftoff_rad)) {
        target.liftoff_rad.push_back(value.liftoff_rad);
      }
    }
    if (target.liftoff_rad.size() < 2) {
      if (skipped != nullptr && !target.liftoff_rad.empty()) {
        skipped->push_back("foot " + std::string(FootName(foot)) +
                           ": one trial only, no spread to weigh it by; left out of the fit");
      }
      continue;
    }
    target.summary = stats::Summarize(target.liftoff_rad);
    target.measurement_rad = MedianHalfWidth(values, foot);
    target.standard_error_rad =
        std::max(target.summary.stddev / std::sqrt(static_cast<double>(target.summary.n)),
                 options.standard_error_floor_rad);
    targets.push_back(std::move(target));
  }
  if (targets.empty()) {
    return InvalidArgumentError(
        "no foot has two or more trials with a value; nothing to calibrate");
  }
  return targets;
}

// ---------------------------------------------------------------------------------------
// the simulated side

TensionPoint TensionAtSigma(const std::vector<TensionPoint>& points, double sigma,
                            const std::string& name) {
  TensionPoint result = points.front();
  if (points.size() >= 2) {
    // the segment holding sigma, or the end segment it extends
    size_t s = 0;
    while (s + 2 < points.size() && sigma > points[s + 1].sigma) ++s;
    const TensionPoint& a = points[s];
    const TensionPoint& b = points[s + 1];
    const double t = (sigma - a.sigma) / (b.sigma - a.sigma);
    result.silicone_n_per_m = Lerp(a.silicone_n_per_m, b.silicone_n_per_m, t);
    result.buna_n_n_per_m = Lerp(a.buna_n_n_per_m, b.buna_n_n_per_m, t);
    result.spring_n_per_m = Lerp(a.spring_n_per_m, b.spring_n_per_m, t);
  }
  result.name = name;
  result.sigma = sigma;
  return result;
}

Result<std::vector<TensionSample>> SimulateTensions(const sim::ModelDescription& model,
                                                    const sim::SweepOptions& sweep,
                                                    const std::vector<TensionPoint>& points) {
  sim::SweepOptions options = sweep;
  options.tension_points = points;
  LIFTOFF_ASSIGN_OR_RETURN(const sim::SweepResult result, sim::RunSweep(model, options, {}));
  std::vector<TensionSample> samples(points.size());
  for (size_t i = 0; i < points.size(); ++i) samples[i].tension = points[i];
  for (const sim::SweepRun& run : result.runs) {
    samples[static_cast<size_t>(run.tension_index)].liftoff_rad[FootIndex(run.foot)] =
        run.LiftoffRad();
  }
  return samples;
}

json TensionSamplesToJson(const std::vector<TensionSample>& samples) {
  json array = json::array();
  for (const TensionSample& sample : samples) {
    json entry = {{"name", sample.tension.name},
                  {"sigma", sample.tension.sigma},
                  {"silicone_n_per_m", sample.tension.silicone_n_per_m},
                  {"buna_n_n_per_m", sample.tension.buna_n_n_per_m},
                  {"spring_n_per_m", sample.tension.spring_n_per_m}};
    for (const Foot foot : kAllFeet) {
      const std::optional<double>& value = sample.liftoff_rad[FootIndex(foot)];
      entry[std::string(FootName(foot))] = value ? json(*value) : json(nullptr);
    }
    array.push_back(std::move(entry));
  }
  return {{"samples", std::move(array)}};
}

Result<std::vector<TensionSample>> TensionSamplesFromJson(const json& document,
                                                          const std::string& source) {
  JsonReader reader(document, source);
  std::vector<TensionSample> samples;
  for (JsonReader& entry : reader.ObjectArray("samples")) {
    TensionSample& sample = samples.emplace_back();
    sample.tension.name = entry.String("name");
    sample.tension.sigma = entry.Number("sigma");
    sample.tension.silicone_n_per_m = entry.Number("silicone_n_per_m");
    sample.tension.buna_n_n_per_m = entry.Number("buna_n_n_per_m");
    sample.tension.spring_n_per_m = entry.Number("spring_n_per_m");
    for (const Foot foot : kAllFeet) {
      sample.liftoff_rad[FootIndex(foot)] =
          entry.OptionalNumber(FootName(foot), {.min = 0.0, .max = 10.0});
    }
  }
  LIFTOFF_RETURN_IF_ERROR(reader.Finish());
  return samples;
}

// ---------------------------------------------------------------------------------------
// ranking

std::string Ranking::Brief() const {
  std::string text;
  for (const PointAgreement& point : overall) {
    text += (text.empty() ? "" : ", ") + point.tension.name + " (chi2 " +
            (point.complete ? FormatFixed(point.chi_square, 1) : std::string("incomplete")) + ")";
  }
  return text;
}

Ranking RankTensionPoints(const std::vector<FootTarget>& targets,
                          const std::vector<TensionSample>& samples) {
  Ranking ranking;
  for (const TensionSample& sample : samples) {
    PointAgreement& point = ranking.overall.emplace_back();
    point.tension = sample.tension;
    point.complete = true;
    for (const FootTarget& target : targets) {
      FootAgreement& foot = point.feet.emplace_back();
      foot.foot = target.foot;
      foot.sim_rad = sample.liftoff_rad[FootIndex(target.foot)];
      foot.z =
          foot.sim_rad ? (*foot.sim_rad - target.summary.mean) / target.standard_error_rad : kNaN;
      if (foot.sim_rad) point.chi_square += foot.z * foot.z;
      point.complete = point.complete && foot.sim_rad.has_value();
    }
  }
  auto missing = [](const PointAgreement& point) {
    return std::count_if(point.feet.begin(), point.feet.end(),
                         [](const FootAgreement& foot) { return !foot.sim_rad; });
  };
  std::stable_sort(ranking.overall.begin(), ranking.overall.end(),
                   [&](const PointAgreement& a, const PointAgreement& b) {
                     const auto missing_a = missing(a), missing_b = missing(b);
                     if (missing_a != missing_b) return missing_a < missing_b;
                     return a.chi_square < b.chi_square;
                   });
  for (size_t f = 0; f < targets.size(); ++f) {
    std::vector<std::pair<double, std::string>> by_distance;
    for (const PointAgreement& point : ranking.overall) {
      if (point.feet[f].sim_rad)
        by_distance.emplace_back(std::abs(point.feet[f].z), point.tension.name);
    }
    std::stable_sort(by_distance.begin(), by_distance.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    auto& names = ranking.per_foot.emplace_back(targets[f].foot, std::vector<std::string>()).second;
    for (auto& [distance, name] : by_distance) names.push_back(std::move(name));
  }
  return ranking;
}

// ---------------------------------------------------------------------------------------
// the fit

Status FitOptions::Validate() const {
  if (!(std::isfinite(sigma_min) && std::isfinite(sigma_max) && sigma_min < sigma_max &&
        sigma_min >= -10.0 && sigma_max <= 10.0)) {
    return InvalidArgumentError("sigma_min, sigma_max: expected -10 <= min < max <= 10, got " +
                                FormatNumber(sigma_min) + ", " + FormatNumber(sigma_max));
  }
  if (!(sigma_step > 0.0 && (sigma_max - sigma_min) / sigma_step <= 1000.0)) {
    return InvalidArgumentError(
        "sigma_step: expected a number > 0 giving at most 1000 steps, got " +
        FormatNumber(sigma_step));
  }
  if (bootstrap_samples < 10 || bootstrap_samples > 1000000) {
    return InvalidArgumentError("bootstrap_samples: expected an integer in [10, 1000000], got " +
                                std::to_string(bootstrap_samples));
  }
  if (!(poor_fit_p > 0.0 && poor_fit_p < 1.0)) {
    return InvalidArgumentError("poor_fit_p: expected a number in (0, 1), got " +
                                FormatNumber(poor_fit_p));
  }
  return Status::Ok();
}

std::vector<TensionPoint> GridTensionPoints(const std::vector<TensionPoint>& points,
                                            const FitOptions& options) {
  std::vector<TensionPoint> grid;
  const int steps = static_cast<int>(
      std::floor((options.sigma_max - options.sigma_min) / options.sigma_step + 1e-9));
  for (int i = 0; i <= steps; ++i) {
    const double sigma = options.sigma_min + i * options.sigma_step;
    const std::string sign = sigma < 0.0 ? "-" : "+";
    grid.push_back(
        TensionAtSigma(points, sigma, "sigma=" + sign + FormatFixed(std::abs(sigma), 2)));
  }
  return grid;
}

std::string TensionFit::Brief() const {
  return "sigma " + FormatFixed(sigma, 2) + " +- " + FormatFixed(sigma_stddev, 2) + " (95 % [" +
         FormatFixed(sigma_low95, 2) + ", " + FormatFixed(sigma_high95, 2) + "]), +- " +
         FormatFixed(sigma_systematic, 2) + " systematic, chi2/dof " +
         (std::isfinite(chi_square_per_dof) ? FormatFixed(chi_square_per_dof, 1) : "n/a") +
         (poor ? " (poor)" : "");
}

namespace {

// The larger move of the fitted sigma when every foot's mean shifts by +measurement_rad,
// or every one by -measurement_rad (a bias the trials share).
double SystematicSigma(const Curves& curves, const std::vector<double>& means,
                       const std::vector<double>& errors, const std::vector<FootTarget>& targets,
                       double sigma) {
  double largest = 0.0;
  for (const double sign : {1.0, -1.0}) {
    std::vector<double> shifted = means;
    for (size_t f = 0; f < targets.size(); ++f) shifted[f] += sign * targets[f].measurement_rad;
    largest = std::max(largest, std::abs(FitCurves(curves, shifted, errors).sigma - sigma));
  }
  return largest;
}

}  // namespace

Result<TensionFit> FitTension(const std::vector<FootTarget>& targets,
                              const std::vector<TensionSample>& grid,
                              const std::vector<TensionPoint>& points, const FitOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (targets.empty()) return InvalidArgumentError("no hardware targets to fit");
  LIFTOFF_ASSIGN_OR_RETURN(const Curves curves, SearchableCurves(targets, grid));
  std::vector<double> means, errors;
  MeansAndErrors(targets, means, errors);

  // the fit, and its spread over resampled trials
  TensionFit fit;
  const CurveFit best = FitCurves(curves, means, errors);
  fit.sigma = best.sigma;
  fit.chi_square = best.chi_square;
  fit.tension = TensionAtSigma(points, best.sigma, "fitted");
  std::vector<double> sigmas = BootstrapSigmas(targets, curves, errors, options);
  fit.sigma_stddev = StandardDeviation(sigmas);
  fit.sigma_low95 = FiniteQuantile(sigmas, 0.025);
  fit.sigma_high95 = FiniteQuantile(sigmas, 0.975);
  fit.sigma_systematic = SystematicSigma(curves, means, errors, targets, best.sigma);
  fit.sigma_total = std::hypot(fit.sigma_stddev, fit.sigma_systematic);
  fit.searched_sigma_min = curves.sigma.front();
  fit.searched_sigma_max = curves.sigma.back();
  for (size_t f = 0; f < targets.size(); ++f) {
    const double sim = CurveValue(curves, f, fit.sigma);
    fit.feet.push_back({targets[f].foot, sim, (sim - means[f]) / errors[f]});
  }

  // what makes it less than it seems
  fit.degrees_of_freedom = static_cast<int>(targets.size()) - 1;
  if (fit.sigma <= fit.searched_sigma_min || fit.sigma >= fit.searched_sigma_max) {
    const bool grid_end = fit.sigma <= options.sigma_min || fit.sigma >= options.sigma_max;
    fit.warnings.push_back("the fit sits at the edge of the searched range (sigma " +
                           FormatFixed(fit.searched_sigma_min, 2) + " .. " +
                           FormatFixed(fit.searched_sigma_max, 2) + "; " +
                           (grid_end ? "the grid's end" : "beyond it the robot did not stand") +
                           "): the best tension may lie outside it");
  }
  AddReachWarnings(targets, curves, fit.warnings);
  JudgeGoodness(fit, options);
  return fit;
}

// ---------------------------------------------------------------------------------------
// the stiffness ratio

std::vector<TensionPoint> ScaledBunaN(const std::vector<TensionPoint>& points, double ratio) {
  std::vector<TensionPoint> scaled = points;
  for (TensionPoint& point : scaled) point.buna_n_n_per_m *= ratio;
  return scaled;
}

Status RatioFitOptions::Validate() const {
  const bool positive_increasing =
      std::all_of(ratios.begin(), ratios.end(),
                  [](double r) { return std::isfinite(r) && r > 0.0 && r <= 100.0; }) &&
      std::adjacent_find(ratios.begin(), ratios.end(), std::greater_equal<>()) == ratios.end();
  const bool holds_one = std::find(ratios.begin(), ratios.end(), 1.0) != ratios.end();
  const std::string expected =
      "ratios: expected 3 .. 100 increasing multipliers in (0, 100] "
      "holding 1, got ";
  if (ratios.size() < 3 || ratios.size() > 100) {
    return InvalidArgumentError(expected + std::to_string(ratios.size()) + " values");
  }
  if (!positive_increasing) {
    return InvalidArgumentError(expected + "values out of range or not increasing");
  }
  if (!holds_one) return InvalidArgumentError(expected + "none equal to 1");
  return Status::Ok();
}

namespace {

// How far the profile's chi-square stays within `level` going from row `best` towards
// `step` (-1: lower ratios, +1: higher): the first fitted row beyond it (`reached`), or the
// last fitted row when it never rises through it (`reached` false). The crossing lies
// between that row and the one before it; chi-square is far from linear or quadratic over
// a coarse grid of ratios (a sigma pinned at the grid's end bends it), so the row itself is
// the bound: the interval is as coarse as the ratios tried.
double ProfileBound(const std::vector<RatioProfileRow>& rows, size_t best, int step, double level,
                    bool& reached) {
  size_t inside = best;
  reached = false;
  while (step < 0 ? inside > 0 : inside + 1 < rows.size()) {
    const size_t next = step < 0 ? inside - 1 : inside + 1;
    if (!rows[next].fitted) break;
    if (rows[next].chi_square > level) {
      reached = true;
      return rows[next].ratio;
    }
    inside = next;
  }
  return rows[inside].ratio;
}

// What makes the ratio's fit less than it seems: a least chi-square at the end of the ratios
// fitted, a flat profile, no degree of freedom, a poor chi-square.
void AddRatioWarnings(const std::vector<FootTarget>& targets, const FitOptions& fit_options,
                      size_t best, RatioFit& fit) {
  const auto fitted = [&](size_t i) { return fit.profile[i].fitted; };
  size_t first = 0, last = fit.profile.size() - 1;
  while (!fitted(first)) ++first;
  while (!fitted(last)) --last;
  const auto fitted_count = std::count_if(fit.profile.begin(), fit.profile.end(),
                                          [](const RatioProfileRow& row) { return row.fitted; });
  const bool flat = fit.ratio_low == fit.profile[first].ratio &&
                    fit.ratio_high == fit.profile[last].ratio && !fit.determined;
  std::string edges;
  for (const RatioProfileRow& row : fit.profile) {
    if (row.fitted && row.at_edge)
      edges += (edges.empty() ? "x" : ", x") + FormatFixed(row.ratio, 2);
  }
  if (!edges.empty()) {
    fit.warnings.push_back("at " + edges +
                           " the tension scale sits at an end of its searched range (the grid's "
                           "end, or beyond it the robot did not stand): there chi-square only "
                           "bounds the profile, which may lie lower");
  }
  if (fitted_count < 2) {
    fit.warnings.push_back("the tension scale could be fitted at one ratio only (x" +
                           FormatFixed(fit.ratio, 2) +
                           "): at the others some foot did not stand or lift; nothing to profile");
  } else if ((best == first || best == last) && !flat) {
    fit.warnings.push_back("the least chi-square lies at the end of the ratios fitted (x" +
                           FormatFixed(fit.ratio, 2) +
                           "; the end of those tried, or of those the robot stood at): the "
                           "best ratio may lie beyond it");
  } else if (!fit.determined) {
    fit.warnings.push_back(
        "the ratio is not determined by these trials: chi-square stays within " +
        FormatFixed(fit.delta_chi_square, 1) + " of its least from x" +
        FormatFixed(fit.ratio_low, 2) + " to x" + FormatFixed(fit.ratio_high, 2) +
        (flat ? ", the ratios fitted" : ", reaching the last ratio fitted on that side") +
        ": a change of the ratio moves the feet as a change of the tension "
        "scale does");
  }
  if (fit.degrees_of_freedom <= 0) {
    fit.warnings.push_back(std::to_string(targets.size()) +
                           (targets.size() == 1 ? " foot" : " feet") +
                           " against two parameters: no degree of freedom left to judge the "
                           "fit");
    return;
  }
  const double limit = PoorFitLimit(fit.degrees_of_freedom, fit_options);
  fit.poor = fit.chi_square > limit;
  if (fit.poor) {
    fit.warnings.push_back("poor fit: chi2 " + FormatFixed(fit.chi_square, 1) + " for " +
                           Plural(fit.degrees_of_freedom, "degree") + " of freedom (above " +
                           FormatFixed(limit, 1) + ", p < " + FormatNumber(fit_options.poor_fit_p) +
                           "): no tension scale and ratio of this model match every foot within "
                           "the trials' spread");
  }
}

}  // namespace

std::string RatioFit::Brief() const {
  std::string text = "ratio x" + FormatFixed(ratio, 2) + " (68 % [" + FormatFixed(ratio_low, 2) +
                     ", " + FormatFixed(ratio_high, 2) + "]), sigma " + FormatFixed(sigma, 2) +
                     ", chi2 " + FormatFixed(chi_square, 1) + ", " +
                     std::to_string(degrees_of_freedom) + " dof";
  if (!determined) text += "; not determined by these trials";
  if (poor) text += " (poor)";
  return text;
}

Result<RatioFit> FitStiffnessRatio(const std::vector<FootTarget>& targets,
                                   const std::vector<std::vector<TensionSample>>& grids,
                                   const FitOptions& fit_options, const RatioFitOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  LIFTOFF_RETURN_IF_ERROR(fit_options.Validate());
  if (targets.empty()) return InvalidArgumentError("no hardware targets to fit");
  if (grids.size() != options.ratios.size()) {
    return InvalidArgumentError("grids: expected one per ratio (" +
                                std::to_string(options.ratios.size()) + "), got " +
                                std::to_string(grids.size()));
  }
  // the tension scale fitted at each ratio (as FitTension fits it; its bootstrap is not
  // needed for the profile)
  std::vector<double> means, errors;
  MeansAndErrors(targets, means, errors);
  RatioFit fit;
  std::optional<size_t> best;
  for (size_t i = 0; i < grids.size(); ++i) {
    RatioProfileRow& row = fit.profile.emplace_back();
    row.ratio = options.ratios[i];
    const Result<Curves> curves = SearchableCurves(targets, grids[i]);
    if (!curves.ok()) continue;  // no two neighbouring complete points at this ratio
    const CurveFit at_ratio = FitCurves(*curves, means, errors);
    row.fitted = true;
    row.sigma = at_ratio.sigma;
    row.chi_square = at_ratio.chi_square;
    row.at_edge = row.sigma <= curves->sigma.front() || row.sigma >= curves->sigma.back();
    if (!best || row.chi_square < fit.profile[*best].chi_square) best = i;
  }
  if (!best) return NotFoundError("the tension scale could be fitted at no ratio");
  fit.ratio = fit.profile[*best].ratio;
  fit.sigma = fit.profile[*best].sigma;
  fit.chi_square = fit.profile[*best].chi_square;

  // the profile interval, and whether it says anything
  fit.degrees_of_freedom = static_cast<int>(targets.size()) - 2;
  if (fit.degrees_of_freedom > 0) {
    fit.delta_chi_square =
        std::max(1.0, fit.chi_square / static_cast<double>(fit.degrees_of_freedom));
  }
  const double level = fit.chi_square + fit.delta_chi_square;
  bool low_reached = false, high_reached = false;
  fit.ratio_low = ProfileBound(fit.profile, *best, -1, level, low_reached);
  fit.ratio_high = ProfileBound(fit.profile, *best, +1, level, high_reached);
  fit.determined = low_reached && high_reached;
  AddRatioWarnings(targets, fit_options, *best, fit);
  return fit;
}

// ---------------------------------------------------------------------------------------
// Monte Carlo

Status MonteCarloOptions::Validate() const {
  if (samples < 0 || samples > 1000000) {
    return InvalidArgumentError("samples: expected an integer in [0, 1000000], got " +
                                std::to_string(samples));
  }
  if (!(stddev_scale >= 0.0 && stddev_scale <= 100.0)) {
    return InvalidArgumentError("stddev_scale: expected a number in [0, 100], got " +
                                FormatNumber(stddev_scale));
  }
  return Status::Ok();
}

Result<std::vector<TensionPoint>> MonteCarloDraws(const Calibration& calibration,
                                                  const MonteCarloOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  const MaterialConstant* silicone = calibration.FindMaterial("silicone");
  const MaterialConstant* buna_n = calibration.FindMaterial("buna_n");
  const MaterialConstant* spring = calibration.FindMaterial("spring");
  if (silicone == nullptr || buna_n == nullptr || spring == nullptr) {
    return InvalidArgumentError(calibration.Brief() +
                                ": /materials: the Monte Carlo needs silicone, buna_n and spring");
  }
  // each draw its own stream, seeded by the seed and its index: draw k is the same
  // whichever draws are made with it (a shard of the Monte Carlo draws only its own)
  SplitMix64 random(0);
  auto draw = [&](const MaterialConstant& material) {
    for (;;) {
      const double value = material.stiffness_n_per_m + options.stddev_scale *
                                                            material.stiffness_stddev_n_per_m *
                                                            random.Gaussian();
      if (value >= 0.01 * material.stiffness_n_per_m) return value;
    }
  };
  std::vector<TensionPoint> draws;
  for (int i = 1; i <= options.samples; ++i) {
    constexpr uint64_t kIndexMix = 0xD1B54A32D192ED03;  // odd: index -> seed is one to one
    SplitMix64 seeder(options.seed ^ (kIndexMix * static_cast<uint64_t>(i)));
    random = SplitMix64(seeder.Next());
    TensionPoint& point = draws.emplace_back();
    char name[16];
    std::snprintf(name, sizeof name, "mc-%04d", i);
    point.name = name;
    point.sigma = i;
    point.silicone_n_per_m = draw(*silicone);
    point.buna_n_n_per_m = draw(*buna_n);
    point.spring_n_per_m = draw(*spring);
  }
  return draws;
}

std::vector<FootDistribution> Distributions(const std::vector<TensionSample>& samples) {
  std::vector<FootDistribution> distributions;
  for (const Foot foot : kAllFeet) {
    FootDistribution distribution;
    distribution.foot = foot;
    for (const TensionSample& sample : samples) {
      const std::optional<double>& value = sample.liftoff_rad[FootIndex(foot)];
      if (value) {
        distribution.liftoff_rad.push_back(*value);
      } else {
        ++distribution.missing;
      }
    }
    if (distribution.liftoff_rad.empty()) continue;
    distribution.summary = stats::Summarize(distribution.liftoff_rad);
    distributions.push_back(std::move(distribution));
  }
  return distributions;
}

}  // namespace liftoff::fit
