// The controller emulator: the model's physics and test sequence against hand-computed
// figures, and the emulator over a real pseudo-terminal read through a plain termios file
// descriptor (frames split at '$' and '\n' and checked by wire::DecodeLine), with every
// injected fault accounted for against the emulator's own record of what it did.
//
// Hand-computed constants (2018 drive chain, 12 counts/rev, 1000:1, spur 4:1):
//   counts per output-shaft radian = 12000 / 2 pi = 1909.859
//   bend target at 80 %: 0.2 * 0.088 m / (3 * 0.004 m) = 1.466667 rad -> 2801.13 -> 2801
//   ramp +pi/3 (vertebra) = 4 pi/3 shaft rad -> 8000 counts exactly
#include "liftoff/capture/emulator.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "liftoff/core/time.h"
#include "support/test_support.h"

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;
using wire::EventKind;
using wire::FrameType;

constexpr double kPi = std::numbers::pi;
constexpr double kCountsPerShaftRad = 12000.0 / (2.0 * kPi);
constexpr int64_t kMs = kNanosecondsPerMillisecond;
constexpr int64_t kSecond = kNanosecondsPerSecond;

std::vector<wire::Frame> Take(ControllerModel& model) {
  std::vector<wire::Frame> frames;
  model.TakeFrames(frames);
  return frames;
}

std::vector<wire::Frame> EventsOf(const std::vector<wire::Frame>& frames) {
  std::vector<wire::Frame> events;
  for (const wire::Frame& frame : frames) {
    if (frame.type == FrameType::kEvent) events.push_back(frame);
  }
  return events;
}

uint32_t SequenceOf(const wire::Frame& frame) {
  switch (frame.type) {
    case FrameType::kSample: return frame.sample.sequence;
    case FrameType::kHeader: return frame.header.sequence;
    case FrameType::kEvent: return frame.event.sequence;
    default: return 0;
  }
}

wire::CommandFrame MakeCommand(wire::CommandKind kind, int32_t a = 0, int32_t b = 0, int32_t c = 0,
                               int32_t d = 0) {
  wire::CommandFrame command;
  command.command = kind;
  command.args[0] = a;
  command.args[1] = b;
  command.args[2] = c;
  command.args[3] = d;
  return command;
}

// A quick test: bend from 0.1 s, ramp +pi/3 from 1.0 s over 0.5 s, TEST_END 0.2 s later.
ControllerModelOptions ShortTest() {
  ControllerModelOptions options;
  options.bend_delay_s = 0.1;
  options.ramp_delay_s = 1.0;
  options.test.ramp_duration_s = 0.5;
  options.end_hold_s = 0.2;
  options.max_shaft_speed_rad_per_s = 20.0;
  return options;
}

// ---------------------------------------------------------------------------------------
// ControllerModel

TEST(ControllerModel, NothingMovesAndLedStaysOffBeforeStart) {
  ControllerModel model(ControllerModelOptions{});
  model.Advance(2500 * kMs);
  model.EmitSample();
  const std::vector<wire::Frame> frames = Take(model);
  // boot header, one header per idle second, then the sample
  ASSERT_EQ(frames.size(), 4u);
  for (size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(frames[i].type, FrameType::kHeader);
    EXPECT_EQ(frames[i].header.device_time_us, static_cast<uint32_t>(i) * 1'000'000u);
    EXPECT_EQ(frames[i].header.counts_per_motor_rev, 12u);
    EXPECT_EQ(frames[i].header.gearbox_ratio, 1000u);
    EXPECT_EQ(frames[i].header.spur_gear_ratio, 4u);
    EXPECT_EQ(frames[i].header.protocol_version, 1u);
  }
  const wire::SampleFrame& sample = frames[3].sample;
  EXPECT_EQ(sample.sequence, 3u);
  EXPECT_EQ(sample.device_time_us, 2'500'000u);
  EXPECT_EQ(sample.led_on, 0);
  EXPECT_EQ(sample.bend_counts, 0);
  EXPECT_EQ(sample.rotate_counts, 0);
  EXPECT_EQ(sample.bend_setpoint_counts, 0);
  EXPECT_EQ(sample.rotate_setpoint_counts, 0);
  EXPECT_EQ(model.phase(), TestPhase::kIdle);
}

