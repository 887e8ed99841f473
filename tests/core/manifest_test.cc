#include "liftoff/core/manifest.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace liftoff {
namespace {

using ::testing::HasSubstr;
using testing::ReadFile;
using testing::ScratchDir;
using testing::WriteFile;
namespace fs = std::filesystem;

// Every field the format has, paths relative to the manifest, one absolute.
constexpr char kFullManifest[] = R"({
  "format": "liftoff-manifest",
  "version": 1,
  "description": "2018 foot-lifting tests",
  "calibration": "../calib/laika-2018.json",
  "trials": [
    {
      "id": "A1",
      "foot": "A",
      "test": 1,
      "pulled_group": "HR",
      "rotation": "-",
      "log": {"path": "logs/Test1 Front Right Blue.txt", "format": "laika-2018"},
      "video": {"path": "videos/A1.mp4", "px_per_mm": 1.38},
      "times": {"led_on_s": 1.25, "liftoff_s": 9.27, "led_on_uncertainty_s": 0.017,
                "liftoff_uncertainty_s": 0.05, "source": "video"},
      "roi": {"led_px": [10, 20, 30, 40], "foot_px": [0, 0, 640, 360]},
      "notes": "first try"
    },
    {
      "id": "B2",
      "foot": "B",
      "log": {"path": "/data/b2.csv"},
      "times": {"led_on_s": 0, "liftoff_s": 8.02}
    }
  ]
})";

