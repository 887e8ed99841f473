#include "liftoff/synth/trial3d.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/random.h"
#include "liftoff/core/time.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/model.h"
#include "liftoff/synth/egl_context.h"
#include "liftoff/synth/trial_writer.h"
#include "liftoff/synth/video_writer.h"

namespace liftoff::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kShakeBoundPx = 4.0;
constexpr uint64_t kShakeStream = 0x5A4E3D0000000001ull;
constexpr uint64_t kNoiseStream = 0x5A4E3D0000000002ull;
constexpr uint64_t kLogStream = 0x5A4E3D0000000003ull;

// Trial3dSpec::rise_slowdown's range (Set3dVariation's too).
Status CheckRiseSlowdown(double rise_slowdown) {
  if (rise_slowdown >= 1 && rise_slowdown <= 20) return Status::Ok();
  return InvalidArgumentError("rise_slowdown: expected 1 .. 20, got " +
                              FormatNumber(rise_slowdown));
}

Status OutOfRange(const std::string& id, const char* field, double value, double low, double high) {
  std::ostringstream message;
  message << "trial3d " << id << ": " << field << ": expected a number in [" << low << ", "
          << high << "], got " << value;
  return InvalidArgumentError(message.str());
}

// linear interpolation on increasing `x`, held beyond the ends
double Interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (x.empty()) return 0.0;
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  const size_t i = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin());
  const double u = (at - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + u * (y[i] - y[i - 1]);
}

// first instant the linear curve exceeds `level`
std::optional<double> FirstAbove(const std::vector<double>& t, const std::vector<double>& h,
                                 double level) {
  for (size_t i = 0; i < h.size(); ++i) {
    if (h[i] <= level) continue;
    if (i == 0) return t[0];
    return t[i - 1] + (level - h[i - 1]) / (h[i] - h[i - 1]) * (t[i] - t[i - 1]);
  }
  return std::nullopt;
}

std::string CodecTag(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264: return "h264_mp4";
    case VideoCodec::kMjpeg: return "mjpeg_avi";
    case VideoCodec::kFfv1: return "ffv1_mkv";
  }
  return "?";
}

// the camera's frame times through the 2D path's schedule (drops, jitter)
TrialSpec ScheduleSpec(const Trial3dSpec& spec, double duration_s) {
  TrialSpec schedule;
  schedule.id = spec.id;
  schedule.seed = spec.seed;
  schedule.duration_s = duration_s;
  schedule.camera.width_px = spec.scene.width_px;
  schedule.camera.height_px = spec.scene.height_px;
  schedule.camera.fps = spec.fps;
  schedule.camera.exposure_s = spec.exposure_s;
  schedule.camera.drop_probability = spec.drop_probability;
  schedule.camera.timestamp_jitter_s = spec.timestamp_jitter_s;
  schedule.camera.codec = spec.codec;
  schedule.camera.quality = spec.quality;
  return schedule;
}

// ---------------------------------------------------------------------------------------
// image effects

struct Effects {
  const Trial3dSpec& spec;
  std::vector<cv::Point2d> shake{{0, 0}};
  SplitMix64 shake_rng;

  explicit Effects(const Trial3dSpec& s) : spec(s), shake_rng(s.seed ^ kShakeStream) {}

  // the walk's offset of frame k (a reflected random walk, as the 2D renderer's)
  cv::Point2d ShakeAt(size_t frame) {
    const auto reflect = [](double x) {
      while (std::abs(x) > kShakeBoundPx) x = (x > 0 ? 2 : -2) * kShakeBoundPx - x;
      return x;
    };
    while (shake.size() <= frame) {
      const cv::Point2d last = shake.back();
      const double dx = spec.shake_px * shake_rng.Gaussian(),
                   dy = spec.shake_px * shake_rng.Gaussian();
      shake.emplace_back(reflect(last.x + dx), reflect(last.y + dy));
    }
    return spec.shake_px > 0 ? shake[frame] : cv::Point2d(0, 0);
  }

  // the lamp's brightness averaged over the exposure centred on pts
  double FlickerGain(double pts_s) const {
    if (spec.flicker_amplitude <= 0) return 1.0;
    const double omega = 2 * kPi * spec.flicker_hz;
    const double t0 = pts_s - spec.exposure_s / 2, t1 = pts_s + spec.exposure_s / 2;
    return 1 + spec.flicker_amplitude * (std::cos(omega * t0) - std::cos(omega * t1)) /
                   (omega * (t1 - t0));
  }

  // a rolling shutter's readout: each sensor row sees the lamp's mean over its own exposure,
  // which starts r / rows of the readout after the first row's (centred on pts); in place
  void ScaleRows(cv::Mat& image, double pts_s) const {
    for (int r = 0; r < image.rows; ++r) {
      const double offset_s = spec.flicker_readout_s * ((r + 0.5) / image.rows - 0.5);
      image.row(r) *= FlickerGain(pts_s + offset_s);
    }
  }

  cv::Mat Apply(const cv::Mat& linear, size_t frame, double pts_s) {
    // linear: CV_32FC3, 8-bit scale
    const bool rolling = spec.flicker_readout_s > 0 && spec.flicker_amplitude > 0;
    cv::Mat image = linear * ((rolling ? 1.0 : FlickerGain(pts_s)) * spec.gain);  // a new matrix
    const cv::Point2d offset = ShakeAt(frame);
    if (offset.x != 0 || offset.y != 0) {
      const cv::Matx23d move(1, 0, offset.x, 0, 1, offset.y);
      cv::Mat moved;
      cv::warpAffine(image, moved, move, image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      image = moved;
    }
    if (rolling) ScaleRows(image, pts_s);  // the bands stay on the sensor's rows
    if (spec.blur_sigma_px > 0) cv::GaussianBlur(image, image, cv::Size(0, 0), spec.blur_sigma_px);
    if (spec.noise_sigma > 0) {
      cv::RNG rng(spec.seed ^ kNoiseStream ^ (0x9E3779B97F4A7C15ull * (frame + 1)));
      cv::Mat noise(image.size(), CV_32FC3);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, spec.noise_sigma);
      image += noise;
    }
    cv::Mat bgr;
    image.convertTo(bgr, CV_8UC3);  // rounds and saturates
    return bgr;
  }
};

// ---------------------------------------------------------------------------------------
// truth

nlohmann::json Rect(const cv::Rect& r) { return {r.x, r.y, r.width, r.height}; }

double Round(double value, double places) {
  const double scale = std::pow(10.0, places);
  return std::round(value * scale) / scale;
}

cv::Rect Clipped(cv::Rect r, int width, int height) { return r & cv::Rect(0, 0, width, height); }

