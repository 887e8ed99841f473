// Reference firmware for Laika's test controller: reads the quadrature encoders of the
// bending and rotating motors, holds both motors on their setpoints, runs the
// foot-lifting test sequence with the sync LED, and speaks liftoff's serial protocol v1
// (docs/protocol.md) through wire_format.h, the very encoder and decoder the host tests.
//
// Board: Arduino Mega 2560 (pins below) or Teensy 3.x/4.x (native USB; choose any
// interrupt-capable pins). Motor drivers: one PWM + direction H-bridge per motor (e.g.
// Pololu VNH5019, Cytron MD10C). See samples/firmware/README.md for wiring and settings.
#include "wire_format.h"

namespace wire = liftoff::wire;

// ---------------------------------------------------------------------------------------
// Settings

// Serial link. A 16 MHz AVR divides 1,000,000 baud exactly (921,600 is 3.5 % off); USB
// boards (Teensy) ignore the number. At 115200 baud set kSampleRateHz to 200 at most.
#ifndef LIFTOFF_BAUD
#define LIFTOFF_BAUD 1000000
#endif
// Sample frames per second (default 1 kHz). Samples that do not fit the transmit buffer
// are dropped (their sequence number is spent, so the host sees the gap).
#ifndef LIFTOFF_SAMPLE_RATE_HZ
#define LIFTOFF_SAMPLE_RATE_HZ 1000
#endif
const uint32_t kSampleRateHz = LIFTOFF_SAMPLE_RATE_HZ;
const uint32_t kSamplePeriodUs = 1000000UL / kSampleRateHz;
const uint32_t kControlPeriodUs = 1000;  // position control at 1 kHz

// Pins (Arduino Mega 2560: 2, 3, 18, 19 are external-interrupt pins).
const uint8_t kBendEncoderA = 2;
const uint8_t kBendEncoderB = 3;
const uint8_t kRotateEncoderA = 18;
const uint8_t kRotateEncoderB = 19;
const uint8_t kBendPwm = 9;  // H-bridge PWM input
const uint8_t kBendDir = 8;  // H-bridge direction input (HIGH: positive counts)
const uint8_t kRotatePwm = 10;
const uint8_t kRotateDir = 7;
const uint8_t kLedPin = 13;  // the sync LED the cameras see (onboard LED on pin 13)

// Drive chain (calib/laika-2018.json): counts per rotor revolution in 4x quadrature,
// gearbox, spur gear. Announced in every header frame.
const uint32_t kCountsPerMotorRev = 12;
const uint32_t kGearboxRatio = 1000;
const uint32_t kSpurGearRatio = 4;
const float kCountsPerShaftRad = kCountsPerMotorRev * kGearboxRatio / 6.2831853f;

// Bending spool: the bend target is the largest groove's cable at the commanded fraction
// of its length; it shortens at the paper's 0.025 m/s.
const float kLargestGrooveRadiusM = 0.012f;
const float kCableLengthM = 0.088f;
const float kBendSpeedMPerS = 0.025f;

// Test sequence, device time from START (the same as `liftoff emulate`).
const uint32_t kBendDelayUs = 500000UL;
const uint32_t kRampDelayUs = 4000000UL;
const uint32_t kEndHoldUs = 500000UL;

// Default test (START with four zero arguments): HR, 80 %, +60 deg over 40 s.
const int32_t kDefaultStart[4] = {2, 800, 60000, 40000};

// Position control: PWM = kP * error, at least kMinPwm outside the dead band.
const float kP = 0.5f;  // PWM steps per count of error
const int32_t kDeadBandCounts = 2;
const int kMinPwm = 30;
// Stall: error above this (0.5 rad of output shaft) for kStallUs during a test is a
// fault, and the test stops.
const int32_t kStallErrorCounts = 1000;
const uint32_t kStallUs = 1000000UL;

const char kFirmwareName[] = "laika-fw 1.0";

// ---------------------------------------------------------------------------------------
// Encoders: both channels of each encoder on CHANGE interrupts, counted in 4x mode.

// quadrature step from (previous AB << 2 | current AB): +1, -1, or 0 (none or invalid)
const int8_t kQuadratureStep[16] = {0, 1, -1, 0, -1, 0, 0, 1, 1, 0, 0, -1, 0, -1, 1, 0};

volatile int32_t g_bend_counts = 0;
volatile int32_t g_rotate_counts = 0;
volatile uint8_t g_bend_ab = 0;
volatile uint8_t g_rotate_ab = 0;

void BendEncoderIsr() {
  const uint8_t ab = (digitalRead(kBendEncoderA) << 1) | digitalRead(kBendEncoderB);
  g_bend_counts += kQuadratureStep[(g_bend_ab << 2) | ab];
  g_bend_ab = ab;
}

