// JSON loading with errors that name the file and the JSON path (a JSON Pointer, RFC 6901)
// of the bad field, and that reject keys nobody reads (a misspelt key is an error, not a
// silently ignored default).
//
//   LIFTOFF_ASSIGN_OR_RETURN(nlohmann::json document, LoadJsonFile(path));
//   JsonReader root(document, path.string());
//   double ratio = root.Number("gearbox_ratio", {.min = 0, .min_exclusive = true});
//   JsonReader motors = root.Object("motors");
//   int counts = motors.Integer("counts_per_rev", {.min = 1});
//   LIFTOFF_RETURN_IF_ERROR(root.Finish());  // first error anywhere, or unknown keys
//
// Errors read: `calib.json: /motors/counts_per_rev: expected an integer >= 1, got 0`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/status.h"

namespace liftoff {

/// Reads and parses a JSON file. kNotFound when it does not exist, kIo when it cannot be
/// read, kParse with "file:line:column: message" for a syntax error.
Result<nlohmann::json> LoadJsonFile(const std::filesystem::path& path);

/// Parses JSON text; `source_name` names it in errors (a file name or "<stdin>").
Result<nlohmann::json> ParseJsonText(std::string_view text, std::string_view source_name);

/// Writes `document` with `indent` spaces (and a final newline), through a temporary
/// file renamed into place so a crash never leaves half a file. kIo on failure.
Status WriteJsonFile(const std::filesystem::path& path, const nlohmann::json& document,
                     int indent = 2);

/// A closed or open interval for numbers read from JSON.
struct NumberRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;  ///< min itself is not allowed
  bool max_exclusive = false;  ///< max itself is not allowed
};

/// "a number in [0, 1]", "an integer >= 1", "a number > 0", or "a number" (unbounded):
/// what an error message says was expected.
std::string DescribeNumberRange(const NumberRange& range, bool integer = false);
/// Whether `value` is finite and inside `range`.
bool InNumberRange(double value, const NumberRange& range);
/// A number as people write it: 0.25, 1e-06, 1000.
std::string FormatNumber(double value);
/// A result number for a JSON document: the number, or null when it is not finite (JSON
/// has no NaN or infinity, and no non-finite number is ever printed as a result).
nlohmann::json NumberOrNull(double value);

/// Reads one JSON object field by field. Each getter marks its key as read; a missing
/// required key, a wrong type or an out-of-range value records an error naming the
/// file and the JSON pointer, and returns a default. Readers of nested objects share
/// the error record of the reader they came from. Finish() on the root returns the
/// first recorded error or, failing that, the first key no reader read.
class JsonReader {
 public:
  /// `source` names the document in errors (usually its file name). The reader keeps a
  /// pointer to `value`, which must outlive it.
  JsonReader(const nlohmann::json& value, std::string source);

  /// True when `key` is present (and not null). Does not mark it read.
  bool Has(std::string_view key) const;

  // Required fields: an error when missing.
  double Number(std::string_view key, const NumberRange& range = {});
  int64_t Integer(std::string_view key, const NumberRange& range = {});
  bool Boolean(std::string_view key);
  std::string String(std::string_view key);
  /// One of `allowed` (exact match); returns its index in `allowed`.
  size_t Enum(std::string_view key, const std::vector<std::string_view>& allowed);
  JsonReader Object(std::string_view key);
  /// An array of objects, one reader each.
  std::vector<JsonReader> ObjectArray(std::string_view key);
  /// An array of numbers; `size` 0 means any length.
  std::vector<double> NumberArray(std::string_view key, size_t size = 0,
                                  const NumberRange& range = {});

  // Optional fields: nullopt when missing or null.
  std::optional<double> OptionalNumber(std::string_view key, const NumberRange& range = {});
  std::optional<int64_t> OptionalInteger(std::string_view key, const NumberRange& range = {});
  std::optional<bool> OptionalBoolean(std::string_view key);
  std::optional<std::string> OptionalString(std::string_view key);
  std::optional<size_t> OptionalEnum(std::string_view key,
                                     const std::vector<std::string_view>& allowed);
  std::optional<JsonReader> OptionalObject(std::string_view key);
  std::optional<std::vector<JsonReader>> OptionalObjectArray(std::string_view key);
  std::optional<std::vector<double>> OptionalNumberArray(std::string_view key, size_t size = 0,
                                                         const NumberRange& range = {});

  /// The raw value of `key`, marked read (nullptr when missing). For free-form parts
  /// such as notes.
  const nlohmann::json* Raw(std::string_view key);

  /// Records an error about `key` (or about this object when `key` is empty):
  /// "source: /pointer/key: message". Use for checks the getters cannot make.
  void Fail(std::string_view key, std::string_view message);

  /// Marks every key of this object as read (for objects with free-form contents).
  void AcceptAnyKeys();

  /// First recorded error, else the first unread key of any reader sharing this
  /// record ("... /motors/gear_ration: unknown key; expected one of ..."), else OK.
  Status Finish() const;

  /// Whether an error has been recorded so far (cheap; no unknown-key check).
  bool failed() const;

  /// JSON pointer of this object, "" for the root.
  const std::string& pointer() const { return pointer_; }
  /// "source: /pointer/key", the prefix every error about `key` carries.
  std::string Where(std::string_view key) const;

 private:
  struct Shared;
  JsonReader(const nlohmann::json* value, std::string pointer, std::shared_ptr<Shared> shared);
  const nlohmann::json* Find(std::string_view key, bool mark_read);
  std::string ChildPointer(std::string_view key) const;
  bool CheckRange(std::string_view key, double value, const NumberRange& range, bool integer);

  const nlohmann::json* value_;
  std::string pointer_;
  size_t record_index_ = 0;  // this object's entry in Shared::objects
  std::shared_ptr<Shared> shared_;
};

/// Escapes a key for a JSON pointer: "~" -> "~0", "/" -> "~1".
std::string JsonPointerEscape(std::string_view key);

}  // namespace liftoff
