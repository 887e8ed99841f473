// The trial manifest: one JSON file that lists a set of trials, each with its foot, the
// cable group pulled and rotation direction, its controller log, optional video, optional
// hand-measured event times and regions of interest. Paths inside are relative to the
// manifest's folder. Format: docs/formats.md, "trial manifest".
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"

namespace liftoff {

/// File formats a trial's controller log may be in.
enum class LogFormat {
  kLiftoff,    ///< liftoff's own log (docs/formats.md)
  kLaika2018,  ///< the 2018 Laika serial dump: `t_ms,value,` lines, CR line ends
  kCsv,        ///< a user's own logger: a CSV file with named columns (CsvLogColumns)
};

/// How a plain CSV log (LogFormat::kCsv) is read: its first line names the columns, then
/// one sample a line; other columns are ignored. The `controller.csv` files of liftoff's
/// video development set are one such log: time "t_ms" in "ms", angle "rotation_rad" in
/// "rad", the LED switching on at time 0.
struct CsvLogColumns {
  /// The controller clock's column and its unit: "s", "ms", "us" or "ns".
  std::string time_column;
  std::string time_unit = "s";
  /// The rotating vertebra's column and its unit: "rad" or "deg" (the vertebra's angle),
  /// or "counts" (the rotating motor's encoder counts, turned into the vertebra's angle
  /// through the calibration).
  std::string angle_column;
  std::string angle_unit = "rad";
  /// Where the LED switch-on is: a column of the LED's state (0 or 1; its first rise), or
  /// its time on the log's clock, s. Neither: the log's origin, with a warning.
  std::optional<std::string> led_column;
  std::optional<double> led_on_s;
};

/// "liftoff", "laika-2018", "csv".
std::string_view LogFormatName(LogFormat format);
std::optional<LogFormat> ParseLogFormat(std::string_view text);

/// The two instants of a trial on the video's clock, with their timing uncertainty.
struct EventTimes {
  /// Video time at which the LED switched on, ns from the video's start.
  int64_t led_on_ns = 0;
  /// Video time at which the foot left the ground, ns from the video's start.
  int64_t liftoff_ns = 0;
  /// Half-width of the uncertainty of led_on_ns, ns (>= 0).
  int64_t led_on_uncertainty_ns = 0;
  /// Half-width of the uncertainty of liftoff_ns, ns (>= 0).
  int64_t liftoff_uncertainty_ns = 0;
  /// Who measured them: "hand", "video", "synthetic".
  std::string source = "hand";
};

/// A rectangle in video pixels.
struct RegionPx {
  int x_px = 0;
  int y_px = 0;
  int width_px = 0;
  int height_px = 0;
};

struct TrialRecord {
  /// Unique within the manifest, e.g. "A1".
  std::string id;
  /// Foot expected to lift.
  Foot foot = Foot::kA;
  /// Test number within the foot's series (1-based), when known.
  std::optional<int> test_number;
  /// Horizontal cable group shortened to bend the spine (HR or HL), when known.
  std::optional<CableGroup> pulled_group;
  /// Direction of the rotating vertebra's ramp, when known.
  std::optional<RotationSense> rotation;
  /// Controller log, absolute (resolved against the manifest's folder when loaded).
  std::filesystem::path log_path;
  LogFormat log_format = LogFormat::kLiftoff;
  /// The columns of a LogFormat::kCsv log (required for it, absent otherwise).
  std::optional<CsvLogColumns> log_columns;
  /// Video of the trial, absolute, when there is one.
  std::optional<std::filesystem::path> video_path;
  /// Image scale at the foot, px per mm of vertical motion, when known (a liftoff
  /// threshold in mm needs it; video analysis estimates it from the foot's width
  /// otherwise).
  std::optional<double> px_per_mm;
  /// Event times read by hand (or by any tool outside liftoff), when given.
  std::optional<EventTimes> times;
  /// Where the LED and the foot are in the video, when given.
  std::optional<RegionPx> led_roi_px;
  std::optional<RegionPx> foot_roi_px;
  /// Free text.
  std::string notes;
};

struct TrialManifest {
  /// File it was loaded from (empty when built in code).
  std::filesystem::path source_path;
  /// Folder relative paths are resolved against.
  std::filesystem::path base_dir;
  /// One line for people.
  std::string description;
  /// Calibration named by the manifest, absolute, when it names one.
  std::optional<std::filesystem::path> calibration_path;
  std::vector<TrialRecord> trials;

  /// Unique ids, known formats, non-negative uncertainties, liftoff after LED on.
  Status Validate() const;
};

/// Loads a manifest. Every error names the file and the JSON path of the bad field
/// ("trials.json: /trials/3/foot: expected one of A, B, C, D, got \"E\""). Paths are
/// resolved against the manifest's folder; missing log files are not checked here.
Result<TrialManifest> LoadManifest(const std::filesystem::path& path);
/// The same from parsed JSON; `source` names it in errors, `base_dir` resolves paths.
Result<TrialManifest> ManifestFromJson(const nlohmann::json& document, const std::string& source,
                                       const std::filesystem::path& base_dir);
/// The manifest as JSON, with paths written relative to `base_dir` where possible.
nlohmann::json ManifestToJson(const TrialManifest& manifest, const std::filesystem::path& base_dir);
/// Writes the manifest to `path`, paths relative to the file's folder.
Status WriteManifest(const std::filesystem::path& path, const TrialManifest& manifest);

}  // namespace liftoff
