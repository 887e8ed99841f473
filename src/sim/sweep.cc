#include "liftoff/sim/sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::sim {
namespace {

constexpr int kMaxThreads = 1024;

size_t Index(int i) { return static_cast<size_t>(i); }

std::string RunName(Foot foot, const TensionPoint& tension) {
  return "run " + std::string(FootName(foot)) + " " + tension.name;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// options

SweepOptions::SweepOptions()
    : tension_points(PaperTensionPoints().begin(), PaperTensionPoints().end()) {}

Status SweepOptions::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(base.Validate().WithContext("base"));
  if (feet.empty()) return InvalidArgumentError("feet: expected at least one foot, got none");
  std::set<Foot> seen_feet;
  for (size_t f = 0; f < feet.size(); ++f) {
    if (!seen_feet.insert(feet[f]).second) {
      return InvalidArgumentError("feet/" + std::to_string(f) + ": foot " +
                                  std::string(FootName(feet[f])) + " appears twice");
    }
  }
  if (tension_points.empty()) {
    return InvalidArgumentError("tension_points: expected at least one, got none");
  }
  std::set<std::string> seen_points;
  for (size_t t = 0; t < tension_points.size(); ++t) {
    const std::string where = "tension_points/" + std::to_string(t);
    if (tension_points[t].name.empty()) {
      return InvalidArgumentError(where + "/name: expected a non-empty name");
    }
    if (!seen_points.insert(tension_points[t].name).second) {
      return InvalidArgumentError(where + "/name: \"" + tension_points[t].name +
                                  "\" appears twice");
    }
  }
  if (threads < 0 || threads > kMaxThreads) {
    return InvalidArgumentError("threads: expected an integer in [0, " +
                                std::to_string(kMaxThreads) + "], got " + std::to_string(threads));
  }
  RunControl control;
  control.progress_period_s = progress_period_s;
  return control.Validate();
}

// ---------------------------------------------------------------------------------------
// results

bool SweepRun::Stood() const {
  return result.status != RunStatus::kDidNotStand && result.status != RunStatus::kDiverged;
}

std::optional<double> SweepRun::LiftoffRad() const { return result.TargetLiftoffRad(); }

std::string SweepRun::Brief() const { return result.Brief(); }

const SweepRun* SweepResult::Find(Foot foot, std::string_view tension) const {
  for (const SweepRun& run : runs) {
    if (run.foot == foot && run.tension_point.name == tension) return &run;
  }
  return nullptr;
}

std::vector<SweepFootRange> SweepResult::Ranges() const {
  std::vector<SweepFootRange> ranges;
  for (Foot foot : feet) {
    SweepFootRange range;
    range.foot = foot;
    for (const SweepRun& run : runs) {
      if (run.foot != foot) continue;
      ++range.runs;
      if (run.result.status == RunStatus::kDiverged) ++range.diverged_runs;
      const std::optional<double> value = run.LiftoffRad();
      if (!value) continue;
      range.min_rad = range.counted_runs == 0 ? *value : std::min(range.min_rad, *value);
      range.max_rad = range.counted_runs == 0 ? *value : std::max(range.max_rad, *value);
      ++range.counted_runs;
    }
    ranges.push_back(range);
  }
  return ranges;
}

std::string SweepResult::Brief() const {
  const int stood = static_cast<int>(
      std::count_if(runs.begin(), runs.end(), [](const SweepRun& run) { return run.Stood(); }));
  std::ostringstream out;
  out << model_name << ": " << Plural(static_cast<int64_t>(runs.size()), "run") << " (" << stood
      << " stood)";
  for (const SweepFootRange& range : Ranges()) {
    out << ", " << FootName(range.foot) << " ";
    if (range.counted_runs == 0) {
      out << "-";
    } else {
      out << FormatFixed(range.min_rad, 3) << "-" << FormatFixed(range.max_rad, 3);
    }
  }
  out << " rad, " << Plural(threads, "thread");
  return out.str();
}

// ---------------------------------------------------------------------------------------
// the sweep

namespace {

// Every run's entry in `sweep` and its options, each checked against the model before any
// run starts.
Result<std::vector<ExperimentOptions>> PlanRuns(const ModelDescription& description,
                                                const SweepOptions& options, SweepResult& sweep) {
  std::vector<ExperimentOptions> run_options;
  for (Foot foot : options.feet) {
    for (size_t t = 0; t < options.tension_points.size(); ++t) {
      ExperimentOptions run = options.base;
      run.foot = foot;
      run.tension_point = options.tension_points[t];
      SweepRun& entry = sweep.runs.emplace_back();
      entry.index = static_cast<int>(sweep.runs.size() - 1);
      entry.foot = foot;
      entry.tension_index = static_cast<int>(t);
      entry.tension_point = options.tension_points[t];
      auto model = BuildExperimentModel(description, run);
      if (!model.ok()) return model.status().WithContext(RunName(foot, entry.tension_point));
      run_options.push_back(std::move(run));
    }
  }
  return run_options;
}

// The sweep's work queue: each worker takes the next run index; results land in their own
// slot, so the order and the values do not depend on the threads.
class SweepWorkers {
 public:
  SweepWorkers(const ModelDescription& description,
               const std::vector<ExperimentOptions>& run_options, const SweepOptions& options,
               const SweepProgressCallback& progress, SweepResult& sweep)
      : description_(description),
        run_options_(run_options),
        progress_(progress),
        sweep_(sweep),
        run_count_(static_cast<int>(sweep.runs.size())),
        failures_(Index(run_count_)),
        last_progress_(Index(run_count_)) {
    control_.progress_period_s = options.progress_period_s;
    control_.stop_once_decided = options.stop_once_decided;
  }

