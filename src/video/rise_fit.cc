#include "rise_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "liftoff/core/robust_stats.h"

namespace liftoff::video::internal {
namespace {

// Least noise assumed, a fraction of the threshold (a frozen, codec-held curve has none).
constexpr double kNoiseFloor = 0.05;
// Least rise over the window that counts as rising, a fraction of the threshold.
constexpr double kLeastRise = 1e-6;

struct Coefficients {
  double level = 0, slope = 0, curvature = 0;
};

double HuberWeight(double residual, double scale) {
  const double a = std::abs(residual);
  return a <= scale ? 1.0 : scale / a;
}

double HuberLoss(double residual, double scale) {
  const double a = std::abs(residual);
  return a <= scale ? a * a : 2 * scale * a - scale * scale;
}

// Weighted least squares of h ~ level + slope u + curvature u^2 (u = max(0, t - knee)) with
// slope, curvature >= 0: the unconstrained solution, else the best of the constrained
// subsets (an active-set search over two sign constraints).
Coefficients SolveWeighted(const std::vector<double>& t, const std::vector<double>& h,
                           const std::vector<double>& w, double knee) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  double sum_w_h2 = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double u = std::max(0.0, t[i] - knee);
    const Eigen::Vector3d row(1.0, u, u * u);
    normal += w[i] * row * row.transpose();
    rhs += w[i] * h[i] * row;
    sum_w_h2 += w[i] * h[i] * h[i];
  }
  Coefficients best;
  double best_sse = std::numeric_limits<double>::infinity();
  // subsets of {slope, curvature} left free, the level always free
  const std::array<std::array<bool, 2>, 4> subsets = {{{true, true}, {true, false},
                                                       {false, true}, {false, false}}};
  for (const auto& free : subsets) {
    std::array<Eigen::Index, 3> columns{};
    Eigen::Index n = 0;
    columns[static_cast<size_t>(n++)] = 0;
    if (free[0]) columns[static_cast<size_t>(n++)] = 1;
    if (free[1]) columns[static_cast<size_t>(n++)] = 2;
    Eigen::MatrixXd a(n, n);
    Eigen::VectorXd b(n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const Eigen::Index row = columns[static_cast<size_t>(r)];
      b(r) = rhs(row);
      for (Eigen::Index c = 0; c < n; ++c) a(r, c) = normal(row, columns[static_cast<size_t>(c)]);
    }
    const Eigen::VectorXd x = a.ldlt().solve(b);
    if (!x.allFinite()) continue;
    Eigen::Vector3d full = Eigen::Vector3d::Zero();
    for (Eigen::Index r = 0; r < n; ++r) full(columns[static_cast<size_t>(r)]) = x(r);
    if (full(1) < 0 || full(2) < 0) continue;
    const double sse = sum_w_h2 - 2 * full.dot(rhs) + full.dot(normal * full);
    if (sse < best_sse) {
      best_sse = sse;
      best = {full(0), full(1), full(2)};
    }
  }
  return best;
}

double Evaluate(const Coefficients& c, double knee, double t) {
  const double u = std::max(0.0, t - knee);
  return c.level + c.slope * u + c.curvature * u * u;
}

// How a sample counts against the model: the target it is compared with and its weight.
// Lag-free samples: themselves, lag_free_weight. Samples that may lag, once the model
// rises: above it, themselves; below it by at most lag_bound (a codec's possible lag),
// themselves with lag_weight; further below, the bound's edge, in full.
struct Term {
  double target, weight;
};
Term TermOf(double h, double model, double level, double t, double knee, bool lag_free,
            const RiseFitOptions& options) {
  if (lag_free) return {h, options.lag_free_weight};
  if (t <= knee || h >= model) return {h, 1.0};
  // an older picture of a foot that only rises: at most the model's own rise below it
  const double bound = std::min(options.lag_bound, model - level);
  if (h >= model - bound) return {h, options.lag_weight};
  return {h + bound, 1.0};
}

