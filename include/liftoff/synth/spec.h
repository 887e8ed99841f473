// Synthetic trials: the specification of one rendered foot-lifting trial (camera,
// nuisances, robot motion, controller log) and the exact ground truth it implies.
//
// Three clocks, all int64 ns:
//   video clock   t_video_ns   frame timestamps (frame 0 at ~0); a frame's timestamp is the
//                              middle of its exposure
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
  int width_px = 1280;  ///< 320 .. 1920, even (4:2:0 chroma)
  int height_px = 720;  ///< 240 .. 1080, even
  double fps = 60.0;    ///< nominal frame rate: 30, 60, 120 or 240 (any in 1 .. 1000)
  /// Exposure time per frame, s (0 < exposure <= 1/fps). A frame with timestamp t_frame
  /// integrates the scene over [t_frame - exposure / 2, t_frame + exposure / 2) (the
  /// timestamp is the middle of the exposure): an LED switching on mid-exposure gives a
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
  /// Shadows under the feet: a soft dark ellipse on the bed under each foot, resting or
  /// not, that shrinks and fades as the foot rises (false: no foot casts one).
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
  /// Parametric: absolute rotation at which the foot leaves the ground, rad (0 .. pi).
  double liftoff_rad = 0.45;
  /// Parametric: m per rad^exponent (0 < gain <= 10).
  double gain_m = 0.25;
  /// Parametric: 0 < exponent <= 5.
  double exponent = 1.5;
  /// CSV: path (JSON "csv", relative to the spec file; required when kind is "csv").
  /// The file: optional '#' comment lines, a header line naming at least the columns
  /// "rotation_rad" and "<F>_height_m" for the lifting foot F ("A_height_m"), then one
  /// row per rotation, comma-separated, at least two rows, |rotation_rad| strictly
  /// increasing (a simulation of either sense). Heights are interpolated linearly in
  /// |rotation|, held at the end rows beyond them, and clamped to >= 0.
  std::filesystem::path csv_path;
};

/// The robot and the test.
struct MotionSpec {
  /// Foot that lifts.
  Foot foot = Foot::kA;
  /// Rotation direction (sign of the commanded angle).
  RotationSense rotation = RotationSense::kPositive;
  HeightCurveSpec height;
  /// Test clock (s since LED on): bend phase and ramp (0 <= bend_start_s <= bend_end_s,
  /// all in [0, 3600]; ramp_start_s in [0, 3600]).
  double bend_start_s = 0.5;
  double bend_end_s = 3.5;
  double ramp_start_s = 4.0;
  /// Ramp rate of the rotating vertebra, rad/s (the paper: (pi/3)/40), in (0, 10].
  double ramp_rate_rad_per_s = 0.026179938779914945;
  /// The diagonal partner of the lifting foot (A<->D, B<->C) rises too, this much later
  /// in rotation, rad (<= 0: it stays down), in [-pi, pi].
  double diagonal_lag_rad = 0.0;
};

/// The matching controller log.
struct LogSpec {
  /// Device clock at the LED switch-on, ns (the 2018 firmware: 0; a modern controller
  /// logs an led_on event at some non-zero time), 0 .. 10^15 (about 11 days).
  int64_t led_on_device_ns = 0;
  /// Device clock rate error against the video clock, parts per million (-1000 .. 1000).
  double clock_drift_ppm = 0.0;
  /// Sample rate, Hz (1 .. 10000), and uniform timing jitter of each sample, s
  /// (0 .. 0.5 / rate_hz, so samples stay in order).
  double rate_hz = 100.0;
  double jitter_s = 0.0;
  /// Bursty like the 2018 logs: samples only in bursts of burst_length_s every
  /// burst_period_s (0: continuous; otherwise 0 < burst_length_s <= burst_period_s <= 60).
  double burst_period_s = 0.0;
  double burst_length_s = 0.06;
  /// Write an explicit led_on event (otherwise the origin is the LED switch-on).
  bool led_event = true;
  /// Seconds of log before the LED switches on and after the clip ends (0 .. 60 each).
  double lead_s = 0.5;
  double tail_s = 1.0;
};

/// One synthetic trial.
struct TrialSpec {
  /// Id used for file names and the manifest ("ci-003-h264"): 1 .. 100 of A-Z a-z 0-9
  /// '.' '_' '-', not starting with '.'.
  std::string id = "synthetic";
  /// Seed of every random draw (noise, shake, drops, jitter, texture).
  uint64_t seed = 1;
  /// Clip length, s. The default holds the paper's test: LED at 1 s, ramp from 5 s,
  /// liftoff at 0.45 rad near 22 s. Short CI clips use a faster ramp instead. (0, 3600].
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
/// errors naming the JSON pointer). `base_dir` resolves height.csv_path. The document
/// mirrors the struct, except that the LED colour is "color_bgr": [b, g, r] and the CSV
/// path is "csv"; enums are strings ("codec": "ffv1", "foot": "A", "rotation": "+").
///   {"id": "ci-001", "seed": 7, "duration_s": 3,
///    "camera": {"width_px": 320, "height_px": 240, "fps": 60, "codec": "h264", ...},
///    "nuisance": {"noise_sigma": 2, ...}, "led": {"color_bgr": [40, 40, 255], ...},
///    "motion": {"foot": "A", "rotation": "+", "height": {"kind": "csv", "csv": "c.csv"}},
///    "log": {"clock_drift_ppm": 50, ...}}
/// Errors name the source and the JSON pointer: "t.json: /camera/fps: expected a number
/// in [1, 1000], got 0" (kInvalidArgument for values, as JsonReader for types and keys).
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

