#include "liftoff/core/json.h"

#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace liftoff {
namespace {

using ::liftoff::testing::ReadFile;
using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::WriteFile;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// --- files ---------------------------------------------------------------------------

TEST(LoadJsonFile, ReadsAValidFile) {
  ScratchDir dir;
  WriteFile(dir / "a.json", R"({"x": [1, 2.5, "three"]})");
  const Result<json> document = LoadJsonFile(dir / "a.json");
  ASSERT_TRUE(document.ok()) << document.status().ToString();
  EXPECT_EQ((*document)["x"][1], 2.5);
  EXPECT_EQ((*document)["x"][2], "three");
}

TEST(LoadJsonFile, MissingFileIsNotFoundNamingIt) {
  ScratchDir dir;
  const std::filesystem::path path = dir / "absent.json";
  const Result<json> document = LoadJsonFile(path);
  ASSERT_FALSE(document.ok());
  EXPECT_EQ(document.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(document.status().message(), HasSubstr(path.string()));
}

TEST(LoadJsonFile, DirectoryIsInvalidArgument) {
  ScratchDir dir;
  const Result<json> document = LoadJsonFile(dir.path());
  ASSERT_FALSE(document.ok());
  EXPECT_EQ(document.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(document.status().message(), HasSubstr(dir.path().string()));
}

TEST(LoadJsonFile, SyntaxErrorNamesFileLineAndColumn) {
  ScratchDir dir;
  const std::filesystem::path path = dir / "bad.json";
  // the stray comma is line 3, column 8
  WriteFile(path, "{\n  \"a\": 1,\n  \"b\": ,\n  \"c\": 3\n}\n");
  const Result<json> document = LoadJsonFile(path);
  ASSERT_FALSE(document.ok());
  EXPECT_EQ(document.status().code(), StatusCode::kParse);
  EXPECT_THAT(document.status().message(), StartsWith(path.string() + ":3:8: invalid JSON"));
}

TEST(ParseJsonText, SyntaxErrorOnFirstLineNamesSource) {
  const Result<json> document = ParseJsonText("[1, 2", "<stdin>");
  ASSERT_FALSE(document.ok());
  EXPECT_EQ(document.status().code(), StatusCode::kParse);
  EXPECT_THAT(document.status().message(), StartsWith("<stdin>:1:"));
}

TEST(ParseJsonText, TruncatedObjectNamesLastLine) {
  const Result<json> document = ParseJsonText("{\n\"a\": 1,\n", "t.json");
  ASSERT_FALSE(document.ok());
  EXPECT_THAT(document.status().message(), StartsWith("t.json:3:"));
}

TEST(ParseJsonText, NumberTooLargeForADoubleIsAParseErrorWithItsPlace) {
  const Result<json> document = ParseJsonText("{\n  \"z\": [0, 1e999]\n}", "m.json");
  ASSERT_FALSE(document.ok());
  EXPECT_EQ(document.status().code(), StatusCode::kParse);
  EXPECT_THAT(document.status().message(),
              StartsWith("m.json:2:12: invalid JSON: number overflow parsing '1e999'"));
}

TEST(WriteJsonFile, WritesIndentedJsonThatReadsBack) {
  ScratchDir dir;
  const std::filesystem::path path = dir / "out.json";
  const json document = {{"name", "laika"}, {"ratios", {1, 1, 2, 3}}};
  ASSERT_TRUE(WriteJsonFile(path, document).ok());
  const std::string text = ReadFile(path);
  EXPECT_THAT(text, HasSubstr("\n  \"name\": \"laika\""));
  EXPECT_EQ(text.back(), '\n');
  EXPECT_FALSE(std::filesystem::exists(dir / "out.json.tmp"));
  EXPECT_EQ(LoadJsonFile(path).value(), document);
}

TEST(WriteJsonFile, CreatesMissingFolders) {
  ScratchDir dir;
  ASSERT_TRUE(WriteJsonFile(dir / "no" / "such" / "x.json", json::object()).ok());
  EXPECT_EQ(LoadJsonFile(dir / "no" / "such" / "x.json").value(), json::object());
}

TEST(WriteJsonFile, FolderBelowAFileIsIoError) {
  ScratchDir dir;
  liftoff::testing::WriteFile(dir / "plain-file", "x");
  const Status status = WriteJsonFile(dir / "plain-file" / "x.json", json::object());
  EXPECT_EQ(status.code(), StatusCode::kIo);
  EXPECT_THAT(status.message(), HasSubstr("plain-file"));
}

TEST(JsonPointerEscape, EscapesTildeAndSlash) {
  EXPECT_EQ(JsonPointerEscape("plain"), "plain");
  EXPECT_EQ(JsonPointerEscape("a/b~c"), "a~1b~0c");
  EXPECT_EQ(JsonPointerEscape("~1"), "~01");
}

// --- JsonReader ------------------------------------------------------------------------

TEST(JsonReader, ReadsFieldsOfEveryType) {
  const json document = json::parse(R"({
    "ratio": 2.5, "count": 7, "enabled": true, "name": "laika", "foot": "C",
    "motor": {"counts_per_rev": 12}, "trials": [{"id": "A1"}, {"id": "A2"}],
    "radii_m": [0.004, 0.008]})");
  JsonReader root(document, "calib.json");
  EXPECT_EQ(root.Number("ratio"), 2.5);
  EXPECT_EQ(root.Integer("count"), 7);
  EXPECT_TRUE(root.Boolean("enabled"));
  EXPECT_EQ(root.String("name"), "laika");
  EXPECT_EQ(root.Enum("foot", {"A", "B", "C", "D"}), 2u);
  JsonReader motor = root.Object("motor");
  EXPECT_EQ(motor.pointer(), "/motor");
  EXPECT_EQ(motor.Integer("counts_per_rev"), 12);
  std::vector<JsonReader> trials = root.ObjectArray("trials");
  ASSERT_EQ(trials.size(), 2u);
  EXPECT_EQ(trials[1].pointer(), "/trials/1");
  EXPECT_EQ(trials[0].String("id"), "A1");
  EXPECT_EQ(trials[1].String("id"), "A2");
  EXPECT_EQ(root.NumberArray("radii_m", 2), (std::vector<double>{0.004, 0.008}));
  EXPECT_TRUE(root.Finish().ok()) << root.Finish().ToString();
}

TEST(JsonReader, MissingRequiredFieldNamesPointer) {
  const json document = json::parse(R"({"motor": {}})");
  JsonReader root(document, "calib.json");
  JsonReader motor = root.Object("motor");
  EXPECT_EQ(motor.Number("gearbox_ratio"), 0.0);
  EXPECT_TRUE(root.failed());
  const Status status = root.Finish();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), "calib.json: /motor/gearbox_ratio: missing required field");
}

