#include "report_shards.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "liftoff/cli/sim_commands.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/version.h"
#include "liftoff/sim/model.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::string_view kShardFormat = "liftoff-report-shard";
constexpr int kShardVersion = 3;  // 2: LED pulses carry missing_frames_before_on; 3: spread_frames

// ---------------------------------------------------------------------------------------
// values: numbers that may be NaN (JSON null), optionals, rectangles, statuses

json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }
double NumberFrom(const json& value) {
  return value.is_null() ? std::numeric_limits<double>::quiet_NaN() : value.get<double>();
}
double NumberAt(const json& object, const char* key) { return NumberFrom(object.at(key)); }
template <typename T>
json Optional(const std::optional<T>& value) {
  return value ? json(*value) : json(nullptr);
}
template <typename T>
std::optional<T> OptionalFrom(const json& value) {
  return value.is_null() ? std::nullopt : std::optional<T>(value.get<T>());
}
json Rect(const cv::Rect& rect) { return {rect.x, rect.y, rect.width, rect.height}; }
cv::Rect RectFrom(const json& value) {
  return {value.at(0).get<int>(), value.at(1).get<int>(), value.at(2).get<int>(),
          value.at(3).get<int>()};
}
json Rects(const std::vector<cv::Rect>& rects) {
  json array = json::array();
  for (const cv::Rect& rect : rects) array.push_back(Rect(rect));
  return array;
}
std::vector<cv::Rect> RectsFrom(const json& array) {
  std::vector<cv::Rect> rects;
  for (const json& value : array) rects.push_back(RectFrom(value));
  return rects;
}

json StatusJson(const Status& status) {
  return {{"code", static_cast<int>(status.code())}, {"message", status.message()}};
}
Status StatusAt(const json& object) {
  const int code = object.at("code").get<int>();
  if (code < 0 || code > static_cast<int>(StatusCode::kOutOfRange)) {
    throw std::out_of_range("status code " + std::to_string(code) + " unknown");
  }
  if (code == 0) return Status::Ok();
  return Status(static_cast<StatusCode>(code), object.at("message").get<std::string>());
}

// ---------------------------------------------------------------------------------------
// a trial's outcome: measurement, log report, video analysis

json MeasurementJson(const sync::LiftoffMeasurement& m) {
  const sync::AngleLookup& l = m.lookup;
  return {{"interval_ns", m.interval_ns},
          {"interval_uncertainty_ns", m.interval_uncertainty_ns},
          {"log_from_video",
           {m.log_from_video.source_origin_ns, m.log_from_video.target_at_origin_ns,
            Number(m.log_from_video.scale)}},
          {"liftoff_log_ns", m.liftoff_log_ns},
          {"liftoff_rad", Number(m.liftoff_rad)},
          {"lower_rad", Number(m.lower_rad)},
          {"upper_rad", Number(m.upper_rad)},
          {"lookup",
           {{"rule", std::string(sync::LookupRuleName(l.rule))},
            {"query_ns", l.query_ns},
            {"query_uncertainty_ns", l.query_uncertainty_ns},
            {"vertebra_rad", Number(l.vertebra_rad)},
            {"lower_rad", Number(l.lower_rad)},
            {"upper_rad", Number(l.upper_rad)},
            {"sample_before_ns", Optional(l.sample_before_ns)},
            {"sample_after_ns", Optional(l.sample_after_ns)},
            {"in_gap", l.in_gap},
            {"gap_ns", l.gap_ns},
            {"past_end", l.past_end},
            {"before_start", l.before_start},
            {"warnings", l.warnings}}}};
}

