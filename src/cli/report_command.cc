#include "liftoff/cli/report_command.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/cli/figures.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/markup.h"
#include "liftoff/core/text.h"
#include "liftoff/core/version.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/table.h"
#include "report_calibration.h"
#include "report_shards.h"
#include "report_trials.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::string_view kCacheFormat = "liftoff-sim-cache";
constexpr int kCacheVersion = 1;

// ---------------------------------------------------------------------------------------
// inputs

// kInvalidArgument when `input` lies inside `dir`: the report never writes over an input
Status CheckOutsideOutput(const fs::path& input, const fs::path& dir, std::string_view what) {
  std::error_code error;
  const fs::path inside = fs::weakly_canonical(fs::absolute(input), error);
  fs::path folder = fs::weakly_canonical(fs::absolute(dir), error);
  if (folder.filename().empty()) folder = folder.parent_path();
  const auto [folder_end, unused] =
      std::mismatch(folder.begin(), folder.end(), inside.begin(), inside.end());
  if (folder_end != folder.end()) return Status::Ok();
  return InvalidArgumentError("--output: " + dir.string() + " holds the " + std::string(what) +
                              " " + input.string() +
                              "; choose a folder without inputs (the report never overwrites one)");
}

// every file the report reads: manifest, calibration, logs, videos (TrialInputs), model
Status CheckInputsOutsideOutput(const ReportCommand& command, const CampaignAnalysis& campaign) {
  std::vector<NamedPath> inputs;
  if (fs::is_regular_file(command.manifest_path))
    inputs.push_back({"manifest", command.manifest_path});
  for (NamedPath& input : TrialInputs(campaign.manifest)) inputs.push_back(std::move(input));
  inputs.push_back({"calibration", campaign.calibration.source_path});
  if (!command.no_sim) inputs.push_back({"model", ModelPathFrom(command.sweep.experiment)});
  for (const NamedPath& input : inputs) {
    if (input.path.empty()) continue;
    LIFTOFF_RETURN_IF_ERROR(CheckOutsideOutput(input.path, command.output_dir, input.role));
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// the simulated column, from the cache or a fresh sweep

// One run's targeted foot: height above its reference against |rotation| (Figure 7).
struct SimCurve {
  std::string foot;
  std::string tension_point;
  std::vector<double> rotation_rad;
  std::vector<double> height_m;
};

// The simulation results and each standing run's curve, in sweep order.
struct SimColumn {
  stats::SimResults results;
  std::vector<SimCurve> curves;
  fs::path cache_path;
  bool from_cache = false;
};

// what the sweep's values depend on: model bytes, calibration, every experiment option,
// the feet and tension points, the ramp mode and the software version
Result<std::string> CacheKey(const ReportCommand& command, const Calibration& calibration) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string model,
                           ReadWholeFile(ModelPathFrom(command.sweep.experiment)));
  const std::string key_text = "model\n" + model + "\ncalibration\n" +
                               CalibrationToJson(calibration).dump() + "\nexperiment\n" +
                               DescribeOverrides(command.sweep.experiment) + "\nfeet\n" +
                               Join(command.sweep.feet, ",") + "\ntensions\n" +
                               Join(command.sweep.tensions, ",") +
                               "\nfull_ramp\n" + (command.sweep.full_ramp ? "1" : "0") +
                               "\nversion\n" + kVersion;
  return HashHex(key_text);
}

// the targeted foot's |rotation| and height above its reference, per run that stood
std::vector<SimCurve> CurvesFromSweep(const sim::SweepResult& sweep) {
  std::vector<SimCurve> curves;
  for (const sim::SweepRun& run : sweep.runs) {
    if (!run.Stood()) continue;
    SimCurve& curve = curves.emplace_back();
    curve.foot = FootName(run.foot);
    curve.tension_point = run.tension_point.name;
    for (const sim::CurvePoint& point : run.result.curve) {
      curve.rotation_rad.push_back(std::abs(point.rotation_rad));
      curve.height_m.push_back(point.height_m[static_cast<size_t>(run.foot)]);
    }
  }
  return curves;
}

json CurvesToJson(const std::vector<SimCurve>& curves) {
  json array = json::array();
  for (const SimCurve& curve : curves) {
    array.push_back({{"foot", curve.foot},
                     {"tension_point", curve.tension_point},
                     {"rotation_rad", curve.rotation_rad},
                     {"height_m", curve.height_m}});
  }
  return array;
}

