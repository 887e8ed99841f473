// Pieces the subcommands share: choosing the calibration, reading the lookup options,
// detecting a log's format, writing output files.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>

#include "liftoff/cli/commands.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/output.h"
#include "liftoff/sync/lookup.h"

namespace liftoff::cli {

/// The calibration chosen by flag, else by the manifest (`manifest_choice`), else the
/// default one.
Result<Calibration> ChooseCalibration(const CalibrationChoice& choice,
                                      const std::filesystem::path& manifest_choice = {});

/// OK when `value_s` lies in `range`, else kInvalidArgument naming the flag:
/// "--max-past-end: expected a number in [0, 1e+06] s, got 1e+10".
Status CheckSecondsFlag(std::string_view flag, double value_s, const NumberRange& range);

/// OK when `--max-bad-lines` is >= 0, else kInvalidArgument naming the flag.
Status CheckMaxBadLinesFlag(int64_t max_bad_lines);

/// LookupChoice as validated sync::LookupOptions (kInvalidArgument naming the flag).
Result<sync::LookupOptions> LookupOptionsFrom(const LookupChoice& choice);

/// Reads a log whose format is "auto", "liftoff" or "laika-2018"; "auto" asks
/// DetectLogFormat (liftoff logs start with "# liftoff-log", after an optional BOM).
Result<ControllerLog> LoadLogByName(const std::filesystem::path& path, const std::string& format,
                                    const Calibration& calibration, const LogReadOptions& options);

/// A manifest file, or a 2018 Laika folder imported on the fly (warnings to `err`).
Result<TrialManifest> LoadTrials(const std::filesystem::path& path, std::ostream& err);

/// The files a manifest's trials read, each named for messages: every trial's log
/// ("trial T1's log") and video, and the manifest's calibration.
std::vector<NamedPath> TrialInputs(const TrialManifest& manifest);

/// The output policy (liftoff/core/output.h) at a command's edge: prints the error of
/// CheckOutputsAreNotInputs and returns its exit code; kExitOk when no output is an input.
int RefuseToOverwriteInputs(const std::vector<NamedPath>& outputs,
                            const std::vector<NamedPath>& inputs, std::ostream& err);

/// Prints each line of a log's read report that a person should see ("warning: ...").
void PrintLogWarnings(const LogReadReport& report, std::ostream& err);

}  // namespace liftoff::cli
