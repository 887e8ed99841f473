// Synthetic trials: the specification of one rendered foot-lifting trial (camera,
// nuisances, robot motion, controller log) and the exact ground truth it implies.
//
// Three clocks, all int64 ns:
//   video clock   t_video_ns   from the first frame's exposure start (frame 0 at ~0)
//   device clock  t_device_ns  the controller's; the LED switches on at led_on_device_ns
//   test clock    seconds since the LED switched on (the test's own timeline, `_s`)
// device_from_video maps the video's LED-on instant to the log's, with optional drift.
// The physical story on the test clock: bend from bend_start_s to bend_end_s, then the
// rotating vertebra ramps at ramp_rate_rad_per_s from ramp_start_s; the chosen foot's
// height above its rest is a function of |rotation| (a parametric curve or a simulated
// curve from CSV); it leaves the ground at the first instant its height exceeds 0.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/manifest.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/core/time.h"

namespace liftoff::synth {

/// Video containers and codecs the writer produces.
enum class VideoCodec {
  kH264,   ///< libx264 in MP4, B-frames on (the quirk video analysis must survive)
  kMjpeg,  ///< Motion JPEG in AVI
  kFfv1,   ///< lossless FFV1 in Matroska (exact pixels: used by truth-checking tests)
};
std::string_view VideoCodecName(VideoCodec codec);  ///< "h264", "mjpeg", "ffv1"
std::optional<VideoCodec> ParseVideoCodec(std::string_view text);
/// File extension with the dot: ".mp4", ".avi", ".mkv".
std::string_view VideoCodecExtension(VideoCodec codec);

/// The camera and its frame timing.
struct CameraSpec {
  int width_px = 1280;   ///< 320 .. 1920
  int height_px = 720;   ///< 240 .. 1080
  double fps = 60.0;     ///< nominal frame rate: 30, 60, 120 or 240 (any in 1 .. 1000)
  /// Exposure time per frame, s (0 < exposure <= 1/fps). A frame integrates the scene
  /// over [t_frame, t_frame + exposure): an LED switching on mid-exposure gives a
  /// partial-brightness frame.
  double exposure_s = 1.0 / 120.0;
  /// Variable frame rate: probability that a frame is dropped (its slot is skipped, so
  /// timestamps jump), 0 .. 0.5.
  double drop_probability = 0.0;
  /// Variable frame rate: each frame's timestamp is moved by a uniform random offset of
  /// up to this much, s (0 .. 0.4 / fps). Timestamps stay increasing.
  double timestamp_jitter_s = 0.0;
  VideoCodec codec = VideoCodec::kFfv1;
  /// Encoder quality: CRF for H.264 (0 .. 51), q:v for MJPEG (2 .. 31); unused by FFV1.
  int quality = 20;
};

/// Image nuisances, each off at its default.
struct NuisanceSpec {
  /// Gaussian sensor noise, standard deviation in 8-bit grey levels (0 .. 30).
  double noise_sigma = 0.0;
  /// Motion blur: scene sub-samples integrated over the exposure (1 = none, up to 16).
  int motion_blur_samples = 1;
  /// Illumination flicker of mains lighting: relative amplitude (0 .. 0.5) at
  /// flicker_hz (100 or 120 for 50/60 Hz mains, brightness at twice the mains frequency).
  double flicker_amplitude = 0.0;
  double flicker_hz = 100.0;
  /// Camera shake: random-walk translation, standard deviation of its step per frame,
  /// px (0 .. 2), bounded to +-4 px.
  double shake_px = 0.0;
  /// Shadow under a lifted foot (a soft dark ellipse on the bed that shrinks and fades
  /// as the foot rises).
  bool shadow = true;
};

/// The sync LED.
struct LedSpec {
  /// Centre in the image, fractions of width and height (0..1).
  double x_frac = 0.9;
  double y_frac = 0.12;
  /// Radius of the lit disc, px (1 .. 40).
  double radius_px = 6.0;
  /// Colour when on, BGR 0..255.
  int blue = 40, green = 40, red = 255;
  /// Peak brightness when on, relative (0.1 .. 4); above 1 saturates the sensor.
  double intensity = 1.5;
  /// Glow around the disc: Gaussian halo radius as a multiple of radius_px (0 .. 6).
  double bloom = 2.0;
  /// When it switches on, video clock, s. Negative or beyond the clip: never on (an
  /// invalid input for the video pipeline's error tests).
  double on_video_s = 1.0;
};

/// The foot's height curve against the absolute rotation of the centre vertebra.
struct HeightCurveSpec {
  /// "parametric": height = gain * (|theta| - liftoff_rad)^exponent above liftoff_rad;
  /// "csv": columns rotation_rad and <foot>_height_m from a simulation (liftoff sim).
  std::string kind = "parametric";
  /// Parametric: absolute rotation at which the foot leaves the ground, rad.
  double liftoff_rad = 0.45;
  /// Parametric: m per rad^exponent.
  double gain_m = 0.25;
  double exponent = 1.5;
  /// CSV: path (relative to the spec file) and the foot column to read.
  std::filesystem::path csv_path;
};

/// The robot and the test.
struct MotionSpec {
  /// Foot that lifts.
  Foot foot = Foot::kA;
  /// Rotation direction (sign of the commanded angle).
  RotationSense rotation = RotationSense::kPositive;
  HeightCurveSpec height;
  /// Test clock (s since LED on): bend phase and ramp.
  double bend_start_s = 0.5;
  double bend_end_s = 3.5;
  double ramp_start_s = 4.0;
  /// Ramp rate of the rotating vertebra, rad/s (the paper: (pi/3)/40).
  double ramp_rate_rad_per_s = 0.026179938779914945;
  /// The diagonal partner of the lifting foot rises too, this much later in rotation,
  /// rad (<= 0: it stays down).
  double diagonal_lag_rad = 0.0;
};

/// The matching controller log.
struct LogSpec {
  /// Device clock at the LED switch-on, ns (the 2018 firmware: 0; a modern controller
  /// logs an led_on event at some non-zero time).
  int64_t led_on_device_ns = 0;
  /// Device clock rate error against the video clock, parts per million.
  double clock_drift_ppm = 0.0;
  /// Sample rate, Hz, and uniform timing jitter of each sample, s.
  double rate_hz = 100.0;
  double jitter_s = 0.0;
  /// Bursty like the 2018 logs: samples only in bursts of burst_length_s every
  /// burst_period_s (0: continuous).
  double burst_period_s = 0.0;
  double burst_length_s = 0.06;
  /// Write an explicit led_on event (otherwise the origin is the LED switch-on).
  bool led_event = true;
  /// Seconds of log before the LED switches on and after the clip ends.
  double lead_s = 0.5;
  double tail_s = 1.0;
};

/// One synthetic trial.
struct TrialSpec {
  /// Id used for file names and the manifest ("ci-003-h264").
  std::string id = "synthetic";
  /// Seed of every random draw (noise, shake, drops, jitter, texture).
  uint64_t seed = 1;
  /// Clip length, s. The default holds the paper's test: LED at 1 s, ramp from 5 s,
  /// liftoff at 0.45 rad near 22 s. Short CI clips use a faster ramp instead.
  double duration_s = 24.0;
  CameraSpec camera;
  NuisanceSpec nuisance;
  LedSpec led;
  MotionSpec motion;
  LogSpec log;

