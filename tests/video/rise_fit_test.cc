// The liftoff model's fit (src/video/rise_fit.h) on heights drawn from the model itself,
// h(t) = level + slope u + curvature u^2 with u = max(0, t - knee), where the crossing of
// level + threshold is known in closed form; noise from a seeded generator.
#include "rise_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/test_support.h"

namespace liftoff::video::internal {
namespace {

constexpr int kSamples = 60;
constexpr double kSpacingS = 1.0 / 120;

struct Truth {
  double knee_s = 24 * kSpacingS;  // a sample time: on the fit's knee grid
  double level = 3.0;
  double slope = 20.0;       // per s
  double curvature = 400.0;  // per s^2

  double Height(double t_s) const {
    const double u = std::max(0.0, t_s - knee_s);
    return level + slope * u + curvature * u * u;
  }
  // level + slope u + curvature u^2 = level + threshold, solved for u
  double Crossing(double threshold) const {
    if (curvature == 0) return knee_s + threshold / slope;
    return knee_s +
           (-slope + std::sqrt(slope * slope + 4 * curvature * threshold)) / (2 * curvature);
  }
};

std::vector<double> Times() {
  std::vector<double> t_s(kSamples);
  for (int i = 0; i < kSamples; ++i) t_s[static_cast<size_t>(i)] = i * kSpacingS;
  return t_s;
}

std::vector<double> Heights(const Truth& truth, const std::vector<double>& t_s) {
  std::vector<double> h;
  for (const double t : t_s) h.push_back(truth.Height(t));
  return h;
}

void ExpectExactFit(const Truth& truth) {
  const RiseFitOptions options;
  const std::vector<double> t_s = Times();
  const RiseFit fit = FitRise(t_s, Heights(truth, t_s), {}, options);
  ASSERT_TRUE(fit.ok);
  std::printf("knee %.3f ms: knee error %.2e s, crossing error %.2e s\n", truth.knee_s * 1e3,
              fit.knee_s - truth.knee_s, fit.crossing_s - truth.Crossing(options.threshold));
  EXPECT_NEAR(fit.knee_s, truth.knee_s, 1e-6 * kSpacingS);
  EXPECT_NEAR(fit.level, truth.level, 1e-6);
  // relative to the rise's scale: what the coefficients add over a tenth of a second
  EXPECT_NEAR(fit.slope, truth.slope, 1e-6 * 10);
  EXPECT_NEAR(fit.curvature, truth.curvature, 1e-6 * 100);
  EXPECT_NEAR(fit.crossing_s, truth.Crossing(options.threshold), 1e-6 * kSpacingS);
  const double u = fit.crossing_s - truth.knee_s;
  EXPECT_NEAR(fit.rate_at_crossing, truth.slope + 2 * truth.curvature * u, 1e-6 * 10);
  EXPECT_LE(fit.crossing_low_s, fit.crossing_s);
  EXPECT_GE(fit.crossing_high_s, fit.crossing_s);
}

TEST(FitRise, RecoversExactModelWithKneeOnASample) { ExpectExactFit(Truth{}); }

TEST(FitRise, RecoversExactModelWithKneeHalfwayBetweenSamples) {
  Truth truth;
  truth.knee_s = 24.5 * kSpacingS;  // the grid's midpoints
  ExpectExactFit(truth);
}

TEST(FitRise, RecoversPurelyLinearAndPurelyQuadraticRises) {
  Truth linear;
  linear.curvature = 0;
  linear.slope = 30;
  ExpectExactFit(linear);
  Truth quadratic;
  quadratic.slope = 0;
  quadratic.curvature = 600;
  ExpectExactFit(quadratic);
}

TEST(FitRise, KneeOffTheGridStillBracketsTheCrossing) {
  // a knee 0.3 spacing after a sample: the best grid knee is near, the interval holds it
  Truth truth;
  truth.knee_s = 24.3 * kSpacingS;
  const RiseFitOptions options;
  const std::vector<double> t_s = Times();
  const RiseFit fit = FitRise(t_s, Heights(truth, t_s), {}, options);
  ASSERT_TRUE(fit.ok);
  const double crossing = truth.Crossing(options.threshold);
  std::printf("knee off grid: crossing error %.3f ms, interval [%.3f, %.3f] ms around truth\n",
              (fit.crossing_s - crossing) * 1e3, (fit.crossing_low_s - crossing) * 1e3,
              (fit.crossing_high_s - crossing) * 1e3);
  EXPECT_NEAR(fit.crossing_s, crossing, 0.5 * kSpacingS);
  EXPECT_LE(fit.crossing_low_s, crossing);
  EXPECT_GE(fit.crossing_high_s, crossing);
}

// Fraction of seeded noisy trials whose crossing interval holds the true crossing.
double Coverage(double noise, const std::vector<bool>& lag_free, double* mean_width_s) {
  const Truth truth;
  const RiseFitOptions options;
  const std::vector<double> t_s = Times();
  const double crossing = truth.Crossing(options.threshold);
  constexpr int kTrials = 200;
  int covered = 0;
  double width_sum = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::mt19937 generator(static_cast<unsigned>(1000 + trial));
    std::normal_distribution<double> gaussian(0.0, noise);
    std::vector<double> h = Heights(truth, t_s);
    for (double& value : h) value += gaussian(generator);
    const RiseFit fit = FitRise(t_s, h, lag_free, options);
    if (!fit.ok) continue;
    if (fit.crossing_low_s <= crossing && crossing <= fit.crossing_high_s) ++covered;
    width_sum += fit.crossing_high_s - fit.crossing_low_s;
  }
  *mean_width_s = width_sum / kTrials;
  return static_cast<double>(covered) / kTrials;
}

TEST(FitRise, CrossingIntervalCoversTheTruthUnderGaussianNoise) {
  for (const double noise : {0.05, 0.1, 0.2}) {
    double width_s = 0;
    const double coverage = Coverage(noise, {}, &width_s);
    std::printf("noise %.2f of the threshold: coverage %.1f %% of 200, mean width %.2f ms\n",
                noise, 100 * coverage, width_s * 1e3);
    EXPECT_GE(coverage, 0.9) << "noise " << noise;
  }
}

TEST(FitRise, EverySampleLagFreeGivesTheIntervalOfEverySamplePlain) {
  // the same weight on every sample, 1 or lag_free_weight, is the same fit and interval;
  // at a large noise the loss-based interval, not the grid margin, has to hold the truth
  constexpr double kNoise = 0.8;
  double lag_free_width_s = 0, plain_width_s = 0;
  const double lag_free = Coverage(kNoise, {}, &lag_free_width_s);
  const double plain = Coverage(kNoise, std::vector<bool>(kSamples, false), &plain_width_s);
  std::printf("noise %.2f: coverage %.1f %% all lag-free (width %.2f ms), %.1f %% plain "
              "(%.2f ms)\n",
              kNoise, 100 * lag_free, lag_free_width_s * 1e3, 100 * plain, plain_width_s * 1e3);
  EXPECT_NEAR(lag_free_width_s, plain_width_s, 1e-9);
  EXPECT_EQ(lag_free, plain);
  EXPECT_GE(lag_free, 0.95);
}

TEST(FitRise, SingleTenSigmaOutlierBarelyMovesTheCrossing) {
  const Truth truth;
  const RiseFitOptions options;
  const std::vector<double> t_s = Times();
  constexpr double kNoise = 0.05;
  std::mt19937 generator(7);
  std::normal_distribution<double> gaussian(0.0, kNoise);
  std::vector<double> h = Heights(truth, t_s);
  for (double& value : h) value += gaussian(generator);
  const RiseFit clean = FitRise(t_s, h, {}, options);
  ASSERT_TRUE(clean.ok);
  // up and down, before the knee, just after it, and around the crossing
  double worst_s = 0;
  for (const size_t frame : {10u, 22u, 26u, 28u, 30u}) {
    for (const double sign : {1.0, -1.0}) {
      std::vector<double> bumped = h;
      bumped[frame] += sign * 10 * kNoise;
      const RiseFit fit = FitRise(t_s, bumped, {}, options);
      ASSERT_TRUE(fit.ok);
      worst_s = std::max(worst_s, std::abs(fit.crossing_s - clean.crossing_s));
    }
  }
  std::printf("10-sigma outlier: crossing moves at most %.3f ms (spacing %.2f ms)\n",
              worst_s * 1e3, kSpacingS * 1e3);
  EXPECT_LT(worst_s, 0.003);
}

TEST(FitRise, EmptyLagFreeMeansEverySampleIsLagFree) {
  const Truth truth;
  const std::vector<double> t_s = Times();
  std::mt19937 generator(3);
  std::normal_distribution<double> gaussian(0.0, 0.1);
  std::vector<double> h = Heights(truth, t_s);
  for (double& value : h) value += gaussian(generator);
  RiseFitOptions options;
  options.lag_bound = 0.5;
  options.lag_weight = 0.2;
  const RiseFit empty = FitRise(t_s, h, {}, options);
  const RiseFit all = FitRise(t_s, h, std::vector<bool>(t_s.size(), true), options);
  ASSERT_TRUE(empty.ok);
  ASSERT_TRUE(all.ok);
  EXPECT_EQ(empty.knee_s, all.knee_s);
  EXPECT_EQ(empty.slope, all.slope);
  EXPECT_EQ(empty.curvature, all.curvature);
  EXPECT_EQ(empty.crossing_s, all.crossing_s);
  EXPECT_EQ(empty.crossing_low_s, all.crossing_low_s);
  EXPECT_EQ(empty.crossing_high_s, all.crossing_high_s);
}

TEST(FitRise, LagAwareIntervalHoldsTheTruthUnderASawtoothLag) {
  // a codec that renews the picture every 6 frames: after the knee the decoded height lags
  // the model by a sawtooth in [0, lag_bound); one renewed frame near the crossing is
  // marked lag-free
  const Truth truth;
  RiseFitOptions options;
  options.lag_bound = 0.6;
  options.lag_weight = 0.1;
  const std::vector<double> t_s = Times();
  std::vector<double> h = Heights(truth, t_s);
  std::vector<bool> lag_free(t_s.size(), false);
  constexpr int kPeriod = 6;
  const int knee_index = static_cast<int>(std::lround(truth.knee_s / kSpacingS));
  for (int i = knee_index + 1; i < kSamples; ++i) {
    const int phase = (i - knee_index) % kPeriod;
    h[static_cast<size_t>(i)] -= options.lag_bound * phase / kPeriod;
  }
  const double crossing = truth.Crossing(options.threshold);
  const size_t key = static_cast<size_t>(knee_index + kPeriod * 2);  // lag 0: on the model
  ASSERT_NEAR(h[key], truth.Height(t_s[key]), 1e-12);
  lag_free[key] = true;
  const RiseFit fit = FitRise(t_s, h, lag_free, options);
  ASSERT_TRUE(fit.ok);
  std::printf("lag-aware: interval [%.3f, %.3f] ms around truth, middle %+.3f ms\n",
              (fit.crossing_low_s - crossing) * 1e3, (fit.crossing_high_s - crossing) * 1e3,
              (fit.crossing_middle_s - crossing) * 1e3);
  EXPECT_LE(fit.crossing_low_s, crossing);
  EXPECT_GE(fit.crossing_high_s, crossing);
}

// Reads tests/video/data/hard3d-02-k250-rise.csv (t_s,height_px,lag_free after `#` lines
// and a header).
void ReadRise(std::vector<double>& t_s, std::vector<double>& h, std::vector<bool>& lag_free) {
  std::ifstream in(testing::SourceDir() / "tests" / "video" / "data" / "hard3d-02-k250-rise.csv");
  std::string line;
  while (std::getline(in, line)) {
    double t = 0, height = 0;
    int free = 0;
    if (line.empty() || line[0] == '#' ||
        std::sscanf(line.c_str(), "%lf,%lf,%d", &t, &height, &free) != 3) {
      continue;
    }
    t_s.push_back(t);
    h.push_back(height);
    lag_free.push_back(free != 0);
  }
}

// A real curve (data/README.md): 3 s of rest that wanders by +-0.3 px (H.264 holding a noisy,
// shaken picture with a key frame every 250 frames), then a rise the samples follow, every
// sample allowed to lag by 3.5 px. A sample lags only behind a foot that has risen, by at
// most the model's own rise: the rest below the level counts against an early knee, which
// could otherwise sit on the wander's upper half as a "lagging" slow rise (its crossing
// 0.77 s early).
TEST(FitRise, RestBelowTheLevelIsNoCodecLagOnARealCurve) {
  std::vector<double> t_s, h;
  std::vector<bool> lag_free;
  ReadRise(t_s, h, lag_free);
  ASSERT_EQ(t_s.size(), 107u);
  RiseFitOptions options;
  options.threshold = 0.646473;
  options.lag_bound = 3.506864;
  options.lag_weight = 0.02;
  const RiseFit fit = FitRise(t_s, h, lag_free, options);
  ASSERT_TRUE(fit.ok);
  constexpr double kTruthS = 19.264 - 16.166667;
  std::printf("real curve: best crossing %+.1f ms, middle %+.1f ms, [%+.1f, %+.1f] ms\n",
              (fit.crossing_s - kTruthS) * 1e3, (fit.crossing_middle_s - kTruthS) * 1e3,
              (fit.crossing_low_s - kTruthS) * 1e3, (fit.crossing_high_s - kTruthS) * 1e3);
  EXPECT_LE(fit.crossing_low_s, kTruthS);
  EXPECT_GE(fit.crossing_high_s, kTruthS);
  EXPECT_NEAR(fit.crossing_middle_s, kTruthS, 0.3);
}

TEST(FitRise, FewerThanEightSamplesOrMismatchedSizesAreNotOk) {
  const Truth truth;
  std::vector<double> t_s = Times();
  t_s.resize(7);
  EXPECT_FALSE(FitRise(t_s, Heights(truth, t_s), {}, {}).ok);
  t_s = Times();
  std::vector<double> h = Heights(truth, t_s);
  EXPECT_TRUE(FitRise(t_s, h, {}, {}).ok);
  h.pop_back();
  EXPECT_FALSE(FitRise(t_s, h, {}, {}).ok);
  h.push_back(0);
  EXPECT_FALSE(FitRise(t_s, h, std::vector<bool>(3, true), {}).ok);
}

TEST(FitRise, FlatSeriesDoesNotRise) {
  // a constant's least-squares slope is roundoff (1e-15 .. 1e-12), not a rise
  const std::vector<double> t_s = Times();
  for (const double level : {0.0, 3.0, 1234.5}) {
    const RiseFit fit = FitRise(t_s, std::vector<double>(t_s.size(), level), {}, {});
    EXPECT_FALSE(fit.ok) << "level " << level << ": crossing " << fit.crossing_s << " s";
  }
}

TEST(RiseModel, IsFlatUntilTheKneeThenRisesQuadratically) {
  RiseFit fit;
  fit.knee_s = 1.0;
  fit.level = 2.0;
  fit.slope = 3.0;
  fit.curvature = 4.0;
  EXPECT_DOUBLE_EQ(RiseModel(fit, 0.5), 2.0);
  EXPECT_DOUBLE_EQ(RiseModel(fit, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(RiseModel(fit, 1.5), 2.0 + 1.5 + 1.0);
  EXPECT_DOUBLE_EQ(RiseModel(fit, 3.0), 2.0 + 6.0 + 16.0);
}

}  // namespace
}  // namespace liftoff::video::internal
