#include "liftoff/capture/emulator.h"

#include "liftoff/core/random.h"

#include <fcntl.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <limits>
#include <mutex>
#include <system_error>

#include "liftoff/capture/serial_port.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/time.h"

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;
constexpr double kRadPerDegree = kPi / 180.0;
// the largest spool groove is 3x the smallest (grooves 1-1-2-3)
constexpr double kLargestGrooveMultiple = 3.0;
// paced mode: bytes waiting for a reader beyond which new frames are discarded
constexpr size_t kMaxQueuedBytes = size_t{1} << 20;
// unpaced mode: make more frames only while fewer bytes than this wait
constexpr size_t kUnpacedQueueBytes = size_t{64} << 10;
constexpr int kUnpacedBatchFrames = 256;
// longest sleep between looks at the stop flag and the host's commands
constexpr int64_t kMaxSleepNs = 10 * kNanosecondsPerMillisecond;
// how long queued frames may take to reach the reader at the end of a run
constexpr int64_t kDrainNs = kNanosecondsPerSecond;
// device time sent after TEST_END before Run returns (exit_after_test)
constexpr int64_t kAfterTestNs = kNanosecondsPerSecond;
constexpr int32_t kFaultBadFrame = 1;

// "field: expected <range>, got <value>"
Status OutOfRange(const char* field, const char* range, double value) {
  return InvalidArgumentError(std::string(field) + ": expected " + range + ", got " +
                              FormatNumber(value));
}

// True when lo <= value <= hi (false for NaN).
bool Within(double value, double lo, double hi) { return value >= lo && value <= hi; }

uint32_t SequenceOf(const wire::Frame& frame) {
  switch (frame.type) {
    case wire::FrameType::kSample: return frame.sample.sequence;
    case wire::FrameType::kHeader: return frame.header.sequence;
    case wire::FrameType::kEvent: return frame.event.sequence;
    case wire::FrameType::kCommand: break;
  }
  return 0;
}

uint32_t WireMicroseconds(int64_t device_time_ns) {
  // the controller's 32-bit microsecond clock wraps
  return static_cast<uint32_t>(static_cast<uint64_t>(device_time_ns / kNanosecondsPerMicrosecond));
}

// Points `link` at `target` atomically: a new symlink beside it, renamed over it.
Status PointLink(const fs::path& link, const std::string& target) {
  fs::path temporary = link;
  temporary += ".tmp-" + std::to_string(::getpid());
  std::error_code error;
  fs::remove(temporary, error);
  fs::create_symlink(target, temporary, error);
  if (error) {
    return IoError(link.string() + ": cannot point the link at " + target + ": " + error.message());
  }
  return RenameIntoPlace(temporary, link);
}

Status MakeNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) {
    return IoError(std::string("pty master: cannot make it non-blocking: ") + std::strerror(errno));
  }
  return Status::Ok();
}

}  // namespace

// ---------------------------------------------------------------------------------------
// TestParameters

Status TestParameters::Validate() const {
  if (pulled_group != CableGroup::kHR && pulled_group != CableGroup::kHL) {
    return InvalidArgumentError("pulled_group: expected HR or HL, got " +
                                std::string(CableGroupName(pulled_group)));
  }
  if (!Within(bend_target_fraction, 0.5, 1.0)) {
    return OutOfRange("bend_target_fraction", "0.5 .. 1", bend_target_fraction);
  }
  if (!Within(ramp_amplitude_rad, -kPi, kPi)) {
    return OutOfRange("ramp_amplitude_rad", "-pi .. pi", ramp_amplitude_rad);
  }
  if (!Within(ramp_duration_s, 0.001, 3600.0)) {
    return OutOfRange("ramp_duration_s", "0.001 .. 3600", ramp_duration_s);
  }
  return Status::Ok();
}

wire::CommandFrame TestParameters::StartCommand() const {
  wire::CommandFrame command;
  command.command = wire::CommandKind::kStart;
  command.args[0] = static_cast<int32_t>(pulled_group);
  command.args[1] = static_cast<int32_t>(std::lround(bend_target_fraction * 1000.0));
  command.args[2] = static_cast<int32_t>(std::lround(ramp_amplitude_rad / kRadPerDegree * 1000.0));
  command.args[3] = static_cast<int32_t>(std::lround(ramp_duration_s * 1000.0));
  return command;
}