  /// Every field in range; messages name the field ("camera.fps: expected ...").
  Status Validate() const;
};

/// Reads a trial spec from JSON (all fields optional, defaults above; unknown keys are
/// errors naming the JSON pointer). `base_dir` resolves height.csv_path.
Result<TrialSpec> TrialSpecFromJson(const nlohmann::json& document, const std::string& source,
                                    const std::filesystem::path& base_dir);
nlohmann::json TrialSpecToJson(const TrialSpec& spec);

/// The exact answer for one rendered trial.
struct GroundTruth {
  std::string trial_id;
  Foot foot = Foot::kA;
  /// Video clock: LED switch-on (nullopt when it never switches on within the clip).
  std::optional<int64_t> led_on_video_ns;
  /// Index of the first frame whose exposure sees the LED on, and the fraction of that
  /// frame's exposure during which it was on (1 when the switch-on fell between frames).
  std::optional<int64_t> led_first_frame;
  double led_first_frame_fraction = 0.0;
  /// Video clock: first instant the foot's height exceeds 0 m and 0.001 m (nullopt when
  /// the foot does not lift within the clip).
  std::optional<int64_t> liftoff_0mm_video_ns;
  std::optional<int64_t> liftoff_1mm_video_ns;
  /// Absolute vertebra rotation at those instants, rad.
  std::optional<double> liftoff_0mm_rad;
  std::optional<double> liftoff_1mm_rad;
  /// Presentation time of every frame written, video clock, ns (strictly increasing).
  std::vector<int64_t> frame_times_ns;
  /// Image scale at the lifting foot, px per mm.
  double px_per_mm = 0.0;
  /// Regions of interest, video pixels.
  RegionPx led_roi_px;
  RegionPx foot_roi_px;
  /// Pixel row of the foot's bottom edge at rest (subpixel), for tests.
  double foot_rest_bottom_px = 0.0;

  nlohmann::json ToJson() const;
};
Result<GroundTruth> GroundTruthFromJson(const nlohmann::json& document, const std::string& source);

/// The trial's motion as functions of the clocks: what the renderer draws and the log
/// generator samples. Pure and cheap; built once per trial.
class Timeline {
 public:
  /// Loads the height curve (CSV when asked) and fixes the ramp offset.
  static Result<Timeline> Create(const TrialSpec& spec);

  /// Test clock (s since LED on) of a video instant.
  double TestSecondsFromVideoNs(int64_t t_video_ns) const;
  /// Device clock of a video instant (the log's clock).
  int64_t DeviceNsFromVideoNs(int64_t t_video_ns) const;
  /// Video instant of a device-clock instant.
  int64_t VideoNsFromDeviceNs(int64_t t_device_ns) const;

  /// Signed vertebra angle at a test-clock second, rad.
  double VertebraRadAt(double test_s) const;
  /// Bending spool angle at a test-clock second, rad (0 before the bend).
  double BendSpoolRadAt(double test_s, double target_spool_rad) const;
  /// Height of `foot` above its rest at a video instant, m (>= 0).
  double FootHeightMAt(Foot foot, int64_t t_video_ns) const;
  /// Whether the LED is on at a video instant.
  bool LedOnAt(int64_t t_video_ns) const;

  /// First video instant at which the lifting foot's height exceeds `height_m`
  /// (nullopt when not within [0, duration]); exact to 1 ns.
  std::optional<int64_t> FirstVideoNsAbove(double height_m) const;

  const TrialSpec& spec() const { return spec_; }

 private:
  TrialSpec spec_;
  std::vector<double> curve_rotation_rad_, curve_height_m_;  // CSV curve, when used
  double HeightAtRotation(double abs_rotation_rad, bool diagonal) const;
};

}  // namespace liftoff::synth
