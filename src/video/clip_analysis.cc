#include "liftoff/video/clip_analysis.h"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include <nlohmann/json.hpp>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "video_util.h"

namespace liftoff::video {
namespace {


using nlohmann::json;

constexpr NumberRange kRestOffsetRange{.min = -60.0, .max = 60.0};
// the longest exposure accepted, in median frame intervals (timestamps rounded to 1 ms)
constexpr double kMaxExposureIntervals = 1.05;

// the frames of one clip, streamed to the detectors (the foot tracker's samples are the
// only per-frame state kept)
class ClipPass {
 public:
  ClipPass(const ClipAnalysisOptions& options, const FootTracker::Options& foot,
           const std::filesystem::path& path)
      : path_(path), led_(options.led) {
    if (!foot.foot_roi_px.empty()) foot_.emplace(foot);
  }

  Status Process(const Frame& frame) {
    Status led = led_.Process(frame);
    if (!led.ok()) return led.WithContext(DisplayPath(path_));
    if (foot_) {
      Status foot = foot_->Process(frame);
      if (!foot.ok()) return foot.WithContext(DisplayPath(path_));
    }
    return Status::Ok();
  }

  LedDetector& led() { return led_; }
  std::optional<FootTracker>& foot() { return foot_; }

  // the parts of a frame the detectors read
  std::vector<cv::Rect> RegionsRead(cv::Size frame_px) const {
    std::vector<cv::Rect> regions = led_.RegionsRead(frame_px);
    if (foot_) regions.push_back(foot_->RegionRead(frame_px));
    return regions;
  }

 private:
  const std::filesystem::path& path_;
  LedDetector led_;
  std::optional<FootTracker> foot_;
};

// Decoded frames travel from the decoding thread to the analysing one through `ready`;
// their buffers come back through `spare`, so no picture is allocated after the first few.
class FrameQueue {
 public:
  explicit FrameQueue(int buffers) : frames_(static_cast<size_t>(buffers)) {
    for (Frame& frame : frames_) spare_.push_back(&frame);
  }

  // decoder side: a buffer to decode into; null once cancelled
  Frame* TakeSpare() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return cancelled_ || !spare_.empty(); });
    if (cancelled_) return nullptr;
    Frame* frame = spare_.front();
    spare_.pop_front();
    return frame;
  }
  void PushReady(Frame* frame) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      ready_.push_back(frame);
    }
    changed_.notify_all();
  }
  // decoder side: no more frames; `status` says why (OK at the end of the stream)
  void Close(Status status) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
      end_status_ = std::move(status);
    }
    changed_.notify_all();
  }

  // analyser side: the next decoded frame; null when the decoder closed and all are taken
  Frame* TakeReady() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return closed_ || !ready_.empty(); });
    if (ready_.empty()) return nullptr;
    Frame* frame = ready_.front();
    ready_.pop_front();
    return frame;
  }
  void ReturnSpare(Frame* frame) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      spare_.push_back(frame);
    }
    changed_.notify_all();
  }
  // analyser side: stop the decoder early (an analysis error)
  void Cancel() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      cancelled_ = true;
    }
    changed_.notify_all();
  }
  Status end_status() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return end_status_;
  }

 private:
  std::vector<Frame> frames_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Frame*> spare_, ready_;
  bool closed_ = false;
  bool cancelled_ = false;
  Status end_status_;
};

// A reader that handed out a picture it still shares would see it overwritten by the
// next decode while it waits in the queue: such a picture is copied out.
void OwnPicture(Frame& frame) {
  if (frame.bgr.u != nullptr && frame.bgr.u->refcount > 1) frame.bgr = frame.bgr.clone();
}

// the decoder thread's loop
void DecodeInto(VideoReader& reader, FrameQueue& queue) {
  try {
    while (Frame* frame = queue.TakeSpare()) {
      Result<bool> next = reader.Next(*frame);
      if (!next.ok()) return queue.Close(next.status());
      if (!*next) return queue.Close(Status::Ok());
      OwnPicture(*frame);
      queue.PushReady(frame);
    }
    queue.Close(Status::Ok());
  } catch (const std::exception& error) {
    queue.Close(ParseError(DisplayPath(reader.path()) + ": decoding failed: " + error.what()));
  }
}