sync::LiftoffMeasurement MeasurementAt(const json& j) {
  sync::LiftoffMeasurement m;
  m.interval_ns = j.at("interval_ns").get<int64_t>();
  m.interval_uncertainty_ns = j.at("interval_uncertainty_ns").get<int64_t>();
  const json& clock = j.at("log_from_video");
  m.log_from_video.source_origin_ns = clock.at(0).get<int64_t>();
  m.log_from_video.target_at_origin_ns = clock.at(1).get<int64_t>();
  m.log_from_video.scale = NumberFrom(clock.at(2));
  m.liftoff_log_ns = j.at("liftoff_log_ns").get<int64_t>();
  m.liftoff_rad = NumberAt(j, "liftoff_rad");
  m.lower_rad = NumberAt(j, "lower_rad");
  m.upper_rad = NumberAt(j, "upper_rad");
  const json& l = j.at("lookup");
  const auto rule = sync::ParseLookupRule(l.at("rule").get<std::string>());
  if (!rule) throw std::out_of_range("lookup rule unknown");
  m.lookup.rule = *rule;
  m.lookup.query_ns = l.at("query_ns").get<int64_t>();
  m.lookup.query_uncertainty_ns = l.at("query_uncertainty_ns").get<int64_t>();
  m.lookup.vertebra_rad = NumberAt(l, "vertebra_rad");
  m.lookup.lower_rad = NumberAt(l, "lower_rad");
  m.lookup.upper_rad = NumberAt(l, "upper_rad");
  m.lookup.sample_before_ns = OptionalFrom<int64_t>(l.at("sample_before_ns"));
  m.lookup.sample_after_ns = OptionalFrom<int64_t>(l.at("sample_after_ns"));
  m.lookup.in_gap = l.at("in_gap").get<bool>();
  m.lookup.gap_ns = l.at("gap_ns").get<int64_t>();
  m.lookup.past_end = l.at("past_end").get<bool>();
  m.lookup.before_start = l.at("before_start").get<bool>();
  m.lookup.warnings = l.at("warnings").get<std::vector<std::string>>();
  return m;
}

json LogReportJson(const LogReadReport& r) {
  json issues = json::array();
  for (const LogIssue& issue : r.issues) issues.push_back({issue.line, issue.reason});
  return {{"source", r.source.string()},   {"format", r.format},
          {"lines_total", r.lines_total},  {"samples", r.samples},
          {"events", r.events},            {"bad_lines", r.bad_lines},
          {"truncated_last_line", r.truncated_last_line},
          {"out_of_order", r.out_of_order}, {"issues", issues}};
}

LogReadReport LogReportAt(const json& j) {
  LogReadReport r;
  r.source = j.at("source").get<std::string>();
  r.format = j.at("format").get<std::string>();
  r.lines_total = j.at("lines_total").get<int64_t>();
  r.samples = j.at("samples").get<int64_t>();
  r.events = j.at("events").get<int64_t>();
  r.bad_lines = j.at("bad_lines").get<int64_t>();
  r.truncated_last_line = j.at("truncated_last_line").get<bool>();
  r.out_of_order = j.at("out_of_order").get<int64_t>();
  for (const json& issue : j.at("issues")) {
    r.issues.push_back({issue.at(0).get<int64_t>(), issue.at(1).get<std::string>()});
  }
  return r;
}

json EventJson(const video::TimedEvent& e) {
  return {e.t_ns, e.uncertainty_ns, e.frame_before, e.frame_after};
}
video::TimedEvent EventAt(const json& j) {
  return {j.at(0).get<int64_t>(), j.at(1).get<int64_t>(), j.at(2).get<int64_t>(),
          j.at(3).get<int64_t>()};
}

json TimingJson(const video::FrameTimingReport& t) {
  json irregular = json::array();
  for (const video::TimingIrregularity& i : t.irregularities) {
    irregular.push_back({static_cast<int>(i.kind), i.frame_index, i.t_ns, i.interval_ns,
                         i.missing_frames});
  }
  return {{"frames", t.frames},
          {"first_ns", t.first_ns},
          {"last_ns", t.last_ns},
          {"median_interval_ns", t.median_interval_ns},
          {"fps", Number(t.fps)},
          {"container_fps", Number(t.container_fps)},
          {"container_frames", t.container_frames},
          {"codec_fourcc", t.codec_fourcc},
          {"lossless_codec", t.lossless_codec},
          {"dropped_frames", t.dropped_frames},
          {"repaired_frames", t.repaired_frames},
          {"irregularities", irregular},
          {"irregular_frames", t.irregular_frames},
          {"decoder_errors", t.decoder_errors},
          {"first_decoder_error", t.first_decoder_error},
          {"keyframes", t.keyframes},
          {"keyframes_known", t.keyframes_known}};
}

