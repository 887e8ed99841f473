#include "report_calibration.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/markup.h"
#include "liftoff/core/text.h"
#include "liftoff/sim/model.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::string_view kCacheFormat = "liftoff-calibration-cache";
constexpr int kCacheVersion = 2;  // 2: each Monte Carlo draw seeded by its index

size_t FootIndex(Foot foot) { return static_cast<size_t>(foot); }

// the simulation's value for `foot` at the fitted tension, rad; NaN when there is none
double AtFitRad(const ReportCalibration& calibration, Foot foot) {
  if (!calibration.at_fit) return std::nan("");
  return calibration.at_fit->liftoff_rad[FootIndex(foot)].value_or(std::nan(""));
}

std::string Signed(double value, int decimals) {
  return (value >= 0.0 ? "+" : "") + FormatFixed(value, decimals);
}

// ---------------------------------------------------------------------------------------
// the simulated side

// the sweep's runs as one sample per tension point, in the order they first appear;
// sigma from the calibration's point of that name (NaN when it has none)
std::vector<fit::TensionSample> SweepSamples(const stats::SimResults& sim,
                                             const Calibration& calibration) {
  std::vector<fit::TensionSample> samples;
  std::map<std::string, size_t> index_by_name;
  for (const stats::SimRun& run : sim.runs) {
    auto [entry, added] = index_by_name.try_emplace(run.tension_point, samples.size());
    if (added) {
      fit::TensionSample& sample = samples.emplace_back();
      const TensionPoint* point = calibration.FindTensionPoint(run.tension_point);
      if (point != nullptr) sample.tension = *point;
      if (point == nullptr) sample.tension.sigma = std::nan("");
      sample.tension.name = run.tension_point;
    }
    if (run.stood) samples[entry->second].liftoff_rad[FootIndex(run.foot)] = run.liftoff_rad;
  }
  return samples;
}

// what the cached runs depend on beyond the sweep's key (in the cache file's name)
std::string CacheOptions(const ReportCommand& command) {
  const fit::FitOptions& grid = command.fit;
  const fit::MonteCarloOptions& mc = command.monte_carlo;
  return "grid " + FormatNumber(grid.sigma_min) + " " + FormatNumber(grid.sigma_max) + " " +
         FormatNumber(grid.sigma_step) + "; monte carlo " + std::to_string(mc.samples) + " " +
         std::to_string(mc.seed) + " " + FormatNumber(mc.stddev_scale);
}

// The cache file's runs: the grid, the Monte Carlo and, with --fit-ratio, the grid again at
// each other stiffness ratio (by its Buna-N multiplier; older files have none).
using RatioGrids = std::map<double, std::vector<fit::TensionSample>>;
struct CachedRuns {
  std::vector<fit::TensionSample> grid, monte_carlo;
  RatioGrids ratio_grids;
};

// the cached runs, when the file is there and made with these options
std::optional<CachedRuns> LoadCachedRuns(const fs::path& path, const std::string& options) {
  if (!fs::exists(path)) return std::nullopt;
  auto document = LoadJsonFile(path);
  if (!document.ok() || !document->is_object() || document->value("format", "") != kCacheFormat ||
      document->value("version", 0) != kCacheVersion || document->value("options", "") != options ||
      !document->contains("grid") || !document->contains("monte_carlo")) {
    return std::nullopt;
  }
  auto grid = fit::TensionSamplesFromJson((*document)["grid"], path.string());
  auto monte_carlo = fit::TensionSamplesFromJson((*document)["monte_carlo"], path.string());
  if (!grid.ok() || !monte_carlo.ok()) return std::nullopt;
  CachedRuns runs{std::move(grid).value(), std::move(monte_carlo).value(), {}};
  // (a damaged entry of the ratios' grids costs that grid only: it is simulated again)
  const json ratios = document->value("ratio_grids", json::array());
  for (const json& entry : ratios.is_array() ? ratios : json::array()) {
    if (!entry.is_object() || !entry.contains("ratio") || !entry["ratio"].is_number() ||
        !entry.contains("grid")) {
      continue;
    }
    auto ratio_grid = fit::TensionSamplesFromJson(entry["grid"], path.string());
    if (ratio_grid.ok())
      runs.ratio_grids[entry["ratio"].get<double>()] = std::move(ratio_grid).value();
  }
  return runs;
}

