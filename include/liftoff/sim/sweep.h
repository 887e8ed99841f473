// The tension sweep: the paper's five tension points (Table III) x the four foot motions
// (MotionFor), every run a full experiment (RunExperiment's procedure), run in parallel on
// a work queue of std::threads. Each run is a pure function of (model, options): the
// results come back in a fixed order (foot-major: A low, A med-low, ..., D high) and are
// bit-identical whatever the number of threads.
//
//   LIFTOFF_ASSIGN_OR_RETURN(ModelDescription model, LoadModelDescription(DefaultModelPath()));
//   SweepOptions options;                      // the paper's 20 runs, all cores
//   LIFTOFF_ASSIGN_OR_RETURN(SweepResult sweep, RunSweep(model, options, nullptr));
//   for (const SweepRun& run : sweep.runs) std::cout << run.Brief() << '\n';
//   for (const SweepFootRange& range : sweep.Ranges()) ...   // Table IV's sim columns
//
// The results file the table command reads (stats::SimResults, "liftoff-sim-results")
// is made from a SweepResult in the CLI layer (liftoff/cli/sim_commands.h), since sim and
// stats are siblings.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {

// ---------------------------------------------------------------------------------------
// the sweep

struct SweepOptions {
  /// Options of every run. Its foot, tension_point_index and tension_point are replaced
  /// per run; everything else (timeline, liftoff rule, model and engine choices) applies
  /// to every run. pulled_group and rotation, when set, also apply to every run (each
  /// foot's motion is MotionFor(foot) otherwise).
  ExperimentOptions base;
  /// Tension points to run, in result order. Default: PaperTensionPoints(), low .. high.
  std::vector<TensionPoint> tension_points;
  /// Feet (foot motions) to run, in result order. Default: A, B, C, D.
  std::vector<Foot> feet = {Foot::kA, Foot::kB, Foot::kC, Foot::kD};
  /// Worker threads (>= 0; 0: std::thread::hardware_concurrency(), at least 1). Never
  /// more than there are runs.
  int threads = 0;
  /// Each run stops once its targeted foot's outcome is settled (RunControl); the values
  /// the sweep reports are the same as with full runs. false: every run goes to the end
  /// of the ramp.
  bool stop_once_decided = true;
  /// Intermediate progress of each run every this much simulated time, s (> 0).
  double progress_period_s = 0.5;

  SweepOptions();
  /// kInvalidArgument naming the field: no feet or tension points, a repeated foot or
  /// tension point name, negative threads, bad base options.
  Status Validate() const;
};

/// One run of the sweep.
struct SweepRun {
  /// Index of the run in SweepResult::runs (foot-major order).
  int index = 0;
  /// The foot the run targets and its tension point (index into
  /// SweepOptions::tension_points, and the point itself).
  Foot foot = Foot::kA;
  int tension_index = 0;
  TensionPoint tension_point;
  /// The whole experiment's outcome (curves included, up to where the run stopped).
  ExperimentResult result;

  /// Whether the robot stood (status is neither kDidNotStand nor kDiverged).
  bool Stood() const;
  /// The targeted foot's absolute liftoff rotation, rad, when the robot stood and that
  /// foot lifted.
  std::optional<double> LiftoffRad() const;
  /// The result's Brief().
  std::string Brief() const;
};

/// The simulated range of one foot over the sweep's tension points (Table IV's sim
/// columns).
struct SweepFootRange {
  Foot foot = Foot::kA;
  /// Runs of this foot, and those where the robot stood and the foot lifted.
  int runs = 0;
  int counted_runs = 0;
  /// Runs of this foot whose engine diverged (left out of the range, reported apart).
  int diverged_runs = 0;
  /// Smallest and largest liftoff rotation over the counted runs, rad (0 when none).
  double min_rad = 0.0;
  double max_rad = 0.0;
};

struct SweepResult {
  /// The model's name (ModelDescription::name).
  std::string model_name;
  /// Tension points and feet, as run (the options' order).
  std::vector<TensionPoint> tension_points;
  std::vector<Foot> feet;
  /// feet.size() x tension_points.size() runs, foot-major: runs[f * tension_points.size()
  /// + t] is feet[f] at tension_points[t].
  std::vector<SweepRun> runs;
  /// Worker threads used (the only field that depends on the machine).
  int threads = 1;

  /// The run of `foot` at the tension point named `tension`, or nullptr.
  const SweepRun* Find(Foot foot, std::string_view tension) const;
  /// One range per foot of `feet`, in that order.
  std::vector<SweepFootRange> Ranges() const;
  /// "laika-ntrt: 20 runs (18 stood), A 0.412-0.452, B ..., 2 threads".
  std::string Brief() const;
};

/// What the sweep reports while it runs. Calls are serialised (never two at once) but
/// come from the worker threads; keep them short.
struct SweepProgress {
  /// Runs finished so far (counting this one when `finished`), and in all.
  int runs_done = 0;
  int runs_total = 0;
  /// The run this report is about.
  int run_index = 0;
  Foot foot = Foot::kA;
  const TensionPoint* tension_point = nullptr;
  /// Where the run has got to (its last report when finished).
  RunProgress run;
  /// The finished run (its result is final), or nullptr for an intermediate report.
  const SweepRun* finished = nullptr;
};
using SweepProgressCallback = std::function<void(const SweepProgress& progress)>;

/// Runs the sweep. kInvalidArgument for bad options or a model that does not fit them
/// (checked for every run before any starts). A run where the robot does not stand is a
/// result, not an error. `progress` may be empty.
Result<SweepResult> RunSweep(const ModelDescription& description, const SweepOptions& options,
                             const SweepProgressCallback& progress);

/// The paper's tension point named `name` ("low", "med-low", "mean", "med-high", "high"),
/// or given by its index "0".."4"; kInvalidArgument listing the names otherwise.
Result<TensionPoint> PaperTensionPointByName(std::string_view name);

}  // namespace liftoff::sim