// the foot's region a person would draw: 3.5 diameters square, the foot a little below
// the middle (room above for the lift)
cv::Rect FootRoi(cv::Point2d centre, double diameter_px, int width, int height) {
  const int side = static_cast<int>(std::lround(std::max(24.0, 3.5 * diameter_px)));
  return Clipped({static_cast<int>(std::lround(centre.x - side / 2.0)),
                  static_cast<int>(std::lround(centre.y - 0.585 * side)), side, side},
                 width, height);
}

cv::Rect LedRoi(cv::Point2d centre, double radius_px, int width, int height) {
  const int half = static_cast<int>(std::lround(std::max(12.0, 7.0 * radius_px)));
  return Clipped({static_cast<int>(std::lround(centre.x)) - half,
                  static_cast<int>(std::lround(centre.y)) - half, 2 * half, 2 * half},
                 width, height);
}

// the log's rotation at `t_s` after the LED: previous sample, or linear between samples
double LogLookup(const std::vector<ControllerSample>& log, double t_s, bool linear) {
  const double t_ms = t_s * 1000;
  size_t i = 0;
  while (i + 1 < log.size() && static_cast<double>(log[i + 1].t_ms) <= t_ms) ++i;
  if (!linear || i + 1 >= log.size()) return log[i].rotation_rad;
  const double u = (t_ms - static_cast<double>(log[i].t_ms)) /
                   static_cast<double>(log[i + 1].t_ms - log[i].t_ms);
  return log[i].rotation_rad + u * (log[i + 1].rotation_rad - log[i].rotation_rad);
}

std::string ControllerCsv(const std::vector<ControllerSample>& log) {
  std::ostringstream out;
  out << "t_ms,rotation_rad\n";
  char value[32];
  for (const ControllerSample& sample : log) {
    std::snprintf(value, sizeof value, "%.9f", sample.rotation_rad);
    out << sample.t_ms << ',' << value << '\n';
  }
  return out.str();
}

}  // namespace

// ---------------------------------------------------------------------------------------

Status Trial3dSpec::Validate() const {
  if (id.empty() || id.size() > 100 || id[0] == '.' ||
      !std::all_of(id.begin(), id.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
      })) {
    return InvalidArgumentError("trial3d: id: expected 1-100 of A-Z a-z 0-9 . _ -, got \"" + id +
                                "\"");
  }
  LIFTOFF_RETURN_IF_ERROR(scene.Validate().WithContext("trial3d " + id));
  if (tension_point_index < 0 || tension_point_index > 4)
    return OutOfRange(id, "tension_point_index", tension_point_index, 0, 4);
  if (tension) {
    for (const auto& [field, value] :
         {std::pair{"tension.silicone_n_per_m", tension->silicone_n_per_m},
          std::pair{"tension.buna_n_n_per_m", tension->buna_n_n_per_m},
          std::pair{"tension.spring_n_per_m", tension->spring_n_per_m}}) {
      if (!(value >= 1 && value <= 1e5)) return OutOfRange(id, field, value, 1, 1e5);
    }
  }
  if (!(theta_rate_rad_s >= 0.005 && theta_rate_rad_s <= 1))
    return OutOfRange(id, "theta_rate_rad_s", theta_rate_rad_s, 0.005, 1);
  if (!(max_rotation_rad >= 0.05 && max_rotation_rad <= kPi / 3 + 1e-12))
    return OutOfRange(id, "max_rotation_rad", max_rotation_rad, 0.05, kPi / 3);
  if (!(contact_floor_m >= 0 && contact_floor_m <= 1e-3))
    return OutOfRange(id, "contact_floor_m", contact_floor_m, 0, 1e-3);
  LIFTOFF_RETURN_IF_ERROR(CheckRiseSlowdown(rise_slowdown).WithContext("trial3d " + id));
  if (!(fps >= 1 && fps <= 240)) return OutOfRange(id, "fps", fps, 1, 240);
  if (!(exposure_s > 0 && exposure_s <= 1 / fps))
    return OutOfRange(id, "exposure_s", exposure_s, 0, 1 / fps);
  if (!(drop_probability >= 0 && drop_probability <= 0.5))
    return OutOfRange(id, "drop_probability", drop_probability, 0, 0.5);
  if (!(timestamp_jitter_s >= 0 && timestamp_jitter_s <= 0.4 / fps))
    return OutOfRange(id, "timestamp_jitter_s", timestamp_jitter_s, 0, 0.4 / fps);
  if (drop_frames_at_led < 0 || drop_frames_at_led > 5)
    return OutOfRange(id, "drop_frames_at_led", drop_frames_at_led, 0, 5);
  if (!(led_on_s >= 0.2 && led_on_s <= 60)) return OutOfRange(id, "led_on_s", led_on_s, 0.2, 60);
  if (!(after_lift_s >= 0.1 && after_lift_s <= 10))
    return OutOfRange(id, "after_lift_s", after_lift_s, 0.1, 10);
  if (!(max_duration_s > led_on_s && max_duration_s <= 120))
    return OutOfRange(id, "max_duration_s", max_duration_s, led_on_s, 120);
  if (!(noise_sigma >= 0 && noise_sigma <= 30))
    return OutOfRange(id, "noise_sigma", noise_sigma, 0, 30);
  if (!(gain >= 0.2 && gain <= 4)) return OutOfRange(id, "gain", gain, 0.2, 4);
  if (!(flicker_amplitude >= 0 && flicker_amplitude <= 0.5))
    return OutOfRange(id, "flicker_amplitude", flicker_amplitude, 0, 0.5);
  if (flicker_hz != 100 && flicker_hz != 120)
    return OutOfRange(id, "flicker_hz (100 or 120)", flicker_hz, 100, 120);
  if (!(flicker_readout_s >= 0 && flicker_readout_s <= 1 / fps))
    return OutOfRange(id, "flicker_readout_s", flicker_readout_s, 0, 1 / fps);
  if (!(shake_px >= 0 && shake_px <= 2)) return OutOfRange(id, "shake_px", shake_px, 0, 2);
  if (!(blur_sigma_px >= 0 && blur_sigma_px <= 5))
    return OutOfRange(id, "blur_sigma_px", blur_sigma_px, 0, 5);
  if (motion_blur_samples < 1 || motion_blur_samples > 16)
    return OutOfRange(id, "motion_blur_samples", motion_blur_samples, 1, 16);
  VideoWriterOptions writer;
  writer.codec = codec;
  writer.width_px = scene.width_px;
  writer.height_px = scene.height_px;
  writer.nominal_fps = fps;
  writer.quality = quality;
  writer.keyframe_interval_frames = keyframe_interval_frames;
  return writer.Validate().WithContext("trial3d " + id);
}