TEST(ControllerModel, StartSwitchesTheLedOnAndAnnouncesTheTest) {
  ControllerModel model(ControllerModelOptions{});
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kStart, 2, 800, 60000, 40000), 300 * kMs);
  const std::vector<wire::Frame> frames = Take(model);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].event.kind, EventKind::kAck);
  EXPECT_EQ(frames[0].event.arg, 0);  // START's code
  EXPECT_EQ(frames[1].event.kind, EventKind::kTestStart);
  EXPECT_EQ(frames[2].event.kind, EventKind::kLedOn);
  EXPECT_EQ(frames[3].type, FrameType::kHeader);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(SequenceOf(frames[i]), 1u + i);  // the boot header was 0
  }
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(frames[i].event.device_time_us, 300'000u) << i;
  EXPECT_EQ(frames[3].header.device_time_us, 300'000u);
  EXPECT_TRUE(model.led_on());
  EXPECT_EQ(model.phase(), TestPhase::kStarting);
  EXPECT_EQ(model.test().pulled_group, CableGroup::kHR);
  EXPECT_NEAR(model.test().ramp_amplitude_rad, kPi / 3, 1e-12);
  model.EmitSample();
  EXPECT_EQ(Take(model)[0].sample.led_on, 1);
}

TEST(ControllerModel, BendReachesItsTargetWithinTheLag) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  // before the bend delay nothing moves
  model.Advance(90 * kMs);
  EXPECT_EQ(model.bend_counts(), 0);
  EXPECT_EQ(model.phase(), TestPhase::kStarting);
  // the spool winds at 0.025 / 0.012 = 2.0833 rad/s for 1.466667 rad: done at 0.804 s
  model.Advance(500 * kMs);
  EXPECT_EQ(model.phase(), TestPhase::kBending);
  EXPECT_NEAR(model.bend_setpoint_rad(), 0.4 * 0.025 / 0.012, 1e-9);
  // a first-order lag behind a ramp trails it by rate * tau
  EXPECT_NEAR(model.bend_setpoint_rad() - model.bend_shaft_rad(), 0.025 / 0.012 * 0.05, 1e-3);
  model.Advance(800 * kMs);
  EXPECT_LT(model.bend_shaft_rad(), 1.466667);
  // five time constants after the setpoint arrived
  model.Advance(804 * kMs + 250 * kMs);
  EXPECT_EQ(model.phase(), TestPhase::kRamping);
  EXPECT_EQ(model.bend_setpoint_counts(), 2801);
  EXPECT_NEAR(model.bend_counts(), 2801, 2);
  model.Advance(1500 * kMs);
  EXPECT_EQ(model.bend_counts(), 2801);
}

TEST(ControllerModel, PullingHlWindsTheSpoolTheOtherWay) {
  ControllerModelOptions options = ShortTest();
  options.test.pulled_group = CableGroup::kHL;
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  model.Advance(2 * kSecond);
  EXPECT_EQ(model.bend_setpoint_counts(), -2801);
  EXPECT_EQ(model.bend_counts(), -2801);
}

TEST(ControllerModel, RotationFollowsTheRampWithinLagTimesRate) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  // the shaft ramps 4 pi/3 rad in 0.5 s: 8.3776 rad/s, trailing by 8.3776 * 0.05 = 0.419 rad
  const double rate_rad_per_s = 4.0 * kPi / 3.0 / 0.5;
  for (int64_t t_ms = 1250; t_ms <= 1490; t_ms += 40) {
    model.Advance(t_ms * kMs);
    const double expected_setpoint = rate_rad_per_s * (static_cast<double>(t_ms) / 1000.0 - 1.0);
    EXPECT_NEAR(model.rotate_setpoint_rad(), expected_setpoint, 1e-9) << t_ms;
    const double lag_rad = model.rotate_setpoint_rad() - model.rotate_shaft_rad();
    EXPECT_LE(lag_rad, rate_rad_per_s * 0.05 + 1e-6) << t_ms;
    EXPECT_GE(lag_rad, 0.95 * rate_rad_per_s * 0.05) << t_ms;
  }
  model.Advance(1250 * kMs + 1);
  model.Advance(1250 * kMs);  // an earlier time changes nothing
  EXPECT_EQ(model.device_time_ns(), 1490 * kMs);
  // halfway: pi/6 of vertebra = 2 pi/3 of shaft = 4000 counts
  ControllerModel halfway(options);
  halfway.StartTest(options.test, 0);
  halfway.Advance(1250 * kMs);
  EXPECT_EQ(halfway.rotate_setpoint_counts(), 4000);
  model.Advance(2 * kSecond);
  EXPECT_EQ(model.rotate_setpoint_counts(), 8000);
  EXPECT_EQ(model.rotate_counts(), 8000);
}

TEST(ControllerModel, SpeedLimitCapsTheShaft) {
  ControllerModelOptions options = ShortTest();
  options.max_shaft_speed_rad_per_s = 3.3;
  options.test.ramp_duration_s = 0.1;  // 41.9 rad/s asked
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  model.Advance(1 * kSecond);
  const double at_ramp_start = model.rotate_shaft_rad();
  model.Advance(1500 * kMs);
  EXPECT_LE(model.rotate_shaft_rad() - at_ramp_start, 3.3 * 0.5 + 1e-9);
  EXPECT_GE(model.rotate_shaft_rad() - at_ramp_start, 3.3 * 0.5 * 0.99);
}

TEST(ControllerModel, CountsAreTheShaftAngleQuantised) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  int distinct_fractions = 0;
  for (int64_t t_us = 0; t_us < 1'800'000; t_us += 777) {
    model.Advance(t_us * 1000);
    model.EmitSample();
    const wire::SampleFrame sample = Take(model).back().sample;
    EXPECT_EQ(sample.bend_counts, std::llround(model.bend_shaft_rad() * kCountsPerShaftRad));
    EXPECT_EQ(sample.rotate_counts, std::llround(model.rotate_shaft_rad() * kCountsPerShaftRad));
    EXPECT_EQ(sample.rotate_setpoint_counts,
              std::llround(model.rotate_setpoint_rad() * kCountsPerShaftRad));
    const double fraction = model.rotate_shaft_rad() * kCountsPerShaftRad;
    if (std::abs(fraction - std::round(fraction)) > 0.1) ++distinct_fractions;
  }
  // the angles really fall between counts
  EXPECT_GT(distinct_fractions, 100);
}

