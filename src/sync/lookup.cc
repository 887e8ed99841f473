#include "liftoff/sync/lookup.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <tuple>
#include <utility>

#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::sync {
namespace {

// a sample that carries a vertebra angle
struct AnglePoint {
  int64_t time_ns;
  double vertebra_rad;
};

std::string Rad(double value_rad) { return FormatFixed(value_rad, 4); }

std::string Sec(int64_t ns) { return FormatSeconds(ns, 3) + " s"; }

// the angle at `time_ns` under `rule`, holding the end values outside the log
double AngleAt(const std::vector<AnglePoint>& points, int64_t time_ns, LookupRule rule) {
  if (time_ns <= points.front().time_ns) return points.front().vertebra_rad;
  if (time_ns >= points.back().time_ns) return points.back().vertebra_rad;
  const auto after =
      std::upper_bound(points.begin(), points.end(), time_ns,
                       [](int64_t t, const AnglePoint& point) { return t < point.time_ns; });
  const AnglePoint& before = *(after - 1);
  if (rule == LookupRule::kSampleAndHold || before.time_ns == time_ns) return before.vertebra_rad;
  const double fraction = static_cast<double>(time_ns - before.time_ns) /
                          static_cast<double>(after->time_ns - before.time_ns);
  return before.vertebra_rad + fraction * (after->vertebra_rad - before.vertebra_rad);
}

// The samples with an angle around [begin_ns, end_ns]: all inside, plus two on either side
// (or up to the log's ends), found by binary search so a lookup costs O(log n + window)
// even in a long capture.
std::vector<AnglePoint> AnglePointsAround(const std::vector<LogSample>& samples, int64_t begin_ns,
                                          int64_t end_ns) {
  const auto by_time = [](const LogSample& sample, int64_t t) { return sample.device_time_ns < t; };
  auto lo = std::lower_bound(samples.begin(), samples.end(), begin_ns, by_time);
  auto hi = std::lower_bound(lo, samples.end(), end_ns, by_time);
  for (int found = 0; lo != samples.begin() && found < 2;) {
    --lo;
    if (!std::isnan(lo->vertebra_rad)) ++found;
  }
  for (int found = 0; hi != samples.end() && found < 2; ++hi) {
    if (!std::isnan(hi->vertebra_rad)) ++found;
  }
  std::vector<AnglePoint> points;
  for (auto it = lo; it != hi; ++it) {
    if (!std::isnan(it->vertebra_rad)) points.push_back({it->device_time_ns, it->vertebra_rad});
  }
  return points;
}

}  // namespace

std::string_view LookupRuleName(LookupRule rule) {
  switch (rule) {
    case LookupRule::kLinear: return "linear";
    case LookupRule::kSampleAndHold: return "sample-and-hold";
  }
  return "unknown";
}

std::optional<LookupRule> ParseLookupRule(std::string_view text) {
  if (text == "linear") return LookupRule::kLinear;
  if (text == "hold" || text == "sample-and-hold") return LookupRule::kSampleAndHold;
  return std::nullopt;
}

Status LookupOptions::Validate() const {
  for (const auto& [name, value_s, range] :
       {std::tuple{"gap_threshold_s", gap_threshold_s, kGapThresholdRange},
        std::tuple{"max_past_end_s", max_past_end_s, kMaxPastEndRange}}) {
    if (!InNumberRange(value_s, range)) {
      return InvalidArgumentError(std::string("lookup options: ") + name + ": expected " +
                                  DescribeNumberRange(range) + " s, got " + FormatNumber(value_s));
    }
  }
  return Status::Ok();
}

std::string AngleLookup::Brief() const {
  std::string text = Rad(vertebra_rad) + " rad [" + Rad(lower_rad) + ", " + Rad(upper_rad) +
                     "] at " + FormatSeconds(query_ns) + " +/- " +
                     FormatSeconds(query_uncertainty_ns) + " s (" +
                     std::string(LookupRuleName(rule));
  if (in_gap) text += "; in a " + FormatSeconds(gap_ns, 2) + " s gap";
  if (past_end) text += "; past the log's end";
  if (before_start) text += "; before the log's start";
  return text + ")";
}