// every frame through the pass; decoding on a second thread when asked
Status RunPass(VideoReader& reader, ClipPass& pass, int queue_frames,
               const ClipProgress& progress) {
  int64_t done = 0;
  if (queue_frames == 0) {
    Frame frame;
    while (true) {
      LIFTOFF_ASSIGN_OR_RETURN(const bool more, reader.Next(frame));
      if (!more) return Status::Ok();
      LIFTOFF_RETURN_IF_ERROR(pass.Process(frame));
      if (progress) progress(++done, frame.t_ns);
    }
  }

  FrameQueue queue(queue_frames + 1);
  std::thread decoder(DecodeInto, std::ref(reader), std::ref(queue));
  // the decoder is stopped and joined however this scope is left (errors, exceptions)
  struct Joiner {
    FrameQueue& queue;
    std::thread& thread;
    ~Joiner() {
      queue.Cancel();
      if (thread.joinable()) thread.join();
    }
  } joiner{queue, decoder};

  while (Frame* frame = queue.TakeReady()) {
    const Status processed = pass.Process(*frame);
    const int64_t t_ns = frame->t_ns;
    queue.ReturnSpare(frame);
    if (!processed.ok()) return processed;
    if (progress) progress(++done, t_ns);
  }
  return queue.end_status();
}

// [LED on + from, LED on + to), extended forward to hold min_frames frames when it holds
// fewer; the warning says so
struct RestWindow {
  int64_t from_ns = 0;
  int64_t to_ns = 0;
  int64_t frames = 0;
  std::string warning;
};

RestWindow ChooseRestWindow(const ClipAnalysisOptions& options, int64_t led_on_ns,
                            const std::vector<HeightSample>& samples) {
  RestWindow window;
  window.from_ns = led_on_ns + NsFromSeconds(options.rest_from_led_s);
  window.to_ns = led_on_ns + NsFromSeconds(options.rest_to_led_s);
  const auto before = [](const HeightSample& sample, int64_t t_ns) { return sample.t_ns < t_ns; };
  const auto first = std::lower_bound(samples.begin(), samples.end(), window.from_ns, before);
  const auto last = std::lower_bound(first, samples.end(), window.to_ns, before);
  window.frames = last - first;
  const auto wanted = static_cast<int64_t>(options.rest_min_frames);
  if (window.frames >= wanted) return window;

  // too few frames: the first `wanted` frames from the window's start (all there are)
  const int64_t available = samples.end() - first;
  if (available == 0) {
    window.warning = "rest window " + FormatSeconds(window.from_ns) + "-" +
                     FormatSeconds(window.to_ns) + " s holds no frame";
    return window;
  }
  const int64_t taken = std::min(wanted, available);
  const int64_t old_to_ns = window.to_ns;
  window.to_ns = (first + (taken - 1))->t_ns + 1;
  window.warning = "rest window extended to " + FormatSeconds(window.to_ns) + " s (from " +
                   FormatSeconds(old_to_ns) + " s) to hold " + Plural(taken, "frame") +
                   "; it held " + Plural(window.frames, "frame");
  window.frames = taken;
  return window;
}

json RectJson(const cv::Rect& rect) {
  return {{"x_px", rect.x}, {"y_px", rect.y}, {"width_px", rect.width}, {"height_px", rect.height}};
}

json EventJson(const TimedEvent& event) {
  return {{"t_ns", event.t_ns},
          {"t_s", SecondsFromNs(event.t_ns)},
          {"uncertainty_ms", 1e-6 * static_cast<double>(event.uncertainty_ns)},
          {"frame_before", event.frame_before},
          {"frame_after", event.frame_after}};
}

std::string_view IrregularityKindName(TimingIrregularity::Kind kind) {
  switch (kind) {
    case TimingIrregularity::Kind::kDropped: return "dropped";
    case TimingIrregularity::Kind::kIrregular: return "irregular";
    case TimingIrregularity::Kind::kRepaired: return "repaired";
  }
  return "irregular";
}

