// The LED's switch-on and switch-off instants from the frames around them: the interval
// of every instant consistent with what two neighbouring frames saw (private to the video
// module; tested on its own in tests/video/led_timing_test.cc).
//
// Exposure convention: a frame with timestamp t integrates [t - E/2, t + E/2] (the
// timestamp is the middle of the exposure). A frame then sees an LED that switches on at
// s lit for the fraction clamp((t + E/2 - s) / E, 0, 1) of its exposure, and one that
// switches off at s lit for clamp((s - t + E/2) / E, 0, 1). Every bound below is linear
// in E for a given frame, so the union over the exposures allowed is found exactly from a
// few candidate exposures (the range's ends and where two bounds cross).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace liftoff::video::internal {

// Half-widths are capped here, ns (about 146 years: far inside int64).
constexpr double kMaxNs = 4.6e18;

// A closed interval of instants, ns (double: sub-ns maths, rounded at the end).
struct InstantInterval {
  double low_ns = 0.0, high_ns = 0.0;
  int64_t Middle() const { return static_cast<int64_t>(std::llround(0.5 * (low_ns + high_ns))); }
  int64_t HalfWidth() const {  // (bounded: never beyond int64)
    return static_cast<int64_t>(std::ceil(std::min(0.5 * std::max(0.0, high_ns - low_ns), kMaxNs)));
  }
  bool Contains(double t_ns) const { return t_ns >= low_ns && t_ns <= high_ns; }
};

// What one frame saw of the LED: the lit fraction of its exposure lies in [low, high]
// (0 <= low <= high <= 1).
struct LitFraction {
  double low = 0.0, high = 0.0;
};

// The exposures allowed, ns: [min_ns, max_ns] (equal when the exposure is known; 0 ..
// the frame interval when it is not).
struct ExposureRange {
  double min_ns = 0.0, max_ns = 0.0;
};

// The switch-on instants consistent with frame `dark` (timestamp t_dark_ns, lit fraction
// in [0, dark.high]) and the next frame `lit` (t_lit_ns > t_dark_ns, lit fraction in
// [lit.low, lit.high]) for some exposure in `exposure`. When no exposure in the range is
// consistent (measurements off by more than their bands), the range is widened down to 0
// (where every observation is consistent), so the answer is never empty.
inline InstantInterval SwitchOnInterval(double t_dark_ns, LitFraction dark, double t_lit_ns,
                                        LitFraction lit, ExposureRange exposure) {
  // for an exposure e, s lies in [max(low_dark(e), low_lit(e)), high(e)] with
  //   dark frame lit at most dark.high:      s >= t_dark + (1/2 - dark.high) e
  //   lit frame lit at most lit.high (< 1):  s >= t_lit + (1/2 - lit.high) e
  //   lit frame lit at least lit.low:        s <= t_lit + (1/2 - lit.low) e
  struct Line {
    double at0 = 0.0, slope = 0.0;
    double At(double e) const { return at0 + slope * e; }
  };
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  const Line low_dark{t_dark_ns, 0.5 - dark.high};
  const bool lit_bounds_below = lit.high < 1.0;
  const Line low_lit{lit_bounds_below ? t_lit_ns : kNone, 0.5 - lit.high};
  const Line high{t_lit_ns, 0.5 - lit.low};
  const auto low = [&](double e) {
    return lit_bounds_below ? std::max(low_dark.At(e), low_lit.At(e)) : low_dark.At(e);
  };
  for (int attempt = 0; attempt < 2; ++attempt) {
    const double e_min = attempt == 0 ? exposure.min_ns : 0.0, e_max = exposure.max_ns;
    // the range's ends and the crossings of every two bounds inside it
    std::array<double, 5> candidates{e_min, e_max, e_min, e_min, e_min};
    const auto crossing = [&](const Line& a, const Line& b, double& out) {
      if (a.slope == b.slope || !std::isfinite(a.at0) || !std::isfinite(b.at0)) return;
      const double e = (b.at0 - a.at0) / (a.slope - b.slope);
      if (e > e_min && e < e_max) out = e;
    };
    crossing(low_dark, high, candidates[2]);
    if (lit_bounds_below) {
      crossing(low_lit, high, candidates[3]);
      crossing(low_dark, low_lit, candidates[4]);
    }
    InstantInterval interval{std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity()};
    const double tolerance_ns = 1e-6 * std::max(1.0, e_max);
    for (const double e : candidates) {
      if (low(e) > high.At(e) + tolerance_ns) continue;
      interval.low_ns = std::min(interval.low_ns, low(e));
      interval.high_ns = std::max(interval.high_ns, high.At(e));
    }
    if (interval.low_ns <= interval.high_ns) return interval;
  }
  return {t_dark_ns, t_lit_ns};  // unreachable: e -> 0 is always consistent
}

