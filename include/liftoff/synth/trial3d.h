// Synthetic trials through the 3D camera (scene3d.h): the robot's motion from liftoff's own
// simulation, camera timing and effects, a real encoder, and the exact truth, written in
// the folder format of the independent development clips (../shared/video-dev/README.md):
//
//   <output_dir>/<id>/video.mp4 | video.avi | video.mkv   the clip
//   <output_dir>/<id>/controller.csv                      t_ms,rotation_rad
//   <output_dir>/<id>/truth.json                          the answer (docs/synth.md)
//   <output_dir>/<id>/<id>.csv                            the same test's liftoff-format log
//
// and, for the set, <output_dir>/manifest.json: the ok clips as a trial manifest (foot,
// motion, liftoff log, video, ROIs, pixel scale), so `liftoff table` and `liftoff sync`
// read 3D trials as they read 2D ones.
//
// Motion. sim::RunExperiment runs the paper's procedure for the trial's foot at its
// tension point (high by default) with the ramp at theta_rate_rad_s up to
// max_rotation_rad. The ramp's start is the LED switch-on (t_led_on on the video clock):
// the simulated instant t_sim is shown at t_video = led_on_s + (t_sim - ramp start). The
// lifting foot's height h(t) is the simulated marker height above its reference, linear
// between the 0.01 s samples, with heights below contact_floor_m counted as 0 (on the
// floor); the vertebra's angle is the simulated hinge angle. The renderer shows h(t) by
// rolling the lifting foot's end of the robot (scene3d.h). t_lift and t_lift_1mm are the first
// instants h(t) exceeds 0 and 1 mm (exact on the linear curve).
//
// Camera. Frame i is presented at pts_i (the frame schedule and container rounding of
// trial_writer.h's FrameScheduleNs and VideoWriter::StoredPtsNs) and integrates
// [pts_i - e/2, pts_i + e/2]; it shows the pose at pts_i (or, with motion_blur_samples
// > 1, the average of the poses at the midpoints of the exposure's equal parts). The LED's lit
// fraction is the part of that exposure after the switch-on; a partially lit frame is off + f (on -
// off) of the two rendered pictures (glow included), so it is exact. Then, in this order: flicker
// (the lamp's 1 + a sin(2 pi f t) averaged over the exposure) times gain, camera shake (a
// reflected random walk, +-4 px, bilinear), Gaussian blur, Gaussian sensor noise (per-pixel, seeded
// by (seed, frame)), then the encoder. With a rolling shutter's readout the flicker comes after the
// shake instead, row by row on the sensor: row r sees the lamp over its own exposure, which starts
// r / rows of the readout after the first row's, so the bands roll from frame to frame while the
// picture itself stays the global shutter's.
//
// Everything is a pure function of the spec: the same spec gives the same truth and log
// bytes, and on one machine the same pixels.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/scene3d.h"
#include "liftoff/synth/spec.h"

namespace liftoff::synth {

/// One 3D trial.
struct Trial3dSpec {
  /// Folder name and truth id: 1-100 of A-Z a-z 0-9 . _ -.
  std::string id = "synth3d";
  /// Noise, shake, drops, jitter, the log's sample spacing, clutter.
  uint64_t seed = 1;
  Scene3dOptions scene;
  /// The foot that lifts; the simulation pulls and turns as sim::MotionFor(foot).
  Foot foot = Foot::kA;
  /// The simulation's tension point, 0 (low) .. 4 (high): see sim::PaperTensionPoints ...
  int tension_point_index = 4;
  /// ... or explicit stiffnesses (win when set; each 1 .. 100000 N/m), e.g. a point on the
  /// calibration's tension line (fit::TensionAtSigma) or a draw around one (campaign.h).
  /// The truth names the point ("tension_point") but not its stiffnesses.
  std::optional<TensionPoint> tension;
  /// The vertebra's ramp rate, rad/s (0.005 .. 1; the paper's is 0.02618), and where the
  /// ramp stops (held there), rad (0.05 .. pi/3; below the liftoff rotation: the foot
  /// never lifts).
  double theta_rate_rad_s = 0.15;
  double max_rotation_rad = 1.0471975511965976;
  /// Heights below this are contact noise of the simulation, counted as 0, m (0 .. 1e-3).
  double contact_floor_m = 2e-5;
  /// The foot rises this many times slower than simulated once it leaves the ground (1 ..
  /// 20; the vertebra still turns as commanded): the simulated robot tips, so its foot is
  /// 1 mm up about 0.2 s after leaving the ground, where a softer robot's (the development
  /// set's) takes about 0.5 s, which a codec holds back longer.
  double rise_slowdown = 1.0;

