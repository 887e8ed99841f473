// Small text helpers for messages and tables, shared so every module words numbers alike.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace liftoff {

/// `value` with exactly `decimals` digits after the point: FormatFixed(0.4567, 3) is
/// "0.457" (printf's %.*f, independent of the locale's decimal point only in the "C" locale,
/// which liftoff never changes).
inline std::string FormatFixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

/// "1 frame", "3 frames": a count with its noun, plural when the count is not 1.
inline std::string Plural(int64_t count, std::string_view noun) {
  return std::to_string(count) + " " + std::string(noun) + (count == 1 ? "" : "s");
}

}  // namespace liftoff
