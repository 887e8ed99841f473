// From a trial's video times to the rotating vertebra's angle at liftoff.
//
// The video gives two instants on its own clock: the LED switching on and the foot
// leaving the ground. The controller log's clock has its origin at (or records) the LED
// switch-on, so the interval between the two maps the liftoff onto the log:
//   ClockMap log_from_video{video LED-on -> log LED-on, scale 1};
//   int64_t liftoff_log_ns = log_from_video(video_times.liftoff_ns);
// and the vertebra angle is read from the log's samples at that instant, under a lookup
// rule, with an interval that says how far the answer can be trusted.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/status.h"
#include "liftoff/core/time.h"

namespace liftoff::sync {

/// How a log's samples answer a query between them.
enum class LookupRule {
  /// Straight line between the two samples around the query (the sample's own value at a
  /// sample).
  kLinear,
  /// The last sample at or before the query (inclusive: a sample exactly at the query is
  /// used). The 2018 authors' rule.
  kSampleAndHold,
};

/// "linear", "sample-and-hold".
std::string_view LookupRuleName(LookupRule rule);
/// Parses "linear", "hold" or "sample-and-hold"; nullopt otherwise.
std::optional<LookupRule> ParseLookupRule(std::string_view text);

struct LookupOptions {
  /// Rule used for the reported value.
  LookupRule rule = LookupRule::kLinear;
  /// Two consecutive samples further apart than this bracket a gap, s (> 0). Inside a gap
  /// the angle is only known to lie between the bracketing samples' values.
  /// (0, kMaxTimeSeconds].
  double gap_threshold_s = 0.25;
  /// A query up to this long after the last sample (or before the first) is answered with
  /// the held end value and flagged; further out it is kOutOfRange, s
  /// ([0, kMaxTimeSeconds]).
  double max_past_end_s = 1.0;

  /// The allowed values of gap_threshold_s and max_past_end_s, s.
  static constexpr NumberRange kGapThresholdRange{
      .min = 0.0, .max = kMaxTimeSeconds, .min_exclusive = true};
  static constexpr NumberRange kMaxPastEndRange{.min = 0.0, .max = kMaxTimeSeconds};

  /// kInvalidArgument naming the field and the allowed range.
  Status Validate() const;
};

/// The vertebra angle at one instant of a log, with its uncertainty.
struct AngleLookup {
  /// Rule that produced `vertebra_rad`.
  LookupRule rule = LookupRule::kLinear;
  /// Queried instant, device clock, ns.
  int64_t query_ns = 0;
  /// Half-width of the query's uncertainty, ns (the window is query_ns +/- this).
  int64_t query_uncertainty_ns = 0;
  /// Vertebra angle at the query under `rule`, rad (signed, as logged).
  double vertebra_rad = 0.0;
  /// Range the angle can take over the query's uncertainty window under `rule`, widened
  /// over gaps (to both bracketing values) and past the log's ends (by the log's mean
  /// rate times the distance), rad. lower_rad <= vertebra_rad <= upper_rad.
  double lower_rad = 0.0;
  double upper_rad = 0.0;
  /// Device time of the last sample at or before the query, and of the first at or after
  /// it (both equal the query for a query exactly at a sample), ns. Samples without a
  /// vertebra angle are ignored.
  std::optional<int64_t> sample_before_ns;
  std::optional<int64_t> sample_after_ns;
  /// Whether the query's window overlaps a gap (see LookupOptions::gap_threshold_s).
  bool in_gap = false;
  /// Length of that gap (the one around the query, else the longest overlapped), ns; 0
  /// when not in a gap.
  int64_t gap_ns = 0;
  /// Whether the query is after the last sample / before the first (within tolerance; the
  /// end value is held).
  bool past_end = false;
  bool before_start = false;
  /// Sentences for people: "instant 6.000 s is inside a 0.93 s gap between samples at
  /// 5.071 s and 6.004 s", ...
  std::vector<std::string> warnings;

  /// "-0.4600 rad [-0.4800, -0.4550] at 6.130 s (sample-and-hold; inside a 0.93 s gap)".
  std::string Brief() const;
};

/// The vertebra angle of `log` at `query_ns` (device clock), with the interval it can
/// take over [query - uncertainty, query + uncertainty]. Uses the samples' vertebra_rad,
/// skipping samples where it is NaN. kInvalidArgument for bad options or a negative
/// uncertainty; kNotFound for a log without any vertebra angle; kOutOfRange for a query
/// more than options.max_past_end_s outside the log ("instant 12.400 s is after the log's
/// last sample at 9.079 s (log spans 0.004-9.079 s)").
Result<AngleLookup> LookupVertebraAngle(const ControllerLog& log, int64_t query_ns,
                                        int64_t query_uncertainty_ns, const LookupOptions& options);

/// One trial's liftoff angle.
struct LiftoffMeasurement {
  /// Liftoff minus LED on, on the video's clock, ns.
  int64_t interval_ns = 0;
  /// Half-width of the interval's uncertainty: the sum of both events' uncertainties, ns.
  int64_t interval_uncertainty_ns = 0;
  /// Video clock to the log's device clock: the video's LED-on instant maps to the log's
  /// LED-on time (0 when the log records none: the 2018 device clock starts at the LED
  /// switch-on), scale 1.
  ClockMap log_from_video;
  /// Liftoff on the log's device clock, ns.
  int64_t liftoff_log_ns = 0;
  /// The lookup at liftoff_log_ns with interval_uncertainty_ns.
  AngleLookup lookup;
  /// |vertebra angle| at liftoff, rad (the paper reports absolute values).
  double liftoff_rad = 0.0;
  /// Interval of |angle| over the lookup's interval, rad (0 <= lower <= upper).
  double lower_rad = 0.0;
  double upper_rad = 0.0;

  /// "liftoff 6.130 s after LED on (+/- 0.077 s): |vertebra| 0.4600 rad [0.4550, 0.4800] ...".
  std::string Brief() const;
};

/// Maps `video_times` onto `log` and looks up the angle at liftoff. kInvalidArgument when
/// liftoff is before LED on or an uncertainty is negative; otherwise the lookup's errors.
Result<LiftoffMeasurement> MeasureLiftoff(const ControllerLog& log, const EventTimes& video_times,
                                          const LookupOptions& options);

}  // namespace liftoff::sync
