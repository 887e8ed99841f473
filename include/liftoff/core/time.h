// Time: int64 nanoseconds for clocks and timestamps, double seconds only in `_s` names.
//
// Every clock in liftoff (the controller's device clock, the host's clock, a video's
// presentation clock) is an int64_t count of nanoseconds from that clock's own origin.
// Mappings between clocks are named target_from_source:
//   ClockMap log_from_video = ...;  int64_t t_log_ns = log_from_video(t_video_ns);
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "liftoff/core/status.h"

namespace liftoff {

inline constexpr int64_t kNanosecondsPerMicrosecond = 1'000;
inline constexpr int64_t kNanosecondsPerMillisecond = 1'000'000;
inline constexpr int64_t kNanosecondsPerSecond = 1'000'000'000;

/// The largest number of seconds an option, flag or file may give for a time or a duration
/// (1e6 s, about 11.6 days: far longer than any trial or capture, and far inside int64
/// nanoseconds, so sums and differences of a few such times cannot overflow). Readers
/// reject larger values with kInvalidArgument naming the field.
inline constexpr double kMaxTimeSeconds = 1e6;

/// Seconds to nanoseconds, rounded to the nearest nanosecond (5.67 -> 5'670'000'000).
/// Saturates at the int64 limits beyond about +-9.2e9 s; NaN gives 0. Callers bound their
/// inputs (kMaxTimeSeconds) so neither happens for data a user gave.
int64_t NsFromSeconds(double seconds);
/// Nanoseconds to seconds.
constexpr double SecondsFromNs(int64_t ns) { return static_cast<double>(ns) * 1e-9; }
constexpr int64_t NsFromMilliseconds(int64_t ms) { return ms * kNanosecondsPerMillisecond; }
constexpr int64_t NsFromMicroseconds(int64_t us) { return us * kNanosecondsPerMicrosecond; }

/// Parses a decimal number of `unit_ns`-long units exactly, without going through a
/// double: ParseDecimalNs("8.02", kNanosecondsPerSecond) is exactly 8'020'000'000 and
/// ParseDecimalNs("1074.33", kNanosecondsPerMillisecond) is 1'074'330'000. Accepts an
/// optional sign, digits, an optional '.' and more digits, nothing else (no exponent,
/// no spaces). Digits finer than 1 ns are rounded half away from zero. kParse on
/// anything else, kOutOfRange when the value does not fit in int64 nanoseconds.
Result<int64_t> ParseDecimalNs(std::string_view text, int64_t unit_ns);

/// "12.345678901" style: seconds with `decimals` digits after the point (0..9).
std::string FormatSeconds(int64_t ns, int decimals = 3);
/// "4.2 ms": a duration as milliseconds with `decimals` digits (0..9) and the unit.
std::string FormatMilliseconds(int64_t ns, int decimals = 1);

/// The current host time, nanoseconds since the Unix epoch (CLOCK_REALTIME).
int64_t HostNowNs();
/// A monotonic clock for durations, nanoseconds from an arbitrary origin.
int64_t MonotonicNowNs();

/// An affine map between two clocks: target = target_at_origin + scale * (source -
/// source_origin). scale is 1 + drift (dimensionless); 1 when the clocks tick alike.
struct ClockMap {
  /// Source-clock instant that maps to `target_at_origin_ns`, nanoseconds.
  int64_t source_origin_ns = 0;
  /// Target-clock instant of the origin, nanoseconds.
  int64_t target_at_origin_ns = 0;
  /// Target nanoseconds per source nanosecond (1 + drift).
  double scale = 1.0;

  /// Maps a source instant to the target clock, rounded to the nearest nanosecond.
  int64_t operator()(int64_t source_ns) const;
  /// Maps a source duration to a target duration.
  int64_t MapDuration(int64_t source_duration_ns) const;
};

}  // namespace liftoff
