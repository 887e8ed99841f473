#include "liftoff/core/json.h"

#include "liftoff/core/file.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

namespace liftoff {
namespace {

using nlohmann::json;

std::string Describe(const json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

// Line and column of a byte offset, both from 1.
std::pair<size_t, size_t> LineColumn(std::string_view text, size_t offset) {
  size_t line = 1, column = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {line, column};
}

// The deepest nesting of arrays and objects a JSON file may have (liftoff's own files
// nest 5 deep); checked before parsing, as parsing and reading recurse.
constexpr int kMaxJsonDepth = 64;

// The largest JSON file read, bytes (manifests and models are kilobytes).
constexpr std::uintmax_t kMaxJsonFileBytes = std::uintmax_t{64} << 20;

// Byte offset of the first bracket deeper than kMaxJsonDepth, or npos. Brackets inside
// strings do not count; the syntax itself is left to the parser.
size_t FirstTooDeep(std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) return i;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return std::string_view::npos;
}

}  // namespace

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

std::string DescribeNumberRange(const NumberRange& range, bool integer) {
  std::string what = integer ? "an integer" : "a number";
  const bool has_min = std::isfinite(range.min);
  const bool has_max = std::isfinite(range.max);
  if (has_min && has_max) {
    return what + " in " + (range.min_exclusive ? "(" : "[") + FormatNumber(range.min) + ", " +
           FormatNumber(range.max) + (range.max_exclusive ? ")" : "]");
  }
  if (has_min) return what + (range.min_exclusive ? " > " : " >= ") + FormatNumber(range.min);
  if (has_max) return what + (range.max_exclusive ? " < " : " <= ") + FormatNumber(range.max);
  return what;
}

bool InNumberRange(double value, const NumberRange& range) {
  if (!std::isfinite(value)) return false;
  const bool above_min = range.min_exclusive ? value > range.min : value >= range.min;
  const bool below_max = range.max_exclusive ? value < range.max : value <= range.max;
  return above_min && below_max;
}

std::string JsonPointerEscape(std::string_view key) {
  std::string escaped;
  for (char c : key) {
    if (c == '~') {
      escaped += "~0";
    } else if (c == '/') {
      escaped += "~1";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

Result<json> ParseJsonText(std::string_view text, std::string_view source_name) {
  if (const size_t deep = FirstTooDeep(text); deep != std::string_view::npos) {
    const auto [line, column] = LineColumn(text, deep);
    return ParseError(std::string(source_name) + ":" + std::to_string(line) + ":" +
                      std::to_string(column) + ": JSON nested deeper than " +
                      std::to_string(kMaxJsonDepth) + " levels; expected at most " +
                      std::to_string(kMaxJsonDepth));
  }
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& error) {
    // nlohmann reports a byte offset; turn it into line:column a person can open
    const auto [line, column] = LineColumn(text, error.byte == 0 ? 0 : error.byte - 1);
    std::string what = error.what();
    const size_t cut = what.find("syntax error");
    if (cut != std::string::npos) what = what.substr(cut);
    return ParseError(std::string(source_name) + ":" + std::to_string(line) + ":" +
                      std::to_string(column) + ": invalid JSON: " + what);
  } catch (const json::out_of_range& error) {
    // a number too large for a double ("number overflow parsing '1e999'"): nlohmann gives
    // no offset, so the literal it quotes is looked up in the text
    std::string what = error.what();
    const size_t cut = what.find("number overflow");
    if (cut != std::string::npos) what = what.substr(cut);
    std::string where = std::string(source_name);
    const size_t open = what.find('\''), close = what.rfind('\'');
    if (open != std::string::npos && close > open + 1) {
      const size_t at = text.find(what.substr(open + 1, close - open - 1));
      if (at != std::string_view::npos) {
        const auto [line, column] = LineColumn(text, at);
        where += ":" + std::to_string(line) + ":" + std::to_string(column);
      }
    }
    return ParseError(where + ": invalid JSON: " + what);
  }
}

Result<json> LoadJsonFile(const std::filesystem::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string contents, ReadWholeFile(path, kMaxJsonFileBytes));
  return ParseJsonText(contents, path.string());
}

Status WriteJsonFile(const std::filesystem::path& path, const json& document, int indent) {
  return WriteFileAtomically(path, document.dump(indent) + "\n");
}

// ---------------------------------------------------------------------------------------
// JsonReader

struct JsonReader::Shared {
  struct ObjectRecord {
    const json* object = nullptr;
    std::string pointer;
    std::set<std::string, std::less<>> read_keys;  // every key asked for
    bool any_key = false;
  };
  std::string source;
  Status first_error;
  std::vector<ObjectRecord> objects;
};

JsonReader::JsonReader(const json& value, std::string source)
    // the source is set before the delegated constructor can report a non-object
    : JsonReader(&value, "", std::make_shared<Shared>(Shared{std::move(source), Status(), {}})) {}

JsonReader::JsonReader(const json* value, std::string pointer, std::shared_ptr<Shared> shared)
    : value_(value), pointer_(std::move(pointer)), shared_(std::move(shared)) {
  if (value_ != nullptr && !value_->is_object()) {
    Fail("", "expected a JSON object, got " + Describe(*value_));
    value_ = nullptr;
  }
  record_index_ = shared_->objects.size();
  shared_->objects.push_back({value_, pointer_, {}, false});
}

std::string JsonReader::ChildPointer(std::string_view key) const {
  return pointer_ + "/" + JsonPointerEscape(key);
}

std::string JsonReader::Where(std::string_view key) const {
  const std::string where = key.empty() ? (pointer_.empty() ? "/" : pointer_) : ChildPointer(key);
  return shared_->source + ": " + where;
}

void JsonReader::Fail(std::string_view key, std::string_view message) {
  if (!shared_->first_error.ok()) return;  // the first error is the one worth reading
  shared_->first_error =
      Status(StatusCode::kInvalidArgument, Where(key) + ": " + std::string(message));
}

bool JsonReader::failed() const { return !shared_->first_error.ok(); }

void JsonReader::AcceptAnyKeys() { shared_->objects[record_index_].any_key = true; }

bool JsonReader::Has(std::string_view key) const {
  if (value_ == nullptr) return false;
  const auto it = value_->find(key);
  return it != value_->end() && !it->is_null();
}

const json* JsonReader::Find(std::string_view key, bool mark_read) {
  if (value_ == nullptr) return nullptr;
  // every key asked for is a known key, present or not
  if (mark_read) shared_->objects[record_index_].read_keys.emplace(key);
  const auto it = value_->find(key);
  if (it == value_->end() || it->is_null()) return nullptr;
  return &*it;
}

const json* JsonReader::Raw(std::string_view key) { return Find(key, true); }

bool JsonReader::CheckRange(std::string_view key, double value, const NumberRange& range,
                            bool integer) {
  if (!InNumberRange(value, range)) {
    Fail(key, "expected " + DescribeNumberRange(range, integer) + ", got " + FormatNumber(value));
    return false;
  }
  return true;
}

std::optional<double> JsonReader::OptionalNumber(std::string_view key, const NumberRange& range) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  if (!value->is_number()) {
    Fail(key, "expected " + DescribeNumberRange(range, false) + ", got " + Describe(*value));
    return std::nullopt;
  }
  const double number = value->get<double>();
  if (!CheckRange(key, number, range, false)) return std::nullopt;
  return number;
}

std::optional<int64_t> JsonReader::OptionalInteger(std::string_view key, const NumberRange& range) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  if (!value->is_number_integer()) {
    Fail(key, "expected " + DescribeNumberRange(range, true) + ", got " + Describe(*value));
    return std::nullopt;
  }
  const int64_t number = value->get<int64_t>();
  if (!CheckRange(key, static_cast<double>(number), range, true)) return std::nullopt;
  return number;
}