json TimingJson(const FrameTimingReport& timing) {
  json irregularities = json::array();
  for (const TimingIrregularity& item : timing.irregularities) {
    irregularities.push_back({{"kind", IrregularityKindName(item.kind)},
                              {"frame", item.frame_index},
                              {"t_s", SecondsFromNs(item.t_ns)},
                              {"interval_ms", 1e-6 * static_cast<double>(item.interval_ns)},
                              {"missing_frames", item.missing_frames}});
  }
  const double median_s = SecondsFromNs(timing.median_interval_ns);
  return {{"frames", timing.frames},
          {"first_s", SecondsFromNs(timing.first_ns)},
          {"last_s", SecondsFromNs(timing.last_ns)},
          {"median_interval_ms", 1e3 * median_s},
          {"fps", timing.fps > 0 ? json(timing.fps) : json()},
          {"codec", timing.codec_fourcc},
          {"lossless_codec", timing.lossless_codec},
          {"keyframes", timing.keyframes},
          {"keyframes_known", timing.keyframes_known},
          {"dropped_frames", timing.dropped_frames},
          {"repaired_frames", timing.repaired_frames},
          {"irregular_frames", timing.irregular_frames},
          {"container_fps", timing.container_fps},
          {"container_frames", timing.container_frames},
          {"irregularities", irregularities}};
}

}  // namespace

std::string_view LiftoffInstantName(LiftoffInstant instant) {
  return instant == LiftoffInstant::kOnset ? "onset" : "threshold";
}

std::optional<LiftoffInstant> ParseLiftoffInstant(std::string_view text) {
  if (text == "threshold") return LiftoffInstant::kThreshold;
  if (text == "onset") return LiftoffInstant::kOnset;
  return std::nullopt;
}

Status ClipAnalysisOptions::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(reader.Validate().WithContext("reader"));
  LIFTOFF_RETURN_IF_ERROR(led.Validate().WithContext("led"));
  const Status foot_valid =
      foot.foot_roi_px.empty() ? foot.ValidateAllButRegion() : foot.Validate();
  LIFTOFF_RETURN_IF_ERROR(foot_valid.WithContext("foot"));
  const auto check = [](std::string_view field, double value, const NumberRange& range) {
    if (InNumberRange(value, range)) return Status::Ok();
    return InvalidArgumentError(std::string(field) + ": expected " + DescribeNumberRange(range) +
                                ", got " + FormatNumber(value));
  };
  LIFTOFF_RETURN_IF_ERROR(check("rest_from_led_s", rest_from_led_s, kRestOffsetRange));
  LIFTOFF_RETURN_IF_ERROR(check("rest_to_led_s", rest_to_led_s, kRestOffsetRange));
  if (rest_to_led_s <= rest_from_led_s) {
    return InvalidArgumentError("rest_to_led_s: expected more than rest_from_led_s (" +
                                FormatNumber(rest_from_led_s) + "), got " +
                                FormatNumber(rest_to_led_s));
  }
  LIFTOFF_RETURN_IF_ERROR(check("rest_min_frames", rest_min_frames, {.min = 1, .max = 1000}));
  LIFTOFF_RETURN_IF_ERROR(check("queue_frames", queue_frames, {.min = 0, .max = 16}));
  return Status::Ok();
}

const TimedEvent* ClipAnalysis::liftoff() const {
  if (!foot) return nullptr;
  return liftoff_instant == LiftoffInstant::kOnset ? &foot->onset : &foot->above_threshold;
}

Result<EventTimes> ClipAnalysis::Events() const {
  const TimedEvent* lifted = liftoff();
  if (lifted == nullptr || led.pulses.empty()) {
    return NotFoundError(DisplayPath(video_path) +
                         ": no liftoff: the clip was analysed without a foot region");
  }
  EventTimes times;
  times.led_on_ns = led_on().on_ns;
  times.led_on_uncertainty_ns = led_on().on_uncertainty_ns;
  times.liftoff_ns = lifted->t_ns;
  times.liftoff_uncertainty_ns = lifted->uncertainty_ns;
  times.source = "video";
  return times;
}

std::string ClipAnalysis::Brief() const {
  std::string text = video_path.filename().string() + ": ";
  if (!led.pulses.empty()) {
    text += "LED on " + FormatSeconds(led_on().on_ns, 4) + " s +- " +
            FormatMilliseconds(led_on().on_uncertainty_ns);
  }
  if (const TimedEvent* lifted = liftoff()) {
    text += ", liftoff " + FormatSeconds(lifted->t_ns, 4) + " s +- " +
            FormatMilliseconds(lifted->uncertainty_ns);
    if (liftoff_instant == LiftoffInstant::kOnset) {
      text += " (onset)";
    } else if (foot->px_per_mm > 0) {
      text += " (" + FormatFixed(foot->threshold_px / foot->px_per_mm, 2) +
              " mm = " + FormatFixed(foot->threshold_px, 2) + " px)";
    } else {
      text += " (" + FormatFixed(foot->threshold_px, 2) + " px)";
    }
    if (!led.pulses.empty()) {
      text += ", interval " + FormatSeconds(lifted->t_ns - led_on().on_ns, 4) + " s";
    }
  }
  text += ", " + Plural(timing.frames, "frame");
  if (!warnings.empty()) text += ", " + Plural(static_cast<int64_t>(warnings.size()), "warning");
  return text;
}