void RotateEncoderIsr() {
  const uint8_t ab = (digitalRead(kRotateEncoderA) << 1) | digitalRead(kRotateEncoderB);
  g_rotate_counts += kQuadratureStep[(g_rotate_ab << 2) | ab];
  g_rotate_ab = ab;
}

// Both counts at one instant (a 32-bit read is not atomic on an 8-bit AVR).
void ReadCounts(int32_t& bend, int32_t& rotate) {
  noInterrupts();
  bend = g_bend_counts;
  rotate = g_rotate_counts;
  interrupts();
}

// ---------------------------------------------------------------------------------------
// Frames out. Every frame takes the next sequence number, sent or not.

uint32_t g_sequence = 0;
bool g_led_on = false;
uint32_t g_last_header_us = 0;

// Samples are dropped when the transmit buffer has no room (the control loop never
// waits); events and headers wait for room (they are rare and must arrive).
void Send(const char* text, size_t size, bool may_drop) {
  if (size == 0) return;
  if (may_drop && Serial.availableForWrite() < static_cast<int>(size)) return;
  Serial.write(reinterpret_cast<const uint8_t*>(text), size);
}

void SendHeader() {
  wire::HeaderFrame h;
  h.sequence = g_sequence++;
  h.device_time_us = micros();
  h.protocol_version = wire::kProtocolVersion;
  for (size_t i = 0; i < sizeof(kFirmwareName); ++i) h.firmware[i] = kFirmwareName[i];
  h.counts_per_motor_rev = kCountsPerMotorRev;
  h.gearbox_ratio = kGearboxRatio;
  h.spur_gear_ratio = kSpurGearRatio;
  char text[wire::kMaxFrameBytes];
  Send(text, wire::EncodeHeader(h, text, sizeof(text)), false);
  g_last_header_us = h.device_time_us;
}

void SendEvent(wire::EventKind kind, int32_t arg, const char* why) {
  wire::EventFrame e;
  e.sequence = g_sequence++;
  e.device_time_us = micros();
  e.kind = kind;
  e.arg = arg;
  for (size_t i = 0; why[i] != '\0' && i < wire::kMaxTextBytes; ++i) e.text[i] = why[i];
  char text[wire::kMaxFrameBytes];
  Send(text, wire::EncodeEvent(e, text, sizeof(text)), false);
}

// ---------------------------------------------------------------------------------------
// Motors and the test sequence

struct Test {
  bool running = false;
  uint32_t start_us = 0;
  float bend_from = 0, bend_to = 0;      // counts
  float rotate_from = 0, rotate_to = 0;  // counts
  uint32_t bend_us = 0;                  // duration of the bend
  uint32_t ramp_us = 0;                  // duration of the ramp
};

Test g_test;
float g_bend_setpoint = 0;  // counts
float g_rotate_setpoint = 0;
uint32_t g_bend_stall_since_us = 0;
uint32_t g_rotate_stall_since_us = 0;

void Drive(uint8_t pwm_pin, uint8_t dir_pin, float setpoint, int32_t counts) {
  const float error = setpoint - static_cast<float>(counts);
  int pwm = 0;
  if (error > kDeadBandCounts || error < -kDeadBandCounts) {
    const float magnitude = (error < 0 ? -error : error) * kP;
    pwm = magnitude > 255 ? 255 : (magnitude < kMinPwm ? kMinPwm : static_cast<int>(magnitude));
  }
  digitalWrite(dir_pin, error >= 0 ? HIGH : LOW);
  analogWrite(pwm_pin, pwm);
}

void SetLed(bool on) {
  g_led_on = on;
  digitalWrite(kLedPin, on ? HIGH : LOW);
}

// Ends the running test: 0 done, 1 stopped. Motors hold where the setpoints are.
void EndTest(int32_t reason) {
  g_test.running = false;
  SendEvent(wire::EventKind::kTestEnd, reason, "");
  SetLed(false);
  SendEvent(wire::EventKind::kLedOff, 0, "");
}

void StartTest(const int32_t* args) {
  const bool pull_left = args[0] == 3;  // HL winds the spool negative
  const float bend_rad = (1000 - args[1]) / 1000.0f * kCableLengthM / kLargestGrooveRadiusM;
  const float bend_speed_rad_per_s = kBendSpeedMPerS / kLargestGrooveRadiusM;
  const float vertebra_rad = args[2] / 1000.0f * 3.14159265f / 180.0f;
  g_test.running = true;
  g_test.start_us = micros();
  g_test.bend_from = g_bend_setpoint;
  g_test.bend_to = (pull_left ? -bend_rad : bend_rad) * kCountsPerShaftRad;
  g_test.bend_us = static_cast<uint32_t>(bend_rad / bend_speed_rad_per_s * 1e6f);
  g_test.rotate_from = g_rotate_setpoint;
  g_test.rotate_to = vertebra_rad * kSpurGearRatio * kCountsPerShaftRad;
  g_test.ramp_us = static_cast<uint32_t>(args[3]) * 1000UL;
  g_bend_stall_since_us = g_rotate_stall_since_us = 0;
  SendEvent(wire::EventKind::kTestStart, 0, "");
  SetLed(true);
  SendEvent(wire::EventKind::kLedOn, 0, "");
}