TEST(ControllerModel, TestEndsAfterTheRampAndTheHold) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  Take(model);
  model.StartTest(options.test, 100 * kMs);
  Take(model);
  model.Advance(1700 * kMs);
  EXPECT_EQ(model.phase(), TestPhase::kSettling);
  EXPECT_TRUE(Take(model).empty());
  model.Advance(1900 * kMs);
  // start 0.1 + ramp delay 1.0 + ramp 0.5 + hold 0.2 = 1.8 s
  const std::vector<wire::Frame> events = EventsOf(Take(model));
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].event.kind, EventKind::kTestEnd);
  EXPECT_EQ(events[0].event.arg, 0);
  EXPECT_EQ(events[0].event.device_time_us, 1'800'000u);
  EXPECT_EQ(events[1].event.kind, EventKind::kLedOff);
  EXPECT_EQ(model.phase(), TestPhase::kDone);
  EXPECT_FALSE(model.led_on());
  ASSERT_TRUE(model.test_end_ns());
  EXPECT_EQ(*model.test_end_ns(), 1800 * kMs);
  // done: headers again once a second, motors hold
  model.Advance(2900 * kMs);
  const std::vector<wire::Frame> idle = Take(model);
  ASSERT_EQ(idle.size(), 1u);
  EXPECT_EQ(idle[0].type, FrameType::kHeader);
  EXPECT_EQ(model.rotate_counts(), 8000);
}

TEST(ControllerModel, StopEndsTheTestAndHoldsTheMotors) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kStop), 1200 * kMs);
  const std::vector<wire::Frame> frames = Take(model);
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[0].event.kind, EventKind::kAck);
  EXPECT_EQ(frames[0].event.arg, 1);  // STOP's code
  EXPECT_EQ(frames[1].event.kind, EventKind::kTestEnd);
  EXPECT_EQ(frames[1].event.arg, 1);  // stopped
  EXPECT_EQ(frames[2].event.kind, EventKind::kLedOff);
  EXPECT_EQ(frames[3].type, FrameType::kHeader);
  EXPECT_EQ(model.phase(), TestPhase::kStopped);
  EXPECT_FALSE(model.led_on());
  const int32_t bend = model.bend_counts();
  const int32_t rotate = model.rotate_counts();
  EXPECT_GT(rotate, 0);
  EXPECT_LT(rotate, 8000);
  model.Advance(3 * kSecond);
  EXPECT_EQ(model.bend_counts(), bend);
  EXPECT_EQ(model.rotate_counts(), rotate);
  EXPECT_EQ(model.rotate_setpoint_counts(), rotate);
}

TEST(ControllerModel, ZeroMakesBothEncodersReadZeroWithoutMoving) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  model.StartTest(options.test, 0);
  model.Command(MakeCommand(wire::CommandKind::kZero), 500 * kMs);
  std::vector<wire::Frame> events = EventsOf(Take(model));
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.back().event.kind, EventKind::kNak);
  EXPECT_EQ(events.back().event.arg, 2);  // ZERO's code
  EXPECT_STREQ(events.back().event.text, "busy");

  model.Advance(3 * kSecond);
  ASSERT_EQ(model.phase(), TestPhase::kDone);
  EXPECT_EQ(model.rotate_counts(), 8000);
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kZero), 3 * kSecond);
  events = EventsOf(Take(model));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].event.kind, EventKind::kAck);
  EXPECT_EQ(events[0].event.arg, 2);
  EXPECT_EQ(model.bend_counts(), 0);
  EXPECT_EQ(model.rotate_counts(), 0);
  model.Advance(5 * kSecond);
  EXPECT_EQ(model.bend_counts(), 0);
  EXPECT_EQ(model.rotate_counts(), 0);
}

TEST(ControllerModel, PingIsAnsweredWithItsToken) {
  ControllerModel model(ControllerModelOptions{});
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kPing, 4242), 10 * kMs);
  const std::vector<wire::Frame> frames = Take(model);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].event.kind, EventKind::kPong);
  EXPECT_EQ(frames[0].event.arg, 4242);
  EXPECT_EQ(frames[0].event.device_time_us, 10'000u);
  EXPECT_EQ(frames[1].type, FrameType::kHeader);
}

