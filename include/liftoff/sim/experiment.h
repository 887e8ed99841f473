// The paper's foot-lifting experiment (section IV.C), engine-independent:
//
//   ExperimentOptions  every parameter of the test (defaults: the paper's);
//   BuildExperimentModel  the Laika model at a tension point with the pulled side group
//                      made the mechanical spring, plus the option overrides;
//   Procedure          what to command at any instant: each cable's rest length, the
//                      hinge's angle (drop and settle, bend, ramp);
//   LiftoffRecorder    takes a Sample every sample_period_s (foot marker heights, hinge
//                      angle, lowest non-foot point) and applies the liftoff rule and the
//                      "does not stand" check;
//   RunExperiment      the whole run with liftoff's own engine.
//
// Another engine (e.g. MuJoCo) runs the same experiment by building the same Model,
// stepping with Procedure's commands and feeding LiftoffRecorder samples:
//
//   LIFTOFF_ASSIGN_OR_RETURN(Model model, BuildExperimentModel(description, options));
//   Procedure procedure(model, options);
//   LiftoffRecorder recorder(model, options);
//   std::vector<double> rest(model.cables.size());
//   for (int64_t step = 1; step <= procedure.step_count(); ++step) {
//     const double t_s = procedure.TimeAt(step);      // end of this step
//     procedure.RestLengthsAt(t_s, rest);
//     const double angle_rad = procedure.HingeAngleAt(t_s);
//     ... advance the engine to t_s with these commands ...
//     if (procedure.IsSampleStep(step)) recorder.Add(sample from the engine at t_s);
//     if (recorder.CanStop()) break;
//   }
//   ExperimentResult result = recorder.Finish();
//
// Timeline (defaults): the robot is built 0.05 m above its standing pose and dropped at
// t = 0; from bend_start_s = 2 s the pulled group's rest lengths shorten at 0.025 m/s
// until each reaches P = 80 % of its initial rest length; from ramp_start_s = 6 s the
// hinge angle is sense * (t - 6) / 40 * pi/3, reaching pi/3 at t = 46 s (then held).
// Liftoff of a foot: the first sample after the reference time (5 s) at which its marker
// is more than 1 mm above its height at the reference time; its rotation is |hinge angle|
// at that sample.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/sim/engine.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {

/// The paper's five tension test points (Table III), low to high: silicone 216, 227, 237,
/// 248, 258 N/m; Buna-N 547, 678, 810, 941, 1073 N/m; the spring 187 N/m throughout
/// (the same numbers as calib/laika-2018.json).
const std::array<TensionPoint, 5>& PaperTensionPoints();

/// Pretension of each group as a multiple of its stiffness: T0 = ratio * k_material.
/// The side groups' ratio multiplies the silicone's k for both sides (the spring carries
/// the same pretension as its silicone partner).
struct PretensionRatios {
  /// HT (silicone), HB (Buna-N), the four saddle groups (silicone), side groups, m.
  double top_m = 0.006;
  double bottom_m = 0.015;
  double saddle_m = 0.052;
  double side_m = 0.004;
};

/// The combination that lifts a foot, found with this simulation (see MotionFor).
/// Same struct as core's PaperTableTwoMotion.
using Motion = FootLiftingMotion;

/// The group pulled and the rotation sense that lift `foot` first, found with this
/// simulation: pinned at the high tension point by experiment_test.cc
/// (EachMotionLiftsItsFootFirst); the 20-run sweep lifts the targeted foot first at every
/// tension point:
///   A (front right): HR, +      B (front left): HL, -
///   C (back right):  HR, -      D (back left):  HL, +
/// Sign convention: the hinge axis points backwards (-x, the source model's +x), so a
/// positive angle turns the front half (v3b) counter-clockwise seen from behind the robot
/// (its top towards the robot's left, its right side up). A twist lifts a diagonal pair
/// (+: A and D, -: B and C); pulling a side group bends the spine so that the feet on the
/// pulled side carry less weight, which picks the foot of the pair (HR: A or C; HL: B or
/// D). This is the source model's assignment (HR for A and C, HL for B and D; A and D one
/// sense, B and C the other). Against the paper's Table II as printed: row 1 (HR +, front
/// right) and row 2 (HL +, "back left") agree by position (row 2's letter C is the
/// documented C/D swap); rows 3 and 4 (HR - "front left", HL - "back right") do not:
/// here HR - lifts the back right foot and HL - the front left one. Read by letter (core's
/// PaperTableTwoMotion: A HR+, B HR-, C HL+, D HL-) only A agrees.
Motion MotionFor(Foot foot);

