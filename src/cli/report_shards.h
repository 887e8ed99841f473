// `liftoff report --shard i/n` and `liftoff report --merge SHARD...` (docs/cluster.md): a
// campaign's trial analysis and the calibration's Monte Carlo cut into n deterministic
// shares (ShardSpec), each written to a shard file, and the shard files merged back into
// exactly what one run gives.
//
// A shard file (JSON, format "liftoff-report-shard", version 1) holds the fingerprint of
// the inputs and options (manifest, calibration, lookup, model, sweep, fit and Monte
// Carlo options, software version), the shard's index and count, each of its trials'
// outcomes (status, measurement, log report, video analysis, the notes printed about it)
// and its Monte Carlo draws' simulated values. What of a trial's video analysis is
// carried: TrialOutcomeToJson / TrialOutcomeFromJson in report_shards.cc, the one place a
// field the report newly reads must be added (the sharded-run test compares the merged
// report with the single run's byte for byte, so a forgotten field shows there).
#pragma once

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "cli_common.h"
#include "liftoff/cli/report_command.h"
#include "liftoff/fit/tension_fit.h"

namespace liftoff::cli {

/// One trial in a shard file: its manifest index and id, status, measurement, log report,
/// video analysis (all of video::ClipAnalysis, the foot's per-frame trace included) and
/// the notes printed about it. The trial's record is not carried: the merge takes it from
/// its own manifest.
nlohmann::json TrialOutcomeToJson(size_t index, const sync::TrialOutcome& outcome,
                                  const std::vector<std::string>& notes);
/// The same back into `outcome` (its record left as it is) and `notes`; throws
/// nlohmann::json::exception or std::out_of_range for a damaged entry.
void TrialOutcomeFromJson(const nlohmann::json& entry, sync::TrialOutcome& outcome,
                          std::vector<std::string>& notes);

/// The command's --shard (1/1 when not given); kInvalidArgument naming the flag for a bad
/// one, or for --shard with --merge.
Result<ShardSpec> ReportShardFlags(const ReportCommand& command);

/// The report's trials: analysed here, --jobs at a time (all of them, or the shard's),
/// or, with --merge, read from the shard files (their Monte Carlo draws into
/// `monte_carlo`). Each trial's notes go to `err`, in manifest order, either way.
Result<CampaignAnalysis> CampaignForReport(const ReportCommand& command, const ShardSpec& shard,
                                           std::vector<fit::TensionSample>& monte_carlo,
                                           std::ostream& err);

/// A shard's run after its trials: its Monte Carlo draws simulated, its shard file
/// written to DIR (ShardFilePath), one line about it on `out`.
Status RunReportShard(const ReportCommand& command, const ShardSpec& shard,
                      const CampaignAnalysis& campaign, std::ostream& out, std::ostream& err);

/// The shard file of shard `shard` in `dir`: DIR/shard-2-of-4.json.
std::filesystem::path ShardFilePath(const std::filesystem::path& dir, const ShardSpec& shard);

/// What the report's results depend on, hashed (16 hex digits): the manifest's trials,
/// the calibration, the lookup options, and with the simulation the model file's bytes,
/// the experiment, feet, tensions, ramp, fit and Monte Carlo options; the version.
Result<std::string> ReportFingerprint(const ReportCommand& command,
                                      const CampaignAnalysis& campaign);

/// The Monte Carlo draws `shard` holds (draw k, from 0, when k % n == i - 1; the draws are
/// the same whatever n: fit::MonteCarloDraws seeds each by its index), simulated. `draws`
/// receives their indices.
Result<std::vector<fit::TensionSample>> SimulateShardDraws(const ReportCommand& command,
                                                           const Calibration& calibration,
                                                           const ShardSpec& shard,
                                                           std::vector<size_t>& draws);

/// Writes the shard file of `campaign` (a shard's trials) and its Monte Carlo `samples`
/// (draw indices `draws`) to `path`.
Status WriteReportShard(const std::filesystem::path& path, const ShardSpec& shard,
                        const std::string& fingerprint, const CampaignAnalysis& campaign,
                        const std::vector<size_t>& draws,
                        const std::vector<fit::TensionSample>& samples);

/// The shard files merged into `campaign` (loaded with no trial analysed: its manifest
/// and calibration): every trial's outcome and notes in manifest order, first_failure as
/// one run sets it; and the Monte Carlo's samples in draw order into `monte_carlo`.
/// kInvalidArgument naming the file for a shard made from other inputs or options
/// (`fingerprint` differs), of another count, a duplicate, a missing shard, or a file
/// whose trials or draws are not the ones its index holds; kParse for a damaged file.
Status MergeReportShards(const std::vector<std::filesystem::path>& paths,
                         const std::string& fingerprint, int monte_carlo_samples,
                         CampaignAnalysis& campaign,
                         std::vector<fit::TensionSample>& monte_carlo);

}  // namespace liftoff::cli
