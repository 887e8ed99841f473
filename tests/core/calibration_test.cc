#include "liftoff/core/calibration.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"
#include "support/test_support.h"

namespace liftoff {
namespace {

using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::WriteFile;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kPi = std::numbers::pi;

std::filesystem::path ShippedPath() {
  return liftoff::testing::SourceDir() / "calib" / "laika-2018.json";
}

// Round numbers for hand computation: 12 counts per rotor turn, 1000:1, 4:1, grooves of
// 1, 1, 2 and 3 cm on cables of 10 cm.
Calibration RoundCalibration() {
  Calibration calibration;
  calibration.name = "round";
  calibration.encoder_counts_per_motor_rev = 12;
  calibration.gearbox_ratio = 1000;
  calibration.spur_gear_ratio = 4;
  calibration.spool_groove_radii_m = {0.01, 0.01, 0.02, 0.03};
  calibration.cable_lengths_m = {0.1, 0.1, 0.1, 0.1};
  calibration.materials = {{"silicone", 237, 11}};
  calibration.tension_points = {{"low", -1, 200, 500, 187}, {"high", 1, 250, 900, 187}};
  return calibration;
}

// The shipped file as JSON, for tests that break one field of it.
json ShippedJson() { return LoadJsonFile(ShippedPath()).value(); }

Status FromJsonStatus(const json& document) {
  return CalibrationFromJson(document, "calib.json").status();
}

// --- conversions -----------------------------------------------------------------------

TEST(Calibration, MotorAngleIsCountsOverCountsPerRev) {
  const Calibration calibration = RoundCalibration();
  EXPECT_DOUBLE_EQ(calibration.MotorAngleFromCounts(12), 2 * kPi);
  EXPECT_DOUBLE_EQ(calibration.MotorAngleFromCounts(3), kPi / 2);
  EXPECT_DOUBLE_EQ(calibration.MotorAngleFromCounts(-6), -kPi);
  EXPECT_EQ(calibration.MotorAngleFromCounts(0), 0.0);
}

TEST(Calibration, ShaftAngleIsMotorAngleOverGearboxRatio) {
  const Calibration calibration = RoundCalibration();
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromMotorAngle(2000 * kPi), 2 * kPi);
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromMotorAngle(-1.0), -0.001);
}

TEST(Calibration, TwelveThousandCountsIsOneShaftTurnAndAQuarterVertebraTurn) {
  const Calibration calibration = RoundCalibration();
  // 12 counts/rev x 1000:1 = 12000 counts per output-shaft revolution
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromCounts(12000), 2 * kPi);
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromCounts(12000), kPi / 2);
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromCounts(-3000), -kPi / 2);
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromCounts(-3000), -kPi / 8);
}

TEST(Calibration, VertebraAngleIsShaftAngleOverSpurRatio) {
  const Calibration calibration = RoundCalibration();
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromShaftAngle(1.0), 0.25);
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromShaftAngle(-2.2), -0.55);
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromVertebraAngle(0.25), 1.0);
  EXPECT_DOUBLE_EQ(calibration.ShaftAngleFromVertebraAngle(-kPi / 3), -4 * kPi / 3);
}

TEST(Calibration, CountsFromShaftAngleRoundsToNearestCount) {
  const Calibration calibration = RoundCalibration();
  EXPECT_EQ(calibration.CountsFromShaftAngle(2 * kPi), 12000);
  EXPECT_EQ(calibration.CountsFromShaftAngle(-kPi), -6000);
  const double one_count_rad = 2 * kPi / 12000;
  EXPECT_EQ(calibration.CountsFromShaftAngle(0.4 * one_count_rad), 0);
  EXPECT_EQ(calibration.CountsFromShaftAngle(0.6 * one_count_rad), 1);
  EXPECT_EQ(calibration.CountsFromShaftAngle(-0.6 * one_count_rad), -1);
  for (int64_t counts : {0, 1, -1, 11999, 123456, -987654}) {
    EXPECT_EQ(calibration.CountsFromShaftAngle(calibration.ShaftAngleFromCounts(counts)), counts);
  }
}

TEST(Calibration, SpoolTurnsWithItsShaft) {
  EXPECT_EQ(RoundCalibration().SpoolAngleFromShaftAngle(1.25), 1.25);
}