Result<TestParameters> TestParameters::FromStartCommand(const wire::CommandFrame& command,
                                                        const TestParameters& defaults) {
  if (command.command != wire::CommandKind::kStart) return InvalidArgumentError("not START");
  const int32_t* a = command.args;
  if (a[0] == 0 && a[1] == 0 && a[2] == 0 && a[3] == 0) return defaults;
  // each message starts with the NAK reason, up to the ':'
  const auto bad = [](const char* reason, int32_t got, const char* expected) {
    return InvalidArgumentError(std::string(reason) + ": " + std::to_string(got) + " (expected " +
                                expected + ")");
  };
  TestParameters test;
  if (a[0] != static_cast<int32_t>(CableGroup::kHR) &&
      a[0] != static_cast<int32_t>(CableGroup::kHL)) {
    return bad("bad group", a[0], "2 for HR or 3 for HL");
  }
  if (a[1] < 500 || a[1] > 1000) return bad("bad bend", a[1], "500 .. 1000 permille");
  if (a[2] < -180000 || a[2] > 180000) {
    return bad("bad amplitude", a[2], "-180000 .. 180000 millidegrees");
  }
  if (a[3] < 1 || a[3] > 3600000) return bad("bad duration", a[3], "1 .. 3600000 ms");
  test.pulled_group = static_cast<CableGroup>(a[0]);
  test.bend_target_fraction = a[1] / 1000.0;
  test.ramp_amplitude_rad = a[2] / 1000.0 * kRadPerDegree;
  test.ramp_duration_s = a[3] / 1000.0;
  return test;
}

// ---------------------------------------------------------------------------------------
// ControllerModelOptions

Status ControllerModelOptions::Validate() const {
  if (counts_per_motor_rev < 1) return OutOfRange("counts_per_motor_rev", ">= 1", 0);
  if (gearbox_ratio < 1) return OutOfRange("gearbox_ratio", ">= 1", 0);
  if (spur_gear_ratio < 1) return OutOfRange("spur_gear_ratio", ">= 1", 0);
  if (!Within(spool_groove_radius_m, 1e-4, 1.0)) {
    return OutOfRange("spool_groove_radius_m", "0.0001 .. 1", spool_groove_radius_m);
  }
  if (!Within(cable_length_m, 1e-3, 10.0)) {
    return OutOfRange("cable_length_m", "0.001 .. 10", cable_length_m);
  }
  if (Status status = test.Validate(); !status.ok()) return status.WithContext("test");
  if (!Within(bend_delay_s, 0.0, 3600.0))
    return OutOfRange("bend_delay_s", "0 .. 3600", bend_delay_s);
  if (!Within(bend_speed_m_per_s, 1e-6, 100.0)) {
    return OutOfRange("bend_speed_m_per_s", "0.000001 .. 100", bend_speed_m_per_s);
  }
  if (!Within(ramp_delay_s, 0.0, 3600.0))
    return OutOfRange("ramp_delay_s", "0 .. 3600", ramp_delay_s);
  if (!Within(end_hold_s, 0.0, 3600.0)) return OutOfRange("end_hold_s", "0 .. 3600", end_hold_s);
  if (!Within(motor_time_constant_s, 1e-6, 100.0)) {
    return OutOfRange("motor_time_constant_s", "0.000001 .. 100", motor_time_constant_s);
  }
  if (!Within(max_shaft_speed_rad_per_s, 1e-6, 1e6)) {
    return OutOfRange("max_shaft_speed_rad_per_s", "0.000001 .. 1000000",
                      max_shaft_speed_rad_per_s);
  }
  // the largest angle a test can command must stay far inside int32 counts
  const double largest_rad = std::max(BendSpoolAngleRad(0.5), RotateShaftAngleRad(kPi));
  if (largest_rad * counts_per_shaft_rad() > 1e9) {
    return InvalidArgumentError(
        "counts_per_motor_rev, gearbox_ratio, spur_gear_ratio: a test's largest angle, " +
        FormatNumber(largest_rad) + " rad, would be " +
        FormatNumber(largest_rad * counts_per_shaft_rad()) + " counts; expected at most 1e9");
  }
  if (firmware.size() > wire::kMaxTextBytes ||
      firmware.find_first_of(",*$\r\n") != std::string::npos) {
    return InvalidArgumentError(
        "firmware: expected at most " + std::to_string(wire::kMaxTextBytes) +
        " characters without ',', '*', '$' or line breaks, got \"" + firmware + "\"");
  }
  return Status::Ok();
}

double ControllerModelOptions::counts_per_shaft_rad() const {
  return static_cast<double>(counts_per_motor_rev) * static_cast<double>(gearbox_ratio) /
         (2.0 * kPi);
}

double ControllerModelOptions::BendSpoolAngleRad(double fraction) const {
  return (1.0 - fraction) * cable_length_m / (kLargestGrooveMultiple * spool_groove_radius_m);
}

double ControllerModelOptions::RotateShaftAngleRad(double vertebra_rad) const {
  return static_cast<double>(spur_gear_ratio) * vertebra_rad;
}