// a cache file: its format and version, the simulation results and the curves
Result<SimColumn> LoadCachedColumn(const fs::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(const json document, LoadJsonFile(path));
  JsonReader reader(document, path.string());
  if (reader.String("format") != kCacheFormat) {
    reader.Fail("format", "expected \"" + std::string(kCacheFormat) + "\"");
  }
  reader.Integer("version", {.min = kCacheVersion, .max = kCacheVersion});
  reader.String("key");
  const json* results = reader.Raw("results");
  if (results == nullptr) reader.Fail("results", "missing");
  SimColumn column;
  for (JsonReader& entry : reader.ObjectArray("curves")) {
    SimCurve& curve = column.curves.emplace_back();
    curve.foot = entry.String("foot");
    curve.tension_point = entry.String("tension_point");
    curve.rotation_rad = entry.NumberArray("rotation_rad");
    curve.height_m = entry.NumberArray("height_m");
  }
  const Status read = reader.Finish();
  if (!read.ok())
    return Status(read.code(), read.message() + "; delete the file to rerun the sweep");
  LIFTOFF_ASSIGN_OR_RETURN(column.results, stats::SimResultsFromJson(*results, path.string()));
  column.cache_path = path;
  column.from_cache = true;
  return column;
}

Result<SimColumn> SimulatedColumn(const ReportCommand& command, const Calibration& calibration,
                                  std::ostream& err) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string key, CacheKey(command, calibration));
  const fs::path cache_dir =
      command.cache_dir.empty() ? command.output_dir / "sim-cache" : command.cache_dir;
  const fs::path path = cache_dir / (key + ".json");
  if (fs::exists(path)) return LoadCachedColumn(path);

  LIFTOFF_ASSIGN_OR_RETURN(const sim::SweepResult sweep,
                           RunSweepShowingProgress(command.sweep, err));
  const std::string overrides = DescribeOverrides(command.sweep.experiment);
  SimColumn column;
  column.results = SimResultsFromSweep(
      sweep, "liftoff sim sweep" + (overrides.empty() ? "" : " " + overrides));
  column.results.source = path.string();
  column.curves = CurvesFromSweep(sweep);
  column.cache_path = path;
  const json document = {{"format", kCacheFormat},
                         {"version", kCacheVersion},
                         {"key", key},
                         {"results", stats::SimResultsToJson(column.results)},
                         {"curves", CurvesToJson(column.curves)}};
  LIFTOFF_RETURN_IF_ERROR(WriteJsonFile(path, document));
  return column;
}

// ---------------------------------------------------------------------------------------
// figures: data and a gnuplot script each, drawn when gnuplot is there

// (b) the paper's Figure 7: per foot, the simulated height against |rotation| for each
// tension point, the hardware's liftoff range as dashed vertical lines
std::optional<Figure> Figure7(const std::vector<SimCurve>& curves,
                             const stats::ResultsTable& table) {
  if (curves.empty()) return std::nullopt;
  Figure figure{"figure7", "foot height against rotation per tension point (paper Figure 7)",
                "", ""};
  std::map<std::string, std::vector<std::pair<int, std::string>>> blocks_by_foot;
  std::map<std::string, double> max_rotation_by_foot;  // each panel's x range, rad
  int block = 0;
  for (const SimCurve& curve : curves) {
    double& max_rotation = max_rotation_by_foot[curve.foot];
    figure.data += "# block " + std::to_string(block) + ": foot " + curve.foot + ", tension " +
                   curve.tension_point + ": rotation_rad height_mm\n";
    for (size_t i = 0; i < curve.rotation_rad.size() && i < curve.height_m.size(); ++i) {
      max_rotation = std::max(max_rotation, curve.rotation_rad[i]);
      figure.data += FormatNumber(curve.rotation_rad[i]) + " " +
                     FormatNumber(curve.height_m[i] * 1e3) + "\n";
    }
    figure.data += "\n\n";
    blocks_by_foot[curve.foot].emplace_back(block++, curve.tension_point);
  }
  const size_t panels = blocks_by_foot.size();
  figure.body = "  set multiplot layout " + std::to_string(panels > 2 ? 2 : 1) + "," +
                std::to_string(panels > 1 ? 2 : 1) +
                " title \"Simulated foot height against rotation; hardware liftoff range "
                "dashed\"\n"
                "  set xlabel \"|vertebra rotation| (rad)\"\n"
                "  set ylabel \"foot height above reference (mm)\"\n"
                "  set grid\n  set key top left\n";
  for (const auto& [foot, blocks] : blocks_by_foot) {
    figure.body += "  set title \"foot " + foot + "\"\n  unset arrow\n";
    double max_x = max_rotation_by_foot[foot];
    for (const stats::FootRow& row : table.rows) {
      if (FootName(row.foot) != foot || row.hardware.n == 0) continue;
      max_x = std::max(max_x, row.hardware.max);
      for (const double x : {row.hardware.min, row.hardware.max}) {
        figure.body += "  set arrow from " + FormatNumber(x) + ", graph 0 to " +
                       FormatNumber(x) + ", graph 1 nohead dt 2 lw 2 lc rgb \"black\"\n";
      }
    }
    // arrows outside the x range would be drawn over the next panel
    figure.body += "  set xrange [0:" + FormatFixed(max_x * 1.05, 3) + "]\n";
    std::string plot;
    for (const auto& [index, tension] : blocks) {
      plot += std::string(plot.empty() ? "  plot " : ", \\\n       ") + "\"figure7.dat\" index " +
              std::to_string(index) + " using 1:2 with lines lw 2 title \"" + tension + "\"";
    }
    figure.body += plot + "\n";
  }
  figure.body += "  unset multiplot\n";
  return figure;
}

