// The sweep: the paper's runs in a fixed order, the same values whatever the threads, the
// early stop changing nothing it reports, robots that do not stand left out of the ranges,
// progress for every run. Runs use a shortened timeline (settle 1 s, bend from 1 s, ramp
// 60 degrees over 10 s from 2 s) to stay fast.
#include "liftoff/sim/sweep.h"

#include <atomic>
#include <map>
#include <numbers>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace liftoff::sim {
namespace {

using ::testing::HasSubstr;

ModelDescription Laika() {
  auto description = LoadModelDescription(DefaultModelPath());
  EXPECT_TRUE(description.ok()) << description.status().ToString();
  return description.value_or(ModelDescription{});
}

ExperimentOptions ShortTimeline() {
  ExperimentOptions options;
  options.bend_start_s = 1.0;
  options.reference_time_s = 1.9;
  options.ramp_start_s = 2.0;
  options.ramp_duration_s = 10.0;
  return options;
}

// A lattice far too soft to carry the robot (a quarter of the paper's low point).
TensionPoint Soft() { return {"soft", -9.0, 54.0, 137.0, 187.0}; }

// Two feet in non-alphabetical order and a standing and a sagging tension point.
SweepOptions SmallSweep() {
  SweepOptions options;
  options.base = ShortTimeline();
  options.feet = {Foot::kD, Foot::kA};
  options.tension_points = {Soft(), PaperTensionPoints()[4]};
  return options;
}

TEST(SweepOptions, DefaultToThePapersTwentyRuns) {
  const SweepOptions options;
  EXPECT_TRUE(options.Validate().ok());
  ASSERT_EQ(options.feet.size(), 4u);
  EXPECT_EQ(options.feet[0], Foot::kA);
  EXPECT_EQ(options.feet[3], Foot::kD);
  // paper Table III: silicone and Buna-N together, the spring fixed
  const std::vector<std::string> names = {"low", "med-low", "mean", "med-high", "high"};
  const std::vector<double> silicone = {216, 227, 237, 248, 258};
  const std::vector<double> buna_n = {547, 678, 810, 941, 1073};
  ASSERT_EQ(options.tension_points.size(), 5u);
  for (size_t t = 0; t < 5; ++t) {
    EXPECT_EQ(options.tension_points[t].name, names[t]);
    EXPECT_DOUBLE_EQ(options.tension_points[t].silicone_n_per_m, silicone[t]);
    EXPECT_DOUBLE_EQ(options.tension_points[t].buna_n_n_per_m, buna_n[t]);
    EXPECT_DOUBLE_EQ(options.tension_points[t].spring_n_per_m, 187.0);
  }
}

TEST(SweepOptions, ValidateNamesTheField) {
  SweepOptions twice;
  twice.feet = {Foot::kA, Foot::kB, Foot::kA};
  EXPECT_THAT(twice.Validate().message(), HasSubstr("feet/2: foot A appears twice"));
  SweepOptions none;
  none.tension_points.clear();
  EXPECT_THAT(none.Validate().message(), HasSubstr("tension_points"));
  SweepOptions same_name;
  same_name.tension_points = {PaperTensionPoints()[0], PaperTensionPoints()[0]};
  EXPECT_THAT(same_name.Validate().message(), HasSubstr("tension_points/1/name"));
  SweepOptions threads;
  threads.threads = -1;
  EXPECT_THAT(threads.Validate().message(), HasSubstr("threads"));
  SweepOptions base;
  base.base.bend_fraction = 1.5;
  EXPECT_THAT(base.Validate().message(), HasSubstr("base: bend_fraction"));
  SweepOptions period;
  period.progress_period_s = 0.0;
  EXPECT_THAT(period.Validate().message(), HasSubstr("progress_period_s"));
  EXPECT_EQ(period.Validate().code(), StatusCode::kInvalidArgument);
}

TEST(PaperTensionPointByName, AcceptsNamesAndIndices) {
  auto med_high = PaperTensionPointByName("med-high");
  ASSERT_TRUE(med_high.ok());
  EXPECT_DOUBLE_EQ(med_high->silicone_n_per_m, 248.0);
  EXPECT_DOUBLE_EQ(med_high->buna_n_n_per_m, 941.0);
  auto second = PaperTensionPointByName("2");
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(second->name, "mean");
  auto bad = PaperTensionPointByName("medium");
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.status().message(), HasSubstr("\"medium\""));
}

