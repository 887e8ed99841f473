#include "liftoff/core/calibration.h"

#include "liftoff/core/file.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "liftoff/core/field_checker.h"
#include "liftoff/core/json.h"

namespace liftoff {
namespace {

using nlohmann::json;

constexpr std::string_view kFormatName = "liftoff-calibration";
constexpr int64_t kFormatVersion = 1;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Allowed values. Validate() checks them; docs/calibration.md lists them.
// A groove radius above 0.1 m, or a cable above 10 m, is almost always millimetres
// written as metres.
constexpr NumberRange kGrooveRadius{.min = 0.0, .max = 0.1, .min_exclusive = true};
constexpr NumberRange kCableLength{.min = 0.0, .max = 10.0, .min_exclusive = true};
constexpr NumberRange kSigma{.min = -10.0, .max = 10.0};
// Physical ranges, not only signs: a ratio of 1e-320 is positive but turns every angle
// into infinity. Encoders have 1 to millions of counts per revolution; gear ratios lie
// between 1:100 and 100000:1; cable materials lie between 1e-3 and 1e7 N/m.
constexpr NumberRange kCountsPerRev{.min = 1.0, .max = 1e7};
constexpr NumberRange kGearRatio{.min = 0.01, .max = 1e5};
constexpr NumberRange kStiffness{.min = 1e-3, .max = 1e7};
constexpr NumberRange kStiffnessSpread{.min = 0.0, .max = 1e7};

std::string Index(std::string_view array, size_t i) {
  return std::string(array) + "/" + std::to_string(i);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// checks

namespace {

// Calibration::Validate's parts, in the file's order; each records the first problem

void CheckMaterials(const std::vector<MaterialConstant>& materials, FieldChecker& check) {
  if (materials.empty()) check.Fail("/materials", "expected at least one material");
  std::set<std::string, std::less<>> names;
  for (size_t i = 0; i < materials.size(); ++i) {
    const std::string where = Index("/materials", i);
    const MaterialConstant& material = materials[i];
    if (material.name.empty()) check.Fail(where + "/name", "expected a non-empty name");
    if (!names.insert(material.name).second) {
      check.Fail(where + "/name", "material \"" + material.name + "\" is listed twice");
    }
    check.Number(where + "/stiffness_n_per_m", material.stiffness_n_per_m, kStiffness);
    check.Number(where + "/stiffness_stddev_n_per_m", material.stiffness_stddev_n_per_m,
                 kStiffnessSpread);
  }
}

// a tension point against the one before: the lattice stiffens with sigma, so both
// elastomers must rise (or stay) with it
void CheckTensionOrder(const TensionPoint& point, const TensionPoint& previous,
                       const std::string& where, FieldChecker& check) {
  const std::string order = "; tension points run from low to high tension";
  if (!(point.sigma > previous.sigma)) {
    check.Fail(where + "/sigma", "expected more than the previous point's " +
                                     FormatNumber(previous.sigma) + ", got " +
                                     FormatNumber(point.sigma) + order);
  }
  if (point.silicone_n_per_m < previous.silicone_n_per_m) {
    check.Fail(where + "/silicone_n_per_m", "expected at least the previous point's " +
                                                FormatNumber(previous.silicone_n_per_m) + ", got " +
                                                FormatNumber(point.silicone_n_per_m) + order);
  }
  if (point.buna_n_n_per_m < previous.buna_n_n_per_m) {
    check.Fail(where + "/buna_n_n_per_m", "expected at least the previous point's " +
                                              FormatNumber(previous.buna_n_n_per_m) + ", got " +
                                              FormatNumber(point.buna_n_n_per_m) + order);
  }
}

// tension points: named once each, in order low .. high
void CheckTensionPoints(const std::vector<TensionPoint>& points, FieldChecker& check) {
  if (points.empty()) check.Fail("/tension_points", "expected at least one tension point");
  std::set<std::string, std::less<>> names;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::string where = Index("/tension_points", i);
    const TensionPoint& point = points[i];
    if (point.name.empty()) check.Fail(where + "/name", "expected a non-empty name");
    if (!names.insert(point.name).second) {
      check.Fail(where + "/name", "tension point \"" + point.name + "\" is listed twice");
    }
    check.Number(where + "/sigma", point.sigma, kSigma);
    check.Number(where + "/silicone_n_per_m", point.silicone_n_per_m, kStiffness);
    check.Number(where + "/buna_n_n_per_m", point.buna_n_n_per_m, kStiffness);
    check.Number(where + "/spring_n_per_m", point.spring_n_per_m, kStiffness);
    if (i > 0) CheckTensionOrder(point, points[i - 1], where, check);
  }
}

// notes: each names a field of the file format (in `document`) and says something
void CheckNotes(const std::map<std::string, std::string>& notes, const json& document,
                FieldChecker& check) {
  for (const auto& [field, provenance] : notes) {
    const std::string where = "/notes/" + JsonPointerEscape(field);
    bool known = false;
    try {
      known = field.rfind("/notes", 0) != 0 && document.contains(json::json_pointer(field));
    } catch (const json::exception&) {
      known = false;  // not a JSON pointer at all
    }
    if (!known) {
      check.Fail(where,
                 "expected the JSON pointer of a field of this file, such as "
                 "\"/motor/gearbox_ratio\"");
    }
    if (provenance.empty()) check.Fail(where, "expected a non-empty note");
  }
}

}  // namespace

Status Calibration::Validate() const {
  // the first problem, named by the field's JSON pointer in the file format
  FieldChecker check;
  // name and the drive chain
  if (name.empty()) check.Fail("/name", "expected a non-empty name");
  if (name.find_first_of("\r\n") != std::string::npos) check.Fail("/name", "expected one line");
  check.Number("/motor/encoder_counts_per_motor_rev", encoder_counts_per_motor_rev, kCountsPerRev);
  check.Number("/motor/gearbox_ratio", gearbox_ratio, kGearRatio);
  check.Number("/rotating_vertebra/spur_gear_ratio", spur_gear_ratio, kGearRatio);

  // the bending spool
  for (size_t i = 0; i < kSpoolGrooves; ++i) {
    check.Number(Index("/bending_spool/groove_radii_m", i), spool_groove_radii_m[i], kGrooveRadius);
    check.Number(Index("/bending_spool/cable_lengths_m", i), cable_lengths_m[i], kCableLength);
  }

  CheckMaterials(materials, check);
  CheckTensionPoints(tension_points, check);
  if (!notes.empty() && check.ok()) CheckNotes(notes, CalibrationToJson(*this), check);
  return check.status();
}

std::string Calibration::Brief() const {
  if (source_path.empty()) return name + " (built in code)";
  return name + " (" + DisplayPath(source_path) + ")";
}

// ---------------------------------------------------------------------------------------
// conversions

double Calibration::MotorAngleFromCounts(int64_t counts) const {
  return static_cast<double>(counts) / encoder_counts_per_motor_rev * kTwoPi;
}

double Calibration::ShaftAngleFromMotorAngle(double motor_rad) const {
  return motor_rad / gearbox_ratio;
}

double Calibration::ShaftAngleFromCounts(int64_t counts) const {
  // one division by counts per shaft revolution: whole revolutions come out exact
  return static_cast<double>(counts) / (encoder_counts_per_motor_rev * gearbox_ratio) * kTwoPi;
}

int64_t Calibration::CountsFromShaftAngle(double shaft_rad) const {
  return std::llround(shaft_rad / kTwoPi * (encoder_counts_per_motor_rev * gearbox_ratio));
}

double Calibration::VertebraAngleFromShaftAngle(double shaft_rad) const {
  return shaft_rad / spur_gear_ratio;
}

double Calibration::ShaftAngleFromVertebraAngle(double vertebra_rad) const {
  return vertebra_rad * spur_gear_ratio;
}

double Calibration::VertebraAngleFromCounts(int64_t counts) const {
  return VertebraAngleFromShaftAngle(ShaftAngleFromCounts(counts));
}

std::array<double, kSpoolGrooves> Calibration::CableShorteningFromSpoolAngle(
    double spool_rad) const {
  std::array<double, kSpoolGrooves> shortening_m{};
  for (size_t i = 0; i < kSpoolGrooves; ++i) shortening_m[i] = spool_groove_radii_m[i] * spool_rad;
  return shortening_m;
}

std::array<double, kSpoolGrooves> Calibration::PercentLengthChangeFromSpoolAngle(
    double spool_rad) const {
  const std::array<double, kSpoolGrooves> shortening_m = CableShorteningFromSpoolAngle(spool_rad);
  std::array<double, kSpoolGrooves> percent{};
  for (size_t i = 0; i < kSpoolGrooves; ++i)
    percent[i] = -100.0 * shortening_m[i] / cable_lengths_m[i];
  return percent;
}

const TensionPoint* Calibration::FindTensionPoint(std::string_view point_name) const {
  for (const TensionPoint& point : tension_points) {
    if (point.name == point_name) return &point;
  }
  return nullptr;
}

const MaterialConstant* Calibration::FindMaterial(std::string_view material_name) const {
  for (const MaterialConstant& material : materials) {
    if (material.name == material_name) return &material;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------
// the file format

Result<Calibration> CalibrationFromJson(const json& document, const std::string& source) {
  JsonReader root(document, source);
  // what kind of file this is, before anything else in it
  root.Enum("format", {kFormatName});
  const int64_t version = root.Integer("version");
  if (root.failed()) return root.Finish();
  if (version != kFormatVersion) {
    return UnsupportedError(root.Where("version") + ": calibration format version " +
                            std::to_string(version) + " is not supported; expected " +
                            std::to_string(kFormatVersion));
  }

  // types, missing fields and unknown keys here; values in Validate()
  Calibration calibration;
  calibration.name = root.String("name");
  calibration.description = root.OptionalString("description").value_or("");

  JsonReader motor = root.Object("motor");
  calibration.encoder_counts_per_motor_rev = motor.Number("encoder_counts_per_motor_rev");
  calibration.gearbox_ratio = motor.Number("gearbox_ratio");

  JsonReader rotating_vertebra = root.Object("rotating_vertebra");
  calibration.spur_gear_ratio = rotating_vertebra.Number("spur_gear_ratio");

  JsonReader spool = root.Object("bending_spool");
  const std::vector<double> radii_m = spool.NumberArray("groove_radii_m", kSpoolGrooves);
  const std::vector<double> lengths_m = spool.NumberArray("cable_lengths_m", kSpoolGrooves);
  if (radii_m.size() == kSpoolGrooves) {
    std::copy(radii_m.begin(), radii_m.end(), calibration.spool_groove_radii_m.begin());
  }
  if (lengths_m.size() == kSpoolGrooves) {
    std::copy(lengths_m.begin(), lengths_m.end(), calibration.cable_lengths_m.begin());
  }

  for (JsonReader& entry : root.ObjectArray("materials")) {
    MaterialConstant& material = calibration.materials.emplace_back();
    material.name = entry.String("name");
    material.stiffness_n_per_m = entry.Number("stiffness_n_per_m");
    material.stiffness_stddev_n_per_m = entry.Number("stiffness_stddev_n_per_m");
  }

  for (JsonReader& entry : root.ObjectArray("tension_points")) {
    TensionPoint& point = calibration.tension_points.emplace_back();
    point.name = entry.String("name");
    point.sigma = entry.Number("sigma");
    point.silicone_n_per_m = entry.Number("silicone_n_per_m");
    point.buna_n_n_per_m = entry.Number("buna_n_n_per_m");
    point.spring_n_per_m = entry.Number("spring_n_per_m");
  }

  // notes: free-form keys (JSON pointers), string values
  if (std::optional<JsonReader> notes = root.OptionalObject("notes")) {
    const json* object = root.Raw("notes");
    notes->AcceptAnyKeys();
    if (object != nullptr && object->is_object()) {
      for (const auto& item : object->items())
        calibration.notes[item.key()] = notes->String(item.key());
    }
  }

  LIFTOFF_RETURN_IF_ERROR(root.Finish());
  LIFTOFF_RETURN_IF_ERROR(calibration.Validate().WithContext(source));
  return calibration;
}

json CalibrationToJson(const Calibration& calibration) {
  json document = json::object();
  document["format"] = kFormatName;
  document["version"] = kFormatVersion;
  document["name"] = calibration.name;
  if (!calibration.description.empty()) document["description"] = calibration.description;
  document["motor"] = {{"encoder_counts_per_motor_rev", calibration.encoder_counts_per_motor_rev},
                       {"gearbox_ratio", calibration.gearbox_ratio}};
  document["rotating_vertebra"] = {{"spur_gear_ratio", calibration.spur_gear_ratio}};
  document["bending_spool"] = {{"groove_radii_m", calibration.spool_groove_radii_m},
                               {"cable_lengths_m", calibration.cable_lengths_m}};
  json materials = json::array();
  for (const MaterialConstant& material : calibration.materials) {
    materials.push_back({{"name", material.name},
                         {"stiffness_n_per_m", material.stiffness_n_per_m},
                         {"stiffness_stddev_n_per_m", material.stiffness_stddev_n_per_m}});
  }
  document["materials"] = std::move(materials);
  json points = json::array();
  for (const TensionPoint& point : calibration.tension_points) {
    points.push_back({{"name", point.name},
                      {"sigma", point.sigma},
                      {"silicone_n_per_m", point.silicone_n_per_m},
                      {"buna_n_n_per_m", point.buna_n_n_per_m},
                      {"spring_n_per_m", point.spring_n_per_m}});
  }
  document["tension_points"] = std::move(points);
  if (!calibration.notes.empty()) document["notes"] = calibration.notes;
  return document;
}

Result<Calibration> LoadCalibration(const std::filesystem::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(json document, LoadJsonFile(path));
  LIFTOFF_ASSIGN_OR_RETURN(Calibration calibration, CalibrationFromJson(document, path.string()));
  calibration.source_path = path;
  return calibration;
}

std::filesystem::path DefaultCalibrationPath() {
  if (const char* path = std::getenv("LIFTOFF_CALIBRATION"); path != nullptr && *path != '\0') {
    return path;
  }
  return std::filesystem::path(LIFTOFF_SOURCE_DIR) / "calib" / "laika-2018.json";
}

}  // namespace liftoff