// ---------------------------------------------------------------------------------------
// the report pages

struct ReportContent {
  const ReportCommand* command = nullptr;
  const CampaignAnalysis* campaign = nullptr;
  const std::vector<stats::TrialValue>* values = nullptr;
  const stats::ResultsTable* table = nullptr;
  const SimColumn* sim = nullptr;
  /// The calibration (with the simulation).
  const ReportCalibration* calibration = nullptr;
  std::vector<Figure> figures;
  /// Per trial: its traces figure and verification image.
  std::vector<TrialEvidence> evidence;
  /// OK when gnuplot drew every figure.
  Status drawn;
};

std::string SimDescription(const ReportContent& content) {
  if (content.sim == nullptr) return "none (--no-sim)";
  const SimColumn& sim = *content.sim;
  return sim.results.model + ", " + Plural(static_cast<int64_t>(sim.results.runs.size()), "run") +
         " (" + sim.results.description + "), cache " + sim.cache_path.string();
}

// provenance lines shared by both pages: (label, text)
std::vector<std::pair<std::string, std::string>> Provenance(const ReportContent& content) {
  const CampaignAnalysis& campaign = *content.campaign;
  const int64_t trials = static_cast<int64_t>(campaign.analysis.outcomes.size());
  return {{"manifest", content.command->manifest_path.string() + " (" + Plural(trials, "trial") +
                           ", " + std::to_string(campaign.analysis.failed()) + " failed)"},
          {"calibration", campaign.calibration.Brief()},
          {"model", content.command->no_sim
                        ? std::string("none")
                        : ModelPathFrom(content.command->sweep.experiment).string()},
          {"simulation", SimDescription(content)},
          {"software", std::string("liftoff ") + kVersion}};
}

std::string ReportMarkdown(const ReportContent& content) {
  std::string text = "# liftoff report\n\n";
  for (const auto& [label, value] : Provenance(content)) text += "- " + label + ": " + value + "\n";
  text +=
      "\n## Table\n\n" + stats::RenderResultsTable(*content.table, stats::TableFormat::kMarkdown) +
      "\n" +
      stats::RenderTrialTable(*content.values, stats::TableFormat::kMarkdown,
                              content.campaign->analysis.calibration, content.table->lookup_rule) +
      "\n## Figures\n\n";
  if (!content.drawn.ok()) text += "Not drawn: " + content.drawn.ToString() + "\n\n";
  for (const Figure& figure : content.figures) {
    if (content.drawn.ok()) text += "![" + figure.title + "](figures/" + figure.name + ".png)\n\n";
    text += "Script [figures/" + figure.name + ".gp](figures/" + figure.name +
            ".gp), data [figures/" + figure.name + ".dat](figures/" + figure.name + ".dat)\n\n";
  }
  if (content.calibration) text += CalibrationMarkdown(*content.calibration, "##") + "\n";
  return text + TrialsMarkdown(*content.campaign, content.evidence, content.drawn.ok());
}

std::string HtmlNumber(double value) {
  return std::isfinite(value) ? FormatFixed(value, 3) : "&ndash;";
}