std::optional<bool> JsonReader::OptionalBoolean(std::string_view key) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  if (!value->is_boolean()) {
    Fail(key, "expected true or false, got " + Describe(*value));
    return std::nullopt;
  }
  return value->get<bool>();
}

std::optional<std::string> JsonReader::OptionalString(std::string_view key) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  if (!value->is_string()) {
    Fail(key, "expected a string, got " + Describe(*value));
    return std::nullopt;
  }
  return value->get<std::string>();
}

std::optional<size_t> JsonReader::OptionalEnum(std::string_view key,
                                               const std::vector<std::string_view>& allowed) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  std::string expected = "expected one of ";
  for (size_t i = 0; i < allowed.size(); ++i) {
    expected += (i ? ", " : "") + std::string(allowed[i]);
  }
  if (!value->is_string()) {
    Fail(key, expected + ", got " + Describe(*value));
    return std::nullopt;
  }
  const std::string& text = value->get_ref<const std::string&>();
  for (size_t i = 0; i < allowed.size(); ++i) {
    if (text == allowed[i]) return i;
  }
  Fail(key, expected + ", got " + Describe(*value));
  return std::nullopt;
}

std::optional<JsonReader> JsonReader::OptionalObject(std::string_view key) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  return JsonReader(value, ChildPointer(key), shared_);
}