  // one worker: runs until the queue is empty
  void Work() {
    for (int i = next_run_.fetch_add(1); i < run_count_; i = next_run_.fetch_add(1)) {
      SweepRun& entry = sweep_.runs[Index(i)];
      auto on_progress = [&](const RunProgress& run_progress) {
        std::lock_guard<std::mutex> lock(report_mutex_);
        last_progress_[Index(i)] = run_progress;
        if (progress_) progress_(Report(i, run_progress));
      };
      auto result =
          RunExperimentWithProgress(description_, run_options_[Index(i)], control_, on_progress);
      std::lock_guard<std::mutex> lock(report_mutex_);
      ++runs_done_;
      if (!result.ok()) {
        failures_[Index(i)] = result.status().WithContext(RunName(entry.foot, entry.tension_point));
        continue;
      }
      entry.result = std::move(result).value();
      if (!progress_) continue;
      SweepProgress report = Report(i, last_progress_[Index(i)]);
      report.finished = &entry;
      progress_(report);
    }
  }

  // the first failure in run order (the same whatever the threads)
  Status FirstFailure() const {
    for (const Status& failure : failures_) {
      if (!failure.ok()) return failure;
    }
    return Status::Ok();
  }

 private:
  // called with report_mutex_ held
  SweepProgress Report(int i, const RunProgress& run) const {
    const SweepRun& entry = sweep_.runs[Index(i)];
    SweepProgress report;
    report.runs_done = runs_done_;
    report.runs_total = run_count_;
    report.run_index = i;
    report.foot = entry.foot;
    report.tension_point = &entry.tension_point;
    report.run = run;
    return report;
  }

  const ModelDescription& description_;
  const std::vector<ExperimentOptions>& run_options_;
  const SweepProgressCallback& progress_;
  SweepResult& sweep_;
  const int run_count_;
  RunControl control_;
  std::atomic<int> next_run_{0};
  std::mutex report_mutex_;  // serialises progress calls and the bookkeeping below
  int runs_done_ = 0;
  std::vector<Status> failures_;
  std::vector<RunProgress> last_progress_;
};

}  // namespace

Result<SweepResult> RunSweep(const ModelDescription& description, const SweepOptions& options,
                             const SweepProgressCallback& progress) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  SweepResult sweep;
  sweep.model_name = description.name;
  sweep.tension_points = options.tension_points;
  sweep.feet = options.feet;
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<ExperimentOptions> run_options,
                           PlanRuns(description, options, sweep));

  // the threads: as asked, else the machine's, never more than the runs
  const int run_count = static_cast<int>(sweep.runs.size());
  const int available = options.threads > 0
                            ? options.threads
                            : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  sweep.threads = std::min(available, run_count);

  SweepWorkers workers(description, run_options, options, progress, sweep);
  std::vector<std::thread> helpers;
  for (int t = 1; t < sweep.threads; ++t) helpers.emplace_back([&workers] { workers.Work(); });
  workers.Work();
  for (std::thread& helper : helpers) helper.join();
  LIFTOFF_RETURN_IF_ERROR(workers.FirstFailure());
  return sweep;
}

Result<TensionPoint> PaperTensionPointByName(std::string_view name) {
  const auto& points = PaperTensionPoints();
  for (size_t i = 0; i < points.size(); ++i) {
    if (name == points[i].name || name == std::to_string(i)) return points[i];
  }
  return InvalidArgumentError(
      "tension point: expected low, med-low, mean, med-high, high or an index 0..4, got \"" +
      std::string(name) + "\"");
}

}  // namespace liftoff::sim