/// What the robot did.
enum class RunStatus {
  /// The robot stood and at least one foot lifted.
  kLifted,
  /// The robot stood through the run but no foot lifted.
  kNoLiftoff,
  /// The robot did not stand (non-foot geometry within ground_clearance_m of the ground,
  /// or a body origin below the highest foot centre) at some sample from the reference
  /// time to the first liftoff: liftoff values are meaningless (kept for diagnosis only).
  kDidNotStand,
  /// The engine diverged: some position, velocity or rest length stopped being finite (or
  /// grew beyond any physical motion) at `diverged_at_s`. Nothing of the run is a result;
  /// a smaller time step or less stiffness/damping is needed.
  kDiverged,
};
/// "lifted", "no liftoff", "did not stand", "diverged".
std::string_view RunStatusName(RunStatus status);

struct ExperimentOptions {
  // -- the motion --
  /// Foot the test targets. The pulled group and rotation default to MotionFor(foot).
  Foot foot = Foot::kA;
  std::optional<CableGroup> pulled_group;  ///< HR or HL
  std::optional<RotationSense> rotation;

  // -- the tension point --
  /// Index into PaperTensionPoints() (0 low .. 4 high; default high, the point the paper
  /// found closest to the hardware) ...
  int tension_point_index = 4;
  /// ... or explicit stiffnesses (wins when set; its name is reported).
  std::optional<TensionPoint> tension_point;
  PretensionRatios pretension_ratios;
  /// Damping of every cable, N*s/m (>= 0).
  double cable_damping_n_s_per_m = 10.0;

  // -- timeline --
  /// Drop height above the standing pose, m (0 .. 0.5).
  double drop_height_m = 0.05;
  /// Bend: start, s; rest-length shortening speed, m/s (> 0); target fraction P of each
  /// pulled cable's initial rest length (0 < P <= 1).
  double bend_start_s = 2.0;
  double bend_speed_m_per_s = 0.025;
  double bend_fraction = 0.8;
  /// Ramp of the hinge: start, s; duration, s (> 0); final |angle|, rad (0 .. pi).
  double ramp_start_s = 6.0;
  double ramp_duration_s = 40.0;
  double ramp_angle_rad = 1.0471975511965976;  // pi / 3

  // -- liftoff rule --
  /// Reference instant of the foot heights, s (<= ramp_start_s, a sample instant).
  double reference_time_s = 5.0;
  /// Height above the reference that counts as lifted, m (> 0).
  double liftoff_threshold_m = 0.001;
  /// Sampling period, s (a whole multiple of the time step).
  double sample_period_s = 0.01;
  /// Standing check: non-foot geometry closer to the ground than this counts as resting on
  /// it, m (>= 0).
  double ground_clearance_m = 0.001;
  /// Stop once the first foot has lifted and |angle| has gone this much past its liftoff,
  /// rad (>= 0; infinity: run the whole ramp).
  double stop_after_liftoff_rad = std::numeric_limits<double>::infinity();

  // -- model and engine choices (unset: the model file's) --
  std::optional<double> friction;
  std::optional<double> spine_friction;
  std::optional<CableAttachment> cable_attachment;
  std::optional<RestLengthReference> rest_length_reference;
  std::optional<bool> spine_ground_collisions;
  std::optional<bool> spine_self_collisions;
  std::optional<bool> damping_cap;
  /// Marker height above each foot's bottom, m (>= 0; NTRTsim's logs: 1.5).
  std::optional<double> foot_marker_height_m;
  /// The engine; the default step 0.005 s (liftoff converged to the 0.01 s sampling: see
  /// the step study in the report / docs).
  EngineOptions engine{.time_step_s = 0.005};

  Status Validate() const;
  /// The tension point in use (explicit, or the paper's at the index).
  TensionPoint EffectiveTensionPoint() const;
  /// The group and sense in use (explicit, or MotionFor(foot)).
  Motion EffectiveMotion() const;
};

/// The experiment's model: `description` with the tension point's stiffnesses and
/// pretensions applied by group name (HT, STR, STL, SBR, SBL and the unpulled side group:
/// silicone; HB: Buna-N; the pulled group: the spring; T0 by PretensionRatios), every
/// cable's damping set, and the option overrides applied; then BuildModel.
/// kInvalidArgument for bad options or a description without those groups.
Result<Model> BuildExperimentModel(const ModelDescription& description,
                                   const ExperimentOptions& options);

