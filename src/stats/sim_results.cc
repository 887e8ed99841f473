#include "liftoff/stats/sim_results.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"

namespace liftoff::stats {
namespace {

using nlohmann::json;

constexpr std::string_view kFormatName = "liftoff-sim-results";
constexpr int64_t kFormatVersion = 1;

const std::vector<std::string_view> kFootNames = {"A", "B", "C", "D"};
const std::vector<std::string_view> kGroupNames = {"HT", "HB", "HR", "HL"};
const std::vector<std::string_view> kRotationNames = {"+", "-"};

SimRun ReadRun(JsonReader& reader) {
  SimRun run;
  run.foot = kAllFeet[reader.Enum("foot", kFootNames)];
  run.tension_point = reader.String("tension_point");
  if (!reader.failed() && run.tension_point.empty()) {
    reader.Fail("tension_point", "expected a non-empty name such as \"high\"");
  }
  run.stood = reader.Boolean("stood");
  run.diverged = reader.OptionalBoolean("diverged").value_or(false);
  if (!reader.failed() && run.diverged && run.stood) {
    reader.Fail("diverged", "a diverged run cannot have stood (stood must be false)");
  }
  run.liftoff_rad = reader.OptionalNumber("liftoff_rad", {.min = 0.0});
  if (!reader.failed() && run.stood && !run.liftoff_rad) {
    reader.Fail("liftoff_rad",
                "missing required field (a run that stood needs its liftoff rotation)");
  }
  if (auto group = reader.OptionalEnum("pulled_group", kGroupNames)) {
    run.pulled_group = ParseCableGroup(kGroupNames[*group]);
  }
  if (auto rotation = reader.OptionalEnum("rotation", kRotationNames)) {
    run.rotation = ParseRotationSense(kRotationNames[*rotation]);
  }
  run.notes = reader.OptionalString("notes").value_or("");
  return run;
}

}  // namespace

std::map<Foot, SimFootRange> SimRangesFromRuns(std::span<const SimRun> runs) {
  std::map<Foot, SimFootRange> ranges;
  for (const SimRun& run : runs) {
    if (!run.stood || !run.liftoff_rad) continue;
    const double value = *run.liftoff_rad;
    auto [it, inserted] = ranges.try_emplace(run.foot, SimFootRange{value, value, 0, false});
    it->second.min_rad = std::min(it->second.min_rad, value);
    it->second.max_rad = std::max(it->second.max_rad, value);
    ++it->second.n_runs;
  }
  return ranges;
}

Result<SimResults> SimResultsFromJson(const json& document, const std::string& source) {
  JsonReader root(document, source);
  SimResults results;
  results.source = source;

  // header: format first, so a wrong file says so before anything else
  root.Enum("format", {kFormatName});
  const int64_t version = root.Integer("version", {.min = 1});
  if (!root.failed() && version > kFormatVersion) {
    return UnsupportedError(root.Where("version") + ": version " + std::to_string(version) +
                            " is newer than this liftoff reads (" + std::to_string(kFormatVersion) +
                            ")");
  }
  results.model = root.String("model");
  results.description = root.OptionalString("description").value_or("");

  // runs, then the ranges they give
  const bool has_runs = root.Has("runs");
  if (auto runs = root.OptionalObjectArray("runs")) {
    for (JsonReader& run : *runs) results.runs.push_back(ReadRun(run));
  }
  results.ranges = SimRangesFromRuns(results.runs);

  // the summary's ranges replace the runs' where both exist
  const bool has_summary = root.Has("summary");
  const json* summary_json = root.Raw("summary");
  if (auto summary = root.OptionalObject("summary"); summary && summary_json->is_object()) {
    for (const auto& [key, unused] : summary_json->items()) {
      const std::optional<Foot> foot = ParseFoot(key);
      if (!foot) {
        summary->Fail(key, "unknown foot; expected one of A, B, C, D");
        continue;
      }
      JsonReader range_reader = summary->Object(key);
      const double min_rad = range_reader.Number("min_rad", {.min = 0.0});
      const double max_rad = range_reader.Number("max_rad", {.min = 0.0});
      if (!range_reader.failed() && max_rad < min_rad) {
        range_reader.Fail("max_rad", "expected a number >= min_rad (" + FormatNumber(min_rad) +
                                         "), got " + FormatNumber(max_rad));
      }
      SimFootRange& range = results.ranges[*foot];
      range.min_rad = min_rad;
      range.max_rad = max_rad;
      range.from_summary = true;
    }
  }
  if (!has_runs && !has_summary) root.Fail("", "expected \"runs\" or \"summary\" (or both)");

  LIFTOFF_RETURN_IF_ERROR(root.Finish());
  return results;
}

Result<SimResults> LoadSimResults(const std::filesystem::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(json document, LoadJsonFile(path));
  return SimResultsFromJson(document, path.string());
}

json SimResultsToJson(const SimResults& results) {
  json document = {{"format", kFormatName}, {"version", kFormatVersion}, {"model", results.model}};
  if (!results.description.empty()) document["description"] = results.description;

  // runs, with the optional fields only when set
  json runs = json::array();
  for (const SimRun& run : results.runs) {
    json entry = {{"foot", FootName(run.foot)}, {"tension_point", run.tension_point}};
    if (run.liftoff_rad) entry["liftoff_rad"] = *run.liftoff_rad;
    entry["stood"] = run.stood;
    if (run.diverged) entry["diverged"] = true;
    if (run.pulled_group) entry["pulled_group"] = CableGroupName(*run.pulled_group);
    if (run.rotation) entry["rotation"] = RotationSenseName(*run.rotation);
    if (!run.notes.empty()) entry["notes"] = run.notes;
    runs.push_back(std::move(entry));
  }

  // only typed-in ranges go to "summary"; the others follow from the runs
  json summary = json::object();
  for (const auto& [foot, range] : results.ranges) {
    if (!range.from_summary) continue;
    summary[std::string(FootName(foot))] = {{"min_rad", range.min_rad}, {"max_rad", range.max_rad}};
  }
  if (!runs.empty() || summary.empty()) document["runs"] = std::move(runs);
  if (!summary.empty()) document["summary"] = std::move(summary);
  return document;
}

}  // namespace liftoff::stats
