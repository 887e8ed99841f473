#include "height_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "video_util.h"

namespace liftoff::video::internal {
namespace {

double Seconds(int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

}  // namespace

double LevelStep(const std::vector<double>& curve, size_t key, size_t count) {
  std::vector<double> after, before;
  for (size_t g = key; g < std::min(curve.size(), key + count); ++g) after.push_back(curve[g]);
  for (size_t g = key - std::min(key, count); g < key; ++g) before.push_back(curve[g]);
  const double step = FiniteMedian(after) - FiniteMedian(before);
  return std::isfinite(step) ? step : 0.0;
}

bool ResetsADrift(const std::vector<HeightSample>& samples, const std::vector<double>& curve,
                  size_t key, double step, size_t count) {
  size_t previous = key;
  while (previous-- > 0 && !samples[previous].keyframe) {
  }
  if (previous >= key || key - previous < 2 * count) return false;
  const auto median_of = [&](size_t from) {
    std::vector<double> values(curve.begin() + static_cast<std::ptrdiff_t>(from),
                               curve.begin() + static_cast<std::ptrdiff_t>(from + count));
    return FiniteMedian(values);
  };
  const double drift = median_of(key - count) - median_of(previous);
  return drift * step < 0 && std::abs(drift) >= 0.5 * std::abs(step);
}

void LevelQuietKeyframes(const std::vector<HeightSample>& samples, size_t start, size_t cut,
                         size_t frames, double quiet_px, std::vector<double>& levelled) {
  const auto holds = [&](size_t from, size_t to) {  // frames [from, to)
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (size_t f = from; f < to; ++f) {
      if (!std::isfinite(levelled[f])) return false;
      low = std::min(low, levelled[f]);
      high = std::max(high, levelled[f]);
    }
    return high - low <= quiet_px;
  };
  for (size_t key = start + frames; key + frames <= cut; ++key) {
    if (!samples[key].keyframe) continue;
    if (!holds(key - frames, key) || !holds(key, key + frames)) continue;
    const double step = LevelStep(levelled, key, frames);
    for (size_t f = start; f < key; ++f) levelled[f] += step;
  }
}

double KeyframeNoisePx(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                       size_t first, size_t last) {
  std::vector<double> keys;
  for (size_t f = first; f < std::min(last, height.size()); ++f) {
    if (samples[f].keyframe && std::isfinite(height[f])) keys.push_back(height[f]);
  }
  return keys.size() > kMinKeyframeChanges ? SuccessiveDifferenceSigma(keys) : 0.0;
}

size_t ReachKeyframe(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                     const std::vector<double>& smooth, size_t cut, size_t smooth_half,
                     double threshold_px, double reach_s, double reach_tops) {
  double highest = std::isfinite(height[cut]) ? height[cut]
                                              : -std::numeric_limits<double>::infinity();
  for (size_t f = cut + 1; f + smooth_half < smooth.size(); ++f) {
    if (Seconds(samples[f].t_ns - samples[cut].t_ns) > reach_s) break;
    if (!(smooth[f] <= reach_tops * smooth[cut])) break;
    if (height[f] < highest - threshold_px) break;
    if (std::isfinite(height[f])) highest = std::max(highest, height[f]);
    if (samples[f].keyframe && std::isfinite(height[f])) return f;
  }
  return 0;
}

double LagBoundPx(const std::vector<double>& height, size_t first, size_t last, double min_lag_px,
                  double factor, double noise_px) {
  const auto change = [&](size_t f) {
    const double c = height[f] - height[f - 1];
    return std::isfinite(c) ? c : 0.0;
  };
  double largest = 0;
  for (size_t f = first + 1; f <= last; ++f) {
    const double before = f >= first + 2 ? change(f - 1) : 0.0;
    const double after = f + 1 <= last ? change(f + 1) : 0.0;
    largest = std::max(largest, change(f) - std::max({0.0, before, after}));
  }
  return std::max(min_lag_px, factor * (largest - noise_px));
}

size_t SustainedCrossing(const std::vector<double>& height, size_t first, size_t last,
                         double level) {
  for (size_t f = first; f + 2 <= last; ++f) {
    if (height[f] >= level && height[f + 1] >= level && height[f + 2] >= level) return f;
  }
  return last + 1;
}

double SurelyAboveS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                    size_t first, size_t last, double level, double margin_px) {
  const size_t above = SustainedCrossing(height, first, last, level + margin_px);
  if (above > last) return std::numeric_limits<double>::quiet_NaN();
  return Seconds(samples[above].t_ns);
}

size_t FinalRunStart(const std::vector<double>& height, size_t first, size_t last, double level) {
  if (!(height[last] >= level)) return last + 1;
  size_t f = last;
  while (f > first && !(height[f - 1] < level)) --f;
  return f;
}

double LineCrossingS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                     size_t at, size_t first, size_t last, double level) {
  if (at > last || at < first + 2) return std::numeric_limits<double>::quiet_NaN();
  double st = 0, sh = 0, stt = 0, sth = 0, n = 0;
  const double origin_s = Seconds(samples[at].t_ns);
  for (size_t f = at - 2; f <= at + 2 && f <= last; ++f) {
    if (!std::isfinite(height[f])) continue;
    const double t = Seconds(samples[f].t_ns) - origin_s;
    st += t, sh += height[f], stt += t * t, sth += t * height[f], n += 1;
  }
  const double slope = (n * sth - st * sh) / (n * stt - st * st);
  if (!(slope > 0)) return std::numeric_limits<double>::quiet_NaN();
  const double intercept = (sh - slope * st) / n;
  return origin_s + (level - intercept) / slope;
}