std::optional<std::vector<JsonReader>> JsonReader::OptionalObjectArray(std::string_view key) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  if (!value->is_array()) {
    Fail(key, "expected an array of objects, got " + Describe(*value));
    return std::nullopt;
  }
  std::vector<JsonReader> readers;
  readers.reserve(value->size());
  for (size_t i = 0; i < value->size(); ++i) {
    readers.push_back(
        JsonReader(&(*value)[i], ChildPointer(key) + "/" + std::to_string(i), shared_));
  }
  return readers;
}

std::optional<std::vector<double>> JsonReader::OptionalNumberArray(std::string_view key,
                                                                   size_t size,
                                                                   const NumberRange& range) {
  const json* value = Find(key, true);
  if (value == nullptr) return std::nullopt;
  const std::string expected = size ? "expected an array of " + std::to_string(size) + " numbers"
                                    : "expected an array of numbers";
  if (!value->is_array() || (size != 0 && value->size() != size)) {
    Fail(key, expected + ", got " + Describe(*value));
    return std::nullopt;
  }
  std::vector<double> numbers;
  for (size_t i = 0; i < value->size(); ++i) {
    const json& element = (*value)[i];
    // the index is a pointer step of its own, not part of an escaped key
    const auto fail_element = [&](const std::string& got) {
      if (!shared_->first_error.ok()) return;
      shared_->first_error = InvalidArgumentError(
          shared_->source + ": " + ChildPointer(key) + "/" + std::to_string(i) + ": expected " +
          DescribeNumberRange(range, false) + ", got " + got);
    };
    if (!element.is_number()) {
      fail_element(Describe(element));
      return std::nullopt;
    }
    numbers.push_back(element.get<double>());
    if (!InNumberRange(numbers.back(), range)) {
      fail_element(FormatNumber(numbers.back()));
      return std::nullopt;
    }
  }
  return numbers;
}

// Required getters: the optional ones plus "missing" errors.
namespace {
constexpr std::string_view kMissing = "missing required field";
}

double JsonReader::Number(std::string_view key, const NumberRange& range) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalNumber(key, range).value_or(0.0);
}

int64_t JsonReader::Integer(std::string_view key, const NumberRange& range) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalInteger(key, range).value_or(0);
}

bool JsonReader::Boolean(std::string_view key) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalBoolean(key).value_or(false);
}

std::string JsonReader::String(std::string_view key) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalString(key).value_or("");
}

size_t JsonReader::Enum(std::string_view key, const std::vector<std::string_view>& allowed) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalEnum(key, allowed).value_or(0);
}

JsonReader JsonReader::Object(std::string_view key) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  if (auto object = OptionalObject(key)) return *std::move(object);
  return JsonReader(nullptr, ChildPointer(key), shared_);
}

std::vector<JsonReader> JsonReader::ObjectArray(std::string_view key) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalObjectArray(key).value_or(std::vector<JsonReader>{});
}

std::vector<double> JsonReader::NumberArray(std::string_view key, size_t size,
                                            const NumberRange& range) {
  if (!Has(key) && value_ != nullptr) Fail(key, kMissing);
  return OptionalNumberArray(key, size, range).value_or(std::vector<double>{});
}

Status JsonReader::Finish() const {
  if (!shared_->first_error.ok()) return shared_->first_error;
  for (const auto& record : shared_->objects) {
    if (record.object == nullptr || record.any_key) continue;
    for (const auto& [key, unused] : record.object->items()) {
      if (record.read_keys.count(key)) continue;
      std::string known;
      for (const auto& read : record.read_keys) known += (known.empty() ? "" : ", ") + read;
      return InvalidArgumentError(shared_->source + ": " + record.pointer + "/" +
                                  JsonPointerEscape(key) + ": unknown key" +
                                  (known.empty() ? "" : "; known keys here: " + known));
    }
  }
  return Status::Ok();
}

}  // namespace liftoff
