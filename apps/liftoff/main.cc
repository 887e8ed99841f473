// liftoff: the command table. Each subcommand's flags map onto an options struct of
// liftoff/cli/commands.h; the work happens in its Run<Command>().
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "liftoff/cli/capture_commands.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/cli/sim_commands.h"
#include "liftoff/cli/synth_commands.h"
#include "liftoff/cli/video_commands.h"
#include "liftoff/core/json.h"
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

// the clip analysis' regions, foot, scale, threshold and exposure (`video` and `sync`);
// the options are returned so a mode flag can require or exclude them
std::vector<CLI::Option*> AddClipFlags(CLI::App* app, ClipChoice& clip) {
  std::vector<CLI::Option*> options;
  options.push_back(app->add_option(
      "--led-roi", clip.led_roi, "LED region x,y,w,h in pixels (default: located automatically)"));
  options.push_back(app->add_option("--foot-roi", clip.foot_roi,
                                    "Foot region x,y,w,h in pixels: the foot at rest and room "
                                    "above it (without it: the LED only)"));
  options.push_back(
      app->add_option("--foot", clip.foot, "Check that the tracked foot shows this foot's tape colour: A, B, C or D"));
  options.push_back(
      app->add_option("--px-per-mm", clip.px_per_mm,
                      "Image scale at the foot, px per mm (default: from the foot's width)"));
  CLI::Option* threshold_mm =
      app->add_option("--threshold-mm", clip.threshold_mm, "Liftoff threshold above rest, mm")
          ->capture_default_str();
  options.push_back(threshold_mm);
  options.push_back(
      app->add_option("--threshold-px", clip.threshold_px,
                      "Liftoff threshold above rest, px (> 0; instead of --threshold-mm)")
          ->excludes(threshold_mm));
  options.push_back(app->add_option(
      "--exposure-ms", clip.exposure_ms,
      "Camera exposure per frame, ms, at most the frame interval (default 0: unknown; the LED "
      "then allows any exposure up to the frame interval, the foot takes half the frame "
      "interval)"));
  return options;
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

void AddSimFlags(CLI::App* app, SimExperimentChoice& choice) {
  app->add_option("--model", choice.model_path,
                  "Model JSON (default: the bundled samples/models/laika.json)");
  app->add_option("--pulled", choice.pulled,
                  "Cable group the bend pulls: HR or HL (default: the foot's motion)");
  app->add_option("--rotation", choice.rotation,
                  "Ramp direction: + or - (write --rotation=-; default: the foot's motion)");
  app->add_option("--bend-fraction", choice.bend_fraction,
                  "Bend each pulled cable to this fraction of its rest length (default 0.8)");
  app->add_option("--bend-start-s", choice.bend_start_s, "Bend start, s (default 2)");
  app->add_option("--bend-speed", choice.bend_speed_m_per_s,
                  "Rest-length shortening speed, m/s (default 0.025)");
  app->add_option("--ramp-deg", choice.ramp_deg,
                  "Final |rotation| of the ramp, degrees (default 60)");
  app->add_option("--ramp-s", choice.ramp_s, "Ramp duration, s (default 40)");
  app->add_option("--ramp-start-s", choice.ramp_start_s, "Ramp start, s (default 6)");
  app->add_option("--drop-height-m", choice.drop_height_m,
                  "Drop height above the standing pose, m (default 0.05)");
  app->add_option("--reference-s", choice.reference_s,
                  "Instant of the reference foot heights, s (default 5)");
  app->add_option("--threshold-mm", choice.threshold_mm,
                  "Liftoff: height above the reference, mm (default 1)");
  app->add_option("--sample-period-s", choice.sample_period_s, "Sampling period, s (default 0.01)");
  app->add_option("--ground-clearance-mm", choice.ground_clearance_mm,
                  "Standing check: non-foot geometry this close to the ground rests on it, mm "
                  "(default 1)");
  app->add_option("--stop-after-rad", choice.stop_after_rad,
                  "Stop once |rotation| is this far past the first liftoff, rad (default: never)");
  app->add_option("--damping", choice.damping_n_s_per_m, "Cable damping, N*s/m (default 10)");
  app->add_option("--pretension-ratios", choice.pretension_ratios,
                  "T0/k of HT,HB,saddles,sides in m (default 0.006,0.015,0.052,0.004)");
  app->add_option("--friction", choice.friction,
                  "Ground friction coefficient (default: the model's)");
  app->add_option("--spine-friction", choice.spine_friction,
                  "Friction of the spine and hips with the ground (default: the model's)");
  app->add_option("--marker-height-m", choice.marker_height_m,
                  "Foot markers this far above the feet's bottoms, m (default: the model's)");
  app->add_option("--attachment", choice.attachment,
                  "Cable ends: node or surface (default: the model's)");
  app->add_option("--rest-reference", choice.rest_reference,
                  "Rest length from the attachment or node distance (default: the model's)");
  app->add_option("--collisions", choice.collisions,
                  "feet, ground (spine and hips with the ground too), self (spine rods with each "
                  "other) or all (default: the model's)");
  app->add_option("--damping-cap", choice.damping_cap,
                  "Cap cable damping at the spring term: on or off (default: the model's)");
  app->add_option("--dt", choice.dt_s,
                  "Engine time step, s (default " +
                      liftoff::FormatNumber(liftoff::sim::ExperimentOptions().engine.time_step_s) +
                      ")");
  app->add_flag("--implicit-stiffness", choice.implicit_stiffness,
                "Treat cable stiffness implicitly too");
  app->add_option("--solver-iterations", choice.solver_iterations,
                  "Contact solver sweeps per step (default 50)");
  app->add_option("--contact-bias", choice.contact_bias,
                  "Fraction of a penetration removed per step (default 0.2)");
  app->add_option("--progress", choice.progress, "Progress on stderr: auto, live, lines or off")
      ->capture_default_str();
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
  table_app->add_option("--plot", table.plot_path,
                        "Write the hardware-vs-simulation plot here (SVG)");
  table_app->add_option("--verify-dir", table.verify_dir,
                        "Write a verification image per video-analysed trial here (<id>.png)");
  table_app
      ->add_option("--progress", table.progress,
                   "Video analysis progress on stderr: auto, live, lines or off")
      ->capture_default_str();

  ReportCommand report;
  CLI::App* report_app = app.add_subcommand(
      "report",
      "The campaign in one folder: every trial, the simulated column (cached), the tables, the "
      "figures (gnuplot), report.md and report.html");
  report_app
      ->add_option("manifest", report.manifest_path,
                   "Trial manifest (JSON), or a 2018 Laika folder (logs + video times CSV)")
      ->required();
  report_app->add_option("--output,-o", report.output_dir, "Folder to write the report in")
      ->required();
  AddCalibrationFlag(report_app, report.calibration);
  AddLookupFlags(report_app, report.lookup);
  report_app->add_flag("--no-sim", report.no_sim, "Leave the simulation out");
  report_app->add_option("--cache-dir", report.cache_dir,
                         "Cached sweeps (<key>.json) here (default: DIR/sim-cache)");
  report_app->add_option("--gnuplot", report.gnuplot, "The gnuplot program")
      ->capture_default_str();
  report_app->add_option("--feet", report.sweep.feet, "Simulated feet, comma-separated")
      ->capture_default_str();
  report_app
      ->add_option("--tensions", report.sweep.tensions,
                   "Simulated tension points, comma-separated names or 0..4, or all")
      ->capture_default_str();
  report_app->add_option("--threads", report.sweep.threads, "Sweep worker threads (0: all cores)")
      ->capture_default_str();
  AddSimFlags(report_app, report.sweep.experiment);  // its --progress is the report's too
  report_app->add_option("--fit-min", report.fit.sigma_min, "Tension scale fitted from (sigma)")
      ->capture_default_str();
  report_app->add_option("--fit-max", report.fit.sigma_max, "... to (sigma)")
      ->capture_default_str();
  report_app->add_option("--fit-step", report.fit.sigma_step, "Simulated every (sigma)")
      ->capture_default_str();
  report_app
      ->add_option("--bootstrap", report.fit.bootstrap_samples, "Bootstrap resamples of the fit")
      ->capture_default_str();
  report_app
      ->add_option("--mc-samples", report.monte_carlo.samples,
                   "Monte Carlo draws of the spring constants (0: none)")
      ->capture_default_str();
  report_app->add_option("--mc-seed", report.monte_carlo.seed, "Monte Carlo seed")
      ->capture_default_str();
  report_app
      ->add_option("--mc-sd-scale", report.monte_carlo.stddev_scale,
                   "Monte Carlo: Table I's standard deviations times this")
      ->capture_default_str();

  Import2018Command import;
  CLI::App* import_app = app.add_subcommand(
      "import-2018", "Turn a 2018 Laika folder (logs + video times CSV) into a trial manifest");
  import_app->add_option("folder", import.folder, "Folder with TestN*.txt and the times CSV")
      ->required();
  import_app->add_option("--output,-o", import.output_path, "Manifest to write")->required();
  import_app->add_flag("--force", import.force, "Overwrite an existing manifest");

  SyncCommand sync;
  CLI::App* sync_app = app.add_subcommand(
      "sync",
      "Rotation at liftoff from one log and the two video instants, given or found in the clip");
  sync_app->add_option("log", sync.log_path, "Controller log")->required();
  CLI::Option* led_on =
      sync_app->add_option("--led-on", sync.led_on_s, "Video time of the LED switch-on, s");
  CLI::Option* liftoff =
      sync_app->add_option("--liftoff", sync.liftoff_s, "Video time of the liftoff, s");
  CLI::Option* uncertainty =
      sync_app
          ->add_option("--uncertainty", sync.uncertainty_s, "Timing uncertainty of each instant, s")
          ->capture_default_str();
  led_on->needs(liftoff);
  liftoff->needs(led_on);
  CLI::Option* sync_video =
      sync_app
          ->add_option("--video", sync.video_path,
                       "Find the two instants in this clip (instead of --led-on and --liftoff)")
          ->excludes(led_on)
          ->excludes(liftoff)
          ->excludes(uncertainty);
  for (CLI::Option* option : AddClipFlags(sync_app, sync.clip)) option->needs(sync_video);
  sync_app
      ->add_option("--verify", sync.verify_path, "With --video: write a verification image (PNG)")
      ->needs(sync_video);
  sync_app
      ->add_option("--progress", sync.progress,
                   "With --video: progress on stderr: auto, live, lines or off")
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
  capture_app->add_flag("--force", capture.force,
                        "Replace an existing log and journal (an earlier recording)");
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
  synth_app->add_option("--set", synth.set_name, "Write a whole named set: ci, paper, ci3d or hard3d (the 3D camera)");
  synth_app->add_option("--output,-o", synth.output_dir, "Folder for the files");
  synth_app->add_flag("--print-spec", synth.print_spec, "Print the default spec as JSON");
  synth_app->add_flag("--quiet,-q", synth.quiet, "No progress lines on stderr");
  AddCalibrationFlag(synth_app, synth.calibration);

  VideoCommand video;
  CLI::App* video_app = app.add_subcommand(
      "video", "Find the LED switch-on and the foot's liftoff in one clip, with proof");
  video_app->add_option("clip", video.video_path, "Video file")->required();
  AddClipFlags(video_app, video.clip);
  video_app
      ->add_option(
          "--rest-window", video.clip.rest_window,
          "Foot rest window FROM,TO in s from the LED switch-on (write --rest-window=-1,0)")
      ->capture_default_str();
  video_app->add_option("--liftoff", video.clip.liftoff, "Liftoff instant: threshold or onset")
      ->capture_default_str();
  video_app->add_option("--verify", video.verify_path, "Write a verification image (PNG)");
  video_app->add_option("--annotate", video.annotate_path,
                        "Write the clip with the detections drawn (Motion JPEG AVI)");
  video_app->add_flag("--json", video.json, "JSON output");
  video_app
      ->add_option("--progress", video.progress, "Progress on stderr: auto, live, lines or off")
      ->capture_default_str();

  CLI::App* sim_app = app.add_subcommand(
      "sim", "Simulate the foot-lifting test: one run, the tension sweep, MJCF export");
  sim_app->require_subcommand(1);
  SimRunCommand sim_run;
  CLI::App* sim_run_app = sim_app->add_subcommand(
      "run", "One simulated test: each foot's liftoff rotation, optionally the height curves");
  sim_run_app->add_option("--foot", sim_run.foot, "Foot the test targets: A, B, C or D")
      ->capture_default_str();
  sim_run_app
      ->add_option("--tension", sim_run.tension,
                   "Tension point: low, med-low, mean, med-high, high or 0..4")
      ->capture_default_str();
  sim_run_app->add_option(
      "--stiffness", sim_run.stiffness,
      "Explicit stiffnesses SILICONE,BUNA_N,SPRING in N/m (instead of --tension)");
  AddSimFlags(sim_run_app, sim_run.experiment);
  sim_run_app->add_flag("--json", sim_run.json, "JSON output");
  sim_run_app->add_option("--curves", sim_run.curves_path,
                          "Write the foot-height curves (CSV) here; - for stdout");

  SimSweepCommand sim_sweep;
  CLI::App* sim_sweep_app = sim_app->add_subcommand(
      "sweep",
      "The tension points x the four foot motions in parallel (paper Table IV's sim columns)");
  sim_sweep_app->add_option("--feet", sim_sweep.feet, "Feet, comma-separated")
      ->capture_default_str();
  sim_sweep_app
      ->add_option("--tensions", sim_sweep.tensions,
                   "Tension points, comma-separated names or 0..4, or all")
      ->capture_default_str();
  sim_sweep_app->add_option("--threads", sim_sweep.threads, "Worker threads (0: all cores)")
      ->capture_default_str();
  sim_sweep_app->add_flag("--full-ramp", sim_sweep.full_ramp,
                          "Run every test to the end of the ramp (same values, slower)");
  AddSimFlags(sim_sweep_app, sim_sweep.experiment);
  sim_sweep_app->add_option("--output,-o", sim_sweep.output_path,
                            "Write the simulation results JSON (for liftoff table --sim)");
  sim_sweep_app->add_flag("--json", sim_sweep.json, "Print the results JSON instead of the table");
  sim_sweep_app->add_option(
      "--hardware", sim_sweep.hardware_path,
      "Trial manifest or 2018 Laika folder: also print the hardware-vs-simulation table");
  sim_sweep_app
      ->add_option("--format,-f", sim_sweep.format, "Hardware table format: md, csv, latex or json")
      ->capture_default_str();
  AddCalibrationFlag(sim_sweep_app, sim_sweep.calibration);
  AddLookupFlags(sim_sweep_app, sim_sweep.lookup);

  SimExportMjcfCommand sim_export;
  CLI::App* sim_export_app =
      sim_app->add_subcommand("export-mjcf", "Write the model as a MuJoCo MJCF file");
  sim_export_app->add_option("--output,-o", sim_export.output_path, "MJCF file; - for stdout")
      ->required();
  sim_export_app->add_option("--foot", sim_export.foot, "The experiment's model for this foot")
      ->capture_default_str();
  sim_export_app->add_option("--tension", sim_export.tension, "... at this tension point")
      ->capture_default_str();
  sim_export_app->add_flag("--as-is", sim_export.as_is,
                           "Export the model file as written (no tension point applied)");
  sim_export_app
      ->add_option("--hinge-drive", sim_export.hinge_drive,
                   "equality (set by a runner each step) or actuator (a position servo)")
      ->capture_default_str();
  sim_export_app->add_option("--lift-m", sim_export.lift_m, "Raise the free bodies by this, m")
      ->capture_default_str();
  AddSimFlags(sim_export_app, sim_export.experiment);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? kExitOk : kExitUsage;
  }

  try {
    if (*table_app) return RunTable(table, std::cout, std::cerr);
    if (*report_app) return RunReport(report, std::cout, std::cerr);
    if (*import_app) return RunImport2018(import, std::cout, std::cerr);
    if (*sync_app) return RunSync(sync, std::cout, std::cerr);
    if (*log_app) return RunLog(log, std::cout, std::cerr);
    if (*calib_app) return RunCalib(calib, std::cout, std::cerr);
    if (*capture_app) return RunCapture(capture, std::cout, std::cerr);
    if (*emulate_app) return RunEmulate(emulate, std::cout, std::cerr);
    if (*ports_app) return RunPorts(ports, std::cout, std::cerr);
    if (*journal_app) return RunJournal(journal, std::cout, std::cerr);
    if (*synth_app) return RunSynth(synth, std::cout, std::cerr);
    if (*video_app) return RunVideo(video, std::cout, std::cerr);
    if (*sim_run_app) return RunSimRun(sim_run, std::cout, std::cerr);
    if (*sim_sweep_app) return RunSimSweep(sim_sweep, std::cout, std::cerr);
    if (*sim_export_app) return RunSimExportMjcf(sim_export, std::cout, std::cerr);
  } catch (const std::exception& error) {
    std::cerr << "liftoff: internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitUsage;
}
