#include "liftoff/core/time.h"

#include <cmath>
#include <ctime>
#include <limits>
#include <string>

#include "liftoff/core/text.h"

namespace liftoff {
namespace {
__extension__ using Int128 = __int128;  // exact decimal arithmetic
}  // namespace

int64_t NsFromSeconds(double seconds) {
  // llround is undefined outside int64: saturate there (2^63 ns is about 9.2e9 s)
  constexpr double kTwoToThe63 = 9223372036854775808.0;
  const double ns = seconds * 1e9;
  if (std::isnan(ns)) return 0;
  if (ns >= kTwoToThe63) return std::numeric_limits<int64_t>::max();
  if (ns <= -kTwoToThe63) return std::numeric_limits<int64_t>::min();
  return std::llround(ns);
}

Result<int64_t> ParseDecimalNs(std::string_view text, int64_t unit_ns) {
  assert(unit_ns > 0);
  const auto bad = [&] {
    return ParseError("expected a decimal number such as 12.34, got \"" + std::string(text) + "\"");
  };
  // sign
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  // integer part and fraction apart; 19 fraction digits resolve 1 ns of any unit up to
  // 1e18 ns and decide its rounding, so later digits are checked but not used
  constexpr int kMaxFractionDigits = 19;
  constexpr Int128 kInt64Max = std::numeric_limits<int64_t>::max();
  const auto too_large = [&] {
    return OutOfRangeError("\"" + std::string(text) + "\" is too large a time");
  };
  Int128 whole = 0;
  Int128 fraction = 0;
  int fraction_digits = 0;
  bool seen_digit = false;
  bool seen_point = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '.' && !seen_point) {
      seen_point = true;
      continue;
    }
    if (c < '0' || c > '9') return bad();
    seen_digit = true;
    if (!seen_point) {
      whole = whole * 10 + (c - '0');
      if (whole > kInt64Max) return too_large();  // unit_ns >= 1: already too many ns
    } else if (fraction_digits < kMaxFractionDigits) {
      fraction = fraction * 10 + (c - '0');
      ++fraction_digits;
    }
  }
  if (!seen_digit) return bad();
  // scale to nanoseconds: whole * unit_ns + fraction * unit_ns / 10^digits, rounded half
  // away from zero (every product stays below 2^127)
  Int128 denominator = 1;
  for (int d = 0; d < fraction_digits; ++d) denominator *= 10;
  const Int128 ns = whole * unit_ns + (fraction * unit_ns + denominator / 2) / denominator;
  // the negative side holds one more nanosecond than the positive
  if (ns > kInt64Max + (negative ? 1 : 0)) return too_large();
  return static_cast<int64_t>(negative ? -ns : ns);
}

std::string FormatMilliseconds(int64_t ns, int decimals) {
  assert(decimals >= 0 && decimals <= 9);
  return FormatFixed(1e-6 * static_cast<double>(ns), decimals) + " ms";
}

std::string FormatSeconds(int64_t ns, int decimals) {
  assert(decimals >= 0 && decimals <= 9);
  return FormatFixed(SecondsFromNs(ns), decimals);
}

int64_t HostNowNs() {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<int64_t>(now.tv_sec) * kNanosecondsPerSecond + now.tv_nsec;
}

int64_t MonotonicNowNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<int64_t>(now.tv_sec) * kNanosecondsPerSecond + now.tv_nsec;
}

int64_t ClockMap::operator()(int64_t source_ns) const {
  return target_at_origin_ns + MapDuration(source_ns - source_origin_ns);
}

int64_t ClockMap::MapDuration(int64_t source_duration_ns) const {
  if (scale == 1.0) return source_duration_ns;  // exact for the common case
  return std::llround(static_cast<double>(source_duration_ns) * scale);
}

}  // namespace liftoff