video::FrameTimingReport TimingAt(const json& j) {
  video::FrameTimingReport t;
  t.frames = j.at("frames").get<int64_t>();
  t.first_ns = j.at("first_ns").get<int64_t>();
  t.last_ns = j.at("last_ns").get<int64_t>();
  t.median_interval_ns = j.at("median_interval_ns").get<int64_t>();
  t.fps = NumberAt(j, "fps");
  t.container_fps = NumberAt(j, "container_fps");
  t.container_frames = j.at("container_frames").get<int64_t>();
  t.codec_fourcc = j.at("codec_fourcc").get<std::string>();
  t.lossless_codec = j.at("lossless_codec").get<bool>();
  t.dropped_frames = j.at("dropped_frames").get<int64_t>();
  t.repaired_frames = j.at("repaired_frames").get<int64_t>();
  for (const json& i : j.at("irregularities")) {
    t.irregularities.push_back({static_cast<video::TimingIrregularity::Kind>(i.at(0).get<int>()),
                                i.at(1).get<int64_t>(), i.at(2).get<int64_t>(),
                                i.at(3).get<int64_t>(), i.at(4).get<int64_t>()});
  }
  t.irregular_frames = j.at("irregular_frames").get<int64_t>();
  t.decoder_errors = j.at("decoder_errors").get<int64_t>();
  t.first_decoder_error = j.at("first_decoder_error").get<std::string>();
  t.keyframes = j.at("keyframes").get<int64_t>();
  t.keyframes_known = j.at("keyframes_known").get<bool>();
  return t;
}

// Doubles as JSON numbers (non-finite ones as Number writes them).
json NumbersJson(const std::vector<double>& values) {
  json array = json::array();
  for (const double value : values) array.push_back(Number(value));
  return array;
}

json LedJson(const video::LedResult& led) {
  json pulses = json::array();
  for (const video::LedPulse& p : led.pulses) {
    pulses.push_back({p.on_ns, p.on_uncertainty_ns, p.first_lit_frame, Number(p.first_lit_fraction),
                      Optional(p.off_ns), p.off_uncertainty_ns, p.missing_frames_before_on,
                      p.spread_frames});
  }
  return {{"roi_px", Rect(led.roi_px)},
          {"roi_located", led.roi_located},
          {"off_level", Number(led.off_level)},
          {"on_level", Number(led.on_level)},
          {"contrast_levels", Number(led.contrast_levels)},
          {"pulses", pulses},
          {"warnings", led.warnings},
          {"trace_t_ns", led.trace_t_ns},
          {"trace_brightness_levels", NumbersJson(led.trace_brightness_levels)}};
}

video::LedResult LedAt(const json& j) {
  video::LedResult led;
  led.roi_px = RectFrom(j.at("roi_px"));
  led.roi_located = j.at("roi_located").get<bool>();
  led.off_level = NumberAt(j, "off_level");
  led.on_level = NumberAt(j, "on_level");
  led.contrast_levels = NumberAt(j, "contrast_levels");
  for (const json& p : j.at("pulses")) {
    video::LedPulse& pulse = led.pulses.emplace_back();
    pulse.on_ns = p.at(0).get<int64_t>();
    pulse.on_uncertainty_ns = p.at(1).get<int64_t>();
    pulse.first_lit_frame = p.at(2).get<int64_t>();
    pulse.first_lit_fraction = NumberFrom(p.at(3));
    pulse.off_ns = OptionalFrom<int64_t>(p.at(4));
    pulse.off_uncertainty_ns = p.at(5).get<int64_t>();
    pulse.missing_frames_before_on = p.at(6).get<int>();
    pulse.spread_frames = p.at(7).get<int>();
  }
  led.warnings = j.at("warnings").get<std::vector<std::string>>();
  led.trace_t_ns = j.at("trace_t_ns").get<std::vector<int64_t>>();
  for (const json& level : j.at("trace_brightness_levels")) {
    led.trace_brightness_levels.push_back(NumberFrom(level));
  }
  return led;
}

// the per-frame trace as columns: frame, t_ns, rise_px, shake_y_px, quality, keyframe
json SamplesJson(const std::vector<video::HeightSample>& samples) {
  json frame = json::array(), t = json::array(), rise = json::array(), shake = json::array(),
       quality = json::array(), keyframe = json::array();
  for (const video::HeightSample& s : samples) {
    frame.push_back(s.frame_index);
    t.push_back(s.t_ns);
    rise.push_back(Number(s.rise_px));
    shake.push_back(Number(s.shake_y_px));
    quality.push_back(Number(s.quality));
    keyframe.push_back(s.keyframe);
  }
  return {{"frame", frame}, {"t_ns", t},           {"rise_px", rise},
          {"shake_y_px", shake}, {"quality", quality}, {"keyframe", keyframe}};
}

