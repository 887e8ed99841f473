// One checker for the fields of a value already read (a loaded model, a calibration, an
// options struct): the model, synth spec and calibration readers share it, so every
// message has the same shape, "source: /json/pointer: expected ..., got ...".
#pragma once

#include <string>
#include <string_view>

#include "liftoff/core/json.h"
#include "liftoff/core/status.h"

namespace liftoff {

/// Checks the fields of a value already read (a loaded model, an options struct) and keeps
/// the first problem, named by the field's path: a JSON pointer ("/motor/gearbox_ratio")
/// or a struct's field path ("camera.fps"). Later problems are ignored.
///
///   FieldChecker check("sim.json");
///   check.Number("/bodies/0/mass_kg", mass_kg, {.min = 0, .min_exclusive = true});
///   return check.status();  // "sim.json: /bodies/0/mass_kg: expected a number > 0, got 0"
class FieldChecker {
 public:
  /// `source` names the document in messages (a file name); empty: no prefix.
  explicit FieldChecker(std::string source = {});

  /// "expected a number in [0, 1], got 2" when `value` is not finite or outside `range`.
  void Number(std::string_view field, double value, const NumberRange& range);
  /// The same, the range described as "an integer ...".
  void Integer(std::string_view field, double value, const NumberRange& range);
  /// Records a problem of class kInvalidArgument (unless one is recorded already).
  void Fail(std::string_view field, std::string message);
  /// Records a problem of class kUnsupported (unless one is recorded already).
  void Unsupported(std::string_view field, std::string message);

  /// Whether no problem has been recorded.
  bool ok() const { return code_ == StatusCode::kOk; }
  /// The first problem's field path and message ("" while ok()).
  const std::string& field() const { return field_; }
  const std::string& message() const { return message_; }
  /// OK, or the first problem: "source: field: message".
  Status status() const;

 private:
  void Record(StatusCode code, std::string_view field, std::string message);

  std::string source_;
  StatusCode code_ = StatusCode::kOk;
  std::string field_, message_;
};

}  // namespace liftoff