Status SaveCachedRuns(const fs::path& path, const std::string& options, const CachedRuns& runs) {
  json ratio_grids = json::array();
  for (const auto& [ratio, grid] : runs.ratio_grids) {
    ratio_grids.push_back({{"ratio", ratio}, {"grid", fit::TensionSamplesToJson(grid)}});
  }
  const json document = {{"format", kCacheFormat},
                         {"version", kCacheVersion},
                         {"options", options},
                         {"grid", fit::TensionSamplesToJson(runs.grid)},
                         {"monte_carlo", fit::TensionSamplesToJson(runs.monte_carlo)},
                         {"ratio_grids", std::move(ratio_grids)}};
  return WriteJsonFile(path, document);
}

// the grid and Monte Carlo runs, from the cache or simulated (the Monte Carlo's taken
// from `merged` when given) and cached; returns the ratio grids the cache holds (none when
// the runs were simulated now)
Result<RatioGrids> SimulateOrLoad(const ReportCommand& command, const Calibration& calibration,
                                  const sim::ModelDescription& model,
                                  const sim::SweepOptions& sweep,
                                  const std::vector<fit::TensionSample>* merged,
                                  ReportCalibration& result, std::ostream& err) {
  const std::string options = CacheOptions(command);
  if (auto cached = LoadCachedRuns(result.cache_path, options)) {
    result.grid = std::move(cached->grid);
    result.monte_carlo = std::move(cached->monte_carlo);
    result.from_cache = true;
    return std::move(cached->ratio_grids);
  }
  const std::vector<TensionPoint> grid =
      fit::GridTensionPoints(calibration.tension_points, command.fit);
  std::vector<TensionPoint> draws;
  if (merged == nullptr) {
    LIFTOFF_ASSIGN_OR_RETURN(draws, fit::MonteCarloDraws(calibration, command.monte_carlo));
  }
  if (command.sweep.experiment.progress != "off") {
    err << "calibration: simulating " << Plural(static_cast<int64_t>(grid.size()), "tension scale")
        << " and " << Plural(static_cast<int64_t>(draws.size()), "Monte Carlo draw")
        << (merged ? " (the Monte Carlo's from the shards)" : "")
        << ", each for " << sweep.feet.size() << (sweep.feet.size() == 1 ? " foot" : " feet")
        << "\n";
  }
  const auto start = std::chrono::steady_clock::now();
  LIFTOFF_ASSIGN_OR_RETURN(result.grid, fit::SimulateTensions(model, sweep, grid));
  if (merged != nullptr) {
    result.monte_carlo = *merged;
  } else if (!draws.empty()) {
    LIFTOFF_ASSIGN_OR_RETURN(result.monte_carlo, fit::SimulateTensions(model, sweep, draws));
  }
  if (command.sweep.experiment.progress != "off") {
    const std::chrono::duration<double> wall = std::chrono::steady_clock::now() - start;
    err << "calibration: " << (grid.size() + draws.size()) * sweep.feet.size() << " runs in "
        << FormatFixed(wall.count(), 2) << " s wall\n";
  }
  LIFTOFF_RETURN_IF_ERROR(
      SaveCachedRuns(result.cache_path, options, {result.grid, result.monte_carlo, {}}));
  return RatioGrids{};
}

// the campaign's calibration with the fitted point among its tension points, in sigma
// order (an earlier "fitted" point replaced); a fit that falls on one of its points (the
// same sigma) is that point, named in its note
Calibration FittedCalibration(const Calibration& calibration, const fit::TensionFit& fitted,
                              const std::string& campaign) {
  Calibration result = calibration;
  result.source_path.clear();
  result.name = calibration.name + "-fitted";
  result.description =
      calibration.description + "; tension scale fitted by liftoff report on " + campaign;
  std::vector<TensionPoint>& points = result.tension_points;
  points.erase(std::remove_if(points.begin(), points.end(),
                              [](const TensionPoint& point) { return point.name == "fitted"; }),
               points.end());
  const auto at = std::find_if(points.begin(), points.end(), [&](const TensionPoint& point) {
    return point.sigma >= fitted.sigma - 1e-9;
  });
  const bool on_a_point = at != points.end() && std::abs(at->sigma - fitted.sigma) <= 1e-9;
  const size_t index = static_cast<size_t>(at - points.begin());
  if (!on_a_point) points.insert(at, fitted.tension);
  for (auto note = result.notes.begin(); note != result.notes.end();) {
    note =
        note->first.rfind("/tension_points/", 0) == 0 ? result.notes.erase(note) : std::next(note);
  }
  result.notes["/tension_points/" + std::to_string(index)] =
      std::string(on_a_point ? "the tension scale fitted by liftoff report to " + campaign +
                                   " falls on this point: "
                             : "fitted by liftoff report to " + campaign + ": ") +
      fitted.Brief() + "; stiffnesses on the line through the calibration's points at that sigma";
  return result;
}

