// Importer for the 2018 Laika hardware data (the logs behind the paper's Table IV).
//
// A 2018 log is the controller's serial output as a laptop's terminal saved it: lines
// end in a bare CR (some files CR LF), each line `t_ms,value,` with t_ms the controller
// clock in milliseconds from the LED switch-on and value the rotating motor's
// output-shaft angle in radians (sign depends on direction); samples come in bursts
// (about 17 in 60 ms, then about 1 s of nothing); some files end in a truncated line.
// The folder also holds `foot lifting times from hw videos.csv`: three header lines, then
// `foot,test,LED-on time (s),liftoff time (s),difference (s)` read by eye from videos.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"

namespace liftoff::capture {

/// Reads one 2018 log into a ControllerLog: device_time_ns from t_ms, rotate_shaft_rad
/// from value, vertebra_rad through `calibration`; the header names the calibration and
/// the source file. Blank lines (from CR LF ends) are ignored; malformed lines are
/// skipped, counted and listed with their line numbers (see LogReadOptions). kNotFound,
/// kParse ("file:line: expected `t_ms,value,`, got ..."), kParse "no samples".
Result<ControllerLog> ImportLaika2018Log(const std::filesystem::path& path,
                                         const Calibration& calibration,
                                         const LogReadOptions& options = {});

/// Result of turning a 2018 folder into a trial manifest.
struct Laika2018FolderImport {
  /// One trial per CSV row (ids "A1".."D5"), logs as laika-2018 format, times from the
  /// CSV with uncertainty = half a unit of the last printed digit plus one 30 fps frame.
  TrialManifest manifest;
  /// Things a person should know: rows whose difference column disagrees with
  /// liftoff - LED-on by more than 1 ms, logs missing for a row, ...
  std::vector<std::string> warnings;
};

/// Reads `folder` (the logs and the times CSV) and builds the manifest that would be
/// written at `manifest_path` (paths inside are relative to its folder). The pulled group
/// and rotation direction of each foot follow the paper's Table II by foot letter
/// (A: HR +, B: HR -, C: HL +, D: HL -); see docs/formats.md. kNotFound when the folder
/// or the CSV is missing, kParse "csv:line: ..." for a malformed row.
Result<Laika2018FolderImport> ImportLaika2018Folder(const std::filesystem::path& folder,
                                                    const std::filesystem::path& manifest_path);

/// Name of the CSV of hand-measured times inside a 2018 folder.
inline constexpr const char* kLaika2018TimesCsv = "foot lifting times from hw videos.csv";

}  // namespace liftoff::capture
