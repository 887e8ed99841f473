#include "liftoff/core/manifest.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"
#include "liftoff/core/time.h"

namespace liftoff {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr std::string_view kFormatName = "liftoff-manifest";
constexpr int64_t kFormatVersion = 1;
// times and uncertainties, seconds: bounded so they convert to int64 nanoseconds
constexpr NumberRange kTimeRange{.min = 0.0, .max = kMaxTimeSeconds};
// test numbers: whole and positive, small enough for an int
constexpr NumberRange kTestNumberRange{.min = 1.0, .max = 1e9};
constexpr NumberRange kPxPerMmRange{.min = 0.0, .max = 1000.0, .min_exclusive = true};

// The folder relative paths hang from, made absolute so resolved paths are too.
fs::path AbsoluteDir(const fs::path& dir) {
  std::error_code error;
  fs::path absolute = fs::absolute(dir.empty() ? fs::path(".") : dir, error);
  if (error) absolute = dir;
  return absolute.lexically_normal();
}

// A path from the file: relative ones hang from `base_dir`, absolute ones stay.
std::optional<fs::path> ReadPath(JsonReader& reader, std::string_view key, const fs::path& base_dir,
                                 bool required) {
  const std::optional<std::string> text =
      required ? std::optional(reader.String(key)) : reader.OptionalString(key);
  if (!text || reader.failed()) return std::nullopt;
  if (text->empty()) {
    reader.Fail(key, "expected a non-empty path");
    return std::nullopt;
  }
  return (base_dir / fs::path(*text)).lexically_normal();
}

// A path for the file: relative to `base_dir` when the two share a folder below the root
// (so "../calib/x.json" stays relative and "/mnt/usb/x.csv" stays absolute).
std::string WritePath(const fs::path& path, const fs::path& base_dir) {
  if (path.is_relative()) return path.generic_string();
  const fs::path normal = path.lexically_normal();
  const auto [in_path, in_base] =
      std::mismatch(normal.begin(), normal.end(), base_dir.begin(), base_dir.end());
  const fs::path relative = normal.lexically_relative(base_dir);
  if (std::distance(normal.begin(), in_path) < 2 || relative.empty())
    return normal.generic_string();
  return relative.generic_string();
}

// The columns of a "csv" log, beside its path and format.
CsvLogColumns ReadCsvColumns(JsonReader& log) {
  CsvLogColumns columns;
  columns.time_column = log.String("time_column");
  if (auto unit = log.OptionalEnum("time_unit", {"s", "ms", "us", "ns"})) {
    columns.time_unit = std::array{"s", "ms", "us", "ns"}[*unit];
  }
  columns.angle_column = log.String("angle_column");
  if (auto unit = log.OptionalEnum("angle_unit", {"rad", "deg", "counts"})) {
    columns.angle_unit = std::array{"rad", "deg", "counts"}[*unit];
  }
  columns.led_column = log.OptionalString("led_column");
  columns.led_on_s =
      log.OptionalNumber("led_on_s", {.min = -kMaxTimeSeconds, .max = kMaxTimeSeconds});
  for (const auto& [key, name] :
       {std::pair<const char*, const std::string*>{"time_column", &columns.time_column},
        {"angle_column", &columns.angle_column}}) {
    if (!log.failed() && name->empty()) log.Fail(key, "expected a column name");
  }
  if (!log.failed() && columns.led_column && columns.led_on_s) {
    log.Fail("led_on_s", "expected either led_column or led_on_s, not both");
  }
  return columns;
}

// [x, y, width, height] in whole pixels, the rectangle inside the first quadrant.
std::optional<RegionPx> ReadRegion(JsonReader& reader, std::string_view key) {
  const json* value = reader.Raw(key);
  if (value == nullptr) return std::nullopt;
  const auto whole = [](const json& number, int64_t min) {
    return number.is_number_integer() && number.get<int64_t>() >= min &&
           number.get<int64_t>() <= std::numeric_limits<int>::max();
  };
  if (!value->is_array() || value->size() != 4 || !whole((*value)[0], 0) ||
      !whole((*value)[1], 0) || !whole((*value)[2], 1) || !whole((*value)[3], 1)) {
    std::string got = value->dump();
    if (got.size() > 40) got = got.substr(0, 37) + "...";
    reader.Fail(
        key,
        "expected [x, y, width, height] in whole pixels (x, y >= 0; width, height >= 1), got " +
            got);
    return std::nullopt;
  }
  return RegionPx{(*value)[0].get<int>(), (*value)[1].get<int>(), (*value)[2].get<int>(),
                  (*value)[3].get<int>()};
}

std::optional<EventTimes> ReadTimes(JsonReader& trial) {
  std::optional<JsonReader> reader = trial.OptionalObject("times");
  if (!reader) return std::nullopt;
  EventTimes times;
  const double led_on_s = reader->Number("led_on_s", kTimeRange);
  const double liftoff_s = reader->Number("liftoff_s", kTimeRange);
  const double led_on_uncertainty_s =
      reader->OptionalNumber("led_on_uncertainty_s", kTimeRange).value_or(0.0);
  const double liftoff_uncertainty_s =
      reader->OptionalNumber("liftoff_uncertainty_s", kTimeRange).value_or(0.0);
  times.source = reader->OptionalString("source").value_or("hand");
  if (reader->failed()) return std::nullopt;
  if (times.source.empty()) reader->Fail("source", "expected a non-empty name such as \"hand\"");
  if (!(liftoff_s > led_on_s)) {
    reader->Fail("liftoff_s", "expected a time after led_on_s (" + FormatNumber(led_on_s) +
                                  " s), got " + FormatNumber(liftoff_s));
  }
  times.led_on_ns = NsFromSeconds(led_on_s);
  times.liftoff_ns = NsFromSeconds(liftoff_s);
  times.led_on_uncertainty_ns = NsFromSeconds(led_on_uncertainty_s);
  times.liftoff_uncertainty_ns = NsFromSeconds(liftoff_uncertainty_s);
  return times;
}

TrialRecord ReadTrial(JsonReader& reader, const fs::path& base_dir) {
  TrialRecord trial;
  // who it is
  trial.id = reader.String("id");
  if (!reader.failed() && trial.id.empty()) reader.Fail("id", "expected a non-empty id");
  const auto is_control = [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; };
  if (!reader.failed() && std::any_of(trial.id.begin(), trial.id.end(), is_control)) {
    reader.Fail("id", "expected one line without control characters (it names files and table "
                      "rows)");
  }
  trial.foot = static_cast<Foot>(reader.Enum("foot", {"A", "B", "C", "D"}));
  if (auto test = reader.OptionalInteger("test", kTestNumberRange)) {
    trial.test_number = static_cast<int>(*test);
  }
  static const std::vector<std::string_view> kGroups = {"HR", "HL", "HT", "HB"};
  if (auto group = reader.OptionalEnum("pulled_group", kGroups))
    trial.pulled_group = ParseCableGroup(kGroups[*group]);
  if (auto sense = reader.OptionalEnum("rotation", {"+", "-"})) {
    trial.rotation = *sense == 0 ? RotationSense::kPositive : RotationSense::kNegative;
  }

  // its files
  JsonReader log = reader.Object("log");
  trial.log_path = ReadPath(log, "path", base_dir, true).value_or(fs::path());
  if (auto format = log.OptionalEnum(
          "format", {LogFormatName(LogFormat::kLiftoff), LogFormatName(LogFormat::kLaika2018),
                     LogFormatName(LogFormat::kCsv)})) {
    trial.log_format = static_cast<LogFormat>(*format);
  }
  if (trial.log_format == LogFormat::kCsv) trial.log_columns = ReadCsvColumns(log);
  if (std::optional<JsonReader> video = reader.OptionalObject("video")) {
    trial.video_path = ReadPath(*video, "path", base_dir, true);
    trial.px_per_mm = video->OptionalNumber("px_per_mm", kPxPerMmRange);
  }

  // what was measured by hand, and where to look in the video
  trial.times = ReadTimes(reader);
  if (std::optional<JsonReader> roi = reader.OptionalObject("roi")) {
    trial.led_roi_px = ReadRegion(*roi, "led_px");
    trial.foot_roi_px = ReadRegion(*roi, "foot_px");
  }
  trial.notes = reader.OptionalString("notes").value_or("");
  return trial;
}

// ns / 1e9 is correctly rounded: 1'234'567'891 ns is written as 1.234567891.
double SecondsForJson(int64_t ns) { return static_cast<double>(ns) / 1e9; }

json RegionToJson(const RegionPx& region) {
  return json::array({region.x_px, region.y_px, region.width_px, region.height_px});
}

}  // namespace

