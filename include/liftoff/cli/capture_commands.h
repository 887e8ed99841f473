// The live-capture subcommands: `liftoff capture`, `liftoff emulate`, `liftoff ports` and
// `liftoff journal`. Same shape as commands.h: an Add function binds flags to each of
// these option structs; each Run function writes results to `out`, diagnostics to `err`, and
// returns the process exit code (ExitCodeFor; docs/cli.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>

#include "liftoff/cli/commands.h"

namespace liftoff::cli {

/// The test a START command asks for (capture --start) or the emulator runs on its own
/// (emulate): the paper's procedure by default.
struct TestChoice {
  /// Cable group the bend pulls: "HR" or "HL".
  std::string pulled_group = "HR";
  /// Each cable of the group at this percentage of its rest length (50 .. 100).
  double bend_percent = 80.0;
  /// Rotating vertebra's ramp amplitude, degrees, signed by direction.
  double ramp_deg = 60.0;
  /// Ramp duration, s.
  double ramp_s = 40.0;
};

/// `liftoff capture PORT -o LOG`: records a test from the controller's serial port.
struct CaptureCommand {
  /// Device path, stable id ("usb:2341:0043"), symlink or pseudo-terminal.
  std::string port;
  /// Controller log to write.
  std::filesystem::path log_path;
  /// Raw journal; empty: LOG.journal.
  std::filesystem::path journal_path;
  /// Replace an existing log or journal; off: refuse (exit code of kInvalidArgument).
  bool force = false;
  /// Line speed, bits/s.
  int baud_rate = 115200;
  /// Send START with `test` once the port is open.
  bool send_start = false;
  TestChoice test;
  /// Stop after this long, s (0: no limit).
  double max_duration_s = 0.0;
  /// Fail (exit code of kTimeout) when no frame arrives this long after opening, s (0:
  /// wait for ever).
  double first_frame_timeout_s = 10.0;
  /// Keep capturing after the controller's TEST_END.
  bool no_stop_on_test_end = false;
  /// How often to look for an unplugged port again, s.
  double reconnect_poll_s = 0.2;
  /// Status line on stderr: "auto" (live when stderr is a terminal, else a line every
  /// few seconds), "live", "lines" or "off".
  std::string status = "auto";
  CalibrationChoice calibration;
  /// Install SIGINT/SIGTERM handlers that stop the capture cleanly (restored on return;
  /// a second signal kills as usual).
  bool handle_signals = true;
};
int RunCapture(const CaptureCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff emulate`: a controller emulator on a pseudo-terminal; prints its port path.
struct EmulateCommand {
  /// Sample frames per second.
  double rate_hz = 1000.0;
  /// Write as fast as the reader takes frames (benchmarks).
  bool unpaced = false;
  /// Start the test without waiting for START.
  bool autostart = false;
  /// The test run by autostart or a START without parameters.
  TestChoice test;
  /// Stable symlink to the pty (survives disconnects); empty: none.
  std::filesystem::path link_path;
  /// Faults: byte corruption and frame drop probabilities (0 .. 1); a stall and a
  /// disconnect (at, for: host seconds; at < 0: never); clock drift, ppm; seed.
  double corrupt_probability = 0.0;
  double drop_probability = 0.0;
  double stall_at_s = -1.0;
  double stall_for_s = 0.0;
  double disconnect_at_s = -1.0;
  double disconnect_for_s = 0.0;
  double drift_ppm = 0.0;
  uint64_t seed = 1;
  /// Host seconds to run (0: until Ctrl-C, or the test ended unless keep_running).
  double duration_s = 0.0;
  bool keep_running = false;
  bool handle_signals = true;
};
int RunEmulate(const EmulateCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff ports`: the machine's serial ports.
struct PortsCommand {};
int RunPorts(const PortsCommand& command, std::ostream& out, std::ostream& err);

/// `liftoff journal J [--replay -o LOG]`: dumps a capture journal, or rebuilds its log.
struct JournalCommand {
  std::filesystem::path journal_path;
  /// Rebuild the controller log with live capture's parsing.
  bool replay = false;
  /// Where the rebuilt log goes (with replay); empty: print the summary only.
  std::filesystem::path output_path;
  /// Overwrite an existing output file.
  bool force = false;
  CalibrationChoice calibration;
  /// Dump bytes as hexadecimal instead of text.
  bool hex = false;
  /// Records to dump at most (0: all).
  int64_t max_records = 0;
};
int RunJournal(const JournalCommand& command, std::ostream& out, std::ostream& err);

/// Each command above added to the command line `parent` (flags bound to its struct).
Subcommand AddCaptureCommand(Command& parent);
Subcommand AddEmulateCommand(Command& parent);
Subcommand AddPortsCommand(Command& parent);
Subcommand AddJournalCommand(Command& parent);

}  // namespace liftoff::cli
