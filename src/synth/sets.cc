#include "liftoff/synth/sets.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <system_error>
#include <thread>
#include <utility>

#include <nlohmann/json.hpp>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/synth/video_writer.h"

namespace liftoff::synth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The CI clips' height curve from a "simulation", written into the set's folder by
// WriteSet (a CSV curve needs a file).
constexpr const char* kCiCurveFile = "ci-height-curve.csv";

// Hardware liftoff rotations of the paper's Table IV (middle of each foot's range), and
// the rotation sense of Table II read by foot letter.
double PaperLiftoffRad(Foot foot) {
  switch (foot) {
    case Foot::kA: return 0.47;
    case Foot::kB: return 0.58;
    case Foot::kC: return 0.52;
    case Foot::kD: return 0.42;
  }
  return 0.45;
}
// Rotation at which a parametric curve reaches 1 mm, rad.
double OneMillimetreRad(const HeightCurveSpec& curve) {
  return curve.liftoff_rad + std::pow(0.001 / curve.gain_m, 1.0 / curve.exponent);
}

// Clip length that ends `margin_s` after the 1 mm instant, rounded up to 0.1 s.
double FitDuration(const TrialSpec& spec, double liftoff_1mm_rad, double margin_s) {
  const double liftoff_s = spec.led.on_video_s + spec.motion.ramp_start_s +
                           liftoff_1mm_rad / spec.motion.ramp_rate_rad_per_s;
  return std::ceil((liftoff_s + margin_s) * 10.0) / 10.0;
}

// The CI baseline: VGA, 60 fps, H.264, the LED on at 0.61 s (between two exposures),
// a 0.2 rad/s ramp from 0.2 s after it, every nuisance off but the shadow. Variations are
// made from this; the duration is fitted after them (Finish).
TrialSpec CiBaseline() {
  TrialSpec spec;
  spec.id = "ci-baseline";
  spec.seed = 1;
  spec.camera.width_px = 640;
  spec.camera.height_px = 480;
  spec.camera.fps = 60.0;
  spec.camera.exposure_s = 1.0 / 120.0;
  spec.camera.codec = VideoCodec::kH264;
  spec.camera.quality = 20;
  spec.led.on_video_s = 0.61;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.15;
  spec.motion.ramp_start_s = 0.2;
  spec.motion.ramp_rate_rad_per_s = 0.2;
  spec.log.lead_s = 0.5;
  spec.log.tail_s = 0.5;
  return spec;
}

TrialSpec CiTrial(int number, const std::string& what, Foot foot) {
  TrialSpec spec = CiBaseline();
  char id[16];
  std::snprintf(id, sizeof id, "ci-%02d-", number);
  spec.id = id + what;
  spec.seed = 1000 + static_cast<uint64_t>(number);
  spec.motion.foot = foot;
  spec.motion.rotation = PaperTableTwoMotion(foot).rotation;
  spec.motion.height.liftoff_rad = PaperLiftoffRad(foot);
  return spec;
}

// Ends the clip 0.4 s after the 1 mm instant (the video pipeline sees the foot rise).
TrialSpec Finish(TrialSpec spec) {
  double liftoff_1mm_rad = OneMillimetreRad(spec.motion.height);
  if (spec.motion.height.kind == "csv") liftoff_1mm_rad = 0.52;  // the CI curve's 1 mm point
  spec.duration_s = FitDuration(spec, liftoff_1mm_rad, 0.4);
  return spec;
}

// A simulation-like curve for foot C: a slight sag (negative, clamped to 0) while loaded,
// leaving the ground at 0.5 rad, then rising faster and faster.
std::string CiHeightCurveCsv() {
  std::string text =
      "# liftoff synth CI height curve: foot C, shaped like a simulated liftoff at 0.5 rad\n"
      "rotation_rad,C_height_m\n";
  for (int i = 0; i <= 80; ++i) {
    const double rotation_rad = 0.01 * i;
    const double above_rad = rotation_rad - 0.5;
    const double height_m =
        above_rad <= 0.0 ? -0.0003 * rotation_rad : 0.05 * above_rad + 0.5 * above_rad * above_rad;
    char row[64];
    std::snprintf(row, sizeof row, "%.2f,%.7f\n", rotation_rad, height_m);
    text += row;
  }
  return text;
}

// What writing one item of a set gave: a valid trial, or an invalid input's file.
struct ItemOutput {
  std::optional<WrittenTrial> trial;
  fs::path file;
  json index_entry;
  int64_t frames = 0;
  double render_seconds = 0.0, encode_seconds = 0.0;
};