TEST(Calibration, GroovesShortenCablesByRadiusTimesAngle) {
  const auto shortening_m = RoundCalibration().CableShorteningFromSpoolAngle(0.5);
  EXPECT_DOUBLE_EQ(shortening_m[0], 0.005);
  EXPECT_DOUBLE_EQ(shortening_m[1], 0.005);
  EXPECT_DOUBLE_EQ(shortening_m[2], 0.010);
  EXPECT_DOUBLE_EQ(shortening_m[3], 0.015);
}

TEST(Calibration, PercentLengthChangeIsNegativeWhenShortened) {
  const Calibration calibration = RoundCalibration();
  const auto percent = calibration.PercentLengthChangeFromSpoolAngle(0.5);
  EXPECT_DOUBLE_EQ(percent[0], -5.0);
  EXPECT_DOUBLE_EQ(percent[1], -5.0);
  EXPECT_DOUBLE_EQ(percent[2], -10.0);
  EXPECT_DOUBLE_EQ(percent[3], -15.0);
  // turning back lets the cables out
  const auto back = calibration.PercentLengthChangeFromSpoolAngle(-0.2);
  EXPECT_DOUBLE_EQ(back[0], 2.0);
  EXPECT_DOUBLE_EQ(back[3], 6.0);
}

TEST(Calibration, PercentLengthChangeUsesEachCablesOwnLength) {
  Calibration calibration = RoundCalibration();
  calibration.cable_lengths_m = {0.1, 0.2, 0.05, 0.3};
  const auto percent = calibration.PercentLengthChangeFromSpoolAngle(1.0);
  EXPECT_DOUBLE_EQ(percent[0], -10.0);  // 0.01 of 0.1
  EXPECT_DOUBLE_EQ(percent[1], -5.0);   // 0.01 of 0.2
  EXPECT_DOUBLE_EQ(percent[2], -40.0);  // 0.02 of 0.05
  EXPECT_DOUBLE_EQ(percent[3], -10.0);  // 0.03 of 0.3
}

TEST(Calibration, FindsMaterialsAndTensionPointsByName) {
  const Calibration calibration = RoundCalibration();
  ASSERT_NE(calibration.FindMaterial("silicone"), nullptr);
  EXPECT_EQ(calibration.FindMaterial("silicone")->stiffness_n_per_m, 237);
  EXPECT_EQ(calibration.FindMaterial("steel"), nullptr);
  ASSERT_NE(calibration.FindTensionPoint("high"), nullptr);
  EXPECT_EQ(calibration.FindTensionPoint("high")->buna_n_n_per_m, 900);
  EXPECT_EQ(calibration.FindTensionPoint("mean"), nullptr);
}

TEST(Calibration, BriefNamesCalibrationAndFile) {
  Calibration calibration = RoundCalibration();
  EXPECT_THAT(calibration.Brief(), StartsWith("round"));
  calibration.source_path = "calib/round.json";
  EXPECT_EQ(calibration.Brief(), "round (calib/round.json)");
}

// --- the shipped 2018 calibration ------------------------------------------------------

TEST(Laika2018Calibration, LoadsAndValidates) {
  const Result<Calibration> calibration = LoadCalibration(ShippedPath());
  ASSERT_TRUE(calibration.ok()) << calibration.status().ToString();
  EXPECT_EQ(calibration->name, "laika-2018");
  EXPECT_EQ(calibration->source_path, ShippedPath());
  EXPECT_TRUE(calibration->Validate().ok());
  // the name first, then the file it came from (relative when under the working folder)
  EXPECT_THAT(calibration->Brief(), ::testing::StartsWith("laika-2018 ("));
  EXPECT_THAT(calibration->Brief(), ::testing::EndsWith("calib/laika-2018.json)"));
}

TEST(Laika2018Calibration, HasThePapersDriveChain) {
  const Calibration calibration = LoadCalibration(ShippedPath()).value();
  EXPECT_EQ(calibration.gearbox_ratio, 1000);               // paper: 1000:1 gearbox
  EXPECT_EQ(calibration.spur_gear_ratio, 4);                // paper: 4:1 spur gear pair
  EXPECT_EQ(calibration.encoder_counts_per_motor_rev, 12);  // assumed
  // the 2018 authors' rule: vertebra angle = 0.25 x logged shaft angle
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromShaftAngle(1.84), 0.46);
  EXPECT_DOUBLE_EQ(calibration.VertebraAngleFromCounts(12000), kPi / 2);
}

