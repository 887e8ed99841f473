#include "patch_selection.h"

#include <cmath>
#include <optional>

namespace liftoff::video::internal {
namespace {

// The curve's crossing of `level` (see PatchCrossingSpreadS), s; nullopt for none.
std::optional<double> CrossingS(const std::vector<double>& t_s, const std::vector<double>& curve,
                                size_t first, double level, size_t sustain) {
  size_t above = 0, start = 0;
  std::optional<size_t> below;
  for (size_t f = first; f < curve.size() && above < sustain; ++f) {
    if (!std::isfinite(curve[f])) continue;
    if (curve[f] > level) {
      if (above++ == 0) start = f;
    } else {
      above = 0;
      below = f;
    }
  }
  if (above < sustain || !below) return std::nullopt;
  const double h0 = curve[*below], h1 = curve[start];
  return t_s[*below] + (t_s[start] - t_s[*below]) * (level - h0) / (h1 - h0);
}

}  // namespace

double PatchCrossingSpreadS(const std::vector<double>& t_s,
                            const std::vector<std::vector<double>>& curves, size_t first,
                            double level, double crossing_s, size_t sustain) {
  std::vector<double> distances;
  for (const std::vector<double>& curve : curves) {
    const std::optional<double> crossing = CrossingS(t_s, curve, first, level, sustain);
    if (crossing) distances.push_back(std::abs(*crossing - crossing_s));
  }
  if (distances.size() < 3) return 0.0;
  return 1.4826 * FiniteMedian(distances);
}

}  // namespace liftoff::video::internal