// docs/protocol.md section 3: a header follows every reply, during a test too, and no
// other header interrupts a running test.
TEST(ControllerModel, EveryReplyIsFollowedByAHeaderEvenDuringATest) {
  const ControllerModelOptions options = ShortTest();
  ControllerModel model(options);
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kStart), 100 * kMs);
  std::vector<wire::Frame> frames = Take(model);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back().type, FrameType::kHeader);
  // 1.2 s of samples into the test: no header of its own
  for (int64_t t_ms = 110; t_ms <= 1300; t_ms += 10) {
    model.Advance(t_ms * kMs);
    model.EmitSample();
  }
  for (const wire::Frame& frame : Take(model)) EXPECT_NE(frame.type, FrameType::kHeader);
  ASSERT_EQ(model.phase(), TestPhase::kRamping);
  // a PING during the test: PONG, then a header
  model.Command(MakeCommand(wire::CommandKind::kPing, -7), 1305 * kMs);
  frames = Take(model);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].event.kind, EventKind::kPong);
  EXPECT_EQ(frames[0].event.arg, -7);  // arg is signed: the token comes back as sent
  EXPECT_EQ(frames[1].type, FrameType::kHeader);
  EXPECT_EQ(frames[1].header.device_time_us, 1'305'000u);
  // a START refused as busy: NAK, then a header
  model.Command(MakeCommand(wire::CommandKind::kStart), 1310 * kMs);
  frames = Take(model);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].event.kind, EventKind::kNak);
  EXPECT_EQ(frames[1].type, FrameType::kHeader);
}

TEST(ControllerModel, BadCommandsAreRefusedWithNak) {
  struct Case {
    wire::CommandFrame command;
    int32_t code;
    const char* why;
  };
  const Case cases[] = {
      {MakeCommand(wire::CommandKind::kStart, 1, 800, 60000, 40000), 0, "bad group"},
      {MakeCommand(wire::CommandKind::kStart, 2, 400, 60000, 40000), 0, "bad bend"},
      {MakeCommand(wire::CommandKind::kStart, 2, 800, 190000, 40000), 0, "bad amplitude"},
      {MakeCommand(wire::CommandKind::kStart, 2, 800, 60000, 0), 0, "bad duration"},
      {MakeCommand(static_cast<wire::CommandKind>(9)), 9, "unknown command"},
  };
  for (const Case& c : cases) {
    ControllerModel model(ControllerModelOptions{});
    Take(model);
    model.Command(c.command, 0);
    const std::vector<wire::Frame> events = EventsOf(Take(model));
    ASSERT_EQ(events.size(), 1u) << c.why;
    EXPECT_EQ(events[0].event.kind, EventKind::kNak);
    EXPECT_EQ(events[0].event.arg, c.code);
    EXPECT_STREQ(events[0].event.text, c.why);
    EXPECT_FALSE(model.led_on());
    EXPECT_EQ(model.phase(), TestPhase::kIdle);
  }
  // a second START while one runs
  ControllerModel model(ControllerModelOptions{});
  model.Command(MakeCommand(wire::CommandKind::kStart), 0);
  Take(model);
  model.Command(MakeCommand(wire::CommandKind::kStart), 10 * kMs);
  const std::vector<wire::Frame> events = EventsOf(Take(model));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_STREQ(events[0].event.text, "busy");
  // a line that is no command
  model.RejectLine(20 * kMs);
  const std::vector<wire::Frame> fault = Take(model);
  ASSERT_EQ(fault.size(), 1u);
  EXPECT_EQ(fault[0].event.kind, EventKind::kFault);
  EXPECT_EQ(fault[0].event.arg, 1);
}

TEST(ControllerModel, SameInputsGiveTheSameBytes) {
  const auto run = [](const ControllerModelOptions& options) {
    ControllerModel model(options);
    std::string bytes;
    std::vector<wire::Frame> frames;
    for (int64_t k = 0; k < 3000; ++k) {
      if (k == 100) model.Command(MakeCommand(wire::CommandKind::kStart), k * kMs);
      if (k == 2000) model.Command(MakeCommand(wire::CommandKind::kPing, 7), k * kMs + 300'000);
      model.Advance(k * kMs);
      model.EmitSample();
    }
    model.TakeFrames(frames);
    for (const wire::Frame& frame : frames) {
      char line[wire::kMaxFrameBytes];
      const size_t size = wire::EncodeFrame(frame, line, sizeof line);
      EXPECT_GT(size, 0u);
      bytes.append(line, size);
    }
    return bytes;
  };
  const std::string first = run(ShortTest());
  EXPECT_EQ(first, run(ShortTest()));
  ControllerModelOptions slower = ShortTest();
  slower.motor_time_constant_s = 0.06;
  EXPECT_NE(first, run(slower));
  EXPECT_GT(first.size(), 3000u * 30u);
}

TEST(TestParameters, StartCommandCarriesTheParametersInWireUnits) {
  TestParameters test;
  test.pulled_group = CableGroup::kHL;
  test.ramp_amplitude_rad = -kPi / 3;
  const wire::CommandFrame command = test.StartCommand();
  EXPECT_EQ(command.command, wire::CommandKind::kStart);
  EXPECT_EQ(command.args[0], 3);
  EXPECT_EQ(command.args[1], 800);
  EXPECT_EQ(command.args[2], -60000);
  EXPECT_EQ(command.args[3], 40000);
  const Result<TestParameters> back = TestParameters::FromStartCommand(command, TestParameters{});
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->pulled_group, CableGroup::kHL);
  EXPECT_DOUBLE_EQ(back->bend_target_fraction, 0.8);
  EXPECT_NEAR(back->ramp_amplitude_rad, -kPi / 3, 1e-12);
  EXPECT_DOUBLE_EQ(back->ramp_duration_s, 40.0);
  // all-zero arguments: the controller's own test
  TestParameters defaults;
  defaults.ramp_duration_s = 12.5;
  const Result<TestParameters> own =
      TestParameters::FromStartCommand(MakeCommand(wire::CommandKind::kStart), defaults);
  ASSERT_TRUE(own.ok());
  EXPECT_DOUBLE_EQ(own->ramp_duration_s, 12.5);
}