// ---------------------------------------------------------------------------------------
// text

std::string ZText(const fit::FootAgreement& foot) {
  return foot.sim_rad ? Signed(foot.z, 1) : std::string("no value");
}

std::string RankingMarkdown(const ReportCalibration& calibration, const std::string& heading) {
  const fit::Ranking& ranking = calibration.ranking;
  if (ranking.overall.empty()) return "";
  std::string text = heading + "# Tension points ranked\n\n| rank | point | sigma | chi2 |";
  std::string rule = "| ---: | --- | ---: | ---: |";
  for (const fit::FootTarget& target : calibration.targets) {
    text += " z " + std::string(FootName(target.foot)) + " |";
    rule += " ---: |";
  }
  text += "\n" + rule + "\n";
  for (size_t i = 0; i < ranking.overall.size(); ++i) {
    const fit::PointAgreement& point = ranking.overall[i];
    text += "| " + std::to_string(i + 1) + " | " + point.tension.name + " | " +
            (std::isfinite(point.tension.sigma) ? Signed(point.tension.sigma, 2) : "?") + " | " +
            (point.complete ? FormatFixed(point.chi_square, 1) : "incomplete") + " |";
    for (const fit::FootAgreement& foot : point.feet) text += " " + ZText(foot) + " |";
    text += "\n";
  }
  const std::vector<TensionPoint>& points = calibration.tension_points;
  for (size_t i = 0; i < ranking.overall.size() && !points.empty(); ++i) {
    if (ranking.overall[i].tension.name != points.back().name) continue;
    text += "\nThe highest tension point, " + points.back().name + ", ranks " +
            std::to_string(i + 1) + " of " + std::to_string(ranking.overall.size()) + ".\n";
  }
  text += "\nPer foot, best first (by |z|):\n\n";
  for (const auto& [foot, names] : ranking.per_foot) {
    std::string list;
    for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
    text += "- " + std::string(FootName(foot)) + ": " + (list.empty() ? "no value" : list) + "\n";
  }
  return text + "\n";
}

std::string FitMarkdown(const ReportCalibration& calibration, const ReportCommand& command,
                        const std::string& heading) {
  std::string text = heading + "# Fitted tension scale\n\n";
  if (!calibration.fit) return text + "No fit: " + calibration.fit_status.ToString() + "\n\n";
  const fit::TensionFit& fitted = *calibration.fit;
  const TensionPoint& tension = fitted.tension;
  text += "- sigma " + Signed(fitted.sigma, 3) + " +- " + FormatFixed(fitted.sigma_stddev, 3) +
          " (bootstrap over each foot's trials, " + std::to_string(command.fit.bootstrap_samples) +
          " resamples, seed " + std::to_string(command.fit.seed) + "; 95 % [" +
          Signed(fitted.sigma_low95, 3) + ", " + Signed(fitted.sigma_high95, 3) + "])\n";
  text += "- systematic +- " + FormatFixed(fitted.sigma_systematic, 3) +
          ": the move of the fit when every trial shifts together by its foot's median "
          "measurement uncertainty (a bias the trials share, which the bootstrap cannot see); "
          "with the bootstrap, +- " + FormatFixed(fitted.sigma_total, 3) + " in all\n";
  text += "- stiffnesses: silicone " + FormatFixed(tension.silicone_n_per_m, 1) + " N/m, Buna-N " +
          FormatFixed(tension.buna_n_n_per_m, 1) + " N/m, spring " +
          FormatFixed(tension.spring_n_per_m, 1) + " N/m (`liftoff sim run --stiffness " +
          FormatFixed(tension.silicone_n_per_m, 1) + "," + FormatFixed(tension.buna_n_n_per_m, 1) +
          "," + FormatFixed(tension.spring_n_per_m, 1) + "`; in calibration.json)\n";
  text += "- chi2 " + FormatFixed(fitted.chi_square, 2) + " for " +
          Plural(fitted.degrees_of_freedom, "degree") + " of freedom" +
          (std::isfinite(fitted.chi_square_per_dof)
               ? " (chi2/dof " + FormatFixed(fitted.chi_square_per_dof, 2) + ")"
               : std::string()) +
          (fitted.poor ? ": poor" : ": consistent with the trials' spread") + "\n";
  text += "- searched sigma " + Signed(fitted.searched_sigma_min, 2) + " .. " +
          Signed(fitted.searched_sigma_max, 2) + " (simulated every " +
          FormatNumber(command.fit.sigma_step) +
          "; between those points the liftoff rotation is interpolated linearly)\n\n";
  text +=
      "| foot | trials | hardware mean | standard error | measurement uncertainty | "
      "sim at the fit (interpolated) | sim at the fit (run) | z |\n"
      "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (size_t f = 0; f < fitted.feet.size(); ++f) {
    const fit::FootTarget& target = calibration.targets[f];
    const double run = AtFitRad(calibration, target.foot);
    text += "| " + std::string(FootName(target.foot)) + " | " + std::to_string(target.summary.n) +
            " | " + FormatFixed(target.summary.mean, 3) + " | " +
            FormatFixed(target.standard_error_rad, 4) + " | " +
            FormatFixed(target.measurement_rad, 4) + " | " +
            FormatFixed(*fitted.feet[f].sim_rad, 3) + " | " +
            (std::isfinite(run) ? FormatFixed(run, 3) : std::string("no value")) + " | " +
            Signed(fitted.feet[f].z, 1) + " |\n";
  }
  text += "\n";
  for (const std::string& warning : fitted.warnings) text += "- warning: " + warning + "\n";
  for (const std::string& skipped : calibration.skipped) text += "- note: " + skipped + "\n";
  return text + "\n";
}

