#include "liftoff/cli/capture_commands.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <memory>
#include <ostream>

#include "cli_common.h"
#include "liftoff/cli/progress_line.h"
#include "liftoff/capture/capture_session.h"
#include "liftoff/capture/emulator.h"
#include "liftoff/capture/journal.h"
#include "liftoff/capture/serial_port.h"
#include "liftoff/core/output.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {
namespace {

// Set by SIGINT/SIGTERM; a lock-free atomic is safe to store from a handler.
std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void OnStopSignal(int) { g_stop_requested.store(true); }

// SIGINT and SIGTERM set g_stop_requested while in scope; the previous handlers come back
// at the end. SA_RESETHAND: a second Ctrl-C acts as it would without us (kills).
class ScopedStopSignals {
 public:
  explicit ScopedStopSignals(bool install) : installed_(install) {
    g_stop_requested.store(false);
    if (!installed_) return;
    struct sigaction action {};
    action.sa_handler = OnStopSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = static_cast<int>(SA_RESETHAND);
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
  }
  ~ScopedStopSignals() {
    if (!installed_) return;
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  ScopedStopSignals(const ScopedStopSignals&) = delete;
  ScopedStopSignals& operator=(const ScopedStopSignals&) = delete;

 private:
  bool installed_;
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

// TestChoice as the emulator's TestParameters (kInvalidArgument naming the flag).
Result<capture::TestParameters> TestParametersFrom(const TestChoice& choice) {
  const std::optional<CableGroup> group = ParseCableGroup(choice.pulled_group);
  if (!group || (*group != CableGroup::kHR && *group != CableGroup::kHL)) {
    return InvalidArgumentError("--pulled: expected HR or HL, got \"" + choice.pulled_group + "\"");
  }
  capture::TestParameters test;
  test.pulled_group = *group;
  test.bend_target_fraction = choice.bend_percent / 100.0;
  test.ramp_amplitude_rad = choice.ramp_deg * std::numbers::pi / 180.0;
  test.ramp_duration_s = choice.ramp_s;
  const Status valid = test.Validate();
  if (!valid.ok()) {
    return InvalidArgumentError("--pulled/--bend-percent/--ramp-deg/--ramp-s: " + valid.message());
  }
  return test;
}

// "  12.3 s  12034 frames  1000/s  0 checksum failures  0 gaps  LED on  vertebra 0.4321 rad"
std::string StatusText(const capture::CaptureStatus& status) {
  std::string text = FormatFixed(status.elapsed_s, 1) + " s  " + std::to_string(status.frames) +
                     " frames  " + FormatFixed(status.rate_hz, 0) + "/s  " +
                     std::to_string(status.checksum_errors) + " checksum failures  " +
                     std::to_string(status.gaps) + " gaps  LED " +
                     (status.led_on ? (*status.led_on ? "on " : "off") : "?  ");
  if (!std::isnan(status.last_vertebra_rad)) {
    text += "  vertebra " + FormatFixed(status.last_vertebra_rad, 4) + " rad";
  }
  if (!status.connected) text += "  (port gone: waiting for it)";
  return text;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// liftoff capture

int RunCapture(const CaptureCommand& command, std::ostream& out, std::ostream& err) {
  // flags
  auto status_line = ProgressLine::Create(command.status, "--status", "capture", err);
  if (!status_line.ok()) return ReportError(status_line.status(), err);
  capture::CaptureOptions options;
  options.port = command.port;
  options.settings.baud_rate = command.baud_rate;
  options.log_path = command.log_path;
  options.journal_path = command.journal_path;
  options.replace_existing = command.force;
  options.max_duration_s = command.max_duration_s;
  options.first_frame_timeout_s = command.first_frame_timeout_s;
  options.stop_on_test_end = !command.no_stop_on_test_end;
  options.reconnect_poll_s = command.reconnect_poll_s;
  options.status_interval_s = status_line->live() ? 0.25 : 5.0;
  if (command.send_start) {
    auto test = TestParametersFrom(command.test);
    if (!test.ok()) return ReportError(test.status(), err);
    options.send_start = true;
    options.start_command = test->StartCommand();
  }
  const Status valid = options.Validate();
  if (!valid.ok()) return ReportError(valid, err);
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);

  // the capture, with a status line and Ctrl-C as a clean stop
  ScopedStopSignals signals(command.handle_signals);
  std::function<void(const capture::CaptureStatus&)> on_status;
  if (!status_line->off()) {
    on_status = [&](const capture::CaptureStatus& status) { status_line->Show(StatusText(status)); };
  }
  err << "capturing " << command.port << " -> " << options.log_path.string() << " (journal "
      << options.JournalPath().string() << "); Ctrl-C stops\n";
  auto summary = capture::RunCapture(options, *calibration, g_stop_requested, on_status);
  status_line->Keep();
  if (!summary.ok()) return ReportError(summary.status(), err);

  for (const std::string& warning : summary->warnings) err << "warning: " << warning << '\n';
  out << summary->Brief() << '\n'
      << "log: " << summary->log_path.string() << '\n'
      << "journal: " << summary->journal_path.string() << '\n'
      << "calibration: " << calibration->Brief() << '\n';
  if (!summary->device.empty()) out << "device: " << summary->device << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff emulate

int RunEmulate(const EmulateCommand& command, std::ostream& out, std::ostream& err) {
  capture::EmulatorOptions options;
  options.rate_hz = command.rate_hz;
  options.unpaced = command.unpaced;
  options.autostart = command.autostart;
  auto test = TestParametersFrom(command.test);
  if (!test.ok()) return ReportError(test.status(), err);
  options.model.test = *test;
  options.corrupt_byte_probability = command.corrupt_probability;
  options.drop_frame_probability = command.drop_probability;
  options.stall_at_s = command.stall_at_s;
  options.stall_for_s = command.stall_for_s;
  options.disconnect_at_s = command.disconnect_at_s;
  options.disconnect_for_s = command.disconnect_for_s;
  options.clock_drift_ppm = command.drift_ppm;
  options.seed = command.seed;
  options.link_path = command.link_path;
  options.duration_s = command.duration_s;
  options.exit_after_test = !command.keep_running;

  // the handlers first: a script that reads the port line below may signal at once, and
  // the stop must then end the run cleanly (removing the link) rather than kill us
  ScopedStopSignals signals(command.handle_signals);
  auto emulator = capture::Emulator::Create(options);
  if (!emulator.ok()) return ReportError(emulator.status(), err);
  // the port path is the one line on stdout, at once: scripts read it to connect
  out << (*emulator)->port_path().string() << std::endl;
  err << "emulating a controller on " << (*emulator)->port_path().string() << " at "
      << FormatFixed(command.rate_hz, 0) << " Hz" << (command.autostart ? " (autostart)" : "")
      << "; Ctrl-C stops\n";

  const Status ran = (*emulator)->Run(g_stop_requested);
  err << "emulator: " << (*emulator)->stats().Brief() << '\n';
  if (!ran.ok()) return ReportError(ran, err);
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff ports

int RunPorts(const PortsCommand&, std::ostream& out, std::ostream& err) {
  auto ports = capture::ListPorts();
  if (!ports.ok()) return ReportError(ports.status(), err);
  out << capture::FormatPortList(*ports);
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff journal

int RunJournal(const JournalCommand& command, std::ostream& out, std::ostream& err) {
  if (!command.replay) {
    if (!command.output_path.empty()) {
      return ReportError(InvalidArgumentError("--output: only with --replay"), err);
    }
    capture::JournalDumpOptions options;
    options.text = !command.hex;
    options.max_records = command.max_records;
    if (command.max_records < 0) {
      return ReportError(InvalidArgumentError("--max-records: expected >= 0, got " +
                                              std::to_string(command.max_records)),
                         err);
    }
    const Status dumped = capture::DumpJournal(command.journal_path, options, out);
    if (!dumped.ok()) return ReportError(dumped, err);
    return kExitOk;
  }

  // replay: the log as live capture would have written it
  if (!command.output_path.empty()) {
    const Status refused = RefuseToReplace(command.output_path, "", command.force);
    if (!refused.ok()) return ReportError(refused, err);
  }
  auto calibration = ChooseCalibration(command.calibration);
  if (!calibration.ok()) return ReportError(calibration.status(), err);
  auto replay = capture::ReplayJournal(command.journal_path, *calibration);
  if (!replay.ok()) return ReportError(replay.status(), err);
  if (replay->truncated) {
    err << "warning: " << command.journal_path.string() << ": the last record is cut off ("
        << replay->truncated_bytes << " bytes skipped: the capture stopped mid-write)\n";
  }
  out << replay->Brief() << '\n';
  if (command.output_path.empty()) return kExitOk;
  const Status written = WriteControllerLog(command.output_path, replay->log);
  if (!written.ok()) return ReportError(written, err);
  err << "wrote " << command.output_path.string() << '\n';
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// the flags of each command

namespace {

void AddTestFlags(CLI::App& app, TestChoice& test) {
  app.add_option("--pulled", test.pulled_group, "Cable group the bend pulls: HR or HL")
      ->capture_default_str();
  app.add_option("--bend-percent", test.bend_percent,
                 "Bend each cable of the group to this percentage of its rest length")
      ->capture_default_str();
  app.add_option("--ramp-deg", test.ramp_deg,
                 "Rotating vertebra's ramp amplitude, degrees, signed by direction")
      ->capture_default_str();
  app.add_option("--ramp-s", test.ramp_s, "Ramp duration, seconds")->capture_default_str();
}

}  // namespace

Subcommand AddCaptureCommand(CLI::App& parent) {
  auto command = std::make_shared<CaptureCommand>();
  CLI::App* app = parent.add_subcommand(
      "capture", "Record a test from the controller's serial port: raw journal + controller log");
  app->add_option("port", command->port, "Serial port: device path, stable id or symlink")
      ->required();
  app->add_option("--output,-o", command->log_path, "Controller log to write")->required();
  app->add_option("--journal", command->journal_path, "Raw journal (default: LOG.journal)");
  app->add_flag("--force", command->force,
                "Replace an existing log and journal (an earlier recording)");
  app->add_option("--baud", command->baud_rate, "Line speed, bits/s")->capture_default_str();
  app->add_flag("--start", command->send_start,
                "Send START with the test parameters and record them in the log");
  AddTestFlags(*app, command->test);
  app->add_option("--max-duration", command->max_duration_s, "Stop after this long, s")
      ->capture_default_str();
  app->add_option("--first-frame-timeout", command->first_frame_timeout_s,
                  "Fail when no frame arrives this long after opening, s (0: wait for ever)")
      ->capture_default_str();
  app->add_flag("--no-stop-on-test-end", command->no_stop_on_test_end,
                "Keep capturing after the controller's TEST_END");
  app->add_option("--reconnect-poll", command->reconnect_poll_s,
                  "Look for an unplugged port this often, s")
      ->capture_default_str();
  app->add_option("--status", command->status, "Status line: auto, live, lines or off")
      ->capture_default_str();
  AddCalibrationFlag(*app, command->calibration);
  return RunsWith(app, command, RunCapture);
}

Subcommand AddEmulateCommand(CLI::App& parent) {
  auto command = std::make_shared<EmulateCommand>();
  CLI::App* app = parent.add_subcommand(
      "emulate", "A test controller on a pseudo-terminal (prints its path), with fault injection");
  app->add_option("--rate", command->rate_hz, "Sample frames per second")->capture_default_str();
  app->add_flag("--unpaced", command->unpaced, "Send as fast as the reader takes frames");
  app->add_flag("--autostart", command->autostart, "Start the test without a START command");
  AddTestFlags(*app, command->test);
  app->add_option("--link", command->link_path,
                  "Stable symlink to the pseudo-terminal (kept across disconnects)");
  app->add_option("--corrupt", command->corrupt_probability,
                  "Probability that a byte gets a bit flipped")
      ->capture_default_str();
  app->add_option("--drop", command->drop_probability, "Probability that a frame is dropped")
      ->capture_default_str();
  app->add_option("--stall-at", command->stall_at_s, "Pause the output at this time, s");
  app->add_option("--stall-for", command->stall_for_s, "... for this long, s")
      ->capture_default_str();
  app->add_option("--disconnect-at", command->disconnect_at_s,
                  "Unplug at this time, s (needs --link)");
  app->add_option("--disconnect-for", command->disconnect_for_s, "... for this long, s")
      ->capture_default_str();
  app->add_option("--drift-ppm", command->drift_ppm, "Device clock rate error, ppm")
      ->capture_default_str();
  app->add_option("--seed", command->seed, "Seed of the fault generator")->capture_default_str();
  app->add_option("--duration", command->duration_s, "Run this long, s (0: until done)")
      ->capture_default_str();
  app->add_flag("--keep-running", command->keep_running,
                "Keep running after the test ends (until Ctrl-C or --duration)");
  return RunsWith(app, command, RunEmulate);
}

Subcommand AddPortsCommand(CLI::App& parent) {
  auto command = std::make_shared<PortsCommand>();
  CLI::App* app = parent.add_subcommand("ports", "List the serial ports of this machine");
  return RunsWith(app, command, RunPorts);
}

Subcommand AddJournalCommand(CLI::App& parent) {
  auto command = std::make_shared<JournalCommand>();
  CLI::App* app =
      parent.add_subcommand("journal", "Show a capture journal, or rebuild its controller log");
  app->add_option("journal", command->journal_path, "Capture journal")->required();
  app->add_flag("--replay", command->replay,
                "Rebuild the controller log with live capture's parsing");
  app->add_option("--output,-o", command->output_path, "With --replay: log to write");
  app->add_flag("--force", command->force, "Overwrite an existing output file");
  app->add_flag("--hex", command->hex, "Dump bytes as hexadecimal");
  app->add_option("--max-records", command->max_records, "Dump at most this many records");
  AddCalibrationFlag(*app, command->calibration);
  return RunsWith(app, command, RunJournal);
}

}  // namespace liftoff::cli