double LocalCrossingS(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                      size_t first, size_t last, double level) {
  return LineCrossingS(samples, height, SustainedCrossing(height, first, last, level), first,
                       last, level);
}

Sinking SankBefore(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                   size_t first, size_t at, double rest_level, double threshold_px,
                   double sunk_px) {
  Sinking sinking;
  double lowest = rest_level;
  size_t deepest = at;
  for (size_t f = first; f < at; ++f) {
    if (std::isfinite(height[f]) && height[f] < lowest) {
      lowest = height[f];
      deepest = f;
    }
  }
  if (!(lowest < rest_level - sunk_px)) return sinking;
  // back from the deepest frame (the curve passes rest again on its way up)
  size_t rest = deepest;
  while (rest > first && !(std::abs(height[rest - 1] - rest_level) <= threshold_px)) --rest;
  sinking.sank = true;
  sinking.depth_px = rest_level - lowest;
  sinking.rest_s = Seconds(samples[rest > 0 ? rest - 1 : 0].t_ns);
  return sinking;
}

CurveCheck CheckCrossing(const std::vector<HeightSample>& samples,
                         const std::vector<double>& height, size_t first, size_t last,
                         double level, double model_s, double model_uncertainty_s) {
  CurveCheck check;
  const size_t above = FinalRunStart(height, first, last, level);
  if (above > last || above == 0) return check;
  const double above_s = Seconds(samples[above].t_ns);
  if (!(model_s - model_uncertainty_s > above_s)) return check;
  const double before_s = Seconds(samples[above - 1].t_ns);
  double curve_s = LineCrossingS(samples, height, above, first, last, level);
  if (!(curve_s >= before_s && curve_s <= above_s)) {
    const double from = height[above - 1], to = height[above];
    curve_s = std::isfinite(from) && to > from
                  ? before_s + (above_s - before_s) * (level - from) / (to - from)
                  : above_s;
  }
  check.disagreed = true;
  check.crossing_s = curve_s;
  check.uncertainty_s = std::max(model_uncertainty_s, above_s - before_s);
  return check;
}

Instant SunkCrossing(double rest_s, double crossing_s, double uncertainty_s) {
  const double low_s = std::min(rest_s, crossing_s - uncertainty_s);
  const double high_s = crossing_s + uncertainty_s;
  return {0.5 * (low_s + high_s), 0.5 * (high_s - low_s)};
}

namespace {

// One patch's crossing for PatchCrossingSpreadS, s; nullopt for none.
std::optional<double> PatchCrossingS(const std::vector<HeightSample>& samples,
                                     const std::vector<double>& curve_px, size_t first,
                                     double level_px, size_t sustain_frames, size_t short_frames) {
  size_t last = curve_px.size();  // one past the last measured frame
  while (last > first && !std::isfinite(curve_px[last - 1])) --last;
  size_t above = 0, start = 0;
  std::optional<size_t> below;
  for (size_t f = first; f < last && above < sustain_frames; ++f) {
    if (!std::isfinite(curve_px[f])) continue;
    if (curve_px[f] > level_px) {
      if (above++ == 0) start = f;
    } else {
      above = 0;
      below = f;
    }
  }
  // a run shorter than sustain_frames went on to the patch's last measured frame
  if (above < std::min(sustain_frames, short_frames) || !below) return std::nullopt;
  const double t0_s = Seconds(samples[*below].t_ns), t1_s = Seconds(samples[start].t_ns);
  const double h0_px = curve_px[*below], h1_px = curve_px[start];
  return t0_s + (t1_s - t0_s) * (level_px - h0_px) / (h1_px - h0_px);
}

}  // namespace

double PatchCrossingSpreadS(const std::vector<HeightSample>& samples,
                            const std::vector<std::vector<double>>& curves_px, size_t first,
                            double level_px, size_t sustain_frames, size_t short_frames) {
  std::vector<double> crossings_s;
  for (const std::vector<double>& curve_px : curves_px) {
    const std::optional<double> crossing_s =
        PatchCrossingS(samples, curve_px, first, level_px, sustain_frames, short_frames);
    if (crossing_s && std::isfinite(*crossing_s)) crossings_s.push_back(*crossing_s);
  }
  if (crossings_s.size() < 3) return 0.0;
  return MadSigma(std::move(crossings_s));
}

}  // namespace liftoff::video::internal