// the ratio's profile (with --fit-ratio)
std::string RatioMarkdown(const ReportCalibration& calibration, const std::string& heading) {
  std::string text = heading + "# Stiffness ratio\n\n";
  if (!calibration.ratio_fit)
    return text + "No fit: " + calibration.ratio_status.ToString() + "\n\n";
  const fit::RatioFit& fitted = *calibration.ratio_fit;
  text +=
      "The Buna-N stiffness times each ratio below (silicone and spring as they are), the "
      "tension scale fitted again at each; chi2 over the ratio is the profile. " +
      fitted.Brief() + ". The 68 % interval holds the ratios whose chi2 lies within " +
      FormatFixed(fitted.delta_chi_square, 2) +
      " of the least (1, times chi2/dof when that is above 1).\n\n"
      "| Buna-N x | sigma | chi2 |\n| ---: | ---: | ---: |\n";
  for (const fit::RatioProfileRow& row : fitted.profile) {
    text += "| " + FormatFixed(row.ratio, 2) + " | " +
            (row.fitted ? Signed(row.sigma, 3) + (row.at_edge ? " (edge)" : "") + " | " +
                              FormatFixed(row.chi_square, 2)
                        : std::string("no fit | no fit")) +
            " |\n";
  }
  text += "\n";
  for (const std::string& warning : fitted.warnings) text += "- warning: " + warning + "\n";
  return text + "\n";
}

std::string MonteCarloMarkdown(const ReportCalibration& calibration, const ReportCommand& command,
                               const std::string& heading) {
  const fit::MonteCarloOptions& options = command.monte_carlo;
  std::string text = heading + "# Monte Carlo over the spring constants\n\n";
  if (options.samples == 0) return text + "Not run (--mc-samples 0).\n\n";
  text += Plural(options.samples, "draw") + " (seed " + std::to_string(options.seed) +
          ", standard deviations x " + FormatNumber(options.stddev_scale) +
          ") of each material's spring constant from a normal distribution with paper Table I's "
          "mean and standard deviation (the calibration's materials), applied to every cable of "
          "that material; each draw runs every foot.\n\n"
          "| foot | lifted | no value | mean | sd | min | max | hardware mean |\n"
          "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const fit::FootDistribution& foot : calibration.distributions) {
    std::string hardware = "&ndash;";
    for (const fit::FootTarget& target : calibration.targets) {
      if (target.foot == foot.foot) hardware = FormatFixed(target.summary.mean, 3);
    }
    const stats::Summary& summary = foot.summary;
    text += "| " + std::string(FootName(foot.foot)) + " | " + std::to_string(summary.n) + " | " +
            std::to_string(foot.missing) + " | " + FormatFixed(summary.mean, 3) + " | " +
            (std::isfinite(summary.stddev) ? FormatFixed(summary.stddev, 3) : "&ndash;") + " | " +
            FormatFixed(summary.min, 3) + " | " + FormatFixed(summary.max, 3) + " | " + hardware +
            " |\n";
  }
  return text + "\n";
}

