#include "liftoff/sync/trial_analysis.h"

#include <algorithm>

#include "liftoff/capture/log_loader.h"

namespace liftoff::sync {
namespace {

// the error with the trial id in front
Status ForTrial(const Status& status, const TrialRecord& trial) {
  return status.WithContext(trial.id);
}

// one trial, start to end
Status AnalyzeTrial(const TrialManifest& manifest, const Calibration& calibration,
                    const AnalysisOptions& options, TrialOutcome& outcome) {
  const TrialRecord& trial = outcome.trial;
  // hand times are the only source of event times for now
  if (!trial.times) {
    if (trial.video_path) {
      return ForTrial(UnsupportedError(trial.video_path->string() +
                                       ": automatic video analysis is not available yet; "
                                       "give hand times"),
                      trial);
    }
    const std::string manifest_name =
        manifest.source_path.empty() ? "manifest" : manifest.source_path.string();
    return ForTrial(
        InvalidArgumentError(manifest_name + ": the trial has neither event times nor a video; "
                                             "give hand times"),
        trial);
  }

  // the log (its errors name it), then the angle at liftoff on it (they do not)
  Result<ControllerLog> log =
      capture::LoadControllerLog(trial.log_path, trial.log_format, calibration, options.log);
  if (!log.ok()) return ForTrial(log.status(), trial);
  outcome.log_report = log->report;
  Result<LiftoffMeasurement> measurement = MeasureLiftoff(*log, *trial.times, options.lookup);
  if (!measurement.ok()) {
    return ForTrial(measurement.status().WithContext(trial.log_path.string()), trial);
  }
  outcome.measurement = std::move(measurement).value();
  return Status::Ok();
}

}  // namespace

Status AnalysisOptions::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(lookup.Validate());
  return log.Validate();
}

int64_t ManifestAnalysis::failed() const {
  return std::count_if(outcomes.begin(), outcomes.end(),
                       [](const TrialOutcome& outcome) { return !outcome.status.ok(); });
}

std::vector<stats::TrialValue> ManifestAnalysis::Values() const {
  std::vector<stats::TrialValue> values;
  for (const TrialOutcome& outcome : outcomes) {
    if (!outcome.status.ok() || !outcome.measurement) continue;
    const LiftoffMeasurement& measurement = *outcome.measurement;
    const AngleLookup& lookup = measurement.lookup;
    // what to be wary of, in one short line
    std::string flags;
    const auto add = [&flags](const std::string& flag) {
      flags += (flags.empty() ? "" : "; ") + flag;
    };
    if (lookup.in_gap) add("gap " + FormatSeconds(lookup.gap_ns, 2) + " s");
    if (lookup.past_end && lookup.sample_before_ns) {
      add("past end " + FormatSeconds(lookup.query_ns - *lookup.sample_before_ns) + " s");
    }
    if (lookup.before_start && lookup.sample_after_ns) {
      add("before start " + FormatSeconds(*lookup.sample_after_ns - lookup.query_ns) + " s");
    }
    stats::TrialValue value;
    value.trial_id = outcome.trial.id;
    value.foot = outcome.trial.foot;
    value.liftoff_rad = measurement.liftoff_rad;
    value.lower_rad = measurement.lower_rad;
    value.upper_rad = measurement.upper_rad;
    value.flags = flags;
    values.push_back(std::move(value));
  }
  return values;
}

ManifestAnalysis AnalyzeManifest(const TrialManifest& manifest, const Calibration& calibration,
                                 const AnalysisOptions& options) {
  ManifestAnalysis analysis;
  analysis.calibration = calibration.Brief();
  analysis.rule = options.lookup.rule;
  const Status options_status = options.Validate();
  for (const TrialRecord& trial : manifest.trials) {
    TrialOutcome outcome;
    outcome.trial = trial;
    // bad options fail every trial alike; otherwise each trial stands alone
    outcome.status = options_status.ok() ? AnalyzeTrial(manifest, calibration, options, outcome)
                                         : options_status.WithContext(trial.id);
    analysis.outcomes.push_back(std::move(outcome));
  }
  return analysis;
}

}  // namespace liftoff::sync
