// The controller emulator behind `liftoff emulate`: a Laika test controller on a
// pseudo-terminal that speaks protocol v1 (docs/protocol.md, wire_format.h).
//
// Two layers:
//  - ControllerModel: the controller itself, deterministic and free of I/O. Two motors
//    (bending spool, rotating vertebra) follow the commanded bend and ramp through a
//    first-order lag with a speed limit; their encoders quantise the output-shaft angle
//    through the drive-chain constants; the test sequence switches the LED and raises
//    events; every frame it emits carries the next sequence number.
//  - Emulator: paces the model's frames onto a PseudoTerminal in real time (or as fast as
//    the pty accepts), answers the host's commands, and injects faults (corrupted bytes,
//    dropped frames, stalls, disconnects, clock drift) while recording exactly what it
//    did, so a test can account for every frame.
//
// The test sequence, in device time from START (the paper's procedure, section IV.C,
// with its 2 s settling shortened to the emulator's bend delay):
//   START        LED on; events TEST_START, LED_ON
//   +0.5 s       bend: the spool winds towards the bend target, the largest groove's
//                cable shortening at 0.025 m/s (the paper's rate)
//   +4.0 s       ramp: rotating vertebra from its angle at the ramp's start to the
//                amplitude, linearly over the duration (+pi/3 over 40 s: the paper's ramp)
//   ramp end +0.5 s  TEST_END (arg 0, done), LED off, LED_OFF; motors hold
// STOP aborts at once: TEST_END (arg 1, stopped), LED off, motors hold where they are.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/capture/wire_format.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"

namespace liftoff::capture {

/// The parameters of one foot-lifting test, as a START command carries them.
struct TestParameters {
  /// Cable group the bend pulls: HR or HL. The emulator winds the spool positive for HR
  /// and negative for HL (its convention; the spool angle's sign is all that differs).
  CableGroup pulled_group = CableGroup::kHR;
  /// Bend target: each cable of the group at this fraction of its rest length (0.5 .. 1;
  /// 0.8 = 80 %, the paper's P).
  double bend_target_fraction = 0.8;
  /// Rotating vertebra's ramp amplitude, rad, signed by direction (|.| <= pi; the paper:
  /// +-pi/3).
  double ramp_amplitude_rad = std::numbers::pi / 3.0;
  /// Duration of the ramp, s (0.001 .. 3600; the paper: 40).
  double ramp_duration_s = 40.0;

  /// kInvalidArgument naming the field and its allowed range.
  Status Validate() const;

  /// The START command for these parameters (wire_format.h: a = group, b = permille of
  /// rest length, c = millidegrees, d = milliseconds; each rounded to the nearest unit).
  wire::CommandFrame StartCommand() const;
  /// The parameters a START command carries. A START whose four arguments are all 0 asks
  /// for `defaults` (the controller's own test). kInvalidArgument (the message fits a NAK:
  /// "bad group", "bad bend", "bad amplitude", "bad duration") when an argument is outside
  /// the ranges above; also when `command` is not START ("not START").
  static Result<TestParameters> FromStartCommand(const wire::CommandFrame& command,
                                                 const TestParameters& defaults);
};

/// The emulated controller's hardware and test sequence. Defaults: the 2018 Laika.
struct ControllerModelOptions {
  /// Encoder counts per motor rotor revolution (12), motor revolutions per output-shaft
  /// revolution (1000) and output-shaft revolutions per rotating-vertebra revolution (4):
  /// the constants the header frame announces. Both encoders count the output shaft
  /// through the first two: counts = round(shaft_rad * counts_per_shaft_rad()).
  uint32_t counts_per_motor_rev = 12;
  uint32_t gearbox_ratio = 1000;
  uint32_t spur_gear_ratio = 4;

  /// Radius of the smallest spool groove, m; the grooves run 1-1-2-3 times it, so the
  /// largest is 3x (calib/laika-2018.json).
  double spool_groove_radius_m = 0.004;
  /// Cable length the bend target's percentage refers to, m (a horizontal cable between
  /// rod surfaces, 0.088).
  double cable_length_m = 0.088;
  /// The test run by autostart and by a START with all-zero arguments.
  TestParameters test;

  /// Device time from START to the start of the bend, s (>= 0).
  double bend_delay_s = 0.5;
  /// Speed of the bend: shortening rate of the largest groove's cable, m/s (> 0; the
  /// paper's 0.025).
  double bend_speed_m_per_s = 0.025;
  /// Device time from START to the start of the ramp, s (>= 0).
  double ramp_delay_s = 4.0;
  /// Device time from the end of the ramp to TEST_END, s (>= 0).
  double end_hold_s = 0.5;

