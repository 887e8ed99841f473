// Live capture end to end over pseudo-terminals: the emulator (in-process threads, or the
// real `liftoff emulate` and `liftoff capture` binaries for the signal test) plays the
// controller; every log is checked against the emulator's ground truth, its controller
// model run through the very calls the emulator makes.
#include "liftoff/capture/capture_session.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/capture/emulator.h"
#include "liftoff/capture/journal.h"
#include "liftoff/capture/protocol.h"
#include "liftoff/capture/serial_port.h"
#include "liftoff/cli/commands.h"
#include "liftoff/core/time.h"
#include "support/test_support.h"

extern char** environ;

namespace liftoff::capture {
namespace {

using liftoff::testing::DriveChainCalibration;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;

// ---------------------------------------------------------------------------------------
// fixtures

// A whole test in about a second of device time: autostart at 50 ms, a quick bend, the
// ramp from 0.3 s to 0.8 s, TEST_END at 0.9 s.
EmulatorOptions QuickTest(double rate_hz) {
  EmulatorOptions options;
  options.rate_hz = rate_hz;
  options.autostart = true;
  options.autostart_delay_s = 0.05;
  options.model.bend_delay_s = 0.05;
  options.model.bend_speed_m_per_s = 0.1;
  options.model.ramp_delay_s = 0.25;
  options.model.end_hold_s = 0.1;
  options.model.max_shaft_speed_rad_per_s = 30.0;
  options.model.test.ramp_duration_s = 0.5;
  return options;
}

uint32_t SequenceOf(const wire::Frame& frame) {
  switch (frame.type) {
    case wire::FrameType::kSample: return frame.sample.sequence;
    case wire::FrameType::kHeader: return frame.header.sequence;
    case wire::FrameType::kEvent: return frame.event.sequence;
    case wire::FrameType::kCommand: break;
  }
  ADD_FAILURE() << "a command frame has no sequence number";
  return 0;
}

// The frames the emulator's controller made, by sequence number, up to `last`: its model
// driven as the emulator drives it (autostart, then one sample every 1/rate_hz of device
// time), which does not depend on the host's timing as long as no command is sent.
std::map<uint32_t, wire::Frame> TruthFrames(const EmulatorOptions& options, uint32_t last) {
  ControllerModel model(options.model);
  bool autostart_pending = options.autostart;
  const double period_ns = 1e9 / options.rate_hz;
  std::vector<wire::Frame> frames;
  for (int64_t k = 0; model.next_sequence() <= last; ++k) {
    const int64_t device_ns = std::llround(static_cast<double>(k) * period_ns);
    if (autostart_pending && device_ns >= NsFromSeconds(options.autostart_delay_s)) {
      autostart_pending = false;
      model.StartTest(options.model.test, NsFromSeconds(options.autostart_delay_s));
    }
    model.Advance(device_ns);
    model.EmitSample();
    model.TakeFrames(frames);
  }
  std::map<uint32_t, wire::Frame> by_sequence;
  for (const wire::Frame& frame : frames) {
    if (SequenceOf(frame) <= last) by_sequence[SequenceOf(frame)] = frame;
  }
  return by_sequence;
}

// The 2018 drive chain by hand: 12 counts per rotor turn, 1000:1, 4:1.
double VertebraRadFromCounts(int64_t counts) {
  return static_cast<double>(counts) * 2.0 * std::numbers::pi / 12000.0 / 4.0;
}

// Expects `sample` to be exactly the frame the controller sent.
void ExpectSampleIsFrame(const LogSample& sample, const wire::SampleFrame& frame) {
  EXPECT_EQ(sample.device_time_ns, int64_t{frame.device_time_us} * 1000) << *sample.sequence;
  EXPECT_EQ(sample.led_on, frame.led_on == 1) << *sample.sequence;
  EXPECT_EQ(sample.bend_counts, frame.bend_counts) << *sample.sequence;
  EXPECT_EQ(sample.rotate_counts, frame.rotate_counts) << *sample.sequence;
  EXPECT_NEAR(sample.vertebra_rad, VertebraRadFromCounts(frame.rotate_counts), 1e-12);
}

bool WaitFor(const std::function<bool()>& condition, double timeout_s) {
  const int64_t deadline_ns = MonotonicNowNs() + NsFromSeconds(timeout_s);
  while (!condition()) {
    if (MonotonicNowNs() > deadline_ns) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

// An emulator running on its own thread; stopped and joined on destruction.
class EmulatorThread {
 public:
  explicit EmulatorThread(const EmulatorOptions& options) {
    auto created = Emulator::Create(options);
    EXPECT_TRUE(created.ok()) << created.status().ToString();
    if (!created.ok()) return;
    emulator_ = std::move(created).value();
    thread_ = std::thread([this] {
      result_ = emulator_->Run(stop_);
      done_ = true;
    });
  }
  ~EmulatorThread() { (void)Stop(); }
  EmulatorThread(const EmulatorThread&) = delete;
  EmulatorThread& operator=(const EmulatorThread&) = delete;

  bool ok() const { return emulator_ != nullptr; }
  const Emulator& emulator() const { return *emulator_; }
  std::string port() const { return emulator_->port_path().string(); }
  bool done() const { return done_; }
  Status Stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    return result_;
  }

 private:
  std::unique_ptr<Emulator> emulator_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  Status result_;
  std::thread thread_;
};

// RunCapture on its own thread, with the last status kept; stopped and joined on
// destruction.
class CaptureThread {
 public:
  CaptureThread(CaptureOptions options, Calibration calibration)
      : options_(std::move(options)), calibration_(std::move(calibration)) {
    thread_ = std::thread([this] {
      result_ = RunCapture(options_, calibration_, stop_, [this](const CaptureStatus& status) {
        bytes_ = status.bytes;
        frames_ = status.frames;
      });
      done_ = true;
    });
  }
  ~CaptureThread() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  CaptureThread(const CaptureThread&) = delete;
  CaptureThread& operator=(const CaptureThread&) = delete;

  int64_t bytes() const { return bytes_; }
  int64_t frames() const { return frames_; }
  bool done() const { return done_; }
  Result<CaptureSummary> Finish(bool stop) {
    if (stop) stop_ = true;
    thread_.join();
    return result_;
  }

 private:
  CaptureOptions options_;
  Calibration calibration_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> done_{false};
  std::atomic<int64_t> bytes_{0};
  std::atomic<int64_t> frames_{0};
  Result<CaptureSummary> result_ = InvalidArgumentError("not finished");
  std::thread thread_;
};

CaptureOptions QuickCapture(const std::string& port, const std::filesystem::path& log_path) {
  CaptureOptions options;
  options.port = port;
  options.log_path = log_path;
  options.read_timeout_ms = 10;
  options.status_interval_s = 0.01;
  options.reconnect_poll_s = 0.02;
  options.max_duration_s = 20;  // a safety net: every test ends long before
  return options;
}

// Samples of a log by sequence number.
std::map<uint32_t, const LogSample*> BySequence(const ControllerLog& log) {
  std::map<uint32_t, const LogSample*> samples;
  for (const LogSample& sample : log.samples) samples[*sample.sequence] = &sample;
  return samples;
}

ControllerLog ReadLog(const std::filesystem::path& path) {
  auto log = ReadControllerLog(path);
  EXPECT_TRUE(log.ok()) << log.status().ToString();
  if (!log.ok()) return {};
  EXPECT_EQ(log->report.bad_lines, 0) << log->report.Brief();
  return std::move(log).value();
}

std::vector<const LogEvent*> EventsOf(const ControllerLog& log, LogEventKind kind) {
  std::vector<const LogEvent*> events;
  for (const LogEvent& event : log.events) {
    if (event.kind == kind) events.push_back(&event);
  }
  return events;
}

// A full quick test captured until TEST_END; the log read back from disk.
struct FullCapture {
  EmulatorOptions emulator_options;
  CaptureSummary summary;
  ControllerLog log;
  EmulatorStats emulator_stats;
  std::vector<CaptureStatus> statuses;
};

FullCapture CaptureQuickTest(const ScratchDir& dir, const Calibration& calibration) {
  FullCapture run;
  run.emulator_options = QuickTest(2000);
  EmulatorThread emulator(run.emulator_options);
  if (!emulator.ok()) return run;
  std::atomic<bool> stop{false};
  auto summary = RunCapture(QuickCapture(emulator.port(), dir / "trial.csv"), calibration, stop,
                            [&](const CaptureStatus& status) { run.statuses.push_back(status); });
  EXPECT_TRUE(emulator.Stop().ok());
  EXPECT_TRUE(summary.ok()) << summary.status().ToString();
  if (!summary.ok()) return run;
  run.summary = *summary;
  run.emulator_stats = emulator.emulator().stats();
  run.log = ReadLog(dir / "trial.csv");
  return run;
}

// ---------------------------------------------------------------------------------------
// end to end

TEST(CaptureSession, CapturesAFullTestWithEveryFrameAccountedFor) {
  ScratchDir dir;
  const FullCapture run = CaptureQuickTest(dir, DriveChainCalibration());
  ASSERT_GT(run.summary.frames, 1500);
  EXPECT_EQ(run.summary.stopped_by, "test end");
  EXPECT_EQ(run.emulator_stats.frames_dropped + run.emulator_stats.frames_overflowed, 0);

  // the capture saw frames 0 .. N-1, each in the log as a sample or an event (headers
  // go to the log's header)
  const uint32_t last = static_cast<uint32_t>(run.summary.frames - 1);
  const std::map<uint32_t, wire::Frame> truth = TruthFrames(run.emulator_options, last);
  std::vector<const wire::Frame*> truth_events;
  int64_t truth_samples = 0;
  int64_t truth_headers = 0;
  const auto samples = BySequence(run.log);
  for (const auto& [sequence, frame] : truth) {
    if (frame.type == wire::FrameType::kSample) {
      ++truth_samples;
      const auto found = samples.find(sequence);
      ASSERT_NE(found, samples.end()) << "sample " << sequence << " is missing";
      ExpectSampleIsFrame(*found->second, frame.sample);
    } else if (frame.type == wire::FrameType::kEvent) {
      truth_events.push_back(&frame);
    } else {
      ++truth_headers;
    }
  }
  EXPECT_EQ(static_cast<int64_t>(run.log.samples.size()), truth_samples);
  ASSERT_EQ(run.log.events.size(), truth_events.size());
  for (size_t i = 0; i < truth_events.size(); ++i) {
    EXPECT_EQ(run.log.events[i].device_time_ns,
              int64_t{truth_events[i]->event.device_time_us} * 1000);
    EXPECT_EQ(run.log.events[i].kind,
              EventFromFrame(truth_events[i]->event, 0, 0).value_or(LogEvent{}).kind);
  }
  EXPECT_EQ(truth_samples + static_cast<int64_t>(truth_events.size()) + truth_headers,
            run.summary.frames);
  EXPECT_EQ(run.summary.samples + run.summary.events + truth_headers, run.summary.frames);
  EXPECT_EQ(run.summary.gaps, 0);
  EXPECT_EQ(run.summary.checksum_errors, 0);
  EXPECT_EQ(run.summary.garbage_bytes, 0);
  EXPECT_FALSE(EventsOf(run.log, LogEventKind::kTestEnd).empty());

  // the header names the device, the calibration and the port
  EXPECT_EQ(run.log.header.device, "liftoff-emulator 1.0");
  EXPECT_EQ(run.log.header.calibration, "test");
  EXPECT_EQ(run.log.header.metadata.at("device_gearbox_ratio"), "1000");
  EXPECT_THAT(run.log.header.source, HasSubstr("capture /dev/pts/"));
  // the status went out while it ran
  ASSERT_FALSE(run.statuses.empty());
  EXPECT_TRUE(run.statuses.back().connected);
  EXPECT_GT(run.statuses.back().frames, 0);
}

TEST(CaptureSession, AcceptsNoCorruptedFrameAndKeepsEveryIntactOne) {
  ScratchDir dir;
  EmulatorOptions options = QuickTest(2000);
  options.corrupt_byte_probability = 0.001;
  options.seed = 7;
  options.duration_s = 0.8;

  // the capture reads until it has every byte the emulator wrote
  CaptureOptions capture = QuickCapture("", dir / "trial.csv");
  capture.stop_on_test_end = false;
  std::unique_ptr<CaptureThread> reader;
  EmulatorStats stats;
  std::vector<uint32_t> corrupted;
  {
    EmulatorThread emulator(options);
    ASSERT_TRUE(emulator.ok());
    capture.port = emulator.port();
    reader = std::make_unique<CaptureThread>(capture, DriveChainCalibration());
    ASSERT_TRUE(WaitFor([&] { return emulator.done(); }, 10));
    ASSERT_TRUE(emulator.Stop().ok());
    stats = emulator.emulator().stats();
    corrupted = emulator.emulator().corrupted_sequences();
    ASSERT_TRUE(WaitFor([&] { return reader->bytes() == stats.bytes_written; }, 10))
        << reader->bytes() << " of " << stats.bytes_written << " bytes read";
  }
  auto summary = reader->Finish(/*stop=*/true);
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  ASSERT_GT(corrupted.size(), 20u) << "1 byte in 1000 of ~70 KB corrupts dozens of frames";
  EXPECT_EQ(stats.frames_written, stats.frames_generated);

  // every sample in the log is the one the controller sent under its number, and every
  // frame that was not corrupted is there
  const ControllerLog log = ReadLog(dir / "trial.csv");
  const uint32_t last = static_cast<uint32_t>(stats.frames_written - 1);
  const std::map<uint32_t, wire::Frame> truth = TruthFrames(options, last);
  const std::set<uint32_t> corrupted_set(corrupted.begin(), corrupted.end());
  const auto samples = BySequence(log);
  for (const auto& [sequence, frame] : truth) {
    if (frame.type != wire::FrameType::kSample) continue;
    const bool kept = samples.count(sequence) > 0;
    EXPECT_EQ(kept, corrupted_set.count(sequence) == 0) << "sample " << sequence;
    if (kept) ExpectSampleIsFrame(*samples.at(sequence), frame.sample);
  }
  int64_t missing_marked = 0;
  for (const LogEvent* gap : EventsOf(log, LogEventKind::kGap)) {
    missing_marked += std::stoll(gap->detail);
  }
  // every corrupted frame is marked missing, except one at the very end (no frame after it)
  const int64_t trailing = corrupted_set.count(last) ? 1 : 0;
  EXPECT_EQ(missing_marked, static_cast<int64_t>(corrupted.size()) - trailing);
  EXPECT_EQ(summary->missing_frames, missing_marked);
  EXPECT_GT(summary->checksum_errors, 0);
  EXPECT_EQ(summary->samples, static_cast<int64_t>(log.samples.size()));
}

TEST(CaptureSession, ReconnectsAfterADisconnectAndMarksTheGap) {
  ScratchDir dir;
  EmulatorOptions options = QuickTest(2000);
  options.model.test.ramp_duration_s = 1.0;
  options.link_path = dir / "controller";
  options.disconnect_at_s = 0.4;
  options.disconnect_for_s = 0.3;
  EmulatorThread emulator(options);
  ASSERT_TRUE(emulator.ok());
  std::atomic<bool> stop{false};
  auto summary =
      RunCapture(QuickCapture(emulator.port(), dir / "trial.csv"), DriveChainCalibration(), stop);
  ASSERT_TRUE(emulator.Stop().ok());
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  std::string why = summary->Brief();
  for (const std::string& warning : summary->warnings) why += "; " + warning;
  EXPECT_EQ(summary->reconnects, 1) << why;
  EXPECT_EQ(summary->stopped_by, "test end");
  EXPECT_EQ(emulator.emulator().stats().disconnects, 1);

  // a reconnect, then the gap it left, samples on both sides
  const ControllerLog log = ReadLog(dir / "trial.csv");
  const auto reconnects = EventsOf(log, LogEventKind::kReconnect);
  const auto gaps = EventsOf(log, LogEventKind::kGap);
  ASSERT_EQ(reconnects.size(), 1u);
  ASSERT_EQ(gaps.size(), 1u);
  EXPECT_THAT(reconnects[0]->detail, HasSubstr("port reopened after"));
  EXPECT_LE(reconnects[0]->device_time_ns, gaps[0]->device_time_ns);
  EXPECT_LT(log.FirstSampleNs(), gaps[0]->device_time_ns);
  EXPECT_GT(log.LastSampleNs(), gaps[0]->device_time_ns);

  // every sample in the log is the one the controller sent at its device time (the
  // header the emulator sends after reconnecting shifts the sequence numbers, not the
  // times), and every sample the log lacks lies inside the gap
  const auto samples = BySequence(log);
  const uint32_t last_seen = samples.rbegin()->first;
  std::map<int64_t, const LogSample*> by_time;
  for (const LogSample& sample : log.samples) by_time[sample.device_time_ns] = &sample;
  const int64_t gap_ns = gaps[0]->device_time_ns;
  const int64_t before_gap_ns = std::prev(by_time.lower_bound(gap_ns))->first;
  const int64_t after_gap_ns = by_time.upper_bound(gap_ns)->first;
  int64_t missing = 0;
  for (const auto& [sequence, frame] : TruthFrames(options, last_seen)) {
    const int64_t t_ns = int64_t{frame.sample.device_time_us} * 1000;
    if (frame.type != wire::FrameType::kSample || t_ns > log.LastSampleNs()) continue;
    if (by_time.count(t_ns) > 0) {
      ExpectSampleIsFrame(*by_time.at(t_ns), frame.sample);
    } else {
      ++missing;
      EXPECT_TRUE(t_ns > before_gap_ns && t_ns < after_gap_ns) << "sample at " << t_ns << " ns";
    }
  }
  EXPECT_GT(missing, 100) << "0.3 s without link at 2 kHz";

  // the gap names the missing frames; every frame the emulator lost lies in it
  unsigned long long first = 0, last = 0;
  ASSERT_EQ(std::sscanf(gaps[0]->detail.c_str(), "%*d frames, sequence %llu..%llu", &first, &last),
            2)
      << gaps[0]->detail;
  EXPECT_GE(static_cast<int64_t>(last - first + 1), missing);
  for (uint32_t lost : emulator.emulator().dropped_sequences()) {
    if (lost <= last_seen) {
      EXPECT_TRUE(lost >= first && lost <= last) << "frame " << lost;
    }
  }
}

TEST(CaptureSession, SendsStartAndRecordsTheCommandedTest) {
  ScratchDir dir;
  EmulatorOptions options = QuickTest(1000);
  options.autostart = false;
  EmulatorThread emulator(options);
  ASSERT_TRUE(emulator.ok());
  TestParameters test;
  test.pulled_group = CableGroup::kHL;
  test.bend_target_fraction = 0.85;
  test.ramp_amplitude_rad = -std::numbers::pi / 6;
  test.ramp_duration_s = 0.3;
  CaptureOptions capture = QuickCapture(emulator.port(), dir / "trial.csv");
  capture.send_start = true;
  capture.start_command = test.StartCommand();
  std::atomic<bool> stop{false};
  auto summary = RunCapture(capture, DriveChainCalibration(), stop);
  ASSERT_TRUE(emulator.Stop().ok());
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_EQ(summary->stopped_by, "test end");
  EXPECT_EQ(emulator.emulator().stats().commands_received, 1);

  const ControllerLog log = ReadLog(dir / "trial.csv");
  EXPECT_EQ(log.header.metadata.at("commanded_pulled_group"), "HL");
  EXPECT_EQ(log.header.metadata.at("commanded_bend_percent"), "85.0");
  EXPECT_EQ(log.header.metadata.at("commanded_ramp_deg"), "-30.000");
  EXPECT_EQ(log.header.metadata.at("commanded_ramp_s"), "0.300");
  ASSERT_GE(log.events.size(), 3u);
  EXPECT_EQ(log.events[0].kind, LogEventKind::kNote);
  EXPECT_EQ(log.events[0].detail, "ACK START");
  EXPECT_EQ(log.events[1].kind, LogEventKind::kTestStart);
  // the controller ran the commanded test: the vertebra ends near -30 degrees (its motor
  // lags the 0.3 s ramp by a few hundredths of a radian when TEST_END comes)
  EXPECT_NEAR(log.samples.back().vertebra_rad, -std::numbers::pi / 6, 0.03);
  EXPECT_LT(log.samples.back().vertebra_rad, -0.45);
}

TEST(CaptureSession, GarbageBurstDoesNotStallTheParser) {
  ScratchDir dir;
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok()) << pty.status().ToString();
  CaptureThread capture(QuickCapture(pty->slave_path(), dir / "trial.csv"),
                        DriveChainCalibration());

  const auto send = [&](const std::string& bytes) {
    for (size_t written = 0; written < bytes.size();) {
      const ssize_t n = ::write(pty->master_fd(), bytes.data() + written, bytes.size() - written);
      ASSERT_GT(n, 0) << std::strerror(errno);
      written += static_cast<size_t>(n);
    }
  };
  const auto frames = [](uint32_t from, uint32_t to) {
    std::string bytes;
    for (uint32_t sequence = from; sequence < to; ++sequence) {
      wire::SampleFrame sample;
      sample.sequence = sequence;
      sample.device_time_us = 1000 * sequence;
      sample.rotate_counts = static_cast<int32_t>(sequence);
      char out[wire::kMaxFrameBytes];
      bytes.append(out, wire::EncodeSample(sample, out, sizeof out));
    }
    return bytes;
  };
  std::mt19937 random(5);
  std::string garbage(100 * 1024, '\0');
  for (char& byte : garbage) byte = static_cast<char>(random() & 0xFF);
  wire::EventFrame end;
  end.sequence = 200;
  end.device_time_us = 200'000;
  end.kind = wire::EventKind::kTestEnd;
  char out[wire::kMaxFrameBytes];
  const std::string test_end(out, wire::EncodeEvent(end, out, sizeof out));

  // 100 frames, 100 KB of noise, 100 frames and TEST_END: the capture must get through
  // the noise at once and stop at the end
  send(frames(0, 100));
  ASSERT_TRUE(WaitFor([&] { return capture.frames() >= 100; }, 5));
  const int64_t burst_start_ns = MonotonicNowNs();
  send(garbage);
  send(frames(100, 200) + test_end);
  ASSERT_TRUE(WaitFor([&] { return capture.done(); }, 5));
  const double took_s = SecondsFromNs(MonotonicNowNs() - burst_start_ns);
  EXPECT_LT(took_s, 1.0) << "100 KB of garbage took " << took_s << " s to get through";

  auto summary = capture.Finish(/*stop=*/false);
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_EQ(summary->stopped_by, "test end");
  EXPECT_EQ(summary->samples, 200);
  EXPECT_EQ(summary->gaps, 0);
  EXPECT_EQ(summary->bytes,
            static_cast<int64_t>(frames(0, 200).size() + garbage.size() + test_end.size()));
  EXPECT_GT(summary->garbage_bytes, 50 * 1024);
  const ControllerLog log = ReadLog(dir / "trial.csv");
  ASSERT_EQ(log.samples.size(), 200u);
  for (uint32_t i = 0; i < 200; ++i) EXPECT_EQ(log.samples[i].rotate_counts, int64_t{i});
}

TEST(CaptureSession, CapturedLogGoesStraightIntoTheTable) {
  ScratchDir dir;
  auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
  ASSERT_TRUE(calibration.ok()) << calibration.status().ToString();
  const FullCapture run = CaptureQuickTest(dir, *calibration);
  ASSERT_FALSE(run.log.samples.empty());

  // the video saw the LED at 2.0 s and the liftoff 0.7 s later
  WriteFile(dir / "manifest.json", R"({
    "format": "liftoff-manifest", "version": 1,
    "trials": [{"id": "E1", "foot": "A", "log": {"path": "trial.csv", "format": "liftoff"},
                "times": {"led_on_s": 2.0, "liftoff_s": 2.7}}]})");
  cli::TableCommand table;
  table.manifest_path = dir / "manifest.json";
  table.format = "json";
  table.tables = "trials";
  table.calibration.calibration_path = SourceDir() / "calib" / "laika-2018.json";
  std::ostringstream out, err;
  ASSERT_EQ(cli::RunTable(table, out, err), 0) << err.str();
  const nlohmann::json result = nlohmann::json::parse(out.str());
  const double liftoff_rad = result.at("trials").at(0).at("liftoff_rad").get<double>();