// Huber-weighted fit at one knee: its coefficients and its total loss.
std::pair<Coefficients, double> FitAtKnee(const std::vector<double>& t,
                                          const std::vector<double>& h,
                                          const std::vector<bool>& lag_free, double knee,
                                          double scale, const RiseFitOptions& options) {
  std::vector<double> w(t.size(), 1.0), target = h;
  Coefficients c;
  for (int pass = 0; pass < options.passes; ++pass) {
    c = SolveWeighted(t, target, w, knee);
    for (size_t i = 0; i < t.size(); ++i) {
      const double model = Evaluate(c, knee, t[i]);
      const Term term = TermOf(h[i], model, c.level, t[i], knee, lag_free[i], options);
      target[i] = term.target;
      w[i] = HuberWeight(term.target - model, scale) * term.weight;
    }
  }
  double loss = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double model = Evaluate(c, knee, t[i]);
    const Term term = TermOf(h[i], model, c.level, t[i], knee, lag_free[i], options);
    loss += HuberLoss(term.target - model, scale) * term.weight;
  }
  return {c, loss};
}

// Time after the knee at which the model has risen by `threshold`; infinity if never.
double TimeToRise(const Coefficients& c, double threshold) {
  if (c.curvature > 0) {
    return (-c.slope + std::sqrt(c.slope * c.slope + 4 * c.curvature * threshold)) /
           (2 * c.curvature);
  }
  if (c.slope > 0) return threshold / c.slope;
  return std::numeric_limits<double>::infinity();
}

// The robust noise of a series from its successive differences (model-free), at least
// kNoiseFloor times the threshold. (SuccessiveDifferenceSigma is the same estimator with
// the mean of the middle two for an even count; see UpperMedianOf.)
double DifferenceNoise(const std::vector<double>& height, double threshold) {
  std::vector<double> differences;
  for (size_t i = 1; i < height.size(); ++i) {
    differences.push_back(std::abs(height[i] - height[i - 1]));
  }
  return std::max(kMadToSigma * UpperMedianOf(differences) / std::sqrt(2.0),
                  kNoiseFloor * threshold);
}

// Every knee tried, with its fit; `best` the least loss among the rising fits.
struct KneeSearch {
  std::vector<double> knees;
  std::vector<double> losses;  // infinity for a fit that does not rise
  std::vector<Coefficients> coefficients;
  size_t best = 0;
};

// candidate knees: every sample time and the midpoints between them
KneeSearch KneeGrid(const std::vector<double>& t_s) {
  KneeSearch search;
  for (size_t i = 0; i + 1 < t_s.size(); ++i) {
    search.knees.push_back(t_s[i]);
    search.knees.push_back(0.5 * (t_s[i] + t_s[i + 1]));
  }
  search.losses.resize(search.knees.size());
  search.coefficients.resize(search.knees.size());
  return search;
}

// Fits every knee at Huber scale `scale`; false when none gives a rising fit.
bool FitEveryKnee(const std::vector<double>& t_s, const std::vector<double>& height,
                  const std::vector<bool>& lag_free, double scale, const RiseFitOptions& options,
                  KneeSearch& search) {
  double best_loss = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < search.knees.size(); ++k) {
    auto [c, loss] = FitAtKnee(t_s, height, lag_free, search.knees[k], scale, options);
    search.coefficients[k] = c;
    // rising: by the last sample, beyond what roundoff makes of a flat series (~1e-13)
    const double rise = Evaluate(c, search.knees[k], t_s.back()) - c.level;
    search.losses[k] =
        rise > kLeastRise * options.threshold ? loss : std::numeric_limits<double>::infinity();
    if (search.losses[k] < best_loss) {
      best_loss = search.losses[k];
      search.best = k;
    }
  }
  return std::isfinite(best_loss);
}

// the samples' residuals from the best fit
std::vector<double> BestResiduals(const std::vector<double>& t_s, const std::vector<double>& height,
                                  const KneeSearch& search) {
  std::vector<double> residuals(t_s.size());
  for (size_t i = 0; i < t_s.size(); ++i) {
    residuals[i] =
        height[i] - Evaluate(search.coefficients[search.best], search.knees[search.best], t_s[i]);
  }
  return residuals;
}

// robust standard deviation of residuals about zero: kMadToSigma times their median
// absolute value
double ResidualSigma(const std::vector<double>& residuals) {
  std::vector<double> absolute(residuals.size());
  for (size_t i = 0; i < residuals.size(); ++i) absolute[i] = std::abs(residuals[i]);
  return kMadToSigma * UpperMedianOf(std::move(absolute));
}

