// A whole trial manifest, trial by trial: load each controller log, map the trial's
// video times onto it and read the vertebra angle at liftoff. The video times are the
// trial's hand-given ones, or, for a trial with a video and no times, found by video
// analysis (video::AnalyzeClip). One trial's failure never stops the others; each carries
// its own Status.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/stats/table.h"
#include "liftoff/sync/lookup.h"
#include "liftoff/video/clip_analysis.h"

namespace liftoff::sync {

struct AnalysisOptions {
  /// How angles are read from the logs.
  LookupOptions lookup;
  /// How tolerant the log readers are.
  LogReadOptions log;
  /// Video analysis of the trials that have a video and no times. Each trial's record
  /// fills in its own parts: the LED region (roi.led_px; without it the LED is located
  /// automatically, unless video.led.roi_px is set), the foot region (roi.foot_px,
  /// required), the tape colour of its foot (when use_tape_colour) and the pixel scale
  /// (video.px_per_mm; without it video.foot.px_per_mm, 0 = estimated from the foot's
  /// width).
  video::ClipAnalysisOptions video;
  /// Track the foot by its tape colour (A blue, B orange, C purple, D red) as well as by
  /// its edges.
  bool use_tape_colour = true;
  /// Called while a trial's video is analysed: the trial, frames done, the last frame's
  /// time (video clock, ns). May be empty.
  std::function<void(const TrialRecord& trial, int64_t frames_done, int64_t t_ns)> video_progress;

  /// Every part's checks (the video options without a foot region: that is per trial).
  Status Validate() const;
};

/// What became of one trial.
struct TrialOutcome {
  /// The manifest's record.
  TrialRecord trial;
  /// OK, or why the trial has no measurement; the message starts with the trial id and
  /// names the file concerned ("A1: /data/Test1.txt: no such file").
  Status status;
  /// The measurement, when status is OK.
  std::optional<LiftoffMeasurement> measurement;
  /// What the log reader made of the trial's log (empty when it was never read).
  LogReadReport log_report;
  /// The video analysis, when the trial's times came from its video (kept even when the
  /// lookup on the log then failed): regions, pulses, the foot's track, warnings.
  std::optional<video::ClipAnalysis> video;
};

struct ManifestAnalysis {
  /// One per manifest trial, in manifest order.
  std::vector<TrialOutcome> outcomes;
  /// The calibration used (Calibration::Brief()), printed with every result.
  std::string calibration;
  /// The lookup rule used.
  LookupRule rule = LookupRule::kLinear;
  /// Number of outcomes whose status is not OK.
  int64_t failed() const;

  /// The successful trials' |angles| with their intervals, in manifest order. flags sum up
  /// what to be wary of, separated by "; ": "gap 0.93 s", "past end 0.091 s",
  /// "before start 0.010 s", "video: 2 warnings" (times from video analysis that warned);
  /// empty when nothing.
  std::vector<stats::TrialValue> Values() const;
};

/// Analyses every trial of `manifest`: loads its log with capture::LoadControllerLog
/// (through `calibration`), takes its hand-given times, or analyses its video when it has
/// a video and no times (LED switch-on and liftoff, source "video"), and measures the
/// liftoff angle. Hand times win when a trial has both. A trial with a video and no times
/// fails with the video analysis' error (kInvalidArgument without a foot region, kNotFound
/// when the LED never switches on or the foot never lifts, kParse for a damaged video, ...);
/// with neither a video nor times, kInvalidArgument. Invalid options fail every trial.
ManifestAnalysis AnalyzeManifest(const TrialManifest& manifest, const Calibration& calibration,
                                 const AnalysisOptions& options);

/// The manifest's trial `index` (< manifest.trials.size()) alone, as AnalyzeManifest
/// analyses it: trials share nothing, so callers may analyse several at once on their own
/// threads (options.video_progress is then called from those threads).
TrialOutcome AnalyzeManifestTrial(const TrialManifest& manifest, const Calibration& calibration,
                                  const AnalysisOptions& options, size_t index);

}  // namespace liftoff::sync