  // truth: the LED went on at the autostart (50 ms device time); 0.7 s later, at 750 ms,
  // the controller sent a sample with the vertebra at its rotate counts
  const auto truth = TruthFrames(run.emulator_options, 2000);
  double truth_rad = kNotMeasured;
  for (const auto& [sequence, frame] : truth) {
    if (frame.type == wire::FrameType::kSample && frame.sample.device_time_us == 750'000) {
      truth_rad = std::abs(VertebraRadFromCounts(frame.sample.rotate_counts));
    }
  }
  EXPECT_GT(truth_rad, 0.5) << "the ramp is well under way at 0.75 s";
  EXPECT_NEAR(liftoff_rad, truth_rad, 1e-6);
}

// ---------------------------------------------------------------------------------------
// Ctrl-C on the real binaries

// A child process; killed and reaped on destruction if still running.
class Child {
 public:
  // Runs LIFTOFF_BINARY with `arguments`; stdout to `stdout_fd` (or a file), stderr to a
  // file.
  Child(const std::vector<std::string>& arguments, int stdout_fd,
        const std::filesystem::path& stdout_path, const std::filesystem::path& stderr_path) {
    std::vector<std::string> all = {LIFTOFF_BINARY};
    all.insert(all.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& argument : all) argv.push_back(argument.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (stdout_fd >= 0) {
      posix_spawn_file_actions_adddup2(&actions, stdout_fd, STDOUT_FILENO);
    } else {
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_path.c_str(),
                                       O_WRONLY | O_CREAT | O_TRUNC, 0644);
    }
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_path.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  bool started() const { return pid_ > 0; }
  void Signal(int signal) const { ::kill(pid_, signal); }
  // The exit code, -signal when killed by one, nullopt when still running after timeout.
  std::optional<int> Wait(double timeout_s) {
    std::optional<int> code;
    WaitFor(
        [&] {
          int status = 0;
          if (::waitpid(pid_, &status, WNOHANG) != pid_) return false;
          code = WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
          pid_ = -1;
          return true;
        },
        timeout_s);
    return code;
  }

 private:
  pid_t pid_ = -1;
};

// One line from `fd`, waiting up to `timeout_s`.
std::string ReadLine(int fd, double timeout_s) {
  std::string line;
  const int64_t deadline_ns = MonotonicNowNs() + NsFromSeconds(timeout_s);
  while (MonotonicNowNs() < deadline_ns) {
    pollfd poll_fd{fd, POLLIN, 0};
    if (::poll(&poll_fd, 1, 50) <= 0) continue;
    char c = 0;
    if (::read(fd, &c, 1) != 1) break;
    if (c == '\n') return line;
    line += c;
  }
  return line;
}

TEST(CaptureSession, CtrlCLeavesACompleteLogAndAJournalThatReplaysToIt) {
  ScratchDir dir;
  int pipe_fds[2];
  ASSERT_EQ(::pipe2(pipe_fds, O_CLOEXEC), 0);
  Child emulator({"emulate", "--rate", "1000", "--autostart", "--ramp-s", "20", "--duration", "30"},
                 pipe_fds[1], {}, dir / "emulate.err");
  ::close(pipe_fds[1]);
  ASSERT_TRUE(emulator.started());
  const std::string port = ReadLine(pipe_fds[0], 10);
  ASSERT_THAT(port, HasSubstr("/dev/pts/")) << ReadFile(dir / "emulate.err");

  const std::filesystem::path log_path = dir / "trial.csv";
  Child capture({"capture", port, "-o", log_path.string(), "--status", "off"}, -1,
                dir / "capture.out", dir / "capture.err");
  ASSERT_TRUE(capture.started());
  // a few hundred samples in, Ctrl-C
  ASSERT_TRUE(WaitFor([&] { return ReadFile(log_path).size() > 30'000; }, 10))
      << ReadFile(dir / "capture.err");
  capture.Signal(SIGINT);
  const std::optional<int> code = capture.Wait(10);
  ASSERT_TRUE(code.has_value()) << "capture did not stop on SIGINT";
  EXPECT_EQ(*code, 0) << ReadFile(dir / "capture.err");
  EXPECT_THAT(ReadFile(dir / "capture.out"), HasSubstr("stopped by stop request"));
  emulator.Signal(SIGINT);
  EXPECT_EQ(emulator.Wait(10), 0) << ReadFile(dir / "emulate.err");
  ::close(pipe_fds[0]);

  // the log is whole: no bad line, no cut-off end
  auto log = ReadControllerLog(log_path);
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  EXPECT_EQ(log->report.bad_lines, 0);
  EXPECT_FALSE(log->report.truncated_last_line);
  EXPECT_GT(log->samples.size(), 300u);
  EXPECT_EQ(log->header.device, "liftoff-emulator 1.0");

  // and the journal rebuilds exactly the same rows
  auto calibration = LoadCalibration(DefaultCalibrationPath());
  ASSERT_TRUE(calibration.ok());
  auto replay = ReplayJournal(dir / "trial.csv.journal", *calibration);
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  EXPECT_FALSE(replay->truncated);
  ASSERT_EQ(replay->log.samples.size(), log->samples.size());
  for (size_t i = 0; i < log->samples.size(); ++i) {
    const LogSample& a = log->samples[i];
    const LogSample& b = replay->log.samples[i];
    ASSERT_EQ(a.device_time_ns, b.device_time_ns) << i;
    EXPECT_EQ(a.host_time_ns, b.host_time_ns);
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.led_on, b.led_on);
    EXPECT_EQ(a.bend_counts, b.bend_counts);
    EXPECT_EQ(a.rotate_counts, b.rotate_counts);
    EXPECT_EQ(a.vertebra_rad, b.vertebra_rad);
  }
  ASSERT_EQ(replay->log.events.size(), log->events.size());
  for (size_t i = 0; i < log->events.size(); ++i) {
    EXPECT_EQ(log->events[i].kind, replay->log.events[i].kind);
    EXPECT_EQ(log->events[i].device_time_ns, replay->log.events[i].device_time_ns);
  }
}

struct BinaryRun {
  std::optional<int> code;
  std::string out;
  std::string err;
};

// Runs LIFTOFF_BINARY to the end (at most 20 s).
BinaryRun RunBinary(const std::vector<std::string>& arguments, const ScratchDir& dir) {
  BinaryRun run;
  {
    Child child(arguments, -1, dir / "binary.out", dir / "binary.err");
    run.code = child.Wait(20);
  }
  run.out = ReadFile(dir / "binary.out");
  run.err = ReadFile(dir / "binary.err");
  return run;
}

TEST(CaptureCommands, ExitCodesNameWhatWentWrong) {
  ScratchDir dir;
  // a port that is not there: not found (4)
  BinaryRun run =
      RunBinary({"capture", "/dev/liftoff-no-such-port", "-o", (dir / "a.csv").string()}, dir);
  EXPECT_EQ(run.code, 4) << run.err;
  EXPECT_THAT(run.err, HasSubstr("/dev/liftoff-no-such-port"));
  // a bad test parameter: invalid argument (3), naming the flag
  run = RunBinary({"capture", "/dev/liftoff-no-such-port", "-o", (dir / "a.csv").string(),
                   "--start", "--pulled", "HT"},
                  dir);
  EXPECT_EQ(run.code, 3);
  EXPECT_THAT(run.err, HasSubstr("--pulled: expected HR or HL, got \"HT\""));
  // a port that stays silent: timeout (7)
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok());
  run = RunBinary({"capture", pty->slave_path(), "-o", (dir / "a.csv").string(),
                   "--first-frame-timeout", "0.2", "--status", "off"},
                  dir);
  EXPECT_EQ(run.code, 7) << run.err;
  EXPECT_THAT(run.err, HasSubstr("no frame arrived within 0.2 s"));
  // a journal that is not there: not found (4); one that is not a journal: parse (5)
  run = RunBinary({"journal", (dir / "none.journal").string()}, dir);
  EXPECT_EQ(run.code, 4);
  EXPECT_THAT(run.err, HasSubstr("none.journal: no such file"));
  WriteFile(dir / "text.journal", "hello\n");
  run = RunBinary({"journal", (dir / "text.journal").string(), "--replay"}, dir);
  EXPECT_EQ(run.code, 5);
  EXPECT_THAT(run.err, HasSubstr("text.journal: byte 0: expected the journal magic"));
}

TEST(CaptureCommands, JournalReplayWritesTheLogAndDumpShowsFrames) {
  ScratchDir dir;
  {
    JournalWriter writer;
    ASSERT_TRUE(
        writer.Open(dir / "a.journal", JournalHeader{"/dev/ttyACM0", "921600 8N1", 0}).ok());
    wire::SampleFrame sample;
    sample.sequence = 7;
    sample.device_time_us = 1000;
    sample.rotate_counts = 12000;
    char out[wire::kMaxFrameBytes];
    const size_t size = wire::EncodeSample(sample, out, sizeof out);
    ASSERT_TRUE(writer.Append({reinterpret_cast<const uint8_t*>(out), size}, 5'000'000).ok());
    ASSERT_TRUE(writer.Close().ok());
  }
  BinaryRun run = RunBinary({"journal", (dir / "a.journal").string()}, dir);
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("+0.005000 s  received"));
  EXPECT_THAT(run.out, HasSubstr("  $S,7,1000,0,0,12000,0,0*"));

  run = RunBinary(
      {"journal", (dir / "a.journal").string(), "--replay", "-o", (dir / "a.csv").string()}, dir);
  EXPECT_EQ(run.code, 0) << run.err;
  auto log = ReadControllerLog(dir / "a.csv");
  ASSERT_TRUE(log.ok()) << log.status().ToString();
  ASSERT_EQ(log->samples.size(), 1u);
  EXPECT_EQ(log->samples[0].sequence, 7u);
  EXPECT_NEAR(log->samples[0].vertebra_rad, std::numbers::pi / 2, 1e-12);  // 1 shaft turn / 4
  // an existing output is kept unless --force
  run = RunBinary(
      {"journal", (dir / "a.journal").string(), "--replay", "-o", (dir / "a.csv").string()}, dir);
  EXPECT_EQ(run.code, 3);
  EXPECT_THAT(run.err, HasSubstr("a.csv: exists; pass --force to replace it"));
}

// ---------------------------------------------------------------------------------------
// errors

TEST(CaptureSession, RejectsBadOptionsNamingTheField) {
  std::atomic<bool> stop{false};
  CaptureOptions options = QuickCapture("", "trial.csv");
  auto result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(), HasSubstr("capture port"));

