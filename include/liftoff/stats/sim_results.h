// Simulation results: the liftoff rotation the simulator found for each foot at each
// tension test point (paper Table III/IV), read from a JSON file so the results table can
// set them beside the hardware. Format (docs/formats.md, "Simulation results"):
//
//   {"format": "liftoff-sim-results", "version": 1,
//    "model": "laika-ntrt", "description": "...",
//    "runs": [{"foot": "A", "tension_point": "high", "liftoff_rad": 0.47, "stood": true,
//              "pulled_group": "HR", "rotation": "+", "notes": "..."}],
//    "summary": {"A": {"min_rad": 0.33, "max_rad": 0.47}}}
//
// "runs" and/or "summary" may be present. "summary" lets a user type in published ranges;
// where a foot has both, the summary's min/max win and the runs are still listed. Runs
// that did not stand (stood = false: the robot sagged onto the ground) are left out of
// min/max and reported.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"

namespace liftoff::stats {

/// One simulated foot-lifting test.
struct SimRun {
  /// Foot that lifted (the foot the test targets).
  Foot foot = Foot::kA;
  /// Tension test point, usually one of "low", "med-low", "mean", "med-high", "high".
  std::string tension_point;
  /// Absolute rotation of the rotating vertebra at liftoff, rad (>= 0). Required when the
  /// robot stood; may be absent when it did not.
  std::optional<double> liftoff_rad;
  /// Whether the robot stood up at this tension point. false: excluded from min/max.
  bool stood = true;
  /// Horizontal cable group shortened to bend the spine, when given.
  std::optional<CableGroup> pulled_group;
  /// Direction of the vertebra's ramp, when given.
  std::optional<RotationSense> rotation;
  /// Free text.
  std::string notes;
  /// Whether the run's engine diverged (then stood is false and there is no liftoff):
  /// excluded from min/max and reported apart.
  bool diverged = false;
};

/// The simulated range of one foot's liftoff rotation (paper Table IV's sim columns).
struct SimFootRange {
  /// Smallest and largest absolute liftoff rotation, rad.
  double min_rad = 0.0;
  double max_rad = 0.0;
  /// Standing runs of this foot in the file (0 when the range comes only from "summary").
  int64_t n_runs = 0;
  /// True when min/max come from the file's "summary" rather than from its runs.
  bool from_summary = false;
};

struct SimResults {
  /// File the results came from (or any name given to SimResultsFromJson).
  std::string source;
  /// Name of the simulated model, e.g. "laika-ntrt".
  std::string model;
  /// One line for people (may be empty).
  std::string description;
  /// Every run, in file order, standing or not.
  std::vector<SimRun> runs;
  /// Range per foot: from the standing runs, replaced by "summary" where given. Feet with
  /// neither have no entry.
  std::map<Foot, SimFootRange> ranges;
};

/// Min/max/count of the standing runs with a liftoff value, per foot (from_summary false).
std::map<Foot, SimFootRange> SimRangesFromRuns(std::span<const SimRun> runs);

/// Loads a simulation results file. kNotFound when missing, kParse for bad JSON,
/// kInvalidArgument naming file and JSON pointer for a bad or unknown field
/// ("sim.json: /runs/2/foot: expected one of A, B, C, D, got \"E\""), kUnsupported for a
/// newer version.
Result<SimResults> LoadSimResults(const std::filesystem::path& path);
/// The same from parsed JSON; `source` names it in errors and becomes SimResults::source.
Result<SimResults> SimResultsFromJson(const nlohmann::json& document, const std::string& source);
/// The results in the file format: every run, and "summary" for the ranges marked
/// from_summary (so the output loads back to the same SimResults).
nlohmann::json SimResultsToJson(const SimResults& results);

}  // namespace liftoff::stats