TEST(EmulatorOptions, ValidateNamesTheField) {
  struct Case {
    void (*change)(EmulatorOptions&);
    const char* field;
  };
  const Case cases[] = {
      {[](EmulatorOptions& o) { o.rate_hz = 0; }, "rate_hz: expected 1 .. 100000, got 0"},
      {[](EmulatorOptions& o) { o.drop_frame_probability = 1.5; }, "drop_frame_probability"},
      {[](EmulatorOptions& o) { o.corrupt_byte_probability = -0.1; }, "corrupt_byte_probability"},
      {[](EmulatorOptions& o) { o.stall_for_s = -1; }, "stall_for_s"},
      {[](EmulatorOptions& o) { o.disconnect_at_s = 1; },
       "disconnect_at_s: a disconnect needs link_path"},
      {[](EmulatorOptions& o) { o.clock_drift_ppm = 2e5; }, "clock_drift_ppm"},
      {[](EmulatorOptions& o) { o.duration_s = std::nan(""); }, "duration_s"},
      {[](EmulatorOptions& o) { o.model.motor_time_constant_s = 0; },
       "model: motor_time_constant_s"},
      {[](EmulatorOptions& o) { o.model.test.bend_target_fraction = 0.2; },
       "model: test: bend_target_fraction: expected 0.5 .. 1, got 0.2"},
      {[](EmulatorOptions& o) { o.model.test.pulled_group = CableGroup::kHT; },
       "model: test: pulled_group: expected HR or HL, got HT"},
      {[](EmulatorOptions& o) { o.model.firmware = "a,b"; }, "model: firmware"},
      {[](EmulatorOptions& o) { o.model.gearbox_ratio = 100000000; }, "gearbox_ratio"},
  };
  EXPECT_TRUE(EmulatorOptions{}.Validate().ok());
  for (const Case& c : cases) {
    EmulatorOptions options;
    c.change(options);
    const Status status = options.Validate();
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << c.field;
    EXPECT_NE(status.message().find(c.field), std::string::npos) << status.message();
  }
  EmulatorOptions bad;
  bad.rate_hz = -5;
  const auto emulator = Emulator::Create(bad);
  ASSERT_FALSE(emulator.ok());
  EXPECT_NE(emulator.status().message().find("rate_hz"), std::string::npos);
}