  options.port = "/dev/pts/9999";
  options.read_timeout_ms = 0;
  result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_THAT(result.status().message(), HasSubstr("capture read_timeout_ms: expected > 0"));

  options = QuickCapture("/dev/pts/9999", "trial.csv");
  options.send_start = true;  // with a PING
  result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_THAT(result.status().message(), HasSubstr("capture start_command: expected a START"));
}

TEST(CaptureSession, MissingPortIsNotFoundAndWritesNothing) {
  ScratchDir dir;
  std::atomic<bool> stop{false};
  auto result = RunCapture(QuickCapture("/dev/liftoff-no-such-port", dir / "trial.csv"),
                           DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(result.status().message(), HasSubstr("/dev/liftoff-no-such-port"));
  EXPECT_FALSE(std::filesystem::exists(dir / "trial.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "trial.csv.journal"));
}

TEST(CaptureSession, SilentPortTimesOutWithItsJournalOnDisk) {
  ScratchDir dir;
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok());
  const std::string noise = "not a frame\n";
  ASSERT_EQ(::write(pty->master_fd(), noise.data(), noise.size()),
            static_cast<ssize_t>(noise.size()));
  CaptureOptions options = QuickCapture(pty->slave_path(), dir / "trial.csv");
  options.first_frame_timeout_s = 0.2;
  std::atomic<bool> stop{false};
  auto result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kTimeout);
  EXPECT_THAT(result.status().message(), HasSubstr("no frame arrived within 0.2 s (12 bytes"));
  // what did arrive is in the journal
  JournalReader reader;
  ASSERT_TRUE(reader.Open(dir / "trial.csv.journal").ok());
  EXPECT_EQ(reader.header().port, pty->slave_path());
  JournalChunk chunk;
  ASSERT_TRUE(reader.Next(chunk));
  EXPECT_EQ(chunk.bytes, noise);
}


// ---------------------------------------------------------------------------------------
// issue 12: earlier recordings, replaced links, replay order

// Writes `frames` to a pty's master as the controller would.
void SendFrames(int master_fd, const std::vector<wire::Frame>& frames) {
  std::string bytes;
  for (const wire::Frame& frame : frames) {
    char line[wire::kMaxFrameBytes];
    size_t size = 0;
    switch (frame.type) {
      case wire::FrameType::kSample: size = wire::EncodeSample(frame.sample, line, sizeof line); break;
      case wire::FrameType::kHeader: size = wire::EncodeHeader(frame.header, line, sizeof line); break;
      case wire::FrameType::kEvent: size = wire::EncodeEvent(frame.event, line, sizeof line); break;
      case wire::FrameType::kCommand: break;
    }
    ASSERT_GT(size, 0u);
    bytes.append(line, size);
  }
  ASSERT_EQ(::write(master_fd, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
}

wire::Frame Sample(uint32_t sequence, uint32_t device_time_us) {
  wire::Frame frame;
  frame.type = wire::FrameType::kSample;
  frame.sample.sequence = sequence;
  frame.sample.device_time_us = device_time_us;
  frame.sample.led_on = 1;
  frame.sample.rotate_counts = static_cast<int32_t>(sequence) * 3;
  return frame;
}

wire::Frame Event(uint32_t sequence, uint32_t device_time_us, wire::EventKind kind) {
  wire::Frame frame;
  frame.type = wire::FrameType::kEvent;
  frame.event.sequence = sequence;
  frame.event.device_time_us = device_time_us;
  frame.event.kind = kind;
  return frame;
}

wire::Frame Header(uint32_t sequence, uint32_t device_time_us) {
  wire::Frame frame;
  frame.type = wire::FrameType::kHeader;
  frame.header.sequence = sequence;
  frame.header.device_time_us = device_time_us;
  frame.header.protocol_version = 1;
  std::strcpy(frame.header.firmware, "hand 1.0");
  frame.header.counts_per_motor_rev = 12;
  frame.header.gearbox_ratio = 1000;
  frame.header.spur_gear_ratio = 4;
  return frame;
}

TEST(CaptureSession, RefusesToReplaceAnEarlierRecordingUnlessForced) {
  ScratchDir dir;
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok());
  std::atomic<bool> stop{false};
  CaptureOptions options = QuickCapture(pty->slave_path(), dir / "trial.csv");
  options.max_duration_s = 0.1;

  // an earlier log, or only its journal, or a dangling link where the log goes: refused,
  // naming the file, and nothing changes
  WriteFile(dir / "trial.csv", "earlier trial\n");
  auto result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(), HasSubstr((dir / "trial.csv").string() + ": exists"));
  EXPECT_THAT(result.status().message(), HasSubstr("--force"));
  EXPECT_EQ(ReadFile(dir / "trial.csv"), "earlier trial\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "trial.csv.journal"));

  std::filesystem::rename(dir / "trial.csv", dir / "trial.csv.journal");
  result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(), HasSubstr("trial.csv.journal: exists"));
  EXPECT_EQ(ReadFile(dir / "trial.csv.journal"), "earlier trial\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "trial.csv"));

  std::filesystem::create_symlink(dir / "nowhere.csv", dir / "other.csv");
  options.log_path = dir / "other.csv";
  result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir / "nowhere.csv"));

  // a journal named as the log through another spelling is the log
  options.log_path = dir / "new.csv";
  options.journal_path = dir / "." / "new.csv";
  result = RunCapture(options, DriveChainCalibration(), stop);
  EXPECT_THAT(result.status().message(), HasSubstr("capture journal_path: must differ"));

  // with replace_existing (--force) the earlier journal is replaced
  options.log_path = dir / "trial.csv";
  options.journal_path.clear();
  options.replace_existing = true;
  result = RunCapture(options, DriveChainCalibration(), stop);
  ASSERT_TRUE(result.ok()) << result.status().ToString();
  JournalReader reader;
  EXPECT_TRUE(reader.Open(dir / "trial.csv.journal").ok());
  EXPECT_TRUE(std::filesystem::exists(dir / "trial.csv"));
}

TEST(CaptureCommands, CaptureRefusesAnExistingLogAndForceReplacesIt) {
  ScratchDir dir;
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok());
  const std::string log_path = (dir / "trial.csv").string();
  WriteFile(log_path, "earlier trial\n");
  BinaryRun run = RunBinary({"capture", pty->slave_path(), "-o", log_path, "--max-duration", "0.1",
                             "--first-frame-timeout", "0", "--status", "off"},
                            dir);
  EXPECT_EQ(run.code, 3) << run.err;
  EXPECT_THAT(run.err, HasSubstr(log_path + ": exists"));
  EXPECT_EQ(ReadFile(log_path), "earlier trial\n");
  run = RunBinary({"capture", pty->slave_path(), "-o", log_path, "--max-duration", "0.1",
                   "--first-frame-timeout", "0", "--status", "off", "--force"},
                  dir);
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_THAT(ReadFile(log_path), HasSubstr("# liftoff-log 1"));
}