std::string HtmlTable(const stats::ResultsTable& table) {
  std::string html =
      "<table>\n<tr><th>Foot</th><th>Sim min</th><th>Sim max</th><th>HW n</th><th>HW min</th>"
      "<th>HW max</th><th>HW mean</th><th>HW sd</th><th>95 % CI of the mean</th></tr>\n";
  for (const stats::FootRow& row : table.rows) {
    const stats::Summary& hw = row.hardware;
    html += "<tr><td>" + std::string(FootName(row.foot)) + "</td><td>" +
            (row.sim ? HtmlNumber(row.sim->min_rad) : "&ndash;") + "</td><td>" +
            (row.sim ? HtmlNumber(row.sim->max_rad) : "&ndash;") + "</td><td>" +
            std::to_string(hw.n) + "</td><td>" + HtmlNumber(hw.min) + "</td><td>" +
            HtmlNumber(hw.max) + "</td><td>" + HtmlNumber(hw.mean) + "</td><td>" +
            HtmlNumber(hw.stddev) + "</td><td>[" + HtmlNumber(hw.ci_low) + ", " +
            HtmlNumber(hw.ci_high) + "]</td></tr>\n";
  }
  html += "</table>\n<p>" + EscapeMarkup(table.title) + ", rad; calibration " +
          EscapeMarkup(table.calibration) + "; lookup " + EscapeMarkup(table.lookup_rule) +
          "</p>\n";
  for (const std::string& note : table.notes) html += "<p>note: " + EscapeMarkup(note) + "</p>\n";
  return html;
}

Result<std::string> ReportHtml(const ReportContent& content, const fs::path& dir) {
  const fs::path figures_dir = dir / "figures";
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>liftoff report</title>\n<style>body{font-family:sans-serif;max-width:1250px;"
      "margin:auto}table{border-collapse:collapse}td,th{border:1px solid #999;padding:2px 8px;"
      "text-align:right}img{max-width:100%}.evidence{display:flex;gap:8px;align-items:flex-start}"
      ".evidence figure{flex:1;margin:4px 0}</style>\n</head>\n<body>\n<h1>liftoff "
      "report</h1>\n<ul>\n";
  for (const auto& [label, value] : Provenance(content)) {
    html += "<li>" + label + ": " + EscapeMarkup(value) + "</li>\n";
  }
  html += "</ul>\n<h2>Table</h2>\n" + HtmlTable(*content.table) + "<h2>Figures</h2>\n";
  if (!content.drawn.ok())
    html += "<p>Not drawn: " + EscapeMarkup(content.drawn.ToString()) + "</p>\n";
  for (const Figure& figure : content.figures) {
    if (!content.drawn.ok()) continue;
    LIFTOFF_ASSIGN_OR_RETURN(const std::string img,
                             InlinePng(figures_dir / (figure.name + ".png"), figure.title));
    html += "<figure>" + img + "<figcaption>" + EscapeMarkup(figure.title) +
            "</figcaption></figure>\n";
  }
  if (content.calibration) html += CalibrationHtml(*content.calibration);
  LIFTOFF_ASSIGN_OR_RETURN(const std::string trials, TrialsHtml(*content.campaign, content.evidence,
                                                                content.drawn.ok(), dir));
  return html + trials + "</body>\n</html>\n";
}

// ---------------------------------------------------------------------------------------
// writing it all

Status WriteTables(const ReportContent& content, const fs::path& dir) {
  const std::string& calibration = content.campaign->analysis.calibration;
  const std::string& rule = content.table->lookup_rule;
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(
      dir / "table.md", stats::RenderResultsTable(*content.table, stats::TableFormat::kMarkdown) +
                            "\n" +
                            stats::RenderTrialTable(*content.values, stats::TableFormat::kMarkdown,
                                                    calibration, rule)));
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(
      dir / "table.csv", stats::RenderResultsTable(*content.table, stats::TableFormat::kCsv)));
  return WriteFileAtomically(
      dir / "trials.csv",
      stats::RenderTrialTable(*content.values, stats::TableFormat::kCsv, calibration, rule));
}

