// Hardware calibration: encoder and gear constants, the bending spool, the cable
// materials and the tension test points. Loaded from JSON (calib/laika-2018.json; schema
// in docs/calibration.md). Every result liftoff prints names the calibration it used.
//
// The drive chain of the rotating vertebra (vertebra 3):
//   encoder counts --(counts per motor rev)--> motor angle (rotor, before the gearbox)
//     --(gearbox ratio, 1000:1)--> output-shaft angle --(spur gear, 4:1)--> vertebra angle
// The 2018 controller logged the output-shaft angle in radians.
// The bending motors (vertebrae 2 and 4) drive a four-groove spool on their output shaft:
//   output-shaft angle = spool angle; groove i shortens its cable by radius_i * angle.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/status.h"

namespace liftoff {

/// A cable material's linear spring constant (paper Table I).
struct MaterialConstant {
  /// "silicone", "buna_n", "spring".
  std::string name;
  /// Mean spring constant, N/m.
  double stiffness_n_per_m = 0.0;
  /// Standard deviation of the spring constant over the tested samples, N/m (0 = exact).
  double stiffness_stddev_n_per_m = 0.0;
};

/// One of the simulation's tension test points (paper Table III): the silicone lattice
/// and the Buna-N ventral strip varied together.
struct TensionPoint {
  /// "low", "med-low", "mean", "med-high", "high".
  std::string name;
  /// Offset from the mean in standard deviations (-2 .. +2).
  double sigma = 0.0;
  /// Silicone spring constant (HT, saddles, unpulled side group), N/m.
  double silicone_n_per_m = 0.0;
  /// Buna-N spring constant (HB), N/m.
  double buna_n_n_per_m = 0.0;
  /// Mechanical spring of the pulled side group, N/m.
  double spring_n_per_m = 0.0;
};

/// Number of grooves on a bending spool (one per cable of a horizontal group).
inline constexpr int kSpoolGrooves = 4;

struct Calibration {
  /// Short name printed with every result, e.g. "laika-2018".
  std::string name;
  /// One line for people.
  std::string description;
  /// File it was loaded from (empty when built in code).
  std::filesystem::path source_path;

  /// Encoder counts per revolution of the motor's rotor (before the gearbox), counting
  /// every edge the firmware counts (e.g. 12 for a 3-pulse magnetic encoder in 4x mode).
  double encoder_counts_per_motor_rev = 0.0;
  /// Motor revolutions per gearbox output-shaft revolution (1000 for 1000:1).
  double gearbox_ratio = 0.0;
  /// Output-shaft revolutions per revolution of the rotating vertebra's driven half (4).
  double spur_gear_ratio = 0.0;

  /// Radius of each spool groove, m; cables 1..4 of a group (v1-v2 .. v4-v5), ratio
  /// 1-1-2-3 on the 2018 hardware.
  std::array<double, kSpoolGrooves> spool_groove_radii_m{};
  /// Length of the cable on each groove at zero length change, m (what "percent length
  /// change" is a percentage of).
  std::array<double, kSpoolGrooves> cable_lengths_m{};

  /// Paper Table I.
  std::vector<MaterialConstant> materials;
  /// Paper Table III, in order low .. high.
  std::vector<TensionPoint> tension_points;

  /// Where each number comes from (measured, paper, assumed), keyed by field name.
  std::map<std::string, std::string> notes;

  /// Checks every field: positive constants, ordered tension points, finite values.
  /// kInvalidArgument naming the field.
  Status Validate() const;

  /// "laika-2018 (calib/laika-2018.json)".
  std::string Brief() const;

  // Conversions. Angles in radians, signs preserved.
  /// Rotor angle from encoder counts: counts / counts_per_rev * 2 pi.
  double MotorAngleFromCounts(int64_t counts) const;
  /// Output-shaft angle from rotor angle: motor / gearbox_ratio.
  double ShaftAngleFromMotorAngle(double motor_rad) const;
  /// Output-shaft angle from encoder counts.
  double ShaftAngleFromCounts(int64_t counts) const;
  /// Inverse of ShaftAngleFromCounts, rounded to the nearest count (for emulators).
  int64_t CountsFromShaftAngle(double shaft_rad) const;
  /// Rotating vertebra angle from its motor's output-shaft angle: shaft / spur_gear_ratio.
  double VertebraAngleFromShaftAngle(double shaft_rad) const;
  /// Inverse of VertebraAngleFromShaftAngle.
  double ShaftAngleFromVertebraAngle(double vertebra_rad) const;
  /// Rotating vertebra angle from its motor's encoder counts.
  double VertebraAngleFromCounts(int64_t counts) const;
  /// Bending spool angle from its motor's output-shaft angle (direct drive: equal).
  double SpoolAngleFromShaftAngle(double shaft_rad) const { return shaft_rad; }
  /// Shortening of each cable of the group for a spool angle, m (positive = shorter).
  std::array<double, kSpoolGrooves> CableShorteningFromSpoolAngle(double spool_rad) const;
  /// Percent length change of each cable for a spool angle: -100 * shortening / length
  /// (negative = shorter; -20 means the cable is at 80 % of its length).
  std::array<double, kSpoolGrooves> PercentLengthChangeFromSpoolAngle(double spool_rad) const;

  /// The tension point named `name`, or nullptr.
  const TensionPoint* FindTensionPoint(std::string_view name) const;
  /// The material named `name`, or nullptr.
  const MaterialConstant* FindMaterial(std::string_view name) const;
};

/// Loads and validates a calibration file. Unknown keys, missing fields and bad values
/// are errors naming the file and JSON path.
Result<Calibration> LoadCalibration(const std::filesystem::path& path);
/// The same from parsed JSON; `source` names it in errors.
Result<Calibration> CalibrationFromJson(const nlohmann::json& document, const std::string& source);
/// The calibration as JSON in the file format (round-trips through CalibrationFromJson).
nlohmann::json CalibrationToJson(const Calibration& calibration);

/// The calibration used when none is named: $LIFTOFF_CALIBRATION if set, else
/// calib/laika-2018.json in the source tree this binary was built from.
std::filesystem::path DefaultCalibrationPath();

}  // namespace liftoff