// A pty link removed and re-created at once gets its inode back on ext4 (and the same
// seconds-resolution times): the capture must still see a new link and reopen it.
TEST(CaptureSession, ReopensALinkRemovedAndRecreatedAtOnce) {
  ScratchDir dir;
  auto first = PseudoTerminal::Open();
  ASSERT_TRUE(first.ok());
  const std::filesystem::path link = dir / "controller";
  std::filesystem::create_symlink(first->slave_path(), link);
  CaptureOptions options = QuickCapture(link.string(), dir / "trial.csv");
  options.stop_on_test_end = false;
  CaptureThread capture(options, DriveChainCalibration());
  SendFrames(first->master_fd(), {Header(0, 0), Sample(1, 1000), Sample(2, 2000)});
  ASSERT_TRUE(WaitFor([&] { return capture.frames() >= 3; }, 5));

  // unplug: the old pty goes, a new one comes under the same link within the same second
  auto second = PseudoTerminal::Open();
  ASSERT_TRUE(second.ok());
  std::filesystem::remove(link);
  first->CloseMaster();
  std::filesystem::create_symlink(second->slave_path(), link);
  SendFrames(second->master_fd(), {Sample(3, 3000), Sample(4, 4000)});
  const bool reopened = WaitFor([&] { return capture.frames() >= 5; }, 3);
  auto summary = capture.Finish(true);
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_TRUE(reopened) << summary->Brief();
  EXPECT_EQ(summary->reconnects, 1);
  EXPECT_EQ(summary->samples, 4);
}