const char* TestPhaseName(TestPhase phase) {
  switch (phase) {
    case TestPhase::kIdle: return "idle";
    case TestPhase::kStarting: return "starting";
    case TestPhase::kBending: return "bending";
    case TestPhase::kBent: return "bent";
    case TestPhase::kRamping: return "ramping";
    case TestPhase::kSettling: return "settling";
    case TestPhase::kDone: return "done";
    case TestPhase::kStopped: return "stopped";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------
// ControllerModel

ControllerModel::ControllerModel(const ControllerModelOptions& options) : options_(options) {
  assert(options_.Validate().ok());
  counts_per_shaft_rad_ = options_.counts_per_shaft_rad();
  full_step_alpha_ = -std::expm1(-SecondsFromNs(kStepNs) / options_.motor_time_constant_s);
  test_ = options_.test;
  // boot: the constants first
  EmitHeader();
}

int32_t ControllerModel::CountsFromShaftRad(double shaft_rad) const {
  const double counts = std::round(shaft_rad * counts_per_shaft_rad_);
  constexpr double kLimit = std::numeric_limits<int32_t>::max();
  return static_cast<int32_t>(std::clamp(counts, -kLimit, kLimit));
}

TestPhase ControllerModel::phase() const {
  switch (run_) {
    case Run::kNone: return TestPhase::kIdle;
    case Run::kDone: return TestPhase::kDone;
    case Run::kStopped: return TestPhase::kStopped;
    case Run::kRunning: break;
  }
  const int64_t since_start_ns = time_ns_ - *test_start_ns_;
  const int64_t ramp_start_ns = NsFromSeconds(options_.ramp_delay_s);
  if (time_ns_ >= ramp_end_ns_) return TestPhase::kSettling;
  if (since_start_ns >= ramp_start_ns) return TestPhase::kRamping;
  if (since_start_ns < NsFromSeconds(options_.bend_delay_s)) return TestPhase::kStarting;
  return BendProfileRad(time_ns_) == bend_to_rad_ ? TestPhase::kBent : TestPhase::kBending;
}

bool ControllerModel::test_running() const { return run_ == Run::kRunning; }

double ControllerModel::BendProfileRad(int64_t t_ns) const {
  // from where the spool stood at START towards the target, at the bend speed
  const double bend_start_s = SecondsFromNs(*test_start_ns_) + options_.bend_delay_s;
  const double elapsed_s = SecondsFromNs(t_ns) - bend_start_s;
  if (elapsed_s <= 0) return bend_from_rad_;
  const double speed_rad_per_s =
      options_.bend_speed_m_per_s / (kLargestGrooveMultiple * options_.spool_groove_radius_m);
  const double distance_rad = bend_to_rad_ - bend_from_rad_;
  const double moved_rad = speed_rad_per_s * elapsed_s;
  if (moved_rad >= std::abs(distance_rad)) return bend_to_rad_;
  return bend_from_rad_ + std::copysign(moved_rad, distance_rad);
}

double ControllerModel::RotateProfileRad(int64_t t_ns) const {
  // linear from the ramp's start angle to the amplitude over the duration
  const double ramp_start_s = SecondsFromNs(*test_start_ns_) + options_.ramp_delay_s;
  const double fraction =
      std::clamp((SecondsFromNs(t_ns) - ramp_start_s) / test_.ramp_duration_s, 0.0, 1.0);
  return rotate_from_rad_ + (rotate_to_rad_ - rotate_from_rad_) * fraction;
}

void ControllerModel::Step(int64_t step_ns) {
  time_ns_ += step_ns;
  if (run_ == Run::kRunning) {
    bend_setpoint_rad_ = BendProfileRad(time_ns_);
    rotate_setpoint_rad_ = RotateProfileRad(time_ns_);
  }
  // first-order lag towards the setpoint, then the speed limit
  const double alpha = step_ns == kStepNs
                           ? full_step_alpha_
                           : -std::expm1(-SecondsFromNs(step_ns) / options_.motor_time_constant_s);
  const double max_move_rad = options_.max_shaft_speed_rad_per_s * SecondsFromNs(step_ns);
  const auto follow = [&](double& position_rad, double setpoint_rad) {
    const double move_rad = (setpoint_rad - position_rad) * alpha;
    position_rad += std::clamp(move_rad, -max_move_rad, max_move_rad);
  };
  follow(bend_rad_, bend_setpoint_rad_);
  follow(rotate_rad_, rotate_setpoint_rad_);
}

void ControllerModel::Advance(int64_t to_device_time_ns) {
  while (time_ns_ < to_device_time_ns) {
    // steps end exactly at the test's end, so TEST_END carries its exact instant
    int64_t step_end_ns = std::min(time_ns_ + kStepNs, to_device_time_ns);
    const int64_t end_ns = ramp_end_ns_ + NsFromSeconds(options_.end_hold_s);
    if (run_ == Run::kRunning) step_end_ns = std::min(step_end_ns, end_ns);
    Step(step_end_ns - time_ns_);
    if (run_ == Run::kRunning && time_ns_ >= end_ns) EndTest(time_ns_, 0);
    // while no test runs, a header every second for hosts that connect late
    if (run_ != Run::kRunning && time_ns_ - last_header_ns_ >= kNanosecondsPerSecond) EmitHeader();
  }
}

void ControllerModel::StartTest(const TestParameters& test, int64_t device_time_ns) {
  Advance(device_time_ns);
  if (run_ == Run::kRunning) return;
  test_ = test;
  run_ = Run::kRunning;
  test_start_ns_ = time_ns_;
  test_end_ns_.reset();
  const double sign = test.pulled_group == CableGroup::kHL ? -1.0 : 1.0;
  bend_from_rad_ = bend_setpoint_rad_;
  bend_to_rad_ = sign * options_.BendSpoolAngleRad(test.bend_target_fraction);
  rotate_from_rad_ = rotate_setpoint_rad_;
  rotate_to_rad_ = options_.RotateShaftAngleRad(test.ramp_amplitude_rad);
  ramp_end_ns_ = time_ns_ + NsFromSeconds(options_.ramp_delay_s + test.ramp_duration_s);
  led_on_ = true;
  EmitEvent(wire::EventKind::kTestStart, 0, "");
  EmitEvent(wire::EventKind::kLedOn, 0, "");
}

void ControllerModel::EndTest(int64_t t_ns, int32_t reason) {
  run_ = reason == 0 ? Run::kDone : Run::kStopped;
  test_end_ns_ = t_ns;
  led_on_ = false;
  // idle headers resume a second after the end (STOP's reply brings one at once)
  last_header_ns_ = t_ns;
  EmitEvent(wire::EventKind::kTestEnd, reason, "");
  EmitEvent(wire::EventKind::kLedOff, 0, "");
}

void ControllerModel::Command(const wire::CommandFrame& command, int64_t device_time_ns) {
  Advance(device_time_ns);
  const int32_t code = static_cast<int32_t>(command.command);
  const auto ack = [&] { EmitEvent(wire::EventKind::kAck, code, ""); };
  const auto nak = [&](const char* why) { EmitEvent(wire::EventKind::kNak, code, why); };
  switch (command.command) {
    case wire::CommandKind::kStart: {
      if (run_ == Run::kRunning) {
        nak("busy");
        break;
      }
      Result<TestParameters> test = TestParameters::FromStartCommand(command, options_.test);
      if (!test.ok()) {
        // the reason is the message up to its ':'
        const std::string& message = test.status().message();
        std::string why = message.substr(0, std::min(message.find(':'), wire::kMaxTextBytes));
        nak(why.c_str());
        break;
      }
      ack();
      StartTest(*test, time_ns_);
      break;
    }
    case wire::CommandKind::kStop:
      ack();
      if (run_ == Run::kRunning) {
        // hold where the motors are
        bend_setpoint_rad_ = bend_rad_;
        rotate_setpoint_rad_ = rotate_rad_;
        EndTest(time_ns_, 1);
      }
      break;
    case wire::CommandKind::kZero:
      if (run_ == Run::kRunning) {
        nak("busy");
        break;
      }
      // the encoder frame moves to the motors; setpoints move with it so nothing turns
      bend_setpoint_rad_ -= bend_rad_;
      rotate_setpoint_rad_ -= rotate_rad_;
      bend_rad_ = 0;
      rotate_rad_ = 0;
      ack();
      break;
    case wire::CommandKind::kPing: EmitEvent(wire::EventKind::kPong, command.args[0], ""); break;
    default: nak("unknown command"); break;
  }
  EmitHeader();
}

void ControllerModel::RejectLine(int64_t device_time_ns) {
  Advance(device_time_ns);
  EmitEvent(wire::EventKind::kFault, kFaultBadFrame, "bad frame");
}

wire::Frame& ControllerModel::NewFrame(wire::FrameType type) {
  wire::Frame& frame = queue_.emplace_back();
  frame.type = type;
  return frame;
}

void ControllerModel::EmitSample() {
  wire::SampleFrame& sample = NewFrame(wire::FrameType::kSample).sample;
  sample.sequence = next_sequence_++;
  sample.device_time_us = WireMicroseconds(time_ns_);
  sample.led_on = led_on_ ? 1 : 0;
  sample.bend_counts = bend_counts();
  sample.rotate_counts = rotate_counts();
  sample.bend_setpoint_counts = bend_setpoint_counts();
  sample.rotate_setpoint_counts = rotate_setpoint_counts();
}

void ControllerModel::EmitHeader() {
  wire::HeaderFrame& header = NewFrame(wire::FrameType::kHeader).header;
  header.sequence = next_sequence_++;
  header.device_time_us = WireMicroseconds(time_ns_);
  header.protocol_version = wire::kProtocolVersion;
  std::memcpy(header.firmware, options_.firmware.c_str(), options_.firmware.size() + 1);
  header.counts_per_motor_rev = options_.counts_per_motor_rev;
  header.gearbox_ratio = options_.gearbox_ratio;
  header.spur_gear_ratio = options_.spur_gear_ratio;
  last_header_ns_ = time_ns_;
}

void ControllerModel::EmitEvent(wire::EventKind kind, int32_t arg, const char* text) {
  wire::EventFrame& event = NewFrame(wire::FrameType::kEvent).event;
  event.sequence = next_sequence_++;
  event.device_time_us = WireMicroseconds(time_ns_);
  event.kind = kind;
  event.arg = arg;
  std::strncpy(event.text, text, wire::kMaxTextBytes);
  event.text[wire::kMaxTextBytes] = '\0';
}

void ControllerModel::TakeFrames(std::vector<wire::Frame>& out) {
  out.insert(out.end(), queue_.begin(), queue_.end());
  queue_.clear();
}

// ---------------------------------------------------------------------------------------
// EmulatorOptions, EmulatorStats

Status EmulatorOptions::Validate() const {
  if (!Within(rate_hz, 1.0, 100000.0)) return OutOfRange("rate_hz", "1 .. 100000", rate_hz);
  if (!Within(autostart_delay_s, 0.0, 3600.0)) {
    return OutOfRange("autostart_delay_s", "0 .. 3600", autostart_delay_s);
  }
  if (Status status = model.Validate(); !status.ok()) return status.WithContext("model");
  if (!Within(corrupt_byte_probability, 0.0, 1.0)) {
    return OutOfRange("corrupt_byte_probability", "0 .. 1", corrupt_byte_probability);
  }
  if (!Within(drop_frame_probability, 0.0, 1.0)) {
    return OutOfRange("drop_frame_probability", "0 .. 1", drop_frame_probability);
  }
  if (!std::isfinite(stall_at_s))
    return OutOfRange("stall_at_s", "a number (< 0: never)", stall_at_s);
  if (!Within(stall_for_s, 0.0, 3600.0)) return OutOfRange("stall_for_s", "0 .. 3600", stall_for_s);
  if (!std::isfinite(disconnect_at_s)) {
    return OutOfRange("disconnect_at_s", "a number (< 0: never)", disconnect_at_s);
  }
  if (!Within(disconnect_for_s, 0.0, 3600.0)) {
    return OutOfRange("disconnect_for_s", "0 .. 3600", disconnect_for_s);
  }
  if (disconnect_at_s >= 0 && link_path.empty()) {
    return InvalidArgumentError(
        "disconnect_at_s: a disconnect needs link_path (the returning pty has a new name, "
        "and the link is how a host finds it)");
  }
  if (!Within(clock_drift_ppm, -100000.0, 100000.0)) {
    return OutOfRange("clock_drift_ppm", "-100000 .. 100000", clock_drift_ppm);
  }
  if (!Within(duration_s, 0.0, 1e7))
    return OutOfRange("duration_s", "0 .. 1e7 (0: no limit)", duration_s);
  return Status::Ok();
}

std::string EmulatorStats::Brief() const {
  return std::to_string(frames_generated) + " frames made, " + std::to_string(frames_written) +
         " written, " + std::to_string(frames_dropped) + " dropped, " +
         std::to_string(frames_lost_disconnected) + " lost to disconnects, " +
         std::to_string(frames_overflowed) + " overflowed, " + std::to_string(frames_corrupted) +
         " corrupted (" + std::to_string(bytes_corrupted) + " bytes), " +
         std::to_string(disconnects) + " disconnects, " + std::to_string(stalls) + " stalls";
}

// ---------------------------------------------------------------------------------------
// Emulator

namespace {

// When a run's scripted events fall, ns since the run's start (-1: never).
struct RunSchedule {
  int64_t duration_ns = 0;  // 0: no limit
  int64_t stall_at_ns = -1;
  int64_t stall_end_ns = -1;
  int64_t disconnect_at_ns = -1;
  int64_t reconnect_at_ns = -1;
  // sample k leaves at device time k * period, i.e. host time k * period / (1 + drift)
  double host_period_ns = 0;

  int64_t HostDueNs(int64_t k) const {
    return std::llround(static_cast<double>(k) * host_period_ns);
  }
  bool Stalled(int64_t now_ns) const {
    return stall_at_ns >= 0 && now_ns >= stall_at_ns && now_ns < stall_end_ns;
  }
};

// What a run has done so far.
struct RunProgress {
  int64_t next_sample = 0;
  bool stall_counted = false;
  bool disconnect_done = false;
};

void SleepUntil(int64_t monotonic_ns) {
  timespec deadline{};
  deadline.tv_sec = static_cast<time_t>(monotonic_ns / kNanosecondsPerSecond);
  deadline.tv_nsec = static_cast<long>(monotonic_ns % kNanosecondsPerSecond);
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
  }
}

}  // namespace

struct Emulator::Impl {
  explicit Impl(const EmulatorOptions& emulator_options)
      : options(emulator_options), model(emulator_options.model), random(emulator_options.seed) {}

  // A frame in the output queue: its sequence number and length.
  struct Queued {
    uint32_t sequence = 0;
    size_t bytes = 0;
  };

  Status OpenPty();
  void Dispatch(const wire::Frame& frame);
  void MakeSample(int64_t index);
  Status ReadCommands(int64_t device_now_ns);
  void HandleLine(int64_t device_now_ns);
  // Writes what the pty takes now, without waiting.
  Status Flush();
  void Disconnect();
  // one turn of Run's loop, in order
  RunSchedule Schedule() const;
  Status FollowLinkScript(int64_t now_ns, const RunSchedule& schedule, RunProgress& progress);
  bool CountStall(int64_t now_ns, const RunSchedule& schedule, RunProgress& progress);
  void MakeDueSamples(int64_t now_ns, const RunSchedule& schedule, RunProgress& progress);
  void Wait(int64_t start_ns, bool linked, const RunSchedule& schedule,
            const RunProgress& progress);
  Status Drain(const std::atomic<bool>& stop);
  size_t queued_bytes() const { return out.size() - out_head; }
  bool test_over() const {
    return options.exit_after_test && model.test_end_ns() &&
           model.device_time_ns() >= *model.test_end_ns() + kAfterTestNs;
  }

  const EmulatorOptions options;
  ControllerModel model;
  SplitMix64 random;
  std::optional<PseudoTerminal> pty;
  bool disconnected = false;
  double device_per_host = 1.0;
  double sample_period_ns = 0;
  bool autostart_pending = false;

  // output: bytes from out_head on wait for the pty; `queued` holds their frames, the
  // first of which has head_written bytes out already
  std::string out;
  size_t out_head = 0;
  std::deque<Queued> queued;
  size_t head_written = 0;
  std::vector<wire::Frame> frames;

  // input: the host's line being received
  std::string line;
  bool line_too_long = false;

  // what link_path was last pointed at by us (empty: never)
  std::string link_target;

  mutable std::mutex mutex;  // guards stats and the two lists
  EmulatorStats stats;
  std::vector<uint32_t> dropped;
  std::vector<uint32_t> corrupted;
};

Status Emulator::Impl::OpenPty() {
  LIFTOFF_ASSIGN_OR_RETURN(PseudoTerminal opened, PseudoTerminal::Open());
  LIFTOFF_RETURN_IF_ERROR(MakeNonBlocking(opened.master_fd()));
  if (!options.link_path.empty()) {
    LIFTOFF_RETURN_IF_ERROR(PointLink(options.link_path, opened.slave_path()));
    link_target = opened.slave_path();
  }
  pty.emplace(std::move(opened));
  return Status::Ok();
}

void Emulator::Impl::Dispatch(const wire::Frame& frame) {
  const uint32_t sequence = SequenceOf(frame);
  std::lock_guard<std::mutex> lock(mutex);
  ++stats.frames_generated;
  // the frame's fate: lost, dropped, overflowed or queued
  if (disconnected) {
    ++stats.frames_lost_disconnected;
    dropped.push_back(sequence);
    return;
  }
  if (options.drop_frame_probability > 0 && random.Uniform() < options.drop_frame_probability) {
    ++stats.frames_dropped;
    dropped.push_back(sequence);
    return;
  }
  if (!options.unpaced && queued_bytes() >= kMaxQueuedBytes) {
    ++stats.frames_overflowed;
    dropped.push_back(sequence);
    return;
  }
  char bytes[wire::kMaxFrameBytes];
  const size_t size = wire::EncodeFrame(frame, bytes, sizeof bytes);
  assert(size > 0);
  // corruption: each byte independently gets one bit flipped
  if (options.corrupt_byte_probability > 0) {
    int64_t flipped = 0;
    for (size_t i = 0; i < size; ++i) {
      if (random.Uniform() < options.corrupt_byte_probability) {
        bytes[i] = static_cast<char>(bytes[i] ^ (1 << (random.Next() & 7)));
        ++flipped;
      }
    }
    if (flipped > 0) {
      stats.bytes_corrupted += flipped;
      ++stats.frames_corrupted;
      corrupted.push_back(sequence);
    }
  }
  out.append(bytes, size);
  queued.push_back({sequence, size});
}

void Emulator::Impl::MakeSample(int64_t index) {
  const int64_t device_ns = std::llround(static_cast<double>(index) * sample_period_ns);
  if (autostart_pending && device_ns >= NsFromSeconds(options.autostart_delay_s)) {
    autostart_pending = false;
    model.StartTest(options.model.test, NsFromSeconds(options.autostart_delay_s));
  }
  model.Advance(device_ns);
  model.EmitSample();
  frames.clear();
  model.TakeFrames(frames);
  for (const wire::Frame& frame : frames) Dispatch(frame);
}

Status Emulator::Impl::ReadCommands(int64_t device_now_ns) {
  char buffer[512];
  for (;;) {
    const ssize_t n = ::read(pty->master_fd(), buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    // EAGAIN: nothing more; EIO: no reader has the slave open
    if (n < 0 && (errno == EAGAIN || errno == EIO)) return Status::Ok();
    if (n < 0) return IoError(std::string("pty master: read: ") + std::strerror(errno));
    if (n == 0) return Status::Ok();
    for (ssize_t i = 0; i < n; ++i) {
      const char c = buffer[i];
      if (c == '\n') {
        HandleLine(device_now_ns);
      } else if (line.size() < wire::kMaxFrameBytes) {
        line.push_back(c);
      } else {
        line_too_long = true;
      }
    }
  }
}

void Emulator::Impl::HandleLine(int64_t device_now_ns) {
  // commands take effect at the host's instant, but never before the model's present
  const int64_t at_ns = std::max(device_now_ns, model.device_time_ns());
  wire::Frame frame;
  const bool blank = line.empty() || line == "\r";
  const bool ok = !blank && !line_too_long &&
                  wire::DecodeLine(line.data(), line.size(), &frame) == wire::DecodeError::kOk &&
                  frame.type == wire::FrameType::kCommand;
  if (!blank) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++(ok ? stats.commands_received : stats.bad_lines_received);
    }
    if (ok) {
      model.Command(frame.command, at_ns);
    } else {
      model.RejectLine(at_ns);
    }
    frames.clear();
    model.TakeFrames(frames);
    for (const wire::Frame& reply : frames) Dispatch(reply);
  }
  line.clear();
  line_too_long = false;
}