Result<ItemOutput> WriteValidItem(const TrialSpec& spec, const Calibration& calibration,
                                  const fs::path& output_dir) {
  auto written = WriteTrial(spec, calibration, output_dir);
  if (!written.ok()) return written.status().WithContext(spec.id);
  ItemOutput item;
  item.frames = static_cast<int64_t>(written->truth.frame_times_ns.size());
  item.render_seconds = written->render_seconds;
  item.encode_seconds = written->encode_seconds;
  json spec_json = TrialSpecToJson(spec);
  if (spec.motion.height.kind == "csv") {
    spec_json["motion"]["height"]["csv"] = spec.motion.height.csv_path.filename().string();
  }
  item.index_entry = {{"id", spec.id},
                      {"video", written->video_path.filename().string()},
                      {"log", written->log_path.filename().string()},
                      {"truth_file", written->truth_path.filename().string()},
                      {"exercises", DescribeVariations(spec)},
                      {"truth", written->truth.ToJson()},
                      {"spec", spec_json}};
  item.trial = std::move(written).value();
  return item;
}

Result<ItemOutput> WriteInvalidItem(const InvalidInput& input, const Calibration& calibration,
                                    const fs::path& output_dir) {
  ItemOutput item;
  item.index_entry = {{"id", input.id},
                      {"expected_error", std::string(StatusCodeName(input.expected_error))},
                      {"what", input.what}};
  switch (input.kind) {
    case InvalidInput::Kind::kRendered: {
      auto written = WriteTrial(input.spec, calibration, output_dir);
      if (!written.ok()) return written.status().WithContext(input.id);
      item.frames = static_cast<int64_t>(written->truth.frame_times_ns.size());
      item.render_seconds = written->render_seconds;
      item.encode_seconds = written->encode_seconds;
      item.file = written->video_path;
      item.index_entry["log"] = written->log_path.filename().string();
      item.index_entry["truth_file"] = written->truth_path.filename().string();
      item.index_entry["truth"] = written->truth.ToJson();
      break;
    }
    case InvalidInput::Kind::kTruncated: {
      // rendered whole in a scratch folder; only the cut copy stays
      const fs::path scratch = output_dir / (input.id + ".whole");
      auto written = WriteTrial(input.spec, calibration, scratch);
      if (!written.ok()) return written.status().WithContext(input.id);
      item.frames = static_cast<int64_t>(written->truth.frame_times_ns.size());
      item.render_seconds = written->render_seconds;
      item.encode_seconds = written->encode_seconds;
      item.file = output_dir / written->video_path.filename();
      LIFTOFF_RETURN_IF_ERROR(
          WriteTruncatedCopy(written->video_path, item.file, input.keep_fraction)
              .WithContext(input.id));
      std::error_code ignored;
      fs::remove_all(scratch, ignored);
      item.index_entry["keep_fraction"] = input.keep_fraction;
      break;
    }
    case InvalidInput::Kind::kNotAVideo:
      item.file = output_dir / (input.id + ".mp4");
      LIFTOFF_RETURN_IF_ERROR(WriteNotAVideo(item.file).WithContext(input.id));
      break;
  }
  item.index_entry["file"] = item.file.filename().string();
  return item;
}

}  // namespace

