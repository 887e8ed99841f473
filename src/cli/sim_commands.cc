#include "liftoff/cli/sim_commands.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <ostream>
#include <sstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/sim/mjcf.h"
#include "liftoff/sim/model.h"
#include "liftoff/stats/table.h"

namespace liftoff::cli {
namespace {

using nlohmann::json;

constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

// ---------------------------------------------------------------------------------------
// flags

Status CheckFlag(std::string_view flag, double value, const NumberRange& range,
                 std::string_view unit) {
  if (InNumberRange(value, range)) return Status::Ok();
  return InvalidArgumentError(std::string(flag) + ": expected " + DescribeNumberRange(range) +
                              (unit.empty() ? "" : " " + std::string(unit)) + ", got " +
                              FormatNumber(value));
}

// Checks an optional flag and stores value * scale into `target` when given.
Status TakeFlag(std::string_view flag, const std::optional<double>& value, const NumberRange& range,
                std::string_view unit, double scale, double& target) {
  if (!value) return Status::Ok();
  LIFTOFF_RETURN_IF_ERROR(CheckFlag(flag, *value, range, unit));
  target = *value * scale;
  return Status::Ok();
}

std::vector<std::string> SplitCommas(std::string_view text) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    parts.emplace_back(text.substr(start, comma == std::string_view::npos ? comma : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return parts;
}

// "a,b,c" as exactly `count` numbers; kInvalidArgument naming the flag otherwise.
Result<std::vector<double>> NumberList(std::string_view flag, std::string_view text, size_t count,
                                       std::string_view expected) {
  std::vector<double> values;
  for (const std::string& part : SplitCommas(text)) {
    size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != part.size() || !std::isfinite(value)) {
      values.clear();
      break;
    }
    values.push_back(value);
  }
  if (values.size() != count) {
    return InvalidArgumentError(std::string(flag) + ": expected " + std::string(expected) +
                                ", got \"" + std::string(text) + "\"");
  }
  return values;
}

Result<Foot> FootFlag(std::string_view flag, std::string_view text) {
  if (auto foot = ParseFoot(text)) return *foot;
  return InvalidArgumentError(std::string(flag) + ": expected one of A, B, C, D, got \"" +
                              std::string(text) + "\"");
}

Result<TensionPoint> TensionFlag(std::string_view text) {
  auto point = sim::PaperTensionPointByName(text);
  if (!point.ok()) {
    return InvalidArgumentError(
        "--tension: expected low, med-low, mean, med-high, high or an index 0..4, got \"" +
        std::string(text) + "\"");
  }
  return point;
}

// The test's tension point: explicit stiffnesses, else a paper point by name or index.
Result<TensionPoint> RunTensionPoint(const std::string& tension, const std::string& stiffness) {
  if (stiffness.empty()) return TensionFlag(tension);
  LIFTOFF_ASSIGN_OR_RETURN(
      std::vector<double> values,
      NumberList("--stiffness", stiffness, 3, "SILICONE,BUNA_N,SPRING in N/m, e.g. 258,1073,187"));
  for (double value : values) {
    if (!(value > 0.0)) {
      return InvalidArgumentError("--stiffness: expected three numbers > 0 N/m, got \"" +
                                  stiffness + "\"");
    }
  }
  return TensionPoint{"custom", 0.0, values[0], values[1], values[2]};
}

// A Validate() message starts with the option's field name; name the flag instead.
Status RenameFields(const Status& status) {
  static const std::array<std::pair<std::string_view, std::string_view>, 15> kFlags = {{
      {"reference_time_s", "--reference-s"},
      {"sample_period_s", "--sample-period-s"},
      {"ramp_start_s", "--ramp-start-s"},
      {"ramp_duration_s", "--ramp-s"},
      {"bend_start_s", "--bend-start-s"},
      {"bend_fraction", "--bend-fraction"},
      {"bend_speed_m_per_s", "--bend-speed"},
      {"drop_height_m", "--drop-height-m"},
      {"friction", "--friction"},
      {"engine: time_step_s", "--dt"},
      {"engine: solver_iterations", "--solver-iterations"},
      {"engine: contact_bias", "--contact-bias"},
      {"cable_damping_n_s_per_m", "--damping"},
      {"spine_friction", "--spine-friction"},
      {"foot_marker_height_m", "--marker-height-m"},
  }};
  const std::string& message = status.message();
  for (const auto& [field, flag] : kFlags) {
    if (message.rfind(std::string(field) + ":", 0) == 0) {
      return Status(status.code(), std::string(flag) + message.substr(field.size()));
    }
  }
  return status.WithContext("simulation options");
}

Result<sim::ModelDescription> LoadDescription(const SimExperimentChoice& choice) {
  return sim::LoadModelDescription(ModelPathFrom(choice));
}

// ---------------------------------------------------------------------------------------
// progress on stderr

// Live: one line rewritten in place, at most 5 times a second. Lines: one line per
// finished sweep run, and for a single run a line every 5 s of wall time. Off: nothing.
class SimProgress {
 public:
  static Result<SimProgress> Create(std::string_view mode, std::ostream& err) {
    if (mode != "auto" && mode != "live" && mode != "lines" && mode != "off") {
      return InvalidArgumentError("--progress: expected auto, live, lines or off, got \"" +
                                  std::string(mode) + "\"");
    }
    const bool live = mode == "live" || (mode == "auto" && err.rdbuf() == std::cerr.rdbuf() &&
                                         ::isatty(STDERR_FILENO) == 1);
    return SimProgress(err, live, mode == "off");
  }