TEST(Laika2018Calibration, HasSpoolGroovesInRatio1123) {
  const Calibration calibration = LoadCalibration(ShippedPath()).value();
  const auto& radii_m = calibration.spool_groove_radii_m;
  EXPECT_DOUBLE_EQ(radii_m[0], 0.004);
  EXPECT_DOUBLE_EQ(radii_m[1] / radii_m[0], 1.0);
  EXPECT_DOUBLE_EQ(radii_m[2] / radii_m[0], 2.0);
  EXPECT_DOUBLE_EQ(radii_m[3] / radii_m[0], 3.0);
  for (double length_m : calibration.cable_lengths_m) EXPECT_DOUBLE_EQ(length_m, 0.088);
  // one spool radian: 0.004/0.088 = 1/22 of the cable, -100/22 = -50/11 percent, per unit
  const auto percent = calibration.PercentLengthChangeFromSpoolAngle(1.0);
  EXPECT_NEAR(percent[0], -50.0 / 11.0, 1e-12);
  EXPECT_NEAR(percent[1], -50.0 / 11.0, 1e-12);
  EXPECT_NEAR(percent[2], -100.0 / 11.0, 1e-12);
  EXPECT_NEAR(percent[3], -150.0 / 11.0, 1e-12);
}

TEST(Laika2018Calibration, HasTableIMaterials) {
  const Calibration calibration = LoadCalibration(ShippedPath()).value();
  ASSERT_EQ(calibration.materials.size(), 3u);
  const MaterialConstant* silicone = calibration.FindMaterial("silicone");
  const MaterialConstant* buna_n = calibration.FindMaterial("buna_n");
  const MaterialConstant* spring = calibration.FindMaterial("spring");
  ASSERT_TRUE(silicone && buna_n && spring);
  EXPECT_EQ(silicone->stiffness_n_per_m, 237);
  EXPECT_EQ(silicone->stiffness_stddev_n_per_m, 11);
  EXPECT_EQ(buna_n->stiffness_n_per_m, 810);
  EXPECT_EQ(buna_n->stiffness_stddev_n_per_m, 132);
  EXPECT_EQ(spring->stiffness_n_per_m, 187);
  EXPECT_EQ(spring->stiffness_stddev_n_per_m, 0);
}

TEST(Laika2018Calibration, HasTableIIITensionPointsInOrder) {
  const Calibration calibration = LoadCalibration(ShippedPath()).value();
  struct Expected {
    const char* name;
    double sigma, silicone, buna_n;
  };
  const Expected expected[] = {{"low", -2, 216, 547},
                               {"med-low", -1, 227, 678},
                               {"mean", 0, 237, 810},
                               {"med-high", 1, 248, 941},
                               {"high", 2, 258, 1073}};
  ASSERT_EQ(calibration.tension_points.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    const TensionPoint& point = calibration.tension_points[i];
    EXPECT_EQ(point.name, expected[i].name);
    EXPECT_EQ(point.sigma, expected[i].sigma) << point.name;
    EXPECT_EQ(point.silicone_n_per_m, expected[i].silicone) << point.name;
    EXPECT_EQ(point.buna_n_n_per_m, expected[i].buna_n) << point.name;
    EXPECT_EQ(point.spring_n_per_m, 187) << point.name;
  }
}

TEST(Laika2018Calibration, NotesSayWhatIsAssumed) {
  const Calibration calibration = LoadCalibration(ShippedPath()).value();
  const auto& notes = calibration.notes;
  ASSERT_TRUE(notes.count("/motor/encoder_counts_per_motor_rev"));
  EXPECT_THAT(notes.at("/motor/encoder_counts_per_motor_rev"), HasSubstr("assumed"));
  ASSERT_TRUE(notes.count("/bending_spool/groove_radii_m"));
  EXPECT_THAT(notes.at("/bending_spool/groove_radii_m"), HasSubstr("assumed"));
  ASSERT_TRUE(notes.count("/rotating_vertebra/spur_gear_ratio"));
  EXPECT_THAT(notes.at("/rotating_vertebra/spur_gear_ratio"), HasSubstr("0.625/1.5"));
  ASSERT_TRUE(notes.count("/bending_spool/cable_lengths_m"));
  EXPECT_THAT(notes.at("/bending_spool/cable_lengths_m"), HasSubstr("0.088"));
}

