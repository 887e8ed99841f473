// `liftoff sim`: the simulated foot-lifting test (one run, with its height curves), the
// tension sweep (the simulation columns of the paper's Table IV, as the results JSON the
// table command reads), and the MJCF export. Same shape as commands.h: apps/liftoff/main.cc
// maps flags onto these structs; each Run function writes results to `out`, progress and
// diagnostics to `err`, and returns the process exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>

#include "liftoff/cli/commands.h"
#include "liftoff/core/status.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/sweep.h"
#include "liftoff/stats/sim_results.h"

namespace liftoff::cli {

/// The model and the experiment's overrides, shared by `sim run`, `sim sweep` and
/// `sim export-mjcf`. Unset (nullopt / empty) fields keep ExperimentOptions' defaults (the
/// paper's procedure) or the model file's settings. Units are those of the flag names.
struct SimExperimentChoice {
  /// Model file (docs/sim.md); empty: sim::DefaultModelPath(), the bundled Laika.
  std::filesystem::path model_path;

  // the motion (default: sim::MotionFor(foot))
  /// "HR" or "HL".
  std::optional<std::string> pulled;
  /// "+" or "-".
  std::optional<std::string> rotation;

  // the timeline
  /// Bend: each pulled cable to this fraction of its rest length (0 < P <= 1).
  std::optional<double> bend_fraction;
  std::optional<double> bend_start_s;
  /// Rest-length shortening speed, m/s.
  std::optional<double> bend_speed_m_per_s;
  /// Ramp: final |angle|, degrees (0 .. 180); duration and start, s.
  std::optional<double> ramp_deg;
  std::optional<double> ramp_s;
  std::optional<double> ramp_start_s;
  /// Drop height above the standing pose, m.
  std::optional<double> drop_height_m;

  // the liftoff rule
  std::optional<double> reference_s;
  std::optional<double> threshold_mm;
  std::optional<double> sample_period_s;
  std::optional<double> ground_clearance_mm;
  /// Stop once the first foot lifted and |angle| went this far past it, rad.
  std::optional<double> stop_after_rad;

  // the model and the engine
  /// Cable damping, N*s/m.
  std::optional<double> damping_n_s_per_m;
  /// "TOP,BOTTOM,SADDLE,SIDE": T0 / k of each group, m.
  std::string pretension_ratios;
  std::optional<double> friction;
  /// Friction of non-foot geometry with the ground (with --collisions ground or all).
  std::optional<double> spine_friction;
  /// Foot markers this far above the feet's bottoms, m.
  std::optional<double> marker_height_m;
  /// "node" or "surface".
  std::string attachment;
  /// "attachment" or "node".
  std::string rest_reference;
  /// "feet" (only the feet touch anything), "ground" (spine and hips with the ground too),
  /// "self" (spine rods with each other), "all"; empty: the model file's.
  std::string collisions;
  /// "on" or "off".
  std::string damping_cap;
  /// Engine time step, s.
  std::optional<double> dt_s;
  bool implicit_stiffness = false;
  std::optional<int> solver_iterations;
  std::optional<double> contact_bias;

