// liftoff: the command table. Each subcommand's flags map onto an options struct of
// liftoff/cli/commands.h; the work happens in its Run<Command>().
#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "liftoff/cli/commands.h"

namespace {

using namespace liftoff::cli;

void AddCalibrationFlag(CLI::App* app, CalibrationChoice& choice) {
  app->add_option("--calibration,-c", choice.calibration_path,
                  "Calibration JSON (default: the manifest's, else calib/laika-2018.json)");
}

void AddLookupFlags(CLI::App* app, LookupChoice& lookup) {
  app->add_option("--rule", lookup.rule,
                  "Angle lookup: linear (interpolate) or hold (last sample at or before, the "
                  "2018 authors' rule)")
      ->capture_default_str();
  app->add_option("--gap-threshold", lookup.gap_threshold_s,
                  "Samples further apart than this bracket a gap, seconds")
      ->capture_default_str();
  app->add_option("--max-past-end", lookup.max_past_end_s,
                  "Answer lookups up to this far past the log's last sample, seconds")
      ->capture_default_str();
  app->add_option("--max-bad-lines", lookup.max_bad_lines,
                  "Malformed log lines to skip (reported) before a log is rejected")
      ->capture_default_str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"liftoff: measure robot foot-lifting tests against simulation"};
  app.set_version_flag("--version", std::string("liftoff 0.1.0"));
  app.require_subcommand(1);

  TableCommand table;
  CLI::App* table_app = app.add_subcommand(
      "table", "Rotation at liftoff per trial and the per-foot table (paper Table IV layout)");
  table_app
      ->add_option("manifest", table.manifest_path,
                   "Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV)")
      ->required();
  AddCalibrationFlag(table_app, table.calibration);
  AddLookupFlags(table_app, table.lookup);
  table_app->add_option("--format,-f", table.format, "md, csv, latex or json")
      ->capture_default_str();
  table_app->add_option("--tables", table.tables, "both, trials or feet")->capture_default_str();
  table_app->add_option("--sim", table.sim_path, "Simulation results JSON for the sim columns");
  table_app->add_option("--output,-o", table.output_path, "Write here instead of stdout");

  Import2018Command import;
  CLI::App* import_app = app.add_subcommand(
      "import-2018", "Turn a 2018 Laika folder (logs + video times CSV) into a trial manifest");
  import_app->add_option("folder", import.folder, "Folder with TestN*.txt and the times CSV")
      ->required();
  import_app->add_option("--output,-o", import.output_path, "Manifest to write")->required();
  import_app->add_flag("--force", import.force, "Overwrite an existing manifest");

  SyncCommand sync;
  CLI::App* sync_app =
      app.add_subcommand("sync", "Rotation at liftoff from one log and the two video instants");
  sync_app->add_option("log", sync.log_path, "Controller log")->required();
  sync_app->add_option("--led-on", sync.led_on_s, "Video time of the LED switch-on, s")->required();
  sync_app->add_option("--liftoff", sync.liftoff_s, "Video time of the liftoff, s")->required();
  sync_app->add_option("--uncertainty", sync.uncertainty_s, "Timing uncertainty of each instant, s")
      ->capture_default_str();
  sync_app->add_option("--log-format", sync.log_format, "auto, liftoff or laika-2018")
      ->capture_default_str();
  AddCalibrationFlag(sync_app, sync.calibration);
  AddLookupFlags(sync_app, sync.lookup);
  sync_app->add_flag("--json", sync.json, "JSON output");

  LogCommand log;
  CLI::App* log_app = app.add_subcommand(
      "log", "What a controller log holds; optionally convert it to liftoff's format");
  log_app->add_option("log", log.log_path, "Controller log")->required();
  log_app->add_option("--log-format", log.log_format, "auto, liftoff or laika-2018")
      ->capture_default_str();
  AddCalibrationFlag(log_app, log.calibration);
  log_app->add_option("--max-bad-lines", log.max_bad_lines, "Malformed lines to skip (reported)")
      ->capture_default_str();
  log_app->add_option("--gap-threshold", log.gap_threshold_s, "Gap threshold, seconds")
      ->capture_default_str();
  log_app->add_option("--convert", log.convert_path, "Write the log in liftoff's format here");
  log_app->add_flag("--json", log.json, "JSON output");

  CalibCommand calib;
  CLI::App* calib_app =
      app.add_subcommand("calib", "Show a calibration, its provenance and its conversions");
  calib_app->add_option("calibration", calib.calibration.calibration_path,
                        "Calibration JSON (default: calib/laika-2018.json)");
  calib_app->add_flag("--json", calib.json, "Print the calibration as JSON");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? kExitOk : kExitUsage;
  }

  try {
    if (*table_app) return RunTable(table, std::cout, std::cerr);
    if (*import_app) return RunImport2018(import, std::cout, std::cerr);
    if (*sync_app) return RunSync(sync, std::cout, std::cerr);
    if (*log_app) return RunLog(log, std::cout, std::cerr);
    if (*calib_app) return RunCalib(calib, std::cout, std::cerr);
  } catch (const std::exception& error) {
    std::cerr << "liftoff: internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitUsage;
}