// the little Markdown the section uses (headings, tables, bullets, paragraphs) as HTML
std::string MarkdownToHtml(const std::string& markdown) {
  std::string html;
  std::string open;  // "table", "ul" or ""
  auto close = [&] {
    if (!open.empty()) html += "</" + open + ">\n";
    open.clear();
  };
  std::istringstream lines(markdown);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("| ---", 0) == 0) continue;
    if (line.rfind("#", 0) == 0) {
      close();
      const size_t level = line.find_first_not_of('#');
      const std::string tag = "h" + std::to_string(level);
      html += "<" + tag + ">" + EscapeMarkup(line.substr(level + 1)) + "</" + tag + ">\n";
    } else if (line.rfind("| ", 0) == 0) {
      const bool header = open != "table";
      if (header) close(), html += "<table>\n", open = "table";
      std::string row = "<tr>";
      std::istringstream cells(line.substr(2));
      for (std::string cell; std::getline(cells, cell, '|');) {
        while (!cell.empty() && cell.back() == ' ') cell.pop_back();
        while (!cell.empty() && cell.front() == ' ') cell.erase(0, 1);
        const std::string text = cell == "&ndash;" ? cell : EscapeMarkup(cell);
        row += header ? "<th>" + text + "</th>" : "<td>" + text + "</td>";
      }
      html += row + "</tr>\n";
    } else if (line.rfind("- ", 0) == 0) {
      if (open != "ul") close(), html += "<ul>\n", open = "ul";
      html += "<li>" + EscapeMarkup(line.substr(2)) + "</li>\n";
    } else {
      close();
      if (!line.empty()) html += "<p>" + EscapeMarkup(line) + "</p>\n";
    }
  }
  close();
  return html;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// the calibration

namespace {

// The stiffness ratio: the tension scale's grid run again at each ratio but 1 (the grid
// itself), or taken from the cache's `cached` grids (and cached), and the profile fitted. A
// ratio that cannot be fitted is a result (ratio_status); a simulation that fails is an error.
Status FitRatio(const ReportCommand& command, const Calibration& calibration,
                const sim::ModelDescription& model, const sim::SweepOptions& sweep,
                RatioGrids cached, ReportCalibration& result, std::ostream& err) {
  CachedRuns cache{result.grid, result.monte_carlo, std::move(cached)};
  std::vector<double> missing;
  for (double ratio : command.ratio.ratios) {
    if (ratio != 1.0 && !cache.ratio_grids.count(ratio)) missing.push_back(ratio);
  }
  if (!missing.empty()) {
    const bool progress = command.sweep.experiment.progress != "off";
    if (progress) {
      err << "calibration: simulating the grid at "
          << Plural(static_cast<int64_t>(missing.size()), "stiffness ratio") << "\n";
    }
    const auto start = std::chrono::steady_clock::now();
    for (double ratio : missing) {
      const std::vector<TensionPoint> points =
          fit::GridTensionPoints(fit::ScaledBunaN(calibration.tension_points, ratio), command.fit);
      LIFTOFF_ASSIGN_OR_RETURN(cache.ratio_grids[ratio],
                               fit::SimulateTensions(model, sweep, points));
    }
    if (progress) {
      const std::chrono::duration<double> wall = std::chrono::steady_clock::now() - start;
      err << "calibration: stiffness ratios in " << FormatFixed(wall.count(), 2) << " s wall\n";
    }
    LIFTOFF_RETURN_IF_ERROR(SaveCachedRuns(result.cache_path, CacheOptions(command), cache));
    result.ratio_grids_run = static_cast<int>(missing.size());
  }
  std::vector<std::vector<fit::TensionSample>> grids;
  for (double ratio : command.ratio.ratios) {
    grids.push_back(ratio == 1.0 ? result.grid : cache.ratio_grids.at(ratio));
  }
  auto fitted = fit::FitStiffnessRatio(result.targets, grids, command.fit, command.ratio);
  if (fitted.ok()) {
    result.ratio_fit = std::move(fitted).value();
  } else {
    result.ratio_status = fitted.status();
  }
  return Status::Ok();
}

}  // namespace