  /// Motor lag: first-order time constant from setpoint to output-shaft angle, s (> 0).
  double motor_time_constant_s = 0.05;
  /// Speed limit of both output shafts, rad/s (> 0). 3.3 rad/s is about 32 rpm, a
  /// 1000:1 micro metal gearmotor's no-load speed at 6 V; the default test stays below.
  double max_shaft_speed_rad_per_s = 3.3;

  /// Firmware name in the header frame (<= wire::kMaxTextBytes; no ',', '*', '$').
  std::string firmware = "liftoff-emulator 1.0";

  /// kInvalidArgument naming the field and its allowed range.
  Status Validate() const;

  /// Encoder counts per output-shaft radian: counts_per_motor_rev * gearbox_ratio / 2 pi
  /// (1909.86 by default).
  double counts_per_shaft_rad() const;
  /// Spool angle (= bending output-shaft angle) that brings the largest groove's cable to
  /// `fraction` of its length, rad, unsigned: (1 - fraction) * cable_length_m /
  /// (3 * spool_groove_radius_m). 80 %: 0.2 * 0.088 / 0.012 = 1.4667 rad (2801 counts).
  double BendSpoolAngleRad(double fraction) const;
  /// Rotating motor's output-shaft angle for a vertebra angle: spur_gear_ratio * vertebra
  /// (pi/3 -> 4 pi/3 rad, 8000 counts).
  double RotateShaftAngleRad(double vertebra_rad) const;
};

/// Where the test sequence is.
enum class TestPhase {
  kIdle,      ///< no test since power-on
  kStarting,  ///< LED on, waiting for the bend
  kBending,   ///< bend setpoint moving towards its target
  kBent,      ///< bend setpoint at its target, waiting for the ramp
  kRamping,   ///< rotation setpoint ramping
  kSettling,  ///< ramp done, waiting for TEST_END
  kDone,      ///< the test finished (TEST_END arg 0)
  kStopped,   ///< STOP aborted the test (TEST_END arg 1)
};

/// "idle", "starting", "bending", "bent", "ramping", "settling", "done", "stopped".
const char* TestPhaseName(TestPhase phase);

/// The controller: deterministic and pure (no clock, no I/O, no randomness). The caller
/// moves device time forward with Advance and Command (never backwards: an earlier time
/// is treated as the current one), asks for samples with EmitSample, and collects the
/// frames with TakeFrames. Same options and same calls: the same frames, bit for bit.
///
/// Frames it emits on its own: a header at construction (boot, device time 0), after
/// every command, and once per device second while no test runs (idle, done, stopped);
/// the test's events (TEST_START, LED_ON, TEST_END, LED_OFF); the replies ACK, NAK and
/// PONG. Every frame takes the next sequence number, from 0.
class ControllerModel {
 public:
  /// Integration step of the motor model, ns (0.1 ms); a call's last step may be shorter.
  static constexpr int64_t kStepNs = 100'000;

  /// `options` must be valid (asserted).
  explicit ControllerModel(const ControllerModelOptions& options);

  /// Handles a host command at `device_time_ns` (after advancing to it): START (ACK, then
  /// the test starts; NAK "busy" while a test runs, NAK with the reason for bad
  /// arguments), STOP (ACK; ends a running test), ZERO (ACK: both encoders read 0, motors
  /// do not move; NAK "busy" while a test runs), PING (PONG with the token), anything
  /// else NAK "unknown command". Queues a header after the reply.
  void Command(const wire::CommandFrame& command, int64_t device_time_ns);
  /// Starts a test without a command (autostart): no ACK, no header. Ignored while a test
  /// runs.
  void StartTest(const TestParameters& test, int64_t device_time_ns);
  /// Answers a host line that is not a command frame (bad checksum, other frame type,
  /// garbage) with FAULT, arg 1, text "bad frame", at `device_time_ns`.
  void RejectLine(int64_t device_time_ns);
  /// Moves the motors and the test sequence to `to_device_time_ns`.
  void Advance(int64_t to_device_time_ns);
  /// Queues a sample frame of the current state (at the current device time).
  void EmitSample();
  /// Queues a header frame (at the current device time).
  void EmitHeader();
  /// Moves the frames queued since the last call to the end of `out`, oldest first.
  void TakeFrames(std::vector<wire::Frame>& out);