TEST(JsonReader, NullCountsAsMissing) {
  const json document = json::parse(R"({"a": null})");
  JsonReader root(document, "x.json");
  EXPECT_FALSE(root.Has("a"));
  EXPECT_EQ(root.OptionalNumber("a"), std::nullopt);
  EXPECT_TRUE(root.Finish().ok());
  JsonReader again(document, "x.json");
  again.String("a");
  EXPECT_EQ(again.Finish().message(), "x.json: /a: missing required field");
}

TEST(JsonReader, WrongTypeNamesPointerExpectationAndValue) {
  const json document = json::parse(R"({"ratio": "4", "flag": 1, "name": 3, "list": {}})");
  {
    JsonReader root(document, "c.json");
    root.Number("ratio");
    EXPECT_EQ(root.Finish().message(), "c.json: /ratio: expected a number, got \"4\"");
  }
  {
    JsonReader root(document, "c.json");
    root.Boolean("flag");
    EXPECT_EQ(root.Finish().message(), "c.json: /flag: expected true or false, got 1");
  }
  {
    JsonReader root(document, "c.json");
    root.String("name");
    EXPECT_EQ(root.Finish().message(), "c.json: /name: expected a string, got 3");
  }
  {
    JsonReader root(document, "c.json");
    root.ObjectArray("list");
    EXPECT_EQ(root.Finish().message(), "c.json: /list: expected an array of objects, got {}");
  }
}

TEST(JsonReader, IntegerRejectsFractions) {
  const json document = json::parse(R"({"count": 1.5})");
  JsonReader root(document, "c.json");
  root.Integer("count", {.min = 1});
  EXPECT_EQ(root.Finish().message(), "c.json: /count: expected an integer >= 1, got 1.5");
}

TEST(JsonReader, OutOfRangeNamesTheRange) {
  const json document = json::parse(R"({"counts": 0, "ratio": -2, "frac": 1.5, "gain": 1})");
  {
    JsonReader root(document, "c.json");
    root.Integer("counts", {.min = 1});
    EXPECT_EQ(root.Finish().message(), "c.json: /counts: expected an integer >= 1, got 0");
  }
  {
    JsonReader root(document, "c.json");
    root.Number("ratio", {.min = 0, .min_exclusive = true});
    EXPECT_EQ(root.Finish().message(), "c.json: /ratio: expected a number > 0, got -2");
  }
  {
    JsonReader root(document, "c.json");
    root.Number("frac", {.min = 0, .max = 1});
    EXPECT_EQ(root.Finish().message(), "c.json: /frac: expected a number in [0, 1], got 1.5");
  }
  {
    JsonReader root(document, "c.json");
    root.Number("gain", {.max = 1, .max_exclusive = true});
    EXPECT_EQ(root.Finish().message(), "c.json: /gain: expected a number < 1, got 1");
  }
  {
    JsonReader root(document, "c.json");
    EXPECT_EQ(root.Number("frac", {.min = 0, .max = 2}), 1.5);  // inside: no error
    root.AcceptAnyKeys();
    EXPECT_TRUE(root.Finish().ok());
  }
}