double Motion3d::HeightMAt(double t_video_s) const {
  return Interpolate(time_s, height_m, t_video_s);
}
double Motion3d::VertebraRadAt(double t_video_s) const {
  return Interpolate(time_s, vertebra_rad, t_video_s);
}

namespace {

// After motion.t_lift_s, each height is the simulated one `slowdown` times nearer the lift
// (the simulated curve's linear interpolation), the vertebra as it was.
void SlowTheRise(double slowdown, Motion3d& motion) {
  const double lift_s = *motion.t_lift_s;
  const std::vector<double> simulated_m = motion.height_m;
  for (size_t i = 0; i < motion.time_s.size(); ++i) {
    if (motion.time_s[i] <= lift_s) continue;
    const double t_s = lift_s + (motion.time_s[i] - lift_s) / slowdown;
    const auto after = std::upper_bound(motion.time_s.begin(), motion.time_s.end(), t_s);
    const size_t b = static_cast<size_t>(after - motion.time_s.begin());
    const size_t a = b - 1;  // time_s[0] = 0 <= lift_s < t_s
    const double w = (t_s - motion.time_s[a]) / (motion.time_s[b] - motion.time_s[a]);
    motion.height_m[i] = simulated_m[a] + w * (simulated_m[b] - simulated_m[a]);
  }
}

}  // namespace

Result<Motion3d> SimulateMotion3d(const Trial3dSpec& spec) {
  LIFTOFF_RETURN_IF_ERROR(spec.Validate());
  LIFTOFF_ASSIGN_OR_RETURN(sim::ModelDescription description,
                           sim::LoadModelDescription(sim::DefaultModelPath()));
  sim::ExperimentOptions options;
  options.foot = spec.foot;
  options.tension_point_index = spec.tension_point_index;
  options.tension_point = spec.tension;
  options.ramp_angle_rad = spec.max_rotation_rad;
  options.ramp_duration_s = spec.max_rotation_rad / spec.theta_rate_rad_s;
  LIFTOFF_ASSIGN_OR_RETURN(sim::ExperimentResult run, sim::RunExperiment(description, options));
  if (run.status == sim::RunStatus::kDidNotStand) {
    return NotFoundError("trial3d " + spec.id +
                         ": the simulated robot does not stand: " + run.Brief());
  }
  if (run.status == sim::RunStatus::kDiverged) {
    return InvalidArgumentError("trial3d " + spec.id + ": the simulation diverged: " + run.Brief());
  }

  // the ramp's start is the LED switch-on on the video clock
  Motion3d motion;
  const size_t foot = static_cast<size_t>(spec.foot);
  const double shift_s = spec.led_on_s - options.ramp_start_s;
  motion.time_s.push_back(0.0);  // at rest before the ramp
  motion.vertebra_rad.push_back(0.0);
  motion.height_m.push_back(0.0);
  for (const sim::CurvePoint& point : run.curve) {
    const double t = point.time_s + shift_s;
    if (t <= motion.time_s.back()) continue;
    const double h = point.height_m[foot];
    motion.time_s.push_back(t);
    motion.vertebra_rad.push_back(point.rotation_rad);
    motion.height_m.push_back(h < spec.contact_floor_m ? 0.0 : h);
  }
  motion.t_lift_s = FirstAbove(motion.time_s, motion.height_m, 0.0);
  if (motion.t_lift_s && spec.rise_slowdown != 1.0) SlowTheRise(spec.rise_slowdown, motion);
  motion.t_lift_1mm_s = FirstAbove(motion.time_s, motion.height_m, 0.001);
  if (run.feet[foot].lifted) motion.sim_liftoff_rad = run.feet[foot].rotation_rad;
  motion.sim_brief = run.Brief();
  return motion;
}

double EncoderQuantumRad() { return 2 * kPi / (12.0 * 1000.0 * 4.0); }

std::vector<ControllerSample> ControllerLog3d(const Trial3dSpec& spec, double duration_s) {
  SplitMix64 random(spec.seed ^ kLogStream);
  const double quantum = EncoderQuantumRad();
  const int64_t end_ms = static_cast<int64_t>(std::floor((duration_s - spec.led_on_s) * 1000));
  std::vector<ControllerSample> log;
  for (int64_t t_ms = 0; t_ms <= end_ms; t_ms += 8 + static_cast<int64_t>(random.Next() % 5)) {
    const double angle = std::min(spec.theta_rate_rad_s * static_cast<double>(t_ms) / 1000,
                                  spec.max_rotation_rad);
    // whole counts, rounded down (a tiny allowance for the division's rounding)
    log.push_back({t_ms, std::floor(angle / quantum + 1e-9) * quantum});
  }
  return log;
}

double LedLitFraction(double pts_s, double exposure_s, double t_on_s) {
  return std::clamp((pts_s + exposure_s / 2 - t_on_s) / exposure_s, 0.0, 1.0);
}

namespace {

struct Timing {
  double duration_s = 0;
  std::vector<int64_t> pts_ns;
};

Result<Timing> PlanFrames(const Trial3dSpec& spec, const Motion3d& motion,
                          const VideoWriter& writer) {
  Timing timing;
  timing.duration_s = spec.max_duration_s;
  if (motion.t_lift_1mm_s) {
    timing.duration_s = std::min(spec.max_duration_s, *motion.t_lift_1mm_s + spec.after_lift_s);
  }
  int dropped_at_led = 0;
  for (const int64_t t_ns : FrameScheduleNs(ScheduleSpec(spec, timing.duration_s))) {
    const int64_t stored_ns = writer.StoredPtsNs(t_ns);
    const bool after_led = SecondsFromNs(stored_ns) + spec.exposure_s / 2 > spec.led_on_s;
    if (after_led && dropped_at_led < spec.drop_frames_at_led) {
      ++dropped_at_led;
      continue;
    }
    if (timing.pts_ns.empty() || stored_ns > timing.pts_ns.back())
      timing.pts_ns.push_back(stored_ns);
  }
  return timing;
}

// one frame before the effects, CV_32FC3: the scene averaged over the exposure's
// sub-poses (motion blur), the LED blended by its lit fraction
cv::Mat BlendLed(SceneRenderer3d& renderer, const std::vector<RobotPose3d>& poses,
                 double fraction) {
  const auto average = [&](bool led_on) {
    cv::Mat sum;
    for (const RobotPose3d& pose : poses) {
      cv::Mat image = renderer.Render(pose, led_on), linear;
      if (led_on) renderer.AddLedGlow(image, 1.0);
      image.convertTo(linear, CV_32FC3);
      if (sum.empty()) {
        sum = linear;
      } else {
        sum += linear;
      }
    }
    return cv::Mat(sum / static_cast<double>(poses.size()));
  };
  if (fraction <= 0) return average(false);
  if (fraction >= 1) return average(true);
  return cv::Mat(average(false) * (1 - fraction) + average(true) * fraction);
}

// BlendLed, remembering the last frame: the robot stands still until the ramp starts, so
// the frames before it are one picture (rendering is deterministic: reuse is exact)
struct FrameCache {
  std::vector<RobotPose3d> poses;
  double fraction = -1;
  cv::Mat linear;