  const ControllerModelOptions& options() const { return options_; }
  int64_t device_time_ns() const { return time_ns_; }
  TestPhase phase() const;
  /// A test is under way (starting .. settling).
  bool test_running() const;
  bool led_on() const { return led_on_; }
  /// The current (or last) test's parameters and START time (nullopt before the first).
  const TestParameters& test() const { return test_; }
  std::optional<int64_t> test_start_ns() const { return test_start_ns_; }
  /// When the last test ended (TEST_END), device ns; nullopt while none has.
  std::optional<int64_t> test_end_ns() const { return test_end_ns_; }
  /// The sequence number the next frame will take (= frames emitted so far, mod 2^32).
  uint32_t next_sequence() const { return next_sequence_; }

  /// Output-shaft angles and their setpoints in the encoder's frame (ZERO moves it), rad.
  double bend_shaft_rad() const { return bend_rad_; }
  double rotate_shaft_rad() const { return rotate_rad_; }
  double bend_setpoint_rad() const { return bend_setpoint_rad_; }
  double rotate_setpoint_rad() const { return rotate_setpoint_rad_; }
  /// The same as encoder counts: round(angle * counts_per_shaft_rad()).
  int32_t bend_counts() const { return CountsFromShaftRad(bend_rad_); }
  int32_t rotate_counts() const { return CountsFromShaftRad(rotate_rad_); }
  int32_t bend_setpoint_counts() const { return CountsFromShaftRad(bend_setpoint_rad_); }
  int32_t rotate_setpoint_counts() const { return CountsFromShaftRad(rotate_setpoint_rad_); }

 private:
  enum class Run { kNone, kRunning, kDone, kStopped };

  int32_t CountsFromShaftRad(double shaft_rad) const;
  // Setpoints of the running test at device time t.
  double BendProfileRad(int64_t t_ns) const;
  double RotateProfileRad(int64_t t_ns) const;
  void Step(int64_t step_ns);
  void EndTest(int64_t t_ns, int32_t reason);
  void EmitEvent(wire::EventKind kind, int32_t arg, const char* text);
  wire::Frame& NewFrame(wire::FrameType type);

  ControllerModelOptions options_;
  double counts_per_shaft_rad_ = 0;
  double full_step_alpha_ = 0;  // lag factor of a whole kStepNs step

  int64_t time_ns_ = 0;
  int64_t last_header_ns_ = 0;
  uint32_t next_sequence_ = 0;
  bool led_on_ = false;
  Run run_ = Run::kNone;
  TestParameters test_;
  std::optional<int64_t> test_start_ns_;
  std::optional<int64_t> test_end_ns_;
  // the running test's profile: start positions and end instants
  double bend_from_rad_ = 0;
  double bend_to_rad_ = 0;
  double rotate_from_rad_ = 0;
  double rotate_to_rad_ = 0;
  int64_t ramp_end_ns_ = 0;

  double bend_rad_ = 0;
  double rotate_rad_ = 0;
  double bend_setpoint_rad_ = 0;
  double rotate_setpoint_rad_ = 0;
  std::vector<wire::Frame> queue_;
};

/// How the emulator runs and which faults it injects. Times named *_at_s / *_for_s and
/// duration_s are host seconds since Run began; the test's timing is device time.
struct EmulatorOptions {
  /// Sample frames per device second (1 .. 100,000): one sample every 1/rate_hz of device
  /// time, in paced and unpaced mode alike.
  double rate_hz = 1000;
  /// Unpaced: write frames as fast as the pty accepts them (waiting for the reader when
  /// its buffer is full, so nothing is lost to overflow), device time still advancing
  /// 1/rate_hz per sample. For benchmarks. Paced (default): each sample leaves at its
  /// device time, frames due together go out in one write.
  bool unpaced = false;
  /// Start the test without a START command, autostart_delay_s of device time after Run
  /// begins, with model.test.
  bool autostart = false;
  double autostart_delay_s = 0.5;
  /// The controller.
  ControllerModelOptions model;