TEST(JsonReader, EnumListsAllowedValues) {
  const json document = json::parse(R"({"trials": [{}, {}, {}, {"foot": "E"}]})");
  JsonReader root(document, "trials.json");
  std::vector<JsonReader> trials = root.ObjectArray("trials");
  ASSERT_EQ(trials.size(), 4u);
  EXPECT_EQ(trials[3].Enum("foot", {"A", "B", "C", "D"}), 0u);
  EXPECT_EQ(root.Finish().message(),
            "trials.json: /trials/3/foot: expected one of A, B, C, D, got \"E\"");
}

TEST(JsonReader, EnumRejectsNonStrings) {
  const json document = json::parse(R"({"foot": 1})");
  JsonReader root(document, "t.json");
  root.Enum("foot", {"A", "B"});
  EXPECT_EQ(root.Finish().message(), "t.json: /foot: expected one of A, B, got 1");
}

TEST(JsonReader, DeeplyNestedPointer) {
  const json document = json::parse(R"({"a": {"b": [{"c": {"d": "x"}}]}})");
  JsonReader root(document, "n.json");
  JsonReader b0 = root.Object("a").ObjectArray("b")[0];
  b0.Object("c").Integer("d");
  EXPECT_EQ(root.Finish().message(), "n.json: /a/b/0/c/d: expected an integer, got \"x\"");
}

TEST(JsonReader, FirstErrorWins) {
  const json document = json::parse(R"({"a": "x", "b": "y"})");
  JsonReader root(document, "f.json");
  root.Number("a");
  root.Number("b");
  EXPECT_THAT(root.Finish().message(), HasSubstr("/a:"));
}

TEST(JsonReader, UnknownKeyIsAnErrorListingKnownKeys) {
  const json document = json::parse(R"({"motor": {"counts_per_rev": 12, "gear_ration": 1000}})");
  JsonReader root(document, "calib.json");
  JsonReader motor = root.Object("motor");
  motor.Integer("counts_per_rev");
  motor.OptionalNumber("gear_ratio");
  const Status status = root.Finish();
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), StartsWith("calib.json: /motor/gear_ration: unknown key"));
  EXPECT_THAT(status.message(), HasSubstr("counts_per_rev, gear_ratio"));
}

TEST(JsonReader, UnknownKeyInArrayElementNamesIndex) {
  const json document = json::parse(R"({"trials": [{"id": "A1"}, {"id": "A2", "fot": "A"}]})");
  JsonReader root(document, "t.json");
  for (JsonReader& trial : root.ObjectArray("trials")) trial.String("id");
  EXPECT_THAT(root.Finish().message(), StartsWith("t.json: /trials/1/fot: unknown key"));
}

TEST(JsonReader, UnknownKeyWithSlashIsEscaped) {
  const json document = json::parse(R"({"a/b": 1})");
  JsonReader root(document, "e.json");
  EXPECT_THAT(root.Finish().message(), StartsWith("e.json: /a~1b: unknown key"));
}

TEST(JsonReader, HasDoesNotMarkAKeyRead) {
  const json document = json::parse(R"({"extra": 1})");
  JsonReader root(document, "h.json");
  EXPECT_TRUE(root.Has("extra"));
  EXPECT_FALSE(root.Has("other"));
  EXPECT_THAT(root.Finish().message(), HasSubstr("/extra: unknown key"));
}

TEST(JsonReader, UnreadObjectIsCheckedToo) {
  // an object fetched but not read is still checked for unknown keys
  const json document = json::parse(R"({"motor": {"x": 1}})");
  JsonReader root(document, "u.json");
  root.Object("motor");
  EXPECT_THAT(root.Finish().message(), StartsWith("u.json: /motor/x: unknown key"));
}

TEST(JsonReader, RawAndAcceptAnyKeysAllowFreeFormParts) {
  const json document = json::parse(R"({"notes": {"anything": "goes"}, "extra": {"k": 1}})");
  JsonReader root(document, "r.json");
  const json* extra = root.Raw("extra");
  ASSERT_NE(extra, nullptr);
  EXPECT_EQ((*extra)["k"], 1);
  EXPECT_EQ(root.Raw("absent"), nullptr);
  root.Object("notes").AcceptAnyKeys();
  EXPECT_TRUE(root.Finish().ok()) << root.Finish().ToString();
}