/// The commands of the timeline. Times are step indices times the time step (no
/// accumulated rounding).
class Procedure {
 public:
  /// `model` from BuildExperimentModel with the same options (validated).
  Procedure(const Model& model, const ExperimentOptions& options);

  /// Time step, s, and number of steps to the end of the ramp.
  double time_step_s() const { return time_step_s_; }
  int64_t step_count() const { return step_count_; }
  /// End of step `step` (1-based), s.
  double TimeAt(int64_t step) const { return static_cast<double>(step) * time_step_s_; }
  /// Whether the state after `step` is to be sampled (t a multiple of sample_period_s).
  bool IsSampleStep(int64_t step) const { return step % steps_per_sample_ == 0; }

  /// Commanded rest length of every cable at `t_s`, m; `rest_length_m` has one entry per
  /// model cable.
  void RestLengthsAt(double t_s, std::span<double> rest_length_m) const;
  /// Commanded hinge angle at `t_s`, rad (0 before the ramp, held after it).
  double HingeAngleAt(double t_s) const;
  /// Cables of the pulled group.
  const std::vector<int>& pulled_cables() const { return pulled_cables_; }

 private:
  ExperimentOptions options_;
  double time_step_s_ = 0.0;
  int64_t step_count_ = 0;
  int64_t steps_per_sample_ = 1;
  double sense_ = 1.0;
  std::vector<double> initial_rest_length_m_;
  std::vector<int> pulled_cables_;
};

/// One sample of a run.
struct Sample {
  double time_s = 0.0;
  /// Actual (measured) relative angle of the rotating vertebra, rad, signed.
  double hinge_angle_rad = 0.0;
  /// Height of each foot's marker above the ground, m, indexed by Foot.
  std::array<double, 4> foot_marker_height_m = {0.0, 0.0, 0.0, 0.0};
  /// Lowest point of the non-foot geometry (rods, boxes), m above the ground.
  double lowest_body_point_m = 0.0;
  /// Lowest body frame origin (vertebra centres), m above the ground.
  double lowest_body_origin_m = 0.0;
  /// Highest foot sphere centre, m above the ground.
  double highest_foot_center_m = 0.0;
};

/// liftoff's engine's sample of a state.
Sample SampleState(const Model& model, const State& state);

/// One point of the foot-height curves: |rotation| strictly increasing from the ramp's
/// start; heights relative to each marker's height at the reference time.
struct CurvePoint {
  double time_s = 0.0;
  double rotation_rad = 0.0;  ///< signed hinge angle
  std::array<double, 4> height_m = {0.0, 0.0, 0.0, 0.0};
};

struct FootLiftoff {
  bool lifted = false;
  /// Instant and |hinge angle| at liftoff, s and rad (0 when not lifted).
  double time_s = 0.0;
  double rotation_rad = 0.0;
};

struct ExperimentResult {
  /// The test: targeted foot, motion, tension point's name.
  Foot foot = Foot::kA;
  Motion motion;
  std::string tension_point;
  RunStatus status = RunStatus::kNoLiftoff;
  /// Foot that lifted first (unset when none lifted). With kDidNotStand it and `feet` are
  /// kept for diagnosis only: they are not the test's result.
  std::optional<Foot> first_foot;
  /// Each foot's liftoff, indexed by Foot.
  std::array<FootLiftoff, 4> feet;
  /// Marker heights at the reference time, m above the ground.
  std::array<double, 4> reference_height_m = {0.0, 0.0, 0.0, 0.0};
  /// Lowest non-foot point and lowest body origin between the reference time and the
  /// first liftoff (or the end), m; and at the reference time.
  double min_body_point_m = 0.0;
  double min_body_origin_m = 0.0;
  double reference_body_point_m = 0.0;
  /// Why the robot did not stand (empty otherwise).
  std::string not_standing_reason;
  /// With kDiverged: the simulated instant the state was found diverged, s, and what
  /// diverged ("body 3's velocity is not finite").
  double diverged_at_s = 0.0;
  std::string diverged_reason;
  /// Samples from the ramp's start on, |rotation| strictly increasing.
  std::vector<CurvePoint> curve;
  /// Simulated time at the end of the run, s; steps taken.
  double end_time_s = 0.0;
  int64_t steps = 0;