  /// The truth file. Instants are written twice, as integer ns (exact, what programs read)
  /// and as seconds (for people; ignored on reading unless they disagree by more than
  /// 1 us); absent values are null:
  ///   {"format": "liftoff-synth-truth", "version": 1, "trial_id": "ci-001", "foot": "A",
  ///    "led_on_video_ns": 1000000000, "led_on_video_s": 1.0,
  ///    "led_first_frame": 60, "led_first_frame_fraction": 1.0,
  ///    "liftoff_0mm_video_ns": ..., "liftoff_0mm_video_s": ..., "liftoff_0mm_rad": 0.45,
  ///    "liftoff_1mm_video_ns": ..., "liftoff_1mm_video_s": ..., "liftoff_1mm_rad": ...,
  ///    "px_per_mm": 1.2, "foot_rest_bottom_px": 200.5,
  ///    "led_roi_px": {"x_px", "y_px", "width_px", "height_px"}, "foot_roi_px": {...},
  ///    "frame_count": 180, "frame_times_ns": [0, 16666667, ...]}
  nlohmann::json ToJson() const;
};
/// Reads a truth file written by GroundTruth::ToJson; errors name `source` and the JSON
/// pointer.
Result<GroundTruth> GroundTruthFromJson(const nlohmann::json& document, const std::string& source);

/// Exposure time per frame, ns (at least 1).
int64_t ExposureNs(const CameraSpec& camera);
/// Start of the exposure of the frame with timestamp t_frame_ns, ns: t_frame_ns -
/// ExposureNs / 2 (the timestamp is the middle of the exposure; the exposure is
/// [start, start + ExposureNs)).
int64_t ExposureStartNs(const CameraSpec& camera, int64_t t_frame_ns);
/// The LED switch-on, video clock; nullopt when the LED never switches on within the clip
/// (led.on_video_s outside [0, duration_s)).
std::optional<int64_t> LedOnVideoNs(const TrialSpec& spec);
/// Fraction of the exposure of the frame with timestamp t_frame_ns (centred on it: see
/// ExposureStartNs) during which the LED is
/// on, 0 .. 1: what the renderer draws and what the truth reports for the first lit frame.
double LedOnFractionOfExposure(const TrialSpec& spec, int64_t t_frame_ns);

/// The trial's motion as functions of the clocks: what the renderer draws and the log
/// generator samples. Pure and cheap; built once per trial.
class Timeline {
 public:
  /// Loads the height curve (CSV when asked) and fixes the ramp offset.
  static Result<Timeline> Create(const TrialSpec& spec);

  /// Video instant of the LED switch-on, the origin of the test clock (even when it lies
  /// outside the clip).
  int64_t led_on_origin_video_ns() const { return led_on_video_ns_; }
  /// The LED switch-on, video clock; nullopt when the LED never switches on within the
  /// clip (led.on_video_s outside [0, duration_s)).
  std::optional<int64_t> LedOnVideoNs() const;
  /// Clip length, ns.
  int64_t duration_ns() const { return duration_ns_; }

  /// Test clock (s since LED on) of a video instant.
  double TestSecondsFromVideoNs(int64_t t_video_ns) const;
  /// Device clock of a video instant (the log's clock): led_on_device_ns + (t_video -
  /// LED on) * (1 + clock_drift_ppm * 1e-6), rounded to the nearest ns.
  int64_t DeviceNsFromVideoNs(int64_t t_video_ns) const;
  /// Video instant of a device-clock instant (the inverse, within 1 ns).
  int64_t VideoNsFromDeviceNs(int64_t t_device_ns) const;

  /// Signed vertebra angle at a test-clock second, rad: 0 before ramp_start_s, then
  /// sense * ramp_rate * (test_s - ramp_start_s).
  double VertebraRadAt(double test_s) const;
  /// Bending spool angle at a test-clock second, rad: 0 before the bend, linear from
  /// bend_start_s to bend_end_s, `target_spool_rad` after.
  double BendSpoolRadAt(double test_s, double target_spool_rad) const;
  /// Height of `foot` above its rest at a video instant, m (>= 0): the lifting foot by the
  /// height curve of |rotation|, its diagonal partner by the same curve diagonal_lag_rad
  /// later (when the lag is > 0), the others 0.
  double FootHeightMAt(Foot foot, int64_t t_video_ns) const;
  /// Whether the LED is on at a video instant (never, when LedOnVideoNs() is nullopt).
  bool LedOnAt(int64_t t_video_ns) const;
  /// synth::LedOnFractionOfExposure of this trial.
  double LedOnFractionOfExposure(int64_t t_frame_ns) const {
    return synth::LedOnFractionOfExposure(spec_, t_frame_ns);
  }

  /// First video instant at which the lifting foot's height exceeds `height_m`
  /// (nullopt when not within [0, duration]); exact to 1 ns: the result is the first
  /// integer ns at which FootHeightMAt(spec().motion.foot, t) > height_m.
  std::optional<int64_t> FirstVideoNsAbove(double height_m) const;

  const TrialSpec& spec() const { return spec_; }

 private:
  TrialSpec spec_;
  std::vector<double> curve_rotation_rad_, curve_height_m_;  // CSV curve, when used
  int64_t led_on_video_ns_ = 0;
  int64_t duration_ns_ = 0;
  ClockMap device_from_video_, video_from_device_;
  double HeightAtRotation(double abs_rotation_rad, bool diagonal) const;
  double CurveHeightM(double abs_rotation_rad) const;
  std::optional<double> FirstRotationAbove(double height_m) const;
};

}  // namespace liftoff::synth