  const cv::Mat& Get(SceneRenderer3d& renderer, const std::vector<RobotPose3d>& at,
                     double led_fraction) {
    const auto same = [](const RobotPose3d& x, const RobotPose3d& y) {
      return x.lift_m == y.lift_m && x.vertebra_rad == y.vertebra_rad;
    };
    if (led_fraction != fraction || at.size() != poses.size() ||
        !std::equal(at.begin(), at.end(), poses.begin(), same)) {
      linear = BlendLed(renderer, at, led_fraction);
      poses = at;
      fraction = led_fraction;
    }
    return linear;
  }
};

// the poses a frame integrates: the midpoints of its exposure's equal parts (one part:
// the pose at pts)
std::vector<RobotPose3d> ExposurePoses(const Trial3dSpec& spec, const Motion3d& motion,
                                       double pts_s) {
  std::vector<RobotPose3d> poses;
  const int parts = spec.motion_blur_samples;
  for (int k = 0; k < parts; ++k) {
    const double t = pts_s + spec.exposure_s * ((2.0 * k + 1) / (2.0 * parts) - 0.5);
    poses.push_back({motion.HeightMAt(t), motion.VertebraRadAt(t)});
  }
  return poses;
}

// Long on purpose: the truth file's fields, one statement each (docs/synth.md, "Files of
// one 3D trial", lists them).
nlohmann::json TruthJson(const Trial3dSpec& spec, const Motion3d& motion,
                         const SceneRenderer3d& renderer, const std::vector<int64_t>& pts_ns,
                         const std::vector<cv::Point2d>& shake,
                         const std::vector<ControllerSample>& log, const std::string& video_name,
                         double duration_s) {
  using nlohmann::json;
  const int width = spec.scene.width_px, height = spec.scene.height_px;
  const bool led = spec.led_switches_on;
  // lift instants count only within the clip
  const auto within = [&](const std::optional<double>& t) {
    return t && *t < duration_s ? t : std::nullopt;
  };
  const std::optional<double> t_lift = within(motion.t_lift_s),
                              t_lift_1mm = within(motion.t_lift_1mm_s);
  const bool lifts = t_lift_1mm.has_value();
  json truth;
  truth["id"] = spec.id;
  truth["video"] = video_name;
  truth["controller_log"] = "controller.csv";
  truth["expect"] = led && lifts ? "ok" : "reject";
  truth["note"] = "liftoff synth3d (MuJoCo offscreen renderer), motion from liftoff's simulation";
  truth["width"] = width;
  truth["height"] = height;
  truth["nominal_fps"] = spec.fps;
  truth["timing"] = spec.drop_probability > 0 || spec.drop_frames_at_led > 0
                        ? (spec.timestamp_jitter_s > 0 ? "jitter_drop" : "drop")
                    : spec.timestamp_jitter_s > 0 ? "jitter"
                                                  : "cfr";
  truth["codec"] = CodecTag(spec.codec);
  truth["n_frames"] = pts_ns.size();
  json pts = json::array(), led_frac = json::array(), h_mm = json::array();
  std::optional<size_t> first_lit, first_lifted;
  for (size_t i = 0; i < pts_ns.size(); ++i) {
    const double t = SecondsFromNs(pts_ns[i]);
    pts.push_back(t);
    const double fraction = led ? LedLitFraction(t, spec.exposure_s, spec.led_on_s) : 0.0;
    led_frac.push_back(fraction);
    if (fraction > 0 && !first_lit) first_lit = i;
    const double h = motion.HeightMAt(t);
    h_mm.push_back(h * 1000);
    if (h > 0 && !first_lifted) first_lifted = i;
  }
  truth["pts"] = pts;
  truth["t_led_on"] = led ? json(spec.led_on_s) : json(nullptr);
  truth["exposure_s"] = spec.exposure_s;
  truth["exposure_model"] =
      "frame i integrates [pts_i - exposure/2, pts_i + exposure/2] (global shutter); pose shown "
      "is the state at pts_i";
  truth["led_frac"] = led_frac;
  truth["led_first_lit_frame"] = first_lit ? json(*first_lit) : json(nullptr);
  const cv::Point2d led_px = renderer.LedCenterPx();
  const double led_radius = renderer.LedRadiusPx();
  truth["led_roi"] = Rect(LedRoi(led_px, led_radius, width, height));
  truth["led_center_px"] = {Round(led_px.x, 2), Round(led_px.y, 2)};
  truth["led_radius_px"] = Round(led_radius, 2);
  truth["led_rgb"] = spec.scene.led_rgb;
  truth["foot"] = std::string(FootName(spec.foot));
  const cv::Point2d foot_px = renderer.FootCenterPx();
  truth["foot_roi"] = Rect(FootRoi(foot_px, renderer.FootDiameterPx(), width, height));
  truth["foot_center_px"] = {Round(foot_px.x, 2), Round(foot_px.y, 2)};
  truth["foot_diameter_px"] = Round(renderer.FootDiameterPx(), 2);
  truth["foot_shape"] = std::string(FootShapeName(spec.scene.foot_shape));
  truth["t_lift"] = t_lift ? json(*t_lift) : json(nullptr);
  truth["t_lift_1mm"] = lifts ? json(*t_lift_1mm) : json(nullptr);
  truth["h_model"] = {{"source", "liftoff sim: " + motion.sim_brief},
                      {"rule", "linear between the simulation's 0.01 s samples; heights below "
                               "contact_floor_m count as 0"},
                      {"contact_floor_m", spec.contact_floor_m}};
  truth["h_mm"] = h_mm;
  truth["first_lifted_frame"] = first_lifted ? json(*first_lifted) : json(nullptr);
  truth["pixels_per_mm"] = renderer.PixelsPerMm();
  if (spec.shake_px > 0) {
    json offsets = json::array();
    for (size_t i = 0; i < pts_ns.size(); ++i)
      offsets.push_back({Round(shake[i].x, 3), Round(shake[i].y, 3)});
    truth["shake_px"] = offsets;
  } else {
    truth["shake_px"] = nullptr;
  }
  truth["theta_rate_rad_s"] = spec.theta_rate_rad_s;
  truth["encoder_quantum_rad"] = EncoderQuantumRad();
  if (led && lifts) {
    const double lift = *t_lift - spec.led_on_s, lift_1mm = *t_lift_1mm - spec.led_on_s;
    truth["lift_minus_led_s"] = lift;
    truth["theta_at_lift_rad"] = std::abs(motion.VertebraRadAt(*t_lift));
    truth["theta_at_lift_1mm_rad"] = std::abs(motion.VertebraRadAt(*t_lift_1mm));
    truth["theta_at_lift_log_hold"] = LogLookup(log, lift, false);
    truth["theta_at_lift_log_interp"] = LogLookup(log, lift, true);
    truth["theta_at_lift_1mm_log_interp"] = LogLookup(log, lift_1mm, true);
    truth["theta_tolerance_1frame_rad"] = spec.theta_rate_rad_s / spec.fps;
  } else {
    truth["reason"] = !led ? "LED never switches on" : "foot never lifts";
  }
  truth["sim_liftoff_rad"] = motion.sim_liftoff_rad ? json(*motion.sim_liftoff_rad) : json(nullptr);
  const Scene3dOptions& scene = spec.scene;
  truth["params"] = {
      {"seed", spec.seed},
      {"view", std::string(CameraViewName(scene.view))},
      {"camera_height_m", scene.camera_height_m},
      {"camera_distance_m", scene.camera_distance_m},
      {"fovy_deg", scene.fovy_deg},
      {"foot_shape", std::string(FootShapeName(scene.foot_shape))},
      {"colouring", static_cast<int>(scene.colouring)},
      {"floor", scene.floor == FloorKind::kGlossy ? "glossy" : "textured"},
      {"floor_reflectance", scene.floor == FloorKind::kGlossy ? scene.floor_reflectance : 0.0},
      {"clutter_count", scene.clutter_count},
      {"light_elevation_deg", scene.light_elevation_deg},
      {"light_azimuth_deg", scene.light_azimuth_deg},
      {"light_level", scene.light_level},
      {"led_radius_m", scene.led_radius_m},
      {"tension_point_index", spec.tension_point_index},
      {"tension_point",
       spec.tension
           ? spec.tension->name
           : sim::PaperTensionPoints()[static_cast<size_t>(spec.tension_point_index)].name},
      {"max_rotation_rad", spec.max_rotation_rad},
      {"drop_probability", spec.drop_probability},
      {"timestamp_jitter_s", spec.timestamp_jitter_s},
      {"drop_frames_at_led", spec.drop_frames_at_led},
      {"quality", spec.quality},
      {"keyframe_interval_frames", spec.keyframe_interval_frames},
      {"noise_sigma", spec.noise_sigma},
      {"gain", spec.gain},
      {"flicker_amplitude", spec.flicker_amplitude},
      {"flicker_hz", spec.flicker_hz},
      {"flicker_readout_s", spec.flicker_readout_s},
      {"shake_px", spec.shake_px},
      {"blur_sigma_px", spec.blur_sigma_px},
      {"motion_blur_samples", spec.motion_blur_samples},
      {"rise_slowdown", spec.rise_slowdown}};
  return truth;
}

// What RenderAndEncode did: the shake drawn per frame, px, and its time rendering and encoding.
struct Encoded {
  std::vector<cv::Point2d> shake;
  int64_t render_ns = 0;
  int64_t encode_ns = 0;
};

// Renders each frame at `pts_ns`, applies the camera's effects, encodes it, then closes
// `video`.
Result<Encoded> RenderAndEncode(const Trial3dSpec& spec, const Motion3d& motion,
                                SceneRenderer3d& renderer, const std::vector<int64_t>& pts_ns,
                                VideoWriter& video) {
  Effects effects(spec);
  FrameCache cache;
  Encoded encoded;
  for (size_t i = 0; i < pts_ns.size(); ++i) {
    const int64_t started_ns = MonotonicNowNs();
    const double t = SecondsFromNs(pts_ns[i]);
    const double fraction =
        spec.led_switches_on ? LedLitFraction(t, spec.exposure_s, spec.led_on_s) : 0.0;
    const cv::Mat frame =
        effects.Apply(cache.Get(renderer, ExposurePoses(spec, motion, t), fraction), i, t);
    encoded.shake.push_back(effects.ShakeAt(i));
    const int64_t rendered_ns = MonotonicNowNs();
    LIFTOFF_RETURN_IF_ERROR(video.Write(frame, pts_ns[i]));
    encoded.render_ns += rendered_ns - started_ns;
    encoded.encode_ns += MonotonicNowNs() - rendered_ns;
  }
  const int64_t closing_ns = MonotonicNowNs();
  LIFTOFF_RETURN_IF_ERROR(video.Close());
  encoded.encode_ns += MonotonicNowNs() - closing_ns;
  return encoded;
}

// An ok clip's manifest entry: its liftoff-format log, video, regions and scale from `truth`.
TrialRecord ManifestEntry3d(const Trial3dSpec& spec, const nlohmann::json& truth,
                            const WrittenTrial3d& written) {
  TrialRecord entry;
  entry.id = spec.id;
  entry.foot = spec.foot;
  entry.pulled_group = sim::MotionFor(spec.foot).pulled_group;
  entry.rotation = sim::MotionFor(spec.foot).rotation;
  entry.log_path = written.liftoff_log_path;
  entry.log_format = LogFormat::kLiftoff;
  entry.video_path = written.video_path;
  const auto region = [](const nlohmann::json& roi) {
    return RegionPx{roi[0].get<int>(), roi[1].get<int>(), roi[2].get<int>(), roi[3].get<int>()};
  };
  entry.led_roi_px = region(truth["led_roi"]);
  entry.foot_roi_px = region(truth["foot_roi"]);
  entry.px_per_mm = truth["pixels_per_mm"].get<double>();
  entry.notes = "synthetic 3D (liftoff synth, seed " + std::to_string(spec.seed) + "); truth in " +
                spec.id + "/truth.json";
  return entry;
}

}  // namespace