TEST(Emulator, RefusesToReplaceAFileThatIsNotALink) {
  testing::ScratchDir scratch;
  testing::WriteFile(scratch / "port", "keep me");
  EmulatorOptions options;
  options.link_path = scratch / "port";
  const auto emulator = Emulator::Create(options);
  ASSERT_FALSE(emulator.ok());
  EXPECT_EQ(emulator.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(emulator.status().message().find((scratch / "port").string()), std::string::npos);
  EXPECT_EQ(testing::ReadFile(scratch / "port"), "keep me");
}

// ---------------------------------------------------------------------------------------
// Emulator over a pseudo-terminal

// Reads the slave side like a host would, with termios and poll only, and splits the
// bytes into frames: a frame runs from '$' to '\n'; a '$' inside one cuts it off.
class SlaveReader {
 public:
  enum class Outcome { kData, kTimeout, kHangUp };

  explicit SlaveReader(const fs::path& path) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) return;
    termios settings{};
    ::tcgetattr(fd_, &settings);
    ::cfmakeraw(&settings);
    ::tcsetattr(fd_, TCSANOW, &settings);
  }
  ~SlaveReader() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool is_open() const { return fd_ >= 0; }

  Outcome ReadSome(int timeout_ms) {
    pollfd fd{fd_, POLLIN, 0};
    if (::poll(&fd, 1, timeout_ms) <= 0) return Outcome::kTimeout;
    char buffer[4096];
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n > 0) {
      Feed(buffer, static_cast<size_t>(n));
      chunk_times_ns.push_back(MonotonicNowNs());
      return Outcome::kData;
    }
    if (n < 0 && errno == EAGAIN) return Outcome::kTimeout;
    return Outcome::kHangUp;  // 0 bytes after a hang-up, or EIO
  }
  // Reads until `done` is true and then `quiet_ms` pass without a byte.
  void ReadUntil(const std::atomic<bool>& done, int quiet_ms = 100) {
    while (!done.load()) {
      if (ReadSome(5) == Outcome::kHangUp) return;
    }
    while (ReadSome(quiet_ms) == Outcome::kData) {
    }
  }
  void Write(const std::string& text) {
    ASSERT_EQ(::write(fd_, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  }

  std::vector<wire::Frame> frames;
  int64_t rejected_lines = 0;
  int64_t bytes = 0;
  std::vector<int64_t> chunk_times_ns;

 private:
  void Feed(const char* data, size_t size) {
    bytes += static_cast<int64_t>(size);
    for (size_t i = 0; i < size; ++i) {
      const char c = data[i];
      if (c == '$') {
        if (in_frame_) ++rejected_lines;
        line_ = "$";
        in_frame_ = true;
      } else if (in_frame_ && c == '\n') {
        wire::Frame frame;
        if (wire::DecodeLine(line_.data(), line_.size(), &frame) == wire::DecodeError::kOk) {
          frames.push_back(frame);
        } else {
          ++rejected_lines;
        }
        in_frame_ = false;
      } else if (in_frame_) {
        line_.push_back(c);
      }
    }
  }

  int fd_ = -1;
  std::string line_;
  bool in_frame_ = false;
};

// Runs an emulator on a thread; stops and joins it however the test ends.
class Running {
 public:
  explicit Running(Emulator& emulator)
      : thread_([this, &emulator] {
          status_ = emulator.Run(stop_);
          done_ = true;
        }) {}
  ~Running() { static_cast<void>(Join()); }
  Status Join() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    return status_;
  }
  const std::atomic<bool>& done() const { return done_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  Status status_;
  std::thread thread_;
};

// A short, fast emulator run: 5 kHz, the test over 0.35 s after START (the bend takes
// 0.0176 m / 0.25 m/s = 0.07 s from 0.01 s).
EmulatorOptions FastOptions() {
  EmulatorOptions options;
  options.rate_hz = 5000;
  options.exit_after_test = false;
  options.model = ShortTest();
  options.model.bend_delay_s = 0.01;
  options.model.bend_speed_m_per_s = 0.25;
  options.model.ramp_delay_s = 0.1;
  options.model.test.ramp_duration_s = 0.2;
  options.model.end_hold_s = 0.05;
  options.model.max_shaft_speed_rad_per_s = 50;
  return options;
}

std::set<uint32_t> SequencesOf(const std::vector<wire::Frame>& frames) {
  std::set<uint32_t> sequences;
  for (const wire::Frame& frame : frames) sequences.insert(SequenceOf(frame));
  return sequences;
}

std::set<uint32_t> AllBelow(int64_t count) {
  std::set<uint32_t> all;
  for (int64_t i = 0; i < count; ++i) all.insert(static_cast<uint32_t>(i));
  return all;
}

TEST(Emulator, RunsTheTestAndSendsEveryFrameInOrder) {
  EmulatorOptions options = FastOptions();
  options.autostart = true;
  options.autostart_delay_s = 0.05;
  options.exit_after_test = true;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  ASSERT_TRUE(reader.is_open()) << (*emulator)->port_path();
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_EQ(reader.rejected_lines, 0);
  ASSERT_EQ(static_cast<int64_t>(reader.frames.size()), stats.frames_generated);
  EXPECT_EQ(stats.frames_written, stats.frames_generated);
  EXPECT_EQ(stats.bytes_written, reader.bytes);
  EXPECT_TRUE((*emulator)->dropped_sequences().empty());
  for (size_t i = 0; i < reader.frames.size(); ++i) {
    ASSERT_EQ(SequenceOf(reader.frames[i]), i);
  }
  EXPECT_EQ(reader.frames[0].type, FrameType::kHeader);
  // samples 200 us apart in device time; the LED on from TEST_START to TEST_END
  std::vector<EventKind> events;
  int64_t samples = 0;
  int64_t led_on_samples = 0;
  uint32_t last_us = 0;
  for (const wire::Frame& frame : reader.frames) {
    if (frame.type == FrameType::kEvent) events.push_back(frame.event.kind);
    if (frame.type != FrameType::kSample) continue;
    if (samples > 0) {
      EXPECT_EQ(frame.sample.device_time_us - last_us, 200u);
    }
    last_us = frame.sample.device_time_us;
    ++samples;
    led_on_samples += frame.sample.led_on;
  }
  EXPECT_EQ(events, (std::vector<EventKind>{EventKind::kTestStart, EventKind::kLedOn,
                                            EventKind::kTestEnd, EventKind::kLedOff}));
  // ramp delay 0.1 + ramp 0.2 + hold 0.05: 0.35 s of LED at 5 kHz
  EXPECT_NEAR(static_cast<double>(led_on_samples), 1750.0, 1.0);
  // and 1 s of samples after TEST_END at 0.05 + 0.35 s
  EXPECT_NEAR(static_cast<double>(samples), 1.4 * 5000, 2.0);
  // the ramp's end: +pi/3 of vertebra = 8000 counts
  EXPECT_EQ(reader.frames.back().type, FrameType::kSample);
  EXPECT_EQ(reader.frames.back().sample.rotate_counts, 8000);
  EXPECT_EQ(reader.frames.back().sample.bend_counts, 2801);
}

TEST(Emulator, DroppedSequencesAreExactlyTheGaps) {
  EmulatorOptions options = FastOptions();
  options.drop_frame_probability = 0.05;
  options.duration_s = 0.4;
  options.seed = 11;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  const std::vector<uint32_t> dropped = (*emulator)->dropped_sequences();
  EXPECT_EQ(static_cast<int64_t>(dropped.size()), stats.frames_dropped);
  EXPECT_GT(stats.frames_dropped, 40);  // 5 % of ~2000
  EXPECT_EQ(reader.rejected_lines, 0);
  // received and dropped: disjoint, and together every sequence number spent
  std::set<uint32_t> accounted = SequencesOf(reader.frames);
  EXPECT_EQ(accounted.size(), reader.frames.size());
  for (uint32_t sequence : dropped) EXPECT_TRUE(accounted.insert(sequence).second) << sequence;
  EXPECT_EQ(accounted, AllBelow(stats.frames_generated));
}

TEST(Emulator, NoCorruptedFrameSurvivesItsChecksum) {
  EmulatorOptions options = FastOptions();
  options.corrupt_byte_probability = 0.002;
  options.duration_s = 0.4;
  options.seed = 5;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  const std::vector<uint32_t> corrupted = (*emulator)->corrupted_sequences();
  EXPECT_EQ(static_cast<int64_t>(corrupted.size()), stats.frames_corrupted);
  EXPECT_GE(stats.bytes_corrupted, stats.frames_corrupted);
  EXPECT_GT(stats.frames_corrupted, 50);  // ~2000 frames of ~45 bytes, 1 in 500 corrupted
  EXPECT_GE(reader.rejected_lines, stats.frames_corrupted / 2);
  // a frame with a corrupted byte is rejected; every other frame is kept
  std::set<uint32_t> expected = AllBelow(stats.frames_generated);
  for (uint32_t sequence : corrupted) expected.erase(sequence);
  EXPECT_EQ(SequencesOf(reader.frames), expected);
  EXPECT_EQ(reader.frames.size(), expected.size());
}

TEST(Emulator, DisconnectHangsUpAndReturnsOnANewPty) {
  testing::ScratchDir scratch;
  EmulatorOptions options = FastOptions();
  options.rate_hz = 2000;
  options.link_path = scratch / "controller";
  options.disconnect_at_s = 0.15;
  options.disconnect_for_s = 0.1;
  options.duration_s = 0.5;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  EXPECT_EQ((*emulator)->port_path(), options.link_path);
  const fs::path first_target = fs::read_symlink(options.link_path);
  EXPECT_EQ(first_target.string().rfind("/dev/pts/", 0), 0u) << first_target;

  SlaveReader before(options.link_path);
  ASSERT_TRUE(before.is_open());
  Running running(**emulator);
  // the first pty hangs up
  const int64_t give_up_ns = MonotonicNowNs() + 3 * kSecond;
  SlaveReader::Outcome outcome = SlaveReader::Outcome::kTimeout;
  while (outcome != SlaveReader::Outcome::kHangUp && MonotonicNowNs() < give_up_ns) {
    outcome = before.ReadSome(5);
  }
  ASSERT_EQ(outcome, SlaveReader::Outcome::kHangUp);
  // the link moves to a new pty (the old slave is still open here, so its number is taken)
  fs::path target;
  while (MonotonicNowNs() < give_up_ns) {
    std::error_code error;
    target = fs::read_symlink(options.link_path, error);
    if (!error && target != first_target) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_NE(target, first_target);
  SlaveReader after(options.link_path);
  ASSERT_TRUE(after.is_open());
  after.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_EQ(stats.disconnects, 1);
  EXPECT_GT(stats.frames_lost_disconnected, 150);  // 0.1 s at 2 kHz
  const std::vector<uint32_t> dropped = (*emulator)->dropped_sequences();
  EXPECT_EQ(static_cast<int64_t>(dropped.size()), stats.frames_lost_disconnected);
  ASSERT_FALSE(before.frames.empty());
  ASSERT_FALSE(after.frames.empty());
  EXPECT_EQ(before.rejected_lines + after.rejected_lines, 0);
  // each side contiguous; the new pty begins with a header right after the lost frames
  for (size_t i = 0; i < before.frames.size(); ++i) ASSERT_EQ(SequenceOf(before.frames[i]), i);
  const uint32_t first_after = SequenceOf(after.frames[0]);
  for (size_t i = 0; i < after.frames.size(); ++i) {
    ASSERT_EQ(SequenceOf(after.frames[i]), first_after + i);
  }
  EXPECT_EQ(after.frames[0].type, FrameType::kHeader);
  EXPECT_EQ(first_after, dropped.back() + 1);
  EXPECT_GT(dropped.front(), SequenceOf(before.frames.back()));
  EXPECT_EQ(static_cast<int64_t>(first_after + after.frames.size()), stats.frames_generated);
  emulator->reset();
  EXPECT_FALSE(fs::exists(fs::symlink_status(options.link_path)));
}

TEST(Emulator, RemovesItsLinkWhenStoppedDuringADisconnect) {
  testing::ScratchDir scratch;
  EmulatorOptions options = FastOptions();
  options.rate_hz = 2000;
  options.link_path = scratch / "controller";
  options.disconnect_at_s = 0.05;
  options.disconnect_for_s = 60;  // still disconnected when stopped
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  {
    Running running(**emulator);
    const int64_t give_up_ns = MonotonicNowNs() + 3 * kSecond;
    while ((*emulator)->stats().disconnects == 0 && MonotonicNowNs() < give_up_ns) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_EQ((*emulator)->stats().disconnects, 1);
    ASSERT_TRUE(running.Join().ok());
  }
  // the link still names the closed pty: ours, so it goes with the emulator
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(options.link_path)));
  emulator->reset();
  EXPECT_FALSE(fs::exists(fs::symlink_status(options.link_path)));
}