Status Emulator::Impl::Flush() {
  while (queued_bytes() > 0) {
    const ssize_t n = ::write(pty->master_fd(), out.data() + out_head, queued_bytes());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) break;
    if (n < 0) return IoError(std::string("pty master: write: ") + std::strerror(errno));
    // account whole frames
    size_t left = static_cast<size_t>(n);
    out_head += left;
    std::lock_guard<std::mutex> lock(mutex);
    stats.bytes_written += n;
    while (left > 0) {
      const size_t take = std::min(left, queued.front().bytes - head_written);
      head_written += take;
      left -= take;
      if (head_written == queued.front().bytes) {
        ++stats.frames_written;
        queued.pop_front();
        head_written = 0;
      }
    }
  }
  // compact once the written part dominates
  if (out_head > out.size() / 2) {
    out.erase(0, out_head);
    out_head = 0;
  }
  return Status::Ok();
}

void Emulator::Impl::Disconnect() {
  // the queue dies with the port, a partly written frame too
  {
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.disconnects;
    for (const Queued& frame : queued) {
      ++stats.frames_lost_disconnected;
      dropped.push_back(frame.sequence);
    }
  }
  queued.clear();
  head_written = 0;
  out.clear();
  out_head = 0;
  line.clear();
  line_too_long = false;
  pty->CloseMaster();
  pty.reset();
  disconnected = true;
}

