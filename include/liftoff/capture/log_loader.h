// One entry point for reading a trial's controller log, whatever its format.
#pragma once

#include <filesystem>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"

namespace liftoff::capture {

/// Reads `path` as `format` (liftoff's own format or an importable older one). Angles
/// missing from the file but derivable from raw counts or shaft angles are filled in
/// through `calibration` (a liftoff log that carries counts but no vertebra angle, say):
/// rotate_shaft_rad from rotate_counts, vertebra_rad from rotate_shaft_rad, bend_spool_rad
/// from bend_counts; angles present in the file are kept. Errors are the reader's, and
/// always name the file.
/// A LogFormat::kCsv log needs its columns: kInvalidArgument (read it with LoadTrialLog).
Result<ControllerLog> LoadControllerLog(const std::filesystem::path& path, LogFormat format,
                                        const Calibration& calibration,
                                        const LogReadOptions& options = {});

/// A manifest trial's log: LoadControllerLog with the trial's format, or ReadCsvLog with
/// its columns (angles filled in the same way).
Result<ControllerLog> LoadTrialLog(const TrialRecord& trial, const Calibration& calibration,
                                   const LogReadOptions& options = {});

}  // namespace liftoff::capture
