// Status and Result<T>: recoverable failures with a small error vocabulary.
//
// A Status is what a user can cause (a bad file, a bad field, a lookup beyond a log's
// end). Its message says what went wrong, where (file:line or file: /json/path) and what
// was expected, e.g.
//   trials.json: /trials/3/foot: expected one of A, B, C, D, got "E"
// Programmer errors are asserts, not Statuses.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace liftoff {

/// The error vocabulary. Each class maps to its own CLI exit code (docs/cli.md).
enum class StatusCode {
  kOk = 0,
  kInvalidArgument,  ///< a value is outside what is allowed (options, fields, flags)
  kNotFound,         ///< a file, key, port or event does not exist (LED never on, ...)
  kParse,            ///< a file's content is malformed (JSON syntax, log lines, CSV)
  kIo,               ///< reading or writing failed (permissions, disk, device gone)
  kTimeout,          ///< something did not happen in time
  kUnsupported,      ///< a known but unsupported format, version or feature
  kOutOfRange,       ///< an instant or index outside the data (lookup beyond a log)
};

/// Short lowercase name of a code: "invalid argument", "not found", ...
std::string_view StatusCodeName(StatusCode code);

/// Success, or an error class with a message that names what, where and what was
/// expected.
class [[nodiscard]] Status {
 public:
  Status() = default;  ///< OK
  Status(StatusCode code, std::string message);

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }

  /// "parse: trials.json: /trials/3/foot: expected ..." (or "ok").
  std::string ToString() const;

  /// The same error with `context` put in front of the message: "context: message".
  /// Used to add a file name or a trial id as an error travels up.
  Status WithContext(std::string_view context) const;

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

// Constructors that read as sentences: return InvalidArgumentError("...").
Status InvalidArgumentError(std::string message);
Status NotFoundError(std::string message);
Status ParseError(std::string message);
Status IoError(std::string message);
Status TimeoutError(std::string message);
Status UnsupportedError(std::string message);
Status OutOfRangeError(std::string message);

/// A value of type T or an error Status.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}         // NOLINT: implicit by design
  Result(Status status) : status_(std::move(status)) {  // NOLINT: implicit by design
    assert(!status_.ok() && "a Result holds a value or an error, never an OK status");
  }

  bool ok() const { return value_.has_value(); }
  /// The error; an OK Status when a value is held.
  const Status& status() const { return status_; }

  const T& value() const& {
    assert(ok());
    return *value_;
  }
  T& value() & {
    assert(ok());
    return *value_;
  }
  T&& value() && {
    assert(ok());
    return std::move(*value_);
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  /// The value, or `fallback` when this holds an error.
  T value_or(T fallback) const& { return ok() ? *value_ : std::move(fallback); }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace liftoff

// Early return of an error Status from a function that returns Status or Result<T>.
#define LIFTOFF_RETURN_IF_ERROR(expr)                  \
  do {                                                 \
    ::liftoff::Status liftoff_status_ = (expr);        \
    if (!liftoff_status_.ok()) return liftoff_status_; \
  } while (false)

#define LIFTOFF_CONCAT_INNER(a, b) a##b
#define LIFTOFF_CONCAT(a, b) LIFTOFF_CONCAT_INNER(a, b)

// LIFTOFF_ASSIGN_OR_RETURN(auto log, ReadLog(path)); declares `log` or returns the error.
#define LIFTOFF_ASSIGN_OR_RETURN(lhs, expr) \
  LIFTOFF_ASSIGN_OR_RETURN_IMPL(LIFTOFF_CONCAT(liftoff_result_, __LINE__), lhs, expr)
#define LIFTOFF_ASSIGN_OR_RETURN_IMPL(result, lhs, expr) \
  auto result = (expr);                                  \
  if (!result.ok()) return result.status();              \
  lhs = std::move(result).value()
