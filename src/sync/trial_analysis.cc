#include "liftoff/sync/trial_analysis.h"

#include <algorithm>

#include "liftoff/capture/log_loader.h"
#include "liftoff/core/text.h"

namespace liftoff::sync {
namespace {

// the error with the trial id in front
Status ForTrial(const Status& status, const TrialRecord& trial) {
  return status.WithContext(trial.id);
}

// the trial's video through video analysis, with the trial's regions, foot and scale
Result<video::ClipAnalysis> AnalyzeTrialVideo(const TrialRecord& trial,
                                              const AnalysisOptions& options) {
  const std::filesystem::path& video_path = *trial.video_path;
  if (!trial.foot_roi_px) {
    return InvalidArgumentError(video_path.string() +
                                ": the trial has a video but no foot region (roi.foot_px) to "
                                "find its liftoff in; give one, or hand times");
  }
  video::ClipAnalysisOptions clip = options.video;
  if (trial.led_roi_px) clip.led.roi_px = video::RectFromRegion(*trial.led_roi_px);
  clip.foot.foot_roi_px = video::RectFromRegion(*trial.foot_roi_px);
  if (options.use_tape_colour) clip.foot.tape_colour = trial.foot;
  if (trial.px_per_mm) clip.foot.px_per_mm = *trial.px_per_mm;
  video::ClipProgress progress;
  if (options.video_progress) {
    progress = [&](int64_t frames_done, int64_t t_ns) {
      options.video_progress(trial, frames_done, t_ns);
    };
  }
  return video::AnalyzeClip(video_path, clip, progress);
}

// one trial, start to end
Status AnalyzeTrial(const TrialManifest& manifest, const Calibration& calibration,
                    const AnalysisOptions& options, TrialOutcome& outcome) {
  const TrialRecord& trial = outcome.trial;
  // hand times, else the video's
  EventTimes times;
  if (trial.times) {
    times = *trial.times;
  } else if (trial.video_path) {
    Result<video::ClipAnalysis> clip = AnalyzeTrialVideo(trial, options);
    if (!clip.ok()) return ForTrial(clip.status(), trial);
    outcome.video = std::move(clip).value();
    Result<EventTimes> found = outcome.video->Events();
    if (!found.ok()) return ForTrial(found.status(), trial);
    times = *found;
  } else {
    const std::string manifest_name =
        manifest.source_path.empty() ? "manifest" : manifest.source_path.string();
    return ForTrial(
        InvalidArgumentError(manifest_name + ": the trial has neither event times nor a video; "
                                             "give hand times"),
        trial);
  }

  // the log (its errors name it), then the angle at liftoff on it (they do not)
  Result<ControllerLog> log =
      capture::LoadTrialLog(trial, calibration, options.log);
  if (!log.ok()) return ForTrial(log.status(), trial);
  outcome.log_report = log->report;
  Result<LiftoffMeasurement> measurement = MeasureLiftoff(*log, times, options.lookup);
  if (!measurement.ok()) {
    return ForTrial(measurement.status().WithContext(trial.log_path.string()), trial);
  }
  outcome.measurement = std::move(measurement).value();
  return Status::Ok();
}

}  // namespace

Status AnalysisOptions::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(lookup.Validate());
  LIFTOFF_RETURN_IF_ERROR(log.Validate());
  return video.Validate().WithContext("video");
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
    if (outcome.video && !outcome.video->warnings.empty()) {
      add("video: " + Plural(static_cast<int64_t>(outcome.video->warnings.size()), "warning"));
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
  for (size_t i = 0; i < manifest.trials.size(); ++i) {
    analysis.outcomes.push_back(AnalyzeManifestTrial(manifest, calibration, options, i));
  }
  return analysis;
}

TrialOutcome AnalyzeManifestTrial(const TrialManifest& manifest, const Calibration& calibration,
                                  const AnalysisOptions& options, size_t index) {
  TrialOutcome outcome;
  outcome.trial = manifest.trials.at(index);
  // bad options fail every trial alike; otherwise each trial stands alone
  const Status options_status = options.Validate();
  outcome.status = options_status.ok() ? AnalyzeTrial(manifest, calibration, options, outcome)
                                       : options_status.WithContext(outcome.trial.id);
  return outcome;
}

}  // namespace liftoff::sync