// Long on purpose: a table of the set's clips, one block each, read top to bottom like
// docs/synth.md's list of them.
std::vector<TrialSpec> CiSet() {
  std::vector<TrialSpec> set;
  const auto add = [&](TrialSpec spec) { set.push_back(Finish(std::move(spec))); };

  // codecs and the four feet, both senses (Table II pairs)
  {
    TrialSpec spec = CiTrial(1, "baseline-ffv1", Foot::kA);
    spec.camera.codec = VideoCodec::kFfv1;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(2, "h264-bframes-30fps", Foot::kB);
    spec.camera.quality = 23;
    spec.camera.fps = 30.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(3, "mjpeg", Foot::kC);
    spec.camera.codec = VideoCodec::kMjpeg;
    spec.camera.quality = 5;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(4, "foot-d-30fps", Foot::kD);
    spec.camera.fps = 30.0;
    spec.camera.exposure_s = 1.0 / 60.0;
    // 60 % into frame 18's exposure, centred on 0.6 s: [0.6 - 1/120, 0.6 + 1/120)
    spec.led.on_video_s = 0.6 + 0.1 / 60.0;
    add(spec);
  }
  // resolutions: 720p, and one short 1080p clip (a faster ramp, an earlier liftoff)
  {
    TrialSpec spec = CiTrial(5, "720p", Foot::kA);
    spec.camera.width_px = 1280;
    spec.camera.height_px = 720;
    spec.camera.fps = 30.0;
    spec.nuisance.noise_sigma = 2.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(6, "1080p-short", Foot::kC);
    spec.camera.width_px = 1920;
    spec.camera.height_px = 1080;
    spec.camera.fps = 30.0;
    spec.motion.ramp_rate_rad_per_s = 0.5;
    spec.motion.height.liftoff_rad = 0.3;
    add(spec);
  }
  // frame rates and exposure: 120 fps with a short exposure the LED switches on inside,
  // 240 fps, a full-frame exposure that gives a partial LED frame
  {
    TrialSpec spec = CiTrial(7, "120fps-short-exposure", Foot::kB);
    spec.camera.fps = 120.0;
    spec.camera.exposure_s = 0.001;
    spec.led.on_video_s = 0.6 - 0.0001;  // 0.4 ms into frame 72's [0.5995, 0.6005) s
    spec.motion.ramp_rate_rad_per_s = 0.3;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(8, "240fps", Foot::kD);
    spec.camera.fps = 240.0;
    spec.camera.exposure_s = 1.0 / 480.0;
    // 80 % into frame 146's exposure (timestamp 146/240 s, the middle of it)
    spec.led.on_video_s = 146.0 / 240.0 + 0.3 / 480.0;
    spec.motion.ramp_rate_rad_per_s = 0.4;
    spec.motion.height.liftoff_rad = 0.3;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(9, "long-exposure-partial-led-ffv1", Foot::kC);
    spec.camera.codec = VideoCodec::kFfv1;
    spec.camera.fps = 30.0;
    spec.camera.exposure_s = 1.0 / 30.0;
    // 60 % into frame 18's exposure, centred on 0.6 s: [0.6 - 1/60, 0.6 + 1/60)
    spec.led.on_video_s = 0.6 + 0.1 / 30.0;
    add(spec);
  }
  // variable frame rate
  {
    TrialSpec spec = CiTrial(10, "vfr-drops", Foot::kA);
    spec.camera.drop_probability = 0.15;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(11, "vfr-jitter", Foot::kB);
    spec.camera.timestamp_jitter_s = 0.35 / 60.0;
    spec.camera.drop_probability = 0.05;
    add(spec);
  }
  // image nuisances
  {
    TrialSpec spec = CiTrial(12, "noise-mjpeg", Foot::kD);
    spec.camera.codec = VideoCodec::kMjpeg;
    spec.camera.quality = 8;
    spec.nuisance.noise_sigma = 10.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(13, "motion-blur", Foot::kA);
    spec.camera.exposure_s = 1.0 / 60.0;
    spec.nuisance.motion_blur_samples = 8;
    spec.motion.ramp_rate_rad_per_s = 0.4;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(14, "flicker-50hz-mjpeg", Foot::kB);
    spec.camera.codec = VideoCodec::kMjpeg;
    spec.camera.quality = 4;
    spec.nuisance.flicker_amplitude = 0.15;
    spec.nuisance.flicker_hz = 100.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(15, "flicker-60hz-120fps", Foot::kC);
    spec.camera.fps = 120.0;
    spec.camera.exposure_s = 1.0 / 500.0;
    spec.nuisance.flicker_amplitude = 0.25;
    spec.nuisance.flicker_hz = 120.0;
    spec.motion.ramp_rate_rad_per_s = 0.4;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(16, "shake", Foot::kD);
    spec.nuisance.shake_px = 1.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(17, "no-shadow", Foot::kA);
    spec.nuisance.shadow = false;
    add(spec);
  }
  // the LED: colour, size, saturation and bloom, position
  {
    TrialSpec spec = CiTrial(18, "led-green-small-dim", Foot::kB);
    spec.led.blue = 40;
    spec.led.green = 255;
    spec.led.red = 40;
    spec.led.radius_px = 2.5;
    spec.led.intensity = 0.6;
    spec.led.bloom = 0.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(19, "led-blue-large-bloom", Foot::kC);
    spec.led.blue = 255;
    spec.led.green = 80;
    spec.led.red = 20;
    spec.led.radius_px = 14.0;
    spec.led.intensity = 4.0;
    spec.led.bloom = 5.0;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(20, "led-white-saturated-corner", Foot::kD);
    spec.led.blue = 255;
    spec.led.green = 255;
    spec.led.red = 255;
    spec.led.x_frac = 0.08;
    spec.led.y_frac = 0.88;
    spec.led.intensity = 2.5;
    spec.led.bloom = 3.0;
    add(spec);
  }
  // the motion: diagonal partner rising, a simulated (CSV) curve
  {
    TrialSpec spec = CiTrial(21, "diagonal-foot", Foot::kA);
    spec.motion.diagonal_lag_rad = 0.03;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(22, "csv-curve", Foot::kC);
    spec.motion.height.kind = "csv";
    spec.motion.height.csv_path = kCiCurveFile;
    add(spec);
  }
  // the log: 2018 style (bursts, origin at the LED, no event), and a modern controller
  // (LED event at a non-zero time, drift, jitter, 200 Hz)
  {
    TrialSpec spec = CiTrial(23, "log-2018-bursty-origin", Foot::kB);
    spec.log.led_event = false;
    spec.log.led_on_device_ns = 0;
    spec.log.burst_period_s = 1.0;
    spec.log.burst_length_s = 0.17;
    add(spec);
  }
  {
    TrialSpec spec = CiTrial(24, "log-event-drift-jitter", Foot::kD);
    spec.log.led_on_device_ns = 1'234'567'890'123;
    spec.log.clock_drift_ppm = 250.0;
    spec.log.rate_hz = 200.0;
    spec.log.jitter_s = 0.002;
    add(spec);
  }
  return set;
}