TEST(Manifest, LoadsAFullExampleWithResolvedPaths) {
  ScratchDir dir;
  WriteFile(dir / "set" / "trials.json", kFullManifest);
  const Result<TrialManifest> manifest = LoadManifest(dir / "set" / "trials.json");
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();

  EXPECT_EQ(manifest->source_path, dir / "set" / "trials.json");
  EXPECT_EQ(manifest->base_dir, dir / "set");
  EXPECT_EQ(manifest->description, "2018 foot-lifting tests");
  EXPECT_EQ(manifest->calibration_path, dir / "calib" / "laika-2018.json");
  ASSERT_EQ(manifest->trials.size(), 2u);

  const TrialRecord& a1 = manifest->trials[0];
  EXPECT_EQ(a1.id, "A1");
  EXPECT_EQ(a1.foot, Foot::kA);
  EXPECT_EQ(a1.test_number, 1);
  EXPECT_EQ(a1.pulled_group, CableGroup::kHR);
  EXPECT_EQ(a1.rotation, RotationSense::kNegative);
  EXPECT_EQ(a1.log_path, dir / "set" / "logs" / "Test1 Front Right Blue.txt");
  EXPECT_EQ(a1.log_format, LogFormat::kLaika2018);
  EXPECT_EQ(a1.video_path, dir / "set" / "videos" / "A1.mp4");
  ASSERT_TRUE(a1.times.has_value());
  EXPECT_EQ(a1.times->led_on_ns, 1'250'000'000);
  EXPECT_EQ(a1.times->liftoff_ns, 9'270'000'000);
  EXPECT_EQ(a1.times->led_on_uncertainty_ns, 17'000'000);
  EXPECT_EQ(a1.times->liftoff_uncertainty_ns, 50'000'000);
  EXPECT_EQ(a1.times->source, "video");
  ASSERT_TRUE(a1.led_roi_px.has_value());
  EXPECT_EQ(a1.led_roi_px->x_px, 10);
  EXPECT_EQ(a1.led_roi_px->y_px, 20);
  EXPECT_EQ(a1.led_roi_px->width_px, 30);
  EXPECT_EQ(a1.led_roi_px->height_px, 40);
  ASSERT_TRUE(a1.foot_roi_px.has_value());
  EXPECT_EQ(a1.foot_roi_px->width_px, 640);
  EXPECT_EQ(a1.notes, "first try");

  // defaults: liftoff format, no video, zero uncertainty, measured by hand
  const TrialRecord& b2 = manifest->trials[1];
  EXPECT_EQ(b2.foot, Foot::kB);
  EXPECT_EQ(b2.log_path, fs::path("/data/b2.csv"));
  EXPECT_EQ(b2.log_format, LogFormat::kLiftoff);
  EXPECT_FALSE(b2.test_number.has_value());
  EXPECT_FALSE(b2.pulled_group.has_value());
  EXPECT_FALSE(b2.rotation.has_value());
  EXPECT_FALSE(b2.video_path.has_value());
  ASSERT_TRUE(b2.times.has_value());
  EXPECT_EQ(b2.times->led_on_ns, 0);
  EXPECT_EQ(b2.times->liftoff_ns, 8'020'000'000);
  EXPECT_EQ(b2.times->led_on_uncertainty_ns, 0);
  EXPECT_EQ(b2.times->liftoff_uncertainty_ns, 0);
  EXPECT_EQ(b2.times->source, "hand");
  EXPECT_FALSE(b2.led_roi_px.has_value());
  EXPECT_TRUE(b2.notes.empty());
  EXPECT_TRUE(manifest->Validate().ok());
}

// A minimal valid manifest with one trial, for editing.
nlohmann::json OneTrial() {
  return nlohmann::json::parse(R"({
    "format": "liftoff-manifest", "version": 1,
    "trials": [{"id": "A1", "foot": "A", "log": {"path": "a1.csv"},
                "times": {"led_on_s": 1.0, "liftoff_s": 2.0},
                "roi": {"led_px": [1, 2, 3, 4]}}]
  })");
}

TEST(Manifest, EachMalformedFieldNamesItsJsonPointer) {
  struct Case {
    std::string pointer;  // where to put the bad value
    nlohmann::json value;
    std::string expected;
  };
  const Case cases[] = {
      {"/trials/0/foot", "E", "trials.json: /trials/0/foot: expected one of A, B, C, D, got \"E\""},
      {"/trials/0/id", 7, "trials.json: /trials/0/id: expected a string, got 7"},
      {"/trials/0/id", "", "trials.json: /trials/0/id: expected a non-empty id"},
      {"/trials/0/test", 0,
       "trials.json: /trials/0/test: expected an integer in [1, 1e+09], got 0"},
      {"/trials/0/test", 1.5,
       "trials.json: /trials/0/test: expected an integer in [1, 1e+09], got 1.5"},
      {"/trials/0/test", 3'000'000'000,
       "trials.json: /trials/0/test: expected an integer in [1, 1e+09], got 3e+09"},
      {"/trials/0/pulled_group", "HX",
       "trials.json: /trials/0/pulled_group: expected one of HR, HL, HT, HB, got \"HX\""},
      {"/trials/0/rotation", "cw",
       "trials.json: /trials/0/rotation: expected one of +, -, got \"cw\""},
      {"/trials/0/log/format", "tsv",
       "trials.json: /trials/0/log/format: expected one of liftoff, laika-2018, csv, got \"tsv\""},
      {"/trials/0/log/format", "csv", "trials.json: /trials/0/log/time_column: missing required field"},
      {"/trials/0/log/path", "", "trials.json: /trials/0/log/path: expected a non-empty path"},
      {"/trials/0/log", "a1.csv",
       "trials.json: /trials/0/log: expected a JSON object, got \"a1.csv\""},
      {"/trials/0/video", nlohmann::json::object(),
       "trials.json: /trials/0/video/path: missing required field"},
      {"/trials/0/times/led_on_s", "1.0",
       "trials.json: /trials/0/times/led_on_s: expected a number in [0, 1e+06], got \"1.0\""},
      {"/trials/0/times/liftoff_s", 0.5,
       "trials.json: /trials/0/times/liftoff_s: expected a time after led_on_s (1 s), got 0.5"},
      {"/trials/0/times/led_on_uncertainty_s", -0.1,
       "trials.json: /trials/0/times/led_on_uncertainty_s: expected a number in [0, 1e+06], got "
       "-0.1"},
      // beyond kMaxTimeSeconds: once converted to INT64_MIN nanoseconds without a word
      {"/trials/0/times/liftoff_s", 1e10,
       "trials.json: /trials/0/times/liftoff_s: expected a number in [0, 1e+06], got 1e+10"},
      {"/trials/0/times/liftoff_uncertainty_s", 1e10,
       "trials.json: /trials/0/times/liftoff_uncertainty_s: expected a number in [0, 1e+06], got "
       "1e+10"},
      {"/trials/0/roi/led_px", nlohmann::json::array({1, 2, 3}),
       "trials.json: /trials/0/roi/led_px: expected [x, y, width, height] in whole pixels"},
      {"/trials/0/roi/led_px", nlohmann::json::array({1, 2, 0, 4}),
       "trials.json: /trials/0/roi/led_px: expected [x, y, width, height] in whole pixels (x, y >= "
       "0; width, "
       "height >= 1), got [1,2,0,4]"},
      {"/trials/0/roi/led_px", nlohmann::json::array({1.5, 2, 3, 4}),
       "trials.json: /trials/0/roi/led_px: expected"},
      {"/trials", nlohmann::json::object(),
       "trials.json: /trials: expected an array of objects, got {}"},
      {"/description", 3, "trials.json: /description: expected a string, got 3"},
      {"/calibration", "", "trials.json: /calibration: expected a non-empty path"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.pointer + " = " + c.value.dump());
    nlohmann::json document = OneTrial();
    document[nlohmann::json::json_pointer(c.pointer)] = c.value;
    const Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
    ASSERT_FALSE(manifest.ok());
    EXPECT_EQ(manifest.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(manifest.status().message(), ::testing::StartsWith(c.expected));
  }
}

TEST(Manifest, MissingRequiredFieldsNameTheirPointer) {
  for (const std::string pointer :
       {"/trials/0/id", "/trials/0/foot", "/trials/0/log", "/trials/0/log/path",
        "/trials/0/times/led_on_s", "/trials", "/version"}) {
    SCOPED_TRACE(pointer);
    nlohmann::json document = OneTrial();
    const nlohmann::json::json_pointer where(pointer);
    document[where.parent_pointer()].erase(where.back());
    const Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
    ASSERT_FALSE(manifest.ok());
    EXPECT_EQ(manifest.status().message(), "trials.json: " + pointer + ": missing required field");
  }
}

TEST(Manifest, AcceptsEveryCableGroupAndBothRotations) {
  const std::pair<std::string, CableGroup> groups[] = {{"HR", CableGroup::kHR},
                                                       {"HL", CableGroup::kHL},
                                                       {"HT", CableGroup::kHT},
                                                       {"HB", CableGroup::kHB}};
  for (const auto& [name, group] : groups) {
    nlohmann::json document = OneTrial();
    document["trials"][0]["pulled_group"] = name;
    document["trials"][0]["rotation"] = name == "HR" ? "+" : "-";
    const Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
    ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
    EXPECT_EQ(manifest->trials[0].pulled_group, group);
    EXPECT_EQ(manifest->trials[0].rotation,
              name == "HR" ? RotationSense::kPositive : RotationSense::kNegative);
  }
}

TEST(Manifest, DuplicateIdsNameBothTrials) {
  nlohmann::json document = OneTrial();
  document["trials"].push_back(document["trials"][0]);
  document["trials"][1]["id"] = "B1";
  document["trials"].push_back(document["trials"][0]);
  const Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
  ASSERT_FALSE(manifest.ok());
  EXPECT_EQ(manifest.status().message(),
            "trials.json: trials[0] and trials[2] have the same id \"A1\"");
}

TEST(Manifest, UnknownKeysAreRejectedWhereverTheyAre) {
  const std::pair<std::string, std::string> cases[] = {
      {"/comment", "trials.json: /comment: unknown key"},
      {"/trials/0/feet", "trials.json: /trials/0/feet: unknown key"},
      {"/trials/0/log/fromat", "trials.json: /trials/0/log/fromat: unknown key"},
      {"/trials/0/times/led_s", "trials.json: /trials/0/times/led_s: unknown key"},
      {"/trials/0/roi/tape_px", "trials.json: /trials/0/roi/tape_px: unknown key"},
  };
  for (const auto& [pointer, expected] : cases) {
    SCOPED_TRACE(pointer);
    nlohmann::json document = OneTrial();
    document[nlohmann::json::json_pointer(pointer)] = 1;
    const Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
    ASSERT_FALSE(manifest.ok());
    EXPECT_THAT(manifest.status().message(), ::testing::StartsWith(expected));
  }
}

TEST(Manifest, OtherFormatsAndVersionsAreRefused) {
  nlohmann::json document = OneTrial();
  document["format"] = "liftoff-calibration";
  Result<TrialManifest> manifest = ManifestFromJson(document, "trials.json", "/data");
  ASSERT_FALSE(manifest.ok());
  EXPECT_EQ(manifest.status().message(),
            "trials.json: /format: expected one of liftoff-manifest, got \"liftoff-calibration\"");

  document = OneTrial();
  document["version"] = 2;
  manifest = ManifestFromJson(document, "trials.json", "/data");
  ASSERT_FALSE(manifest.ok());
  EXPECT_EQ(manifest.status().code(), StatusCode::kUnsupported);
  EXPECT_THAT(manifest.status().message(),
              HasSubstr("trials.json: /version: liftoff-manifest version 2"));
}

TEST(Manifest, MissingFileIsNotFoundAndBadJsonNamesTheLine) {
  ScratchDir dir;
  const Result<TrialManifest> missing = LoadManifest(dir / "trials.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("trials.json"));

  WriteFile(dir / "broken.json", "{\n  \"format\": \"liftoff-manifest\",\n  \"version\": 1,,\n}\n");
  const Result<TrialManifest> broken = LoadManifest(dir / "broken.json");
  ASSERT_FALSE(broken.ok());
  EXPECT_EQ(broken.status().code(), StatusCode::kParse);
  EXPECT_THAT(broken.status().message(), HasSubstr("broken.json:3:"));
}

TEST(Manifest, LoadErrorsNameTheFile) {
  ScratchDir dir;
  nlohmann::json document = OneTrial();
  document["trials"][0]["foot"] = "E";
  WriteFile(dir / "trials.json", document.dump());
  const Result<TrialManifest> manifest = LoadManifest(dir / "trials.json");
  ASSERT_FALSE(manifest.ok());
  EXPECT_EQ(
      manifest.status().message(),
      (dir / "trials.json").string() + ": /trials/0/foot: expected one of A, B, C, D, got \"E\"");
}

TEST(Manifest, ValidateCatchesWhatCodeCanBuild) {
  TrialManifest manifest;
  TrialRecord trial;
  trial.id = "A1";
  trial.log_path = "/data/a1.csv";
  trial.times = EventTimes{.led_on_ns = 1'000'000'000, .liftoff_ns = 3'000'000'000};
  manifest.trials = {trial, trial, trial};
  manifest.trials[1].id = "A2";
  Status status = manifest.Validate();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), "manifest: trials[0] and trials[2] have the same id \"A1\"");

  manifest.trials.resize(2);
  EXPECT_TRUE(manifest.Validate().ok());

  manifest.trials[1].times->liftoff_ns = 1'000'000'000;
  status = manifest.Validate();
  EXPECT_THAT(status.message(),
              HasSubstr("trials[1] (id \"A2\"): times: expected liftoff after LED on"));

  manifest.trials[1].times->liftoff_ns = 3'000'000'000;
  manifest.trials[1].times->liftoff_uncertainty_ns = -1;
  status = manifest.Validate();
  EXPECT_THAT(status.message(),
              HasSubstr("trials[1] (id \"A2\"): times: expected uncertainties >= 0"));

  manifest.trials[1].times->liftoff_uncertainty_ns = 0;
  manifest.trials[1].led_roi_px = RegionPx{0, 0, 0, 5};
  EXPECT_THAT(manifest.Validate().message(),
              HasSubstr("led region: expected width and height >= 1 px"));

  manifest.trials[1].led_roi_px.reset();
  manifest.trials[0].log_path.clear();
  EXPECT_THAT(manifest.Validate().message(),
              HasSubstr("trials[0] (id \"A1\"): expected a log path"));
}

TEST(Manifest, WritesPathsRelativeToItsFolderAndRoundTrips) {
  ScratchDir dir;
  const fs::path base = dir / "set";
  TrialManifest original;
  original.description = "round trip";
  original.calibration_path = dir / "calib" / "laika-2018.json";
  TrialRecord a;
  a.id = "C3";
  a.foot = Foot::kC;
  a.test_number = 3;
  a.pulled_group = CableGroup::kHL;
  a.rotation = RotationSense::kPositive;
  a.log_path = base / "logs" / "c3.txt";
  a.log_format = LogFormat::kLaika2018;
  a.video_path = base / "c3.mp4";
  a.times = EventTimes{.led_on_ns = 1'234'567'891,
                       .liftoff_ns = 9'876'543'210,
                       .led_on_uncertainty_ns = 16'666'667,
                       .liftoff_uncertainty_ns = 33'333'333,
                       .source = "video"};
  a.led_roi_px = RegionPx{5, 6, 7, 8};
  a.foot_roi_px = RegionPx{100, 200, 50, 60};
  a.notes = "re-run";
  TrialRecord b;
  b.id = "D1";
  b.foot = Foot::kD;
  b.log_path = "/elsewhere/d1.csv";
  original.trials = {a, b};
  fs::create_directories(base);
  const Status written_status = WriteManifest(base / "trials.json", original);
  ASSERT_TRUE(written_status.ok()) << written_status.ToString();

  // what a person sees: paths relative to the manifest's folder
  const nlohmann::json written = nlohmann::json::parse(ReadFile(base / "trials.json"));
  EXPECT_EQ(written["format"], "liftoff-manifest");
  EXPECT_EQ(written["version"], 1);
  EXPECT_EQ(written["calibration"], "../calib/laika-2018.json");
  EXPECT_EQ(written["trials"][0]["log"]["path"], "logs/c3.txt");
  EXPECT_EQ(written["trials"][0]["log"]["format"], "laika-2018");
  EXPECT_EQ(written["trials"][0]["video"]["path"], "c3.mp4");
  EXPECT_EQ(written["trials"][0]["times"]["led_on_s"], 1.234567891);
  EXPECT_EQ(written["trials"][0]["roi"]["foot_px"], nlohmann::json::array({100, 200, 50, 60}));
  EXPECT_EQ(written["trials"][1]["log"]["path"], "/elsewhere/d1.csv");
  EXPECT_FALSE(written["trials"][1].contains("times"));

  const Result<TrialManifest> read = LoadManifest(base / "trials.json");
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->description, original.description);
  EXPECT_EQ(read->calibration_path, original.calibration_path);
  ASSERT_EQ(read->trials.size(), 2u);
  const TrialRecord& got = read->trials[0];
  EXPECT_EQ(got.id, a.id);
  EXPECT_EQ(got.foot, a.foot);
  EXPECT_EQ(got.test_number, a.test_number);
  EXPECT_EQ(got.pulled_group, a.pulled_group);
  EXPECT_EQ(got.rotation, a.rotation);
  EXPECT_EQ(got.log_path, a.log_path);
  EXPECT_EQ(got.log_format, a.log_format);
  EXPECT_EQ(got.video_path, a.video_path);
  ASSERT_TRUE(got.times.has_value());
  EXPECT_EQ(got.times->led_on_ns, a.times->led_on_ns);
  EXPECT_EQ(got.times->liftoff_ns, a.times->liftoff_ns);
  EXPECT_EQ(got.times->led_on_uncertainty_ns, a.times->led_on_uncertainty_ns);
  EXPECT_EQ(got.times->liftoff_uncertainty_ns, a.times->liftoff_uncertainty_ns);
  EXPECT_EQ(got.times->source, "video");
  ASSERT_TRUE(got.led_roi_px && got.foot_roi_px);
  EXPECT_EQ(got.led_roi_px->x_px, 5);
  EXPECT_EQ(got.led_roi_px->height_px, 8);
  EXPECT_EQ(got.foot_roi_px->x_px, 100);
  EXPECT_EQ(got.foot_roi_px->height_px, 60);
  EXPECT_EQ(got.notes, "re-run");
  EXPECT_EQ(read->trials[1].log_path, fs::path("/elsewhere/d1.csv"));
  EXPECT_EQ(read->trials[1].log_format, LogFormat::kLiftoff);
  EXPECT_FALSE(read->trials[1].times.has_value());
}

TEST(Manifest, RelativeBaseDirResolvesToAbsolutePaths) {
  const Result<TrialManifest> manifest = ManifestFromJson(OneTrial(), "trials.json", "set");
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  EXPECT_TRUE(manifest->base_dir.is_absolute());
  EXPECT_EQ(manifest->trials[0].log_path, fs::current_path() / "set" / "a1.csv");
}

TEST(Manifest, LogFormatNamesRoundTrip) {
  EXPECT_EQ(LogFormatName(LogFormat::kLiftoff), "liftoff");
  EXPECT_EQ(LogFormatName(LogFormat::kLaika2018), "laika-2018");
  EXPECT_EQ(ParseLogFormat("liftoff"), LogFormat::kLiftoff);
  EXPECT_EQ(ParseLogFormat("laika-2018"), LogFormat::kLaika2018);
  EXPECT_EQ(ParseLogFormat("laika"), std::nullopt);
}

}  // namespace
}  // namespace liftoff