json ClipAnalysis::ToJson() const {
  json pulses = json::array();
  for (const LedPulse& pulse : led.pulses) {
    pulses.push_back({{"on_ns", pulse.on_ns},
                      {"on_s", SecondsFromNs(pulse.on_ns)},
                      {"on_uncertainty_ms", 1e-6 * static_cast<double>(pulse.on_uncertainty_ns)},
                      {"first_lit_frame", pulse.first_lit_frame},
                      {"first_lit_fraction", pulse.first_lit_fraction},
                      {"missing_frames_before_on", pulse.missing_frames_before_on},
                      {"spread_frames", pulse.spread_frames},
                      {"off_s", pulse.off_ns ? json(SecondsFromNs(*pulse.off_ns)) : json()}});
  }
  json document = {
      {"format", "liftoff-video-analysis"},
      {"version", 1},
      {"video", video_path.string()},
      {"width_px", width_px},
      {"height_px", height_px},
      {"timing", TimingJson(timing)},
      {"led",
       {{"roi_px", RectJson(led.roi_px)},
        {"roi_located", led.roi_located},
        {"off_level", led.off_level},
        {"on_level", led.on_level},
        {"contrast_levels", led.contrast_levels},
        {"pulses", pulses},
        {"warnings", led.warnings}}},
      {"foot", nullptr},
      {"events", nullptr},
      {"warnings", warnings},
      {"wall_s", wall_seconds},
  };
  if (foot) {
    json patches = json::array(), foot_patches = json::array();
    for (const cv::Rect& patch : foot->reference_patches_px) patches.push_back(RectJson(patch));
    for (const cv::Rect& patch : foot->foot_patches_px) foot_patches.push_back(RectJson(patch));
    document["foot"] = {
        {"roi_px", RectJson(foot->foot_roi_px)},
        {"reference_patches_px", patches},
        {"foot_patches_px", foot_patches},
        {"low_confidence", foot->low_confidence},
        {"fit_frames", {foot->fit_first_frame, foot->fit_last_frame}},
        {"fit_noise_px", foot->fit_noise_px},
        {"located_by_tape", foot->located_by_tape},
        {"center_x_px", foot->foot_center_x_px},
        {"width_px", foot->foot_width_px},
        {"bottom_px", foot->foot_bottom_px},
        {"px_per_mm", foot->px_per_mm > 0 ? json(foot->px_per_mm) : json()},
        {"px_per_mm_estimated", foot->px_per_mm_estimated},
        {"threshold_px", foot->threshold_px},
        {"threshold_mm", foot->px_per_mm > 0 ? json(foot->threshold_px / foot->px_per_mm) : json()},
        {"rest_window_s", {SecondsFromNs(rest_from_ns), SecondsFromNs(rest_to_ns)}},
        {"rest_frames", rest_frames},
        {"rest_rise_px", foot->rest_rise_px},
        {"rest_noise_px", foot->rest_noise_px},
        {"still_noise_px", foot->still_noise_px},
        {"max_rise_px", foot->max_rise_px},
        {"exposure_offset_ms", 1e-6 * static_cast<double>(foot->exposure_offset_ns)},
        {"poor_frames", foot->poor_frames},
        {"onset", EventJson(foot->onset)},
        {"above_threshold", EventJson(foot->above_threshold)},
        {"warnings", foot->warnings},
    };
  }
  if (Result<EventTimes> events = Events(); events.ok()) {
    const int64_t interval_ns = events->liftoff_ns - events->led_on_ns;
    document["events"] = {
        {"led_on_ns", events->led_on_ns},
        {"led_on_s", SecondsFromNs(events->led_on_ns)},
        {"led_on_uncertainty_ns", events->led_on_uncertainty_ns},
        {"liftoff_ns", events->liftoff_ns},
        {"liftoff_s", SecondsFromNs(events->liftoff_ns)},
        {"liftoff_uncertainty_ns", events->liftoff_uncertainty_ns},
        {"liftoff_instant", LiftoffInstantName(liftoff_instant)},
        {"interval_s", SecondsFromNs(interval_ns)},
        {"interval_uncertainty_ms", 1e-6 * static_cast<double>(events->led_on_uncertainty_ns +
                                                               events->liftoff_uncertainty_ns)},
        {"source", events->source},
    };
  }
  return document;
}