// The controller sends a sample and events at one device instant in both orders; the
// live log and the log rebuilt from its journal must be the same rows, byte for byte, in
// the documented order (docs/formats.md: the events of an instant before its sample).
TEST(CaptureSession, LiveLogAndItsReplayAreTheSameBytes) {
  ScratchDir dir;
  auto pty = PseudoTerminal::Open();
  ASSERT_TRUE(pty.ok());
  CaptureOptions options = QuickCapture(pty->slave_path(), dir / "trial.csv");
  CaptureThread capture(options, DriveChainCalibration());
  SendFrames(pty->master_fd(),
             {Header(0, 0), Sample(1, 1000), Event(2, 1000, wire::EventKind::kAck),
              Event(3, 1000, wire::EventKind::kTestStart), Event(4, 1000, wire::EventKind::kLedOn),
              Sample(5, 2000), Event(6, 3000, wire::EventKind::kLedOff), Sample(7, 3000),
              Sample(9, 4000), Event(10, 4000, wire::EventKind::kTestEnd)});
  auto summary = capture.Finish(false);  // stops at TEST_END
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_EQ(summary->stopped_by, "test end");

  auto replay = ReplayJournal(dir / "trial.csv.journal", DriveChainCalibration());
  ASSERT_TRUE(replay.ok()) << replay.status().ToString();
  ASSERT_TRUE(WriteControllerLog(dir / "replay.csv", replay->log).ok());
  const auto rows = [](const std::string& text) {
    return text.substr(text.find("device_time_ns,"));
  };
  const std::string live = ReadFile(dir / "trial.csv");
  ASSERT_NE(live.find("device_time_ns,"), std::string::npos) << live;
  EXPECT_EQ(rows(live), rows(ReadFile(dir / "replay.csv")));

  // the order, by hand: device time in us and event name ("" for a sample) of each row
  std::vector<std::string> order;
  std::istringstream lines(rows(live));
  std::string line;
  std::getline(lines, line);  // column names
  while (std::getline(lines, line)) {
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 10u) << line;
    order.push_back(fields[0].substr(0, fields[0].size() - 3) + " " + fields[9]);
  }
  EXPECT_THAT(order, ::testing::ElementsAre("1000 note", "1000 test_start", "1000 led_on", "1000 ",
                                            "2000 ", "3000 led_off", "3000 ", "3500 gap",
                                            "4000 test_end", "4000 "));
}

}  // namespace
}  // namespace liftoff::capture