TEST(Emulator, StallDelaysFramesWithoutLosingThem) {
  EmulatorOptions options = FastOptions();
  options.rate_hz = 2000;
  options.stall_at_s = 0.1;
  options.stall_for_s = 0.15;
  options.duration_s = 0.4;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_EQ(stats.stalls, 1);
  EXPECT_EQ(SequencesOf(reader.frames), AllBelow(stats.frames_generated));
  int64_t longest_silence_ns = 0;
  for (size_t i = 1; i < reader.chunk_times_ns.size(); ++i) {
    longest_silence_ns =
        std::max(longest_silence_ns, reader.chunk_times_ns[i] - reader.chunk_times_ns[i - 1]);
  }
  EXPECT_GE(longest_silence_ns, 120 * kMs);
}

TEST(Emulator, AnswersTheHostsCommands) {
  EmulatorOptions options = FastOptions();
  options.duration_s = 0.3;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  char line[wire::kMaxFrameBytes];
  const wire::CommandFrame ping = MakeCommand(wire::CommandKind::kPing, 77);
  const wire::CommandFrame start = MakeCommand(wire::CommandKind::kStart, 3, 800, -60000, 200);
  std::string sent(line, wire::EncodeCommand(ping, line, sizeof line));
  sent += "garbage\n";
  sent.append(line, wire::EncodeCommand(start, line, sizeof line));
  reader.Write(sent);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  std::vector<wire::EventFrame> events;
  for (const wire::Frame& frame : reader.frames) {
    if (frame.type == FrameType::kEvent) events.push_back(frame.event);
  }
  ASSERT_GE(events.size(), 5u);
  EXPECT_EQ(events[0].kind, EventKind::kPong);
  EXPECT_EQ(events[0].arg, 77);
  EXPECT_EQ(events[1].kind, EventKind::kFault);
  EXPECT_EQ(events[2].kind, EventKind::kAck);
  EXPECT_EQ(events[3].kind, EventKind::kTestStart);
  EXPECT_EQ(events[4].kind, EventKind::kLedOn);
  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_EQ(stats.commands_received, 2);
  EXPECT_EQ(stats.bad_lines_received, 1);
  // HL: the spool winds negative
  auto last_sample =
      std::find_if(reader.frames.rbegin(), reader.frames.rend(),
                   [](const wire::Frame& f) { return f.type == FrameType::kSample; });
  ASSERT_NE(last_sample, reader.frames.rend());
  EXPECT_LT(last_sample->sample.bend_setpoint_counts, 0);
}