TrialSpec LiftoffLogSpec3d(const Trial3dSpec& spec, double duration_s) {
  TrialSpec log = ScheduleSpec(spec, duration_s);
  log.led.on_video_s = spec.led_switches_on ? spec.led_on_s : -1.0;
  log.motion.foot = spec.foot;
  log.motion.rotation = sim::MotionFor(spec.foot).rotation;
  log.motion.bend_start_s = 0.0;
  log.motion.bend_end_s = 0.0;
  log.motion.ramp_start_s = 0.0;
  log.motion.ramp_rate_rad_per_s = spec.theta_rate_rad_s;
  log.log.lead_s = 0.0;
  return log;
}

Result<WrittenTrial3d> WriteTrial3d(const Trial3dSpec& spec, const Calibration& calibration,
                                    const std::filesystem::path& output_dir) {
  LIFTOFF_ASSIGN_OR_RETURN(Motion3d motion, SimulateMotion3d(spec));
  LIFTOFF_ASSIGN_OR_RETURN(std::unique_ptr<SceneRenderer3d> renderer,
                           SceneRenderer3d::Create(spec.scene, spec.foot));

  WrittenTrial3d written;
  written.folder = output_dir / spec.id;
  const std::string video_name = "video" + std::string(VideoCodecExtension(spec.codec));
  written.video_path = written.folder / video_name;
  written.controller_path = written.folder / "controller.csv";
  written.truth_path = written.folder / "truth.json";
  VideoWriterOptions writer_options;
  writer_options.codec = spec.codec;
  writer_options.width_px = spec.scene.width_px;
  writer_options.height_px = spec.scene.height_px;
  writer_options.nominal_fps = spec.fps;
  writer_options.quality = spec.quality;
  writer_options.keyframe_interval_frames = spec.keyframe_interval_frames;
  LIFTOFF_ASSIGN_OR_RETURN(std::unique_ptr<VideoWriter> video,
                           VideoWriter::Open(written.video_path, writer_options));
  LIFTOFF_ASSIGN_OR_RETURN(const Timing timing, PlanFrames(spec, motion, *video));

  LIFTOFF_ASSIGN_OR_RETURN(const Encoded encoded,
                           RenderAndEncode(spec, motion, *renderer, timing.pts_ns, *video));

  // the controller's log and the truth
  const std::vector<ControllerSample> log = ControllerLog3d(spec, timing.duration_s);
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(written.controller_path, ControllerCsv(log)));
  const nlohmann::json truth = TruthJson(spec, motion, *renderer, timing.pts_ns, encoded.shake, log,
                                         video_name, timing.duration_s);
  written.truth_json = truth.dump(1) + "\n";
  written.expect = truth["expect"].get<std::string>();
  const auto seconds = [&](const char* key) -> std::optional<double> {
    return truth.contains(key) && truth[key].is_number() ? std::optional(truth[key].get<double>())
                                                         : std::nullopt;
  };
  written.t_led_on_s = seconds("t_led_on");
  written.t_lift_1mm_s = seconds("t_lift_1mm");
  written.theta_at_lift_1mm_rad = seconds("theta_at_lift_1mm_rad");

  // the same test's liftoff-format log and, for an ok clip, its manifest entry
  written.liftoff_log_path = written.folder / (spec.id + ".csv");
  LIFTOFF_ASSIGN_OR_RETURN(const Timeline timeline,
                           Timeline::Create(LiftoffLogSpec3d(spec, timing.duration_s)));
  LIFTOFF_RETURN_IF_ERROR(WriteTrialLog(timeline, calibration, written.liftoff_log_path));
  if (written.expect == "ok") written.manifest_entry = ManifestEntry3d(spec, truth, written);
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(written.truth_path, written.truth_json));
  written.frames = static_cast<int64_t>(timing.pts_ns.size());
  written.render_seconds = SecondsFromNs(encoded.render_ns);
  written.encode_seconds = SecondsFromNs(encoded.encode_ns);
  return written;
}