Result<ReportCalibration> CalibrateCampaign(const ReportCommand& command,
                                            const Calibration& calibration,
                                            const std::vector<stats::TrialValue>& values,
                                            const stats::SimResults& sim,
                                            const fs::path& cache_path,
                                            const std::vector<fit::TensionSample>* monte_carlo,
                                            std::ostream& err) {
  LIFTOFF_RETURN_IF_ERROR(command.fit.Validate());
  LIFTOFF_RETURN_IF_ERROR(command.monte_carlo.Validate());
  ReportCalibration result;
  result.command = &command;
  result.cache_path = cache_path;
  result.fitted = calibration;
  result.tension_points = calibration.tension_points;

  // the simulated runs: grid and Monte Carlo
  LIFTOFF_ASSIGN_OR_RETURN(const sim::ModelDescription model,
                           sim::LoadModelDescription(ModelPathFrom(command.sweep.experiment)));
  LIFTOFF_ASSIGN_OR_RETURN(const sim::SweepOptions sweep, SweepOptionsFrom(command.sweep));
  LIFTOFF_ASSIGN_OR_RETURN(
      RatioGrids cached_ratio_grids,
      SimulateOrLoad(command, calibration, model, sweep, monte_carlo, result, err));
  result.distributions = fit::Distributions(result.monte_carlo);

  // the hardware against them
  auto targets = fit::TargetsFromTrials(values, {}, &result.skipped);
  if (!targets.ok()) {
    result.fit_status = targets.status();
    return result;
  }
  // only the simulated feet can be compared
  for (fit::FootTarget& target : *targets) {
    if (std::find(sweep.feet.begin(), sweep.feet.end(), target.foot) != sweep.feet.end()) {
      result.targets.push_back(std::move(target));
    } else {
      result.skipped.push_back("foot " + std::string(FootName(target.foot)) +
                               ": not simulated (--feet); left out of the calibration");
    }
  }
  if (result.targets.empty()) {
    result.fit_status = InvalidArgumentError("no simulated foot has two or more trials");
    return result;
  }
  result.ranking = fit::RankTensionPoints(result.targets, SweepSamples(sim, calibration));
  auto fitted =
      fit::FitTension(result.targets, result.grid, calibration.tension_points, command.fit);
  if (!fitted.ok()) {
    result.fit_status = fitted.status();
    return result;
  }
  result.fit = std::move(fitted).value();
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<fit::TensionSample> at_fit,
                           fit::SimulateTensions(model, sweep, {result.fit->tension}));
  result.at_fit = at_fit.front();
  result.fitted = FittedCalibration(calibration, *result.fit, command.manifest_path.string());
  if (command.fit_ratio) {
    LIFTOFF_RETURN_IF_ERROR(
        FitRatio(command, calibration, model, sweep, std::move(cached_ratio_grids), result, err));
  }
  return result;
}

// ---------------------------------------------------------------------------------------
// figures

