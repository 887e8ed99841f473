// The report's calibration part (liftoff report, docs/cli.md): the campaign's trials
// against the simulation through liftoff::fit (tension points ranked, the tension scale
// fitted, the Monte Carlo), its simulated runs cached beside the sweep's, and what the
// report writes of it: calibration.json, calibration.md, the figures' data and scripts,
// the pages' section.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/cli/figures.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/status.h"
#include "liftoff/fit/tension_fit.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/table.h"

namespace liftoff::cli {

struct ReportCalibration {
  /// The command it was made for (its fit and Monte Carlo options are reported).
  const ReportCommand* command = nullptr;
  /// The campaign calibration's tension points, low to high.
  std::vector<TensionPoint> tension_points;
  /// The hardware per foot, and the feet left out (fewer than two trials).
  std::vector<fit::FootTarget> targets;
  std::vector<std::string> skipped;
  /// The sweep's tension points ranked.
  fit::Ranking ranking;
  /// The fit's grid, the fit (or why there is none).
  std::vector<fit::TensionSample> grid;
  std::optional<fit::TensionFit> fit;
  Status fit_status;
  /// The simulation at the fitted tension (one run per foot), for the interpolation check.
  std::optional<fit::TensionSample> at_fit;
  /// With --fit-ratio: the stiffness ratio's fit (or why there is none).
  std::optional<fit::RatioFit> ratio_fit;
  Status ratio_status;
  /// The Monte Carlo's draws with their values, and each foot's distribution.
  std::vector<fit::TensionSample> monte_carlo;
  std::vector<fit::FootDistribution> distributions;
  /// The calibration with the fitted tension point added (when there is a fit).
  Calibration fitted;
  /// Cache file of the simulated runs, and whether they came from it.
  std::filesystem::path cache_path;
  bool from_cache = false;
  /// With --fit-ratio: the stiffness ratios whose grid was simulated now (not cached).
  int ratio_grids_run = 0;
};

/// Calibrates the campaign: `values` (the trials) against the sweep's `sim` results and
/// fresh runs for the grid and the Monte Carlo (or their cache: `cache_path`, valid while
/// its options match). `monte_carlo`, when given, holds the Monte Carlo's simulated draws
/// already (merged from shards: report_shards.h), in draw order. kInvalidArgument for bad
/// fit or Monte Carlo options; a campaign that cannot be fitted is a result (fit_status),
/// not an error.
Result<ReportCalibration> CalibrateCampaign(const ReportCommand& command,
                                            const Calibration& calibration,
                                            const std::vector<stats::TrialValue>& values,
                                            const stats::SimResults& sim,
                                            const std::filesystem::path& cache_path,
                                            const std::vector<fit::TensionSample>* monte_carlo,
                                            std::ostream& err);

/// "fit" (liftoff rotation against the tension scale, hardware means, the fit) and
/// "montecarlo" (per foot: the hardware trials and range beside the Monte Carlo's values),
/// each when there is something to draw.
std::vector<Figure> CalibrationFigures(const ReportCalibration& calibration);

/// calibration.md: the metric, the ranking, the fit and its warnings, the Monte Carlo, the
/// files. `heading` is the top heading's level ("#" or "##").
std::string CalibrationMarkdown(const ReportCalibration& calibration, const std::string& heading);

/// The same section as HTML.
std::string CalibrationHtml(const ReportCalibration& calibration);

/// Writes DIR/calibration.json (the fitted calibration; nothing without a fit) and
/// DIR/calibration.md.
Status WriteCalibrationFiles(const ReportCalibration& calibration,
                             const std::filesystem::path& dir);

/// One line for the terminal: "calibration: best point high; fitted sigma 2.31 +- ...".
std::string CalibrationSummary(const ReportCalibration& calibration);

}  // namespace liftoff::cli