// The test's setpoints at `now_us`; ends the test after the ramp and the hold.
void FollowTest(uint32_t now_us) {
  if (!g_test.running) return;
  const uint32_t t = now_us - g_test.start_us;  // wraps correctly for tests < 71 minutes
  if (t >= kBendDelayUs) {
    const uint32_t into = t - kBendDelayUs;
    const float f = into >= g_test.bend_us ? 1.0f : static_cast<float>(into) / g_test.bend_us;
    g_bend_setpoint = g_test.bend_from + (g_test.bend_to - g_test.bend_from) * f;
  }
  if (t >= kRampDelayUs) {
    const uint32_t into = t - kRampDelayUs;
    const float f = into >= g_test.ramp_us ? 1.0f : static_cast<float>(into) / g_test.ramp_us;
    g_rotate_setpoint = g_test.rotate_from + (g_test.rotate_to - g_test.rotate_from) * f;
    if (into >= g_test.ramp_us + kEndHoldUs) EndTest(0);
  }
}

// True once a motor has been far from its setpoint for kStallUs.
bool Stalled(float setpoint, int32_t counts, uint32_t now_us, uint32_t& since_us) {
  const float error = setpoint - static_cast<float>(counts);
  if (error < kStallErrorCounts && error > -kStallErrorCounts) {
    since_us = 0;
    return false;
  }
  if (since_us == 0) since_us = now_us | 1;  // odd, so never 0, which means "not stalling"
  return now_us - since_us >= kStallUs;
}

void Control(uint32_t now_us) {
  FollowTest(now_us);
  int32_t bend = 0, rotate = 0;
  ReadCounts(bend, rotate);
  Drive(kBendPwm, kBendDir, g_bend_setpoint, bend);
  Drive(kRotatePwm, kRotateDir, g_rotate_setpoint, rotate);
  if (!g_test.running) return;
  const bool bend_stall = Stalled(g_bend_setpoint, bend, now_us, g_bend_stall_since_us);
  const bool rotate_stall = Stalled(g_rotate_setpoint, rotate, now_us, g_rotate_stall_since_us);
  if (bend_stall || rotate_stall) {
    SendEvent(wire::EventKind::kFault, bend_stall ? 2 : 3,
              bend_stall ? "bend stall" : "rotate stall");
    g_bend_setpoint = static_cast<float>(bend);
    g_rotate_setpoint = static_cast<float>(rotate);
    EndTest(1);
  }
}

void SendSample(uint32_t now_us) {
  wire::SampleFrame s;
  s.sequence = g_sequence++;
  s.device_time_us = now_us;
  s.led_on = g_led_on ? 1 : 0;
  ReadCounts(s.bend_counts, s.rotate_counts);
  s.bend_setpoint_counts =
      static_cast<int32_t>(g_bend_setpoint + (g_bend_setpoint < 0 ? -0.5f : 0.5f));
  s.rotate_setpoint_counts =
      static_cast<int32_t>(g_rotate_setpoint + (g_rotate_setpoint < 0 ? -0.5f : 0.5f));
  char text[wire::kMaxFrameBytes];
  Send(text, wire::EncodeSample(s, text, sizeof(text)), true);
}

// ---------------------------------------------------------------------------------------
// Commands in

// NAK reason for bad START arguments, or nullptr when they are fine.
const char* CheckStart(const int32_t* a) {
  if (a[0] != 2 && a[0] != 3) return "bad group";
  if (a[1] < 500 || a[1] > 1000) return "bad bend";
  if (a[2] < -180000L || a[2] > 180000L) return "bad amplitude";
  if (a[3] < 1 || a[3] > 3600000L) return "bad duration";
  return nullptr;
}