  /// Liftoff rotation of the targeted foot, rad, when it lifted.
  std::optional<double> TargetLiftoffRad() const;
  /// "A HR+ high: lifted A at 0.412 rad (t 21.74 s); first A" or "... did not stand: ...".
  std::string Brief() const;
};

/// Applies the liftoff rule to samples given in time order.
class LiftoffRecorder {
 public:
  LiftoffRecorder(const Model& model, const ExperimentOptions& options);

  /// The next sample (times increasing, every sample_period_s).
  void Add(const Sample& sample);
  /// True once stopping early loses nothing the options ask for (the first foot lifted
  /// and |angle| went stop_after_liftoff_rad past it).
  bool CanStop() const;
  /// True once the targeted foot's outcome is settled: the robot failed the standing
  /// check, or the targeted foot lifted (RunControl::stop_once_decided). Cheap: no
  /// result is built.
  bool Decided() const;
  /// The outcome so far (call after the last Add).
  ExperimentResult Finish() const;

 private:
  ExperimentOptions options_;
  Motion motion_;
  std::string tension_name_;
  bool have_reference_ = false;
  std::array<double, 4> reference_height_m_ = {0.0, 0.0, 0.0, 0.0};
  std::array<FootLiftoff, 4> feet_;
  std::optional<Foot> first_foot_;
  double first_liftoff_abs_rad_ = 0.0;
  double last_abs_angle_rad_ = -1.0;
  double min_body_point_m_ = std::numeric_limits<double>::infinity();
  double min_body_origin_m_ = std::numeric_limits<double>::infinity();
  double reference_body_point_m_ = 0.0;
  std::string not_standing_reason_;
  std::vector<CurvePoint> curve_;
  double last_time_s_ = 0.0;
  int64_t samples_ = 0;
};

/// The whole experiment with liftoff's engine. kInvalidArgument for bad options or a
/// model that does not fit them. A robot that does not stand is a result (status
/// kDidNotStand), not an error.
Result<ExperimentResult> RunExperiment(const ModelDescription& description,
                                       const ExperimentOptions& options);

// ---------------------------------------------------------------------------------------
// one run, with progress

/// Where a run has got to.
struct RunProgress {
  /// Simulated time reached and the run's planned end (end of the ramp), s.
  double time_s = 0.0;
  double end_time_s = 0.0;
  /// Actual hinge angle of the rotating vertebra at time_s, rad, signed.
  double hinge_angle_rad = 0.0;
};
using RunProgressCallback = std::function<void(const RunProgress& progress)>;

struct RunControl {
  /// Progress is reported every this much simulated time, s (> 0; a whole number of
  /// samples, rounded up), and once at the end.
  double progress_period_s = 0.5;
  /// Stop as soon as the targeted foot's outcome is settled: it lifted (so the first foot
  /// is known too) or the robot has failed the standing check. The liftoff rule and the
  /// standing check only look back, so the targeted foot's value, the first foot and the
  /// status are exactly those of the full run; the curves end there, and feet that had not
  /// lifted by then stay unlifted. Checked every progress_period_s. false: run the whole
  /// timeline (or until ExperimentOptions::stop_after_liftoff_rad says stop).
  bool stop_once_decided = false;

  Status Validate() const;
};

/// RunExperiment with progress reports (and, optionally, the early stop of RunControl):
/// the same steps in the same order (RunExperiment is this with the default RunControl
/// and no callback), so the same result bit for bit when stop_once_decided is false.
/// `progress` may be empty. Errors as RunExperiment, and kInvalidArgument for a bad
/// RunControl.
Result<ExperimentResult> RunExperimentWithProgress(const ModelDescription& description,
                                                   const ExperimentOptions& options,
                                                   const RunControl& control,
                                                   const RunProgressCallback& progress);

/// The foot-height curves as CSV: '#' comment lines (test, status, liftoff per foot),
/// then "time_s,rotation_rad,A_height_m,B_height_m,C_height_m,D_height_m" and one row per
/// curve point (heights relative to the reference, m). The format synth's
/// HeightCurveSpec reads.
std::string HeightCurvesCsv(const ExperimentResult& result);
Status WriteHeightCurvesCsv(const std::filesystem::path& path, const ExperimentResult& result);

/// The bundled model, samples/models/laika.json in the source tree this was built from.
std::filesystem::path DefaultModelPath();

}  // namespace liftoff::sim
