// `liftoff capture PORT -o LOG`: a test recorded from the controller's serial port.
#include "liftoff/cli/capture_commands.h"

#include <cmath>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include "capture_common.h"
#include "cli_common.h"
#include "liftoff/capture/capture_session.h"
#include "liftoff/cli/progress_line.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {
namespace {

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
    on_status = [&](const capture::CaptureStatus& status) {
      status_line->Show(StatusText(status));
    };
  }
  err << "capturing " << command.port << " -> " << options.log_path.string() << " (journal "
      << options.JournalPath().string() << "); Ctrl-C stops\n";
  auto summary = capture::RunCapture(options, *calibration, signals.stop_requested(), on_status);
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

Subcommand AddCaptureCommand(Command& parent) {
  auto command = std::make_shared<CaptureCommand>();
  Command* app = parent.AddSubcommand(
      "capture", "Record a test from the controller's serial port: raw journal + controller log");
  app->AddOption("port", command->port, "Serial port: device path, stable id or symlink")
      ->Required();
  app->AddOption("--output,-o", command->log_path, "Controller log to write")->Required();
  app->AddOption("--journal", command->journal_path, "Raw journal (default: LOG.journal)");
  app->AddSwitch("--force", command->force,
                "Replace an existing log and journal (an earlier recording)");
  app->AddOption("--baud", command->baud_rate, "Line speed, bits/s")->ShowDefault();
  app->AddSwitch("--start", command->send_start,
                "Send START with the test parameters and record them in the log");
  AddTestFlags(*app, command->test);
  app->AddOption("--max-duration", command->max_duration_s, "Stop after this long, s")
      ->ShowDefault();
  app->AddOption("--first-frame-timeout", command->first_frame_timeout_s,
                  "Fail when no frame arrives this long after opening, s (0: wait for ever)")
      ->ShowDefault();
  app->AddSwitch("--no-stop-on-test-end", command->no_stop_on_test_end,
                "Keep capturing after the controller's TEST_END");
  app->AddOption("--reconnect-poll", command->reconnect_poll_s,
                  "Look for an unplugged port this often, s")
      ->ShowDefault();
  app->AddOption("--status", command->status, "Status line: auto, live, lines or off")
      ->ShowDefault();
  AddCalibrationFlag(*app, command->calibration);
  return RunsWith(app, command, RunCapture);
}

}  // namespace liftoff::cli