Emulator::Emulator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Emulator::~Emulator() {
  // remove the link when it is still the one we made (also while disconnected, when it
  // names our closed pty), never one someone has re-pointed since
  const fs::path& link = impl_->options.link_path;
  if (!link.empty() && !impl_->link_target.empty()) {
    std::error_code error;
    if (fs::is_symlink(fs::symlink_status(link, error)) &&
        fs::read_symlink(link, error) == fs::path(impl_->link_target)) {
      fs::remove(link, error);
    }
  }
}

Result<std::unique_ptr<Emulator>> Emulator::Create(const EmulatorOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (!options.link_path.empty()) {
    std::error_code error;
    const fs::file_status status = fs::symlink_status(options.link_path, error);
    if (fs::exists(status) && !fs::is_symlink(status)) {
      return InvalidArgumentError("link_path: " + options.link_path.string() +
                                  " exists and is not a symbolic link; not replacing it");
    }
  }
  auto impl = std::make_unique<Impl>(options);
  impl->device_per_host = 1.0 + options.clock_drift_ppm * 1e-6;
  impl->sample_period_ns = 1e9 / options.rate_hz;
  impl->autostart_pending = options.autostart;
  LIFTOFF_RETURN_IF_ERROR(impl->OpenPty());
  std::unique_ptr<Emulator> emulator(new Emulator(std::move(impl)));
  emulator->port_path_ =
      options.link_path.empty() ? fs::path(emulator->impl_->pty->slave_path()) : options.link_path;
  return emulator;
}