std::vector<InvalidInput> CiInvalidInputs() {
  std::vector<InvalidInput> inputs;
  {
    InvalidInput input;
    input.id = "invalid-led-never-on";
    input.kind = InvalidInput::Kind::kRendered;
    input.expected_error = StatusCode::kNotFound;
    input.what = "the LED never switches on (it was on before the recording began)";
    input.spec = CiTrial(0, "", Foot::kA);
    input.spec.led.on_video_s = -1.0;
    input.spec = Finish(input.spec);
    input.spec.duration_s = std::max(input.spec.duration_s, 2.0);
    inputs.push_back(input);
  }
  {
    InvalidInput input;
    input.id = "invalid-foot-never-lifts";
    input.kind = InvalidInput::Kind::kRendered;
    input.expected_error = StatusCode::kNotFound;
    input.what = "the foot never lifts (the clip ends at 0.06 rad)";
    input.spec = CiTrial(0, "", Foot::kB);
    input.spec.motion.ramp_rate_rad_per_s = 0.05;
    input.spec.duration_s = 2.0;
    inputs.push_back(input);
  }
  {
    InvalidInput input;
    input.id = "invalid-truncated";
    input.kind = InvalidInput::Kind::kTruncated;
    input.expected_error = StatusCode::kParse;
    input.what = "an H.264 MP4 cut after half its bytes (the index lists frames the file lacks)";
    input.spec = Finish(CiTrial(0, "", Foot::kC));
    input.spec.camera.codec = VideoCodec::kH264;
    input.keep_fraction = 0.5;
    inputs.push_back(input);
  }
  {
    InvalidInput input;
    input.id = "invalid-not-a-video";
    input.kind = InvalidInput::Kind::kNotAVideo;
    input.expected_error = StatusCode::kParse;
    input.what = "a text file named like a video";
    inputs.push_back(input);
  }
  for (InvalidInput& input : inputs) {
    input.spec.id = input.id;
    input.spec.seed = 2000 + static_cast<uint64_t>(&input - inputs.data());
  }
  return inputs;
}

