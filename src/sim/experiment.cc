#include "liftoff/sim/experiment.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::sim {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The source model's groups, and which carry which material.
constexpr std::string_view kTop = "HT";
constexpr std::string_view kBottom = "HB";
constexpr std::array<std::string_view, 4> kSaddles = {"STR", "STL", "SBR", "SBL"};

Status Invalid(std::string_view field, const std::string& expected, double got) {
  return InvalidArgumentError(std::string(field) + ": expected " + expected + ", got " +
                              FormatNumber(got));
}

bool IsWholeMultiple(double value, double step) {
  const double ratio = value / step;
  return std::abs(ratio - std::round(ratio)) <= 1e-6 * std::max(1.0, ratio);
}

int64_t RoundToSteps(double value, double step) {
  return static_cast<int64_t>(std::llround(value / step));
}

}  // namespace

const std::array<TensionPoint, 5>& PaperTensionPoints() {
  static const std::array<TensionPoint, 5> points = {{
      {"low", -2.0, 216.0, 547.0, 187.0},
      {"med-low", -1.0, 227.0, 678.0, 187.0},
      {"mean", 0.0, 237.0, 810.0, 187.0},
      {"med-high", 1.0, 248.0, 941.0, 187.0},
      {"high", 2.0, 258.0, 1073.0, 187.0},
  }};
  return points;
}

Motion MotionFor(Foot foot) {
  switch (foot) {
    case Foot::kA: return {CableGroup::kHR, RotationSense::kPositive};
    case Foot::kB: return {CableGroup::kHL, RotationSense::kNegative};
    case Foot::kC: return {CableGroup::kHR, RotationSense::kNegative};
    case Foot::kD: return {CableGroup::kHL, RotationSense::kPositive};
  }
  return {};
}