std::vector<video::HeightSample> SamplesAt(const json& j) {
  std::vector<video::HeightSample> samples(j.at("frame").size());
  for (size_t i = 0; i < samples.size(); ++i) {
    samples[i].frame_index = j.at("frame").at(i).get<int64_t>();
    samples[i].t_ns = j.at("t_ns").at(i).get<int64_t>();
    samples[i].rise_px = NumberFrom(j.at("rise_px").at(i));
    samples[i].shake_y_px = NumberFrom(j.at("shake_y_px").at(i));
    samples[i].quality = NumberFrom(j.at("quality").at(i));
    samples[i].keyframe = j.at("keyframe").at(i).get<bool>();
  }
  return samples;
}

json FootJson(const video::FootTrack& f) {
  return {
      {"samples", SamplesJson(f.samples)},
      {"foot_roi_px", Rect(f.foot_roi_px)},
      {"reference_roi_px", Rect(f.reference_roi_px)},
      {"reference_patches_px", Rects(f.reference_patches_px)},
      {"foot_patches_px", Rects(f.foot_patches_px)},
      {"foot_px", {Number(f.foot_center_x_px), Number(f.foot_width_px), Number(f.foot_bottom_px)}},
      {"located_by_tape", f.located_by_tape},
      {"rest_rise_px", Number(f.rest_rise_px)},
      {"rest_noise_px", Number(f.rest_noise_px)},
      {"still_noise_px", Number(f.still_noise_px)},
      {"px_per_mm", Number(f.px_per_mm)},
      {"px_per_mm_estimated", f.px_per_mm_estimated},
      {"threshold_px", Number(f.threshold_px)},
      {"max_rise_px", Number(f.max_rise_px)},
      {"exposure_offset_ns", f.exposure_offset_ns},
      {"fit_frames", {f.fit_first_frame, f.fit_last_frame}},
      {"fit_noise_px", Number(f.fit_noise_px)},
      {"low_confidence", f.low_confidence},
      {"poor_frames", f.poor_frames},
      {"onset", EventJson(f.onset)},
      {"above_threshold", EventJson(f.above_threshold)},
      {"warnings", f.warnings}};
}

video::FootTrack FootAt(const json& j) {
  video::FootTrack f;
  f.samples = SamplesAt(j.at("samples"));
  f.foot_roi_px = RectFrom(j.at("foot_roi_px"));
  f.reference_roi_px = RectFrom(j.at("reference_roi_px"));
  f.reference_patches_px = RectsFrom(j.at("reference_patches_px"));
  f.foot_patches_px = RectsFrom(j.at("foot_patches_px"));
  f.foot_center_x_px = NumberFrom(j.at("foot_px").at(0));
  f.foot_width_px = NumberFrom(j.at("foot_px").at(1));
  f.foot_bottom_px = NumberFrom(j.at("foot_px").at(2));
  f.located_by_tape = j.at("located_by_tape").get<bool>();
  f.rest_rise_px = NumberAt(j, "rest_rise_px");
  f.rest_noise_px = NumberAt(j, "rest_noise_px");
  f.still_noise_px = NumberAt(j, "still_noise_px");
  f.px_per_mm = NumberAt(j, "px_per_mm");
  f.px_per_mm_estimated = j.at("px_per_mm_estimated").get<bool>();
  f.threshold_px = NumberAt(j, "threshold_px");
  f.max_rise_px = NumberAt(j, "max_rise_px");
  f.exposure_offset_ns = j.at("exposure_offset_ns").get<int64_t>();
  f.fit_first_frame = j.at("fit_frames").at(0).get<int64_t>();
  f.fit_last_frame = j.at("fit_frames").at(1).get<int64_t>();
  f.fit_noise_px = NumberAt(j, "fit_noise_px");
  f.low_confidence = j.at("low_confidence").get<bool>();
  f.poor_frames = j.at("poor_frames").get<int64_t>();
  f.onset = EventAt(j.at("onset"));
  f.above_threshold = EventAt(j.at("above_threshold"));
  f.warnings = j.at("warnings").get<std::vector<std::string>>();
  return f;
}

