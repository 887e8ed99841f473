// `liftoff sim`: the simulated foot-lifting test (one run, with its height curves), the
// tension sweep (the simulation columns of the paper's Table IV, as the results JSON the
// table command reads), and the MJCF export. Same shape as commands.h: an Add function binds
// flags to each struct; each Run function writes results to `out`, progress and
// diagnostics to `err`, and returns the process exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/cli/commands.h"
#include "liftoff/cli/flags.h"
#include "liftoff/core/status.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/mjcf.h"
#include "liftoff/sim/sweep.h"
#include "liftoff/stats/sim_results.h"

namespace liftoff::cli {

/// The model and the experiment's options, shared by `sim run`, `sim sweep` and
/// `sim export-mjcf`. Each option is a field of sim::ExperimentOptions, bound to its flag
/// by one line of ExperimentFlags(); unset optionals keep the model file's settings.
struct SimExperimentChoice {
  /// Model file (docs/sim.md); empty: sim::DefaultModelPath(), the bundled Laika.
  std::filesystem::path model_path;
  /// The experiment as the flags set it (defaults: the paper's procedure); the foot and
  /// the tension point are each command's own flags.
  sim::ExperimentOptions options;
  /// Progress on stderr: "auto" (live on a terminal, else lines), "live", "lines", "off".
  std::string progress = "auto";
};

/// The experiment's flags, one per field of sim::ExperimentOptions (units those of the
/// flag names: --ramp-deg sets ramp_angle_rad).
const std::vector<FieldFlag<sim::ExperimentOptions>>& ExperimentFlags();

/// Adds --model, ExperimentFlags() and --progress to `app`, bound to `choice`.
void AddExperimentFlags(Command& app, SimExperimentChoice& choice);

/// The choice's experiment options once Validate() accepts them; kInvalidArgument naming
/// the flag otherwise: "--ramp-s: expected a number in (0, 3600], got 0".
Result<sim::ExperimentOptions> ExperimentOptionsFrom(const SimExperimentChoice& choice);

/// The model file the choice names: its model_path, else sim::DefaultModelPath().
std::filesystem::path ModelPathFrom(const SimExperimentChoice& choice);

/// The flags of `choice` that differ from the defaults, as a command line would give them
/// ("--model m.json --friction 0.25 --attachment node"); empty when none.
std::string DescribeOverrides(const SimExperimentChoice& choice);

/// `liftoff sim run`: one experiment.
struct SimRunCommand {
  SimExperimentChoice experiment;
  /// Foot the test targets: "A".."D".
  std::string foot = "A";
  /// Tension point: a name ("low", "med-low", "mean", "med-high", "high") or "0".."4".
  std::string tension = "high";
  /// Explicit stiffnesses SILICONE, BUNA_N, SPRING, N/m (wins over `tension`); empty:
  /// the tension point's.
  std::vector<double> stiffness_n_per_m;
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
  /// Feet ("A".."D").
  std::vector<std::string> feet = {"A", "B", "C", "D"};
  /// Tension points: names or indices, or {"all"}.
  std::vector<std::string> tensions = {"all"};
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
  /// The file's options as the flags set them (MjcfFlags()); its time step and time
  /// constants are replaced as said above.
  sim::MjcfOptions mjcf;
  /// Output file; "-": `out`.
  std::filesystem::path output_path;
};
/// The export's flags (--hinge-drive, --lift-m), one per field of sim::MjcfOptions.
const std::vector<FieldFlag<sim::MjcfOptions>>& MjcfFlags();
int RunSimExportMjcf(const SimExportMjcfCommand& command, std::ostream& out, std::ostream& err);

/// The sweep as simulation results (what the table command reads): one run per sweep run,
/// in order, with its foot, tension point, motion, |liftoff rotation| and whether the
/// robot stood (notes: the run's Brief()). A run where the robot stood but the targeted
/// foot never lifted has no value the format can hold (a standing run needs liftoff_rad):
/// it is left out and named in the description. `description` starts the description.
stats::SimResults SimResultsFromSweep(const sim::SweepResult& sweep, std::string description);

/// The three subcommands of `liftoff sim`, added to the `sim` command: flags bound to
/// their command structs.
Subcommand AddSimRunCommand(Command& sim);
Subcommand AddSimSweepCommand(Command& sim);
Subcommand AddSimExportMjcfCommand(Command& sim);
/// --feet, --tensions and --threads of the sweep (`sim sweep`, `report`).
void AddSweepFlags(Command& app, SimSweepCommand& command);

}  // namespace liftoff::cli