// ---------------------------------------------------------------------------------------
// the CI set

namespace {

// A clip of a set: the paper's test at the high tension point, H.264 CRF 23.
Trial3dSpec& AddToSet(std::vector<Trial3dSpec>& set, const std::string& id, uint64_t seed) {
  Trial3dSpec& spec = set.emplace_back();
  spec.id = id;
  spec.seed = seed;
  spec.scene.seed = seed;
  spec.quality = 23;
  // The paper's test: 60 degrees over 40 s, so an error in time costs in rotation what
  // it costs on hardware; the clip goes on 1.5 s past the 1 mm rule (the foot 22-27 mm
  // up, before the simulated robot tips over).
  const sim::ExperimentOptions paper;
  spec.theta_rate_rad_s = paper.ramp_angle_rad / paper.ramp_duration_s;
  spec.after_lift_s = 1.5;
  spec.max_duration_s = 25.0;
  return spec;
}

}  // namespace

// Long on purpose: a table of the set's clips, one block each.
std::vector<Trial3dSpec> Ci3dSet() {
  std::vector<Trial3dSpec> set;
  const auto add = [&](const std::string& id, uint64_t seed) -> Trial3dSpec& {
    return AddToSet(set, id, seed);
  };
  {
    Trial3dSpec& s = add("ci3d-01-side-480p-h264", 301);
    s.foot = Foot::kA;
    s.led_on_s = 2.030;  // mid-exposure: frame 61 is 0.70 lit
  }
  {
    Trial3dSpec& s = add("ci3d-02-oblique-720p-h264", 302);
    s.scene.view = CameraView::kOblique;
    s.scene.width_px = 1280;
    s.scene.height_px = 720;
    s.scene.foot_shape = FootShape::kBlock;
    s.foot = Foot::kC;
    s.led_on_s = 1.9;
    s.noise_sigma = 1.5;
  }
  {
    Trial3dSpec& s = add("ci3d-03-front-480p-mjpeg", 303);
    s.scene.view = CameraView::kFront;
    s.scene.camera_height_m = 0.25;
    s.scene.foot_shape = FootShape::kRubberTip;
    s.foot = Foot::kB;
    s.codec = VideoCodec::kMjpeg;
    s.quality = 5;
    s.led_on_s = 2.037;  // frame 61 is 0.28 lit
  }
  {
    Trial3dSpec& s = add("ci3d-04-oblique-480p-vfr-drops", 304);
    s.scene.view = CameraView::kOblique;
    s.scene.colouring = FootColouring::kUntaped;
    s.foot = Foot::kD;
    s.drop_probability = 0.03;
    s.timestamp_jitter_s = 0.003;
    s.led_on_s = 2.05;
  }
  {
    Trial3dSpec& s = add("ci3d-05-side-480p-hard-shadow", 305);
    s.scene.light_elevation_deg = 15;
    s.scene.light_azimuth_deg = -120;
    s.scene.camera_height_m = 0.2;
    s.foot = Foot::kC;
    s.fps = 60;
    s.exposure_s = 1.0 / 120;
    s.led_on_s = 1.5;  // twice the frames per second: a shorter lead
    s.flicker_amplitude = 0.05;
    s.flicker_hz = 100;
  }
  {
    Trial3dSpec& s = add("ci3d-06-side-480p-glossy-floor", 306);
    s.scene.floor = FloorKind::kGlossy;
    s.scene.foot_shape = FootShape::kBlock;
    s.scene.clutter_count = 8;
    s.foot = Foot::kA;
    s.shake_px = 0.3;
  }
  {
    Trial3dSpec& s = add("ci3d-07-oblique-480p-small-led", 307);
    s.scene.view = CameraView::kOblique;
    s.scene.led_radius_m = 0.0025;
    s.scene.led_glow_level = 60;
    s.scene.colouring = FootColouring::kBlack;
    s.foot = Foot::kB;
    s.blur_sigma_px = 0.8;
  }
  {
    Trial3dSpec& s = add("ci3d-08-oblique-480p-low-light", 308);
    s.scene.view = CameraView::kOblique;
    s.scene.light_level = 0.3;
    s.scene.camera_height_m = 0.5;
    s.gain = 1.8;
    s.noise_sigma = 6;
    s.motion_blur_samples = 3;  // the longest exposure: the robot blurs as it moves
    s.foot = Foot::kA;
    s.exposure_s = 1.0 / 30;
  }
  {
    Trial3dSpec& s = add("ci3d-09-reject-led-never-on", 309);
    s.led_switches_on = false;
    s.foot = Foot::kD;
  }
  {
    Trial3dSpec& s = add("ci3d-10-reject-foot-never-lifts", 310);
    s.scene.view = CameraView::kOblique;
    s.max_rotation_rad = 0.1;  // the ramp stops well before liftoff
    s.max_duration_s = 8.0;
    s.foot = Foot::kB;
  }
  return set;
}