// THE place a video analysis field the report reads is carried through a shard file
json VideoJson(const video::ClipAnalysis& v) {
  return {{"video_path", v.video_path.string()},
          {"size_px", {v.width_px, v.height_px}},
          {"timing", TimingJson(v.timing)},
          {"led", LedJson(v.led)},
          {"foot", v.foot ? FootJson(*v.foot) : json(nullptr)},
          {"rest", {v.rest_from_ns, v.rest_to_ns, v.rest_frames}},
          {"liftoff_instant", std::string(video::LiftoffInstantName(v.liftoff_instant))},
          {"warnings", v.warnings},
          {"wall_s", Number(v.wall_seconds)}};
}

video::ClipAnalysis VideoAt(const json& j) {
  video::ClipAnalysis v;
  v.video_path = j.at("video_path").get<std::string>();
  v.width_px = j.at("size_px").at(0).get<int>();
  v.height_px = j.at("size_px").at(1).get<int>();
  v.timing = TimingAt(j.at("timing"));
  v.led = LedAt(j.at("led"));
  if (!j.at("foot").is_null()) v.foot = FootAt(j.at("foot"));
  v.rest_from_ns = j.at("rest").at(0).get<int64_t>();
  v.rest_to_ns = j.at("rest").at(1).get<int64_t>();
  v.rest_frames = j.at("rest").at(2).get<int64_t>();
  const auto instant = video::ParseLiftoffInstant(j.at("liftoff_instant").get<std::string>());
  if (!instant) throw std::out_of_range("liftoff_instant unknown");
  v.liftoff_instant = *instant;
  v.warnings = j.at("warnings").get<std::vector<std::string>>();
  v.wall_seconds = NumberAt(j, "wall_s");
  return v;
}

}  // namespace

json TrialOutcomeToJson(size_t index, const sync::TrialOutcome& outcome,
                        const std::vector<std::string>& notes) {
  return {{"index", index},
          {"id", outcome.trial.id},
          {"status", StatusJson(outcome.status)},
          {"measurement", outcome.measurement ? MeasurementJson(*outcome.measurement) : json()},
          {"log_report", LogReportJson(outcome.log_report)},
          {"video", outcome.video ? VideoJson(*outcome.video) : json()},
          {"notes", notes}};
}

void TrialOutcomeFromJson(const json& j, sync::TrialOutcome& outcome,
                          std::vector<std::string>& notes) {
  outcome.status = StatusAt(j.at("status"));
  if (!j.at("measurement").is_null()) outcome.measurement = MeasurementAt(j.at("measurement"));
  outcome.log_report = LogReportAt(j.at("log_report"));
  if (!j.at("video").is_null()) outcome.video = VideoAt(j.at("video"));
  notes = j.at("notes").get<std::vector<std::string>>();
}

