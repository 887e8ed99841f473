// The results table: the layout of the paper's Table IV (Foot | Sim min | Sim max | HW min
// | HW max), extended with the hardware statistics (n, mean, sd, median, 95 % CI of the
// mean), rendered as Markdown, CSV, LaTeX or JSON. Every rendering names the calibration
// and the lookup rule the hardware values came from. Layouts: docs/formats.md, "Results
// table".
#pragma once

#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/statistics.h"

namespace liftoff::stats {

/// One hardware trial's result.
struct TrialValue {
  /// Trial id from the manifest, e.g. "A1".
  std::string trial_id;
  Foot foot = Foot::kA;
  /// Absolute rotation of the rotating vertebra at liftoff, rad; NaN when the trial gave
  /// no value (listed, but left out of the statistics).
  double liftoff_rad = std::numeric_limits<double>::quiet_NaN();
  /// Uncertainty interval of liftoff_rad, absolute rotations, rad (lower <= upper); NaN
  /// when unknown.
  double lower_rad = std::numeric_limits<double>::quiet_NaN();
  double upper_rad = std::numeric_limits<double>::quiet_NaN();
  /// Things to know about the value, e.g. "gap 0.93 s" (empty when none).
  std::string flags;
};

/// One foot's line of the table.
struct FootRow {
  Foot foot = Foot::kA;
  /// Statistics of the trials' liftoff_rad, rad (n = 0 when the foot has no values).
  Summary hardware;
  /// Simulated range, when the simulation results have one for this foot.
  std::optional<SimFootRange> sim;
  /// This foot's trials, in input order.
  std::vector<TrialValue> trials;
};

struct ResultsTable {
  /// Caption, e.g. "Absolute vertebra rotation at liftoff (rad)".
  std::string title;
  /// The calibration the hardware values used (Calibration::Brief()); printed with every
  /// rendering.
  std::string calibration;
  /// How a liftoff instant became a rotation, e.g. "sample-and-hold (last sample at or
  /// before the instant)"; printed with every rendering.
  std::string lookup_rule;
  /// Feet in order A..D, only those with trials or simulated values.
  std::vector<FootRow> rows;
  /// Things a reader should know: the simulation's source, runs that did not stand,
  /// ranges typed in from a summary, trials without a value.
  std::vector<std::string> notes;
};

/// Builds the table from per-trial values and, when `sim` is not null, the simulation's
/// ranges. Rows for every foot with trials or sim values, in order A..D; a row's `sim` is
/// empty when the simulation has no range for its foot.
ResultsTable BuildResultsTable(std::span<const TrialValue> trials, const SimResults* sim,
                               std::string calibration, std::string lookup_rule);

enum class TableFormat { kMarkdown, kCsv, kLatex, kJson };

/// "md" or "markdown", "csv", "latex" or "tex", "json"; nullopt otherwise.
std::optional<TableFormat> ParseTableFormat(std::string_view text);
/// "markdown", "csv", "latex", "json".
std::string_view TableFormatName(TableFormat format);

/// Renders the per-foot table. Numbers in rad with 3 decimals (full precision in JSON).
/// Missing values (NaN, no simulation): "–" in Markdown, "--" in LaTeX, an empty field in
/// CSV, null in JSON.
/// - Markdown: a bold title, a pipe table with a header row, then a line naming the
///   calibration and the lookup rule, then the notes.
/// - CSV (RFC 4180, CRLF line ends): a header row, one row per foot; every row carries
///   the calibration and the lookup rule in its last two fields.
/// - LaTeX: a booktabs table (\toprule, \midrule, \bottomrule) whose caption names the
///   calibration and the lookup rule; text is escaped.
/// - JSON: everything, including each trial's values, the calibration and the notes.
std::string RenderResultsTable(const ResultsTable& table, TableFormat format);

/// The per-foot table as JSON (what RenderResultsTable writes for kJson).
nlohmann::json ResultsTableToJson(const ResultsTable& table);

/// Renders one line per trial: id, foot, liftoff rotation, its uncertainty interval and
/// flags, in the same formats and with the same calibration/lookup-rule lines.
std::string RenderTrialTable(std::span<const TrialValue> trials, TableFormat format,
                             std::string_view calibration, std::string_view lookup_rule);

}  // namespace liftoff::stats