Status WriteFiguresAndPages(ReportContent& content, std::ostream& err) {
  const fs::path& dir = content.command->output_dir;
  const fs::path figures_dir = dir / "figures";
  content.figures.push_back(
      TrialsFigure("trials", *content.values, content.sim ? &content.sim->results : nullptr));
  if (content.sim) {
    if (auto figure7 = Figure7(content.sim->curves, *content.table)) {
      content.figures.push_back(std::move(*figure7));
    }
  }
  if (content.calibration) {
    for (Figure& figure : CalibrationFigures(*content.calibration)) {
      content.figures.push_back(std::move(figure));
    }
    LIFTOFF_RETURN_IF_ERROR(WriteCalibrationFiles(*content.calibration, dir));
  }
  for (const Figure& figure : content.figures) {
    LIFTOFF_RETURN_IF_ERROR(
        WriteFigure(figure, figures_dir, content.command->gnuplot, content.drawn));
  }
  LIFTOFF_ASSIGN_OR_RETURN(
      content.evidence,
      WriteTrialEvidence(*content.campaign, dir, content.command->gnuplot, content.drawn, err));
  LIFTOFF_RETURN_IF_ERROR(WriteTables(content, dir));
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(dir / "report.md", ReportMarkdown(content)));
  LIFTOFF_ASSIGN_OR_RETURN(const std::string html, ReportHtml(content, dir));
  return WriteFileAtomically(dir / "report.html", html);
}

// the terminal summary: one line per foot, then where the report is
void PrintSummary(const ReportContent& content, std::ostream& out) {
  const CampaignAnalysis& campaign = *content.campaign;
  out << "report: " << Plural(static_cast<int64_t>(campaign.analysis.outcomes.size()), "trial")
      << ", " << campaign.analysis.failed() << " failed; calibration "
      << campaign.calibration.Brief() << "\n";
  for (const stats::FootRow& row : content.table->rows) {
    out << "  foot " << FootName(row.foot) << ": hardware " << row.hardware.Brief();
    if (row.sim) {
      out << "; simulation " << FormatFixed(row.sim->min_rad, 3) << " .. "
          << FormatFixed(row.sim->max_rad, 3) << " rad";
    }
    out << "\n";
  }
  if (content.sim) {
    out << "simulation: " << (content.sim->from_cache ? "from the cache " : "ran and cached in ")
        << content.sim->cache_path.string() << "\n";
  }
  if (content.calibration) out << CalibrationSummary(*content.calibration) << "\n";
  if (!content.drawn.ok()) {
    out << "figures: not drawn (" << content.drawn.ToString()
        << "); scripts and data are in " << (content.command->output_dir / "figures").string()
        << "\n";
  }
  out << "wrote " << (content.command->output_dir / "report.html").string() << " and report.md\n";
}

}  // namespace

