// The liftoff command line, one Run<Command>() per subcommand, and one Add<Command>() that
// binds its flags to its struct (CLI11, liftoff/cli/flags.h); command_table.cc lists
// them. Tests call the Run functions directly.
//
// Every Run function writes results to `out`, diagnostics to `err`, and returns the
// process exit code (ExitCodeFor; docs/cli.md). A failure never discards what was
// already computed: the table command prints every trial that worked and then fails.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>

#include "liftoff/cli/flags.h"
#include "liftoff/core/status.h"
#include "liftoff/stats/sim_results.h"

namespace liftoff::cli {

/// Exit codes: 0 success, 1 an unexpected internal error, 2 bad command-line usage, and
/// one per Status class (docs/cli.md).
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitUsage = 2;
/// A simulation whose engine diverged (`sim run`; `sim sweep` when any run did): an
/// outcome, not a result (docs/cli.md).
inline constexpr int kExitDiverged = 10;
int ExitCodeFor(StatusCode code);
/// Prints "liftoff: <status>" on `err` and returns its exit code.
int ReportError(const Status& status, std::ostream& err);

/// Options every command that converts angles takes.
struct CalibrationChoice {
  /// Calibration file; empty: the manifest's, else DefaultCalibrationPath().
  std::filesystem::path calibration_path;
};

/// Options of the lookup: how the log is read and how the angle is looked up.
struct LookupChoice {
  /// "linear" or "hold" (sample-and-hold, the 2018 authors' rule).
  std::string rule = "linear";
  /// Consecutive samples further apart than this bracket a gap, seconds.
  double gap_threshold_s = 0.25;
  /// How far past the log's last sample a lookup is answered (held, flagged), seconds.
  double max_past_end_s = 1.0;
  /// Malformed log lines tolerated (skipped and reported) per log.
  int64_t max_bad_lines = 0;
};

/// `liftoff table MANIFEST`: per-trial angles at liftoff and the per-foot table.
struct TableCommand {
  /// Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV), imported as
  /// `liftoff import-2018` would.
  std::filesystem::path manifest_path;
  CalibrationChoice calibration;
  LookupChoice lookup;
  /// "md", "csv", "latex", "json".
  std::string format = "md";
  /// "both", "trials" or "feet".
  std::string tables = "both";
  /// Simulation results JSON (docs/formats.md) for the simulation columns; empty: blank.
  std::filesystem::path sim_path;
  /// Simulation results already in memory (`liftoff sim sweep --hardware`); win over
  /// sim_path.
  std::optional<stats::SimResults> sim_results;
  /// Write the tables here instead of `out`.
  std::filesystem::path output_path;
  /// The per-trial figure (liftoff rotation with its interval beside the simulation) drawn
  /// by gnuplot: its stem .svg, .png, .gp (script) and .dat (data) beside this path; empty:
  /// none.
  std::filesystem::path plot_path;
  /// The gnuplot program (found on the PATH unless a path is given).
  std::string gnuplot = "gnuplot";
  /// Trials whose times come from their video: write <dir>/<trial id>.png, a verification
  /// image, for each; empty: none.
  std::filesystem::path verify_dir;
  /// Progress on stderr while videos are analysed: auto, live, lines or off.
  std::string progress = "auto";
};
int RunTable(const TableCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff import-2018 FOLDER -o MANIFEST`: the 2018 folder as a trial manifest.
struct Import2018Command {
  std::filesystem::path folder;
  std::filesystem::path output_path;
  /// Overwrite an existing manifest.
  bool force = false;
};
int RunImport2018(const Import2018Command& command, std::ostream& out, std::ostream& err);

/// `liftoff log LOG`: what a log holds (span, rate, gaps, LED, skipped lines); optionally
/// converts it to liftoff's format.
struct LogCommand {
  std::filesystem::path log_path;
  std::string log_format = "auto";
  CalibrationChoice calibration;
  int64_t max_bad_lines = 0;
  double gap_threshold_s = 0.25;
  /// Write the log in liftoff's format here.
  std::filesystem::path convert_path;
  bool json = false;
};
int RunLog(const LogCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff calib [FILE]`: the calibration, its provenance and its conversions.
struct CalibCommand {
  CalibrationChoice calibration;
  bool json = false;
};
int RunCalib(const CalibCommand& command, std::ostream& out, std::ostream& err);

/// Each command above added to the command line `parent`: its flags bound to a command
/// struct of its own (defaults: the struct's), run by the returned Subcommand.
Subcommand AddTableCommand(Command& parent);
Subcommand AddImport2018Command(Command& parent);
Subcommand AddLogCommand(Command& parent);
Subcommand AddCalibCommand(Command& parent);

}  // namespace liftoff::cli