  /// Nominal frame rate, Hz (1 .. 240); exposure, s (0 < e <= 1/fps).
  double fps = 30.0;
  double exposure_s = 1.0 / 60.0;
  /// Variable frame rate: dropped-slot probability (0 .. 0.5), timestamp jitter, s
  /// (0 .. 0.4/fps). As CameraSpec.
  double drop_probability = 0.0;
  double timestamp_jitter_s = 0.0;
  /// This many frames dropped from the first whose exposure ends after the LED switch-on
  /// (0 .. 5): the camera misses the switch-on itself.
  int drop_frames_at_led = 0;
  VideoCodec codec = VideoCodec::kH264;
  /// CRF (h264) or q:v (mjpeg), as CameraSpec.
  int quality = 20;
  /// Most frames between key frames (VideoWriterOptions::keyframe_interval_frames; 0: a
  /// nominal second).
  int keyframe_interval_frames = 0;

  /// The LED switch-on (and the ramp's start), video clock, s (0.2 .. 60).
  double led_on_s = 2.0;
  /// false: the LED never lights (the ramp still starts at led_on_s); a reject clip.
  bool led_switches_on = true;
  /// The clip ends this long after t_lift_1mm, s (0.1 .. 10), or at max_duration_s,
  /// whichever is first (and at max_duration_s when the foot never lifts). Keep it short:
  /// the simulated robot tips over within about a second of liftoff (the foot 100+ mm up),
  /// which rolling one end of the robot cannot show; the CI set's clips end 15-21 mm up.
  double after_lift_s = 0.25;
  double max_duration_s = 12.0;

  /// Image effects, off at their defaults except a lens's softness: sensor noise (8-bit
  /// levels, 0 .. 30), gain (0.2 .. 4), flicker amplitude (0 .. 0.5) at flicker_hz (100
  /// or 120) seen through a readout of flicker_readout_s (0: a global shutter, the whole
  /// frame one level; up to 1/fps: a rolling shutter's bands across the rows), shake step
  /// per frame (px, 0 .. 2), Gaussian blur sigma (px, 0 .. 5; the default 0.6 px stands in
  /// for anti-aliasing and optics).
  double noise_sigma = 0.0;
  double gain = 1.0;
  double flicker_amplitude = 0.0;
  double flicker_hz = 100.0;
  double flicker_readout_s = 0.0;
  double shake_px = 0.0;
  double blur_sigma_px = 0.6;
  /// Motion blur: the scene is averaged over this many poses at the midpoints of the
  /// exposure's equal parts (1 .. 16; 1: the pose at pts, as the development set shows it).
  int motion_blur_samples = 1;

  Status Validate() const;
};

/// The motion a trial shows, from the simulation, on the video clock.
struct Motion3d {
  /// Curve points: video time, s; signed vertebra angle, rad; lifting foot's height, m
  /// (contact floor applied). Time increasing; held at the ends.
  std::vector<double> time_s, vertebra_rad, height_m;
  /// First instants the height exceeds 0 and 1 mm, video clock, s (unset: never).
  std::optional<double> t_lift_s, t_lift_1mm_s;
  /// The simulation's own liftoff rotation of the foot (its 1 mm rule on samples), rad.
  std::optional<double> sim_liftoff_rad;
  std::string sim_brief;