TEST(Emulator, UnpacedRunsFasterThanRealTimeWithoutLoss) {
  EmulatorOptions options = FastOptions();
  options.rate_hz = 1000;
  options.unpaced = true;
  options.duration_s = 0.3;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_EQ(stats.frames_written, stats.frames_generated);
  EXPECT_EQ(SequencesOf(reader.frames), AllBelow(stats.frames_generated));
  // more device time than host time went by (1000 frames are 1 s of device time)
  EXPECT_GT(stats.frames_generated, 3 * 300);
}

TEST(Emulator, WithNobodyReadingWholeFramesWaitAndTheRestOverflow) {
  EmulatorOptions options = FastOptions();
  options.rate_hz = 100000;  // 1 MiB of frames in about 0.25 s
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  {
    Running running(**emulator);
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    ASSERT_TRUE(running.Join().ok());
  }
  const EmulatorStats stats = (*emulator)->stats();
  EXPECT_GT(stats.frames_overflowed, 0);
  EXPECT_GT(stats.frames_written, 0);
  EXPECT_EQ(static_cast<int64_t>((*emulator)->dropped_sequences().size()), stats.frames_overflowed);
  // a late reader finds what the pty buffered: whole frames from the first on
  SlaveReader reader((*emulator)->port_path());
  while (reader.ReadSome(50) == SlaveReader::Outcome::kData) {
  }
  EXPECT_EQ(reader.rejected_lines, 0);
  ASSERT_EQ(static_cast<int64_t>(reader.frames.size()), stats.frames_written);
  for (size_t i = 0; i < reader.frames.size(); ++i) ASSERT_EQ(SequenceOf(reader.frames[i]), i);
}

TEST(Emulator, ClockDriftScalesTheDeviceClock) {
  EmulatorOptions options = FastOptions();
  options.rate_hz = 2000;
  options.clock_drift_ppm = 100000;  // the device clock runs 10 % fast
  options.duration_s = 0.5;
  auto emulator = Emulator::Create(options);
  ASSERT_TRUE(emulator.ok()) << emulator.status().ToString();
  SlaveReader reader((*emulator)->port_path());
  Running running(**emulator);
  reader.ReadUntil(running.done());
  ASSERT_TRUE(running.Join().ok());

  int64_t samples = 0;
  for (const wire::Frame& frame : reader.frames) samples += frame.type == FrameType::kSample;
  // 0.5 host s = 0.55 device s = 1100 samples at 2 kHz (1000 without drift)
  EXPECT_GE(samples, 1060);
  EXPECT_LE(samples, 1102);
}

}  // namespace
}  // namespace liftoff::capture