int RunReport(const ReportCommand& command, std::ostream& out, std::ostream& err) {
  if (command.output_dir.empty()) {
    return ReportError(InvalidArgumentError("--output: name the report's folder"), err);
  }
  if (!command.no_sim) {
    auto checked = SweepOptionsFrom(command.sweep);
    if (!checked.ok()) return ReportError(checked.status(), err);
    if (Status fit = command.fit.Validate(); !fit.ok()) {
      return ReportError(
          InvalidArgumentError("--fit-min/--fit-max/--fit-step/--bootstrap: " + fit.message()),
          err);
    }
    if (Status ratio = command.ratio.Validate(); command.fit_ratio && !ratio.ok()) {
      return ReportError(InvalidArgumentError("--ratios: " + ratio.message()), err);
    }
    if (!command.fit_ratio && command.ratio.ratios != fit::RatioFitOptions{}.ratios) {
      return ReportError(InvalidArgumentError("--ratios: given without --fit-ratio"), err);
    }
    if (Status mc = command.monte_carlo.Validate(); !mc.ok()) {
      return ReportError(InvalidArgumentError("--mc-samples/--mc-sd-scale: " + mc.message()), err);
    }
  }

  // the trials, as the table command analyses them: all, a shard's, or merged from shards
  auto shard = ReportShardFlags(command);
  if (!shard.ok()) return ReportError(shard.status(), err);
  std::vector<fit::TensionSample> merged_draws;
  auto campaign = CampaignForReport(command, *shard, merged_draws, err);
  if (!campaign.ok()) return ReportError(campaign.status(), err);
  const Status outside = CheckInputsOutsideOutput(command, *campaign);
  if (!outside.ok()) return ReportError(outside, err);
  if (!command.shard.empty()) {
    const Status written = RunReportShard(command, *shard, *campaign, out, err);
    return written.ok() ? kExitOk : ReportError(written, err);
  }

  // the simulated column
  std::optional<SimColumn> sim;
  if (!command.no_sim) {
    auto column = SimulatedColumn(command, campaign->calibration, err);
    if (!column.ok()) return ReportError(column.status(), err);
    sim = std::move(column).value();
  }

  // the calibration: tension points ranked, the tension scale fitted, the Monte Carlo
  const std::vector<stats::TrialValue> values = campaign->analysis.Values();
  std::optional<ReportCalibration> calibration;
  if (sim) {
    auto calibrated =
        CalibrateCampaign(command, campaign->calibration, values, sim->results,
                          fs::path(sim->cache_path).replace_extension(".calibration.json"),
                          command.merge.empty() ? nullptr : &merged_draws, err);
    if (!calibrated.ok()) return ReportError(calibrated.status(), err);
    calibration = std::move(calibrated).value();
  }

  // the table, the figures, the pages
  const stats::ResultsTable table = stats::BuildResultsTable(
      values, sim ? &sim->results : nullptr, campaign->analysis.calibration,
      std::string(sync::LookupRuleName(campaign->analysis.rule)));
  ReportContent content;
  content.command = &command;
  content.campaign = &*campaign;
  content.values = &values;
  content.table = &table;
  content.sim = sim ? &*sim : nullptr;
  content.calibration = calibration ? &*calibration : nullptr;
  const Status written = WriteFiguresAndPages(content, err);
  if (!written.ok()) return ReportError(written, err);
  if (!content.drawn.ok()) err << "warning: figures: " << content.drawn.ToString() << '\n';
  PrintSummary(content, out);

  if (!campaign->first_failure.ok()) {
    err << "liftoff: " << campaign->analysis.failed() << " of "
        << campaign->analysis.outcomes.size() << " trials failed; the report holds the others\n";
    return ExitCodeFor(campaign->first_failure.code());
  }
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// the flags

Subcommand AddReportCommand(Command& parent) {
  auto command = std::make_shared<ReportCommand>();
  Command* app = parent.AddSubcommand(
      "report",
      "The campaign in one folder: every trial, the simulated column (cached), the tables, the "
      "figures (gnuplot), report.md and report.html");
  app->AddOption("manifest", command->manifest_path,
                  "Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV)")
      ->Required();
  app->AddOption("--output,-o", command->output_dir, "Folder to write the report in")
      ->Required();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  app->AddSwitch("--no-sim", command->no_sim, "Leave the simulation out");
  app->AddOption("--cache-dir", command->cache_dir,
                  "Cached sweeps (<key>.json) here (default: DIR/sim-cache)");
  app->AddOption("--gnuplot", command->gnuplot, "The gnuplot program")->ShowDefault();
  AddSweepFlags(*app, command->sweep);
  AddExperimentFlags(*app, command->sweep.experiment);  // its --progress is the report's too
  app->AddOption("--fit-min", command->fit.sigma_min, "Tension scale fitted from (sigma)")
      ->ShowDefault();
  app->AddOption("--fit-max", command->fit.sigma_max, "... to (sigma)")->ShowDefault();
  app->AddOption("--fit-step", command->fit.sigma_step, "Simulated every (sigma)")
      ->ShowDefault();
  app->AddOption("--bootstrap", command->fit.bootstrap_samples, "Bootstrap resamples of the fit")
      ->ShowDefault();
  app->AddSwitch("--fit-ratio", command->fit_ratio,
                 "Also fit the Buna-N / silicone stiffness ratio (a grid of runs per ratio)");
  std::vector<double>& ratios = command->ratio.ratios;
  app->AddOption("--ratios", ratios,
                 "With --fit-ratio: multipliers of the calibration's ratio tried, holding 1")
      ->CommaSeparated()
      ->ShowDefaultFrom([&ratios] { return JoinNumbers(ratios, ","); });
  app->AddOption("--mc-samples", command->monte_carlo.samples,
                  "Monte Carlo draws of the spring constants (0: none)")
      ->ShowDefault();
  app->AddOption("--mc-seed", command->monte_carlo.seed, "Monte Carlo seed")->ShowDefault();
  app->AddOption("--mc-sd-scale", command->monte_carlo.stddev_scale,
                  "Monte Carlo: Table I's standard deviations times this")
      ->ShowDefault();
  app->AddOption("--jobs,-j", command->jobs,
                  "Trials analysed at once (0: the machine's cores; same results for any)")
      ->ShowDefault();
  app->AddOption("--shard", command->shard,
                  "i/n: analyse shard i of n (trials and Monte Carlo draws) and write "
                  "DIR/shard-i-of-n.json instead of the report (docs/cluster.md)");
  app->AddOption("--merge", command->merge,
                  "Shard files (every shard of one run) merged into the report")
      ->OneOrMore();
  return RunsWith(app, command, RunReport);
}

}  // namespace liftoff::cli