TEST(RunSweep, ReturnsRunsInFootMajorOrderWhateverTheThreads) {
  const ModelDescription laika = Laika();
  SweepOptions options = SmallSweep();
  options.threads = 1;
  auto one = RunSweep(laika, options, nullptr);
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  options.threads = 2;
  auto two = RunSweep(laika, options, nullptr);
  ASSERT_TRUE(two.ok()) << two.status().ToString();
  EXPECT_EQ(one->threads, 1);
  EXPECT_EQ(two->threads, 2);

  // the options' order, foot-major: D soft, D high, A soft, A high
  const std::vector<std::pair<Foot, std::string>> order = {
      {Foot::kD, "soft"}, {Foot::kD, "high"}, {Foot::kA, "soft"}, {Foot::kA, "high"}};
  ASSERT_EQ(one->runs.size(), order.size());
  ASSERT_EQ(two->runs.size(), order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    for (const SweepResult* sweep : {&*one, &*two}) {
      const SweepRun& run = sweep->runs[i];
      EXPECT_EQ(run.index, static_cast<int>(i));
      EXPECT_EQ(run.foot, order[i].first);
      EXPECT_EQ(run.tension_point.name, order[i].second);
      EXPECT_EQ(run.result.foot, order[i].first);
      EXPECT_EQ(run.result.tension_point, order[i].second);
      // each foot runs its own motion
      EXPECT_EQ(run.result.motion.pulled_group, MotionFor(order[i].first).pulled_group);
      EXPECT_EQ(run.result.motion.rotation, MotionFor(order[i].first).rotation);
    }
    // bit-identical outcomes
    const ExperimentResult& a = one->runs[i].result;
    const ExperimentResult& b = two->runs[i].result;
    EXPECT_EQ(a.status, b.status);
    EXPECT_EQ(a.steps, b.steps);
    EXPECT_EQ(a.end_time_s, b.end_time_s);
    for (size_t f = 0; f < 4; ++f) {
      EXPECT_EQ(a.feet[f].lifted, b.feet[f].lifted);
      EXPECT_EQ(a.feet[f].rotation_rad, b.feet[f].rotation_rad);
      EXPECT_EQ(a.reference_height_m[f], b.reference_height_m[f]);
    }
    ASSERT_EQ(a.curve.size(), b.curve.size());
    for (size_t p = 0; p < a.curve.size(); ++p) {
      EXPECT_EQ(a.curve[p].rotation_rad, b.curve[p].rotation_rad);
      EXPECT_EQ(a.curve[p].height_m, b.curve[p].height_m);
    }
  }
  EXPECT_EQ(one->Find(Foot::kA, "high"), &one->runs[3]);
  EXPECT_EQ(one->Find(Foot::kB, "high"), nullptr);
}

TEST(RunSweep, RobotThatDoesNotStandIsMarkedAndLeftOutOfTheRange) {
  const ModelDescription laika = Laika();
  auto sweep = RunSweep(laika, SmallSweep(), nullptr);
  ASSERT_TRUE(sweep.ok()) << sweep.status().ToString();
  for (Foot foot : {Foot::kD, Foot::kA}) {
    const SweepRun* soft = sweep->Find(foot, "soft");
    const SweepRun* high = sweep->Find(foot, "high");
    ASSERT_NE(soft, nullptr);
    ASSERT_NE(high, nullptr);
    // the soft lattice lets the spine down onto the ground: no value
    EXPECT_FALSE(soft->Stood()) << soft->Brief();
    EXPECT_EQ(soft->result.status, RunStatus::kDidNotStand);
    EXPECT_LE(soft->result.min_body_point_m, ExperimentOptions().ground_clearance_m);
    EXPECT_FALSE(soft->LiftoffRad());
    // the paper's high point stands and lifts the targeted foot first, as in the paper
    // (somewhere between 0.2 and 0.7 rad of the 1.047 rad ramp)
    EXPECT_TRUE(high->Stood()) << high->Brief();
    ASSERT_TRUE(high->LiftoffRad()) << high->Brief();
    EXPECT_EQ(high->result.first_foot, foot);
    EXPECT_GT(*high->LiftoffRad(), 0.2);
    EXPECT_LT(*high->LiftoffRad(), 0.7);
  }
  // the ranges: the sagging runs are not counted
  const std::vector<SweepFootRange> ranges = sweep->Ranges();
  ASSERT_EQ(ranges.size(), 2u);
  EXPECT_EQ(ranges[0].foot, Foot::kD);
  EXPECT_EQ(ranges[1].foot, Foot::kA);
  for (const SweepFootRange& range : ranges) {
    EXPECT_EQ(range.runs, 2);
    EXPECT_EQ(range.counted_runs, 1);
    const double high = *sweep->Find(range.foot, "high")->LiftoffRad();
    EXPECT_EQ(range.min_rad, high);
    EXPECT_EQ(range.max_rad, high);
  }
  EXPECT_THAT(sweep->Brief(), HasSubstr("4 runs (2 stood)"));
}

TEST(RunSweep, EarlyStopKeepsWhatTheFullRunsReport) {
  const ModelDescription laika = Laika();
  SweepOptions options = SmallSweep();
  options.tension_points = {PaperTensionPoints()[2], PaperTensionPoints()[4]};
  options.feet = {Foot::kC};
  auto early = RunSweep(laika, options, nullptr);
  ASSERT_TRUE(early.ok()) << early.status().ToString();
  for (const SweepRun& run : early->runs) {
    // the same run by RunExperiment (the whole timeline, no sweep machinery)
    ExperimentOptions alone = ShortTimeline();
    alone.foot = Foot::kC;
    alone.tension_point = run.tension_point;
    auto full = RunExperiment(laika, alone);
    ASSERT_TRUE(full.ok()) << full.status().ToString();
    EXPECT_EQ(full->end_time_s, 12.0);
    EXPECT_LT(run.result.end_time_s, full->end_time_s);
    EXPECT_EQ(run.result.status, full->status);
    EXPECT_EQ(run.result.first_foot, full->first_foot);
    ASSERT_TRUE(full->TargetLiftoffRad());
    EXPECT_EQ(run.LiftoffRad(), full->TargetLiftoffRad());
    EXPECT_EQ(run.result.feet[2].time_s, full->feet[2].time_s);
  }
}

