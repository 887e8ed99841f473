#include "campaign_analysis.h"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <functional>
#include <map>
#include <mutex>
#include <ostream>
#include <thread>

#include "liftoff/cli/progress_line.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"

namespace liftoff::cli {
namespace {

// A whole number and nothing else ("4", not "4x" or "+4").
bool ParseWhole(std::string_view text, int& value) {
  if (text.empty() || text.front() < '0' || text.front() > '9') return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// One line for the whole campaign: trials done, the clips being analysed (the first few
// named) and the frames per second over all of them. Called from the workers' threads.
class CampaignProgress {
 public:
  static constexpr size_t kListedClips = 3;

  CampaignProgress(ProgressLine line, size_t trials)
      : line_(std::move(line)), trials_(trials), started_ns_(MonotonicNowNs()) {}

  void Frame(const std::string& trial, int64_t frames_done) {
    if (line_.off()) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    int64_t& frames = running_[trial];
    frames_ += frames_done - frames;
    frames = frames_done;
    if (line_.Due()) ShowLocked();
  }

  void TrialDone(const std::string& trial) {
    if (line_.off()) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    running_.erase(trial);
    ++done_;
    if (line_.Due()) ShowLocked();
  }

  void Done() { line_.Clear(); }

 private:
  void ShowLocked() {
    const double wall_s = std::max(SecondsFromNs(MonotonicNowNs() - started_ns_), 1e-3);
    std::string text =
        std::to_string(done_) + " of " + Plural(static_cast<int64_t>(trials_), "trial") + " done";
    if (!running_.empty()) text += ", analysing";
    size_t listed = 0;
    for (const auto& [trial, frames] : running_) {
      if (++listed > kListedClips) break;
      text += " " + trial + " (frame " + std::to_string(frames) + ")";
    }
    if (running_.size() > kListedClips) {
      text += " and " + std::to_string(running_.size() - kListedClips) + " more";
    }
    text += ", " + std::to_string(frames_) + " frames, " +
            FormatFixed(static_cast<double>(frames_) / wall_s, 0) + " frames/s";
    line_.Show(text);
  }

  ProgressLine line_;
  size_t trials_;
  int64_t started_ns_;
  std::mutex mutex_;
  std::map<std::string, int64_t> running_;
  int64_t frames_ = 0;
  size_t done_ = 0;
};

// each worker takes the next trial until none is left
void RunWorkers(int jobs, size_t count, const std::function<void(size_t)>& work) {
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < count; i = next++) work(i);
  };
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
  worker();
  for (std::thread& thread : threads) thread.join();
}

}  // namespace

std::string ShardSpec::Name() const { return std::to_string(index) + "/" + std::to_string(count); }

Result<ShardSpec> ParseShard(std::string_view text, std::string_view flag) {
  const size_t slash = text.find('/');
  ShardSpec shard;
  if (slash == std::string_view::npos || !ParseWhole(text.substr(0, slash), shard.index) ||
      !ParseWhole(text.substr(slash + 1), shard.count) || shard.index < 1 ||
      shard.count < shard.index || shard.count > kMaxShards) {
    return InvalidArgumentError(std::string(flag) + ": expected i/n with 1 <= i <= n <= " +
                                std::to_string(kMaxShards) + ", got \"" + std::string(text) +
                                "\"");
  }
  return shard;
}

int JobsFor(int jobs, size_t trials) {
  const size_t wanted = jobs > 0 ? static_cast<size_t>(jobs)
                                 : std::max(1u, std::thread::hardware_concurrency());
  return static_cast<int>(std::clamp<size_t>(std::min(wanted, trials), 1, 1024));
}

Result<std::vector<sync::TrialOutcome>> AnalyzeTrials(const TrialManifest& manifest,
                                                      const Calibration& calibration,
                                                      sync::AnalysisOptions options,
                                                      const CampaignRun& run,
                                                      std::vector<size_t>& indices,
                                                      std::ostream& err) {
  if (run.jobs < 0 || run.jobs > 1024) {
    return InvalidArgumentError("--jobs: expected an integer in [0, 1024], got " +
                                std::to_string(run.jobs));
  }
  LIFTOFF_ASSIGN_OR_RETURN(ProgressLine line,
                           ProgressLine::Create(run.progress, "--progress", "video", err));
  indices.clear();
  for (size_t i = 0; i < manifest.trials.size(); ++i) {
    if (run.shard.Holds(i)) indices.push_back(i);
  }
  // clips decoded at once share the cores: each decoder gets its share
  const int jobs = JobsFor(run.jobs, indices.size());
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (jobs > 1) options.video.reader.decoder_threads = std::max(1, cores / jobs);

  CampaignProgress progress(std::move(line), indices.size());
  options.video_progress = [&](const TrialRecord& trial, int64_t frames_done, int64_t) {
    progress.Frame(trial.id, frames_done);
  };
  std::vector<sync::TrialOutcome> outcomes(indices.size());
  RunWorkers(jobs, indices.size(), [&](size_t i) {
    outcomes[i] = sync::AnalyzeManifestTrial(manifest, calibration, options, indices[i]);
    progress.TrialDone(outcomes[i].trial.id);
  });
  progress.Done();
  return outcomes;
}

}  // namespace liftoff::cli