  // One run: simulated time and rotation.
  void ShowRun(std::string_view label, const sim::RunProgress& progress) {
    if (off_ || !Due()) return;
    const std::string text = std::string(label) + ": t " + FormatFixed(progress.time_s, 1) +
                             " of " + FormatFixed(progress.end_time_s, 1) +
                             " s simulated, rotation " + FormatFixed(progress.hinge_angle_rad, 3) +
                             " rad";
    if (live_) {
      Rewrite(text);
    } else {
      *err_ << "sim: " << text << std::endl;
    }
  }

  // The sweep: the runs under way, and a line for each finished run.
  void ShowSweep(const sim::SweepProgress& progress) {
    if (off_) return;
    if (progress.finished != nullptr) {
      active_.erase(progress.run_index);
      Clear();
      *err_ << "sim: [" << progress.runs_done << "/" << progress.runs_total << "] "
            << progress.finished->Brief() << std::endl;
      return;
    }
    active_[progress.run_index] = {
        std::string(FootName(progress.foot)) + " " + progress.tension_point->name, progress.run};
    if (!live_ || !Due()) return;
    std::string text = "sim sweep: " + std::to_string(progress.runs_done) + "/" +
                       std::to_string(progress.runs_total) + " done";
    for (const auto& [index, run] : active_) {
      text += " | " + run.first + " t " + FormatFixed(run.second.time_s, 1) + " s " +
              FormatFixed(run.second.hinge_angle_rad, 3) + " rad";
    }
    Rewrite(text);
  }

  // Ends a live line (call before printing anything else).
  void Done() { Clear(); }

 private:
  SimProgress(std::ostream& err, bool live, bool off)
      : err_(&err), live_(live), off_(off), last_shown_ns_(MonotonicNowNs()) {}

  bool Due() {
    const int64_t now_ns = MonotonicNowNs();
    const int64_t every_ns = live_ ? NsFromMilliseconds(200) : NsFromSeconds(5.0);
    if (now_ns - last_shown_ns_ < every_ns) return false;
    last_shown_ns_ = now_ns;
    return true;
  }
  void Rewrite(const std::string& text) {
    *err_ << '\r' << text
          << std::string(last_width_ > text.size() ? last_width_ - text.size() : 0, ' ')
          << std::flush;
    last_width_ = text.size();
  }
  void Clear() {
    if (live_ && last_width_ > 0)
      *err_ << '\r' << std::string(last_width_, ' ') << '\r' << std::flush;
    last_width_ = 0;
  }