namespace {

// liftoff against the tension scale per foot, the hardware means, the fit and its interval
std::optional<Figure> FitFigure(const ReportCalibration& calibration) {
  if (calibration.targets.empty() || calibration.grid.empty()) return std::nullopt;
  Figure figure{"fit", "liftoff rotation against the tension scale, hardware means, the fit",
                      "", ""};
  std::string plot;
  const double low = calibration.grid.front().tension.sigma;
  const double high = calibration.grid.back().tension.sigma;
  int block = 0;
  for (size_t f = 0; f < calibration.targets.size(); ++f) {
    const fit::FootTarget& target = calibration.targets[f];
    const std::string foot(FootName(target.foot));
    const std::string colour = std::to_string(FootIndex(target.foot) + 1);
    figure.data +=
        "# block " + std::to_string(block) + ": foot " + foot + ", simulated: sigma liftoff_rad\n";
    for (const fit::TensionSample& sample : calibration.grid) {
      const std::optional<double>& value = sample.liftoff_rad[FootIndex(target.foot)];
      if (value)
        figure.data += FormatNumber(sample.tension.sigma) + " " + FormatNumber(*value) + "\n";
    }
    figure.data += "\n\n# block " + std::to_string(block + 1) + ": foot " + foot +
                   ", hardware mean: sigma liftoff_rad\n" + FormatNumber(low) + " " +
                   FormatNumber(target.summary.mean) + "\n" + FormatNumber(high) + " " +
                   FormatNumber(target.summary.mean) + "\n\n\n";
    plot += std::string(plot.empty() ? "  plot " : ", \\\n       ") + "\"fit.dat\" index " +
            std::to_string(block) + " using 1:2 with linespoints lw 2 pt 7 ps 0.6 lc " + colour +
            " title \"" + foot + " simulated\", \\\n       \"\" index " +
            std::to_string(block + 1) + " using 1:2 with lines dt 2 lw 2 lc " + colour +
            " title \"" + foot + " hardware mean\"";
    block += 2;
  }
  figure.body =
      "  set title \"Simulated liftoff rotation against the tension scale (hardware means dashed; "
      "fit and its 95 % interval vertical)\"\n"
      "  set xlabel \"tension scale sigma (paper Table III: -2 low .. +2 high)\"\n"
      "  set ylabel \"|vertebra rotation| at liftoff (rad)\"\n"
      "  set grid\n  set key outside right\n  unset arrow\n";
  if (calibration.fit) {
    const fit::TensionFit& fitted = *calibration.fit;
    figure.body += "  set arrow from " + FormatNumber(fitted.sigma) + ", graph 0 to " +
                   FormatNumber(fitted.sigma) + ", graph 1 nohead lw 2 lc rgb \"black\"\n";
    for (const double bound : {fitted.sigma_low95, fitted.sigma_high95}) {
      figure.body += "  set arrow from " + FormatNumber(bound) + ", graph 0 to " +
                     FormatNumber(bound) + ", graph 1 nohead dt 3 lc rgb \"black\"\n";
    }
  }
  figure.body += "  set xrange [" + FormatNumber(low) + ":" + FormatNumber(high) + "]\n" + plot +
                 "\n  unset arrow\n";
  return figure;
}

// per foot: the hardware trials and their range beside the Monte Carlo's values and the
// simulation at the fit
std::optional<Figure> MonteCarloFigure(const ReportCalibration& calibration) {
  if (calibration.targets.empty() && calibration.distributions.empty()) return std::nullopt;
  Figure figure{
      "montecarlo", "per foot: hardware trials and range beside the Monte Carlo's simulated values",
      "", ""};
  auto x = [](Foot foot, double offset) {
    return FormatNumber(static_cast<double>(FootIndex(foot)) + 1.0 + offset);
  };
  std::string plot;
  int block = 0;
  auto add_block = [&](const std::string& comment, const std::string& rows,
                       const std::string& style) {
    if (rows.empty()) return;
    figure.data += "# block " + std::to_string(block) + ": " + comment + "\n" + rows + "\n\n";
    plot += std::string(plot.empty() ? "  plot " : ", \\\n       ") + "\"montecarlo.dat\" index " +
            std::to_string(block++) + " " + style;
  };
  std::string trials, ranges, draws, at_fit;
  for (const fit::FootTarget& target : calibration.targets) {
    for (const double value : target.liftoff_rad)
      trials += x(target.foot, -0.15) + " " + FormatNumber(value) + "\n";
    ranges += x(target.foot, -0.25) + " " + FormatNumber(target.summary.mean) + " " +
              FormatNumber(target.summary.min) + " " + FormatNumber(target.summary.max) + "\n";
    const double run = AtFitRad(calibration, target.foot);
    if (std::isfinite(run)) at_fit += x(target.foot, 0.15) + " " + FormatNumber(run) + "\n";
  }
  for (const fit::FootDistribution& foot : calibration.distributions) {
    for (size_t i = 0; i < foot.liftoff_rad.size(); ++i) {
      const double jitter = 0.02 * static_cast<double>(static_cast<int>(i % 7) - 3);
      draws += x(foot.foot, 0.15 + jitter) + " " + FormatNumber(foot.liftoff_rad[i]) + "\n";
    }
  }
  add_block("hardware trials: x liftoff_rad", trials,
            "using 1:2 with points pt 7 ps 1.2 lc rgb \"#1f77b4\" title \"hardware trials\"");
  add_block("hardware range: x mean_rad min_rad max_rad", ranges,
            "using 1:2:3:4 with yerrorbars pt 0 lw 2 lc rgb \"#1f77b4\" title \"hardware range\"");
  add_block(
      "Monte Carlo draws: x liftoff_rad", draws,
      "using 1:2 with points pt 6 ps 0.8 lc rgb \"#d62728\" title \"simulated, Monte Carlo over "
      "Table I\"");
  add_block("simulation at the fitted tension: x liftoff_rad", at_fit,
            "using 1:2 with points pt 5 ps 1.5 lc rgb \"black\" title \"simulated at the fitted "
            "tension\"");
  figure.body =
      "  set title \"Liftoff rotation per foot: hardware beside the simulation's spread over the "
      "spring constants\"\n"
      "  set ylabel \"|vertebra rotation| at liftoff (rad)\"\n"
      "  set xtics (\"A\" 1, \"B\" 2, \"C\" 3, \"D\" 4)\n  set xrange [0.5:4.5]\n"
      "  set grid ytics\n  set key outside right\n" +
      plot + "\n  set xtics autofreq\n";
  return figure;
}

}  // namespace

