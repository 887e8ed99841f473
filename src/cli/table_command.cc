// `liftoff table`: the campaign's per-trial and per-foot tables.
#include "liftoff/cli/commands.h"

#include <memory>
#include <ostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/capture/laika2018.h"
#include "liftoff/cli/figures.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/output.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/stats/sim_results.h"
#include "liftoff/stats/table.h"
#include "liftoff/sync/trial_analysis.h"
#include "liftoff/video/verification.h"

namespace liftoff::cli {
namespace {

// Sends finished text to the output file, or to `out` when none is named.
int Emit(const std::string& text, const std::filesystem::path& output_path, std::ostream& out,
         std::ostream& err) {
  if (output_path.empty()) {
    out << text;
    return kExitOk;
  }
  const Status written = WriteFileAtomically(output_path, text);
  if (!written.ok()) return ReportError(written, err);
  err << "wrote " << output_path.string() << '\n';
  return kExitOk;
}

// the ids of the manifest's trials, in order
std::vector<std::string> TrialIds(const TrialManifest& manifest) {
  std::vector<std::string> ids;
  for (const TrialRecord& trial : manifest.trials) ids.push_back(trial.id);
  return ids;
}

// the plot's files: FILE's stem with .dat, .gp, .png and .svg, beside FILE
std::string PlotName(const std::filesystem::path& plot_path) {
  return plot_path.stem().string();
}

// what `table` writes: the tables, the plot's files, a verification image per trial with a
// video
std::vector<NamedPath> TableOutputs(const TableCommand& command, const TrialManifest& manifest) {
  std::vector<NamedPath> outputs = {{"--output", command.output_path}};
  if (!command.plot_path.empty()) {
    for (std::filesystem::path& file :
         FigureFiles(command.plot_path.parent_path(), PlotName(command.plot_path))) {
      outputs.push_back({"--plot", std::move(file)});
    }
  }
  if (command.verify_dir.empty()) return outputs;
  const std::vector<std::string> stems = TrialFileStems(TrialIds(manifest));
  for (size_t i = 0; i < manifest.trials.size(); ++i) {
    if (!manifest.trials[i].video_path) continue;
    outputs.push_back({"--verify-dir", command.verify_dir / (stems[i] + ".png")});
  }
  return outputs;
}

// The per-trial figure (figures.h, TrialsFigure) as FILE's stem .dat, .gp, .png and .svg
// beside FILE. Errors: a file that cannot be written; gnuplot missing or failing (the
// script and data are written).
Status WritePlot(const TableCommand& command, const std::vector<stats::TrialValue>& values,
                 const stats::SimResults* sim, std::ostream& err) {
  const std::filesystem::path dir = command.plot_path.parent_path();
  const std::string name = PlotName(command.plot_path);
  Status drawn;
  LIFTOFF_RETURN_IF_ERROR(WriteFigure(TrialsFigure(name, values, sim),
                                      dir.empty() ? std::filesystem::path(".") : dir,
                                      command.gnuplot, drawn));
  if (!drawn.ok()) {
    return Status(drawn.code(), "--plot: " + drawn.message() + " (the script and data are in " +
                                    (dir / (name + ".gp")).string() + ")");
  }
  err << "wrote " << (dir / (name + ".svg")).string() << " and .png (script " << name
      << ".gp, data " << name << ".dat)\n";
  return Status::Ok();
}

// what `table` reads: the manifest (or the 2018 folder's times), the calibration, the
// simulation results, every trial's log and video
std::vector<NamedPath> TableInputs(const TableCommand& command, const TrialManifest& manifest,
                                   const Calibration& calibration) {
  std::vector<NamedPath> inputs = TrialInputs(manifest);
  std::error_code error;
  inputs.push_back({"MANIFEST", std::filesystem::is_directory(command.manifest_path, error)
                                    ? command.manifest_path / capture::kLaika2018TimesCsv
                                    : command.manifest_path});
  inputs.push_back({"calibration", calibration.source_path});
  inputs.push_back({"--sim", command.sim_path});
  return inputs;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// liftoff table

std::vector<std::string> OutcomeNotes(const sync::TrialOutcome& outcome) {
  std::ostringstream lines;
  PrintLogWarnings(outcome.log_report, lines);
  if (outcome.video) {
    lines << "note: " << outcome.trial.id << ": video: " << outcome.video->Brief() << '\n';
    for (const std::string& warning : outcome.video->warnings) {
      lines << "warning: " << outcome.trial.id << ": video: " << warning << '\n';
    }
  }
  if (!outcome.status.ok()) {
    lines << "error: " << outcome.status.ToString() << '\n';
  } else {
    for (const std::string& warning : outcome.measurement->lookup.warnings) {
      lines << "note: " << outcome.trial.id << ": " << warning << '\n';
    }
  }
  std::vector<std::string> notes;
  std::istringstream split(lines.str());
  for (std::string line; std::getline(split, line);) notes.push_back(line);
  return notes;
}

Result<CampaignAnalysis> LoadCampaign(const std::filesystem::path& manifest_path,
                                      const CalibrationChoice& calibration_choice,
                                      const LookupChoice& lookup_choice, std::ostream& err) {
  // options, then inputs: manifest (or a 2018 folder read as one) and calibration
  auto lookup = LookupOptionsFrom(lookup_choice);
  if (!lookup.ok()) return lookup.status();
  CampaignAnalysis campaign;
  auto manifest = LoadTrials(manifest_path, err);
  if (!manifest.ok()) return manifest.status();
  campaign.manifest = std::move(manifest).value();
  auto calibration = ChooseCalibration(
      calibration_choice, campaign.manifest.calibration_path.value_or(std::filesystem::path()));
  if (!calibration.ok()) return calibration.status();
  campaign.calibration = std::move(calibration).value();
  campaign.analysis.calibration = campaign.calibration.Brief();
  campaign.analysis.rule = lookup->rule;
  return campaign;
}

Result<CampaignAnalysis> AnalyzeCampaign(const std::filesystem::path& manifest_path,
                                         const CalibrationChoice& calibration_choice,
                                         const LookupChoice& lookup_choice, const CampaignRun& run,
                                         std::ostream& err) {
  if (auto progress = ProgressLine::Create(run.progress, "--progress", "video", err);
      !progress.ok()) {
    return progress.status();
  }
  auto loaded = LoadCampaign(manifest_path, calibration_choice, lookup_choice, err);
  if (!loaded.ok()) return loaded.status();
  CampaignAnalysis& campaign = *loaded;

  // every trial through sync (videos without times through video analysis)
  sync::AnalysisOptions options;
  options.lookup = *LookupOptionsFrom(lookup_choice);
  options.log.max_bad_lines = lookup_choice.max_bad_lines;
  auto outcomes = AnalyzeTrials(campaign.manifest, campaign.calibration, options, run,
                                campaign.trial_indices, err);
  if (!outcomes.ok()) return outcomes.status();
  campaign.analysis.outcomes = std::move(outcomes).value();

  // what a person should know about each trial, on `err` and kept per trial
  for (const sync::TrialOutcome& outcome : campaign.analysis.outcomes) {
    std::vector<std::string>& notes = campaign.notes.emplace_back(OutcomeNotes(outcome));
    for (const std::string& line : notes) err << line << '\n';
    if (!outcome.status.ok() && campaign.first_failure.ok()) {
      campaign.first_failure = outcome.status;
    }
  }
  return loaded;
}

int RunTable(const TableCommand& command, std::ostream& out, std::ostream& err) {
  // flags
  const auto format = TableFormatFlag(command.format);
  if (!format.ok()) return ReportError(format.status(), err);
  if (command.tables != "both" && command.tables != "trials" && command.tables != "feet") {
    return ReportError(InvalidArgumentError("--tables: expected both, trials or feet, got \"" +
                                            command.tables + "\""),
                       err);
  }
  if (!command.plot_path.empty()) {
    const std::string extension = command.plot_path.extension().string();
    const std::string name = PlotName(command.plot_path);
    if ((extension != ".svg" && extension != ".png") || name.empty() || name.front() == '.') {
      return ReportError(InvalidArgumentError("--plot: expected FILE.svg or FILE.png, got \"" +
                                              command.plot_path.string() + "\""),
                         err);
    }
  }
  std::optional<stats::SimResults> sim = command.sim_results;
  if (!sim && !command.sim_path.empty()) {
    auto loaded = stats::LoadSimResults(command.sim_path);
    if (!loaded.ok()) return ReportError(loaded.status(), err);
    sim = std::move(loaded).value();
  }

  // every trial; failures are reported and the rest still tabulated
  CampaignRun run;
  run.progress = command.progress;
  auto campaign =
      AnalyzeCampaign(command.manifest_path, command.calibration, command.lookup, run, err);
  if (!campaign.ok()) return ReportError(campaign.status(), err);
  // nothing is written before this: no output may be one of the inputs
  if (const int refused = RefuseToOverwriteInputs(
          TableOutputs(command, campaign->manifest),
          TableInputs(command, campaign->manifest, campaign->calibration), err);
      refused != kExitOk) {
    return refused;
  }
  const sync::ManifestAnalysis& analysis = campaign->analysis;
  const Status first_failure = campaign->first_failure;

  // tables
  const std::vector<stats::TrialValue> values = analysis.Values();
  const std::string rule_name(sync::LookupRuleName(analysis.rule));
  const stats::ResultsTable table =
      stats::BuildResultsTable(values, sim ? &*sim : nullptr, analysis.calibration, rule_name);
  std::string text;
  if (command.tables == "trials") {
    text = stats::RenderTrialTable(values, *format, analysis.calibration, rule_name);
  } else if (command.tables == "feet" || *format == stats::TableFormat::kJson) {
    text = stats::RenderResultsTable(table, *format);  // JSON holds the trials too
  } else {
    text = stats::RenderTrialTable(values, *format, analysis.calibration, rule_name) + "\n" +
           stats::RenderResultsTable(table, *format);
  }
  const int emitted = Emit(text, command.output_path, out, err);
  if (emitted != kExitOk) return emitted;
  Status verified;
  if (!command.verify_dir.empty()) {
    const TrialVerifications written = WriteTrialVerifications(
        analysis, TrialFileStems(TrialIds(campaign->manifest)), command.verify_dir, err);
    for (const std::string& line : written.written) err << "wrote " << line << '\n';
    verified = written.first_failure;
  }
  if (!command.plot_path.empty() && verified.ok()) {
    verified = WritePlot(command, values, sim ? &*sim : nullptr, err);
  }

  if (!first_failure.ok()) {
    err << "liftoff: " << analysis.failed() << " of " << analysis.outcomes.size()
        << " trials failed; the table holds the others\n";
    return ExitCodeFor(first_failure.code());
  }
  return verified.ok() ? kExitOk : ExitCodeFor(verified.code());
}

Subcommand AddTableCommand(Command& parent) {
  auto command = std::make_shared<TableCommand>();
  Command* app = parent.AddSubcommand(
      "table", "Rotation at liftoff per trial and the per-foot table (paper Table IV layout)");
  app->AddOption("manifest", command->manifest_path,
                  "Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV)")
      ->Required();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  app->AddOption("--format,-f", command->format, "md, csv, latex or json")->ShowDefault();
  app->AddOption("--tables", command->tables, "both, trials or feet")->ShowDefault();
  app->AddOption("--sim", command->sim_path, "Simulation results JSON for the sim columns");
  app->AddOption("--output,-o", command->output_path, "Write here instead of stdout");
  app->AddOption("--plot", command->plot_path,
                  "Draw each trial's liftoff rotation beside the simulation with gnuplot: "
                  "FILE.svg and FILE.png, its script FILE.gp and data FILE.dat beside them");
  app->AddOption("--gnuplot", command->gnuplot, "The gnuplot program (for --plot)")
      ->ShowDefault();
  app->AddOption("--verify-dir", command->verify_dir,
                  "Write a verification image per video-analysed trial here (<id>.png)");
  app->AddOption("--progress", command->progress,
                  "Video analysis progress on stderr: auto, live, lines or off")
      ->ShowDefault();
  return RunsWith(app, command, RunTable);
}

}  // namespace liftoff::cli
