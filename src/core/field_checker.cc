#include "liftoff/core/field_checker.h"

#include <utility>

namespace liftoff {

FieldChecker::FieldChecker(std::string source) : source_(std::move(source)) {}

void FieldChecker::Number(std::string_view field, double value, const NumberRange& range) {
  if (!InNumberRange(value, range)) {
    Fail(field, "expected " + DescribeNumberRange(range) + ", got " + FormatNumber(value));
  }
}

void FieldChecker::Integer(std::string_view field, double value, const NumberRange& range) {
  if (!InNumberRange(value, range)) {
    Fail(field, "expected " + DescribeNumberRange(range, true) + ", got " + FormatNumber(value));
  }
}

void FieldChecker::Fail(std::string_view field, std::string message) {
  Record(StatusCode::kInvalidArgument, field, std::move(message));
}

void FieldChecker::Unsupported(std::string_view field, std::string message) {
  Record(StatusCode::kUnsupported, field, std::move(message));
}

void FieldChecker::Record(StatusCode code, std::string_view field, std::string message) {
  if (!ok()) return;
  code_ = code;
  field_ = field;
  message_ = std::move(message);
}

Status FieldChecker::status() const {
  if (ok()) return Status::Ok();
  return Status(code_, (source_.empty() ? "" : source_ + ": ") + field_ + ": " + message_);
}

}  // namespace liftoff
