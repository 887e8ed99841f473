// Optional values that take less room than std::optional, for records kept by the million
// (a controller log's samples). They read like std::optional (has_value, *, value_or, ==
// with a value, another optional or std::nullopt, conversion to std::optional) but hand
// out copies, not references.
//
//   PackedOptional<T>           sizeof(T) + 1 bytes, byte-aligned: several pack without
//                               padding (std::optional<int64_t> takes 16)
//   PackedOptional<bool>        one byte (absent, false, true)
//   SentinelOptional<T, kAbsent>  sizeof(T): one value of T, never a real one, means absent
//                               (storing it leaves the optional absent)
#pragma once

#include <cassert>
#include <cstdint>
#include <cstring>
#include <optional>
#include <type_traits>

namespace liftoff {
namespace packed_storage {

// a value's bytes and a flag, byte-aligned
template <typename T>
class BytesAndFlag {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  using Value = T;
  bool engaged() const { return engaged_; }
  T get() const {
    T value{};
    std::memcpy(&value, bytes_, sizeof(T));
    return value;
  }
  void set(T value) {
    std::memcpy(bytes_, &value, sizeof(T));
    engaged_ = true;
  }
  void reset() { engaged_ = false; }

 private:
  unsigned char bytes_[sizeof(T)] = {};
  bool engaged_ = false;
};

// absent, false or true in one byte
class TriStateBool {
 public:
  using Value = bool;
  bool engaged() const { return state_ != kAbsent; }
  bool get() const { return state_ == kTrue; }
  void set(bool value) { state_ = value ? kTrue : kFalse; }
  void reset() { state_ = kAbsent; }

 private:
  static constexpr uint8_t kAbsent = 0, kFalse = 1, kTrue = 2;
  uint8_t state_ = kAbsent;
};

// one value of T set aside as "absent" (storing it leaves the optional absent)
template <typename T, T kAbsent>
class Sentinel {
 public:
  using Value = T;
  bool engaged() const { return value_ != kAbsent; }
  T get() const { return value_; }
  void set(T value) { value_ = value; }
  void reset() { value_ = kAbsent; }

 private:
  T value_ = kAbsent;
};

}  // namespace packed_storage

/// An optional value in a compact `Storage` (see the aliases below).
template <typename Storage>
class CompactOptional {
 public:
  using value_type = typename Storage::Value;

  CompactOptional() = default;
  CompactOptional(std::nullopt_t) {}  // implicit, as std::optional's
  CompactOptional(value_type value) { storage_.set(value); }
  CompactOptional(const std::optional<value_type>& value) { 
    if (value) storage_.set(*value);
  }

  bool has_value() const { return storage_.engaged(); }
  explicit operator bool() const { return has_value(); }
  /// The value; asserts there is one.
  value_type operator*() const {
    assert(has_value() && "CompactOptional: no value");
    return storage_.get();
  }
  /// The value; throws std::bad_optional_access when there is none.
  value_type value() const {
    if (!has_value()) throw std::bad_optional_access();
    return storage_.get();
  }
  value_type value_or(value_type fallback) const { return has_value() ? storage_.get() : fallback; }
  void reset() { storage_.reset(); }
  operator std::optional<value_type>() const {
    return has_value() ? std::optional<value_type>(storage_.get()) : std::nullopt;
  }

  friend bool operator==(const CompactOptional& a, const CompactOptional& b) {
    return a.has_value() == b.has_value() && (!a.has_value() || *a == *b);
  }
  friend bool operator==(const CompactOptional& a, std::nullopt_t) { return !a.has_value(); }
  friend bool operator==(const CompactOptional& a, const value_type& b) {
    return a.has_value() && *a == b;
  }

 private:
  Storage storage_;
};

/// sizeof(T) + 1 bytes, byte-aligned; one byte for bool.
template <typename T>
using PackedOptional =
    CompactOptional<std::conditional_t<std::is_same_v<T, bool>, packed_storage::TriStateBool,
                                       packed_storage::BytesAndFlag<T>>>;

/// sizeof(T): `kAbsent` means absent (storing it leaves the optional absent), so it must
/// be a value T never really takes.
template <typename T, T kAbsent>
using SentinelOptional = CompactOptional<packed_storage::Sentinel<T, kAbsent>>;

}  // namespace liftoff