  /// Progress on stderr: "auto" (live on a terminal, else lines), "live", "lines", "off".
  std::string progress = "auto";
};

/// The experiment options the choice asks for (foot and tension point left at their
/// defaults). kInvalidArgument naming the flag: "--threshold-mm: expected a number in
/// (0, 1000], got 0".
Result<sim::ExperimentOptions> ExperimentOptionsFrom(const SimExperimentChoice& choice);

/// The model file the choice names: its model_path, else sim::DefaultModelPath().
std::filesystem::path ModelPathFrom(const SimExperimentChoice& choice);

/// The flags of `choice` that differ from the defaults, as a command line would give them
/// ("--friction 0.25 --attachment node"); empty when none.
std::string DescribeOverrides(const SimExperimentChoice& choice);

/// `liftoff sim run`: one experiment.
struct SimRunCommand {
  SimExperimentChoice experiment;
  /// Foot the test targets: "A".."D".
  std::string foot = "A";
  /// Tension point: a name ("low", "med-low", "mean", "med-high", "high") or "0".."4".
  std::string tension = "high";
  /// Explicit stiffnesses "SILICONE,BUNA_N,SPRING", N/m (wins over `tension`).
  std::string stiffness;
  /// The outcome as JSON ("liftoff-sim-run", docs/sim.md) instead of text.
  bool json = false;
  /// Write the foot-height curves (CSV, sim::HeightCurvesCsv) here; "-": to `out`
  /// instead of the outcome.
  std::filesystem::path curves_path;
};
int RunSimRun(const SimRunCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff sim sweep`: the tension points x the feet, in parallel.
struct SimSweepCommand {
  SimExperimentChoice experiment;
  /// Feet, comma-separated ("A,B,C,D").
  std::string feet = "A,B,C,D";
  /// Tension points, comma-separated names or indices, or "all".
  std::string tensions = "all";
  /// Worker threads; 0: all cores.
  int threads = 0;
  /// Run every experiment to the end of the ramp (default: stop once the targeted foot's
  /// outcome is settled; the values are the same).
  bool full_ramp = false;
  /// Simulation results JSON ("liftoff-sim-results", docs/formats.md) to write.
  std::filesystem::path output_path;
  /// Print that JSON on `out` instead of the text tables.
  bool json = false;
  /// Hardware trials (manifest, or a 2018 Laika folder): also print the hardware-vs-
  /// simulation table (the table command's per-foot table) in `format`.
  std::filesystem::path hardware_path;
  std::string format = "md";
  CalibrationChoice calibration;
  LookupChoice lookup;
};
int RunSimSweep(const SimSweepCommand& command, std::ostream& out, std::ostream& err);

/// The sweep options `command` asks for (feet, tensions, threads, full ramp and the
/// experiment); kInvalidArgument naming the flag.
Result<sim::SweepOptions> SweepOptionsFrom(const SimSweepCommand& command);
/// Runs the sweep `command` asks for with its progress display on `err`, then a line with
/// the run count and wall time. Only the sweep's fields of `command` are used.
Result<sim::SweepResult> RunSweepShowingProgress(const SimSweepCommand& command,
                                                 std::ostream& err);

/// `liftoff sim export-mjcf -o FILE.xml`: the model as MuJoCo MJCF (sim/mjcf.h). The
/// file's time step is MjcfOptions' default unless the experiment's --dt is given (its
/// contact and hinge time constants are then raised to at least two steps, MuJoCo's floor).
struct SimExportMjcfCommand {
  SimExperimentChoice experiment;
  /// The experiment's model at this foot's motion and tension point (as `sim run` builds
  /// it), unless `as_is`.
  std::string foot = "A";
  std::string tension = "high";
  /// Export the model file exactly as written (its own stiffnesses and pretensions).
  bool as_is = false;
  /// "equality" (a constraint a runner sets each step) or "actuator" (a position servo,
  /// for MuJoCo's simulate slider).
  std::string hinge_drive = "equality";
  /// Free bodies raised by this much, m (the drop height makes the file start the drop).
  double lift_m = 0.0;
  /// Output file; "-": `out`.
  std::filesystem::path output_path;
};
int RunSimExportMjcf(const SimExportMjcfCommand& command, std::ostream& out, std::ostream& err);

/// The sweep as simulation results (what the table command reads): one run per sweep run,
/// in order, with its foot, tension point, motion, |liftoff rotation| and whether the
/// robot stood (notes: the run's Brief()). A run where the robot stood but the targeted
/// foot never lifted has no value the format can hold (a standing run needs liftoff_rad):
/// it is left out and named in the description. `description` starts the description.
stats::SimResults SimResultsFromSweep(const sim::SweepResult& sweep, std::string description);

}  // namespace liftoff::cli
