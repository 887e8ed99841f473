// The hardware-vs-simulation plot: one column per foot (A..D), each hardware trial as a
// dot with its uncertainty interval as a whisker, the hardware mean with its 95 %
// confidence interval, and the simulated range (min..max over tension points) as a band
// beside them. Written as SVG: plain text, deterministic, no plotting library, opens in
// any browser and imports into papers.
#pragma once

#include <string>

#include "liftoff/stats/table.h"

namespace liftoff::stats {

struct PlotOptions {
  /// Canvas size, px (200 .. 4000 each).
  int width_px = 720;
  int height_px = 420;
  /// Vertical axis, rad. Both 0: fitted to the data (rounded out to 0.05 rad).
  double min_rad = 0.0;
  double max_rad = 0.0;

  Status Validate() const;
};

/// Renders `table` (BuildResultsTable) as an SVG document. The caption names the
/// calibration and the lookup rule, as every table rendering does. Feet without values
/// keep their column, empty. Trials whose liftoff_rad is NaN are not drawn.
Result<std::string> RenderResultsPlotSvg(const ResultsTable& table,
                                         const PlotOptions& options = {});

}  // namespace liftoff::stats