Result<ClipAnalysis> AnalyzeClip(const std::filesystem::path& path,
                                 const ClipAnalysisOptions& options, const ClipProgress& progress) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  const int64_t started_ns = MonotonicNowNs();
  LIFTOFF_ASSIGN_OR_RETURN(VideoReader reader, VideoReader::Open(path, options.reader));

  // one pass: every frame to the LED detector and the foot tracker (no codec lag to allow
  // for in a lossless clip)
  FootTracker::Options foot_options = options.foot;
  if (reader.timing().lossless_codec) foot_options.compression_error_px = 0.0;
  ClipPass pass(options, foot_options, path);
  reader.ConvertOnly(pass.RegionsRead(cv::Size(reader.width_px(), reader.height_px())));
  LIFTOFF_RETURN_IF_ERROR(RunPass(reader, pass, options.queue_frames, progress));

  ClipAnalysis analysis;
  analysis.video_path = path;
  analysis.width_px = reader.width_px();
  analysis.height_px = reader.height_px();
  analysis.timing = reader.timing();
  analysis.liftoff_instant = options.liftoff;
  const FrameTimingReport& timing = analysis.timing;

  // a frame's exposure cannot outlast its interval (5 % allowed for timestamp rounding)
  const double interval_s = SecondsFromNs(timing.median_interval_ns);
  for (const auto& [field, exposure_s] :
       {std::pair<const char*, double>{"led.exposure_s", options.led.exposure_s},
        {"foot.exposure_s", options.foot.exposure_s}}) {
    if (interval_s > 0 && exposure_s > kMaxExposureIntervals * interval_s) {
      return InvalidArgumentError(
          DisplayPath(path) + ": " + field + " (--exposure-ms): the exposure " +
          FormatFixed(1e3 * exposure_s, 2) + " ms is longer than the frame interval " +
          FormatFixed(1e3 * interval_s, 2) + " ms (median)");
    }
  }
  if (timing.dropped_frames > 0) {
    analysis.warnings.push_back("frames: " + Plural(timing.dropped_frames, "frame") +
                                " dropped (timestamps jump); times are the file's own");
  }
  if (timing.irregular_frames > 0) {
    analysis.warnings.push_back("frames: " + Plural(timing.irregular_frames, "interval") +
                                " off the usual " + FormatMilliseconds(timing.median_interval_ns));
  }

  // the LED, then the rest window from its first switch-on, then the foot
  Result<LedResult> led = pass.led().Finish();
  if (!led.ok()) return led.status().WithContext(DisplayPath(path));
  analysis.led = std::move(led).value();
  for (const std::string& warning : analysis.led.warnings) {
    analysis.warnings.push_back("LED: " + warning);
  }
  if (analysis.led.pulses.size() > 1) {
    analysis.warnings.push_back(
        "LED: " + Plural(static_cast<int64_t>(analysis.led.pulses.size()), "switch-on") +
        " in the clip; the first is the sync instant");
  }
  if (std::optional<FootTracker>& foot = pass.foot()) {
    const RestWindow rest = ChooseRestWindow(options, analysis.led_on().on_ns, foot->samples());
    if (!rest.warning.empty()) analysis.warnings.push_back(rest.warning);
    analysis.rest_from_ns = rest.from_ns;
    analysis.rest_to_ns = rest.to_ns;
    analysis.rest_frames = rest.frames;
    foot->SetRestWindow(rest.from_ns, rest.to_ns);
    Result<FootTrack> track = std::move(*foot).Finish();
    if (!track.ok()) return track.status().WithContext(DisplayPath(path));
    analysis.foot = std::move(track).value();
    for (const std::string& warning : analysis.foot->warnings) {
      analysis.warnings.push_back("foot: " + warning);
    }
  }
  analysis.wall_seconds = SecondsFromNs(MonotonicNowNs() - started_ns);
  return analysis;
}

cv::Rect RectFromRegion(const RegionPx& region) {
  return {region.x_px, region.y_px, region.width_px, region.height_px};
}

RegionPx RegionFromRect(const cv::Rect& rect) {
  return {.x_px = rect.x, .y_px = rect.y, .width_px = rect.width, .height_px = rect.height};
}

}  // namespace liftoff::video
