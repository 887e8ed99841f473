#include "liftoff/capture/log_loader.h"

#include <cmath>

#include "liftoff/capture/laika2018.h"

namespace liftoff::capture {
namespace {

// Fills the angles a sample lacks from what it has: shaft and vertebra angles from the
// rotating motor's counts (or the vertebra angle from the shaft angle), the spool angle
// from the bending motor's counts.
void FillDerivedAngles(LogSample& sample, const Calibration& calibration) {
  if (std::isnan(sample.rotate_shaft_rad) && sample.rotate_counts) {
    sample.rotate_shaft_rad = calibration.ShaftAngleFromCounts(*sample.rotate_counts);
  }
  if (std::isnan(sample.vertebra_rad) && !std::isnan(sample.rotate_shaft_rad)) {
    sample.vertebra_rad = calibration.VertebraAngleFromShaftAngle(sample.rotate_shaft_rad);
  }
  if (std::isnan(sample.bend_spool_rad) && sample.bend_counts) {
    sample.bend_spool_rad =
        calibration.SpoolAngleFromShaftAngle(calibration.ShaftAngleFromCounts(*sample.bend_counts));
  }
}

}  // namespace

Result<ControllerLog> LoadControllerLog(const std::filesystem::path& path, LogFormat format,
                                        const Calibration& calibration,
                                        const LogReadOptions& options) {
  Result<ControllerLog> log = format == LogFormat::kLaika2018
                                  ? ImportLaika2018Log(path, calibration, options)
                                  : ReadControllerLog(path, options);
  if (!log.ok()) return log.status();  // both readers name the file in every error
  if (format == LogFormat::kLiftoff) {
    for (LogSample& sample : log->samples) FillDerivedAngles(sample, calibration);
  }
  return log;
}

}  // namespace liftoff::capture