  // Faults. Each is drawn from a seeded splitmix64 generator, so a run's faults repeat
  // exactly for the same seed and the same frames (paced runs differ only in which frames
  // a host-time fault such as a stall or disconnect meets).
  /// Probability that a byte written gets one random bit flipped (0 .. 1).
  double corrupt_byte_probability = 0;
  /// Probability that a frame is not sent at all (0 .. 1). Its sequence number is spent,
  /// so the host sees a gap.
  double drop_frame_probability = 0;
  /// Output pauses from stall_at_s for stall_for_s (negative at: no stall). Frames made
  /// meanwhile are queued, not lost, and arrive as one burst when it ends (a USB-serial
  /// hold-up); commands wait too.
  double stall_at_s = -1;
  double stall_for_s = 0;
  /// The port disappears at disconnect_at_s (negative: never): the pty master closes (the
  /// reader gets a hang-up; bytes it has not read are discarded by the kernel), frames
  /// made meanwhile and frames queued but not written are lost (sequence numbers spent),
  /// and after disconnect_for_s a new pty takes its place and link_path is re-pointed to
  /// it (a new symlink renamed over the old one: the link always exists, and a host sees
  /// the change as a new inode); a header frame is its first frame. Needs link_path (the
  /// new pty has a new name).
  double disconnect_at_s = -1;
  double disconnect_for_s = 0;
  /// Device clock rate error, parts per million (-100,000 .. 100,000): device time runs
  /// (1 + ppm * 1e-6) times as fast as host time, so paced samples leave that much more
  /// often in host time.
  double clock_drift_ppm = 0;
  uint64_t seed = 1;

  /// A stable symlink to the current pty slave, replaced atomically (empty: none). An
  /// existing symlink there is replaced; any other file is an error. Removed at the end.
  std::filesystem::path link_path;
  /// Host seconds to run (0: until stopped, or the test ended and 1 s of device time
  /// passed, when exit_after_test).
  double duration_s = 0;
  /// Return once the test ended (done or stopped) and 1 more device second was sent.
  bool exit_after_test = true;

  /// kInvalidArgument naming the field and its allowed range.
  Status Validate() const;
};

/// What an emulator did; every sequence number spent lands in exactly one of
/// frames_written, frames_dropped, frames_lost_disconnected, frames_overflowed or the
/// frames still queued (frames_generated minus the others).
struct EmulatorStats {
  /// Frames made by the model (sequence numbers spent).
  int64_t frames_generated = 0;
  /// Frames written whole to a pty.
  int64_t frames_written = 0;
  /// Frames not sent by the drop fault.
  int64_t frames_dropped = 0;
  /// Frames lost to a disconnect (made while the port was gone, or queued when it went).
  int64_t frames_lost_disconnected = 0;
  /// Frames discarded because 1 MiB was already waiting for a reader (paced mode only:
  /// a real controller cannot wait either).
  int64_t frames_overflowed = 0;
  /// Frames with at least one corrupted byte, and the corrupted bytes.
  int64_t frames_corrupted = 0;
  int64_t bytes_corrupted = 0;
  /// Bytes written to a pty.
  int64_t bytes_written = 0;
  /// Host lines received: decoded commands, and lines that were not a command frame
  /// (each answered with FAULT 1 "bad frame").
  int64_t commands_received = 0;
  int64_t bad_lines_received = 0;
  /// Disconnects performed, stalls begun.
  int64_t disconnects = 0;
  int64_t stalls = 0;

  /// "5000 frames made, 4990 written, 5 dropped, 0 lost to disconnects, 0 overflowed,
  /// 3 corrupted (3 bytes), 0 disconnects, 0 stalls".
  std::string Brief() const;
};

/// A controller on a pseudo-terminal. Create, hand port_path() to the host, then Run
/// (on any one thread; stats() and the ground-truth lists may be read from others).
class Emulator {
 public:
  /// The options' kInvalidArgument; kIo when no pty can be opened or the link cannot be
  /// made.
  static Result<std::unique_ptr<Emulator>> Create(const EmulatorOptions& options);
  ~Emulator();
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  /// link_path when set, else the first pty's slave path.
  const std::filesystem::path& port_path() const { return port_path_; }

  /// Runs the controller until `stop` is set, duration_s passed, or the test ended (see
  /// exit_after_test). Frames queued at the end get up to 1 s to reach the reader. Call
  /// once. kIo when writing to or reading from the pty fails for good, or a new pty
  /// cannot be opened after a disconnect.
  Status Run(const std::atomic<bool>& stop);

  EmulatorStats stats() const;
  /// Sequence numbers spent but never written (dropped, lost to a disconnect,
  /// overflowed), ascending: the gaps a complete reader sees.
  std::vector<uint32_t> dropped_sequences() const;
  /// Sequence numbers of frames written with at least one corrupted byte, ascending.
  std::vector<uint32_t> corrupted_sequences() const;

 private:
  struct Impl;
  explicit Emulator(std::unique_ptr<Impl> impl);

  std::unique_ptr<Impl> impl_;
  std::filesystem::path port_path_;
};

}  // namespace liftoff::capture
