// Which of the foot tracker's patches are the foot (private to the video module): curves
// over patches and the test that the foot's candidates move together. A patch's value at a
// frame comes from a callable value(frame, patch): its rise above its rest level, px, up
// positive, NaN where it was not measured.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "height_curve.h"

namespace liftoff::video::internal {

/// Patches that end within this of their rest level are ground, px.
inline constexpr double kGroundTolerancePx = 0.5;
/// The foot's patches move all the way with it: a candidate's gain against the candidates'
/// median curve must reach this fraction of the upper quartile of their gains.
inline constexpr double kFullGainQuantile = 0.75;
inline constexpr double kFullGainFraction = 0.5;
/// A foot candidate that does not rest with the others: its distance from its rest level
/// where theirs is at rest is over this many times theirs and over this many px (a codec's
/// and the registration's noise stays well under it; the patches that slipped and stayed
/// were 7 to 32 px away).
inline constexpr double kOffRestFactor = 3.0;
inline constexpr double kOffRestFloorPx = 2.0;

/// Per frame, the median over `members` of value(frame, patch); NaN where fewer than
/// `min_count` are finite.
template <typename Value>
std::vector<double> MedianCurve(size_t frames, const std::vector<size_t>& members, size_t min_count,
                                const Value& value) {
  std::vector<double> curve(frames, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> values;
  for (size_t f = 0; f < frames; ++f) {
    values.clear();
    for (size_t p : members) values.push_back(value(f, p));
    const double median = FiniteMedian(values);
    if (values.size() >= std::max<size_t>(1, min_count)) curve[f] = median;
  }
  return curve;
}

/// The patches that rest where the others rest (frames [first, frames)): those whose median
/// distance from their rest level, over the frames where the patches' median curve is
/// within kGroundTolerancePx of its own, is at most kOffRestFactor times the patches' median
/// one or at most kOffRestFloorPx (a patch that slipped up an edge seconds before the
/// liftoff and stayed there ends as high as the foot: hard3d-08, --seed 0 and 5000, and
/// hard3d-02, --seed 7000, took one for the foot alone). It cannot tell with two patches
/// (their median is their mean) nor when the off-rest ones are half of them.
template <typename Value>
std::vector<size_t> RestingWithTheOthers(const std::vector<size_t>& patches, size_t first,
                                         size_t frames, const Value& value) {
  const std::vector<double> common = MedianCurve(frames, patches, 1, value);
  std::vector<double> off_rest_px;
  for (size_t p : patches) {
    std::vector<double> distances_px;
    for (size_t f = first; f < frames; ++f) {
      const double v = value(f, p);
      if (std::isfinite(v) && std::abs(common[f]) <= kGroundTolerancePx) {
        distances_px.push_back(std::abs(v));
      }
    }
    off_rest_px.push_back(FiniteMedian(distances_px));
  }
  std::vector<double> sorted = off_rest_px;
  const double usual_px = FiniteMedian(sorted);
  std::vector<size_t> resting;
  for (size_t i = 0; i < patches.size(); ++i) {
    if (!(off_rest_px[i] > std::max(kOffRestFactor * usual_px, kOffRestFloorPx))) {
      resting.push_back(patches[i]);
    }
  }
  return resting;
}

/// The candidates that move with the others, all the way (frames [first, frames)): those
/// resting with the others (RestingWithTheOthers), then each one's gain against their median
/// curve (least squares); a patch that holds some ground or shadow moves by a fraction of
/// the foot's motion, one on something else by none of it.
template <typename Value>
std::vector<size_t> MovingWithTheOthers(const std::vector<size_t>& candidates, size_t first,
                                        size_t frames, const Value& value) {
  const std::vector<size_t> resting = RestingWithTheOthers(candidates, first, frames, value);
  const std::vector<double> common = MedianCurve(frames, resting, 1, value);
  std::vector<double> gains(resting.size(), 0.0);
  for (size_t i = 0; i < resting.size(); ++i) {
    double product = 0, norm = 0;
    for (size_t f = first; f < frames; ++f) {
      const double v = value(f, resting[i]);
      if (!std::isfinite(v) || !std::isfinite(common[f])) continue;
      product += v * common[f];
      norm += common[f] * common[f];
    }
    gains[i] = norm > 0 ? product / norm : 0.0;
  }
  std::vector<double> sorted = gains;
  const double full = FiniteQuantile(sorted, kFullGainQuantile);
  std::vector<size_t> moving;
  for (size_t i = 0; i < resting.size(); ++i) {
    if (gains[i] >= kFullGainFraction * full) moving.push_back(resting[i]);
  }
  return moving;
}

}  // namespace liftoff::video::internal
