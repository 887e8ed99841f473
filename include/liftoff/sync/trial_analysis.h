// A whole trial manifest, trial by trial: load each controller log, map the trial's
// video times onto it and read the vertebra angle at liftoff. One trial's failure never
// stops the others; each carries its own Status.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/stats/table.h"
#include "liftoff/sync/lookup.h"

namespace liftoff::sync {

struct AnalysisOptions {
  /// How angles are read from the logs.
  LookupOptions lookup;
  /// How tolerant the log readers are.
  LogReadOptions log;

  /// Both parts' checks.
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
  /// "before start 0.010 s"; empty when nothing.
  std::vector<stats::TrialValue> Values() const;
};

/// Analyses every trial of `manifest`: loads its log with capture::LoadControllerLog
/// (through `calibration`), takes its hand-given times and measures the liftoff angle.
/// A trial with a video but no times fails kUnsupported (automatic video analysis is not
/// available yet); with neither, kInvalidArgument. Invalid options fail every trial.
ManifestAnalysis AnalyzeManifest(const TrialManifest& manifest, const Calibration& calibration,
                                 const AnalysisOptions& options);

}  // namespace liftoff::sync
