// What the benchmarks share.
#pragma once

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

}  // namespace liftoff::bench