namespace {

// OK when |time_ns| <= kMaxLogTimeNs (readers of liftoff's format enforce it; this holds
// for logs made in memory or read by other readers)
Status CheckLogTime(std::string_view what, int64_t time_ns) {
  if (time_ns >= -kMaxLogTimeNs && time_ns <= kMaxLogTimeNs) return Status::Ok();
  return OutOfRangeError(std::string(what) + " at " + std::to_string(time_ns) +
                         " ns: expected a time within +-4e18 ns (about 127 years)");
}

// the first and last samples that carry an angle
struct AngleEnds {
  AnglePoint first;
  AnglePoint last;
};

// the query's uncertainty window, [begin_ns, end_ns] around query_ns
struct QueryWindow {
  int64_t query_ns;
  int64_t uncertainty_ns;
  int64_t begin_ns;
  int64_t end_ns;
};

Result<AngleEnds> FindAngleEnds(const ControllerLog& log) {
  if (log.samples.empty()) return NotFoundError("the log has no samples");
  const auto has_angle = [](const LogSample& sample) { return !std::isnan(sample.vertebra_rad); };
  const auto first_sample = std::find_if(log.samples.begin(), log.samples.end(), has_angle);
  if (first_sample == log.samples.end()) {
    return NotFoundError("none of the log's " + std::to_string(log.samples.size()) +
                         " samples has a vertebra angle");
  }
  const auto last_sample = std::find_if(log.samples.rbegin(), log.samples.rend(), has_angle);
  return AngleEnds{{first_sample->device_time_ns, first_sample->vertebra_rad},
                   {last_sample->device_time_ns, last_sample->vertebra_rad}};
}

// kOutOfRange for a query more than max_past_end_s outside the log
Status CheckQueryNearLog(int64_t query_ns, const AngleEnds& ends, const LookupOptions& options) {
  const AnglePoint& first = ends.first;
  const AnglePoint& last = ends.last;
  const std::string span =
      "(log spans " + FormatSeconds(first.time_ns) + "-" + FormatSeconds(last.time_ns) + " s)";
  const int64_t tolerance_ns = NsFromSeconds(options.max_past_end_s);
  const std::string limit = "; at most max_past_end_s = " + FormatSeconds(tolerance_ns) +
                            " s outside the log is answered";
  if (query_ns > last.time_ns && query_ns - last.time_ns > tolerance_ns) {
    return OutOfRangeError("instant " + Sec(query_ns) + " is after the log's last sample at " +
                           Sec(last.time_ns) + " " + span + limit);
  }
  if (query_ns < first.time_ns && first.time_ns - query_ns > tolerance_ns) {
    return OutOfRangeError("instant " + Sec(query_ns) + " is before the log's first sample at " +
                           Sec(first.time_ns) + " " + span + limit);
  }
  return Status::Ok();
}

// The checks before a lookup: options, uncertainty, a log with angles, times that cannot
// overflow, a query near enough the log. Returns the log's ends.
Result<AngleEnds> CheckLookup(const ControllerLog& log, int64_t query_ns,
                              int64_t query_uncertainty_ns, const LookupOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (query_uncertainty_ns < 0) {
    return InvalidArgumentError("query uncertainty: expected >= 0 ns, got " +
                                std::to_string(query_uncertainty_ns));
  }
  LIFTOFF_ASSIGN_OR_RETURN(const AngleEnds ends, FindAngleEnds(log));
  // times within +-kMaxLogTimeNs: no difference in the lookup can overflow
  LIFTOFF_RETURN_IF_ERROR(
      CheckLogTime("the log's first sample", log.samples.front().device_time_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the log's last sample", log.samples.back().device_time_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the instant looked up", query_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the instant's uncertainty", query_uncertainty_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckQueryNearLog(query_ns, ends, options));
  return ends;
}

// bracketing samples: last at or before the query, first at or after
void SetBracketingSamples(const std::vector<AnglePoint>& points, AngleLookup& lookup) {
  const int64_t query_ns = lookup.query_ns;
  const auto at_or_after =
      std::lower_bound(points.begin(), points.end(), query_ns,
                       [](const AnglePoint& point, int64_t t) { return point.time_ns < t; });
  if (at_or_after != points.end()) lookup.sample_after_ns = at_or_after->time_ns;
  if (at_or_after != points.end() && at_or_after->time_ns == query_ns) {
    lookup.sample_before_ns = query_ns;
  } else if (at_or_after != points.begin()) {
    lookup.sample_before_ns = (at_or_after - 1)->time_ns;
  }
}

using PointIt = std::vector<AnglePoint>::const_iterator;

// Range of the rule's answer over the window, into lookup.lower_rad/upper_rad: its ends and
// every sample inside. Returns the samples strictly inside the window.
std::pair<PointIt, PointIt> SetRangeOverWindow(const std::vector<AnglePoint>& points,
                                               const QueryWindow& window, AngleLookup& lookup) {
  const double at_window_begin_rad = AngleAt(points, window.begin_ns, lookup.rule);
  const double at_window_end_rad = AngleAt(points, window.end_ns, lookup.rule);
  double lower = std::min({at_window_begin_rad, at_window_end_rad, lookup.vertebra_rad});
  double upper = std::max({at_window_begin_rad, at_window_end_rad, lookup.vertebra_rad});
  const PointIt inside_begin =
      std::upper_bound(points.begin(), points.end(), window.begin_ns,
                       [](int64_t t, const AnglePoint& point) { return t < point.time_ns; });
  PointIt inside_end = inside_begin;
  for (; inside_end != points.end() && inside_end->time_ns < window.end_ns; ++inside_end) {
    lower = std::min(lower, inside_end->vertebra_rad);
    upper = std::max(upper, inside_end->vertebra_rad);
  }
  lookup.lower_rad = lower;
  lookup.upper_rad = upper;
  return {inside_begin, inside_end};
}

// Gaps the window overlaps: the angle there is only known to lie between their ends. Widens
// the range to them and reports one (the gap around the query, else the longest).
void AddGapsOverlapped(const std::vector<AnglePoint>& points, PointIt inside_begin,
                       PointIt inside_end, const QueryWindow& window, double gap_threshold_s,
                       AngleLookup& lookup) {
  const int64_t query_ns = window.query_ns;
  const int64_t gap_threshold_ns = NsFromSeconds(gap_threshold_s);
  const auto scan_begin = inside_begin == points.begin() ? inside_begin : inside_begin - 1;
  const auto scan_end = inside_end == points.end() ? inside_end : inside_end + 1;
  const AnglePoint* gap_before = nullptr;  // the reported gap
  bool query_in_reported_gap = false;
  for (auto it = scan_begin; it != scan_end && it + 1 != points.end(); ++it) {
    const AnglePoint& before = *it;
    const AnglePoint& after = *(it + 1);
    const int64_t gap_ns = after.time_ns - before.time_ns;
    if (gap_ns <= gap_threshold_ns) continue;
    if (before.time_ns >= window.end_ns || after.time_ns <= window.begin_ns) continue;
    lookup.lower_rad = std::min({lookup.lower_rad, before.vertebra_rad, after.vertebra_rad});
    lookup.upper_rad = std::max({lookup.upper_rad, before.vertebra_rad, after.vertebra_rad});
    const bool holds_query = before.time_ns < query_ns && query_ns < after.time_ns;
    if (gap_before == nullptr || (holds_query && !query_in_reported_gap) ||
        (holds_query == query_in_reported_gap && gap_ns > lookup.gap_ns)) {
      gap_before = &before;
      lookup.gap_ns = gap_ns;
      query_in_reported_gap = holds_query;
    }
  }
  if (gap_before == nullptr) return;
  lookup.in_gap = true;
  const std::string where = "a " + FormatSeconds(lookup.gap_ns, 2) + " s gap between samples at " +
                            Sec(gap_before->time_ns) + " and " +
                            Sec(gap_before->time_ns + lookup.gap_ns);
  lookup.warnings.push_back(query_in_reported_gap
                                ? "instant " + Sec(query_ns) + " is inside " + where
                                : "the window " + FormatSeconds(query_ns) + " +/- " +
                                      Sec(window.uncertainty_ns) + " overlaps " + where);
}

// Past either end: the end value is held, and the range widened by the log's mean rate
// times the distance outside.
void WidenPastEnds(const AngleEnds& ends, const QueryWindow& window, AngleLookup& lookup) {
  const AnglePoint& first = ends.first;
  const AnglePoint& last = ends.last;
  const int64_t query_ns = window.query_ns;
  const int64_t span_ns = last.time_ns - first.time_ns;
  const double mean_rate_rad_per_s =
      span_ns > 0 ? std::abs(last.vertebra_rad - first.vertebra_rad) / SecondsFromNs(span_ns) : 0.0;
  const int64_t after_end_ns = std::max<int64_t>(0, window.end_ns - last.time_ns);
  const int64_t before_start_ns = std::max<int64_t>(0, first.time_ns - window.begin_ns);
  const double widen_rad = mean_rate_rad_per_s * SecondsFromNs(after_end_ns + before_start_ns);
  lookup.lower_rad -= widen_rad;
  lookup.upper_rad += widen_rad;
  lookup.past_end = query_ns > last.time_ns;
  lookup.before_start = query_ns < first.time_ns;
  if (lookup.past_end) {
    lookup.warnings.push_back("instant " + Sec(query_ns) + " is " + Sec(query_ns - last.time_ns) +
                              " after the log's last sample at " + Sec(last.time_ns) +
                              "; its value is held");
  } else if (after_end_ns > 0) {
    lookup.warnings.push_back("the window " + FormatSeconds(query_ns) + " +/- " +
                              Sec(window.uncertainty_ns) + " reaches " + Sec(after_end_ns) +
                              " past the log's last sample at " + Sec(last.time_ns));
  }
  if (lookup.before_start) {
    lookup.warnings.push_back("instant " + Sec(query_ns) + " is " + Sec(first.time_ns - query_ns) +
                              " before the log's first sample at " + Sec(first.time_ns) +
                              "; its value is held");
  } else if (before_start_ns > 0) {
    lookup.warnings.push_back("the window " + FormatSeconds(query_ns) + " +/- " +
                              Sec(window.uncertainty_ns) + " reaches " + Sec(before_start_ns) +
                              " before the log's first sample at " + Sec(first.time_ns));
  }
  if (widen_rad > 0.0) {
    lookup.warnings.back() += "; interval widened by the log's mean rate " +
                              Rad(mean_rate_rad_per_s) + " rad/s to +/- " + Rad(widen_rad) + " rad";
  }
}

}  // namespace

Result<AngleLookup> LookupVertebraAngle(const ControllerLog& log, int64_t query_ns,
                                        int64_t query_uncertainty_ns,
                                        const LookupOptions& options) {
  LIFTOFF_ASSIGN_OR_RETURN(const AngleEnds ends,
                           CheckLookup(log, query_ns, query_uncertainty_ns, options));
  const QueryWindow window{query_ns, query_uncertainty_ns, query_ns - query_uncertainty_ns,
                           query_ns + query_uncertainty_ns};

  // the samples around the query's window; every step below works on these
  const std::vector<AnglePoint> points =
      AnglePointsAround(log.samples, window.begin_ns, window.end_ns);

  // the answer at the query, then the range it can take over the window
  AngleLookup lookup;
  lookup.rule = options.rule;
  lookup.query_ns = query_ns;
  lookup.query_uncertainty_ns = query_uncertainty_ns;
  lookup.vertebra_rad = AngleAt(points, query_ns, options.rule);
  SetBracketingSamples(points, lookup);
  const auto [inside_begin, inside_end] = SetRangeOverWindow(points, window, lookup);
  AddGapsOverlapped(points, inside_begin, inside_end, window, options.gap_threshold_s, lookup);
  WidenPastEnds(ends, window, lookup);
  return lookup;
}

std::string LiftoffMeasurement::Brief() const {
  std::string text = "liftoff " + Sec(interval_ns) + " after LED on (+/- " +
                     Sec(interval_uncertainty_ns) + "), " + Sec(liftoff_log_ns) +
                     " on the log: |vertebra| " + Rad(liftoff_rad) + " rad [" + Rad(lower_rad) +
                     ", " + Rad(upper_rad) + "] (" + std::string(LookupRuleName(lookup.rule));
  if (lookup.in_gap) text += "; in a " + FormatSeconds(lookup.gap_ns, 2) + " s gap";
  if (lookup.past_end) text += "; past the log's end";
  if (lookup.before_start) text += "; before the log's start";
  return text + ")";
}

Result<LiftoffMeasurement> MeasureLiftoff(const ControllerLog& log, const EventTimes& video_times,
                                          const LookupOptions& options) {
  // the video's interval, checked
  if (video_times.led_on_uncertainty_ns < 0 || video_times.liftoff_uncertainty_ns < 0) {
    return InvalidArgumentError("event times: uncertainties must be >= 0, got LED on +/- " +
                                Sec(video_times.led_on_uncertainty_ns) + " and liftoff +/- " +
                                Sec(video_times.liftoff_uncertainty_ns));
  }
  if (video_times.liftoff_ns < video_times.led_on_ns) {
    return InvalidArgumentError("event times: liftoff at " + Sec(video_times.liftoff_ns) +
                                " is before the LED switched on at " + Sec(video_times.led_on_ns) +
                                " (video clock)");
  }
  LiftoffMeasurement measurement;
  measurement.interval_ns = video_times.liftoff_ns - video_times.led_on_ns;
  measurement.interval_uncertainty_ns =
      video_times.led_on_uncertainty_ns + video_times.liftoff_uncertainty_ns;

  // the video's LED-on is the log's LED-on (the 2018 device clock starts there)
  const std::optional<int64_t> led_on_log_ns = log.LedOnTimeNs();
  if (led_on_log_ns)
    LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the log's LED switch-on", *led_on_log_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the video's LED switch-on", video_times.led_on_ns));
  LIFTOFF_RETURN_IF_ERROR(CheckLogTime("the video's liftoff", video_times.liftoff_ns));
  measurement.log_from_video.source_origin_ns = video_times.led_on_ns;
  measurement.log_from_video.target_at_origin_ns = led_on_log_ns.value_or(0);
  measurement.log_from_video.scale = 1.0;
  measurement.liftoff_log_ns = measurement.log_from_video(video_times.liftoff_ns);

  // the angle there, as an absolute value
  LIFTOFF_ASSIGN_OR_RETURN(measurement.lookup,
                           LookupVertebraAngle(log, measurement.liftoff_log_ns,
                                               measurement.interval_uncertainty_ns, options));
  if (!led_on_log_ns && log.report.format == "liftoff") {
    // liftoff's own logs mark the LED; without the mark device time 0 is only a guess
    measurement.lookup.warnings.push_back(
        "the log has no LED event: device time 0 taken as the LED switch-on");
  }
  const AngleLookup& lookup = measurement.lookup;
  measurement.liftoff_rad = std::abs(lookup.vertebra_rad);
  const bool spans_zero = lookup.lower_rad <= 0.0 && lookup.upper_rad >= 0.0;
  measurement.lower_rad =
      spans_zero ? 0.0 : std::min(std::abs(lookup.lower_rad), std::abs(lookup.upper_rad));
  measurement.upper_rad = std::max(std::abs(lookup.lower_rad), std::abs(lookup.upper_rad));
  return measurement;
}

}  // namespace liftoff::sync
