// The calibration of the simulation against hardware: the tension scale's line through
// the calibration's points, the ranking on a case with an obvious answer, the fit
// recovering a tension hidden in synthetic trials made with the simulation, and the Monte
// Carlo's reproducibility and spread. Simulated runs use a shortened timeline (ramp 60
// degrees over 10 s from 2 s) to stay fast.
#include "liftoff/fit/tension_fit.h"

#include <cmath>
#include <functional>
#include <iostream>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/core/random.h"
#include "support/test_support.h"

namespace liftoff::fit {
namespace {

using ::testing::HasSubstr;

Calibration Laika2018() {
  auto calibration = LoadCalibration(liftoff::testing::SourceDir() / "calib" / "laika-2018.json");
  EXPECT_TRUE(calibration.ok()) << calibration.status().ToString();
  return calibration.value_or(Calibration{});
}

sim::ModelDescription Laika() {
  auto description = sim::LoadModelDescription(sim::DefaultModelPath());
  EXPECT_TRUE(description.ok()) << description.status().ToString();
  return description.value_or(sim::ModelDescription{});
}

sim::SweepOptions ShortSweep(std::vector<Foot> feet) {
  sim::SweepOptions options;
  options.base.bend_start_s = 1.0;
  options.base.reference_time_s = 1.9;
  options.base.ramp_start_s = 2.0;
  options.base.ramp_duration_s = 10.0;
  options.feet = std::move(feet);
  return options;
}

stats::TrialValue Trial(Foot foot, double liftoff_rad) {
  stats::TrialValue value;
  value.trial_id = std::string(FootName(foot));
  value.foot = foot;
  value.liftoff_rad = liftoff_rad;
  return value;
}

// a standard normal number from the test's own generator (Box-Muller)
double Normal(SplitMix64& random) {
  const double u1 = 1.0 - random.Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * random.Uniform());
}

TEST(TensionAtSigma, FollowsTheCalibrationsPointsAndExtendsTheirLine) {
  const std::vector<TensionPoint>& points = Laika2018().tension_points;
  ASSERT_EQ(points.size(), 5u);
  // on the points: Table III
  EXPECT_DOUBLE_EQ(TensionAtSigma(points, -2.0, "x").silicone_n_per_m, 216.0);
  EXPECT_DOUBLE_EQ(TensionAtSigma(points, 1.0, "x").buna_n_n_per_m, 941.0);
  // between: halfway from mean (237, 810) to med-high (248, 941)
  const TensionPoint half = TensionAtSigma(points, 0.5, "half");
  EXPECT_DOUBLE_EQ(half.silicone_n_per_m, 242.5);
  EXPECT_DOUBLE_EQ(half.buna_n_n_per_m, 875.5);
  EXPECT_DOUBLE_EQ(half.spring_n_per_m, 187.0);
  EXPECT_EQ(half.name, "half");
  EXPECT_DOUBLE_EQ(half.sigma, 0.5);
  // past the high point, on its last segment's line: 258 + (258 - 248), 1073 + 132
  const TensionPoint beyond = TensionAtSigma(points, 3.0, "beyond");
  EXPECT_DOUBLE_EQ(beyond.silicone_n_per_m, 268.0);
  EXPECT_DOUBLE_EQ(beyond.buna_n_n_per_m, 1205.0);
}

TEST(TargetsFromTrials, WeighsEachFootByItsStandardErrorAndSkipsSingleTrials) {
  std::vector<std::string> skipped;
  auto targets =
      TargetsFromTrials({Trial(Foot::kA, 0.40), Trial(Foot::kA, 0.44), Trial(Foot::kB, 0.5),
                         Trial(Foot::kC, 0.3), Trial(Foot::kC, 0.3)},
                        {}, &skipped);
  ASSERT_TRUE(targets.ok()) << targets.status().ToString();
  ASSERT_EQ(targets->size(), 2u);
  // A: sd 0.02 * sqrt(2) over sqrt(2) = 0.02; C: identical trials take the floor
  EXPECT_NEAR((*targets)[0].standard_error_rad, 0.02, 1e-12);
  EXPECT_DOUBLE_EQ((*targets)[1].standard_error_rad, 0.001);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_THAT(skipped[0], HasSubstr("foot B"));
}

TEST(RankTensionPoints, PutsThePointTheTrialsWereMadeFromFirst) {
  // three points, the trials scattered around "middle"'s values; "sagged" has no C value
  auto sample = [](std::string name, double a, std::optional<double> c) {
    TensionSample result;
    result.tension.name = std::move(name);
    result.liftoff_rad[0] = a;
    result.liftoff_rad[2] = c;
    return result;
  };
  const std::vector<TensionSample> samples = {
      sample("sagged", 0.45, std::nullopt), sample("low", 0.38, 0.33), sample("middle", 0.45, 0.40),
      sample("high", 0.52, 0.47)};
  auto targets =
      TargetsFromTrials({Trial(Foot::kA, 0.44), Trial(Foot::kA, 0.46), Trial(Foot::kA, 0.45),
                         Trial(Foot::kC, 0.39), Trial(Foot::kC, 0.41)},
                        {});
  ASSERT_TRUE(targets.ok());
  const Ranking ranking = RankTensionPoints(*targets, samples);
  ASSERT_EQ(ranking.overall.size(), 4u);
  EXPECT_EQ(ranking.overall[0].tension.name, "middle");
  EXPECT_TRUE(ranking.overall[0].complete);
  EXPECT_NEAR(ranking.overall[0].chi_square, 0.0, 1e-9);
  EXPECT_EQ(ranking.overall[3].tension.name, "sagged");  // incomplete: last
  EXPECT_FALSE(ranking.overall[3].complete);
  // A at low: (0.38 - 0.45) / (0.01 / sqrt(3))
  const FootAgreement& a_low = ranking.overall[1].feet[0];
  EXPECT_NEAR(std::abs(a_low.z), 0.07 / (0.01 / std::sqrt(3.0)), 1e-9);
  ASSERT_EQ(ranking.per_foot.size(), 2u);
  EXPECT_EQ(ranking.per_foot[0].first, Foot::kA);
  // A's value at "sagged" equals middle's: both first (stable order keeps the better overall)
  EXPECT_EQ(ranking.per_foot[0].second.front(), "middle");
  EXPECT_EQ(ranking.per_foot[1].second.front(), "middle");
  EXPECT_EQ(ranking.per_foot[1].second.size(), 3u);  // C has no value at "sagged"
}

// Hardware made from the simulation at a tension scale the fit is not told, with 5 trials
// per foot scattered by 0.005 rad: the fit finds it within its 95 % interval.
TEST(FitTension, RecoversTheTensionSyntheticTrialsWereMadeAt) {
  const Calibration calibration = Laika2018();
  const sim::ModelDescription model = Laika();
  const sim::SweepOptions sweep = ShortSweep({Foot::kA, Foot::kC});
  constexpr double kHiddenSigma = 0.6;
  auto truth = SimulateTensions(
      model, sweep, {TensionAtSigma(calibration.tension_points, kHiddenSigma, "hidden")});
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  std::vector<stats::TrialValue> trials;
  SplitMix64 random(7);
  for (const Foot foot : {Foot::kA, Foot::kC}) {
    const std::optional<double> value = (*truth)[0].liftoff_rad[static_cast<size_t>(foot)];
    ASSERT_TRUE(value.has_value()) << FootName(foot);
    for (int i = 0; i < 5; ++i) trials.push_back(Trial(foot, *value + 0.005 * Normal(random)));
  }

  FitOptions options;
  options.sigma_min = -0.5;
  options.sigma_max = 2.0;
  options.sigma_step = 0.25;
  auto grid =
      SimulateTensions(model, sweep, GridTensionPoints(calibration.tension_points, options));
  ASSERT_TRUE(grid.ok()) << grid.status().ToString();
  auto targets = TargetsFromTrials(trials, {});
  ASSERT_TRUE(targets.ok());
  auto fit = FitTension(*targets, *grid, calibration.tension_points, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  SCOPED_TRACE(fit->Brief());
  std::cout << "hidden sigma " << kHiddenSigma << ", fitted " << fit->Brief() << "\n";
  EXPECT_LE(fit->sigma_low95, kHiddenSigma);
  EXPECT_GE(fit->sigma_high95, kHiddenSigma);
  EXPECT_LT(fit->sigma_high95 - fit->sigma_low95, 1.0);  // an interval that says something
  EXPECT_GT(fit->sigma_stddev, 0.0);
  EXPECT_FALSE(fit->poor);
  EXPECT_EQ(fit->degrees_of_freedom, 1);
  EXPECT_EQ(fit->tension.name, "fitted");
  EXPECT_DOUBLE_EQ(fit->tension.silicone_n_per_m,
                   TensionAtSigma(calibration.tension_points, fit->sigma, "").silicone_n_per_m);
}

TEST(FitTension, SaysWhereTheFitIsPoor) {
  // curves rising 0.40 -> 0.46 over sigma 0 .. 2; foot A's trials lie far above them, C's
  // as far below (equal weights): the best compromise is inside, at 0.435 rad
  std::vector<TensionSample> grid;
  for (int i = 0; i <= 2; ++i) {
    TensionSample& sample = grid.emplace_back();
    sample.tension.sigma = i;
    sample.liftoff_rad[0] = 0.40 + 0.03 * i;
    sample.liftoff_rad[2] = 0.40 + 0.03 * i;
  }
  auto targets = TargetsFromTrials(
      {Trial(Foot::kA, 0.56), Trial(Foot::kA, 0.58), Trial(Foot::kC, 0.29), Trial(Foot::kC, 0.31)},
      {});
  ASSERT_TRUE(targets.ok());
  auto fit = FitTension(*targets, grid, Laika2018().tension_points, {});
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_TRUE(fit->poor);
  EXPECT_NEAR(fit->sigma, 35.0 / 30.0, 1e-9);
  // (0.435 - 0.57)^2 / 0.01^2 + (0.435 - 0.30)^2 / 0.01^2, one degree of freedom
  EXPECT_NEAR(fit->chi_square, 364.5, 1e-6);
  EXPECT_NEAR(fit->chi_square_per_dof, 364.5, 1e-6);
  EXPECT_GT(fit->sigma_stddev_scaled, fit->sigma_stddev);
  const std::string warnings = ::testing::PrintToString(fit->warnings);
  EXPECT_THAT(warnings, HasSubstr("foot A: the hardware mean 0.570 rad lies above"));
  EXPECT_THAT(warnings, HasSubstr("foot C: the hardware mean 0.300 rad lies below"));
  EXPECT_THAT(warnings, HasSubstr("poor fit"));
}

// A bias every trial shares moves the fit; the bootstrap cannot see it, the systematic
// term does: on curves rising 0.03 rad per unit of sigma, trials known to +-0.006 rad
// move sigma by 0.2 when all shift together.
TEST(FitTension, StatesWhatABiasTheTrialsShareWouldMove) {
  std::vector<TensionSample> grid;
  for (int i = 0; i <= 4; ++i) {
    TensionSample& sample = grid.emplace_back();
    sample.tension.sigma = i;
    sample.liftoff_rad[0] = 0.40 + 0.03 * i;
    sample.liftoff_rad[2] = 0.40 + 0.03 * i;
  }
  const auto within = [](Foot foot, double value, double half_width) {
    stats::TrialValue trial = Trial(foot, value);
    trial.lower_rad = value - half_width;
    trial.upper_rad = value + half_width;
    return trial;
  };
  auto targets = TargetsFromTrials({within(Foot::kA, 0.459, 0.006), within(Foot::kA, 0.461, 0.004),
                                    within(Foot::kA, 0.460, 0.008), within(Foot::kC, 0.459, 0.006),
                                    within(Foot::kC, 0.461, 0.006)},
                                   {});
  ASSERT_TRUE(targets.ok());
  EXPECT_NEAR((*targets)[0].measurement_rad, 0.006, 1e-12);  // the median half-width
  EXPECT_NEAR((*targets)[1].measurement_rad, 0.006, 1e-12);
  auto fit = FitTension(*targets, grid, Laika2018().tension_points, {});
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_NEAR(fit->sigma, 2.0, 1e-9);
  EXPECT_NEAR(fit->sigma_systematic, 0.2, 1e-9);
  EXPECT_NEAR(fit->sigma_total, std::hypot(fit->sigma_stddev, 0.2), 1e-12);
  EXPECT_THAT(fit->Brief(), HasSubstr("+- 0.20 systematic"));

  // trials without intervals: no systematic term
  auto bare = TargetsFromTrials(
      {Trial(Foot::kA, 0.459), Trial(Foot::kA, 0.461), Trial(Foot::kC, 0.46), Trial(Foot::kC, 0.46)},
      {});
  ASSERT_TRUE(bare.ok());
  auto bare_fit = FitTension(*bare, grid, Laika2018().tension_points, {});
  ASSERT_TRUE(bare_fit.ok());
  EXPECT_EQ(bare_fit->sigma_systematic, 0.0);
  EXPECT_EQ(bare_fit->sigma_total, bare_fit->sigma_stddev);
}

TEST(FitTension, NeedsTwoNeighbouringCompletePoints) {
  std::vector<TensionSample> grid(3);
  grid[0].liftoff_rad[0] = 0.4;
  grid[2].liftoff_rad[0] = 0.5;
  auto targets = TargetsFromTrials({Trial(Foot::kA, 0.44), Trial(Foot::kA, 0.46)}, {});
  ASSERT_TRUE(targets.ok());
  auto fit = FitTension(*targets, grid, Laika2018().tension_points, {});
  EXPECT_EQ(fit.status().code(), StatusCode::kNotFound);
}

// A grid per ratio of analytic curves: foot f's liftoff is value(f, sigma, ratio).
std::vector<std::vector<TensionSample>> RatioGrids(
    const RatioFitOptions& ratios, const std::function<double(Foot, double, double)>& value) {
  std::vector<std::vector<TensionSample>> grids;
  for (double ratio : ratios.ratios) {
    std::vector<TensionSample>& grid = grids.emplace_back();
    for (int i = 0; i <= 24; ++i) {  // sigma -2 .. 4, as FitOptions' default grid
      TensionSample& sample = grid.emplace_back();
      sample.tension.sigma = -2.0 + 0.25 * i;
      for (Foot foot : {Foot::kA, Foot::kB, Foot::kC}) {
        sample.liftoff_rad[static_cast<size_t>(foot)] = value(foot, sample.tension.sigma, ratio);
      }
    }
  }
  return grids;
}

// Trials at value(f, sigma, ratio) +- 0.002 rad, two per foot A, B, C.
Result<std::vector<FootTarget>> RatioTrials(
    const std::function<double(Foot, double, double)>& value, double sigma, double ratio) {
  std::vector<stats::TrialValue> trials;
  for (Foot foot : {Foot::kA, Foot::kB, Foot::kC}) {
    trials.push_back(Trial(foot, value(foot, sigma, ratio) - 0.002));
    trials.push_back(Trial(foot, value(foot, sigma, ratio) + 0.002));
  }
  return TargetsFromTrials(trials, {});
}

TEST(FitStiffnessRatio, RecoversTheRatioWhenTheFeetRespondToItDifferently) {
  // the front foot lifts later with more Buna-N, the back one earlier, B not at all;
  // the tension scale moves every foot alike: the ratio is pinned
  const auto value = [](Foot foot, double sigma, double ratio) {
    const double per_log_ratio = foot == Foot::kA ? 0.04 : (foot == Foot::kC ? -0.04 : 0.0);
    const double base = foot == Foot::kA ? 0.40 : (foot == Foot::kC ? 0.45 : 0.42);
    return base + 0.03 * sigma + per_log_ratio * std::log(ratio);
  };
  const RatioFitOptions options;
  auto targets = RatioTrials(value, 1.0, 1.41);
  ASSERT_TRUE(targets.ok());
  auto fit = FitStiffnessRatio(*targets, RatioGrids(options, value), {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  SCOPED_TRACE(fit->Brief());
  EXPECT_DOUBLE_EQ(fit->ratio, 1.41);
  EXPECT_NEAR(fit->sigma, 1.0, 1e-6);
  EXPECT_TRUE(fit->determined);
  // the interval is narrower than the grid: bounded by the neighbouring ratios
  EXPECT_DOUBLE_EQ(fit->ratio_low, 1.0);
  EXPECT_DOUBLE_EQ(fit->ratio_high, 2.0);
  EXPECT_EQ(fit->degrees_of_freedom, 1);
  EXPECT_EQ(fit->profile.size(), options.ratios.size());
  EXPECT_TRUE(fit->warnings.empty()) << ::testing::PrintToString(fit->warnings);
}

TEST(FitStiffnessRatio, SaysWhenTheBestRatioLiesBeyondThoseTried) {
  const auto value = [](Foot foot, double sigma, double ratio) {
    const double per_log_ratio = foot == Foot::kA ? 0.04 : (foot == Foot::kC ? -0.04 : 0.0);
    return 0.42 + 0.03 * sigma + per_log_ratio * std::log(ratio);
  };
  const RatioFitOptions options;  // up to x2
  auto targets = RatioTrials(value, 1.0, 3.0);
  ASSERT_TRUE(targets.ok());
  auto fit = FitStiffnessRatio(*targets, RatioGrids(options, value), {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_DOUBLE_EQ(fit->ratio, 2.0);
  EXPECT_FALSE(fit->determined);
  EXPECT_TRUE(fit->poor);
  const std::string warnings = ::testing::PrintToString(fit->warnings);
  EXPECT_THAT(warnings,
              HasSubstr("the least chi-square lies at the end of the ratios fitted (x2.00"));
  EXPECT_THAT(warnings, HasSubstr("poor fit: chi2"));
}

TEST(FitStiffnessRatio, MarksRatiosWhoseTensionScaleSitsAtTheGridsEnd) {
  const auto value = [](Foot foot, double sigma, double ratio) {
    const double per_log_ratio = foot == Foot::kA ? 0.04 : (foot == Foot::kC ? -0.04 : 0.0);
    return 0.42 + 0.03 * sigma + per_log_ratio * std::log(ratio);
  };
  const RatioFitOptions options;
  // the trials were made at sigma 3.9, ratio 1; at x0.5 the runs stop at sigma 3 (beyond,
  // the robot "did not stand"), so the scale sits at the end of what was searched there
  auto targets = RatioTrials(value, 3.9, 1.0);
  ASSERT_TRUE(targets.ok());
  std::vector<std::vector<TensionSample>> grids = RatioGrids(options, value);
  for (TensionSample& sample : grids[0]) {
    if (sample.tension.sigma > 3.0) sample.liftoff_rad = {};
  }
  auto fit = FitStiffnessRatio(*targets, grids, {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_TRUE(fit->profile[0].at_edge);
  EXPECT_FALSE(fit->profile[2].at_edge);
  EXPECT_THAT(::testing::PrintToString(fit->warnings),
              HasSubstr("at x0.50 the tension scale sits at an end of its searched range"));
}

TEST(FitStiffnessRatio, SaysWhenOneRatioAloneCouldBeFitted) {
  const auto value = [](Foot, double sigma, double) { return 0.42 + 0.03 * sigma; };
  const RatioFitOptions options;
  auto targets = RatioTrials(value, 1.0, 1.0);
  ASSERT_TRUE(targets.ok());
  std::vector<std::vector<TensionSample>> grids = RatioGrids(options, value);
  for (size_t i : {0u, 1u, 3u, 4u}) {
    for (TensionSample& sample : grids[i]) sample.liftoff_rad = {};
  }
  auto fit = FitStiffnessRatio(*targets, grids, {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_DOUBLE_EQ(fit->ratio, 1.0);
  EXPECT_FALSE(fit->determined);
  EXPECT_THAT(::testing::PrintToString(fit->warnings),
              HasSubstr("the tension scale could be fitted at one ratio only (x1.00)"));
}

TEST(FitStiffnessRatio, SaysWhenTheRatioMovesTheFeetAsTheTensionScaleDoes) {
  // every foot moves with sigma + 2 log(ratio): any ratio fits as well at its own sigma
  const auto value = [](Foot foot, double sigma, double ratio) {
    return (foot == Foot::kA ? 0.40 : (foot == Foot::kB ? 0.42 : 0.45)) +
           0.03 * (sigma + 2.0 * std::log(ratio));
  };
  const RatioFitOptions options;
  auto targets = RatioTrials(value, 1.0, 1.0);
  ASSERT_TRUE(targets.ok());
  auto fit = FitStiffnessRatio(*targets, RatioGrids(options, value), {}, options);
  ASSERT_TRUE(fit.ok()) << fit.status().ToString();
  EXPECT_FALSE(fit->determined) << fit->Brief();
  EXPECT_DOUBLE_EQ(fit->ratio_low, 0.5);
  EXPECT_DOUBLE_EQ(fit->ratio_high, 2.0);
  EXPECT_THAT(::testing::PrintToString(fit->warnings),
              HasSubstr("the ratio is not determined by these trials"));
  EXPECT_THAT(fit->Brief(), HasSubstr("not determined"));
}

TEST(FitStiffnessRatio, RejectsBadRatiosAndAGridPerRatioMissing) {
  RatioFitOptions options;
  options.ratios = {0.5, 2.0, 4.0};  // without 1
  EXPECT_THAT(options.Validate().message(), HasSubstr("ratios: expected"));
  EXPECT_THAT(options.Validate().message(), HasSubstr("got none equal to 1"));
  options.ratios = {0.5, 1.0, 1.0};
  EXPECT_THAT(options.Validate().message(), HasSubstr("got values out of range or not increasing"));
  options.ratios = {1.0, 2.0};
  EXPECT_THAT(options.Validate().message(), HasSubstr("got 2 values"));
  options.ratios = {0.5, 1.0, 2.0};
  EXPECT_TRUE(options.Validate().ok());
  auto targets = TargetsFromTrials({Trial(Foot::kA, 0.44), Trial(Foot::kA, 0.46)}, {});
  ASSERT_TRUE(targets.ok());
  auto fit = FitStiffnessRatio(*targets, {}, {}, options);
  EXPECT_EQ(fit.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(fit.status().message(), HasSubstr("grids: expected one per ratio (3), got 0"));
}

TEST(ScaledBunaN, ScalesBunaNAloneAtEveryPoint) {
  const std::vector<TensionPoint> points = Laika2018().tension_points;
  const std::vector<TensionPoint> scaled = ScaledBunaN(points, 1.5);
  ASSERT_EQ(scaled.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_DOUBLE_EQ(scaled[i].buna_n_n_per_m, 1.5 * points[i].buna_n_n_per_m);
    EXPECT_EQ(scaled[i].silicone_n_per_m, points[i].silicone_n_per_m);
    EXPECT_EQ(scaled[i].spring_n_per_m, points[i].spring_n_per_m);
    EXPECT_EQ(scaled[i].sigma, points[i].sigma);
  }
}

TEST(MonteCarloDraws, AreReproducibleAndSpreadAsTableOneSays) {
  const Calibration calibration = Laika2018();
  MonteCarloOptions options;
  options.samples = 4000;
  auto first = MonteCarloDraws(calibration, options);
  auto again = MonteCarloDraws(calibration, options);
  ASSERT_TRUE(first.ok() && again.ok());
  std::vector<double> silicone, buna_n;
  for (size_t i = 0; i < first->size(); ++i) {
    EXPECT_EQ((*first)[i].silicone_n_per_m, (*again)[i].silicone_n_per_m);
    EXPECT_EQ((*first)[i].buna_n_n_per_m, (*again)[i].buna_n_n_per_m);
    EXPECT_EQ((*first)[i].spring_n_per_m, 187.0);  // Table I: exact
    silicone.push_back((*first)[i].silicone_n_per_m);
    buna_n.push_back((*first)[i].buna_n_n_per_m);
  }
  // Table I: 237 +- 11 and 810 +- 132 N/m (4000 draws: the sample sd within 5 %)
  const stats::Summary silicone_summary = stats::Summarize(silicone);
  const stats::Summary buna_summary = stats::Summarize(buna_n);
  EXPECT_NEAR(silicone_summary.mean, 237.0, 1.0);
  EXPECT_NEAR(silicone_summary.stddev, 11.0, 0.55);
  EXPECT_NEAR(buna_summary.mean, 810.0, 10.0);
  EXPECT_NEAR(buna_summary.stddev, 132.0, 6.6);
  options.seed = 1;
  auto other = MonteCarloDraws(calibration, options);
  ASSERT_TRUE(other.ok());
  EXPECT_NE((*other)[0].silicone_n_per_m, (*first)[0].silicone_n_per_m);
}

// Each draw has its own stream seeded by its index: the draws of a short run are the first
// of a long one, and no two draws repeat (the report's shards rely on it).
TEST(MonteCarloDraws, EachDrawIsSeededByItsIndex) {
  const Calibration calibration = Laika2018();
  MonteCarloOptions options;
  options.samples = 3;
  auto few = MonteCarloDraws(calibration, options);
  options.samples = 50;
  auto many = MonteCarloDraws(calibration, options);
  ASSERT_TRUE(few.ok() && many.ok());
  for (size_t i = 0; i < few->size(); ++i) {
    EXPECT_EQ((*few)[i].name, (*many)[i].name);
    EXPECT_EQ((*few)[i].silicone_n_per_m, (*many)[i].silicone_n_per_m) << i;
    EXPECT_EQ((*few)[i].buna_n_n_per_m, (*many)[i].buna_n_n_per_m) << i;
  }
  for (size_t i = 1; i < many->size(); ++i) {
    EXPECT_NE((*many)[i].silicone_n_per_m, (*many)[i - 1].silicone_n_per_m) << i;
    EXPECT_NE((*many)[i].buna_n_n_per_m, (*many)[i - 1].buna_n_n_per_m) << i;
  }
}

TEST(MonteCarlo, SimulatedSpreadGrowsWithTheStandardDeviations) {
  const Calibration calibration = Laika2018();
  const sim::ModelDescription model = Laika();
  const sim::SweepOptions sweep = ShortSweep({Foot::kC});
  auto spread = [&](double scale) {
    MonteCarloOptions options;
    options.samples = 8;
    options.stddev_scale = scale;
    auto draws = MonteCarloDraws(calibration, options);
    EXPECT_TRUE(draws.ok());
    auto samples = SimulateTensions(model, sweep, *draws);
    EXPECT_TRUE(samples.ok()) << samples.status().ToString();
    const std::vector<FootDistribution> feet = Distributions(*samples);
    EXPECT_EQ(feet.size(), 1u);
    return feet.empty() ? stats::Summary{} : feet[0].summary;
  };
  const stats::Summary narrow = spread(0.25);
  const stats::Summary wide = spread(1.0);
  EXPECT_GE(narrow.n, 6);
  EXPECT_GE(wide.n, 6);
  EXPECT_GT(narrow.stddev, 0.0);
  EXPECT_GT(wide.stddev, 1.5 * narrow.stddev);
  // the same seed draws the same samples
  EXPECT_EQ(spread(1.0).mean, wide.mean);
}

TEST(TensionSamples, RoundTripThroughJson) {
  TensionSample sample;
  sample.tension = {"sigma=+0.25", 0.25, 239.75, 842.75, 187.0};
  sample.liftoff_rad[1] = 0.4321;
  auto back = TensionSamplesFromJson(TensionSamplesToJson({sample}), "cache.json");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  ASSERT_EQ(back->size(), 1u);
  EXPECT_EQ((*back)[0].tension.name, "sigma=+0.25");
  EXPECT_EQ((*back)[0].tension.buna_n_n_per_m, 842.75);
  EXPECT_FALSE((*back)[0].liftoff_rad[0].has_value());
  EXPECT_EQ((*back)[0].liftoff_rad[1], 0.4321);
  auto bad = TensionSamplesFromJson({{"samples", {{{"name", "x"}}}}}, "cache.json");
  EXPECT_THAT(bad.status().message(), HasSubstr("cache.json"));
}

}  // namespace
}  // namespace liftoff::fit