namespace {

// ---------------------------------------------------------------------------------------
// loading and checking shard files

struct LoadedShard {
  fs::path path;
  ShardSpec shard;
  json document;
};

Result<LoadedShard> LoadShard(const fs::path& path, const std::string& fingerprint) {
  LIFTOFF_ASSIGN_OR_RETURN(json document, LoadJsonFile(path));
  const auto bad = [&](const std::string& why) {
    return InvalidArgumentError("--merge: " + path.string() + ": " + why);
  };
  LoadedShard loaded{path, {}, {}};
  try {
    if (!document.is_object() || !document.contains("format") ||
        document.at("format") != std::string(kShardFormat)) {
      return bad("not a liftoff report shard (expected format \"" + std::string(kShardFormat) +
                 "\")");
    }
    if (document.value("version", 0) != kShardVersion) {
      return bad("shard format version " + document.value("version", json(0)).dump() +
                 ", this liftoff reads version " + std::to_string(kShardVersion));
    }
    loaded.shard.index = document.at("shard").at("index").get<int>();
    loaded.shard.count = document.at("shard").at("count").get<int>();
    const std::string made_from = document.at("fingerprint").get<std::string>();
    if (made_from != fingerprint) {
      return bad("made from other inputs or options (fingerprint " + made_from + ", this merge " +
                 fingerprint + "): the manifest, a trial's files, the calibration, the model or "
                 "a flag differs; merge shards of one run with that run's flags");
    }
  } catch (const json::exception& error) {
    return ParseError(path.string() + ": damaged shard file (" + error.what() + ")");
  }
  if (loaded.shard.index < 1 || loaded.shard.count < loaded.shard.index ||
      loaded.shard.count > kMaxShards) {
    return bad("shard " + loaded.shard.Name() + " is no shard");
  }
  loaded.document = std::move(document);
  return loaded;
}

// every shard of one count, once each
Status CheckComplete(const std::vector<LoadedShard>& shards) {
  const LoadedShard& first = shards.front();
  std::map<int, const LoadedShard*> by_index;
  for (const LoadedShard& shard : shards) {
    if (shard.shard.count != first.shard.count) {
      return InvalidArgumentError("--merge: " + shard.path.string() + " is shard " +
                                  shard.shard.Name() + " but " + first.path.string() +
                                  " is shard " + first.shard.Name() +
                                  ": shards of one run have one count");
    }
    const auto [at, added] = by_index.try_emplace(shard.shard.index, &shard);
    if (!added) {
      return InvalidArgumentError("--merge: " + shard.path.string() + " and " +
                                  at->second->path.string() + " are both shard " +
                                  shard.shard.Name());
    }
  }
  std::string missing;
  for (int i = 1; i <= first.shard.count; ++i) {
    if (by_index.count(i) == 0) {
      missing += (missing.empty() ? "" : ", ") + ShardSpec{i, first.shard.count}.Name();
    }
  }
  if (!missing.empty()) {
    return InvalidArgumentError("--merge: shard " + missing + " missing (given " +
                                Plural(static_cast<int64_t>(shards.size()), "file") + ", first " +
                                first.path.string() + "); merge every shard of the run");
  }
  return Status::Ok();
}

// the shard's trials into their places in `campaign`; kInvalidArgument when they are not
// the trials its index holds
Status TakeTrials(const LoadedShard& shard, CampaignAnalysis& campaign,
                  std::vector<bool>& filled) {
  const std::vector<TrialRecord>& trials = campaign.manifest.trials;
  size_t expected = 0;
  for (size_t i = 0; i < trials.size(); ++i) if (shard.shard.Holds(i)) ++expected;
  const json& entries = shard.document.at("trials");
  if (entries.size() != expected) {
    return InvalidArgumentError("--merge: " + shard.path.string() + ": holds " +
                                std::to_string(entries.size()) + " trials, shard " +
                                shard.shard.Name() + " of this manifest has " +
                                std::to_string(expected));
  }
  for (const json& entry : entries) {
    const size_t index = entry.at("index").get<size_t>();
    if (index >= trials.size() || !shard.shard.Holds(index) ||
        entry.at("id").get<std::string>() != trials[index].id) {
      return InvalidArgumentError("--merge: " + shard.path.string() + ": trial " +
                                  entry.at("id").dump() + " (index " + std::to_string(index) +
                                  ") is not a trial of shard " + shard.shard.Name() +
                                  " of this manifest");
    }
    sync::TrialOutcome& outcome = campaign.analysis.outcomes[index];
    outcome.trial = trials[index];
    TrialOutcomeFromJson(entry, outcome, campaign.notes[index]);
    filled[index] = true;
  }
  return Status::Ok();
}

// the shard's Monte Carlo draws into their places
Status TakeDraws(const LoadedShard& shard, int samples, std::vector<fit::TensionSample>& draws,
                 std::vector<bool>& filled) {
  const json& monte_carlo = shard.document.at("monte_carlo");
  LIFTOFF_ASSIGN_OR_RETURN(
      std::vector<fit::TensionSample> values,
      fit::TensionSamplesFromJson(monte_carlo.at("results"), shard.path.string()));
  const std::vector<size_t> indices = monte_carlo.at("draws").get<std::vector<size_t>>();
  size_t expected = 0;
  for (size_t k = 0; k < static_cast<size_t>(samples); ++k) {
    if (shard.shard.Holds(k)) ++expected;
  }
  if (indices.size() != values.size() || indices.size() != expected) {
    return InvalidArgumentError("--merge: " + shard.path.string() + ": holds " +
                                std::to_string(values.size()) + " Monte Carlo draws, shard " +
                                shard.shard.Name() + " of " + std::to_string(samples) +
                                " has " + std::to_string(expected));
  }
  for (size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= draws.size() || !shard.shard.Holds(indices[i])) {
      return InvalidArgumentError("--merge: " + shard.path.string() + ": Monte Carlo draw " +
                                  std::to_string(indices[i]) + " is not one of shard " +
                                  shard.shard.Name());
    }
    draws[indices[i]] = std::move(values[i]);
    filled[indices[i]] = true;
  }
  return Status::Ok();
}

}  // namespace

fs::path ShardFilePath(const fs::path& dir, const ShardSpec& shard) {
  return dir / ("shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) +
                ".json");
}

