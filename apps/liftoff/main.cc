// liftoff: the command table. Each subcommand's flags map onto an options struct of
// liftoff/cli/commands.h; the work happens in its Run<Command>().
#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "liftoff/cli/capture_commands.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/synth_commands.h"
#include "liftoff/core/version.h"

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

void AddTestFlags(CLI::App* app, TestChoice& test) {
  app->add_option("--pulled", test.pulled_group, "Cable group the bend pulls: HR or HL")
      ->capture_default_str();
  app->add_option("--bend-percent", test.bend_percent,
                  "Bend each cable of the group to this percentage of its rest length")
      ->capture_default_str();
  app->add_option("--ramp-deg", test.ramp_deg,
                  "Rotating vertebra's ramp amplitude, degrees, signed by direction")
      ->capture_default_str();
  app->add_option("--ramp-s", test.ramp_s, "Ramp duration, seconds")->capture_default_str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"liftoff: measure robot foot-lifting tests against simulation"};
  app.set_version_flag("--version", std::string("liftoff ") + liftoff::kVersion);
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

  CaptureCommand capture;
  CLI::App* capture_app = app.add_subcommand(
      "capture", "Record a test from the controller's serial port: raw journal + controller log");
  capture_app->add_option("port", capture.port, "Serial port: device path, stable id or symlink")
      ->required();
  capture_app->add_option("--output,-o", capture.log_path, "Controller log to write")->required();
  capture_app->add_option("--journal", capture.journal_path, "Raw journal (default: LOG.journal)");
  capture_app->add_option("--baud", capture.baud_rate, "Line speed, bits/s")->capture_default_str();
  capture_app->add_flag("--start", capture.send_start,
                        "Send START with the test parameters and record them in the log");
  AddTestFlags(capture_app, capture.test);
  capture_app->add_option("--max-duration", capture.max_duration_s, "Stop after this long, s")
      ->capture_default_str();
  capture_app
      ->add_option("--first-frame-timeout", capture.first_frame_timeout_s,
                   "Fail when no frame arrives this long after opening, s (0: wait for ever)")
      ->capture_default_str();
  capture_app->add_flag("--no-stop-on-test-end", capture.no_stop_on_test_end,
                        "Keep capturing after the controller's TEST_END");
  capture_app
      ->add_option("--reconnect-poll", capture.reconnect_poll_s,
                   "Look for an unplugged port this often, s")
      ->capture_default_str();
  capture_app->add_option("--status", capture.status, "Status line: auto, live, lines or off")
      ->capture_default_str();
  AddCalibrationFlag(capture_app, capture.calibration);

  EmulateCommand emulate;
  CLI::App* emulate_app = app.add_subcommand(
      "emulate", "A test controller on a pseudo-terminal (prints its path), with fault injection");
  emulate_app->add_option("--rate", emulate.rate_hz, "Sample frames per second")
      ->capture_default_str();
  emulate_app->add_flag("--unpaced", emulate.unpaced, "Send as fast as the reader takes frames");
  emulate_app->add_flag("--autostart", emulate.autostart, "Start the test without a START command");
  AddTestFlags(emulate_app, emulate.test);
  emulate_app->add_option("--link", emulate.link_path,
                          "Stable symlink to the pseudo-terminal (kept across disconnects)");
  emulate_app->add_option("--corrupt", emulate.corrupt_probability,
                          "Probability that a byte gets a bit flipped");
  emulate_app->add_option("--drop", emulate.drop_probability,
                          "Probability that a frame is dropped");
  emulate_app->add_option("--stall-at", emulate.stall_at_s, "Pause the output at this time, s");
  emulate_app->add_option("--stall-for", emulate.stall_for_s, "... for this long, s");
  emulate_app->add_option("--disconnect-at", emulate.disconnect_at_s,
                          "Unplug at this time, s (needs --link)");
  emulate_app->add_option("--disconnect-for", emulate.disconnect_for_s, "... for this long, s");
  emulate_app->add_option("--drift-ppm", emulate.drift_ppm, "Device clock rate error, ppm");
  emulate_app->add_option("--seed", emulate.seed, "Seed of the fault generator")
      ->capture_default_str();
  emulate_app->add_option("--duration", emulate.duration_s, "Run this long, s (0: until done)");
  emulate_app->add_flag("--keep-running", emulate.keep_running,
                        "Keep running after the test ends (until Ctrl-C or --duration)");

  PortsCommand ports;
  CLI::App* ports_app = app.add_subcommand("ports", "List the serial ports of this machine");

  JournalCommand journal;
  CLI::App* journal_app =
      app.add_subcommand("journal", "Show a capture journal, or rebuild its controller log");
  journal_app->add_option("journal", journal.journal_path, "Capture journal")->required();
  journal_app->add_flag("--replay", journal.replay,
                        "Rebuild the controller log with live capture's parsing");
  journal_app->add_option("--output,-o", journal.output_path, "With --replay: log to write");
  journal_app->add_flag("--force", journal.force, "Overwrite an existing output file");
  journal_app->add_flag("--hex", journal.hex, "Dump bytes as hexadecimal");
  journal_app->add_option("--max-records", journal.max_records, "Dump at most this many records");
  AddCalibrationFlag(journal_app, journal.calibration);

  SynthCommand synth;
  CLI::App* synth_app = app.add_subcommand(
      "synth",
      "Render synthetic trials (video, controller log, ground truth) from a spec or a set");
  synth_app->add_option("spec", synth.spec_path, "Trial spec JSON (see --print-spec)");
  synth_app->add_option("--set", synth.set_name, "Write a whole named set: ci or paper");
  synth_app->add_option("--output,-o", synth.output_dir, "Folder for the files");
  synth_app->add_flag("--print-spec", synth.print_spec, "Print the default spec as JSON");
  synth_app->add_flag("--quiet,-q", synth.quiet, "No progress lines on stderr");
  AddCalibrationFlag(synth_app, synth.calibration);

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
    if (*capture_app) return RunCapture(capture, std::cout, std::cerr);
    if (*emulate_app) return RunEmulate(emulate, std::cout, std::cerr);
    if (*ports_app) return RunPorts(ports, std::cout, std::cerr);
    if (*journal_app) return RunJournal(journal, std::cout, std::cerr);
    if (*synth_app) return RunSynth(synth, std::cout, std::cerr);
  } catch (const std::exception& error) {
    std::cerr << "liftoff: internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitUsage;
}