std::vector<Figure> CalibrationFigures(const ReportCalibration& calibration) {
  std::vector<Figure> figures;
  if (auto figure = FitFigure(calibration)) figures.push_back(std::move(*figure));
  if (auto figure = MonteCarloFigure(calibration)) figures.push_back(std::move(*figure));
  return figures;
}

// ---------------------------------------------------------------------------------------
// pages and files

std::string CalibrationMarkdown(const ReportCalibration& calibration, const std::string& heading) {
  const ReportCommand& command = *calibration.command;
  std::string text = heading + " Calibration\n\n";
  text +=
      "Metric: per foot with at least two trials, z = (simulated liftoff rotation - the "
      "trials' mean) / the standard error of that mean (sd / sqrt(n), at least 0.001 rad); a "
      "tension's agreement over the feet is chi2 = sum of z^2 (smaller is better). A point "
      "where a foot's test did not stand or lift ranks after every complete one. The "
      "tension scale sigma is the coordinate of the calibration's tension points (paper "
      "Table III, -2 low .. +2 high), stiffnesses linear between them and on the end "
      "segments' lines beyond.\n\n";
  if (calibration.targets.empty())
    text += "No calibration: " + calibration.fit_status.ToString() + "\n\n";
  text += RankingMarkdown(calibration, heading);
  if (!calibration.targets.empty()) text += FitMarkdown(calibration, command, heading);
  if (command.fit_ratio && calibration.fit) text += RatioMarkdown(calibration, heading);
  text += MonteCarloMarkdown(calibration, command, heading);
  text +=
      heading +
      "# Files\n\n"
      "- calibration.json: the campaign's calibration with the tension point \"fitted\" "
      "(or, when the fit falls on one of its points, a note on that point; `liftoff calib "
      "calibration.json`; absent without a fit)\n"
      "- figures/fit and figures/montecarlo: .gp scripts with their .dat data\n"
      "- simulated runs cached in " +
      calibration.cache_path.string() + (calibration.from_cache ? " (read from it" : " (run now") +
      (calibration.from_cache && calibration.ratio_grids_run > 0
           ? "; the grid at " + Plural(calibration.ratio_grids_run, "stiffness ratio") + " run now)"
           : ")") +
      "\n";
  return text;
}

std::string CalibrationHtml(const ReportCalibration& calibration) {
  return MarkdownToHtml(CalibrationMarkdown(calibration, "##"));
}

Status WriteCalibrationFiles(const ReportCalibration& calibration, const fs::path& dir) {
  if (calibration.fit) {
    LIFTOFF_RETURN_IF_ERROR(calibration.fitted.Validate());
    LIFTOFF_RETURN_IF_ERROR(
        WriteJsonFile(dir / "calibration.json", CalibrationToJson(calibration.fitted)));
  }
  return WriteFileAtomically(dir / "calibration.md", CalibrationMarkdown(calibration, "#"));
}

std::string CalibrationSummary(const ReportCalibration& calibration) {
  std::string text = "calibration: ";
  if (!calibration.ranking.overall.empty()) {
    const fit::PointAgreement& best = calibration.ranking.overall.front();
    text += "best tension point " + best.tension.name +
            (best.complete ? " (chi2 " + FormatFixed(best.chi_square, 1) + ")" : " (incomplete)") +
            "; ";
  }
  if (calibration.fit) {
    text += "fitted " + calibration.fit->Brief();
    if (!calibration.fit->warnings.empty()) {
      text += "; " + Plural(static_cast<int64_t>(calibration.fit->warnings.size()), "warning") +
              " in calibration.md";
    }
  } else {
    text += "no fit (" + calibration.fit_status.ToString() + ")";
  }
  if (calibration.ratio_fit) {
    text += "; stiffness " + calibration.ratio_fit->Brief();
  } else if (!calibration.ratio_status.ok()) {
    text += "; stiffness ratio: no fit (" + calibration.ratio_status.ToString() + ")";
  }
  return text;
}

}  // namespace liftoff::cli