namespace liftoff {
namespace {

TEST(Manifest, PixelScaleIsReadCheckedAndWrittenBack) {
  testing::ScratchDir dir;
  testing::WriteFile(dir / "trials.json", kFullManifest);
  Result<TrialManifest> manifest = LoadManifest(dir / "trials.json");
  ASSERT_TRUE(manifest.ok()) << manifest.status().ToString();
  ASSERT_TRUE(manifest->trials[0].px_per_mm.has_value());
  EXPECT_DOUBLE_EQ(*manifest->trials[0].px_per_mm, 1.38);
  EXPECT_FALSE(manifest->trials[1].px_per_mm.has_value());
  const nlohmann::json written = ManifestToJson(*manifest, dir.path());
  EXPECT_DOUBLE_EQ(written["trials"][0]["video"]["px_per_mm"].get<double>(), 1.38);

  std::string bad = kFullManifest;
  bad.replace(bad.find("1.38"), 4, "0");
  testing::WriteFile(dir / "bad.json", bad);
  const Result<TrialManifest> rejected = LoadManifest(dir / "bad.json");
  ASSERT_FALSE(rejected.ok());
  EXPECT_THAT(
      rejected.status().message(),
      ::testing::HasSubstr("/trials/0/video/px_per_mm: expected a number in (0, 1000], got 0"));
}

}  // namespace
}  // namespace liftoff
