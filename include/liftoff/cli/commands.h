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

/// A clip analysis' flags as typed (`liftoff video`, `liftoff sync --video`);
/// ClipOptionsFrom (video_commands.h) checks them and makes video::ClipAnalysisOptions.
struct ClipChoice {
  /// Regions "x,y,w,h", px. LED: empty = locate automatically. Foot: empty = LED only.
  std::string led_roi;
  std::string foot_roi;
  /// The foot whose tape colour to track (A, B, C, D); empty: edges only.
  std::string foot;
  /// Image scale at the foot, px per mm; 0: estimated from the foot's width.
  double px_per_mm = 0.0;
  /// Liftoff threshold above rest: mm (with the scale), or px when threshold_px is given
  /// (> 0; then threshold_mm is ignored).
  double threshold_mm = 1.0;
  std::optional<double> threshold_px;
  /// Camera exposure per frame, ms (> 0, at most 1.05 frame intervals); 0: unknown (the
  /// LED allows any exposure up to the frame interval, the foot takes half of it).
  double exposure_ms = 0.0;
  /// Rest window "FROM,TO", s relative to the LED switch-on.
  std::string rest_window = "-0.5,0";
  /// Which foot instant is the liftoff: "threshold" or "onset".
  std::string liftoff = "threshold";
};

/// `liftoff sync LOG --led-on S --liftoff S` or `liftoff sync LOG --video CLIP ...`: one
/// lookup, the rotation at liftoff. The two video instants come either from the command
/// line or from the clip's analysis (exactly one of the two).
struct SyncCommand {
  std::filesystem::path log_path;
  /// "auto", "liftoff", "laika-2018".
  std::string log_format = "auto";
  CalibrationChoice calibration;
  LookupChoice lookup;
  /// Video instants, seconds from the video's start (both, or neither with video_path).
  std::optional<double> led_on_s;
  std::optional<double> liftoff_s;
  /// Half-width of each instant's timing uncertainty, seconds (with led_on_s/liftoff_s).
  double uncertainty_s = 0.0;
  /// The clip whose analysis gives the instants and their uncertainties; needs
  /// clip.foot_roi.
  std::filesystem::path video_path;
  ClipChoice clip;
  /// With video_path: verification image (PNG) to write; empty: none.
  std::filesystem::path verify_path;
  /// With video_path: progress on stderr, "auto", "live", "lines" or "off" (as `liftoff
  /// video`).
  std::string progress = "auto";
  bool json = false;
};
int RunSync(const SyncCommand& command, std::ostream& out, std::ostream& err);

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
Subcommand AddSyncCommand(Command& parent);
Subcommand AddLogCommand(Command& parent);
Subcommand AddCalibCommand(Command& parent);

}  // namespace liftoff::cli