TEST(JsonReader, OptionalGettersReturnNulloptWhenMissing) {
  const json document = json::parse(R"({"present": 3})");
  JsonReader root(document, "o.json");
  EXPECT_EQ(root.OptionalNumber("n"), std::nullopt);
  EXPECT_EQ(root.OptionalInteger("i"), std::nullopt);
  EXPECT_EQ(root.OptionalBoolean("b"), std::nullopt);
  EXPECT_EQ(root.OptionalString("s"), std::nullopt);
  EXPECT_EQ(root.OptionalEnum("e", {"x"}), std::nullopt);
  EXPECT_FALSE(root.OptionalObject("o").has_value());
  EXPECT_FALSE(root.OptionalObjectArray("a").has_value());
  EXPECT_FALSE(root.OptionalNumberArray("v").has_value());
  EXPECT_EQ(root.OptionalInteger("present"), 3);
  EXPECT_TRUE(root.Finish().ok());
}

TEST(JsonReader, OptionalFieldStillCheckedWhenPresent) {
  const json document = json::parse(R"({"rate_hz": -5})");
  JsonReader root(document, "o.json");
  EXPECT_EQ(root.OptionalNumber("rate_hz", {.min = 0, .min_exclusive = true}), std::nullopt);
  EXPECT_EQ(root.Finish().message(), "o.json: /rate_hz: expected a number > 0, got -5");
}

TEST(JsonReader, NumberArrayChecksLengthAndElements) {
  const json document =
      json::parse(R"({"three": [1, 2, 3], "bad": [0.1, -1, 2], "text": [1, "x"]})");
  {
    JsonReader root(document, "a.json");
    root.NumberArray("three", 4);
    EXPECT_EQ(root.Finish().message(),
              "a.json: /three: expected an array of 4 numbers, got [1,2,3]");
  }
  {
    JsonReader root(document, "a.json");
    root.NumberArray("bad", 0, {.min = 0});
    EXPECT_EQ(root.Finish().message(), "a.json: /bad/1: expected a number >= 0, got -1");
  }
  {
    JsonReader root(document, "a.json");
    root.NumberArray("text");
    EXPECT_EQ(root.Finish().message(), "a.json: /text/1: expected a number, got \"x\"");
  }
}

TEST(JsonReader, NonObjectDocumentIsAnError) {
  const json document = json::parse("[1, 2]");
  JsonReader root(document, "l.json");
  EXPECT_FALSE(root.Has("a"));
  EXPECT_EQ(root.Finish().message(), "l.json: /: expected a JSON object, got [1,2]");
}

TEST(JsonReader, NonObjectMemberNamesItsPointer) {
  const json document = json::parse(R"({"motor": 3})");
  JsonReader root(document, "m.json");
  JsonReader motor = root.Object("motor");
  motor.Number("ratio");  // no second error from inside the bad object
  EXPECT_EQ(root.Finish().message(), "m.json: /motor: expected a JSON object, got 3");
}

TEST(JsonReader, MissingObjectReportsOnlyItsAbsence) {
  const json document = json::object();
  JsonReader root(document, "m.json");
  JsonReader motor = root.Object("motor");
  EXPECT_EQ(motor.Number("ratio"), 0.0);
  EXPECT_EQ(root.Finish().message(), "m.json: /motor: missing required field");
}

TEST(JsonReader, FailRecordsCustomErrorsAtPointer) {
  const json document = json::parse(R"({"trials": [{"id": "A1"}]})");
  JsonReader root(document, "t.json");
  std::vector<JsonReader> trials = root.ObjectArray("trials");
  trials[0].String("id");
  trials[0].Fail("id", "duplicate id \"A1\"");
  EXPECT_EQ(root.Finish().message(), "t.json: /trials/0/id: duplicate id \"A1\"");
  EXPECT_EQ(trials[0].Where(""), "t.json: /trials/0");
  EXPECT_EQ(root.Where(""), "t.json: /");
  EXPECT_EQ(root.Where("x"), "t.json: /x");
}

TEST(JsonReader, DescribesLongValuesShortly) {
  const json document =
      json::parse(R"({"name": [1111111111, 2222222222, 3333333333, 4444444444]})");
  JsonReader root(document, "d.json");
  root.String("name");
  const std::string message = root.Finish().message();
  EXPECT_THAT(message, StartsWith("d.json: /name: expected a string, got [1111111111,"));
  EXPECT_THAT(message, ::testing::EndsWith("..."));
  EXPECT_LT(message.size(), 80u);
}

}  // namespace
}  // namespace liftoff