RunSchedule Emulator::Impl::Schedule() const {
  const EmulatorOptions& o = options;
  RunSchedule schedule;
  schedule.duration_ns = NsFromSeconds(o.duration_s);
  schedule.stall_at_ns = o.stall_at_s >= 0 ? NsFromSeconds(o.stall_at_s) : -1;
  schedule.stall_end_ns = schedule.stall_at_ns + NsFromSeconds(o.stall_for_s);
  schedule.disconnect_at_ns = o.disconnect_at_s >= 0 ? NsFromSeconds(o.disconnect_at_s) : -1;
  schedule.reconnect_at_ns = schedule.disconnect_at_ns + NsFromSeconds(o.disconnect_for_s);
  schedule.host_period_ns = sample_period_ns / device_per_host;
  return schedule;
}

// the port goes away, and comes back as a new pty
Status Emulator::Impl::FollowLinkScript(int64_t now_ns, const RunSchedule& schedule,
                                        RunProgress& progress) {
  if (schedule.disconnect_at_ns >= 0 && !progress.disconnect_done && !disconnected &&
      now_ns >= schedule.disconnect_at_ns) {
    Disconnect();
  }
  if (disconnected && now_ns >= schedule.reconnect_at_ns) {
    LIFTOFF_RETURN_IF_ERROR(OpenPty().WithContext("reconnecting after the disconnect"));
    disconnected = false;
    progress.disconnect_done = true;
    model.EmitHeader();
  }
  return Status::Ok();
}