TEST(Laika2018Calibration, IsTheDefault) {
  const char* saved = std::getenv("LIFTOFF_CALIBRATION");
  const std::string saved_value = saved ? saved : "";
  unsetenv("LIFTOFF_CALIBRATION");
  const std::filesystem::path path = DefaultCalibrationPath();
  EXPECT_EQ(path.filename(), "laika-2018.json");
  EXPECT_EQ(path.parent_path().filename(), "calib");
  EXPECT_TRUE(std::filesystem::exists(path)) << path;
  setenv("LIFTOFF_CALIBRATION", "/somewhere/else.json", 1);
  EXPECT_EQ(DefaultCalibrationPath(), "/somewhere/else.json");
  if (saved) {
    setenv("LIFTOFF_CALIBRATION", saved_value.c_str(), 1);
  } else {
    unsetenv("LIFTOFF_CALIBRATION");
  }
}

// --- the file format -------------------------------------------------------------------

TEST(CalibrationFile, RoundTripsThroughJson) {
  Calibration original = RoundCalibration();
  original.description = "for tests";
  original.notes["/motor/gearbox_ratio"] = "datasheet";
  const Result<Calibration> copy = CalibrationFromJson(CalibrationToJson(original), "copy");
  ASSERT_TRUE(copy.ok()) << copy.status().ToString();
  EXPECT_EQ(copy->name, "round");
  EXPECT_EQ(copy->description, "for tests");
  EXPECT_EQ(copy->encoder_counts_per_motor_rev, 12);
  EXPECT_EQ(copy->gearbox_ratio, 1000);
  EXPECT_EQ(copy->spur_gear_ratio, 4);
  EXPECT_EQ(copy->spool_groove_radii_m, original.spool_groove_radii_m);
  EXPECT_EQ(copy->cable_lengths_m, original.cable_lengths_m);
  ASSERT_EQ(copy->materials.size(), 1u);
  EXPECT_EQ(copy->materials[0].stiffness_stddev_n_per_m, 11);
  ASSERT_EQ(copy->tension_points.size(), 2u);
  EXPECT_EQ(copy->tension_points[1].name, "high");
  EXPECT_EQ(copy->tension_points[1].buna_n_n_per_m, 900);
  EXPECT_EQ(copy->notes, original.notes);
}

TEST(CalibrationFile, ShippedFileIsWhatToJsonWrites) {
  const json shipped = ShippedJson();
  EXPECT_EQ(CalibrationToJson(CalibrationFromJson(shipped, "shipped").value()), shipped);
}

TEST(CalibrationFile, WrittenFileLoadsWithItsPath) {
  ScratchDir dir;
  ASSERT_TRUE(WriteJsonFile(dir / "round.json", CalibrationToJson(RoundCalibration())).ok());
  const Result<Calibration> loaded = LoadCalibration(dir / "round.json");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->Brief(), "round (" + (dir / "round.json").string() + ")");
}

TEST(CalibrationFile, MissingFileIsNotFoundNamingIt) {
  ScratchDir dir;
  const Result<Calibration> calibration = LoadCalibration(dir / "nope.json");
  ASSERT_FALSE(calibration.ok());
  EXPECT_EQ(calibration.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(calibration.status().message(), HasSubstr((dir / "nope.json").string()));
}

TEST(CalibrationFile, SyntaxErrorNamesFileAndLine) {
  ScratchDir dir;
  WriteFile(dir / "broken.json",
            "{\n  \"format\": \"liftoff-calibration\",\n  \"version\": 1\n  \"name\": \"x\"\n}\n");
  const Result<Calibration> calibration = LoadCalibration(dir / "broken.json");
  ASSERT_FALSE(calibration.ok());
  EXPECT_EQ(calibration.status().code(), StatusCode::kParse);
  EXPECT_THAT(calibration.status().message(), StartsWith((dir / "broken.json").string() + ":4:"));
}

TEST(CalibrationFile, UnknownKeyNamesFileAndPointer) {
  ScratchDir dir;
  json document = ShippedJson();
  document["motor"]["gear_ratio"] = 1000;
  ASSERT_TRUE(WriteJsonFile(dir / "typo.json", document).ok());
  const Status status = LoadCalibration(dir / "typo.json").status();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              StartsWith((dir / "typo.json").string() + ": /motor/gear_ratio: unknown key"));
}