// Long on purpose: a table of the set's clips, one block each.
std::vector<Trial3dSpec> Hard3dSet() {
  std::vector<Trial3dSpec> set;
  const auto add = [&](const std::string& id, uint64_t seed) -> Trial3dSpec& {
    return AddToSet(set, id, seed);
  };
  {
    Trial3dSpec& s = add("hard3d-01-oblique-480p-strong-flicker", 401);
    s.scene.view = CameraView::kOblique;
    s.flicker_amplitude = 0.35;
    s.flicker_hz = 120;
    s.exposure_s = 1.0 / 500;  // a short exposure sees the lamp's flicker whole
    s.noise_sigma = 2;
    s.foot = Foot::kC;
  }
  {
    Trial3dSpec& s = add("hard3d-02-side-480p-low-light-shake", 402);
    s.scene.light_level = 0.25;
    s.gain = 2.2;
    s.noise_sigma = 7;
    s.shake_px = 1.0;
    s.exposure_s = 1.0 / 30;
    s.foot = Foot::kA;
  }
  {
    Trial3dSpec& s = add("hard3d-03-oblique-720p-drops-at-led", 403);
    s.scene.view = CameraView::kOblique;
    s.scene.width_px = 1280;
    s.scene.height_px = 720;
    s.drop_frames_at_led = 2;
    s.drop_probability = 0.05;
    s.timestamp_jitter_s = 0.004;
    s.led_on_s = 2.013;
    s.foot = Foot::kB;
  }
  {
    Trial3dSpec& s = add("hard3d-04-side-480p-small-robot", 404);
    s.scene.camera_distance_m = 2.2;
    s.scene.led_radius_m = 0.004;
    s.noise_sigma = 2;
    s.foot = Foot::kD;
  }
  {
    Trial3dSpec& s = add("hard3d-05-front-720p-large-robot", 405);
    s.scene.view = CameraView::kFront;
    s.scene.width_px = 1280;
    s.scene.height_px = 720;
    s.scene.camera_distance_m = 0.5;
    s.scene.camera_height_m = 0.12;
    s.scene.foot_shape = FootShape::kBlock;
    s.foot = Foot::kA;
  }
  {
    Trial3dSpec& s = add("hard3d-06-side-480p-tiny-led", 406);
    s.scene.camera_distance_m = 1.3;
    s.scene.led_radius_m = 0.0015;
    s.scene.led_glow_level = 25;
    s.scene.colouring = FootColouring::kUntaped;
    s.noise_sigma = 3;
    s.foot = Foot::kC;
  }
  {
    Trial3dSpec& s = add("hard3d-07-oblique-480p-glossy-low-light", 407);
    s.scene.view = CameraView::kOblique;
    s.scene.floor = FloorKind::kGlossy;
    s.scene.floor_reflectance = 0.8;
    s.scene.light_level = 0.4;
    s.gain = 1.6;
    s.noise_sigma = 5;
    s.foot = Foot::kD;
  }
  {
    Trial3dSpec& s = add("hard3d-08-front-480p-mjpeg-shake", 408);
    s.scene.view = CameraView::kFront;
    s.scene.colouring = FootColouring::kBlack;
    s.scene.foot_shape = FootShape::kRubberTip;
    s.codec = VideoCodec::kMjpeg;
    s.quality = 8;
    s.shake_px = 0.6;
    s.foot = Foot::kB;
  }
  {
    Trial3dSpec& s = add("hard3d-09-side-480p-rolling-flicker", 409);
    s.flicker_amplitude = 0.3;
    s.flicker_hz = 100;
    s.flicker_readout_s = 1.0 / 40;  // a rolling shutter: 2.5 bands that roll every frame
    s.exposure_s = 1.0 / 250;
    s.noise_sigma = 2;
    s.foot = Foot::kD;
  }
  return set;
}

Result<std::vector<Trial3dSpec>> Set3dNamed(const std::string& name) {
  if (name == "ci3d") return Ci3dSet();
  if (name == "hard3d") return Hard3dSet();
  return InvalidArgumentError("unknown 3D set \"" + name + "\": expected ci3d or hard3d");
}

std::string Set3dSummary::Brief() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  const double frames_d = std::max<double>(1.0, static_cast<double>(frames));
  out << name << ": " << trials.size() << " clips, " << frames << " frames in " << wall_seconds
      << " s (render " << 1000 * render_seconds / frames_d << " ms/frame, encode "
      << 1000 * encode_seconds / frames_d << " ms/frame)";
  return out.str();
}