std::string_view RunStatusName(RunStatus status) {
  switch (status) {
    case RunStatus::kLifted: return "lifted";
    case RunStatus::kNoLiftoff: return "no liftoff";
    case RunStatus::kDidNotStand: return "did not stand";
    case RunStatus::kDiverged: return "diverged";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------
// options

namespace {

// the pulled group and the tension point
Status ValidateMotionAndTension(const ExperimentOptions& o) {
  if (o.pulled_group && *o.pulled_group != CableGroup::kHR && *o.pulled_group != CableGroup::kHL) {
    return InvalidArgumentError("pulled_group: expected HR or HL, got " +
                                std::string(CableGroupName(*o.pulled_group)));
  }
  if (!o.tension_point && (o.tension_point_index < 0 || o.tension_point_index > 4)) {
    return Invalid("tension_point_index", "an integer in [0, 4]", o.tension_point_index);
  }
  if (o.tension_point) {
    if (!(o.tension_point->silicone_n_per_m > 0.0 &&
          std::isfinite(o.tension_point->silicone_n_per_m))) {
      return Invalid("tension_point.silicone_n_per_m", "a number > 0",
                     o.tension_point->silicone_n_per_m);
    }
    if (!(o.tension_point->buna_n_n_per_m > 0.0 &&
          std::isfinite(o.tension_point->buna_n_n_per_m))) {
      return Invalid("tension_point.buna_n_n_per_m", "a number > 0",
                     o.tension_point->buna_n_n_per_m);
    }
    if (!(o.tension_point->spring_n_per_m > 0.0 &&
          std::isfinite(o.tension_point->spring_n_per_m))) {
      return Invalid("tension_point.spring_n_per_m", "a number > 0",
                     o.tension_point->spring_n_per_m);
    }
  }
  return Status::Ok();
}

// pretension ratios and cable damping
Status ValidateCables(const ExperimentOptions& o) {
  const std::array<std::pair<std::string_view, double>, 4> ratios = {
      {{"pretension_ratios.top_m", o.pretension_ratios.top_m},
       {"pretension_ratios.bottom_m", o.pretension_ratios.bottom_m},
       {"pretension_ratios.saddle_m", o.pretension_ratios.saddle_m},
       {"pretension_ratios.side_m", o.pretension_ratios.side_m}}};
  for (const auto& [field, value] : ratios) {
    if (!(value >= 0.0 && value < 1.0)) return Invalid(field, "a number in [0, 1)", value);
  }
  if (!(o.cable_damping_n_s_per_m >= 0.0 && std::isfinite(o.cable_damping_n_s_per_m))) {
    return Invalid("cable_damping_n_s_per_m", "a number >= 0", o.cable_damping_n_s_per_m);
  }
  return Status::Ok();
}

// the drop, the bend and the ramp
Status ValidateSchedule(const ExperimentOptions& o) {
  if (!(o.drop_height_m >= 0.0 && o.drop_height_m <= 0.5)) {
    return Invalid("drop_height_m", "a number in [0, 0.5]", o.drop_height_m);
  }
  if (!(o.bend_start_s >= 0.0 && o.bend_start_s <= 3600.0)) {
    return Invalid("bend_start_s", "a number in [0, 3600]", o.bend_start_s);
  }
  if (!(o.bend_speed_m_per_s > 0.0 && o.bend_speed_m_per_s <= 10.0)) {
    return Invalid("bend_speed_m_per_s", "a number in (0, 10]", o.bend_speed_m_per_s);
  }
  if (!(o.bend_fraction > 0.0 && o.bend_fraction <= 1.0)) {
    return Invalid("bend_fraction", "a number in (0, 1]", o.bend_fraction);
  }
  if (!(o.ramp_start_s >= 0.0 && o.ramp_start_s <= 3600.0)) {
    return Invalid("ramp_start_s", "a number in [0, 3600]", o.ramp_start_s);
  }
  if (!(o.ramp_duration_s > 0.0 && o.ramp_duration_s <= 3600.0)) {
    return Invalid("ramp_duration_s", "a number in (0, 3600]", o.ramp_duration_s);
  }
  if (!(o.ramp_angle_rad >= 0.0 && o.ramp_angle_rad <= std::numbers::pi)) {
    return Invalid("ramp_angle_rad", "a number in [0, pi]", o.ramp_angle_rad);
  }
  return Status::Ok();
}

// liftoff detection, ground and friction
Status ValidateContact(const ExperimentOptions& o) {
  if (!(o.liftoff_threshold_m > 0.0 && o.liftoff_threshold_m <= 1.0)) {
    return Invalid("liftoff_threshold_m", "a number in (0, 1]", o.liftoff_threshold_m);
  }
  if (!(o.ground_clearance_m >= 0.0 && o.ground_clearance_m <= 1.0)) {
    return Invalid("ground_clearance_m", "a number in [0, 1]", o.ground_clearance_m);
  }
  if (!(o.stop_after_liftoff_rad >= 0.0)) {
    return Invalid("stop_after_liftoff_rad", "a number >= 0 (or infinity)",
                   o.stop_after_liftoff_rad);
  }
  if (o.friction && !(*o.friction >= 0.0 && std::isfinite(*o.friction))) {
    return Invalid("friction", "a number >= 0", *o.friction);
  }
  if (o.foot_marker_height_m &&
      !(*o.foot_marker_height_m >= 0.0 && *o.foot_marker_height_m <= 100.0)) {
    return Invalid("foot_marker_height_m", "a number in [0, 100]", *o.foot_marker_height_m);
  }
  if (o.spine_friction && !(*o.spine_friction >= 0.0 && std::isfinite(*o.spine_friction))) {
    return Invalid("spine_friction", "a number >= 0", *o.spine_friction);
  }
  return Status::Ok();
}

// the engine, and the sampling on its time step
Status ValidateSampling(const ExperimentOptions& o) {
  LIFTOFF_RETURN_IF_ERROR(o.engine.Validate().WithContext("engine"));
  const double dt = o.engine.time_step_s;
  if (!(o.sample_period_s >= dt && o.sample_period_s <= 10.0) ||
      !IsWholeMultiple(o.sample_period_s, dt)) {
    return InvalidArgumentError("sample_period_s: expected a whole multiple of the time step " +
                                FormatNumber(dt) + " s (at most 10 s), got " +
                                FormatNumber(o.sample_period_s));
  }
  if (!(o.reference_time_s >= 0.0 && o.reference_time_s <= o.ramp_start_s) ||
      !IsWholeMultiple(o.reference_time_s, o.sample_period_s)) {
    return InvalidArgumentError(
        "reference_time_s: expected a multiple of sample_period_s between 0 and ramp_start_s " +
        FormatNumber(o.ramp_start_s) + ", got " + FormatNumber(o.reference_time_s));
  }
  return Status::Ok();
}

}  // namespace

// Validate() in the fields' order, a group at a time; the first error wins.
Status ExperimentOptions::Validate() const {
  LIFTOFF_RETURN_IF_ERROR(ValidateMotionAndTension(*this));
  LIFTOFF_RETURN_IF_ERROR(ValidateCables(*this));
  LIFTOFF_RETURN_IF_ERROR(ValidateSchedule(*this));
  LIFTOFF_RETURN_IF_ERROR(ValidateContact(*this));
  return ValidateSampling(*this);
}

TensionPoint ExperimentOptions::EffectiveTensionPoint() const {
  if (tension_point) return *tension_point;
  return PaperTensionPoints()[static_cast<size_t>(std::clamp(tension_point_index, 0, 4))];
}

Motion ExperimentOptions::EffectiveMotion() const {
  Motion motion = MotionFor(foot);
  if (pulled_group) motion.pulled_group = *pulled_group;
  if (rotation) motion.rotation = *rotation;
  return motion;
}

// ---------------------------------------------------------------------------------------
// the model at a tension point

Result<Model> BuildExperimentModel(const ModelDescription& description,
                                   const ExperimentOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  ModelDescription variant = description;
  const TensionPoint tension = options.EffectiveTensionPoint();
  const Motion motion = options.EffectiveMotion();
  const std::string pulled(CableGroupName(motion.pulled_group));
  const std::string unpulled(
      CableGroupName(motion.pulled_group == CableGroup::kHR ? CableGroup::kHL : CableGroup::kHR));
  const PretensionRatios& ratios = options.pretension_ratios;

  auto set_group = [&](std::string_view name, std::string material, double stiffness,
                       double pretension) -> Status {
    for (CableGroupDescription& group : variant.cable_groups) {
      if (group.name != name) continue;
      group.material = std::move(material);
      group.stiffness_n_per_m = stiffness;
      group.pretension_n = pretension;
      return Status::Ok();
    }
    return InvalidArgumentError("model " + description.name + ": /cable_groups: no group \"" +
                                std::string(name) +
                                "\" (the experiment needs HT, HB, HR, HL, STR, STL, SBR, SBL)");
  };
  const double silicone = tension.silicone_n_per_m;
  LIFTOFF_RETURN_IF_ERROR(set_group(kTop, "silicone", silicone, ratios.top_m * silicone));
  LIFTOFF_RETURN_IF_ERROR(set_group(kBottom, "buna_n", tension.buna_n_n_per_m,
                                    ratios.bottom_m * tension.buna_n_n_per_m));
  for (std::string_view saddle : kSaddles) {
    LIFTOFF_RETURN_IF_ERROR(set_group(saddle, "silicone", silicone, ratios.saddle_m * silicone));
  }
  LIFTOFF_RETURN_IF_ERROR(set_group(unpulled, "silicone", silicone, ratios.side_m * silicone));
  LIFTOFF_RETURN_IF_ERROR(
      set_group(pulled, "spring", tension.spring_n_per_m, ratios.side_m * silicone));
  for (CableGroupDescription& group : variant.cable_groups) {
    group.damping_n_s_per_m = options.cable_damping_n_s_per_m;
  }

  // option overrides
  if (options.friction) variant.contact.friction = *options.friction;
  if (options.spine_friction) variant.contact.spine_friction = *options.spine_friction;
  if (options.cable_attachment) variant.cable_attachment = *options.cable_attachment;
  if (options.rest_length_reference) variant.rest_length_reference = *options.rest_length_reference;
  if (options.spine_ground_collisions)
    variant.contact.spine_ground = *options.spine_ground_collisions;
  if (options.spine_self_collisions) variant.contact.spine_self = *options.spine_self_collisions;
  if (options.damping_cap) variant.damping_cap = *options.damping_cap;
  if (options.foot_marker_height_m) variant.foot_marker_height_m = *options.foot_marker_height_m;

  LIFTOFF_ASSIGN_OR_RETURN(Model model, BuildModel(variant, "model " + description.name));
  for (size_t f = 0; f < 4; ++f) {
    if (model.foot_index[f] < 0) {
      return InvalidArgumentError("model " + description.name + ": has no foot " +
                                  std::string(FootName(static_cast<Foot>(f))));
    }
  }
  if (model.hinges.size() != 1) {
    return InvalidArgumentError("model " + description.name +
                                ": expected exactly one hinge (the rotating vertebra), got " +
                                std::to_string(model.hinges.size()));
  }
  return model;
}

// ---------------------------------------------------------------------------------------
// procedure

Procedure::Procedure(const Model& model, const ExperimentOptions& options)
    : options_(options),
      time_step_s_(options.engine.time_step_s),
      step_count_(
          RoundToSteps(options.ramp_start_s + options.ramp_duration_s, options.engine.time_step_s)),
      steps_per_sample_(
          std::max<int64_t>(1, RoundToSteps(options.sample_period_s, options.engine.time_step_s))) {
  const Motion motion = options.EffectiveMotion();
  sense_ = motion.rotation == RotationSense::kNegative ? -1.0 : 1.0;
  initial_rest_length_m_.resize(model.cables.size());
  for (size_t c = 0; c < model.cables.size(); ++c) {
    initial_rest_length_m_[c] = model.cables[c].rest_length_m;
  }
  pulled_cables_ = model.CablesInGroup(CableGroupName(motion.pulled_group));
}

void Procedure::RestLengthsAt(double t_s, std::span<double> rest_length_m) const {
  std::copy(initial_rest_length_m_.begin(), initial_rest_length_m_.end(), rest_length_m.begin());
  if (t_s <= options_.bend_start_s) return;
  const double shortening = options_.bend_speed_m_per_s * (t_s - options_.bend_start_s);
  for (int cable : pulled_cables_) {
    const double initial = initial_rest_length_m_[static_cast<size_t>(cable)];
    rest_length_m[static_cast<size_t>(cable)] =
        std::max(options_.bend_fraction * initial, initial - shortening);
  }
}

double Procedure::HingeAngleAt(double t_s) const {
  if (t_s <= options_.ramp_start_s) return 0.0;
  const double progress = std::min(1.0, (t_s - options_.ramp_start_s) / options_.ramp_duration_s);
  return sense_ * progress * options_.ramp_angle_rad;
}

// ---------------------------------------------------------------------------------------
// samples and the liftoff rule

Sample SampleState(const Model& model, const State& state) {
  Sample sample;
  sample.time_s = state.time_s;
  sample.hinge_angle_rad = state.hinge_angle_rad.empty() ? 0.0 : state.hinge_angle_rad[0];
  sample.foot_marker_height_m = FootMarkerHeights(model, state);
  sample.lowest_body_point_m = LowestNonFootPoint(model, state);
  double lowest_origin = kInfinity;
  for (const BodyState& body : state.bodies)
    lowest_origin = std::min(lowest_origin, body.position_m.z());
  sample.lowest_body_origin_m = lowest_origin;
  double highest_foot = -kInfinity;
  for (const FootPoint& foot : model.feet) {
    highest_foot = std::max(highest_foot, WorldPoint(state, foot.body, foot.center_m).z());
  }
  sample.highest_foot_center_m = highest_foot;
  return sample;
}

LiftoffRecorder::LiftoffRecorder(const Model& /*model*/, const ExperimentOptions& options)
    : options_(options),
      motion_(options.EffectiveMotion()),
      tension_name_(options.EffectiveTensionPoint().name) {}

void LiftoffRecorder::Add(const Sample& sample) {
  ++samples_;
  last_time_s_ = sample.time_s;
  const double tolerance = 1e-6 * options_.sample_period_s;
  if (sample.time_s < options_.reference_time_s - tolerance) return;
  const bool at_reference = !have_reference_;
  if (at_reference) {
    // the first sample at (or, with a coarse caller, after) the reference instant
    have_reference_ = true;
    reference_height_m_ = sample.foot_marker_height_m;
    reference_body_point_m_ = sample.lowest_body_point_m;
  }
  // standing check until the first liftoff
  if (!first_foot_ && not_standing_reason_.empty()) {
    min_body_point_m_ = std::min(min_body_point_m_, sample.lowest_body_point_m);
    min_body_origin_m_ = std::min(min_body_origin_m_, sample.lowest_body_origin_m);
    std::ostringstream reason;
    if (sample.lowest_body_point_m <= options_.ground_clearance_m) {
      reason << "spine or hips on the ground at t " << FormatFixed(sample.time_s, 2)
             << " s (lowest non-foot point " << FormatFixed(sample.lowest_body_point_m * 1e3, 1)
             << " mm above the ground)";
    } else if (sample.lowest_body_origin_m <= sample.highest_foot_center_m) {
      reason << "a body below the feet at t " << FormatFixed(sample.time_s, 2) << " s";
    }
    not_standing_reason_ = reason.str();
  }
  // liftoff of each foot (recorded even when the robot did not stand, for diagnosis)
  const double abs_angle = std::abs(sample.hinge_angle_rad);
  if (!at_reference) {
    double best_excess = 0.0;
    std::optional<Foot> first_now;
    for (size_t f = 0; f < 4; ++f) {
      if (feet_[f].lifted) continue;
      const double excess =
          sample.foot_marker_height_m[f] - reference_height_m_[f] - options_.liftoff_threshold_m;
      if (excess > 0.0) {
        feet_[f] = {true, sample.time_s, abs_angle};
        if (!first_foot_ && (!first_now || excess > best_excess)) {
          first_now = static_cast<Foot>(f);
          best_excess = excess;
        }
      }
    }
    if (first_now) {
      first_foot_ = first_now;
      first_liftoff_abs_rad_ = abs_angle;
    }
  }

  // the curves: from the ramp's start, |rotation| strictly increasing
  if (sample.time_s >= options_.ramp_start_s - tolerance && abs_angle > last_abs_angle_rad_) {
    CurvePoint point;
    point.time_s = sample.time_s;
    point.rotation_rad = sample.hinge_angle_rad;
    for (size_t f = 0; f < 4; ++f) {
      point.height_m[f] = sample.foot_marker_height_m[f] - reference_height_m_[f];
    }
    curve_.push_back(point);
    last_abs_angle_rad_ = abs_angle;
  }
}

bool LiftoffRecorder::CanStop() const {
  if (!first_foot_) return false;
  return !curve_.empty() && std::abs(curve_.back().rotation_rad) >=
                                first_liftoff_abs_rad_ + options_.stop_after_liftoff_rad;
}

bool LiftoffRecorder::Decided() const {
  if (!not_standing_reason_.empty()) return true;
  return first_foot_.has_value() && feet_[static_cast<size_t>(options_.foot)].lifted;
}

ExperimentResult LiftoffRecorder::Finish() const {
  ExperimentResult result;
  result.foot = options_.foot;
  result.motion = motion_;
  result.tension_point = tension_name_;
  result.reference_height_m = reference_height_m_;
  result.min_body_point_m = min_body_point_m_;
  result.min_body_origin_m = min_body_origin_m_;
  result.reference_body_point_m = reference_body_point_m_;
  result.curve = curve_;
  result.end_time_s = last_time_s_;
  result.feet = feet_;
  result.first_foot = first_foot_;
  result.status = first_foot_ ? RunStatus::kLifted : RunStatus::kNoLiftoff;
  if (!not_standing_reason_.empty()) {
    result.status = RunStatus::kDidNotStand;
    result.not_standing_reason = not_standing_reason_;
  }
  return result;
}

std::optional<double> ExperimentResult::TargetLiftoffRad() const {
  const FootLiftoff& target = feet[static_cast<size_t>(foot)];
  if (status != RunStatus::kLifted || !target.lifted) return std::nullopt;
  return target.rotation_rad;
}

std::string ExperimentResult::Brief() const {
  std::ostringstream out;
  out << FootName(foot) << " " << CableGroupName(motion.pulled_group)
      << RotationSenseName(motion.rotation) << " " << tension_point << ": ";
  if (status == RunStatus::kDidNotStand) {
    out << "did not stand: " << not_standing_reason;
    return out.str();
  }
  if (status == RunStatus::kDiverged) {
    out << "diverged at t = " << FormatFixed(diverged_at_s, 4) << " s: " << diverged_reason;
    return out.str();
  }
  const FootLiftoff& target = feet[static_cast<size_t>(foot)];
  if (target.lifted) {
    out << "lifted " << FootName(foot) << " at " << FormatFixed(target.rotation_rad, 3)
        << " rad (t " << FormatFixed(target.time_s, 2) << " s)";
  } else {
    out << FootName(foot) << " did not lift";
  }
  out << "; first " << (first_foot ? std::string(FootName(*first_foot)) : std::string("none"));
  return out.str();
}

// ---------------------------------------------------------------------------------------
// the run with liftoff's engine

// ---------------------------------------------------------------------------------------
// the run with liftoff's engine, with progress

Status RunControl::Validate() const {
  if (!(progress_period_s > 0.0 && progress_period_s <= 3600.0)) {
    return InvalidArgumentError("progress_period_s: expected a number in (0, 3600], got " +
                                FormatNumber(progress_period_s));
  }
  return Status::Ok();
}

Result<ExperimentResult> RunExperimentWithProgress(const ModelDescription& description,
                                                   const ExperimentOptions& options,
                                                   const RunControl& control,
                                                   const RunProgressCallback& progress) {
  LIFTOFF_RETURN_IF_ERROR(control.Validate());
  LIFTOFF_ASSIGN_OR_RETURN(Model model, BuildExperimentModel(description, options));
  const Procedure procedure(model, options);
  LiftoffRecorder recorder(model, options);
  State state = InitialState(model, options.drop_height_m);
  Controls controls;
  controls.rest_length_m.resize(model.cables.size());
  controls.hinge_angle_rad.resize(1);
  const double end_time_s = procedure.TimeAt(procedure.step_count());
  auto report = [&](double t_s) {
    if (!progress) return;
    progress({t_s, end_time_s, state.hinge_angle_rad.empty() ? 0.0 : state.hinge_angle_rad[0]});
  };

  // the steps exactly as RunExperiment takes them; reports (and the early-stop check) at
  // sample steps, a whole number of samples apart
  const double dt = options.engine.time_step_s;
  const int64_t steps_per_sample = std::max<int64_t>(1, std::llround(options.sample_period_s / dt));
  const int64_t samples_per_report = std::max<int64_t>(
      1,
      static_cast<int64_t>(std::ceil(control.progress_period_s / options.sample_period_s - 1e-9)));
  const int64_t steps_per_report = steps_per_sample * samples_per_report;
  for (int64_t step = 1; step <= procedure.step_count(); ++step) {
    const double t_s = procedure.TimeAt(step);
    procedure.RestLengthsAt(t_s, controls.rest_length_m);
    controls.hinge_angle_rad[0] = procedure.HingeAngleAt(t_s);
    Step(model, options.engine, controls, state);
    state.time_s = t_s;
    // every step, in every build type: a diverged state is an outcome, never a result
    if (std::string diverged = DescribeDivergence(model, state); !diverged.empty()) {
      ExperimentResult result = recorder.Finish();
      result.status = RunStatus::kDiverged;
      result.diverged_at_s = t_s;
      result.diverged_reason = std::move(diverged);
      result.first_foot.reset();
      result.feet = {};
      result.steps = state.step_count;
      report(t_s);
      return result;
    }
    if (!procedure.IsSampleStep(step)) continue;
    recorder.Add(SampleState(model, state));
    if (recorder.CanStop()) break;
    if (step % steps_per_report != 0) continue;
    report(t_s);
    if (control.stop_once_decided) {
      // settled: the target lifted while standing, or the standing check failed
      if (recorder.Decided()) break;
    }
  }
  ExperimentResult result = recorder.Finish();
  result.steps = state.step_count;
  report(state.time_s);
  return result;
}

Result<ExperimentResult> RunExperiment(const ModelDescription& description,
                                       const ExperimentOptions& options) {
  return RunExperimentWithProgress(description, options, RunControl{}, nullptr);
}

std::string HeightCurvesCsv(const ExperimentResult& result) {
  std::ostringstream out;
  out << "# liftoff sim: foot " << FootName(result.foot) << ", pulled "
      << CableGroupName(result.motion.pulled_group) << ", rotation "
      << RotationSenseName(result.motion.rotation) << ", tension point " << result.tension_point
      << "\n";
  out << "# status: " << RunStatusName(result.status);
  if (!result.not_standing_reason.empty()) out << " (" << result.not_standing_reason << ")";
  out << "\n# liftoff |rotation| rad:";
  for (size_t f = 0; f < 4; ++f) {
    out << " " << FootName(static_cast<Foot>(f)) << " "
        << (result.feet[f].lifted ? FormatFixed(result.feet[f].rotation_rad, 4) : "-");
  }
  out << "\n# heights are relative to each foot marker's height at the reference time, m\n";
  out << "time_s,rotation_rad,A_height_m,B_height_m,C_height_m,D_height_m\n";
  for (const CurvePoint& point : result.curve) {
    out << FormatFixed(point.time_s, 3) << "," << FormatFixed(point.rotation_rad, 6);
    for (double height : point.height_m) out << "," << FormatFixed(height, 7);
    out << "\n";
  }
  return out.str();
}

Status WriteHeightCurvesCsv(const std::filesystem::path& path, const ExperimentResult& result) {
  return WriteFileAtomically(path, HeightCurvesCsv(result));
}

std::filesystem::path DefaultModelPath() {
  return std::filesystem::path(LIFTOFF_SOURCE_DIR) / "samples" / "models" / "laika.json";
}

}  // namespace liftoff::sim