TEST(CalibrationFile, UnknownTopLevelKeyIsRejected) {
  json document = ShippedJson();
  document["spur_ratio"] = 4;
  EXPECT_THAT(FromJsonStatus(document).message(),
              StartsWith("calib.json: /spur_ratio: unknown key"));
}

TEST(CalibrationFile, NegativeGearboxRatioNamesPointerAndRange) {
  json document = ShippedJson();
  document["motor"]["gearbox_ratio"] = -1000;
  const Status status = FromJsonStatus(document);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(),
            "calib.json: /motor/gearbox_ratio: expected a number in [0.01, 100000], got -1000");
}

// positive is not enough: 1e-320 (a denormal) turns every angle into infinity
TEST(CalibrationFile, RatiosAndStiffnessesOutsidePhysicalRangesAreRejected) {
  struct Case {
    std::string pointer;
    double value;
    std::string range;  // as docs/calibration.md gives it
  };
  for (const Case& c :
       {Case{"/motor/gearbox_ratio", 1e-320, "[0.01, 100000]"},
        Case{"/motor/gearbox_ratio", 1e300, "[0.01, 100000]"},
        Case{"/rotating_vertebra/spur_gear_ratio", 1e-320, "[0.01, 100000]"},
        Case{"/motor/encoder_counts_per_motor_rev", 0.5, "[1, 1e+07]"},
        Case{"/materials/0/stiffness_n_per_m", 1e300, "[0.001, 1e+07]"},
        Case{"/tension_points/0/spring_n_per_m", 1e-320, "[0.001, 1e+07]"}}) {
    SCOPED_TRACE(c.pointer);
    json document = ShippedJson();
    document[json::json_pointer(c.pointer)] = c.value;
    const Status status = FromJsonStatus(document);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(status.message(),
                StartsWith("calib.json: " + c.pointer + ": expected a number in " + c.range));
  }
}

TEST(CalibrationFile, ZeroCountsPerRevIsRejected) {
  json document = ShippedJson();
  document["motor"]["encoder_counts_per_motor_rev"] = 0;
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /motor/encoder_counts_per_motor_rev: expected a number in [1, 1e+07], got 0");
}

TEST(CalibrationFile, WrongTypeNamesPointer) {
  json document = ShippedJson();
  document["rotating_vertebra"]["spur_gear_ratio"] = "4:1";
  const Status status = FromJsonStatus(document);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(),
            "calib.json: /rotating_vertebra/spur_gear_ratio: expected a number, got \"4:1\"");
}

TEST(CalibrationFile, MissingFieldNamesPointer) {
  json document = ShippedJson();
  document["tension_points"][2].erase("buna_n_n_per_m");
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /tension_points/2/buna_n_n_per_m: missing required field");
}

TEST(CalibrationFile, GrooveRadiiNeedFourEntries) {
  json document = ShippedJson();
  document["bending_spool"]["groove_radii_m"] = {0.004, 0.004, 0.008};
  EXPECT_THAT(
      FromJsonStatus(document).message(),
      StartsWith("calib.json: /bending_spool/groove_radii_m: expected an array of 4 numbers"));
}

TEST(CalibrationFile, GrooveRadiusInMillimetresIsCaught) {
  json document = ShippedJson();
  document["bending_spool"]["groove_radii_m"][3] = 12;
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /bending_spool/groove_radii_m/3: expected a number in (0, 0.1], got 12");
}

TEST(CalibrationFile, TensionPointsOutOfOrderAreRejected) {
  json document = ShippedJson();
  std::swap(document["tension_points"][1], document["tension_points"][2]);  // med-low after mean
  const Status status = FromJsonStatus(document);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(),
              StartsWith("calib.json: /tension_points/2/sigma: expected more than the previous "
                         "point's 0, got -1"));
}

TEST(CalibrationFile, TensionPointStiffnessMustNotFallAsSigmaRises) {
  json document = ShippedJson();
  document["tension_points"][4]["buna_n_n_per_m"] = 900;  // below med-high's 941
  EXPECT_THAT(FromJsonStatus(document).message(),
              StartsWith("calib.json: /tension_points/4/buna_n_n_per_m: expected at least the "
                         "previous point's 941, got 900"));
}