Result<Set3dSummary> WriteSpecs3d(const std::string& name, const std::vector<Trial3dSpec>& set,
                                  const std::filesystem::path& output_folder,
                                  const Calibration& calibration, const std::string& description,
                                  const Set3dProgress& progress) {
  const int64_t started_ns = MonotonicNowNs();
  // absolute, so that the manifest's paths come out relative to its own folder
  const std::filesystem::path output_dir = std::filesystem::absolute(output_folder);
  // every clip's spec first: a bad one (a varied set's exposure longer than a 60 fps clip's
  // frame) fails before anything is rendered or written
  for (const Trial3dSpec& spec : set) LIFTOFF_RETURN_IF_ERROR(spec.Validate().WithContext(spec.id));
  LIFTOFF_ASSIGN_OR_RETURN(std::unique_ptr<EglContext> context, EglContext::Create());
  Set3dSummary summary;
  summary.name = name;
  summary.renderer = context->description();
  nlohmann::json index = {{"format", "liftoff-synth3d-set"},
                          {"version", 1},
                          {"set", name},
                          {"renderer", summary.renderer},
                          {"clips", nlohmann::json::array()}};
  for (size_t i = 0; i < set.size(); ++i) {
    if (progress) progress(static_cast<int>(i), static_cast<int>(set.size()), set[i].id);
    auto written = WriteTrial3d(set[i], calibration, output_dir);
    if (!written.ok()) return written.status().WithContext(set[i].id);
    summary.frames += written->frames;
    summary.render_seconds += written->render_seconds;
    summary.encode_seconds += written->encode_seconds;
    index["clips"].push_back({{"id", set[i].id},
                              {"folder", set[i].id},
                              {"truth", set[i].id + "/truth.json"},
                              {"frames", written->frames},
                              {"render_s", written->render_seconds}});
    summary.trials.push_back(std::move(*written));
  }
  TrialManifest manifest;
  manifest.description = description.empty()
                             ? "liftoff synth set " + name + " (" + calibration.name + ")"
                             : description;
  if (!calibration.source_path.empty()) manifest.calibration_path = calibration.source_path;
  for (const WrittenTrial3d& trial : summary.trials) {
    if (trial.manifest_entry) manifest.trials.push_back(*trial.manifest_entry);
  }
  LIFTOFF_RETURN_IF_ERROR(WriteManifest(output_dir / "manifest.json", manifest));
  summary.wall_seconds = SecondsFromNs(MonotonicNowNs() - started_ns);
  index["frames"] = summary.frames;
  index["manifest"] = "manifest.json";
  LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(output_dir / "set.json", index.dump(1) + "\n"));
  return summary;
}

Status Set3dVariation::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(CheckRiseSlowdown(rise_slowdown));
  if (!(led_on_spread_s >= 0.0 && led_on_spread_s <= 10.0)) {
    return InvalidArgumentError("led_on_spread_s: expected 0 .. 10 s, got " +
                                FormatNumber(led_on_spread_s));
  }
  if (!(flicker_amplitude <= 0.5)) {
    return InvalidArgumentError(
        "flicker_amplitude: expected 0 .. 0.5 (negative: each clip's own), got " +
        FormatNumber(flicker_amplitude));
  }
  // (a readout longer than a clip's frame interval is that clip's error, naming it)
  if (!(flicker_readout_s <= 1.0)) {
    return InvalidArgumentError(
        "flicker_readout_s: expected 0 .. 1/fps s (negative: each clip's own), got " +
        FormatNumber(flicker_readout_s));
  }
  if (!(exposure_s <= 1.0) || exposure_s == 0.0) {
    return InvalidArgumentError(
        "exposure_s: expected 0 < e <= 1/fps s (negative: each clip's own), got " +
        FormatNumber(exposure_s));
  }
  if (!(led_radius_m <= 0.02) || (led_radius_m >= 0.0 && led_radius_m < 0.001)) {
    return InvalidArgumentError(
        "led_radius_m: expected 0.001 .. 0.02 m (negative: each clip's own), got " +
        FormatNumber(led_radius_m));
  }
  VideoWriterOptions writer;
  writer.keyframe_interval_frames = keyframe_interval_frames;
  return writer.Validate();
}

std::vector<Trial3dSpec> VarySet3d(std::vector<Trial3dSpec> set, const Set3dVariation& variation) {
  // a stream of its own, so that the clip's other draws stay as they were
  constexpr uint64_t kLedOnStream = 0x4C45444F4E5F5331ull;
  for (Trial3dSpec& spec : set) {
    spec.seed += variation.seed_offset;
    spec.scene.seed += variation.seed_offset;
    spec.rise_slowdown = variation.rise_slowdown;
    spec.keyframe_interval_frames = variation.keyframe_interval_frames;
    const double shift_s =
        variation.led_on_spread_s * SplitMix64(spec.seed ^ kLedOnStream).Uniform();
    spec.led_on_s += shift_s;
    spec.max_duration_s += shift_s;
    if (variation.flicker_amplitude >= 0) spec.flicker_amplitude = variation.flicker_amplitude;
    if (variation.flicker_readout_s >= 0) spec.flicker_readout_s = variation.flicker_readout_s;
    if (variation.exposure_s > 0) spec.exposure_s = variation.exposure_s;
    if (variation.led_radius_m >= 0) spec.scene.led_radius_m = variation.led_radius_m;
  }
  return set;
}

Result<Set3dSummary> WriteSet3d(const std::string& name, const std::filesystem::path& output_dir,
                                const Calibration& calibration, const Set3dProgress& progress,
                                const Set3dVariation& variation) {
  LIFTOFF_RETURN_IF_ERROR(variation.Validate());
  LIFTOFF_ASSIGN_OR_RETURN(std::vector<Trial3dSpec> named, Set3dNamed(name));
  const std::vector<Trial3dSpec> set = VarySet3d(std::move(named), variation);
  std::string varied;
  if (variation.seed_offset != 0) {
    varied += ", seeds offset by " + std::to_string(variation.seed_offset);
  }
  if (variation.rise_slowdown != 1.0) {
    varied += ", the feet rising " + FormatNumber(variation.rise_slowdown) + " times slower";
  }
  if (variation.keyframe_interval_frames != 0) {
    varied +=
        ", a key frame every " + std::to_string(variation.keyframe_interval_frames) + " frames";
  }
  if (variation.led_on_spread_s != 0.0) {
    varied += ", the LED switch-on up to " + FormatNumber(variation.led_on_spread_s) + " s later";
  }
  if (variation.flicker_amplitude >= 0) {
    varied += ", lamp flicker " + FormatNumber(variation.flicker_amplitude);
  }
  if (variation.flicker_readout_s >= 0) {
    varied += ", readout " + FormatNumber(1e3 * variation.flicker_readout_s) + " ms";
  }
  if (variation.exposure_s > 0) {
    varied += ", exposure " + FormatNumber(1e3 * variation.exposure_s) + " ms";
  }
  if (variation.led_radius_m >= 0) {
    varied += ", LED radius " + FormatNumber(1e3 * variation.led_radius_m) + " mm";
  }
  const std::string description =
      varied.empty() ? "" : "liftoff synth set " + name + " (" + calibration.name + ")" + varied;
  return WriteSpecs3d(name, set, output_dir, calibration, description, progress);
}

}  // namespace liftoff::synth