Result<std::string> ReportFingerprint(const ReportCommand& command,
                                      const CampaignAnalysis& campaign) {
  const LookupChoice& lookup = command.lookup;
  std::string text = "manifest\n" + ManifestToJson(campaign.manifest, "/").dump() +
                     "\ncalibration\n" + CalibrationToJson(campaign.calibration).dump() +
                     "\nlookup\n" + lookup.rule + " " + FormatNumber(lookup.gap_threshold_s) +
                     " " + FormatNumber(lookup.max_past_end_s) + " " +
                     std::to_string(lookup.max_bad_lines) + "\nversion\n" + kVersion;
  if (!command.no_sim) {
    LIFTOFF_ASSIGN_OR_RETURN(const std::string model,
                             ReadWholeFile(ModelPathFrom(command.sweep.experiment)));
    const fit::FitOptions& grid = command.fit;
    const fit::MonteCarloOptions& mc = command.monte_carlo;
    text += "\nmodel\n" + model + "\nexperiment\n" + DescribeOverrides(command.sweep.experiment) +
            "\nfeet\n" + Join(command.sweep.feet, ",") + "\ntensions\n" +
            Join(command.sweep.tensions, ",") + "\nfull_ramp\n" +
            (command.sweep.full_ramp ? "1" : "0") + "\nfit\n" + FormatNumber(grid.sigma_min) +
            " " + FormatNumber(grid.sigma_max) + " " + FormatNumber(grid.sigma_step) + " " +
            std::to_string(grid.bootstrap_samples) + " " + std::to_string(grid.seed) +
            "\nmonte carlo\n" + std::to_string(mc.samples) + " " + std::to_string(mc.seed) + " " +
            FormatNumber(mc.stddev_scale);
  }
  return HashHex(text);
}

Result<std::vector<fit::TensionSample>> SimulateShardDraws(const ReportCommand& command,
                                                           const Calibration& calibration,
                                                           const ShardSpec& shard,
                                                           std::vector<size_t>& draws) {
  draws.clear();
  if (command.no_sim || command.monte_carlo.samples == 0) return std::vector<fit::TensionSample>();
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<TensionPoint> all,
                           fit::MonteCarloDraws(calibration, command.monte_carlo));
  std::vector<TensionPoint> mine;
  for (size_t k = 0; k < all.size(); ++k) {
    if (!shard.Holds(k)) continue;
    draws.push_back(k);
    mine.push_back(all[k]);
  }
  if (mine.empty()) return std::vector<fit::TensionSample>();
  LIFTOFF_ASSIGN_OR_RETURN(const sim::ModelDescription model,
                           sim::LoadModelDescription(ModelPathFrom(command.sweep.experiment)));
  LIFTOFF_ASSIGN_OR_RETURN(const sim::SweepOptions sweep, SweepOptionsFrom(command.sweep));
  return fit::SimulateTensions(model, sweep, mine);
}

Status WriteReportShard(const fs::path& path, const ShardSpec& shard,
                        const std::string& fingerprint, const CampaignAnalysis& campaign,
                        const std::vector<size_t>& draws,
                        const std::vector<fit::TensionSample>& samples) {
  json trials = json::array();
  for (size_t i = 0; i < campaign.analysis.outcomes.size(); ++i) {
    trials.push_back(TrialOutcomeToJson(campaign.trial_indices[i], campaign.analysis.outcomes[i],
                                        campaign.notes[i]));
  }
  const json document = {
      {"format", kShardFormat},
      {"version", kShardVersion},
      {"shard", {{"index", shard.index}, {"count", shard.count}}},
      {"fingerprint", fingerprint},
      {"software", std::string("liftoff ") + kVersion},
      {"trials", std::move(trials)},
      {"monte_carlo", {{"draws", draws}, {"results", fit::TensionSamplesToJson(samples)}}}};
  return WriteJsonFile(path, document);
}