  double HeightMAt(double t_video_s) const;
  double VertebraRadAt(double t_video_s) const;
};

/// Runs the simulation for `spec` and maps it onto the video clock. kInvalidArgument for a
/// bad spec or a diverged simulation; kNotFound when the simulated robot does not stand.
Result<Motion3d> SimulateMotion3d(const Trial3dSpec& spec);

/// The controller's log of a trial: rows (t_ms, rotation_rad) from 0 at the LED
/// switch-on, every 8 .. 12 ms (drawn from the seed), to the clip's end; rotation_rad is
/// |commanded angle| = rate * t (held at max_rotation_rad) quantised down to whole counts
/// of EncoderQuantumRad().
struct ControllerSample {
  int64_t t_ms = 0;
  double rotation_rad = 0.0;
};
std::vector<ControllerSample> ControllerLog3d(const Trial3dSpec& spec, double duration_s);
/// 2 pi / (12 * 1000 * 4) rad: one encoder count at the vertebra.
double EncoderQuantumRad();

/// Fraction of the centred exposure [pts - e/2, pts + e/2] after `t_on_s`, 0 .. 1.
double LedLitFraction(double pts_s, double exposure_s, double t_on_s);

/// The 2D path's spec that writes the same test's liftoff-format log (WriteTrialLog): the
/// LED at led_on_s, the ramp from it at theta_rate_rad_s in the simulation's sense for the
/// foot, the bend (done before the LED in the simulation) at its target throughout, the
/// log from the LED switch-on (no lead) to 1 s after the clip, 100 Hz.
TrialSpec LiftoffLogSpec3d(const Trial3dSpec& spec, double duration_s);

/// What WriteTrial3d produced.
struct WrittenTrial3d {
  std::filesystem::path folder, video_path, controller_path, truth_path;
  /// The liftoff-format log and, for an ok clip, its manifest entry (no event times).
  std::filesystem::path liftoff_log_path;
  std::optional<TrialRecord> manifest_entry;
  int64_t frames = 0;
  double render_seconds = 0.0, encode_seconds = 0.0;
  /// The truth as written, and its answers: "ok" or "reject"; the LED switch-on, the
  /// foot's 1 mm instant (video clock, s) and the rotation there, rad (unset: none).
  std::string truth_json;
  std::string expect;
  std::optional<double> t_led_on_s, t_lift_1mm_s, theta_at_lift_1mm_rad;
};

/// Renders and writes one trial into `output_dir`/<id>/. Needs a current OpenGL context
/// (EglContext) on the calling thread. Errors: the spec's, the simulation's, the
/// renderer's (kUnsupported without rendering), the encoder's, kIo for files.
/// `calibration` quantises the liftoff-format log's counts.
Result<WrittenTrial3d> WriteTrial3d(const Trial3dSpec& spec, const Calibration& calibration,
                                    const std::filesystem::path& output_dir);

/// The 3D CI set: clips at the paper's ramp rate (LED at about 2 s, liftoff 16-17.5 s
/// later, the clip 1.5 s longer) with side, oblique and front views, 480p and 720p, H.264,
/// MJPEG and a VFR-with-drops case, sphere, block and rubber-tip feet, shadows, a glossy
/// floor, a small LED, low light with noise; and two reject clips (LED never on; foot
/// never lifts). docs/synth.md.
std::vector<Trial3dSpec> Ci3dSet();

/// A harder 3D set for development, not rendered in CI (about 4 min): strong flicker with a
/// short exposure, low light with shake, frames dropped at the LED, a small and a large
/// robot in frame, a tiny LED, a glossy floor in low light, MJPEG with shake, a rolling
/// shutter's flicker bands. docs/synth.md.
std::vector<Trial3dSpec> Hard3dSet();

/// The 3D set of that name ("ci3d" or "hard3d"); kInvalidArgument for another.
Result<std::vector<Trial3dSpec>> Set3dNamed(const std::string& name);

/// Writes every trial of `specs` (the set `name`) into `output_dir` on this thread (one EGL
/// context; Mesa renders on all cores), then `manifest.json` (the ok clips; `description`
/// as its description, empty: "liftoff synth set NAME (CALIBRATION)") and `set.json` (the
/// index: id, folder, expect, frames, render time).
/// `progress` (may be empty) is called before each trial with (index, count, id).
struct Set3dSummary {
  std::string name;  ///< the set's: "ci3d", "hard3d"
  std::vector<WrittenTrial3d> trials;
  int64_t frames = 0;
  double wall_seconds = 0.0, render_seconds = 0.0, encode_seconds = 0.0;
  std::string renderer;  ///< EglContext::description()
  /// "ci3d: 10 clips, 1234 frames in 61.2 s (render 35.1 ms/frame, encode 4.2 ms/frame)".
  std::string Brief() const;
};
using Set3dProgress = std::function<void(int index, int count, const std::string& id)>;
Result<Set3dSummary> WriteSpecs3d(const std::string& name, const std::vector<Trial3dSpec>& specs,
                                  const std::filesystem::path& output_dir,
                                  const Calibration& calibration, const std::string& description,
                                  const Set3dProgress& progress = {});
/// How a named set is drawn anew (the defaults: as documented).
struct Set3dVariation {
  /// Every clip's seeds (its noise, shake, drops, floor and clutter) offset by this: the
  /// same conditions drawn anew, to test on footage the detectors were not tuned on.
  uint64_t seed_offset = 0;
  /// Every clip's Trial3dSpec::rise_slowdown (1 .. 20).
  double rise_slowdown = 1.0;
  /// Every clip's Trial3dSpec::keyframe_interval_frames (0 .. 10000; 0: a nominal second).
  int keyframe_interval_frames = 0;
  /// Every clip's LED switch-on (and the ramp, and the clip's end with it) moved later by a
  /// draw from [0, this) s seeded by the clip's seed, s (0 .. 10; 0: as documented, where
  /// most switch-ons fall on a frame's presentation time and a key frame): the switch-on at
  /// any phase of a frame and between key frames, as a camera started by hand has it.
  double led_on_spread_s = 0.0;
  /// Every clip's lamp flicker amplitude (Trial3dSpec::flicker_amplitude, 0 .. 0.5) and
  /// readout, s (Trial3dSpec::flicker_readout_s, 0 .. 1/fps: 0 a global shutter, the whole
  /// frame one level; more a rolling shutter's bands); negative: each clip's own. Each
  /// clip keeps its lamp's frequency. Flicker scales the whole picture, the LED's light
  /// with it; an exposure of many lamp periods averages it away.
  double flicker_amplitude = -1.0;
  double flicker_readout_s = -1.0;
  /// Every clip's exposure, s (Trial3dSpec::exposure_s, 0 < e <= 1/fps; negative: each
  /// clip's own): short ones see the lamp's flicker whole.
  double exposure_s = -1.0;
  /// Every clip's LED radius, m (Scene3dOptions::led_radius_m, 0.001 .. 0.02; negative:
  /// each clip's own): how small an LED the detector meets.
  double led_radius_m = -1.0;

  Status Validate() const;
};
/// `set` varied by `variation` (valid): the specs WriteSet3d writes.
std::vector<Trial3dSpec> VarySet3d(std::vector<Trial3dSpec> set, const Set3dVariation& variation);
/// The named set (Set3dNamed) through WriteSpecs3d, varied by `variation`.
Result<Set3dSummary> WriteSet3d(const std::string& name, const std::filesystem::path& output_dir,
                                const Calibration& calibration, const Set3dProgress& progress = {},
                                const Set3dVariation& variation = {});

}  // namespace liftoff::synth
