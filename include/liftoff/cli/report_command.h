// `liftoff report MANIFEST -o DIR`: the campaign in one command. Every trial analysed as
// `liftoff table` does (a failing trial reported and left out), the simulated column from
// the tension sweep (run, or read from a cache keyed by the model file's bytes, the
// calibration and every experiment option), and in DIR: the tables (Markdown and CSV), the
// figures (gnuplot scripts with their data beside them, drawn as PNG and SVG when gnuplot
// is on the PATH), report.md and a self-contained report.html. Layout: docs/cli.md,
// "liftoff report".
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "liftoff/cli/commands.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/fit/tension_fit.h"

namespace liftoff::cli {

struct ReportCommand {
  /// Trial manifest (JSON), or a 2018 Laika folder.
  std::filesystem::path manifest_path;
  /// Folder the report is written to (created when missing); must hold none of the inputs.
  std::filesystem::path output_dir;
  CalibrationChoice calibration;
  LookupChoice lookup;
  /// The sweep of the simulated column: its experiment, feet, tensions, threads and
  /// full_ramp (its output, hardware and format fields are not used). Its
  /// experiment.progress (auto, live, lines or off) is the whole report's progress on
  /// stderr: video analysis and sweep.
  SimSweepCommand sweep;
  /// Leave the simulation out (no sweep, no Figure 7).
  bool no_sim = false;
  /// Folder of cached sweeps (<key>.json); empty: DIR/sim-cache.
  std::filesystem::path cache_dir;
  /// The calibration (with the simulation): the tension scale's grid, bootstrap and
  /// goodness-of-fit threshold, and the Monte Carlo over the spring constants (its runs are
  /// cached beside the sweep's, keyed by these options too).
  fit::FitOptions fit;
  fit::MonteCarloOptions monte_carlo;
  /// Also fit the ratio of the Buna-N and silicone stiffnesses: the tension scale's grid
  /// run again at each of ratio.ratios but 1 (cached with the grid's runs, by ratio).
  bool fit_ratio = false;
  fit::RatioFitOptions ratio;
  /// The gnuplot program (found on the PATH unless a path is given).
  std::string gnuplot = "gnuplot";
  /// Trials analysed at once (0: the machine's cores); the results are the same for any.
  int jobs = 0;
  /// "i/n": analyse only shard i of n (the trials and Monte Carlo draws k with
  /// k % n == i - 1) and write DIR/shard-i-of-n.json instead of the report. Empty: all.
  std::string shard;
  /// Shard files to merge into the report instead of analysing the trials and running the
  /// Monte Carlo (docs/cluster.md); every shard of one run, made with the same flags.
  std::vector<std::filesystem::path> merge;
};

/// Writes the report. Exit code: 0 when every trial was analysed and every file written;
/// a failing trial's class (ExitCodeFor) after the report of the others is written, as
/// `liftoff table` does; gnuplot missing or failing is a warning (data and scripts are
/// still written). With `shard`: 0 once the shard file is written (its failed trials are
/// in it; the merge exits as one run would).
int RunReport(const ReportCommand& command, std::ostream& out, std::ostream& err);

/// The command added to the command line `parent` (flags bound to its struct).
Subcommand AddReportCommand(Command& parent);

}  // namespace liftoff::cli