// whether the link is stalled now; the stall is counted once
bool Emulator::Impl::CountStall(int64_t now_ns, const RunSchedule& schedule,
                                RunProgress& progress) {
  const bool stalled = schedule.Stalled(now_ns);
  if (stalled && !progress.stall_counted) {
    progress.stall_counted = true;
    std::lock_guard<std::mutex> lock(mutex);
    ++stats.stalls;
  }
  return stalled;
}

// samples due by now (paced), or a batch while the reader keeps up (unpaced)
void Emulator::Impl::MakeDueSamples(int64_t now_ns, const RunSchedule& schedule,
                                    RunProgress& progress) {
  if (options.unpaced) {
    for (int i = 0; i < kUnpacedBatchFrames && queued_bytes() < kUnpacedQueueBytes; ++i) {
      MakeSample(progress.next_sample++);
    }
  } else {
    while (schedule.HostDueNs(progress.next_sample) <= now_ns && !test_over()) {
      MakeSample(progress.next_sample++);
    }
  }
}

// wait: for the next sample (paced), or for the reader to take bytes (unpaced)
void Emulator::Impl::Wait(int64_t start_ns, bool linked, const RunSchedule& schedule,
                          const RunProgress& progress) {
  const int64_t now_ns = MonotonicNowNs() - start_ns;
  if (options.unpaced && linked && queued_bytes() >= kUnpacedQueueBytes) {
    pollfd fd{pty->master_fd(), POLLOUT, 0};
    ::poll(&fd, 1, 10);
  } else if (options.unpaced && !linked) {
    SleepUntil(start_ns + now_ns + kNanosecondsPerMillisecond);
  } else if (!options.unpaced) {
    int64_t wake_ns = std::min(schedule.HostDueNs(progress.next_sample), now_ns + kMaxSleepNs);
    // a reader behind on its bytes gets another try soon
    if (linked && queued_bytes() > 0)
      wake_ns = std::min(wake_ns, now_ns + kNanosecondsPerMillisecond);
    if (wake_ns > now_ns) SleepUntil(start_ns + wake_ns);
  }
}

