// What the benchmarks share.
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"

namespace liftoff::bench {

/// The shipped calibration (calib/laika-2018.json); exits when it is missing, since a
/// benchmark without it measures nothing worth quoting.
inline Calibration ShippedCalibration() {
  auto calibration = LoadCalibration(DefaultCalibrationPath());
  if (!calibration.ok()) {
    std::fprintf(stderr, "%s\n", calibration.status().ToString().c_str());
    std::exit(1);
  }
  return *calibration;
}

/// Waits for the forked `child` and returns its peak resident memory, KiB; -1 when the fork
/// failed or the child did not exit with status 0.
inline long WaitForPeakKib(pid_t child) {
  int status = 0;
  rusage usage{};
  if (child < 0 || ::wait4(child, &status, 0, &usage) != child || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0) {
    return -1;
  }
  return usage.ru_maxrss;
}

/// This process' peak resident memory, KiB: VmHWM of /proc/self/status, which starts at
/// the process' exec (-1 where unreadable).
inline long OwnPeakKib() {
  std::FILE* status = std::fopen("/proc/self/status", "r");
  if (status == nullptr) return -1;
  char line[256];
  long kib = -1;
  while (std::fgets(line, sizeof line, status) != nullptr) {
    if (std::sscanf(line, "VmHWM: %ld kB", &kib) == 1) break;
  }
  std::fclose(status);
  return kib;
}

/// Runs `args` (args[0] the program) in a child process whose standard output comes back
/// through a pipe, and returns N from its line "peak_kib N" (its OwnPeakKib()); -1 when it
/// failed or printed none.
inline long ChildReportedPeakKib(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  std::fflush(stdout);
  const pid_t child = ::fork();
  if (child == 0) {
    ::dup2(fds[1], STDOUT_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  std::string output;
  char buffer[256];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) {
    output.append(buffer, static_cast<size_t>(n));
  }
  ::close(fds[0]);
  if (WaitForPeakKib(child) < 0) return -1;
  const size_t at = output.rfind("peak_kib ");
  return at == std::string::npos ? -1 : std::atol(output.c_str() + at + 9);
}

}  // namespace liftoff::bench