std::string_view LogFormatName(LogFormat format) {
  switch (format) {
    case LogFormat::kLaika2018: return "laika-2018";
    case LogFormat::kCsv: return "csv";
    case LogFormat::kLiftoff: break;
  }
  return "liftoff";
}

std::optional<LogFormat> ParseLogFormat(std::string_view text) {
  for (LogFormat format : {LogFormat::kLiftoff, LogFormat::kLaika2018, LogFormat::kCsv}) {
    if (text == LogFormatName(format)) return format;
  }
  return std::nullopt;
}

namespace {

// The checks of TrialManifest::Validate; `name` names the manifest in messages.
Status ValidateTrials(const std::vector<TrialRecord>& trials, const std::string& name) {
  std::map<std::string, size_t, std::less<>> first_index;
  for (size_t i = 0; i < trials.size(); ++i) {
    const TrialRecord& trial = trials[i];
    const std::string where =
        name + ": trials[" + std::to_string(i) + "] (id \"" + trial.id + "\")";
    // identity and files
    if (trial.id.empty()) return InvalidArgumentError(where + ": expected a non-empty id");
    if (const auto [it, inserted] = first_index.emplace(trial.id, i); !inserted) {
      return InvalidArgumentError(name + ": trials[" + std::to_string(it->second) +
                                  "] and trials[" + std::to_string(i) + "] have the same id \"" +
                                  trial.id + "\"");
    }
    if (trial.log_path.empty()) return InvalidArgumentError(where + ": expected a log path");
    if ((trial.log_format == LogFormat::kCsv) != trial.log_columns.has_value()) {
      return InvalidArgumentError(where +
                                  ": log: expected columns for a csv log, and only for one");
    }
    if (trial.test_number && *trial.test_number < 1) {
      return InvalidArgumentError(where + ": test number: expected an integer >= 1, got " +
                                  std::to_string(*trial.test_number));
    }
    // times: non-negative uncertainties, liftoff after LED on
    if (trial.times) {
      const EventTimes& times = *trial.times;
      if (times.led_on_uncertainty_ns < 0 || times.liftoff_uncertainty_ns < 0) {
        return InvalidArgumentError(where + ": times: expected uncertainties >= 0, got " +
                                    FormatSeconds(times.led_on_uncertainty_ns, 9) + " s and " +
                                    FormatSeconds(times.liftoff_uncertainty_ns, 9) + " s");
      }
      if (times.liftoff_ns <= times.led_on_ns) {
        return InvalidArgumentError(where +
                                    ": times: expected liftoff after LED on, got liftoff at " +
                                    FormatSeconds(times.liftoff_ns, 9) + " s and LED on at " +
                                    FormatSeconds(times.led_on_ns, 9) + " s");
      }
    }
    // regions: positive sizes
    for (const auto& [label, region] :
         {std::pair{"led", &trial.led_roi_px}, std::pair{"foot", &trial.foot_roi_px}}) {
      if (*region && ((*region)->width_px < 1 || (*region)->height_px < 1)) {
        return InvalidArgumentError(
            where + ": " + label + " region: expected width and height >= 1 px, got " +
            std::to_string((*region)->width_px) + " x " + std::to_string((*region)->height_px));
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status TrialManifest::Validate() const {
  return ValidateTrials(trials, source_path.empty() ? "manifest" : source_path.string());
}

Result<TrialManifest> ManifestFromJson(const json& document, const std::string& source,
                                       const fs::path& base_dir) {
  JsonReader root(document, source);
  // what kind of file this is, before anything else in it
  root.Enum("format", {kFormatName});
  const int64_t version = root.Integer("version");
  if (root.failed()) return root.Finish();
  if (version != kFormatVersion) {
    return UnsupportedError(
        root.Where("version") + ": liftoff-manifest version " + std::to_string(version) +
        " is not supported; this build reads version " + std::to_string(kFormatVersion));
  }

  TrialManifest manifest;
  manifest.base_dir = AbsoluteDir(base_dir);
  manifest.description = root.OptionalString("description").value_or("");
  manifest.calibration_path = ReadPath(root, "calibration", manifest.base_dir, false);

  // trials; what no single field shows (an id used twice) is ValidateTrials' to find
  for (JsonReader& reader : root.ObjectArray("trials")) {
    manifest.trials.push_back(ReadTrial(reader, manifest.base_dir));
  }
  LIFTOFF_RETURN_IF_ERROR(root.Finish());
  LIFTOFF_RETURN_IF_ERROR(ValidateTrials(manifest.trials, source));
  return manifest;
}

Result<TrialManifest> LoadManifest(const fs::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(json document, LoadJsonFile(path));
  LIFTOFF_ASSIGN_OR_RETURN(TrialManifest manifest,
                           ManifestFromJson(document, path.string(), path.parent_path()));
  manifest.source_path = path;
  return manifest;
}

json ManifestToJson(const TrialManifest& manifest, const fs::path& base_dir) {
  const fs::path base = AbsoluteDir(base_dir);
  json document = json::object();
  document["format"] = kFormatName;
  document["version"] = kFormatVersion;
  if (!manifest.description.empty()) document["description"] = manifest.description;
  if (manifest.calibration_path)
    document["calibration"] = WritePath(*manifest.calibration_path, base);
  json trials = json::array();
  for (const TrialRecord& trial : manifest.trials) {
    json entry = {{"id", trial.id}, {"foot", FootName(trial.foot)}};
    if (trial.test_number) entry["test"] = *trial.test_number;
    if (trial.pulled_group) entry["pulled_group"] = CableGroupName(*trial.pulled_group);
    if (trial.rotation) entry["rotation"] = RotationSenseName(*trial.rotation);
    entry["log"] = {{"path", WritePath(trial.log_path, base)},
                    {"format", LogFormatName(trial.log_format)}};
    if (trial.log_columns) {
      const CsvLogColumns& columns = *trial.log_columns;
      entry["log"]["time_column"] = columns.time_column;
      entry["log"]["time_unit"] = columns.time_unit;
      entry["log"]["angle_column"] = columns.angle_column;
      entry["log"]["angle_unit"] = columns.angle_unit;
      if (columns.led_column) entry["log"]["led_column"] = *columns.led_column;
      if (columns.led_on_s) entry["log"]["led_on_s"] = *columns.led_on_s;
    }
    if (trial.video_path) {
      entry["video"] = {{"path", WritePath(*trial.video_path, base)}};
      if (trial.px_per_mm) entry["video"]["px_per_mm"] = *trial.px_per_mm;
    }
    if (trial.times) {
      entry["times"] = {
          {"led_on_s", SecondsForJson(trial.times->led_on_ns)},
          {"liftoff_s", SecondsForJson(trial.times->liftoff_ns)},
          {"led_on_uncertainty_s", SecondsForJson(trial.times->led_on_uncertainty_ns)},
          {"liftoff_uncertainty_s", SecondsForJson(trial.times->liftoff_uncertainty_ns)},
          {"source", trial.times->source}};
    }
    if (trial.led_roi_px || trial.foot_roi_px) {
      json roi = json::object();
      if (trial.led_roi_px) roi["led_px"] = RegionToJson(*trial.led_roi_px);
      if (trial.foot_roi_px) roi["foot_px"] = RegionToJson(*trial.foot_roi_px);
      entry["roi"] = std::move(roi);
    }
    if (!trial.notes.empty()) entry["notes"] = trial.notes;
    trials.push_back(std::move(entry));
  }
  document["trials"] = std::move(trials);
  return document;
}

Status WriteManifest(const fs::path& path, const TrialManifest& manifest) {
  return WriteJsonFile(path, ManifestToJson(manifest, AbsoluteDir(path.parent_path())));
}

}  // namespace liftoff
