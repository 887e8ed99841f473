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

/// Reads one 2018 log into a ControllerLog: device_time_ns from t_ms (parsed exactly),
/// rotate_shaft_rad from value, vertebra_rad through `calibration`; the header names the
/// calibration and the source ("import laika-2018 <file name>"). Lines end in CR, CR LF or
/// LF (line numbers count CR LF as one end, as an editor does); blank lines are ignored
/// and not counted. A line is `<t_ms>,<value>,` with the trailing comma optional.
/// Malformed lines and samples whose time does not increase (counted as out_of_order
/// too) are skipped, counted and listed with their line numbers (see LogReadOptions).
/// A malformed last non-blank line (the real files end in a stray "1074.33"), or an
/// unended last line lacking the trailing comma the earlier lines carry, is a truncated
/// last line: always tolerated, reported, and not counted against max_bad_lines.
/// Errors: kInvalidArgument for bad options, kNotFound for a missing file, kParse
/// "file:line: expected `t_ms,value,`, got \"...\" (N bad lines, M allowed by
/// max_bad_lines)" naming the first bad line, kParse "file: no samples (...)".
Result<ControllerLog> ImportLaika2018Log(const std::filesystem::path& path,
                                         const Calibration& calibration,
                                         const LogReadOptions& options = {});

/// Result of turning a 2018 folder into a trial manifest.
struct Laika2018FolderImport {
  /// One trial per CSV row, in row order (ids "A1".."D5"), logs (absolute paths) in
  /// laika-2018 format, times from the CSV parsed exactly, source "hand (2018 video, by
  /// eye)". Uncertainty of each time = half a unit of its column's last printed digit
  /// plus one 30 fps frame (1/30 s); a column's last digit is the finest printed anywhere
  /// in it, because the spreadsheet dropped trailing zeros ("10" for 10.00).
  TrialManifest manifest;
  /// Things a person should know, each naming the trial or file: rows whose difference
  /// column disagrees with liftoff - LED-on by more than 1 ms, logs missing for a row,
  /// `Test*.txt` logs no row names.
  std::vector<std::string> warnings;
};

/// Reads `folder` (the logs and the times CSV) and builds the manifest that would be
/// written at `manifest_path` (paths inside are relative to its folder). The pulled group
/// and rotation direction of each foot follow the paper's Table II by foot letter
/// (A: HR +, B: HR -, C: HL +, D: HL -), noted in each TrialRecord::notes; see
/// docs/formats.md for why that mapping is unverified. The manifest's base_dir is
/// manifest_path's folder. kNotFound when the folder or the CSV is missing; kParse
/// "csv:line: ..." for a column header without "Foot", a malformed row (naming the column),
/// liftoff not after LED-on, a repeated foot and test, or no rows.
Result<Laika2018FolderImport> ImportLaika2018Folder(const std::filesystem::path& folder,
                                                    const std::filesystem::path& manifest_path);

/// Name of the CSV of hand-measured times inside a 2018 folder.
inline constexpr const char* kLaika2018TimesCsv = "foot lifting times from hw videos.csv";

}  // namespace liftoff::capture
