#include "liftoff/stats/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <vector>

#include "liftoff/core/markup.h"
#include "liftoff/core/text.h"

namespace liftoff::stats {
namespace {

// Colours of the feet's tape (A blue, B orange, C purple, D red), as the videos show them.
constexpr std::array<const char*, 4> kFootColour = {"#1f5fbf", "#e07b1a", "#7b3fa0", "#c62828"};

std::string Px(double value) { return FormatFixed(value, 1); }

// Every value the plot shows, for the fitted axis.
void CollectValues(const ResultsTable& table, std::vector<double>& values) {
  for (const FootRow& row : table.rows) {
    for (const TrialValue& trial : row.trials) {
      for (double v : {trial.liftoff_rad, trial.lower_rad, trial.upper_rad}) {
        if (std::isfinite(v)) values.push_back(v);
      }
    }
    if (row.sim) {
      values.push_back(row.sim->min_rad);
      values.push_back(row.sim->max_rad);
    }
  }
}

}  // namespace

Status PlotOptions::Validate() const {
  if (width_px < 200 || width_px > 4000 || height_px < 200 || height_px > 4000) {
    return InvalidArgumentError("plot size: expected 200 .. 4000 px each, got " +
                                std::to_string(width_px) + " x " + std::to_string(height_px));
  }
  const bool fitted = min_rad == 0.0 && max_rad == 0.0;
  if (!fitted && !(std::isfinite(min_rad) && std::isfinite(max_rad) && min_rad < max_rad)) {
    return InvalidArgumentError("plot axis: expected min_rad < max_rad (or both 0), got " +
                                FormatFixed(min_rad, 3) + " .. " + FormatFixed(max_rad, 3));
  }
  return Status::Ok();
}

Result<std::string> RenderResultsPlotSvg(const ResultsTable& table, const PlotOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());

  // axis: given, or fitted to the data and rounded out to 0.05 rad
  double axis_min = options.min_rad, axis_max = options.max_rad;
  if (axis_min == 0.0 && axis_max == 0.0) {
    std::vector<double> values;
    CollectValues(table, values);
    if (values.empty()) values = {0.0, 1.0};
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    axis_min = std::floor(*low / 0.05) * 0.05 - 0.05;
    axis_max = std::ceil(*high / 0.05) * 0.05 + 0.05;
    axis_min = std::max(axis_min, 0.0);
  }

  // layout: plot area inside margins; one column per foot
  const double left = 70, right = options.width_px - 20.0, top = 50,
               bottom = options.height_px - 70.0;
  const double column_width = (right - left) / 4.0;
  const auto y_of = [&](double rad) {
    return bottom - (rad - axis_min) / (axis_max - axis_min) * (bottom - top);
  };

