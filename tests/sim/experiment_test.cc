#include "liftoff/sim/experiment.h"

#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "liftoff/core/robot.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {
namespace {

constexpr double kPi = std::numbers::pi;

ModelDescription Laika() {
  Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  EXPECT_TRUE(description.ok()) << description.status().ToString();
  return description.ok() ? *description : ModelDescription{};
}

TEST(Experiment, ProcedureFollowsThePaperTimeline) {
  const ModelDescription description = Laika();
  ExperimentOptions options;  // foot A: HR pulled, + rotation
  const Result<Model> model = BuildExperimentModel(description, options);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  const Procedure procedure(*model, options);
  EXPECT_EQ(procedure.step_count(), 9200);  // 46 s in 0.005 s steps
  EXPECT_TRUE(procedure.IsSampleStep(2));   // 0.01 s
  EXPECT_FALSE(procedure.IsSampleStep(3));

  std::vector<double> rest(model->cables.size());
  const std::vector<int> pulled = model->CablesInGroup("HR");
  ASSERT_EQ(procedure.pulled_cables(), pulled);
  const int first = pulled[0];
  const double initial = model->cables[static_cast<size_t>(first)].rest_length_m;
  procedure.RestLengthsAt(1.0, rest);
  EXPECT_EQ(rest[static_cast<size_t>(first)], initial);
  procedure.RestLengthsAt(2.4, rest);  // 0.4 s at 0.025 m/s: 0.01 m shorter
  EXPECT_NEAR(rest[static_cast<size_t>(first)], initial - 0.01, 1e-12);
  procedure.RestLengthsAt(5.0, rest);  // long since at 80 %
  EXPECT_NEAR(rest[static_cast<size_t>(first)], 0.8 * initial, 1e-15);
  const int unpulled = model->CablesInGroup("HL")[0];
  EXPECT_EQ(rest[static_cast<size_t>(unpulled)],
            model->cables[static_cast<size_t>(unpulled)].rest_length_m);

  // theta = (t'/40)(pi/3) from 6 s, held after 46 s
  EXPECT_EQ(procedure.HingeAngleAt(5.99), 0.0);
  EXPECT_NEAR(procedure.HingeAngleAt(26.0), kPi / 6.0, 1e-15);
  EXPECT_NEAR(procedure.HingeAngleAt(46.0), kPi / 3.0, 1e-15);
  EXPECT_NEAR(procedure.HingeAngleAt(50.0), kPi / 3.0, 1e-15);
  options.rotation = RotationSense::kNegative;
  EXPECT_NEAR(Procedure(*model, options).HingeAngleAt(26.0), -kPi / 6.0, 1e-15);
}

TEST(Experiment, TensionPointSetsStiffnessesAndPretensions) {
  const ModelDescription description = Laika();
  ExperimentOptions options;
  options.foot = Foot::kB;  // HL pulled
  options.tension_point_index = 4;
  const Result<Model> model = BuildExperimentModel(description, options);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  auto group = [&](const char* name) {
    return model->cable_groups[static_cast<size_t>(model->CableGroupIndex(name))];
  };
  EXPECT_EQ(group("HB").stiffness_n_per_m, 1073.0);
  EXPECT_NEAR(group("HB").pretension_n, 0.015 * 1073.0, 1e-12);
  EXPECT_EQ(group("HT").stiffness_n_per_m, 258.0);
  EXPECT_NEAR(group("SBL").pretension_n, 0.052 * 258.0, 1e-12);
  EXPECT_EQ(group("HL").stiffness_n_per_m, 187.0);  // the pulled side is the spring
  EXPECT_EQ(group("HR").stiffness_n_per_m, 258.0);
  EXPECT_NEAR(group("HL").pretension_n, 0.004 * 258.0, 1e-12);  // same T0 on both sides
  EXPECT_NEAR(group("HR").pretension_n, 0.004 * 258.0, 1e-12);
  for (const Cable& cable : model->cables) EXPECT_EQ(cable.damping_n_s_per_m, 10.0);
}

Sample FlatSample(double t_s, double angle_rad) {
  Sample sample;
  sample.time_s = t_s;
  sample.hinge_angle_rad = angle_rad;
  sample.foot_marker_height_m = {0.0, 0.0, 0.0, 0.0};
  sample.lowest_body_point_m = 0.08;
  sample.lowest_body_origin_m = 0.19;
  sample.highest_foot_center_m = 0.0125;
  return sample;
}

TEST(Experiment, RecorderAppliesTheOneMillimetreRule) {
  // foot C rises linearly from t = 20.005 s at 1 mm per second over its height at 5 s: it
  // is more than 1 mm up first at t = 21.01 s; foot A reaches only 0.9 mm
  ExperimentOptions options;
  options.foot = Foot::kC;
  const Model model;
  LiftoffRecorder recorder(model, options);
  for (int k = 1; k <= 2400; ++k) {
    const double t = 0.01 * k;
    const double angle = -std::max(0.0, t - 6.0) / 40.0 * kPi / 3.0;
    Sample sample = FlatSample(t, angle);
    sample.foot_marker_height_m[0] = 0.0125 + (t > 10.0 ? 0.0009 : 0.0);
    sample.foot_marker_height_m[2] = 0.0125 + (t > 20.005 ? 0.001 * (t - 20.005) : 0.0);
    recorder.Add(sample);
  }
  const ExperimentResult result = recorder.Finish();
  EXPECT_EQ(result.status, RunStatus::kLifted);
  ASSERT_TRUE(result.first_foot.has_value());
  EXPECT_EQ(*result.first_foot, Foot::kC);
  EXPECT_TRUE(result.feet[2].lifted);
  EXPECT_NEAR(result.feet[2].time_s, 21.01, 1e-9);
  EXPECT_NEAR(result.feet[2].rotation_rad, (21.01 - 6.0) / 40.0 * kPi / 3.0, 1e-12);
  EXPECT_FALSE(result.feet[0].lifted);
  ASSERT_TRUE(result.TargetLiftoffRad().has_value());
  EXPECT_NEAR(*result.TargetLiftoffRad(), result.feet[2].rotation_rad, 0.0);
  EXPECT_NEAR(result.reference_height_m[2], 0.0125, 0.0);
  // the curves start at the ramp, |rotation| strictly increasing, heights relative
  ASSERT_FALSE(result.curve.empty());
  EXPECT_NEAR(result.curve.front().time_s, 6.0, 1e-9);
  for (size_t i = 1; i < result.curve.size(); ++i) {
    EXPECT_GT(std::abs(result.curve[i].rotation_rad), std::abs(result.curve[i - 1].rotation_rad));
  }
  EXPECT_NEAR(result.curve.back().height_m[2], 0.003995, 1e-9);
}

TEST(Experiment, RecorderReportsARobotThatDoesNotStand) {
  ExperimentOptions options;
  const Model model;
  LiftoffRecorder recorder(model, options);
  for (int k = 1; k <= 2000; ++k) {
    const double t = 0.01 * k;
    Sample sample = FlatSample(t, std::max(0.0, t - 6.0) / 40.0 * kPi / 3.0);
    sample.lowest_body_point_m = t > 12.005 ? 0.0005 : 0.02;  // the spine sags onto the ground
    sample.foot_marker_height_m[0] = t > 15.0 ? 0.01 : 0.0;
    recorder.Add(sample);
  }
  const ExperimentResult result = recorder.Finish();
  EXPECT_EQ(result.status, RunStatus::kDidNotStand);
  EXPECT_NE(result.not_standing_reason.find("on the ground at t 12.01 s"), std::string::npos)
      << result.not_standing_reason;
  EXPECT_FALSE(result.TargetLiftoffRad().has_value());
  EXPECT_NE(result.Brief().find("did not stand"), std::string::npos);
}

TEST(Experiment, HeightCurvesCsvHasTheColumnsSynthReads) {
  ExperimentResult result;
  result.status = RunStatus::kLifted;
  result.curve = {{6.0, 0.0, {0, 0, 0, 0}}, {6.01, -0.00026, {0.0, 0.0, 0.0001, 0.0}}};
  std::istringstream csv(HeightCurvesCsv(result));
  std::string line;
  std::vector<std::string> data;
  while (std::getline(csv, line)) {
    if (!line.empty() && line[0] != '#') data.push_back(line);
  }
  ASSERT_EQ(data.size(), 3u);
  EXPECT_EQ(data[0], "time_s,rotation_rad,A_height_m,B_height_m,C_height_m,D_height_m");
  EXPECT_EQ(data[2], "6.010,-0.000260,0.0000000,0.0000000,0.0001000,0.0000000");
}

// The four combinations at the high tension point, run once for the tests below.
const std::map<Foot, ExperimentResult>& FourMotions() {
  static const std::map<Foot, ExperimentResult> results = [] {
    std::map<Foot, ExperimentResult> runs;
    const ModelDescription description = Laika();
    for (Foot foot : kAllFeet) {
      ExperimentOptions options;
      options.foot = foot;
      options.tension_point_index = 4;
      options.stop_after_liftoff_rad = 0.0;
      Result<ExperimentResult> result = RunExperiment(description, options);
      EXPECT_TRUE(result.ok()) << result.status().ToString();
      if (result.ok()) runs[foot] = *result;
    }
    return runs;
  }();
  return results;
}

TEST(Experiment, EachMotionLiftsItsFootFirst) {
  for (Foot foot : kAllFeet) {
    ASSERT_EQ(FourMotions().count(foot), 1u);
    const ExperimentResult& result = FourMotions().at(foot);
    EXPECT_EQ(result.status, RunStatus::kLifted) << result.Brief();
    ASSERT_TRUE(result.first_foot.has_value()) << result.Brief();
    EXPECT_EQ(*result.first_foot, foot) << result.Brief();
    // in the paper's simulated range (Table IV: 0.25 .. 0.47 rad over all feet)
    ASSERT_TRUE(result.TargetLiftoffRad().has_value());
    EXPECT_GT(*result.TargetLiftoffRad(), 0.25) << result.Brief();
    EXPECT_LT(*result.TargetLiftoffRad(), 0.50) << result.Brief();
  }
}

TEST(Experiment, BackFeetLiftWithLessRotationThanTheirFrontCounterparts) {
  // the paper, section V.B: C versus B and D versus A
  auto liftoff = [](Foot foot) { return FourMotions().at(foot).TargetLiftoffRad().value_or(0); };
  EXPECT_LT(liftoff(Foot::kC), liftoff(Foot::kB));
  EXPECT_LT(liftoff(Foot::kD), liftoff(Foot::kA));
}

TEST(Experiment, MotionsFollowTheSourceModelsAssignment) {
  // the source model pulled HR for A and C, HL for B and D, and turned A and D one way,
  // B and C the other: a twist raises a diagonal pair, the bend picks the foot
  EXPECT_EQ(MotionFor(Foot::kA).pulled_group, CableGroup::kHR);
  EXPECT_EQ(MotionFor(Foot::kC).pulled_group, CableGroup::kHR);
  EXPECT_EQ(MotionFor(Foot::kB).pulled_group, CableGroup::kHL);
  EXPECT_EQ(MotionFor(Foot::kD).pulled_group, CableGroup::kHL);
  EXPECT_EQ(MotionFor(Foot::kA).rotation, MotionFor(Foot::kD).rotation);
  EXPECT_EQ(MotionFor(Foot::kB).rotation, MotionFor(Foot::kC).rotation);
  EXPECT_NE(MotionFor(Foot::kA).rotation, MotionFor(Foot::kB).rotation);
  // the paper's Table II read by letter (core) agrees for A only
  EXPECT_EQ(MotionFor(Foot::kA).pulled_group, PaperTableTwoMotion(Foot::kA).pulled_group);
  EXPECT_EQ(MotionFor(Foot::kA).rotation, PaperTableTwoMotion(Foot::kA).rotation);
}

TEST(Experiment, TheOtherSenseLiftsTheOtherDiagonal) {
  // HR with the opposite sense lifts C (not A): the twist picks the diagonal
  ExperimentOptions options;
  options.foot = Foot::kA;
  options.rotation = RotationSense::kNegative;
  options.stop_after_liftoff_rad = 0.0;
  const Result<ExperimentResult> result = RunExperiment(Laika(), options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  ASSERT_TRUE(result->first_foot.has_value());
  EXPECT_EQ(*result->first_foot, Foot::kC);
}

TEST(Experiment, LiftoffDoesNotDependOnTheTimeStep) {
  // halving the step moves the answer by less than one sample of the ramp (0.00026 rad)
  std::vector<double> values;
  for (double dt : {0.005, 0.0025}) {
    ExperimentOptions options;
    options.foot = Foot::kD;
    options.engine.time_step_s = dt;
    options.stop_after_liftoff_rad = 0.0;
    const Result<ExperimentResult> result = RunExperiment(Laika(), options);
    ASSERT_TRUE(result.ok()) << result.status().ToString();
    ASSERT_TRUE(result->TargetLiftoffRad().has_value()) << result->Brief();
    values.push_back(*result->TargetLiftoffRad());
  }
  EXPECT_NEAR(values[0], values[1], 0.0003);
}

TEST(Experiment, LowTensionRobotWithoutSpineCollisionsDoesNotStand) {
  ExperimentOptions options;
  options.tension_point_index = 0;
  options.spine_ground_collisions = false;
  options.spine_self_collisions = false;
  options.ramp_duration_s = 4.0;  // the verdict comes at the reference time; keep it short
  const Result<ExperimentResult> result = RunExperiment(Laika(), options);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_EQ(result->status, RunStatus::kDidNotStand) << result->Brief();
  EXPECT_LT(result->reference_body_point_m, 0.0);
}

TEST(Experiment, RunsAreDeterministic) {
  ExperimentOptions options;
  options.foot = Foot::kB;
  options.tension_point_index = 2;
  options.stop_after_liftoff_rad = 0.0;
  const Result<ExperimentResult> first = RunExperiment(Laika(), options);
  const Result<ExperimentResult> second = RunExperiment(Laika(), options);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(HeightCurvesCsv(*first), HeightCurvesCsv(*second));
  EXPECT_EQ(first->feet[1].rotation_rad, second->feet[1].rotation_rad);
}

TEST(Experiment, OptionsValidateNameTheField) {
  ExperimentOptions options;
  EXPECT_TRUE(options.Validate().ok()) << options.Validate().ToString();
  options.bend_fraction = 1.5;
  EXPECT_NE(options.Validate().message().find("bend_fraction"), std::string::npos);
  options = ExperimentOptions{};
  options.tension_point_index = 7;
  EXPECT_NE(options.Validate().message().find("tension_point_index"), std::string::npos);
  options = ExperimentOptions{};
  options.sample_period_s = 0.0123;
  EXPECT_NE(options.Validate().message().find("sample_period_s"), std::string::npos);
  options = ExperimentOptions{};
  options.pulled_group = CableGroup::kHT;
  EXPECT_NE(options.Validate().message().find("pulled_group"), std::string::npos);
  options = ExperimentOptions{};
  options.engine.time_step_s = 1.0;
  EXPECT_NE(options.Validate().message().find("engine: time_step_s"), std::string::npos);
  // a model without the groups the experiment needs
  ModelDescription description = Laika();
  description.cable_groups[0].name = "XX";
  for (CableDescription& cable : description.cables) {
    if (cable.group == "HT") cable.group = "XX";
  }
  EXPECT_NE(BuildExperimentModel(description, ExperimentOptions{})
                .status()
                .message()
                .find("no group \"HT\""),
            std::string::npos);
}

TEST(Experiment, PaperTensionPointsMatchTableThree) {
  const auto& points = PaperTensionPoints();
  EXPECT_EQ(points[0].silicone_n_per_m, 216.0);
  EXPECT_EQ(points[4].silicone_n_per_m, 258.0);
  EXPECT_EQ(points[0].buna_n_n_per_m, 547.0);
  EXPECT_EQ(points[4].buna_n_n_per_m, 1073.0);
  for (const TensionPoint& point : points) EXPECT_EQ(point.spring_n_per_m, 187.0);
}

}  // namespace
}  // namespace liftoff::sim
