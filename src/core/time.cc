#include "liftoff/core/time.h"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>

namespace liftoff {
namespace {
__extension__ using Int128 = __int128;  // exact decimal arithmetic
}  // namespace

int64_t NsFromSeconds(double seconds) { return std::llround(seconds * 1e9); }

Result<int64_t> ParseDecimalNs(std::string_view text, int64_t unit_ns) {
  assert(unit_ns > 0);
  const auto bad = [&] {
    return ParseError("expected a decimal number such as 12.34, got \"" + std::string(text) + "\"");
  };
  // sign
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  // integer part and fraction, as one integer of digits plus a count of fraction digits
  Int128 mantissa = 0;
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
    if (mantissa > (static_cast<Int128>(1) << 100)) {
      if (!seen_point) return OutOfRangeError("\"" + std::string(text) + "\" is too large a time");
      continue;  // sub-attosecond digits cannot change the rounded result
    }
    mantissa = mantissa * 10 + (c - '0');
    if (seen_point) ++fraction_digits;
  }
  if (!seen_digit) return bad();
  // scale to nanoseconds: mantissa * unit_ns / 10^fraction_digits, rounded half away
  Int128 numerator = mantissa * unit_ns;
  Int128 denominator = 1;
  for (int d = 0; d < fraction_digits; ++d) denominator *= 10;
  Int128 ns = (numerator + denominator / 2) / denominator;
  if (ns > std::numeric_limits<int64_t>::max()) {
    return OutOfRangeError("\"" + std::string(text) + "\" is too large a time");
  }
  return static_cast<int64_t>(negative ? -ns : ns);
}

std::string FormatSeconds(int64_t ns, int decimals) {
  assert(decimals >= 0 && decimals <= 9);
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, SecondsFromNs(ns));
  return buffer;
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