  std::ostringstream svg;
  svg << R"(<svg xmlns="http://www.w3.org/2000/svg" width=")" << options.width_px << R"(" height=")"
      << options.height_px << R"(" font-family="sans-serif" font-size="12">)" << '\n';
  svg << R"(<rect width="100%" height="100%" fill="white"/>)" << '\n';
  svg << R"(<text x=")" << Px(options.width_px / 2.0) << R"(" y="24" text-anchor="middle" )"
      << R"(font-size="15" font-weight="bold">)"
      << EscapeMarkup(table.title.empty() ? "Absolute vertebra rotation at liftoff (rad)" : table.title)
      << "</text>\n";

  // grid and axis labels every 0.05 rad
  for (int k = 0;; ++k) {
    const double rad = std::ceil(axis_min / 0.05 - 1e-9) * 0.05 + 0.05 * k;
    if (rad > axis_max + 1e-9) break;
    const double y = y_of(rad);
    svg << R"(<line x1=")" << Px(left) << R"(" x2=")" << Px(right) << R"(" y1=")" << Px(y)
        << R"(" y2=")" << Px(y) << R"(" stroke="#ddd"/>)" << '\n';
    svg << R"(<text x=")" << Px(left - 8) << R"(" y=")" << Px(y + 4) << R"(" text-anchor="end">)"
        << FormatFixed(rad, 2) << "</text>\n";
  }
  svg << R"(<text transform="translate(18 )" << Px((top + bottom) / 2)
      << R"svg() rotate(-90)" text-anchor="middle">liftoff rotation (rad)</text>)svg" << '\n';

  // one column per foot: sim band on the right half, trials and mean on the left half
  for (int foot_index = 0; foot_index < 4; ++foot_index) {
    const Foot foot = static_cast<Foot>(foot_index);
    const double x0 = left + column_width * foot_index;
    const double trials_x = x0 + column_width * 0.35, sim_x = x0 + column_width * 0.72;
    const char* colour = kFootColour[static_cast<size_t>(foot_index)];
    svg << R"(<text x=")" << Px(x0 + column_width / 2) << R"(" y=")" << Px(bottom + 20)
        << R"(" text-anchor="middle" font-weight="bold" fill=")" << colour << R"(">)"
        << FootName(foot) << " (" << FootPosition(foot) << ")</text>\n";

    const auto row = std::find_if(table.rows.begin(), table.rows.end(),
                                  [&](const FootRow& r) { return r.foot == foot; });
    if (row == table.rows.end()) continue;

    // the simulated range as a band
    if (row->sim) {
      const double y_max = y_of(row->sim->max_rad), y_min = y_of(row->sim->min_rad);
      svg << R"(<rect x=")" << Px(sim_x - 12) << R"(" y=")" << Px(y_max) << R"(" width="24" )"
          << R"(height=")" << Px(std::max(y_min - y_max, 1.5)) << R"(" fill="#999" )"
          << R"(fill-opacity="0.45" stroke="#555"><title>sim )" << FootName(foot) << ": "
          << FormatFixed(row->sim->min_rad, 3) << " .. " << FormatFixed(row->sim->max_rad, 3)
          << " rad</title></rect>\n";
    }

    // each trial as a dot with its interval, spread a little sideways to stay visible
    const auto count = static_cast<double>(row->trials.size());
    for (size_t i = 0; i < row->trials.size(); ++i) {
      const TrialValue& trial = row->trials[i];
      if (!std::isfinite(trial.liftoff_rad)) continue;
      const double x = trials_x + (static_cast<double>(i) - (count - 1) / 2) * 6.0;
      if (std::isfinite(trial.lower_rad) && std::isfinite(trial.upper_rad)) {
        svg << R"(<line x1=")" << Px(x) << R"(" x2=")" << Px(x) << R"(" y1=")"
            << Px(y_of(trial.lower_rad)) << R"(" y2=")" << Px(y_of(trial.upper_rad))
            << R"(" stroke=")" << colour << R"(" stroke-opacity="0.5"/>)" << '\n';
      }
      svg << R"(<circle cx=")" << Px(x) << R"(" cy=")" << Px(y_of(trial.liftoff_rad))
          << R"(" r="3.5" fill=")" << colour << R"("><title>)" << EscapeMarkup(trial.trial_id) << ": "
          << FormatFixed(trial.liftoff_rad, 3) << " rad</title></circle>\n";
    }

    // the hardware mean and its confidence interval
    const Summary& hw = row->hardware;
    if (hw.n > 0 && std::isfinite(hw.mean)) {
      const double x = trials_x - (count + 1) / 2 * 6.0 - 14;
      if (std::isfinite(hw.ci_low) && std::isfinite(hw.ci_high)) {
        svg << R"(<line x1=")" << Px(x) << R"(" x2=")" << Px(x) << R"(" y1=")"
            << Px(y_of(hw.ci_low)) << R"(" y2=")" << Px(y_of(hw.ci_high))
            << R"(" stroke="black"/>)" << '\n';
      }
      svg << R"(<line x1=")" << Px(x - 7) << R"(" x2=")" << Px(x + 7) << R"(" y1=")"
          << Px(y_of(hw.mean)) << R"(" y2=")" << Px(y_of(hw.mean))
          << R"(" stroke="black" stroke-width="2"><title>hardware mean )" << FootName(foot) << ": "
          << FormatFixed(hw.mean, 3) << " rad (n " << hw.n << ")</title></line>\n";
    }
  }

  // legend and caption: what the marks are, and where the values came from
  svg << R"(<text x=")" << Px(left) << R"(" y=")" << Px(bottom + 40)
      << R"(" font-size="11">dots: hardware trials (whisker: uncertainty interval); black: )"
      << R"(mean and 95 % CI; grey band: simulated range over tension points</text>)" << '\n';
  svg << R"(<text x=")" << Px(left) << R"(" y=")" << Px(bottom + 56)
      << R"(" font-size="11" fill="#444">calibration: )" << EscapeMarkup(table.calibration)
      << "; lookup: " << EscapeMarkup(table.lookup_rule) << "</text>\n";
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace liftoff::stats
