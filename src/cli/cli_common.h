// Pieces the subcommands share: choosing the calibration, reading the lookup options,
// detecting a log's format, writing output files.
#pragma once

#include <filesystem>
#include <initializer_list>
#include <iosfwd>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "campaign_analysis.h"
#include "liftoff/cli/commands.h"
#include "liftoff/cli/flags.h"
#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/output.h"
#include "liftoff/stats/table.h"
#include "liftoff/sync/lookup.h"
#include "liftoff/sync/trial_analysis.h"

namespace liftoff::cli {

/// The calibration chosen by flag, else by the manifest (`manifest_choice`), else the
/// default one.
Result<Calibration> ChooseCalibration(const CalibrationChoice& choice,
                                      const std::filesystem::path& manifest_choice = {});

/// OK when `value` lies in `range`, else kInvalidArgument naming the flag and `unit`:
/// "--max-past-end: expected a number in [0, 1e+06] s, got 1e+10". For flags that are no
/// option struct's field (those are checked by the struct's Validate()).
Status CheckFlagRange(std::string_view flag, double value, const NumberRange& range,
                      std::string_view unit = "");

/// `status` from an option struct's Validate() with the field it names replaced by its
/// flag (`flag_fields`: {"--gap-threshold", "lookup options.gap_threshold_s"}, a context
/// written "lookup options: " matching "lookup options."); other statuses as they are.
Status NameFlagsIn(const Status& status,
                   std::initializer_list<std::pair<std::string, std::string>> flag_fields);

/// LogReadOptions' check of `--max-bad-lines` (>= 0), naming the flag.
Status CheckMaxBadLinesFlag(int64_t max_bad_lines);

/// sync::LookupOptions::Validate() naming --gap-threshold and --max-past-end.
Status CheckLookupFlags(const sync::LookupOptions& options);

/// A table command's --format; kInvalidArgument "--format: expected md, csv, latex or
/// json, got ..." for another word.
Result<stats::TableFormat> TableFormatFlag(const std::string& text);

/// --calibration (-c), bound to `choice`.
void AddCalibrationFlag(Command& app, CalibrationChoice& choice);
/// --rule, --gap-threshold, --max-past-end, --max-bad-lines, bound to `lookup`.
void AddLookupFlags(Command& app, LookupChoice& lookup);

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

/// A campaign's trials analysed the way `liftoff table` does.
struct CampaignAnalysis {
  TrialManifest manifest;
  Calibration calibration;
  /// The trials analysed (a shard's only: CampaignRun::shard), in manifest order.
  sync::ManifestAnalysis analysis;
  /// Per outcome, its trial's index in the manifest.
  std::vector<size_t> trial_indices;
  /// Per outcome, in the same order: the lines printed about it ("warning: ...",
  /// "note: ...", "error: ...").
  std::vector<std::vector<std::string>> notes;
  /// The first failed trial's status (OK when none failed).
  Status first_failure;
};

/// Loads the manifest (or 2018 folder) and the calibration (analysis.calibration and
/// analysis.rule set), analysing no trial.
Result<CampaignAnalysis> LoadCampaign(const std::filesystem::path& manifest_path,
                                      const CalibrationChoice& calibration_choice,
                                      const LookupChoice& lookup_choice, std::ostream& err);

/// Loads the manifest (or 2018 folder) and the calibration, and analyses every trial
/// that `run.shard` holds, `run.jobs` at a time (videos without times through video
/// analysis, one progress line on `err` in `run.progress`); then each trial's notes go to
/// `err`, in manifest order. A failing trial is a result, not an error: the error is for
/// bad options, manifest or calibration.
Result<CampaignAnalysis> AnalyzeCampaign(const std::filesystem::path& manifest_path,
                                         const CalibrationChoice& calibration_choice,
                                         const LookupChoice& lookup_choice, const CampaignRun& run,
                                         std::ostream& err);

/// The lines about one trial a person should see ("warning: ...", "note: ...", "error:
/// ..."): log warnings, the video's brief and warnings, the failure, the lookup's notes.
std::vector<std::string> OutcomeNotes(const sync::TrialOutcome& outcome);

/// 64-bit FNV-1a of `bytes` as 16 hex digits: a stable key across machines and runs (not
/// a security hash).
std::string HashHex(std::string_view bytes);

}  // namespace liftoff::cli