TEST(CalibrationFile, DuplicateMaterialIsRejected) {
  json document = ShippedJson();
  document["materials"][2]["name"] = "silicone";
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /materials/2/name: material \"silicone\" is listed twice");
}

TEST(CalibrationFile, WrongFormatIsRejected) {
  json document = ShippedJson();
  document["format"] = "liftoff-manifest";
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /format: expected one of liftoff-calibration, got \"liftoff-manifest\"");
}

TEST(CalibrationFile, NewerVersionIsUnsupported) {
  json document = ShippedJson();
  document["version"] = 2;
  const Status status = FromJsonStatus(document);
  EXPECT_EQ(status.code(), StatusCode::kUnsupported);
  EXPECT_THAT(status.message(), StartsWith("calib.json: /version: calibration format version 2"));
}

TEST(CalibrationFile, NoteAboutAnUnknownFieldIsRejected) {
  json document = ShippedJson();
  document["notes"]["/motor/gear_ratio"] = "paper";
  EXPECT_THAT(
      FromJsonStatus(document).message(),
      StartsWith("calib.json: /notes/~1motor~1gear_ratio: expected the JSON pointer of a field"));
}

TEST(CalibrationFile, NoteMustBeText) {
  json document = ShippedJson();
  document["notes"]["/motor/gearbox_ratio"] = 1000;
  EXPECT_EQ(FromJsonStatus(document).message(),
            "calib.json: /notes/~1motor~1gearbox_ratio: expected a string, got 1000");
}

// --- Validate on calibrations built in code --------------------------------------------

TEST(CalibrationValidate, AcceptsAGoodCalibration) {
  EXPECT_TRUE(RoundCalibration().Validate().ok()) << RoundCalibration().Validate().ToString();
}

TEST(CalibrationValidate, EmptyCalibrationNamesTheFirstBadField) {
  const Status status = Calibration{}.Validate();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), StartsWith("/name:"));
}

TEST(CalibrationValidate, RejectsNonFiniteValues) {
  Calibration calibration = RoundCalibration();
  calibration.spur_gear_ratio = std::numeric_limits<double>::infinity();
  EXPECT_THAT(calibration.Validate().message(),
              StartsWith("/rotating_vertebra/spur_gear_ratio: expected a number in [0.01, 100000]"));
  calibration = RoundCalibration();
  calibration.cable_lengths_m[1] = std::nan("");
  EXPECT_THAT(calibration.Validate().message(), StartsWith("/bending_spool/cable_lengths_m/1:"));
}

TEST(CalibrationValidate, RejectsNegativeStandardDeviation) {
  Calibration calibration = RoundCalibration();
  calibration.materials[0].stiffness_stddev_n_per_m = -1;
  EXPECT_EQ(calibration.Validate().message(),
            "/materials/0/stiffness_stddev_n_per_m: expected a number in [0, 1e+07], got -1");
}

TEST(CalibrationValidate, RejectsDuplicateTensionPoint) {
  Calibration calibration = RoundCalibration();
  calibration.tension_points[1].name = "low";
  EXPECT_EQ(calibration.Validate().message(),
            "/tension_points/1/name: tension point \"low\" is listed twice");
}

TEST(CalibrationValidate, NeedsTensionPointsAndMaterials) {
  Calibration calibration = RoundCalibration();
  calibration.tension_points.clear();
  EXPECT_THAT(calibration.Validate().message(), StartsWith("/tension_points:"));
  calibration = RoundCalibration();
  calibration.materials.clear();
  EXPECT_THAT(calibration.Validate().message(), StartsWith("/materials:"));
}

TEST(CalibrationValidate, RejectsNoteThatIsNotAPointer) {
  Calibration calibration = RoundCalibration();
  calibration.notes["gearbox_ratio"] = "paper";
  EXPECT_THAT(calibration.Validate().message(),
              StartsWith("/notes/gearbox_ratio: expected the JSON pointer"));
  calibration.notes.clear();
  calibration.notes["/motor/gearbox_ratio"] = "";
  EXPECT_EQ(calibration.Validate().message(),
            "/notes/~1motor~1gearbox_ratio: expected a non-empty note");
}

}  // namespace
}  // namespace liftoff