// a run that ended by itself gives its last frames time to reach the reader
Status Emulator::Impl::Drain(const std::atomic<bool>& stop) {
  const int64_t drain_end_ns = MonotonicNowNs() + kDrainNs;
  while (queued_bytes() > 0 && MonotonicNowNs() < drain_end_ns &&
         !stop.load(std::memory_order_relaxed)) {
    LIFTOFF_RETURN_IF_ERROR(Flush());
    if (queued_bytes() > 0) {
      pollfd fd{pty->master_fd(), POLLOUT, 0};
      ::poll(&fd, 1, 10);
    }
  }
  return Status::Ok();
}

Status Emulator::Run(const std::atomic<bool>& stop) {
  Impl& s = *impl_;
  const RunSchedule schedule = s.Schedule();
  const int64_t start_ns = MonotonicNowNs();
  RunProgress progress;
  bool finished = false;  // the run's end came by itself (not `stop`)

  while (!stop.load(std::memory_order_relaxed)) {
    const int64_t now_ns = MonotonicNowNs() - start_ns;
    if (schedule.duration_ns > 0 && now_ns >= schedule.duration_ns) {
      finished = true;
      break;
    }
    // the link as scripted, the samples due, then the host's side
    LIFTOFF_RETURN_IF_ERROR(s.FollowLinkScript(now_ns, schedule, progress));
    const bool stalled = s.CountStall(now_ns, schedule, progress);
    const bool linked = !s.disconnected && !stalled;
    s.MakeDueSamples(now_ns, schedule, progress);
    // frames made before the host's commands: the model is never ahead of its present
    if (linked) {
      const int64_t device_now_ns = std::llround(static_cast<double>(now_ns) * s.device_per_host);
      LIFTOFF_RETURN_IF_ERROR(s.ReadCommands(device_now_ns));
      LIFTOFF_RETURN_IF_ERROR(s.Flush());
    }
    if (s.test_over()) {
      finished = true;
      break;
    }
    s.Wait(start_ns, linked, schedule, progress);
  }
  if (finished && !s.disconnected) LIFTOFF_RETURN_IF_ERROR(s.Drain(stop));
  return Status::Ok();
}

EmulatorStats Emulator::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

std::vector<uint32_t> Emulator::dropped_sequences() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<uint32_t> sequences = impl_->dropped;
  std::sort(sequences.begin(), sequences.end());
  return sequences;
}

std::vector<uint32_t> Emulator::corrupted_sequences() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<uint32_t> sequences = impl_->corrupted;
  std::sort(sequences.begin(), sequences.end());
  return sequences;
}

}  // namespace liftoff::capture