Status MergeReportShards(const std::vector<fs::path>& paths, const std::string& fingerprint,
                         int monte_carlo_samples, CampaignAnalysis& campaign,
                         std::vector<fit::TensionSample>& monte_carlo) {
  if (paths.empty()) return InvalidArgumentError("--merge: name the shard files");
  std::vector<LoadedShard> shards;
  for (const fs::path& path : paths) {
    LIFTOFF_ASSIGN_OR_RETURN(LoadedShard shard, LoadShard(path, fingerprint));
    shards.push_back(std::move(shard));
  }
  LIFTOFF_RETURN_IF_ERROR(CheckComplete(shards));

  const size_t trials = campaign.manifest.trials.size();
  campaign.analysis.outcomes.assign(trials, {});
  campaign.notes.assign(trials, {});
  monte_carlo.assign(static_cast<size_t>(monte_carlo_samples), {});
  std::vector<bool> trial_filled(trials, false), draw_filled(monte_carlo.size(), false);
  for (const LoadedShard& shard : shards) {
    try {
      LIFTOFF_RETURN_IF_ERROR(TakeTrials(shard, campaign, trial_filled));
      LIFTOFF_RETURN_IF_ERROR(TakeDraws(shard, monte_carlo_samples, monte_carlo, draw_filled));
    } catch (const std::exception& error) {
      return ParseError(shard.path.string() + ": damaged shard file (" + error.what() + ")");
    }
  }
  // complete and non-overlapping shards fill every place once
  if (std::find(trial_filled.begin(), trial_filled.end(), false) != trial_filled.end() ||
      std::find(draw_filled.begin(), draw_filled.end(), false) != draw_filled.end()) {
    return InvalidArgumentError("--merge: the shards leave a trial or Monte Carlo draw out");
  }
  campaign.trial_indices.resize(trials);
  for (size_t i = 0; i < trials; ++i) {
    campaign.trial_indices[i] = i;
    const Status& status = campaign.analysis.outcomes[i].status;
    if (!status.ok() && campaign.first_failure.ok()) campaign.first_failure = status;
  }
  return Status::Ok();
}

Result<ShardSpec> ReportShardFlags(const ReportCommand& command) {
  if (command.shard.empty()) return ShardSpec{};
  if (!command.merge.empty()) {
    return InvalidArgumentError(
        "--shard, --merge: a run is one shard or the merge of them all, not both");
  }
  return ParseShard(command.shard, "--shard");
}

Result<CampaignAnalysis> CampaignForReport(const ReportCommand& command, const ShardSpec& shard,
                                           std::vector<fit::TensionSample>& monte_carlo,
                                           std::ostream& err) {
  if (command.merge.empty()) {
    const CampaignRun run{.progress = command.sweep.experiment.progress,
                          .jobs = command.jobs,
                          .shard = shard};
    return AnalyzeCampaign(command.manifest_path, command.calibration, command.lookup, run, err);
  }
  LIFTOFF_ASSIGN_OR_RETURN(
      CampaignAnalysis campaign,
      LoadCampaign(command.manifest_path, command.calibration, command.lookup, err));
  LIFTOFF_ASSIGN_OR_RETURN(const std::string fingerprint, ReportFingerprint(command, campaign));
  LIFTOFF_RETURN_IF_ERROR(MergeReportShards(command.merge, fingerprint,
                                            command.no_sim ? 0 : command.monte_carlo.samples,
                                            campaign, monte_carlo));
  for (const std::vector<std::string>& notes : campaign.notes) {
    for (const std::string& line : notes) err << line << '\n';
  }
  return campaign;
}

Status RunReportShard(const ReportCommand& command, const ShardSpec& shard,
                      const CampaignAnalysis& campaign, std::ostream& out, std::ostream& err) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::string fingerprint, ReportFingerprint(command, campaign));
  std::vector<size_t> draws;
  if (!command.no_sim && command.monte_carlo.samples > 0 &&
      command.sweep.experiment.progress != "off") {
    err << "shard " << shard.Name() << ": simulating its share of "
        << Plural(command.monte_carlo.samples, "Monte Carlo draw") << "\n";
  }
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<fit::TensionSample> samples,
                           SimulateShardDraws(command, campaign.calibration, shard, draws));
  const fs::path path = ShardFilePath(command.output_dir, shard);
  LIFTOFF_RETURN_IF_ERROR(
      WriteReportShard(path, shard, fingerprint, campaign, draws, samples));
  out << "shard " << shard.Name() << ": "
      << Plural(static_cast<int64_t>(campaign.analysis.outcomes.size()), "trial") << " ("
      << campaign.analysis.failed() << " failed), "
      << Plural(static_cast<int64_t>(draws.size()), "Monte Carlo draw") << "; wrote "
      << path.string() << "\n";
  return Status::Ok();
}

}  // namespace liftoff::cli
