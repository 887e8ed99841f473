#include "liftoff/capture/log_loader.h"

#include <cmath>

#include "liftoff/capture/csv_log.h"
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
  if (format == LogFormat::kCsv) {
    return InvalidArgumentError(path.string() +
                                ": a CSV log is read through a manifest that names its columns "
                                "(docs/formats.md, CSV logs)");
  }
  Result<ControllerLog> log = format == LogFormat::kLaika2018
                                  ? ImportLaika2018Log(path, calibration, options)
                                  : ReadControllerLog(path, options);
  if (!log.ok()) return log.status();  // both readers name the file in every error
  if (format == LogFormat::kLiftoff) {
    for (LogSample& sample : log->samples) FillDerivedAngles(sample, calibration);
  }
  return log;
}

Result<ControllerLog> LoadTrialLog(const TrialRecord& trial, const Calibration& calibration,
                                   const LogReadOptions& options) {
  if (trial.log_format != LogFormat::kCsv) {
    return LoadControllerLog(trial.log_path, trial.log_format, calibration, options);
  }
  if (!trial.log_columns) {
    return InvalidArgumentError("trial " + trial.id + ": a CSV log needs its columns");
  }
  Result<ControllerLog> log = ReadCsvLog(trial.log_path, *trial.log_columns, options);
  if (!log.ok()) return log.status();
  log->header.calibration = calibration.name;
  for (LogSample& sample : log->samples) FillDerivedAngles(sample, calibration);
  return log;
}

}  // namespace liftoff::capture
