// What the benchmarks share.
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>

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

}  // namespace liftoff::bench
