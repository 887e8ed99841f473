// Peak memory of `liftoff log` and `liftoff sync` on a long liftoff-format log, against
// the file's size (issue 12 asks for under 2x), the samples' own floor (lines x
// sizeof(LogSample)) and a one-sample log: how much of the peak is the representation and
// how much the program. Usage: log_memory_bench [lines [lean]]   (default 10,000,000
// lines, 0.6 GB; "lean": no host time and no bending counts, 0.4 GB, the shape of issue
// 12's 435 MB log)
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_support.h"
#include "liftoff/core/controller_log.h"

namespace {

namespace fs = std::filesystem;

// A 1 kHz capture: device and host times, sequence, LED, both encoders and the angles the
// capture writes, one sample a line, the LED event after the first second.
void WriteLog(const fs::path& path, long long lines, bool lean) {
  std::ofstream out(path, std::ios::binary);
  out << "# liftoff-log 1\n"
         "device_time_ns,host_time_ns,seq,led,bend_counts,rotate_counts,bend_spool_rad,"
         "rotate_shaft_rad,vertebra_rad,event,detail\n";
  std::string line;
  for (long long i = 0; i < lines; ++i) {
    const long long t_ns = i * 1'000'000;
    const std::string host = lean ? "" : std::to_string(1'700'000'000'000'000'000LL + t_ns);
    line = std::to_string(t_ns) + "," + host + "," + std::to_string(i % 4'294'967'296LL) + "," +
           (i >= 1000 ? "1" : "0") + (lean ? ",," : ",4000,") + std::to_string(i / 3) +
           ",,,,,\n";
    if (i == 1000) line += std::to_string(t_ns) + ",,,,,,,,,led_on,\n";
    out << line;
  }
}

// The peak resident memory of `liftoff <arguments>`, bytes; -1 when it failed. (A child's
// ru_maxrss is the larger of its own peak and the pages it shared with this process at the
// fork, before its exec: exact whenever above this process' own peak, which main prints.)
long long PeakRssBytes(const std::vector<std::string>& arguments) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(LIFTOFF_BINARY));
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  std::fflush(stdout);
  const pid_t child = ::fork();
  if (child == 0) {
    std::freopen("/dev/null", "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    ::execv(LIFTOFF_BINARY, argv.data());
    ::_exit(127);
  }
  const long peak_kib = liftoff::bench::WaitForPeakKib(child);
  return peak_kib < 0 ? -1 : static_cast<long long>(peak_kib) * 1024;
}

double Mb(long long bytes) { return static_cast<double>(bytes) / 1e6; }

}  // namespace

int main(int argc, char** argv) {
  const long long lines = argc > 1 ? std::atoll(argv[1]) : 10'000'000;
  const bool lean = argc > 2 && std::string(argv[2]) == "lean";
  const fs::path path =
      fs::temp_directory_path() / ("liftoff-log-memory-" + std::to_string(::getpid()) + ".csv");
  WriteLog(path, lines, lean);
  const auto file_bytes = static_cast<long long>(fs::file_size(path));
  const long long floor_bytes = lines * static_cast<long long>(sizeof(liftoff::LogSample));
  std::printf("log: %lld lines, %.1f MB; samples' floor %lld x %zu B = %.1f MB (%.2fx the file)\n",
              lines, Mb(file_bytes), lines, sizeof(liftoff::LogSample), Mb(floor_bytes),
              static_cast<double>(floor_bytes) / static_cast<double>(file_bytes));
  const struct {
    const char* name;
    std::vector<std::string> arguments;
  } commands[] = {
      {"liftoff log", {"log", path.string()}},
      {"liftoff sync", {"sync", path.string(), "--led-on", "1", "--liftoff", "2"}},
  };
  // the program's own peak, on a one-sample log: the part of the peak that is not samples
  const fs::path tiny = path.string() + ".one.csv";
  WriteLog(tiny, 1, lean);
  const long long own = PeakRssBytes({"log", tiny.string()});
  fs::remove(tiny);
  if (own >= 0) std::printf("liftoff log   peak %.1f MB on a one-sample log\n", Mb(own));
  for (const auto& command : commands) {
    const long long peak = PeakRssBytes(command.arguments);
    if (peak < 0) {
      std::printf("%-13s failed\n", command.name);
      continue;
    }
    std::printf("%-13s peak %.1f MB = %.2fx the file\n", command.name, Mb(peak),
                static_cast<double>(peak) / static_cast<double>(file_bytes));
  }
  fs::remove(path);
  const long bench_kib = liftoff::bench::OwnPeakKib();
  std::printf("(this bench's own peak %.1f MB: a peak above it is the command's own)\n",
              Mb(static_cast<long long>(bench_kib) * 1024));
  return 0;
}