// lag-one correlation of the residuals, clamped to [0, 0.95]
double LagOneCorrelation(const std::vector<double>& residuals) {
  double num = 0, den = 0;
  for (size_t i = 0; i < residuals.size(); ++i) {
    den += residuals[i] * residuals[i];
    if (i > 0) num += residuals[i] * residuals[i - 1];
  }
  return den > 0 ? std::clamp(num / den, 0.0, 0.95) : 0.0;
}

// Every knee within a two-sigma loss increase of the best (noise inflated for correlated
// residuals) widens fit's crossing and knee intervals; needs fit.noise and fit.correlation.
void SetIntervals(const std::vector<double>& t_s, const std::vector<bool>& lag_free,
                  const KneeSearch& search, const RiseFitOptions& options, RiseFit& fit) {
  // (in the losses' unit: when every sample is lag-free, each weighs lag_free_weight)
  const double inflation = (1 + fit.correlation) / (1 - fit.correlation);
  const bool all_lag_free = std::find(lag_free.begin(), lag_free.end(), false) == lag_free.end();
  const double unit = all_lag_free ? options.lag_free_weight : 1.0;
  const double allowed = 4.0 * fit.noise * fit.noise * inflation * unit;
  fit.crossing_low_s = fit.crossing_high_s = fit.crossing_s;
  fit.knee_low_s = fit.knee_high_s = fit.knee_s;
  // the knee grid holds the samples and their midpoints: its step is half the samples'
  // mean spacing, and a knee between two grid points is within a step of both; the bounds
  // get two steps (one sample spacing) of margin
  const size_t n = t_s.size();
  const double grid_step = 0.5 * (t_s.back() - t_s.front()) / static_cast<double>(n - 1);
  const std::vector<double>& knees = search.knees;
  for (size_t k = 0; k < knees.size(); ++k) {
    if (!(search.losses[k] - search.losses[search.best] <= allowed)) continue;
    const double crossing = knees[k] + TimeToRise(search.coefficients[k], options.threshold);
    if (!std::isfinite(crossing)) continue;
    fit.crossing_low_s = std::min(fit.crossing_low_s, crossing - 2 * grid_step);
    fit.crossing_high_s = std::max(fit.crossing_high_s, crossing + 2 * grid_step);
    fit.knee_low_s = std::min(fit.knee_low_s, knees[k] - 2 * grid_step);
    fit.knee_high_s = std::max(fit.knee_high_s, knees[k] + 2 * grid_step);
  }
  fit.crossing_middle_s = 0.5 * (fit.crossing_low_s + fit.crossing_high_s);
}

}  // namespace

double RiseModel(const RiseFit& fit, double t_s) {
  return Evaluate({fit.level, fit.slope, fit.curvature}, fit.knee_s, t_s);
}

RiseFit FitRise(const std::vector<double>& t_s, const std::vector<double>& height,
                const std::vector<bool>& lag_free_in, const RiseFitOptions& options) {
  RiseFit fit;
  const size_t n = t_s.size();
  if (n < 8 || height.size() != n || !(lag_free_in.empty() || lag_free_in.size() == n)) return fit;
  const std::vector<bool> lag_free = lag_free_in.empty() ? std::vector<bool>(n, true) : lag_free_in;

  // two rounds over every knee: the noise first from successive differences, then from
  // the first round's best fit; the second round's residuals give their correlation
  double noise = DifferenceNoise(height, options.threshold);
  KneeSearch search = KneeGrid(t_s);
  if (!FitEveryKnee(t_s, height, lag_free, options.huber_k * noise, options, search)) return fit;
  noise =
      std::max(ResidualSigma(BestResiduals(t_s, height, search)), kNoiseFloor * options.threshold);
  if (!FitEveryKnee(t_s, height, lag_free, options.huber_k * noise, options, search)) return fit;
  fit.correlation = LagOneCorrelation(BestResiduals(t_s, height, search));

  // the best model, its crossing, then the intervals of the knees that fit about as well
  const Coefficients& c = search.coefficients[search.best];
  fit.ok = true;
  fit.knee_s = search.knees[search.best];
  fit.level = c.level;
  fit.slope = c.slope;
  fit.curvature = c.curvature;
  fit.noise = noise;
  const double rise_time = TimeToRise(c, options.threshold);
  fit.crossing_s = fit.knee_s + rise_time;
  fit.rate_at_crossing = c.slope + 2 * c.curvature * rise_time;
  SetIntervals(t_s, lag_free, search, options, fit);
  return fit;
}

}  // namespace liftoff::video::internal
