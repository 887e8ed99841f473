#include "liftoff/synth/trial_writer.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <system_error>
#include <utility>

#include <nlohmann/json.hpp>

#include "liftoff/core/controller_log.h"
#include "liftoff/core/json.h"
#include "liftoff/core/random.h"
#include "liftoff/core/time.h"
#include "liftoff/synth/scene.h"
#include "liftoff/synth/video_writer.h"

namespace liftoff::synth {
namespace {

// Independent random streams per purpose, so that turning one nuisance on never moves
// another's draws (the renderer has its own).
constexpr uint64_t kFrameStream = 0x6672616d65730001ull;
constexpr uint64_t kLogStream = 0x6c6f672d73740002ull;

// The paper's bend: each cable of the pulled group at P = 80 % of its length.
constexpr double kBendLengthFraction = 0.8;

// Shortest text that reads back to the same double, never localised.
std::string Number(double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

}  // namespace

std::vector<int64_t> FrameScheduleNs(const TrialSpec& spec) {
  const CameraSpec& camera = spec.camera;
  const int64_t duration_ns = NsFromSeconds(spec.duration_s);
  SplitMix64 random(spec.seed ^ kFrameStream);
  std::vector<int64_t> times;
  for (int64_t slot = 0;; ++slot) {
    const int64_t slot_ns = NsFromSeconds(static_cast<double>(slot) / camera.fps);
    if (slot_ns >= duration_ns) break;
    // both draws every slot: drops and jitter stay independent of each other
    const double drop_draw = random.Uniform();
    const double jitter_draw = random.Symmetric();
    if (slot == 0) {
      times.push_back(0);
      continue;
    }
    if (drop_draw < camera.drop_probability) continue;
    const int64_t t_ns = std::max(slot_ns + NsFromSeconds(jitter_draw * camera.timestamp_jitter_s),
                                  times.back() + 1);
    if (t_ns >= duration_ns) break;
    times.push_back(t_ns);
  }
  return times;
}

void FillLedTruth(const TrialSpec& spec, const std::vector<int64_t>& frame_times_ns,
                  GroundTruth& truth) {
  truth.led_on_video_ns = LedOnVideoNs(spec);
  truth.led_first_frame.reset();
  truth.led_first_frame_fraction = 0.0;
  if (!truth.led_on_video_ns) return;
  // the first exposure that sees the LED on, by the fraction the renderer draws
  for (size_t i = 0; i < frame_times_ns.size(); ++i) {
    const double fraction = LedOnFractionOfExposure(spec, frame_times_ns[i]);
    if (fraction <= 0.0) continue;
    truth.led_first_frame = static_cast<int64_t>(i);
    truth.led_first_frame_fraction = fraction;
    return;
  }
}

double BendSpoolTargetRad(const Calibration& calibration, CableGroup pulled_group) {
  // the largest groove shortens its cable fastest: it sets the bend
  size_t largest = 0;
  for (size_t i = 1; i < kSpoolGrooves; ++i) {
    if (calibration.spool_groove_radii_m[i] > calibration.spool_groove_radii_m[largest])
      largest = i;
  }
  const double radius_m = calibration.spool_groove_radii_m[largest];
  if (!(radius_m > 0.0)) return 0.0;
  const double angle_rad =
      (1.0 - kBendLengthFraction) * calibration.cable_lengths_m[largest] / radius_m;
  return pulled_group == CableGroup::kHL ? -angle_rad : angle_rad;
}

namespace {

// the log's header: what made the log and what it holds
LogHeader TrialLogHeader(const TrialSpec& spec, const Calibration& calibration, CableGroup pulled,
                         double spool_target_rad) {
  LogHeader header;
  header.calibration = calibration.name;
  header.source = "synth " + spec.id;
  header.device = "liftoff synth";
  header.metadata["trial_id"] = spec.id;
  header.metadata["seed"] = std::to_string(spec.seed);
  header.metadata["foot"] = std::string(FootName(spec.motion.foot));
  header.metadata["pulled_group"] = std::string(CableGroupName(pulled));
  header.metadata["rotation"] = std::string(RotationSenseName(spec.motion.rotation));
  header.metadata["bend_spool_target_rad"] = Number(spool_target_rad);
  header.metadata["ramp_rate_rad_per_s"] = Number(spec.motion.ramp_rate_rad_per_s);
  header.metadata["clock_drift_ppm"] = Number(spec.log.clock_drift_ppm);
  return header;
}

Status AppendLedOn(ControllerLogWriter& writer, int64_t led_device_ns) {
  LogEvent event;
  event.device_time_ns = led_device_ns;
  event.kind = LogEventKind::kLedOn;
  return writer.Append(event);
}

// bursty logs: only slots inside a burst, bursts starting at the LED switch-on
bool OutsideBurst(const LogSpec& log, double since_led_s) {
  if (!(log.burst_period_s > 0.0)) return false;
  const double phase_s =
      since_led_s - std::floor(since_led_s / log.burst_period_s) * log.burst_period_s;
  return phase_s >= log.burst_length_s - 1e-9;
}

// the true motion at device instant t_ns, through the encoders' counts
LogSample SampleAt(const Timeline& timeline, const Calibration& calibration, int64_t t_ns,
                   int64_t led_device_ns, double spool_target_rad) {
  const double test_s = timeline.TestSecondsFromVideoNs(timeline.VideoNsFromDeviceNs(t_ns));
  const int64_t rotate_counts = calibration.CountsFromShaftAngle(
      calibration.ShaftAngleFromVertebraAngle(timeline.VertebraRadAt(test_s)));
  const int64_t bend_counts =
      calibration.CountsFromShaftAngle(timeline.BendSpoolRadAt(test_s, spool_target_rad));
  LogSample sample;
  sample.device_time_ns = t_ns;
  sample.led_on = t_ns >= led_device_ns;
  sample.bend_counts = bend_counts;
  sample.rotate_counts = rotate_counts;
  sample.bend_spool_rad =
      calibration.SpoolAngleFromShaftAngle(calibration.ShaftAngleFromCounts(bend_counts));
  sample.rotate_shaft_rad = calibration.ShaftAngleFromCounts(rotate_counts);
  sample.vertebra_rad = calibration.VertebraAngleFromShaftAngle(sample.rotate_shaft_rad);
  return sample;
}

}  // namespace

Status WriteTrialLog(const Timeline& timeline, const Calibration& calibration,
                     const std::filesystem::path& path) {
  const TrialSpec& spec = timeline.spec();
  const LogSpec& log = spec.log;
  const CableGroup pulled = PaperTableTwoMotion(spec.motion.foot).pulled_group;
  const double spool_target_rad = BendSpoolTargetRad(calibration, pulled);
  ControllerLogWriter writer;
  LIFTOFF_RETURN_IF_ERROR(
      writer.Open(path, TrialLogHeader(spec, calibration, pulled, spool_target_rad)));

  // the span on the device clock: lead_s before the LED (2018-style logs start at it) to
  // tail_s after the clip's end
  const int64_t led_video_ns = timeline.led_on_origin_video_ns();
  const int64_t led_device_ns = log.led_on_device_ns;
  const int64_t first_device_ns =
      log.led_event ? timeline.DeviceNsFromVideoNs(led_video_ns - NsFromSeconds(log.lead_s))
                    : led_device_ns;
  const int64_t last_device_ns = timeline.DeviceNsFromVideoNs(
      std::max(timeline.duration_ns(), led_video_ns) + NsFromSeconds(log.tail_s));

  // the sample grid is anchored at the LED switch-on: slot k at k / rate
  const double period_s = 1.0 / log.rate_hz;
  const auto first_slot = static_cast<int64_t>(
      std::ceil(SecondsFromNs(first_device_ns - led_device_ns) / period_s - 1e-9));
  SplitMix64 random(spec.seed ^ kLogStream);
  bool led_event_written = !log.led_event;
  int64_t previous_ns = std::numeric_limits<int64_t>::min();
  for (int64_t slot = first_slot;; ++slot) {
    const double since_led_s = static_cast<double>(slot) * period_s;
    const int64_t nominal_ns = led_device_ns + NsFromSeconds(since_led_s);
    if (nominal_ns > last_device_ns) break;
    const double jitter_draw = random.Symmetric();
    if (OutsideBurst(log, since_led_s)) continue;
    int64_t t_ns = nominal_ns + NsFromSeconds(jitter_draw * log.jitter_s);
    if (!log.led_event) t_ns = std::max(t_ns, led_device_ns);
    t_ns = std::max(t_ns, previous_ns + 1);
    previous_ns = t_ns;
    // the LED event goes before the first sample at or after it
    if (!led_event_written && t_ns >= led_device_ns) {
      LIFTOFF_RETURN_IF_ERROR(AppendLedOn(writer, led_device_ns));
      led_event_written = true;
    }
    LIFTOFF_RETURN_IF_ERROR(
        writer.Append(SampleAt(timeline, calibration, t_ns, led_device_ns, spool_target_rad)));
  }
  if (!led_event_written) LIFTOFF_RETURN_IF_ERROR(AppendLedOn(writer, led_device_ns));
  return writer.Close();
}

namespace {

VideoWriterOptions VideoOptionsFor(const CameraSpec& camera) {
  VideoWriterOptions options;
  options.codec = camera.codec;
  options.width_px = camera.width_px;
  options.height_px = camera.height_px;
  options.nominal_fps = camera.fps;
  options.quality = camera.quality;
  return options;
}

// the frame times as the container will store them (a slot that would land on the
// previous frame's stored time is dropped, as a camera would)
std::vector<int64_t> StoredFrameTimesNs(const TrialSpec& spec, const VideoWriter& video) {
  std::vector<int64_t> times_ns;
  for (const int64_t t_ns : FrameScheduleNs(spec)) {
    const int64_t stored_ns = video.StoredPtsNs(t_ns);
    if (times_ns.empty() || stored_ns > times_ns.back()) times_ns.push_back(stored_ns);
  }
  return times_ns;
}

// render and encode frame by frame, each at the instant that will be stored; the time
// spent on each goes into `written`
Status RenderAndEncode(SceneRenderer& renderer, VideoWriter& video,
                       const std::vector<int64_t>& frame_times_ns, WrittenTrial& written) {
  int64_t render_ns = 0, encode_ns = 0;
  for (size_t i = 0; i < frame_times_ns.size(); ++i) {
    const int64_t started_ns = MonotonicNowNs();
    const cv::Mat frame = renderer.RenderFrame(static_cast<int64_t>(i), frame_times_ns[i]);
    const int64_t rendered_ns = MonotonicNowNs();
    LIFTOFF_RETURN_IF_ERROR(video.Write(frame, frame_times_ns[i]));
    render_ns += rendered_ns - started_ns;
    encode_ns += MonotonicNowNs() - rendered_ns;
  }
  const int64_t closing_ns = MonotonicNowNs();
  LIFTOFF_RETURN_IF_ERROR(video.Close());
  encode_ns += MonotonicNowNs() - closing_ns;
  written.render_seconds = SecondsFromNs(render_ns);
  written.encode_seconds = SecondsFromNs(encode_ns);
  return Status::Ok();
}

// the truth beside the frame times: LED, liftoff instants and the rotations there, image
// geometry
void FillTruth(const TrialSpec& spec, const Timeline& timeline, const SceneRenderer& renderer,
               GroundTruth& truth) {
  truth.trial_id = spec.id;
  truth.foot = spec.motion.foot;
  FillLedTruth(spec, truth.frame_times_ns, truth);
  const auto rotation_at = [&](int64_t t_video_ns) {
    return std::abs(timeline.VertebraRadAt(timeline.TestSecondsFromVideoNs(t_video_ns)));
  };
  truth.liftoff_0mm_video_ns = timeline.FirstVideoNsAbove(0.0);
  truth.liftoff_1mm_video_ns = timeline.FirstVideoNsAbove(0.001);
  if (truth.liftoff_0mm_video_ns) truth.liftoff_0mm_rad = rotation_at(*truth.liftoff_0mm_video_ns);
  if (truth.liftoff_1mm_video_ns) truth.liftoff_1mm_rad = rotation_at(*truth.liftoff_1mm_video_ns);
  truth.px_per_mm = renderer.px_per_mm();
  truth.led_roi_px = renderer.led_roi_px();
  truth.foot_roi_px = renderer.foot_roi_px();
  truth.foot_rest_bottom_px = renderer.foot_rest_bottom_px();
}

// the manifest entry: what a person would know before analysing the video
TrialRecord ManifestEntry(const TrialSpec& spec, const WrittenTrial& written) {
  const GroundTruth& truth = written.truth;
  TrialRecord entry;
  entry.id = spec.id;
  entry.foot = spec.motion.foot;
  entry.pulled_group = PaperTableTwoMotion(spec.motion.foot).pulled_group;
  entry.rotation = spec.motion.rotation;
  entry.log_path = written.log_path;
  entry.log_format = LogFormat::kLiftoff;
  entry.video_path = written.video_path;
  entry.led_roi_px = truth.led_roi_px;
  entry.foot_roi_px = truth.foot_roi_px;
  entry.px_per_mm = truth.px_per_mm;
  entry.notes = "synthetic (liftoff synth, seed " + std::to_string(spec.seed) + "); truth in " +
                written.truth_path.filename().string();
  return entry;
}

}  // namespace

Result<WrittenTrial> WriteTrial(const TrialSpec& spec, const Calibration& calibration,
                                const std::filesystem::path& output_dir) {
  LIFTOFF_ASSIGN_OR_RETURN(const Timeline timeline, Timeline::Create(spec));
  std::error_code error;
  std::filesystem::create_directories(output_dir, error);
  if (error) return IoError(output_dir.string() + ": cannot create the folder: " + error.message());

  WrittenTrial written;
  written.video_path = output_dir / (spec.id + std::string(VideoCodecExtension(spec.camera.codec)));
  written.log_path = output_dir / (spec.id + ".csv");
  written.truth_path = output_dir / (spec.id + ".truth.json");

  // the renderer first: a trial that cannot be drawn leaves no file behind
  LIFTOFF_ASSIGN_OR_RETURN(SceneRenderer renderer, SceneRenderer::Create(timeline));

  // the video, its truth, the controller log that goes with it, the manifest entry
  LIFTOFF_ASSIGN_OR_RETURN(auto video,
                           VideoWriter::Open(written.video_path, VideoOptionsFor(spec.camera)));
  written.truth.frame_times_ns = StoredFrameTimesNs(spec, *video);
  LIFTOFF_RETURN_IF_ERROR(RenderAndEncode(renderer, *video, written.truth.frame_times_ns, written));
  FillTruth(spec, timeline, renderer, written.truth);
  LIFTOFF_RETURN_IF_ERROR(WriteJsonFile(written.truth_path, written.truth.ToJson()));
  LIFTOFF_RETURN_IF_ERROR(WriteTrialLog(timeline, calibration, written.log_path));
  written.manifest_entry = ManifestEntry(spec, written);
  return written;
}

}  // namespace liftoff::synth