std::vector<std::string> DescribeVariations(const TrialSpec& spec) {
  const TrialSpec base = CiBaseline();
  std::vector<std::string> tags;
  const CameraSpec& camera = spec.camera;
  tags.push_back("foot-" + std::string(FootName(spec.motion.foot)) +
                 std::string(RotationSenseName(spec.motion.rotation)));
  if (camera.width_px != base.camera.width_px || camera.height_px != base.camera.height_px) {
    tags.push_back(std::to_string(camera.width_px) + "x" + std::to_string(camera.height_px));
  }
  if (camera.fps != base.camera.fps) tags.push_back(FormatFixed(camera.fps, 0) + "fps");
  if (camera.codec != base.camera.codec) tags.push_back(std::string(VideoCodecName(camera.codec)));
  const double exposure_frames = camera.exposure_s * camera.fps;
  if (exposure_frames > 0.99) tags.push_back("exposure-full-frame");
  if (exposure_frames < 0.25) tags.push_back("exposure-short");
  if (camera.drop_probability > 0) tags.push_back("vfr-drops");
  if (camera.timestamp_jitter_s > 0) tags.push_back("vfr-jitter");
  GroundTruth led;
  FillLedTruth(spec, FrameScheduleNs(spec), led);
  if (led.led_first_frame && led.led_first_frame_fraction < 1.0)
    tags.push_back("partial-led-frame");

  const NuisanceSpec& nuisance = spec.nuisance;
  if (nuisance.noise_sigma > 0) tags.push_back("noise");
  if (nuisance.motion_blur_samples > 1) tags.push_back("motion-blur");
  if (nuisance.flicker_amplitude > 0) {
    tags.push_back(nuisance.flicker_hz == 100.0 ? "flicker-50hz-mains" : "flicker-60hz-mains");
  }
  if (nuisance.shake_px > 0) tags.push_back("shake");
  if (!nuisance.shadow) tags.push_back("no-shadow");

  const LedSpec& led_spec = spec.led;
  if (led_spec.blue != base.led.blue || led_spec.green != base.led.green ||
      led_spec.red != base.led.red) {
    tags.push_back("led-colour");
  }
  if (led_spec.radius_px != base.led.radius_px) tags.push_back("led-size");
  if (led_spec.intensity != base.led.intensity) {
    tags.push_back(led_spec.intensity > 1.0 ? "led-intensity-saturated" : "led-intensity-dim");
  }
  if (led_spec.bloom != base.led.bloom) tags.push_back("led-bloom");
  if (led_spec.x_frac != base.led.x_frac || led_spec.y_frac != base.led.y_frac) {
    tags.push_back("led-position");
  }

  const MotionSpec& motion = spec.motion;
  if (motion.height.kind == "csv") tags.push_back("csv-height-curve");
  if (motion.diagonal_lag_rad > 0) tags.push_back("diagonal-foot");
  if (motion.ramp_rate_rad_per_s != base.motion.ramp_rate_rad_per_s) tags.push_back("ramp-rate");

  const LogSpec& log = spec.log;
  if (log.burst_period_s > 0) tags.push_back("bursty-log");
  if (!log.led_event) tags.push_back("log-origin-at-led");
  if (log.led_event && log.led_on_device_ns != 0) tags.push_back("log-led-event-offset");
  if (log.clock_drift_ppm != 0) tags.push_back("clock-drift");
  if (log.jitter_s > 0) tags.push_back("log-jitter");
  if (log.rate_hz != base.log.rate_hz) tags.push_back("log-rate");
  return tags;
}

Result<std::vector<TrialSpec>> SetByName(std::string_view name) {
  if (name == "ci") return CiSet();
  if (name == "paper") {
    // the paper's test at full length, one trial per foot, 720p H.264
    std::vector<TrialSpec> set;
    for (const Foot foot : kAllFeet) {
      TrialSpec spec;
      spec.id = "paper-" + std::string(FootName(foot));
      spec.seed = 100 + static_cast<uint64_t>(foot);
      spec.camera.codec = VideoCodec::kH264;
      spec.motion.foot = foot;
      spec.motion.rotation = PaperTableTwoMotion(foot).rotation;
      spec.motion.height.liftoff_rad = PaperLiftoffRad(foot);
      spec.duration_s = FitDuration(spec, OneMillimetreRad(spec.motion.height), 1.0);
      set.push_back(spec);
    }
    return set;
  }
  return NotFoundError("synth set \"" + std::string(name) + "\": expected one of ci, paper");
}

std::string SetSummary::Brief() const {
  const double frames_d = static_cast<double>(std::max<int64_t>(frames, 1));
  std::string text = name + ": " + std::to_string(trials.size()) + " trials";
  if (!invalid_paths.empty())
    text += " + " + std::to_string(invalid_paths.size()) + " invalid inputs";
  text += ", " + std::to_string(frames) + " frames in " + FormatFixed(wall_seconds, 1) +
          " s (render " + FormatFixed(1e3 * render_seconds / frames_d, 2) + " ms/frame, encode " +
          FormatFixed(1e3 * encode_seconds / frames_d, 2) + " ms/frame)";
  return text;
}