void HandleCommand(const wire::CommandFrame& c) {
  const int32_t code = static_cast<int32_t>(c.command);
  switch (c.command) {
    case wire::CommandKind::kStart: {
      const bool defaults = c.args[0] == 0 && c.args[1] == 0 && c.args[2] == 0 && c.args[3] == 0;
      const int32_t* args = defaults ? kDefaultStart : c.args;
      const char* why = g_test.running ? "busy" : CheckStart(args);
      if (why != nullptr) {
        SendEvent(wire::EventKind::kNak, code, why);
        break;
      }
      SendEvent(wire::EventKind::kAck, code, "");
      StartTest(args);
      break;
    }
    case wire::CommandKind::kStop: {
      SendEvent(wire::EventKind::kAck, code, "");
      if (g_test.running) {
        int32_t bend = 0, rotate = 0;
        ReadCounts(bend, rotate);
        g_bend_setpoint = static_cast<float>(bend);
        g_rotate_setpoint = static_cast<float>(rotate);
        EndTest(1);
      }
      break;
    }
    case wire::CommandKind::kZero:
      if (g_test.running) {
        SendEvent(wire::EventKind::kNak, code, "busy");
        break;
      }
      noInterrupts();
      g_bend_counts = 0;
      g_rotate_counts = 0;
      interrupts();
      g_bend_setpoint = g_rotate_setpoint = 0;
      SendEvent(wire::EventKind::kAck, code, "");
      break;
    case wire::CommandKind::kPing: SendEvent(wire::EventKind::kPong, c.args[0], ""); break;
    default: SendEvent(wire::EventKind::kNak, code, "unknown command"); break;
  }
  SendHeader();
}

// Host bytes: a line starts at '$' and ends at '\n' (as on the host side); a line that
// started with '$' but is not a command frame is answered with FAULT 1 "bad frame".
char g_line[wire::kMaxFrameBytes];
size_t g_line_size = 0;
bool g_in_line = false;

void PollHost() {
  while (Serial.available() > 0) {
    const char c = static_cast<char>(Serial.read());
    if (c == '$') {
      g_in_line = true;
      g_line_size = 0;
    }
    if (!g_in_line) continue;
    if (c != '\n') {
      if (g_line_size < sizeof(g_line)) g_line[g_line_size] = c;
      ++g_line_size;  // a line too long fails to decode below
      continue;
    }
    g_in_line = false;
    wire::Frame frame;
    const bool fits = g_line_size <= sizeof(g_line);
    if (fits && wire::DecodeLine(g_line, g_line_size, &frame) == wire::DecodeError::kOk &&
        frame.type == wire::FrameType::kCommand) {
      HandleCommand(frame.command);
    } else {
      SendEvent(wire::EventKind::kFault, 1, "bad frame");
    }
  }
}

// ---------------------------------------------------------------------------------------

uint32_t g_next_control_us = 0;
uint32_t g_next_sample_us = 0;

void setup() {
  pinMode(kBendEncoderA, INPUT_PULLUP);
  pinMode(kBendEncoderB, INPUT_PULLUP);
  pinMode(kRotateEncoderA, INPUT_PULLUP);
  pinMode(kRotateEncoderB, INPUT_PULLUP);
  pinMode(kBendPwm, OUTPUT);
  pinMode(kBendDir, OUTPUT);
  pinMode(kRotatePwm, OUTPUT);
  pinMode(kRotateDir, OUTPUT);
  pinMode(kLedPin, OUTPUT);
  SetLed(false);
  g_bend_ab = (digitalRead(kBendEncoderA) << 1) | digitalRead(kBendEncoderB);
  g_rotate_ab = (digitalRead(kRotateEncoderA) << 1) | digitalRead(kRotateEncoderB);
  attachInterrupt(digitalPinToInterrupt(kBendEncoderA), BendEncoderIsr, CHANGE);
  attachInterrupt(digitalPinToInterrupt(kBendEncoderB), BendEncoderIsr, CHANGE);
  attachInterrupt(digitalPinToInterrupt(kRotateEncoderA), RotateEncoderIsr, CHANGE);
  attachInterrupt(digitalPinToInterrupt(kRotateEncoderB), RotateEncoderIsr, CHANGE);
  Serial.begin(LIFTOFF_BAUD);
  SendHeader();  // boot
  g_next_control_us = g_next_sample_us = micros();
}

void loop() {
  PollHost();
  const uint32_t now = micros();
  // fixed-rate control and sampling; after a hold-up, skip rather than burst
  if (static_cast<int32_t>(now - g_next_control_us) >= 0) {
    Control(now);
    g_next_control_us += kControlPeriodUs;
    if (static_cast<int32_t>(now - g_next_control_us) >= 0)
      g_next_control_us = now + kControlPeriodUs;
  }
  if (static_cast<int32_t>(now - g_next_sample_us) >= 0) {
    SendSample(now);
    g_next_sample_us += kSamplePeriodUs;
    if (static_cast<int32_t>(now - g_next_sample_us) >= 0) g_next_sample_us = now + kSamplePeriodUs;
  }
  // while no test runs, a header every second for hosts that connect late
  if (!g_test.running && now - g_last_header_us >= 1000000UL) SendHeader();
}
