// A user's own controller log: a plain CSV file whose columns the manifest names
// (CsvLogColumns, docs/formats.md "CSV logs").
#pragma once

#include <filesystem>

#include "liftoff/core/controller_log.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"

namespace liftoff::capture {

/// Reads `path` as a CSV log with `columns`. The first non-blank line is the header: names
/// separated by commas (surrounding blanks and double quotes ignored); every later
/// non-blank line is a sample, its fields in the header's order (other columns ignored).
/// Times are decimal numbers of `time_unit`, read exactly, and must increase: a line whose
/// time does not, or that does not parse, is a bad line (skipped and reported within
/// options.max_bad_lines); a last line cut off by the end of the file is tolerated. An angle
/// in "counts" must be a whole number (the rotating motor's encoder counts; LoadTrialLog
/// turns it into the vertebra's angle through the calibration). The LED switch-on is a
/// kLedOn event at `led_on_s`, or the first rise of `led_column`. kNotFound for a missing
/// file; kParse "file:line: ..." for a missing column, too many bad lines or no samples.
Result<ControllerLog> ReadCsvLog(const std::filesystem::path& path, const CsvLogColumns& columns,
                                 const LogReadOptions& options = {});

}  // namespace liftoff::capture