// A switch-on dated from the frames around it, allowing for frames missing between them.
// `surely` holds every instant consistent with the two frames seen (SwitchOnInterval).
// When frames are missing (the two frames more than 1.5 usual intervals apart) and the lit
// frame was lit all through its exposure (it cannot date the switch itself), the estimate
// takes the first missing frame, one usual interval after the dark one, as the first that
// saw the LED, lit for an unknown part of its exposure: frames dropped because of the
// change (a camera or its encoder reacting to it) are dropped from the first one that
// changed. With the exposure E known that is the middle of [dark + E/2, first missing +
// E/2]; unknown, the middle of the union over every E in (0, T]. A drop unrelated to the
// switch could begin anywhere in the gap; `surely` covers the whole gap either way.
// Otherwise the estimate is the middle of `surely`.
struct SwitchOnDating {
  InstantInterval surely;
  double estimate_ns = 0.0;
  // frames missing between the dark and the lit frame, when the estimate took the first
  // of them as the first lit (0 otherwise, a partly lit frame dating the switch itself)
  int missing_frames = 0;
  // the half-width of the narrowest interval centred on the estimate that holds `surely`
  int64_t HalfWidth() const {
    return static_cast<int64_t>(std::ceil(std::min(
        std::max({0.0, estimate_ns - surely.low_ns, surely.high_ns - estimate_ns}), kMaxNs)));
  }
};

inline SwitchOnDating DateSwitchOn(double t_dark_ns, LitFraction dark, double t_lit_ns,
                                   LitFraction lit, ExposureRange exposure, double period_ns) {
  SwitchOnDating dating;
  dating.surely = SwitchOnInterval(t_dark_ns, dark, t_lit_ns, lit, exposure);
  dating.estimate_ns = 0.5 * (dating.surely.low_ns + dating.surely.high_ns);
  const bool gap = period_ns > 0.0 && t_lit_ns - t_dark_ns > 1.5 * period_ns;
  if (!gap || lit.high < 1.0) return dating;
  // (bounded: a gap of hours between two frames must not overflow the count)
  const double intervals = std::min(std::round((t_lit_ns - t_dark_ns) / period_ns), 1e9);
  dating.missing_frames = static_cast<int>(intervals) - 1;
  const InstantInterval first_missing =
      SwitchOnInterval(t_dark_ns, dark, t_dark_ns + period_ns, {0.0, 1.0}, exposure);
  dating.estimate_ns = std::clamp(0.5 * (first_missing.low_ns + first_missing.high_ns),
                                  dating.surely.low_ns, dating.surely.high_ns);
  return dating;
}

// A switch-on that a codec spread over several frames in a row, each lit part way (H.264's
// B-frames blend the step into their neighbours; a small light is built up over frames):
// the instant at which the lit fraction crosses one half, linear between the frame before
// the crossing (t_below_ns, lit f_below < 1/2) and the one at or above it (t_above_ns,
// f_above >= 1/2). A frame lit half its exposure is centred on the switch-on whatever the
// exposure (s = t + E (1/2 - f)), and a blend spreads the step about evenly either side
// of it, so the crossing does not depend on which of the spread frames first passes a
// threshold. Fractions that do not straddle one half give the frame on the half's side: the
// first when it is lit half or more already, the second when it is still under half.
inline double HalfLitInstant(double t_below_ns, double f_below, double t_above_ns, double f_above) {
  if (f_below >= 0.5) return t_below_ns;
  if (!(f_above >= 0.5)) return t_above_ns;
  return t_below_ns + (0.5 - f_below) / (f_above - f_below) * (t_above_ns - t_below_ns);
}

// The switch-off instants consistent with frame `lit` (t_lit_ns, lit fraction in
// [lit.low, lit.high]) and the next frame `dark` (t_dark_ns > t_lit_ns, lit fraction in
// [0, dark.high]): the switch-on problem with time reversed (a centred exposure is
// symmetric).
inline InstantInterval SwitchOffInterval(double t_lit_ns, LitFraction lit, double t_dark_ns,
                                         LitFraction dark, ExposureRange exposure) {
  const InstantInterval reversed = SwitchOnInterval(-t_dark_ns, dark, -t_lit_ns, lit, exposure);
  return {-reversed.high_ns, -reversed.low_ns};
}

}  // namespace liftoff::video::internal
