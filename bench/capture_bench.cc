// Live capture's figures: sustained frames per second through a pseudo-terminal with
// zero loss (the target: 20,000 frames/s, 20x a 1 kHz controller), side by side
// with a plain read of the same bytes (what the pty itself can move), and the capture's
// CPU use while a paced emulator streams at 1 kHz.
//
// Run: build/bench/capture_bench   (each case is one long iteration; counters hold the
// figures: frames_per_s, lost_frames, gaps, cpu_percent)
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "liftoff/capture/capture_session.h"
#include "liftoff/capture/emulator.h"
#include "liftoff/capture/serial_port.h"
#include "liftoff/capture/wire_format.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/time.h"

#include "bench_support.h"

namespace {

using namespace liftoff;
using namespace liftoff::capture;

std::filesystem::path TempDir() {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("liftoff-capture-bench-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

// `frames` sample frames of a 1 kHz ramp (about 50 bytes each), then TEST_END.
std::string EncodedTest(int64_t frames) {
  std::string bytes;
  char out[wire::kMaxFrameBytes];
  for (int64_t i = 0; i < frames; ++i) {
    wire::SampleFrame sample;
    sample.sequence = static_cast<uint32_t>(i);
    sample.device_time_us = static_cast<uint32_t>(i * 1000);
    sample.led_on = 1;
    sample.bend_counts = 2801;
    sample.rotate_counts = static_cast<int32_t>(i / 5);
    sample.bend_setpoint_counts = 2801;
    sample.rotate_setpoint_counts = static_cast<int32_t>(i / 5 + 7);
    bytes.append(out, wire::EncodeSample(sample, out, sizeof out));
  }
  wire::EventFrame end;
  end.sequence = static_cast<uint32_t>(frames);
  end.device_time_us = static_cast<uint32_t>(frames * 1000);
  end.kind = wire::EventKind::kTestEnd;
  bytes.append(out, wire::EncodeEvent(end, out, sizeof out));
  return bytes;
}

// Writes all of `bytes` to the pty master as fast as it takes them.
bool WriteAll(int fd, const std::string& bytes) {
  for (size_t written = 0; written < bytes.size();) {
    const ssize_t n =
        ::write(fd, bytes.data() + written, std::min<size_t>(bytes.size() - written, 1 << 16));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

double ThreadCpuSeconds() {
  rusage usage{};
  ::getrusage(RUSAGE_THREAD, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
}

CaptureOptions BenchCaptureOptions(const std::string& port, const std::filesystem::path& dir) {
  CaptureOptions options;
  options.port = port;
  options.log_path = dir / "bench.csv";
  options.read_timeout_ms = 10;
  options.header_wait_s = 0;     // no header frame here: open the log at the first frame
  options.max_duration_s = 120;  // a safety net
  return options;
}

// ---------------------------------------------------------------------------------------
// (a) throughput: a writer thread pushes pre-encoded frames into the pty as fast as it
// takes them; the capture (port read + journal + parse + log write) reads them.

void BM_CaptureThroughPty(benchmark::State& state) {
  const int64_t frames = state.range(0);
  const std::string bytes = EncodedTest(frames);
  const Calibration calibration = bench::ShippedCalibration();
  const auto dir = TempDir();
  for (auto _ : state) {
    auto pty = PseudoTerminal::Open();
    if (!pty.ok()) {
      state.SkipWithError(pty.status().ToString().c_str());
      break;
    }
    std::atomic<bool> stop{false};
    Result<CaptureSummary> summary = InvalidArgumentError("not run");
    const int64_t start_ns = MonotonicNowNs();
    std::thread capture([&] {
      summary = RunCapture(BenchCaptureOptions(pty->slave_path(), dir), calibration, stop);
    });
    const bool written = WriteAll(pty->master_fd(), bytes);
    capture.join();  // it stops at TEST_END, the last frame
    const double seconds = SecondsFromNs(MonotonicNowNs() - start_ns);
    if (!written || !summary.ok()) {
      state.SkipWithError(summary.ok() ? "write failed" : summary.status().ToString().c_str());
      break;
    }
    state.SetIterationTime(seconds);
    state.counters["frames_per_s"] = static_cast<double>(frames + 1) / seconds;
    state.counters["MB_per_s"] = static_cast<double>(bytes.size()) / seconds * 1e-6;
    state.counters["lost_frames"] = static_cast<double>(frames + 1 - summary->frames);
    state.counters["gaps"] = static_cast<double>(summary->gaps);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_CaptureThroughPty)
    ->Arg(300'000)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The baseline: the same bytes through the same pty, read and thrown away.
void BM_PlainReadThroughPty(benchmark::State& state) {
  const int64_t frames = state.range(0);
  const std::string bytes = EncodedTest(frames);
  for (auto _ : state) {
    auto pty = PseudoTerminal::Open();
    if (!pty.ok()) {
      state.SkipWithError(pty.status().ToString().c_str());
      break;
    }
    auto port = OpenSerialPort(pty->slave_path(), PortSettings{});
    if (!port.ok()) {
      state.SkipWithError(port.status().ToString().c_str());
      break;
    }
    const int64_t start_ns = MonotonicNowNs();
    std::thread writer([&] { WriteAll(pty->master_fd(), bytes); });
    size_t received = 0;
    std::vector<uint8_t> buffer(16 * 1024);
    while (received < bytes.size()) {
      auto n = (*port)->Read(buffer, 1000);
      if (!n.ok() || *n == 0) break;
      received += *n;
    }
    writer.join();
    const double seconds = SecondsFromNs(MonotonicNowNs() - start_ns);
    state.SetIterationTime(seconds);
    state.counters["frames_per_s"] = static_cast<double>(frames + 1) / seconds;
    state.counters["MB_per_s"] = static_cast<double>(received) / seconds * 1e-6;
    state.counters["lost_frames"] = received == bytes.size() ? 0.0 : -1.0;
  }
}
BENCHMARK(BM_PlainReadThroughPty)
    ->Arg(300'000)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The same with the emulator unpaced (its model making every frame) instead of a writer
// of ready-made frames: both ends on this machine's two cores.
void BM_CaptureFromUnpacedEmulator(benchmark::State& state) {
  const double duration_s = 3.0;
  const Calibration calibration = bench::ShippedCalibration();
  const auto dir = TempDir();
  for (auto _ : state) {
    EmulatorOptions options;
    options.unpaced = true;
    options.rate_hz = 100'000;  // device time 10 us a frame
    options.duration_s = duration_s;
    auto emulator = Emulator::Create(options);
    if (!emulator.ok()) {
      state.SkipWithError(emulator.status().ToString().c_str());
      break;
    }
    CaptureOptions capture_options = BenchCaptureOptions((*emulator)->port_path().string(), dir);
    capture_options.stop_on_test_end = false;
    capture_options.status_interval_s = 0.01;
    std::atomic<bool> stop{false};
    std::atomic<int64_t> bytes_read{0};
    Result<CaptureSummary> summary = InvalidArgumentError("not run");
    std::thread capture([&] {
      summary = RunCapture(capture_options, calibration, stop,
                           [&](const CaptureStatus& status) { bytes_read = status.bytes; });
    });
    std::atomic<bool> emulator_stop{false};
    const int64_t start_ns = MonotonicNowNs();
    const Status ran = (*emulator)->Run(emulator_stop);
    const EmulatorStats stats = (*emulator)->stats();
    // the capture finishes what the pty still holds
    const int64_t deadline_ns = MonotonicNowNs() + 10 * kNanosecondsPerSecond;
    while (bytes_read < stats.bytes_written && MonotonicNowNs() < deadline_ns) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const double seconds = SecondsFromNs(MonotonicNowNs() - start_ns);
    stop = true;
    capture.join();
    if (!ran.ok() || !summary.ok()) {
      state.SkipWithError(!ran.ok() ? ran.ToString().c_str() : summary.status().ToString().c_str());
      break;
    }
    state.SetIterationTime(seconds);
    state.counters["frames_per_s"] = static_cast<double>(summary->frames) / seconds;
    state.counters["lost_frames"] = static_cast<double>(stats.frames_written - summary->frames);
    state.counters["gaps"] = static_cast<double>(summary->gaps);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_CaptureFromUnpacedEmulator)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// ---------------------------------------------------------------------------------------
// (b) CPU: a paced emulator at 1 kHz for 5 s; the capture thread's own CPU time
// (RUSAGE_THREAD) over the wall time, in percent of one core.

void BM_CaptureCpuAt1kHz(benchmark::State& state) {
  const double duration_s = 5.0;
  const Calibration calibration = bench::ShippedCalibration();
  const auto dir = TempDir();
  for (auto _ : state) {
    EmulatorOptions options;
    options.rate_hz = 1000;
    options.autostart = true;
    options.model.test.ramp_duration_s = 60;  // the test runs throughout
    options.duration_s = duration_s + 0.5;
    auto emulator = Emulator::Create(options);
    if (!emulator.ok()) {
      state.SkipWithError(emulator.status().ToString().c_str());
      break;
    }
    std::atomic<bool> emulator_stop{false};
    double emulator_cpu_s = 0;
    std::thread emulator_thread([&] {
      const double cpu_start_s = ThreadCpuSeconds();
      (void)(*emulator)->Run(emulator_stop);
      emulator_cpu_s = ThreadCpuSeconds() - cpu_start_s;
    });

    CaptureOptions capture_options = BenchCaptureOptions((*emulator)->port_path().string(), dir);
    capture_options.max_duration_s = duration_s;
    capture_options.read_timeout_ms = 50;
    std::atomic<bool> stop{false};
    const int64_t start_ns = MonotonicNowNs();
    const double cpu_start_s = ThreadCpuSeconds();
    auto summary = RunCapture(capture_options, calibration, stop);
    const double cpu_s = ThreadCpuSeconds() - cpu_start_s;
    const double wall_s = SecondsFromNs(MonotonicNowNs() - start_ns);
    emulator_stop = true;
    emulator_thread.join();
    if (!summary.ok()) {
      state.SkipWithError(summary.status().ToString().c_str());
      break;
    }
    state.SetIterationTime(wall_s);
    state.counters["cpu_percent"] = 100.0 * cpu_s / wall_s;
    state.counters["emulator_cpu_percent"] = 100.0 * emulator_cpu_s / wall_s;
    state.counters["frames_per_s"] = static_cast<double>(summary->frames) / wall_s;
    state.counters["gaps"] = static_cast<double>(summary->gaps);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_CaptureCpuAt1kHz)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