namespace {

// Support files: the CSV height curve the CI set's csv trial reads, written once into
// `output_dir` when a spec reads it, and those specs pointed at it.
Status WriteSupportFiles(const fs::path& output_dir, std::vector<TrialSpec>& specs) {
  bool curve_written = false;
  for (TrialSpec& spec : specs) {
    if (spec.motion.height.kind != "csv" || spec.motion.height.csv_path != kCiCurveFile) continue;
    if (!curve_written) {
      LIFTOFF_RETURN_IF_ERROR(WriteFileAtomically(output_dir / kCiCurveFile, CiHeightCurveCsv()));
      curve_written = true;
    }
    spec.motion.height.csv_path = output_dir / kCiCurveFile;
  }
  return Status::Ok();
}

}  // namespace

Result<SetSummary> WriteSet(std::string_view name, const Calibration& calibration,
                            const fs::path& output_dir,
                            const std::function<void(const SetProgress&)>& progress) {
  const int64_t started_ns = MonotonicNowNs();
  LIFTOFF_ASSIGN_OR_RETURN(std::vector<TrialSpec> specs, SetByName(name));
  const std::vector<InvalidInput> invalid =
      name == "ci" ? CiInvalidInputs() : std::vector<InvalidInput>{};
  std::error_code error;
  fs::create_directories(output_dir, error);
  if (error) return IoError(output_dir.string() + ": cannot create the folder: " + error.message());

  LIFTOFF_RETURN_IF_ERROR(WriteSupportFiles(output_dir, specs));

  // every item on up to two workers; each item's files depend on nothing but the item
  const size_t count = specs.size() + invalid.size();
  std::vector<std::optional<Result<ItemOutput>>> outputs(count);
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex progress_mutex;
  const auto work = [&] {
    for (size_t i = next++; i < count && !failed; i = next++) {
      const std::string& id = i < specs.size() ? specs[i].id : invalid[i - specs.size()].id;
      if (progress) {
        const std::lock_guard<std::mutex> lock(progress_mutex);
        progress(SetProgress{static_cast<int>(i), static_cast<int>(count), id});
      }
      outputs[i] = i < specs.size()
                       ? WriteValidItem(specs[i], calibration, output_dir)
                       : WriteInvalidItem(invalid[i - specs.size()], calibration, output_dir);
      if (!outputs[i]->ok()) failed = true;
    }
  };
  const unsigned workers = std::clamp(std::thread::hardware_concurrency(), 1u, 2u);
  std::vector<std::thread> threads;
  for (unsigned w = 1; w < workers; ++w) threads.emplace_back(work);
  work();
  for (std::thread& thread : threads) thread.join();

  // gather in set order; the first failure in that order is the answer
  SetSummary summary;
  summary.name = std::string(name);
  summary.output_dir = output_dir;
  TrialManifest manifest;
  manifest.description = "liftoff synth set " + summary.name + " (" + calibration.name + ")";
  if (!calibration.source_path.empty()) manifest.calibration_path = calibration.source_path;
  json index_trials = json::array(), index_invalid = json::array();
  for (size_t i = 0; i < count; ++i) {
    if (!outputs[i]) continue;
    if (!outputs[i]->ok()) return outputs[i]->status();
    ItemOutput& item = outputs[i]->value();
    summary.frames += item.frames;
    summary.render_seconds += item.render_seconds;
    summary.encode_seconds += item.encode_seconds;
    if (item.trial) {
      manifest.trials.push_back(item.trial->manifest_entry);
      index_trials.push_back(std::move(item.index_entry));
      summary.trials.push_back(std::move(*item.trial));
    } else {
      summary.invalid_paths.push_back(item.file);
      index_invalid.push_back(std::move(item.index_entry));
    }
  }

  // the manifest of the valid trials and the index of everything
  summary.manifest_path = output_dir / "manifest.json";
  summary.index_path = output_dir / "set.json";
  LIFTOFF_RETURN_IF_ERROR(WriteManifest(summary.manifest_path, manifest));
  const json index = {{"format", "liftoff-synth-set"}, {"version", 1},
                      {"name", summary.name},          {"calibration", calibration.name},
                      {"manifest", "manifest.json"},   {"trials", index_trials},
                      {"invalid", index_invalid}};
  LIFTOFF_RETURN_IF_ERROR(WriteJsonFile(summary.index_path, index));
  summary.wall_seconds = SecondsFromNs(MonotonicNowNs() - started_ns);
  return summary;
}

}  // namespace liftoff::synth