TEST(RunSweep, ReportsProgressForEveryRun) {
  const ModelDescription laika = Laika();
  SweepOptions options = SmallSweep();
  options.threads = 2;
  std::atomic<int> inside{0};
  bool overlapped = false;
  std::map<int, int> finished_reports;
  std::map<int, double> last_time_s;
  std::vector<int> done_sequence;
  bool time_went_back = false;
  auto result = RunSweep(laika, options, [&](const SweepProgress& progress) {
    if (inside.fetch_add(1) != 0) overlapped = true;
    EXPECT_EQ(progress.runs_total, 4);
    ASSERT_NE(progress.tension_point, nullptr);
    if (progress.run.time_s < last_time_s[progress.run_index]) time_went_back = true;
    last_time_s[progress.run_index] = progress.run.time_s;
    if (progress.finished != nullptr) {
      ++finished_reports[progress.run_index];
      done_sequence.push_back(progress.runs_done);
      EXPECT_EQ(progress.finished->index, progress.run_index);
      EXPECT_EQ(progress.finished->foot, progress.foot);
      EXPECT_EQ(progress.run.time_s, progress.finished->result.end_time_s);
    }
    inside.fetch_sub(1);
  });
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  EXPECT_FALSE(overlapped);
  EXPECT_FALSE(time_went_back);
  ASSERT_EQ(finished_reports.size(), 4u);
  for (const auto& [index, count] : finished_reports) EXPECT_EQ(count, 1) << "run " << index;
  EXPECT_EQ(done_sequence, (std::vector<int>{1, 2, 3, 4}));
  // intermediate reports too: every run passes its reference time, 1.9 s
  for (const auto& [index, time_s] : last_time_s) EXPECT_GE(time_s, 1.9) << "run " << index;
}

TEST(RunSweep, RejectsOptionsThatDoNotFitTheModelBeforeRunning) {
  ModelDescription laika = Laika();
  laika.cable_groups.erase(laika.cable_groups.begin());  // loses HT (or whichever is first)
  int reports = 0;
  auto result = RunSweep(laika, SmallSweep(), [&](const SweepProgress&) { ++reports; });
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(), HasSubstr("run D soft"));
  EXPECT_EQ(reports, 0);
}

TEST(RunExperimentWithProgress, TakesTheSameStepsAsRunExperiment) {
  const ModelDescription laika = Laika();
  ExperimentOptions options = ShortTimeline();
  options.foot = Foot::kB;
  options.tension_point_index = 3;
  auto plain = RunExperiment(laika, options);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  std::vector<RunProgress> reports;
  RunControl control;
  control.progress_period_s = 1.0;
  auto reported = RunExperimentWithProgress(laika, options, control,
                                            [&](const RunProgress& p) { reports.push_back(p); });
  ASSERT_TRUE(reported.ok()) << reported.status().ToString();
  EXPECT_EQ(reported->Brief(), plain->Brief());
  EXPECT_EQ(reported->steps, plain->steps);
  EXPECT_EQ(reported->status, plain->status);
  for (size_t f = 0; f < 4; ++f)
    EXPECT_EQ(reported->feet[f].rotation_rad, plain->feet[f].rotation_rad);
  ASSERT_EQ(reported->curve.size(), plain->curve.size());
  for (size_t p = 0; p < plain->curve.size(); ++p) {
    EXPECT_EQ(reported->curve[p].height_m, plain->curve[p].height_m);
  }
  // a report each simulated second (1 .. 12 s) and one at the end; the angle follows
  // the ramp: 0 before 2 s, -(t - 2) / 10 * pi/3 for B after (MotionFor(B) is negative)
  ASSERT_EQ(reports.size(), 13u);
  for (size_t r = 0; r < 12; ++r) {
    EXPECT_NEAR(reports[r].time_s, static_cast<double>(r + 1), 1e-9);
    EXPECT_EQ(reports[r].end_time_s, 12.0);
  }
  EXPECT_EQ(reports[0].hinge_angle_rad, 0.0);
  EXPECT_NEAR(reports[6].hinge_angle_rad, -5.0 / 10.0 * std::numbers::pi / 3.0, 1e-9);
  EXPECT_EQ(reports.back().time_s, 12.0);
}

TEST(RunExperimentWithProgress, RejectsABadPeriod) {
  RunControl control;
  control.progress_period_s = -1.0;
  auto result = RunExperimentWithProgress(Laika(), ShortTimeline(), control, nullptr);
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(), HasSubstr("progress_period_s"));
}

}  // namespace
}  // namespace liftoff::sim
