// `liftoff emulate`: a test controller on a pseudo-terminal, with fault injection.
#include "liftoff/cli/capture_commands.h"

#include <memory>
#include <ostream>

#include "capture_common.h"
#include "cli_common.h"
#include "liftoff/capture/emulator.h"
#include "liftoff/core/text.h"

namespace liftoff::cli {

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

  const Status ran = (*emulator)->Run(signals.stop_requested());
  err << "emulator: " << (*emulator)->stats().Brief() << '\n';
  if (!ran.ok()) return ReportError(ran, err);
  return kExitOk;
}

Subcommand AddEmulateCommand(Command& parent) {
  auto command = std::make_shared<EmulateCommand>();
  Command* app = parent.AddSubcommand(
      "emulate", "A test controller on a pseudo-terminal (prints its path), with fault injection");
  app->AddOption("--rate", command->rate_hz, "Sample frames per second")->ShowDefault();
  app->AddSwitch("--unpaced", command->unpaced, "Send as fast as the reader takes frames");
  app->AddSwitch("--autostart", command->autostart, "Start the test without a START command");
  AddTestFlags(*app, command->test);
  app->AddOption("--link", command->link_path,
                  "Stable symlink to the pseudo-terminal (kept across disconnects)");
  app->AddOption("--corrupt", command->corrupt_probability,
                  "Probability that a byte gets a bit flipped")
      ->ShowDefault();
  app->AddOption("--drop", command->drop_probability, "Probability that a frame is dropped")
      ->ShowDefault();
  app->AddOption("--stall-at", command->stall_at_s, "Pause the output at this time, s");
  app->AddOption("--stall-for", command->stall_for_s, "... for this long, s")
      ->ShowDefault();
  app->AddOption("--disconnect-at", command->disconnect_at_s,
                  "Unplug at this time, s (needs --link)");
  app->AddOption("--disconnect-for", command->disconnect_for_s, "... for this long, s")
      ->ShowDefault();
  app->AddOption("--drift-ppm", command->drift_ppm, "Device clock rate error, ppm")
      ->ShowDefault();
  app->AddOption("--seed", command->seed, "Seed of the fault generator")->ShowDefault();
  app->AddOption("--duration", command->duration_s, "Run this long, s (0: until done)")
      ->ShowDefault();
  app->AddSwitch("--keep-running", command->keep_running,
                "Keep running after the test ends (until Ctrl-C or --duration)");
  return RunsWith(app, command, RunEmulate);
}

}  // namespace liftoff::cli
