// A tiny, portable pseudo-random generator for deterministic simulations, fault
// injection and synthetic data: the same seed gives the same numbers on every platform
// (std::uniform_*_distribution does not promise that).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace liftoff {

/// splitmix64 (Steele, Lea, Flood 2014): 64-bit state, passes BigCrush, one multiply-xor
/// chain per number. Not for cryptography.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}

  /// The next 64 random bits.
  uint64_t Next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 53 random bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1), 53 random bits.
  double Symmetric() { return static_cast<double>(Next() >> 11) * 0x1.0p-52 - 1.0; }
  /// Standard normal (Box-Muller on two uniforms; the first taken in (0, 1]).
  double Gaussian() {
    const double u1 = 1.0 - Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace liftoff