  std::ostream* err_;
  bool live_ = false;
  bool off_ = false;
  int64_t last_shown_ns_ = 0;
  size_t last_width_ = 0;
  std::map<int, std::pair<std::string, sim::RunProgress>> active_;
};

// ---------------------------------------------------------------------------------------
// printing

std::string Motion(const sim::Motion& motion) {
  return std::string(CableGroupName(motion.pulled_group)) +
         std::string(RotationSenseName(motion.rotation));
}

std::string TensionText(const TensionPoint& point) {
  return point.name + " (silicone " + FormatNumber(point.silicone_n_per_m) + ", Buna-N " +
         FormatNumber(point.buna_n_n_per_m) + ", spring " + FormatNumber(point.spring_n_per_m) +
         " N/m)";
}

json OptionalNumber(std::optional<double> value) { return value ? json(*value) : json(); }

json RunToJson(const sim::ExperimentResult& result, const sim::Model& model,
               const TensionPoint& tension, const sim::ExperimentOptions& options) {
  json feet = json::object();
  for (Foot foot : kAllFeet) {
    const size_t f = static_cast<size_t>(foot);
    const sim::FootLiftoff& liftoff = result.feet[f];
    feet[std::string(FootName(foot))] = {
        {"lifted", liftoff.lifted},
        {"time_s", liftoff.lifted ? json(liftoff.time_s) : json()},
        {"rotation_rad", liftoff.lifted ? json(liftoff.rotation_rad) : json()},
        {"reference_height_m", result.reference_height_m[f]}};
  }
  return {{"format", "liftoff-sim-run"},
          {"version", 1},
          {"model", model.description.name},
          {"foot", FootName(result.foot)},
          {"pulled_group", CableGroupName(result.motion.pulled_group)},
          {"rotation", RotationSenseName(result.motion.rotation)},
          {"tension_point",
           {{"name", tension.name},
            {"silicone_n_per_m", tension.silicone_n_per_m},
            {"buna_n_n_per_m", tension.buna_n_n_per_m},
            {"spring_n_per_m", tension.spring_n_per_m}}},
          {"status", sim::RunStatusName(result.status)},
          {"stood", result.status != sim::RunStatus::kDidNotStand &&
                        result.status != sim::RunStatus::kDiverged},
          {"diverged_at_s",
           result.status == sim::RunStatus::kDiverged ? json(result.diverged_at_s) : json()},
          {"diverged_reason",
           result.diverged_reason.empty() ? json() : json(result.diverged_reason)},
          {"not_standing_reason",
           result.not_standing_reason.empty() ? json() : json(result.not_standing_reason)},
          {"first_foot", result.first_foot ? json(FootName(*result.first_foot)) : json()},
          {"liftoff_rad", OptionalNumber(result.TargetLiftoffRad())},
          {"feet", feet},
          {"min_body_point_m", result.min_body_point_m},
          {"reference_body_point_m", result.reference_body_point_m},
          {"min_body_origin_m", result.min_body_origin_m},
          {"end_time_s", result.end_time_s},
          {"steps", result.steps},
          {"time_step_s", options.engine.time_step_s}};
}

void PrintRun(const sim::ExperimentResult& result, const sim::Model& model,
              const TensionPoint& tension, const sim::ExperimentOptions& options,
              std::ostream& out) {
  out << "model: " << model.Brief() << "\n";
  out << "test: foot " << FootName(result.foot) << " (" << FootPosition(result.foot) << "), pull "
      << CableGroupName(result.motion.pulled_group) << ", rotate "
      << RotationSenseName(result.motion.rotation) << "; tension point " << TensionText(tension)
      << "\n";
  out << "result: " << result.Brief() << "\n\n";
  if (result.status == sim::RunStatus::kDiverged) {
    out << "The engine diverged: nothing of the run is a result. Try a smaller --dt, less "
           "--damping or softer cables.\n";
    return;
  }
  out << "| Foot | Liftoff (rad) | At (s) | Height at " << FormatNumber(options.reference_time_s)
      << " s (mm) |\n| --- | ---: | ---: | ---: |\n";
  for (Foot foot : kAllFeet) {
    const size_t f = static_cast<size_t>(foot);
    const sim::FootLiftoff& liftoff = result.feet[f];
    out << "| " << FootName(foot) << (foot == result.foot ? " (target)" : "") << " | "
        << (liftoff.lifted ? FormatFixed(liftoff.rotation_rad, 3) : "–") << " | "
        << (liftoff.lifted ? FormatFixed(liftoff.time_s, 2) : "–") << " | "
        << FormatFixed(result.reference_height_m[f] * 1e3, 2) << " |\n";
  }
  out << "\nLiftoff: a foot's marker more than " << FormatNumber(options.liftoff_threshold_m * 1e3)
      << " mm above its height at " << FormatNumber(options.reference_time_s)
      << " s; rotation = |hinge angle| then.\n";
  out << "Lowest non-foot point: " << FormatFixed(result.min_body_point_m * 1e3, 1)
      << " mm above the ground (" << FormatFixed(result.reference_body_point_m * 1e3, 1)
      << " mm at " << FormatNumber(options.reference_time_s) << " s).\n";
  out << "Simulated " << FormatFixed(result.end_time_s, 2) << " s in " << result.steps
      << " steps of " << FormatNumber(options.engine.time_step_s) << " s.\n";
}

std::string Cell(const sim::SweepRun& run) {
  if (run.result.status == sim::RunStatus::kDiverged) return "diverged";
  if (!run.Stood()) return "no stand";
  if (auto value = run.LiftoffRad()) {
    const bool first = run.result.first_foot == run.foot;
    return FormatFixed(*value, 3) + (first ? "" : " *");
  }
  return "none";
}

// true when a run diverged, each such run said on `err`
bool AnyRunDiverged(const sim::SweepResult& sweep, std::ostream& err) {
  bool any = false;
  for (const sim::SweepRun& run : sweep.runs) {
    if (run.result.status != sim::RunStatus::kDiverged) continue;
    err << "liftoff: " << run.Brief() << '\n';
    any = true;
  }
  return any;
}

void PrintSweep(const sim::SweepResult& sweep, std::ostream& out) {
  const int stood = static_cast<int>(std::count_if(
      sweep.runs.begin(), sweep.runs.end(), [](const sim::SweepRun& run) { return run.Stood(); }));
  out << "**Simulated liftoff rotation (rad): " << sweep.model_name << ", "
      << Plural(static_cast<int64_t>(sweep.runs.size()), "run") << ", " << stood << " stood**\n\n";
  out << "| Foot | Motion |";
  for (const TensionPoint& point : sweep.tension_points) out << " " << point.name << " |";
  out << " Sim min | Sim max |\n| --- | --- |";
  for (size_t t = 0; t < sweep.tension_points.size(); ++t) out << " ---: |";
  out << " ---: | ---: |\n";
  const std::vector<sim::SweepFootRange> ranges = sweep.Ranges();
  for (size_t f = 0; f < sweep.feet.size(); ++f) {
    const size_t first = f * sweep.tension_points.size();
    out << "| " << FootName(sweep.feet[f]) << " | " << Motion(sweep.runs[first].result.motion)
        << " |";
    for (size_t t = 0; t < sweep.tension_points.size(); ++t) {
      out << " " << Cell(sweep.runs[first + t]) << " |";
    }
    const sim::SweepFootRange& range = ranges[f];
    if (range.counted_runs == 0) {
      out << " – | – |\n";
    } else {
      out << " " << FormatFixed(range.min_rad, 3) << " | " << FormatFixed(range.max_rad, 3)
          << " |\n";
    }
  }
  out << "\nAbsolute rotation of the rotating vertebra when the targeted foot lifted. "
         "no stand: the robot did not stand (left out of min/max); diverged: the engine "
         "diverged (left out of min/max); none: the foot did not lift; *: another foot lifted "
         "first.\n";
  std::vector<std::string> notes;
  for (const sim::SweepRun& run : sweep.runs) {
    if (!run.Stood() || !run.LiftoffRad() || run.result.first_foot != run.foot) {
      notes.push_back(run.Brief());
    }
  }
  if (notes.empty()) return;
  out << "\nNotes:\n";
  for (const std::string& note : notes) out << "- " << note << "\n";
}

}  // namespace

// ---------------------------------------------------------------------------------------
// options from flags

std::filesystem::path ModelPathFrom(const SimExperimentChoice& choice) {
  return choice.model_path.empty() ? sim::DefaultModelPath() : choice.model_path;
}

Result<sim::ExperimentOptions> ExperimentOptionsFrom(const SimExperimentChoice& choice) {
  sim::ExperimentOptions options;
  const NumberRange non_negative = {.min = 0.0};
  const NumberRange hour = {.min = 0.0, .max = 3600.0};

  // the motion
  if (choice.pulled) {
    const auto group = ParseCableGroup(*choice.pulled);
    if (!group || (*group != CableGroup::kHR && *group != CableGroup::kHL)) {
      return InvalidArgumentError("--pulled: expected HR or HL, got \"" + *choice.pulled + "\"");
    }
    options.pulled_group = *group;
  }
  if (choice.rotation) {
    const auto sense = ParseRotationSense(*choice.rotation);
    if (!sense) {
      return InvalidArgumentError("--rotation: expected + or -, got \"" + *choice.rotation + "\"");
    }
    options.rotation = *sense;
  }

  // timeline and liftoff rule
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--bend-fraction", choice.bend_fraction,
                                   {.min = 0.0, .max = 1.0, .min_exclusive = true}, "", 1.0,
                                   options.bend_fraction));
  LIFTOFF_RETURN_IF_ERROR(
      TakeFlag("--bend-start-s", choice.bend_start_s, hour, "s", 1.0, options.bend_start_s));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--bend-speed", choice.bend_speed_m_per_s,
                                   {.min = 0.0, .max = 10.0, .min_exclusive = true}, "m/s", 1.0,
                                   options.bend_speed_m_per_s));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--ramp-deg", choice.ramp_deg, {.min = 0.0, .max = 180.0},
                                   "degrees", 1.0 / kDegreesPerRadian, options.ramp_angle_rad));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--ramp-s", choice.ramp_s,
                                   {.min = 0.0, .max = 3600.0, .min_exclusive = true}, "s", 1.0,
                                   options.ramp_duration_s));
  LIFTOFF_RETURN_IF_ERROR(
      TakeFlag("--ramp-start-s", choice.ramp_start_s, hour, "s", 1.0, options.ramp_start_s));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--drop-height-m", choice.drop_height_m,
                                   {.min = 0.0, .max = 0.5}, "m", 1.0, options.drop_height_m));
  LIFTOFF_RETURN_IF_ERROR(
      TakeFlag("--reference-s", choice.reference_s, hour, "s", 1.0, options.reference_time_s));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--threshold-mm", choice.threshold_mm,
                                   {.min = 0.0, .max = 1000.0, .min_exclusive = true}, "mm", 1e-3,
                                   options.liftoff_threshold_m));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--sample-period-s", choice.sample_period_s,
                                   {.min = 0.0, .max = 10.0, .min_exclusive = true}, "s", 1.0,
                                   options.sample_period_s));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--ground-clearance-mm", choice.ground_clearance_mm,
                                   {.min = 0.0, .max = 1000.0}, "mm", 1e-3,
                                   options.ground_clearance_m));
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--stop-after-rad", choice.stop_after_rad, non_negative, "rad",
                                   1.0, options.stop_after_liftoff_rad));

  // model choices
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--damping", choice.damping_n_s_per_m, non_negative, "N*s/m",
                                   1.0, options.cable_damping_n_s_per_m));
  if (!choice.pretension_ratios.empty()) {
    LIFTOFF_ASSIGN_OR_RETURN(
        std::vector<double> ratios,
        NumberList("--pretension-ratios", choice.pretension_ratios, 4,
                   "TOP,BOTTOM,SADDLE,SIDE in m (T0 / k), e.g. 0.006,0.015,0.052,0.004"));
    for (double ratio : ratios) {
      if (!(ratio >= 0.0 && ratio < 1.0)) {
        return InvalidArgumentError(
            "--pretension-ratios: expected four numbers in [0, 1) m, got \"" +
            choice.pretension_ratios + "\"");
      }
    }
    options.pretension_ratios = {ratios[0], ratios[1], ratios[2], ratios[3]};
  }
  if (choice.friction) {
    LIFTOFF_RETURN_IF_ERROR(CheckFlag("--friction", *choice.friction, non_negative, ""));
    options.friction = *choice.friction;
  }
  if (choice.spine_friction) {
    LIFTOFF_RETURN_IF_ERROR(
        CheckFlag("--spine-friction", *choice.spine_friction, non_negative, ""));
    options.spine_friction = *choice.spine_friction;
  }
  if (choice.marker_height_m) {
    LIFTOFF_RETURN_IF_ERROR(
        CheckFlag("--marker-height-m", *choice.marker_height_m, {.min = 0.0, .max = 100.0}, "m"));
    options.foot_marker_height_m = *choice.marker_height_m;
  }
  if (!choice.attachment.empty()) {
    if (choice.attachment == "node") {
      options.cable_attachment = sim::CableAttachment::kNode;
    } else if (choice.attachment == "surface") {
      options.cable_attachment = sim::CableAttachment::kSurface;
    } else {
      return InvalidArgumentError("--attachment: expected node or surface, got \"" +
                                  choice.attachment + "\"");
    }
  }
  if (!choice.rest_reference.empty()) {
    if (choice.rest_reference == "attachment") {
      options.rest_length_reference = sim::RestLengthReference::kAttachment;
    } else if (choice.rest_reference == "node") {
      options.rest_length_reference = sim::RestLengthReference::kNode;
    } else {
      return InvalidArgumentError("--rest-reference: expected attachment or node, got \"" +
                                  choice.rest_reference + "\"");
    }
  }
  if (!choice.collisions.empty()) {
    const std::string& mode = choice.collisions;
    if (mode != "feet" && mode != "ground" && mode != "self" && mode != "all") {
      return InvalidArgumentError("--collisions: expected feet, ground, self or all, got \"" +
                                  mode + "\"");
    }
    options.spine_ground_collisions = mode == "ground" || mode == "all";
    options.spine_self_collisions = mode == "self" || mode == "all";
  }
  if (!choice.damping_cap.empty()) {
    if (choice.damping_cap != "on" && choice.damping_cap != "off") {
      return InvalidArgumentError("--damping-cap: expected on or off, got \"" + choice.damping_cap +
                                  "\"");
    }
    options.damping_cap = choice.damping_cap == "on";
  }

  // engine
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--dt", choice.dt_s, {.min = 1e-6, .max = 0.01}, "s", 1.0,
                                   options.engine.time_step_s));
  options.engine.implicit_stiffness = choice.implicit_stiffness;
  if (choice.solver_iterations) {
    LIFTOFF_RETURN_IF_ERROR(CheckFlag("--solver-iterations", *choice.solver_iterations,
                                      {.min = 1.0, .max = 1000.0}, ""));
    options.engine.solver_iterations = *choice.solver_iterations;
  }
  LIFTOFF_RETURN_IF_ERROR(TakeFlag("--contact-bias", choice.contact_bias, {.min = 0.0, .max = 1.0},
                                   "", 1.0, options.engine.contact_bias));

  // what only the whole set can say (a reference instant after the ramp's start, a sample
  // period that is no multiple of the time step, ...)
  const Status valid = options.Validate();
  if (!valid.ok()) return RenameFields(valid);
  return options;
}

