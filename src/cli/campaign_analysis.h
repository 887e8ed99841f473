// A campaign's trials analysed on the machine's cores (`liftoff report --jobs`), or one
// shard of them (`--shard i/n`), with one progress display for the whole campaign.
// Results come back in manifest order and are the same whatever the number of jobs or
// shards: each trial is analysed alone (sync::AnalyzeManifestTrial).
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/sync/trial_analysis.h"

namespace liftoff::cli {

/// Shard `index` of `count` (1 <= index <= count): the items i (0-based: trials in
/// manifest order, Monte Carlo draws) with i % count == index - 1. 1/1 is everything.
struct ShardSpec {
  int index = 1;
  int count = 1;

  bool whole() const { return count == 1; }
  bool Holds(size_t item) const {
    return item % static_cast<size_t>(count) == static_cast<size_t>(index - 1);
  }
  /// "2/4".
  std::string Name() const;
};

/// Most shards a run may be cut into.
inline constexpr int kMaxShards = 100000;

/// "i/n" with 1 <= i <= n <= kMaxShards; kInvalidArgument naming `flag` otherwise:
/// "--shard: expected i/n with 1 <= i <= n <= 100000, got \"5/4\"".
Result<ShardSpec> ParseShard(std::string_view text, std::string_view flag);

/// How a campaign's trials are run.
struct CampaignRun {
  /// Progress on stderr: auto, live, lines or off.
  std::string progress = "auto";
  /// Trials analysed at once (1 .. 1024; 0: the machine's cores). With more than one
  /// at a time, each clip's decoder gets its share of the cores.
  int jobs = 1;
  /// The trials analysed: those this shard holds.
  ShardSpec shard;
};

/// The number of trials analysed at once for `jobs` (0: the machine's cores) and
/// `trials` to analyse: at least 1, at most `trials`.
int JobsFor(int jobs, size_t trials);

/// The trials of `manifest` that `run.shard` holds, analysed `run.jobs` at a time, with
/// one progress line for them all on `err`. `indices` receives each outcome's manifest
/// index; outcomes are in manifest order. kInvalidArgument for a bad --progress or --jobs.
Result<std::vector<sync::TrialOutcome>> AnalyzeTrials(const TrialManifest& manifest,
                                                      const Calibration& calibration,
                                                      sync::AnalysisOptions options,
                                                      const CampaignRun& run,
                                                      std::vector<size_t>& indices,
                                                      std::ostream& err);

}  // namespace liftoff::cli
