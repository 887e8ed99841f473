// Capture soak (issue 12): a million frames through a pseudo-terminal, 0.1 % of the bytes
// corrupted, ten unplugs (five of them shorter than a second: the link removed and
// re-created at once, the case ext4 hands the same inode back), the sequence number and
// the device clock each wrapping once. The controller is written here from
// docs/protocol.md alone (its own CRC and frame text, not wire_format.h), so the capture
// is checked against an independent reading of the protocol.
//
// Prints: frames sent, kept (accepted by the capture), lost outside the unplug windows
// (must be 0), corrupted frames accepted (must be 0), reconnects marked, the gaps'
// missing frames against the truth, whether `journal --replay` gives the live log's rows
// byte for byte, and the wall time.
//
// Run: build/bench/capture_soak_bench   (one iteration of about half a minute)
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>

#include "liftoff/capture/capture_session.h"
#include "liftoff/capture/journal.h"
#include "liftoff/capture/serial_port.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/time.h"

#include "bench_support.h"

namespace {

using namespace liftoff;
using namespace liftoff::capture;
using namespace std::chrono_literals;

constexpr int64_t kFrames = 1'000'000;
constexpr double kCorruptByteProbability = 0.001;
constexpr int kUnplugs = 10;
// both counters wrap inside the run: the sequence after 400,000 frames, the clock after
// 600 s of device time (one sample per ms)
constexpr uint32_t kFirstSequence = 0xFFFF'FFFFu - 400'000u + 1u;
constexpr uint32_t kFirstDeviceUs = 0xFFFF'FFFFu - 600'000'000u + 1u;
constexpr int64_t kSamplePeriodUs = 1000;

// ---------------------------------------------------------------------------------------
// the controller, from docs/protocol.md

// Section 2: CRC-16/CCITT-FALSE of the bytes between '$' and '*'.
uint16_t ProtocolCrc(const std::string& body) {
  uint16_t crc = 0xFFFF;
  for (const char c : body) {
    crc = static_cast<uint16_t>(crc ^ (static_cast<uint8_t>(c) << 8));
    for (int bit = 0; bit < 8; ++bit) {
      crc = static_cast<uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
    }
  }
  return crc;
}

std::string ProtocolLine(const std::string& body) {
  char crc[8];
  std::snprintf(crc, sizeof crc, "%04X", ProtocolCrc(body));
  return "$" + body + "*" + crc + "\n";
}

// What the controller sent, for the comparison with the log.
struct Sent {
  char type = 'S';            // S, H or E
  int64_t device_ns = 0;      // unwrapped as the host must (from the first reading)
  std::string event;          // E: the log's event name
  int32_t bend_counts = 0;    // S
  int32_t rotate_counts = 0;  // S
  bool led = false;           // S
  bool written = true;        // false: sent while unplugged (lost in an unplug window)
  bool intact = true;         // no byte corrupted
};

// Frame k of the run: a header every 1000 frames, an event every 250 at the instant of
// the sample before it (a tie the log must order as documented), samples otherwise.
Sent NextFrame(int64_t k, int64_t& device_us, std::string& line) {
  Sent sent;
  const auto sequence = static_cast<uint32_t>(kFirstSequence + static_cast<uint64_t>(k));
  if (k % 1000 != 0 && k % 250 != 1) device_us += kSamplePeriodUs;
  const auto t_us = static_cast<uint32_t>(kFirstDeviceUs + static_cast<uint64_t>(device_us));
  sent.device_ns = (int64_t{kFirstDeviceUs} + device_us) * 1000;
  const std::string head = std::to_string(sequence) + "," + std::to_string(t_us) + ",";
  if (k % 1000 == 0) {
    sent.type = 'H';
    line = ProtocolLine("H," + head + "1,soak-fw 1.0,12,1000,4");
  } else if (k % 250 == 1) {
    sent.type = 'E';
    static const char* const kinds[3][3] = {
        {"LED_ON", "0", "led_on"}, {"LED_OFF", "0", "led_off"}, {"PONG", "-42", "note"}};
    const auto* kind = kinds[(k / 250) % 3];
    sent.event = kind[2];
    line = ProtocolLine("E," + head + kind[0] + "," + kind[1] + ",");
  } else {
    sent.led = (k / 5000) % 2 == 1;
    sent.bend_counts = static_cast<int32_t>(k % 5000) - 2500;
    sent.rotate_counts = -static_cast<int32_t>(k % 100'000) * 3;
    line = ProtocolLine("S," + head + (sent.led ? "1," : "0,") + std::to_string(sent.bend_counts) +
                        "," + std::to_string(sent.rotate_counts) + "," +
                        std::to_string(sent.bend_counts + 1) + "," +
                        std::to_string(sent.rotate_counts - 1));
  }
  return sent;
}

// Writes all of `bytes` to the non-blocking pty master; false when the pty took nothing
// for 30 s (a capture that never reconnected leaves the pty's buffer full).
bool WriteAll(int fd, const std::string& bytes) {
  for (size_t written = 0; written < bytes.size();) {
    pollfd writable{fd, POLLOUT, 0};
    if (::poll(&writable, 1, 30'000) == 0) return false;
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

void MakeNonBlocking(int fd) { ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK); }

// ---------------------------------------------------------------------------------------
// the run

struct Figures {
  int64_t sent = 0;
  int64_t sent_in_windows = 0;
  int64_t corrupted = 0;
  int64_t kept = 0;
  int64_t lost_outside_windows = 0;
  int64_t corrupted_accepted = 0;
  int64_t reconnects_marked = 0;
  int64_t stalled_at_frame = -1;  // the capture stopped reading here (never reconnected)
  int64_t missing_reported = 0;
  int64_t missing_expected = 0;
  int64_t replay_rows_differing = -1;
  double wall_s = 0;
  std::string problem;
};

// Waits until the capture has received `written_bytes` bytes, or 30 s (a capture that
// never reconnects then shows as lost frames).
void WaitForCapture(const std::atomic<int64_t>& captured_bytes, int64_t written_bytes) {
  const int64_t deadline_ns = MonotonicNowNs() + 30 * kNanosecondsPerSecond;
  while (captured_bytes.load() < written_bytes && MonotonicNowNs() < deadline_ns) {
    std::this_thread::sleep_for(1ms);
  }
}

// Sends the run through `link`, unplugging ten times; waits for the capture to have
// every byte before each unplug, so what is lost is exactly what was sent unplugged.
std::vector<Sent> Controller(const std::filesystem::path& link,
                             const std::atomic<int64_t>& captured_bytes, std::string& problem,
                             int64_t& stalled_at_frame) {
  std::vector<Sent> frames;
  frames.reserve(kFrames);
  auto opened = PseudoTerminal::Open();
  if (!opened.ok()) {
    problem = opened.status().ToString();
    return frames;
  }
  PseudoTerminal pty = std::move(opened).value();
  MakeNonBlocking(pty.master_fd());
  std::filesystem::create_symlink(pty.slave_path(), link);
  std::mt19937_64 random(12);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::uniform_int_distribution<int> other_byte(1, 255);
  int64_t device_us = 0;
  int64_t written_bytes = 0;
  int64_t unplugged_until = -1;
  std::string batch;
  std::string line;
  const auto flush = [&] {
    if (!WriteAll(pty.master_fd(), batch)) stalled_at_frame = static_cast<int64_t>(frames.size());
    written_bytes += static_cast<int64_t>(batch.size());
    batch.clear();
  };
  for (int64_t k = 0; k < kFrames && problem.empty() && stalled_at_frame < 0; ++k) {
    // an unplug: the capture has every byte, then the link goes (and comes back)
    const int unplug = static_cast<int>(k * kUnplugs / kFrames);
    if (k > 0 && k == (unplug * kFrames + kFrames / 2) / kUnplugs) {
      flush();
      WaitForCapture(captured_bytes, written_bytes);
      const bool short_unplug = unplug % 2 == 1;
      const double away_s = short_unplug ? 0.075 * (unplug / 2) : 1.2;  // 0 .. 0.3 s or 1.2 s
      std::filesystem::remove(link);
      pty.CloseMaster();
      std::this_thread::sleep_for(std::chrono::duration<double>(away_s));
      auto next = PseudoTerminal::Open();
      if (!next.ok()) {
        problem = next.status().ToString();
        break;
      }
      pty = std::move(next).value();
      MakeNonBlocking(pty.master_fd());
      std::filesystem::create_symlink(pty.slave_path(), link);
      unplugged_until = k + std::max<int64_t>(50, static_cast<int64_t>(away_s * 1000));
    }
    Sent sent = NextFrame(k, device_us, line);
    sent.written = k >= unplugged_until;
    if (sent.written) {
      for (char& c : line) {
        if (uniform(random) < kCorruptByteProbability) {
          c = static_cast<char>((static_cast<uint8_t>(c) + other_byte(random)) & 0xFF);
          sent.intact = false;
        }
      }
      batch += line;
      if (batch.size() >= 64 * 1024) flush();
    }
    frames.push_back(std::move(sent));
  }
  flush();
  WaitForCapture(captured_bytes, written_bytes);
  pty.CloseMaster();
  std::filesystem::remove(link);
  return frames;
}

// Rows of a log file from its column line on.
std::string Rows(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return {};
  std::string text;
  char buffer[1 << 16];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;) text.append(buffer, n);
  std::fclose(file);
  const size_t columns = text.find("device_time_ns,");
  return columns == std::string::npos ? std::string() : text.substr(columns);
}

int64_t DifferingLines(const std::string& a, const std::string& b) {
  int64_t differing = 0;
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    const size_t end_a = std::min(a.find('\n', i), a.size());
    const size_t end_b = std::min(b.find('\n', j), b.size());
    if (a.compare(i, end_a - i, b, j, end_b - j) != 0) ++differing;
    i = end_a + 1;
    j = end_b + 1;
  }
  return differing;
}

// Matches the log against what was sent.
void Compare(const std::vector<Sent>& frames, const ControllerLog& log, Figures& figures) {
  std::map<int64_t, const Sent*> samples;
  std::map<std::pair<int64_t, std::string>, const Sent*> events;
  int64_t intact_headers = 0;
  for (const Sent& sent : frames) {
    ++figures.sent;
    if (!sent.written) ++figures.sent_in_windows;
    if (sent.written && !sent.intact) ++figures.corrupted;
    if (!sent.written || !sent.intact) ++figures.missing_expected;
    if (!sent.written) continue;
    if (sent.type == 'S') samples[sent.device_ns] = &sent;
    if (sent.type == 'E') events[{sent.device_ns, sent.event}] = &sent;
    if (sent.type == 'H' && sent.intact) ++intact_headers;
  }
  int64_t found_samples = 0;
  for (const LogSample& row : log.samples) {
    const auto it = samples.find(row.device_time_ns);
    const bool same = it != samples.end() && it->second->intact &&
                      row.bend_counts == it->second->bend_counts &&
                      row.rotate_counts == it->second->rotate_counts &&
                      row.led_on == it->second->led;
    if (same) {
      ++found_samples;
    } else {
      ++figures.corrupted_accepted;
    }
  }
  int64_t event_rows = 0;
  int64_t found_events = 0;
  for (const LogEvent& row : log.events) {
    if (row.kind == LogEventKind::kReconnect) ++figures.reconnects_marked;
    const std::string name(LogEventKindName(row.kind));
    if (name != "led_on" && name != "led_off" && name != "note") continue;
    ++event_rows;
    const auto it = events.find({row.device_time_ns, name});
    if (it != events.end() && it->second->intact && (name != "note" || row.detail == "PONG -42")) {
      ++found_events;
    } else {
      ++figures.corrupted_accepted;
    }
  }
  int64_t intact_samples = 0, intact_events = 0;
  for (const auto& [t, sent] : samples) intact_samples += sent->intact ? 1 : 0;
  for (const auto& [key, sent] : events) intact_events += sent->intact ? 1 : 0;
  // headers make no row: what the capture accepted beyond the rows
  const int64_t accepted_headers =
      figures.kept - static_cast<int64_t>(log.samples.size()) - event_rows;
  figures.corrupted_accepted += std::max<int64_t>(0, accepted_headers - intact_headers);
  figures.lost_outside_windows = (intact_samples - found_samples) +
                                 (intact_events - found_events) +
                                 std::max<int64_t>(0, intact_headers - accepted_headers);
}

Figures Soak(const std::filesystem::path& dir) {
  Figures figures;
  const Calibration calibration = bench::ShippedCalibration();
  const std::filesystem::path link = dir / "controller";
  std::atomic<int64_t> captured_bytes{0};
  std::atomic<bool> stop{false};
  CaptureOptions options;
  options.port = link.string();
  options.log_path = dir / "soak.csv";
  options.stop_on_test_end = false;
  options.status_interval_s = 0.01;
  options.replace_existing = true;
  Result<CaptureSummary> summary = InvalidArgumentError("capture did not run");

  const int64_t start_ns = MonotonicNowNs();
  std::vector<Sent> frames;
  std::string problem;
  {
    // the capture needs the link to start: the controller makes it first
    std::thread controller(
        [&] { frames = Controller(link, captured_bytes, problem, figures.stalled_at_frame); });
    while (!std::filesystem::is_symlink(link) && problem.empty()) std::this_thread::sleep_for(1ms);
    std::thread capture([&] {
      summary = RunCapture(options, calibration, stop, [&](const CaptureStatus& status) {
        captured_bytes.store(status.bytes);
      });
    });
    controller.join();
    stop = true;
    capture.join();
  }
  figures.wall_s = SecondsFromNs(MonotonicNowNs() - start_ns);
  if (!problem.empty()) {
    figures.problem = problem;
    return figures;
  }
  if (!summary.ok()) {
    figures.problem = summary.status().ToString();
    return figures;
  }
  figures.kept = summary->frames;
  figures.missing_reported = summary->missing_frames;

  auto log = ReadControllerLog(options.log_path);
  if (!log.ok()) {
    figures.problem = log.status().ToString();
    return figures;
  }
  Compare(frames, *log, figures);

  // the journal replayed: the same rows, byte for byte
  auto replay = ReplayJournal(options.JournalPath(), calibration);
  if (replay.ok() && WriteControllerLog(dir / "replay.csv", replay->log).ok()) {
    figures.replay_rows_differing = DifferingLines(Rows(options.log_path), Rows(dir / "replay.csv"));
  }
  return figures;
}

void BM_CaptureSoak(benchmark::State& state) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("liftoff-capture-soak-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  Figures figures;
  for (auto _ : state) figures = Soak(dir);
  std::filesystem::remove_all(dir);
  if (!figures.problem.empty()) {
    state.SkipWithError(figures.problem.c_str());
    return;
  }
  state.counters["frames_sent"] = static_cast<double>(figures.sent);
  state.counters["frames_kept"] = static_cast<double>(figures.kept);
  state.counters["lost_outside_unplugs"] = static_cast<double>(figures.lost_outside_windows);
  state.counters["corrupted_accepted"] = static_cast<double>(figures.corrupted_accepted);
  state.counters["reconnects_marked"] = static_cast<double>(figures.reconnects_marked);
  std::printf(
      "capture soak: %lld frames sent (%lld while unplugged, %lld with a corrupted byte)\n"
      "  kept (accepted by the capture): %lld\n"
      "  intact frames lost outside the unplug windows: %lld (must be 0)\n"
      "  corrupted frames accepted: %lld (must be 0)\n"
      "  reconnects marked: %lld of %d unplugs (5 shorter than a second, link re-created)\n"
      "  frames missing by the log's gaps: %lld (truth: %lld)\n"
      "  replay rows differing from the live log: %lld\n"
      "  wall time: %.1f s (%.0f frames/s, unplugged time included)\n%s",
      static_cast<long long>(figures.sent), static_cast<long long>(figures.sent_in_windows),
      static_cast<long long>(figures.corrupted), static_cast<long long>(figures.kept),
      static_cast<long long>(figures.lost_outside_windows),
      static_cast<long long>(figures.corrupted_accepted),
      static_cast<long long>(figures.reconnects_marked), kUnplugs,
      static_cast<long long>(figures.missing_reported),
      static_cast<long long>(figures.missing_expected),
      static_cast<long long>(figures.replay_rows_differing), figures.wall_s,
      static_cast<double>(figures.sent) / figures.wall_s,
      figures.stalled_at_frame < 0
          ? ""
          : ("  the capture stopped reading at frame " + std::to_string(figures.stalled_at_frame) +
             " (never reconnected): the controller stopped sending\n")
                .c_str());
}
BENCHMARK(BM_CaptureSoak)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