std::string DescribeOverrides(const SimExperimentChoice& choice) {
  std::vector<std::string> parts;
  auto number = [&](std::string_view flag, const std::optional<double>& value) {
    if (value) parts.push_back(std::string(flag) + " " + FormatNumber(*value));
  };
  auto text = [&](std::string_view flag, const std::string& value) {
    if (!value.empty()) parts.push_back(std::string(flag) + " " + value);
  };
  if (!choice.model_path.empty()) text("--model", choice.model_path.string());
  if (choice.pulled) text("--pulled", *choice.pulled);
  if (choice.rotation) parts.push_back("--rotation=" + *choice.rotation);
  number("--bend-fraction", choice.bend_fraction);
  number("--bend-start-s", choice.bend_start_s);
  number("--bend-speed", choice.bend_speed_m_per_s);
  number("--ramp-deg", choice.ramp_deg);
  number("--ramp-s", choice.ramp_s);
  number("--ramp-start-s", choice.ramp_start_s);
  number("--drop-height-m", choice.drop_height_m);
  number("--reference-s", choice.reference_s);
  number("--threshold-mm", choice.threshold_mm);
  number("--sample-period-s", choice.sample_period_s);
  number("--ground-clearance-mm", choice.ground_clearance_mm);
  number("--stop-after-rad", choice.stop_after_rad);
  number("--damping", choice.damping_n_s_per_m);
  text("--pretension-ratios", choice.pretension_ratios);
  number("--friction", choice.friction);
  number("--spine-friction", choice.spine_friction);
  number("--marker-height-m", choice.marker_height_m);
  text("--attachment", choice.attachment);
  text("--rest-reference", choice.rest_reference);
  text("--collisions", choice.collisions);
  text("--damping-cap", choice.damping_cap);
  number("--dt", choice.dt_s);
  if (choice.implicit_stiffness) parts.push_back("--implicit-stiffness");
  if (choice.solver_iterations) {
    parts.push_back("--solver-iterations " + std::to_string(*choice.solver_iterations));
  }
  number("--contact-bias", choice.contact_bias);
  std::string joined;
  for (const std::string& part : parts) joined += (joined.empty() ? "" : " ") + part;
  return joined;
}

// ---------------------------------------------------------------------------------------
// liftoff sim run

int RunSimRun(const SimRunCommand& command, std::ostream& out, std::ostream& err) {
  // flags, model
  auto options = ExperimentOptionsFrom(command.experiment);
  if (!options.ok()) return ReportError(options.status(), err);
  auto foot = FootFlag("--foot", command.foot);
  if (!foot.ok()) return ReportError(foot.status(), err);
  auto tension = RunTensionPoint(command.tension, command.stiffness);
  if (!tension.ok()) return ReportError(tension.status(), err);
  options->foot = *foot;
  options->tension_point = *tension;
  auto progress = SimProgress::Create(command.experiment.progress, err);
  if (!progress.ok()) return ReportError(progress.status(), err);
  if (const int refused =
          RefuseToOverwriteInputs({{"--curves", command.curves_path}},
                                  {{"--model", ModelPathFrom(command.experiment)}}, err);
      refused != kExitOk) {
    return refused;
  }
  auto description = LoadDescription(command.experiment);
  if (!description.ok()) return ReportError(description.status(), err);
  auto model = sim::BuildExperimentModel(*description, *options);
  if (!model.ok()) return ReportError(model.status(), err);

  // the run
  const std::string label = "sim " + std::string(FootName(*foot)) + " " + tension->name;
  const int64_t started_ns = MonotonicNowNs();
  auto result = sim::RunExperimentWithProgress(
      *description, *options, sim::RunControl{},
      [&](const sim::RunProgress& run) { progress->ShowRun(label, run); });
  progress->Done();
  if (!result.ok()) return ReportError(result.status(), err);
  const double wall_s = SecondsFromNs(MonotonicNowNs() - started_ns);

  // curves, then the outcome
  if (command.curves_path == "-") {
    out << sim::HeightCurvesCsv(*result);
  } else if (!command.curves_path.empty()) {
    const Status written = sim::WriteHeightCurvesCsv(command.curves_path, *result);
    if (!written.ok()) return ReportError(written, err);
    err << "wrote " << command.curves_path.string() << '\n';
  }
  if (command.curves_path != "-") {
    if (command.json) {
      out << RunToJson(*result, *model, *tension, *options).dump(2) << '\n';
    } else {
      PrintRun(*result, *model, *tension, *options, out);
    }
  }
  err << "sim: " << FormatFixed(result->end_time_s, 2) << " s simulated in "
      << FormatFixed(wall_s, 2) << " s wall\n";
  if (result->status == sim::RunStatus::kDiverged) {
    err << "liftoff: " << result->Brief() << '\n';
    return kExitDiverged;
  }
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff sim sweep

stats::SimResults SimResultsFromSweep(const sim::SweepResult& sweep, std::string description) {
  stats::SimResults results;
  results.model = sweep.model_name;
  std::vector<std::string> no_liftoff;
  for (const sim::SweepRun& run : sweep.runs) {
    const std::optional<double> value = run.LiftoffRad();
    if (run.Stood() && !value) {
      no_liftoff.push_back(std::string(FootName(run.foot)) + " " + run.tension_point.name);
      continue;
    }
    stats::SimRun entry;
    entry.foot = run.foot;
    entry.tension_point = run.tension_point.name;
    entry.liftoff_rad = value;
    entry.stood = run.Stood();
    entry.diverged = run.result.status == sim::RunStatus::kDiverged;
    entry.pulled_group = run.result.motion.pulled_group;
    entry.rotation = run.result.motion.rotation;
    entry.notes = run.Brief();
    results.runs.push_back(std::move(entry));
  }
  if (!no_liftoff.empty()) {
    std::string names;
    for (const std::string& name : no_liftoff) names += (names.empty() ? "" : ", ") + name;
    description += (description.empty() ? "" : "; ") +
                   std::string("stood but the targeted foot did not lift (left out): ") + names;
  }
  results.description = std::move(description);
  results.ranges = stats::SimRangesFromRuns(results.runs);
  return results;
}

Result<sim::SweepOptions> SweepOptionsFrom(const SimSweepCommand& command) {
  auto base = ExperimentOptionsFrom(command.experiment);
  if (!base.ok()) return base.status();
  sim::SweepOptions options;
  options.base = *base;
  options.threads = command.threads;
  options.stop_once_decided = !command.full_ramp;
  if (command.threads < 0) {
    return InvalidArgumentError("--threads: expected an integer >= 0, got " +
                                            std::to_string(command.threads));
  }
  options.feet.clear();
  for (const std::string& name : SplitCommas(command.feet)) {
    auto foot = FootFlag("--feet", name);
    if (!foot.ok()) return foot.status();
    if (std::find(options.feet.begin(), options.feet.end(), *foot) != options.feet.end()) {
      return InvalidArgumentError("--feet: foot " + name + " appears twice");
    }
    options.feet.push_back(*foot);
  }
  if (command.tensions != "all") {
    options.tension_points.clear();
    for (const std::string& name : SplitCommas(command.tensions)) {
      auto point = sim::PaperTensionPointByName(name);
      if (!point.ok()) {
        return InvalidArgumentError("--tensions: expected all or a comma-separated "
                                                "list of low, med-low, mean, med-high, high "
                                                "(or 0..4), got \"" +
                                                name + "\"");
      }
      for (const TensionPoint& seen : options.tension_points) {
        if (seen.name == point->name) {
          return InvalidArgumentError("--tensions: " + point->name + " appears twice");
        }
      }
      options.tension_points.push_back(*point);
    }
  }
  return options;
}

Result<sim::SweepResult> RunSweepShowingProgress(const SimSweepCommand& command,
                                                 std::ostream& err) {
  LIFTOFF_ASSIGN_OR_RETURN(sim::SweepOptions options, SweepOptionsFrom(command));
  LIFTOFF_ASSIGN_OR_RETURN(SimProgress progress,
                           SimProgress::Create(command.experiment.progress, err));
  LIFTOFF_ASSIGN_OR_RETURN(sim::ModelDescription description, LoadDescription(command.experiment));
  const int64_t started_ns = MonotonicNowNs();
  auto sweep = sim::RunSweep(description, options, [&](const sim::SweepProgress& report) {
    progress.ShowSweep(report);
  });
  progress.Done();
  if (!sweep.ok()) return sweep.status();
  const double wall_s = SecondsFromNs(MonotonicNowNs() - started_ns);
  err << "sim: " << Plural(static_cast<int64_t>(sweep->runs.size()), "run") << " in "
      << FormatFixed(wall_s, 2) << " s wall on " << Plural(sweep->threads, "thread") << '\n';
  return sweep;
}

int RunSimSweep(const SimSweepCommand& command, std::ostream& out, std::ostream& err) {
  const auto table_format = stats::ParseTableFormat(command.format);
  if (!table_format) {
    return ReportError(InvalidArgumentError("--format: expected md, csv, latex or json, got \"" +
                                            command.format + "\""),
                       err);
  }
  // the hardware trials are read before the sweep: a missing or broken manifest fails in
  // a second, not after the whole sweep
  if (!command.hardware_path.empty()) {
    std::ostringstream warnings;  // the table reads it again and prints them then
    auto hardware = LoadTrials(command.hardware_path, warnings);
    if (!hardware.ok()) return ReportError(hardware.status().WithContext("--hardware"), err);
  }
  if (const int refused = RefuseToOverwriteInputs(
          {{"--output", command.output_path}},
          {{"--model", ModelPathFrom(command.experiment)}, {"--hardware", command.hardware_path}},
          err);
      refused != kExitOk) {
    return refused;
  }
  auto sweep = RunSweepShowingProgress(command, err);
  if (!sweep.ok()) return ReportError(sweep.status(), err);

  // the results file, then what to print
  const std::string overrides = DescribeOverrides(command.experiment);
  stats::SimResults results =
      SimResultsFromSweep(*sweep, "liftoff sim sweep" + (overrides.empty() ? "" : " " + overrides));
  results.source = command.output_path.empty() ? "this sweep" : command.output_path.string();
  const json document = stats::SimResultsToJson(results);
  if (!command.output_path.empty()) {
    const Status written = WriteJsonFile(command.output_path, document);
    if (!written.ok()) return ReportError(written, err);
    err << "wrote " << command.output_path.string() << '\n';
  }
  if (command.json) {
    out << document.dump(2) << '\n';
  } else {
    PrintSweep(*sweep, out);
  }
  const int ran = AnyRunDiverged(*sweep, err) ? kExitDiverged : kExitOk;
  if (command.hardware_path.empty()) return ran;

  // hardware beside simulation, by the table command's own code
  TableCommand table;
  table.manifest_path = command.hardware_path;
  table.calibration = command.calibration;
  table.lookup = command.lookup;
  table.format = command.format;
  table.tables = "feet";
  table.sim_results = std::move(results);
  if (!command.json) out << '\n';
  const int tabulated = RunTable(table, out, err);
  return tabulated != kExitOk ? tabulated : ran;
}

// ---------------------------------------------------------------------------------------
// liftoff sim export-mjcf

int RunSimExportMjcf(const SimExportMjcfCommand& command, std::ostream& out, std::ostream& err) {
  // flags
  auto options = ExperimentOptionsFrom(command.experiment);
  if (!options.ok()) return ReportError(options.status(), err);
  // MuJoCo's step: MjcfOptions' own unless --dt says otherwise; soft constraints never
  // faster than MuJoCo's floor of two steps
  sim::MjcfOptions mjcf;
  if (command.experiment.dt_s) mjcf.time_step_s = *command.experiment.dt_s;
  mjcf.contact_time_constant_s = std::max(mjcf.contact_time_constant_s, 2.0 * mjcf.time_step_s);
  mjcf.hinge_time_constant_s = std::max(mjcf.hinge_time_constant_s, 2.0 * mjcf.time_step_s);
  mjcf.lift_m = command.lift_m;
  if (command.hinge_drive == "equality") {
    mjcf.hinge_drive = sim::MjcfHingeDrive::kEquality;
  } else if (command.hinge_drive == "actuator") {
    mjcf.hinge_drive = sim::MjcfHingeDrive::kPositionActuator;
  } else {
    return ReportError(InvalidArgumentError("--hinge-drive: expected equality or actuator, got \"" +
                                            command.hinge_drive + "\""),
                       err);
  }
  if (const Status checked = CheckFlag("--lift-m", command.lift_m, {.min = 0.0, .max = 1.0}, "m");
      !checked.ok()) {
    return ReportError(checked, err);
  }
  if (command.output_path.empty()) {
    return ReportError(InvalidArgumentError("--output: expected a file name (or - for stdout)"),
                       err);
  }

  if (const int refused =
          RefuseToOverwriteInputs({{"--output", command.output_path}},
                                  {{"--model", ModelPathFrom(command.experiment)}}, err);
      refused != kExitOk) {
    return refused;
  }

  // the model: as written, or the experiment's at a foot and tension point
  auto description = LoadDescription(command.experiment);
  if (!description.ok()) return ReportError(description.status(), err);
  Result<sim::Model> model = Status(StatusCode::kInvalidArgument, "no model");
  if (command.as_is) {
    SimExperimentChoice flags = command.experiment;
    flags.model_path.clear();
    flags.progress.clear();
    const std::string overrides = DescribeOverrides(flags);
    if (!overrides.empty()) {
      return ReportError(InvalidArgumentError("--as-is exports the model file as written; it "
                                              "takes no experiment flags, got: " +
                                              overrides),
                         err);
    }
    model = sim::BuildModel(*description, description->name);
  } else {
    auto foot = FootFlag("--foot", command.foot);
    if (!foot.ok()) return ReportError(foot.status(), err);
    auto tension = TensionFlag(command.tension);
    if (!tension.ok()) return ReportError(tension.status(), err);
    options->foot = *foot;
    options->tension_point = *tension;
    model = sim::BuildExperimentModel(*description, *options);
  }
  if (!model.ok()) return ReportError(model.status(), err);

  // the file
  auto text = sim::ExportMjcf(*model, mjcf);
  if (!text.ok()) return ReportError(text.status(), err);
  if (command.output_path == "-") {
    out << *text;
    return kExitOk;
  }
  const Status written = WriteFileAtomically(command.output_path, *text);
  if (!written.ok()) return ReportError(written, err);
  err << "wrote " << command.output_path.string() << " (" << model->Brief() << ")\n";
  return kExitOk;
}

}  // namespace liftoff::cli
