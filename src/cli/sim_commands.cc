#include "liftoff/cli/sim_commands.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <numbers>
#include <ostream>
#include <sstream>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/cli/progress_line.h"
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

// ---------------------------------------------------------------------------------------
// flags

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

// The test's tension point: explicit stiffnesses (checked by ExperimentOptions::Validate),
// else a paper point by name or index.
Result<TensionPoint> RunTensionPoint(const std::string& tension,
                                     const std::vector<double>& stiffness_n_per_m) {
  if (stiffness_n_per_m.empty()) return TensionFlag(tension);
  if (stiffness_n_per_m.size() != 3) {
    return InvalidArgumentError(
        "--stiffness: expected SILICONE,BUNA_N,SPRING in N/m, e.g. 258,1073,187, got " +
        Plural(static_cast<int64_t>(stiffness_n_per_m.size()), "number"));
  }
  sim::ExperimentOptions checked;
  checked.tension_point = TensionPoint{"custom", 0.0, stiffness_n_per_m[0],
                                       stiffness_n_per_m[1], stiffness_n_per_m[2]};
  const Status valid = checked.Validate();
  if (auto named = MessageNamingFlag(valid.message(), "--stiffness", "tension_point", true)) {
    return InvalidArgumentError(*named);
  }
  LIFTOFF_RETURN_IF_ERROR(valid);
  return *checked.tension_point;
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
    LIFTOFF_ASSIGN_OR_RETURN(ProgressLine line,
                             ProgressLine::Create(mode, "--progress", "sim", err));
    return SimProgress(std::move(line));
  }

  // One run: simulated time and rotation.
  void ShowRun(std::string_view label, const sim::RunProgress& progress) {
    if (line_.off() || !line_.Due()) return;
    line_.Show(std::string(label) + ": t " + FormatFixed(progress.time_s, 1) + " of " +
               FormatFixed(progress.end_time_s, 1) + " s simulated, rotation " +
               FormatFixed(progress.hinge_angle_rad, 3) + " rad");
  }

  // The sweep: the runs under way, and a line for each finished run.
  void ShowSweep(const sim::SweepProgress& progress) {
    if (progress.finished != nullptr) {
      active_.erase(progress.run_index);
      line_.Line("[" + std::to_string(progress.runs_done) + "/" +
                 std::to_string(progress.runs_total) + "] " + progress.finished->Brief());
      return;
    }
    active_[progress.run_index] = {
        std::string(FootName(progress.foot)) + " " + progress.tension_point->name, progress.run};
    if (!line_.live() || !line_.Due()) return;
    std::string text = "sim sweep: " + std::to_string(progress.runs_done) + "/" +
                       std::to_string(progress.runs_total) + " done";
    for (const auto& [index, run] : active_) {
      text += " | " + run.first + " t " + FormatFixed(run.second.time_s, 1) + " s " +
              FormatFixed(run.second.hinge_angle_rad, 3) + " rad";
    }
    line_.Show(text);
  }

  // Ends a live line (call before printing anything else).
  void Done() { line_.Clear(); }

 private:
  explicit SimProgress(ProgressLine line) : line_(std::move(line)) {}

  ProgressLine line_;
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

// Long on purpose: the table of the experiment's flags, one line each.
const std::vector<FieldFlag<sim::ExperimentOptions>>& ExperimentFlags() {
  using O = sim::ExperimentOptions;
  using sim::CableAttachment;
  using sim::RestLengthReference;
  using Collisions = std::pair<bool, bool>;  // spine with the ground, spine with itself
  static const std::vector<FieldFlag<O>> flags = {
      // the motion (unset: sim::MotionFor(foot))
      ChoiceFlag<O>("--pulled", LIFTOFF_FIELD(pulled_group),
                    std::vector<std::pair<std::string, CableGroup>>{{"HR", CableGroup::kHR},
                                                                    {"HL", CableGroup::kHL}},
                    "Cable group the bend pulls (default: the foot's motion)"),
      ChoiceFlag<O>("--rotation", LIFTOFF_FIELD(rotation),
                    std::vector<std::pair<std::string, RotationSense>>{
                        {"+", RotationSense::kPositive}, {"-", RotationSense::kNegative}},
                    "Ramp direction, written --rotation=- (default: the foot's motion)"),
      // the timeline
      NumberFlag<O>("--bend-fraction", LIFTOFF_FIELD(bend_fraction), kSameUnit,
                    "Bend each pulled cable to this fraction of its rest length"),
      NumberFlag<O>("--bend-start-s", LIFTOFF_FIELD(bend_start_s), kSameUnit, "Bend start, s"),
      NumberFlag<O>("--bend-speed", LIFTOFF_FIELD(bend_speed_m_per_s), kSameUnit,
                    "Rest-length shortening speed, m/s"),
      NumberFlag<O>("--ramp-deg", LIFTOFF_FIELD(ramp_angle_rad), kDegreesForRadians,
                    "Final |rotation| of the ramp, degrees"),
      NumberFlag<O>("--ramp-s", LIFTOFF_FIELD(ramp_duration_s), kSameUnit, "Ramp duration, s"),
      NumberFlag<O>("--ramp-start-s", LIFTOFF_FIELD(ramp_start_s), kSameUnit, "Ramp start, s"),
      NumberFlag<O>("--drop-height-m", LIFTOFF_FIELD(drop_height_m), kSameUnit,
                    "Drop height above the standing pose, m"),
      // the liftoff rule
      NumberFlag<O>("--reference-s", LIFTOFF_FIELD(reference_time_s), kSameUnit,
                    "Instant of the reference foot heights, s"),
      NumberFlag<O>("--threshold-mm", LIFTOFF_FIELD(liftoff_threshold_m), kMillimetresForMetres,
                    "Liftoff: height above the reference, mm"),
      NumberFlag<O>("--sample-period-s", LIFTOFF_FIELD(sample_period_s), kSameUnit,
                    "Sampling period, s"),
      NumberFlag<O>("--ground-clearance-mm", LIFTOFF_FIELD(ground_clearance_m),
                    kMillimetresForMetres,
                    "Standing check: non-foot geometry this close to the ground rests on it, mm"),
      NumberFlag<O>("--stop-after-rad", LIFTOFF_FIELD(stop_after_liftoff_rad), kSameUnit,
                    "Stop once |rotation| is this far past the first liftoff, rad (inf: never)"),
      // the model and the engine
      NumberFlag<O>("--damping", LIFTOFF_FIELD(cable_damping_n_s_per_m), kSameUnit,
                    "Cable damping, N*s/m"),
      NumbersFlag<O>(
          "--pretension-ratios", "pretension_ratios", 4,
          [](const O& o) {
            const sim::PretensionRatios& r = o.pretension_ratios;
            return std::vector<double>{r.top_m, r.bottom_m, r.saddle_m, r.side_m};
          },
          [](O& o, const std::vector<double>& v) {
            o.pretension_ratios = {v[0], v[1], v[2], v[3]};
          },
          "four numbers TOP,BOTTOM,SADDLE,SIDE in m (T0 / k)", "T0/k of HT,HB,saddles,sides, m"),
      NumberFlag<O>("--friction", LIFTOFF_FIELD(friction), kSameUnit,
                    "Ground friction coefficient (default: the model's)"),
      NumberFlag<O>("--spine-friction", LIFTOFF_FIELD(spine_friction), kSameUnit,
                    "Friction of the spine and hips with the ground (default: the model's)"),
      NumberFlag<O>("--marker-height-m", LIFTOFF_FIELD(foot_marker_height_m), kSameUnit,
                    "Foot markers this far above the feet's bottoms, m (default: the model's)"),
      ChoiceFlag<O>("--attachment", LIFTOFF_FIELD(cable_attachment),
                    std::vector<std::pair<std::string, CableAttachment>>{
                        {"node", CableAttachment::kNode}, {"surface", CableAttachment::kSurface}},
                    "Cable ends (default: the model's)"),
      ChoiceFlag<O>("--rest-reference", LIFTOFF_FIELD(rest_length_reference),
                    std::vector<std::pair<std::string, RestLengthReference>>{
                        {"attachment", RestLengthReference::kAttachment},
                        {"node", RestLengthReference::kNode}},
                    "Rest length from the attachment or node distance (default: the model's)"),
      ChoiceFlagOf<O, Collisions>(
          "--collisions", "spine_ground_collisions",
          {{"feet", {false, false}},
           {"ground", {true, false}},
           {"self", {false, true}},
           {"all", {true, true}}},
          [](const O& o) -> std::optional<Collisions> {
            if (!o.spine_ground_collisions && !o.spine_self_collisions) return std::nullopt;
            return Collisions{o.spine_ground_collisions.value_or(false),
                              o.spine_self_collisions.value_or(false)};
          },
          [](O& o, const Collisions& c) {
            o.spine_ground_collisions = c.first;
            o.spine_self_collisions = c.second;
          },
          "What touches what: only the feet, the spine and hips with the ground too, the "
          "spine rods with each other, or all (default: the model's)"),
      ChoiceFlag<O>("--damping-cap", LIFTOFF_FIELD(damping_cap),
                    std::vector<std::pair<std::string, bool>>{{"on", true}, {"off", false}},
                    "Cap cable damping at the spring term (default: the model's)"),
      NumberFlag<O>("--dt", LIFTOFF_FIELD(engine.time_step_s), kSameUnit, "Engine time step, s"),
      SwitchFlag<O>("--implicit-stiffness", LIFTOFF_FIELD(engine.implicit_stiffness),
                    "Treat cable stiffness implicitly too"),
      NumberFlag<O>("--solver-iterations", LIFTOFF_FIELD(engine.solver_iterations), kSameUnit,
                    "Contact solver sweeps per step"),
      NumberFlag<O>("--contact-bias", LIFTOFF_FIELD(engine.contact_bias), kSameUnit,
                    "Fraction of a penetration removed per step"),
  };
  return flags;
}

void AddExperimentFlags(Command& app, SimExperimentChoice& choice) {
  app.AddOption("--model", choice.model_path,
                 "Model JSON (default: the bundled samples/models/laika.json)");
  AddFlags(app, ExperimentFlags(), choice.options);
  app.AddOption("--progress", choice.progress, "Progress on stderr: auto, live, lines or off")
      ->ShowDefault();
}

const std::vector<FieldFlag<sim::MjcfOptions>>& MjcfFlags() {
  using O = sim::MjcfOptions;
  static const std::vector<FieldFlag<O>> flags = {
      ChoiceFlag<O>("--hinge-drive", LIFTOFF_FIELD(hinge_drive),
                    std::vector<std::pair<std::string, sim::MjcfHingeDrive>>{
                        {"equality", sim::MjcfHingeDrive::kEquality},
                        {"actuator", sim::MjcfHingeDrive::kPositionActuator}},
                    "The hinge's drive: a constraint a runner sets each step, or a position "
                    "servo"),
      NumberFlag<O>("--lift-m", LIFTOFF_FIELD(lift_m), kSameUnit,
                    "Raise the free bodies by this, m"),
  };
  return flags;
}

Result<sim::ExperimentOptions> ExperimentOptionsFrom(const SimExperimentChoice& choice) {
  const Status valid = choice.options.Validate();
  if (valid.ok()) return choice.options;
  const Status named = NameFlagIn(valid, ExperimentFlags());
  return named.message() != valid.message() ? named : valid.WithContext("simulation options");
}

std::string DescribeOverrides(const SimExperimentChoice& choice) {
  const std::string model =
      choice.model_path.empty() ? "" : "--model " + choice.model_path.string();
  const std::string changed = DescribeChanged(ExperimentFlags(), choice.options);
  return model + (!model.empty() && !changed.empty() ? " " : "") + changed;
}

// ---------------------------------------------------------------------------------------
// liftoff sim run

int RunSimRun(const SimRunCommand& command, std::ostream& out, std::ostream& err) {
  // flags, model
  auto options = ExperimentOptionsFrom(command.experiment);
  if (!options.ok()) return ReportError(options.status(), err);
  auto foot = FootFlag("--foot", command.foot);
  if (!foot.ok()) return ReportError(foot.status(), err);
  auto tension = RunTensionPoint(command.tension, command.stiffness_n_per_m);
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
    const std::string names = Join(no_liftoff, ", ");
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
  for (const std::string& name : command.feet) {
    auto foot = FootFlag("--feet", name);
    if (!foot.ok()) return foot.status();
    if (std::find(options.feet.begin(), options.feet.end(), *foot) != options.feet.end()) {
      return InvalidArgumentError("--feet: foot " + name + " appears twice");
    }
    options.feet.push_back(*foot);
  }
  if (command.tensions != std::vector<std::string>{"all"}) {
    options.tension_points.clear();
    for (const std::string& name : command.tensions) {
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
  if (const auto checked = TableFormatFlag(command.format); !checked.ok()) {
    return ReportError(checked.status(), err);
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
  sim::MjcfOptions mjcf = command.mjcf;
  const double time_step_s = command.experiment.options.engine.time_step_s;
  if (time_step_s != sim::ExperimentOptions().engine.time_step_s) mjcf.time_step_s = time_step_s;
  mjcf.contact_time_constant_s = std::max(mjcf.contact_time_constant_s, 2.0 * mjcf.time_step_s);
  mjcf.hinge_time_constant_s = std::max(mjcf.hinge_time_constant_s, 2.0 * mjcf.time_step_s);
  if (const Status valid = NameFlagIn(mjcf.Validate(), MjcfFlags()); !valid.ok()) {
    return ReportError(valid, err);
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

// ---------------------------------------------------------------------------------------
// the flags of the three

Subcommand AddSimRunCommand(Command& sim) {
  auto command = std::make_shared<SimRunCommand>();
  Command* app = sim.AddSubcommand(
      "run", "One simulated test: each foot's liftoff rotation, optionally the height curves");
  app->AddOption("--foot", command->foot, "Foot the test targets: A, B, C or D")
      ->ShowDefault();
  app->AddOption("--tension", command->tension,
                  "Tension point: low, med-low, mean, med-high, high or 0..4")
      ->ShowDefault();
  app->AddOption("--stiffness", command->stiffness_n_per_m,
                  "Explicit stiffnesses SILICONE,BUNA_N,SPRING in N/m (instead of --tension)")
      ->CommaSeparated();
  AddExperimentFlags(*app, command->experiment);
  app->AddSwitch("--json", command->json, "JSON output");
  app->AddOption("--curves", command->curves_path,
                  "Write the foot-height curves (CSV) here; - for stdout");
  return RunsWith(app, command, RunSimRun);
}

Subcommand AddSimSweepCommand(Command& sim) {
  auto command = std::make_shared<SimSweepCommand>();
  Command* app = sim.AddSubcommand(
      "sweep",
      "The tension points x the four foot motions in parallel (paper Table IV's sim columns)");
  AddSweepFlags(*app, *command);
  app->AddSwitch("--full-ramp", command->full_ramp,
                "Run every test to the end of the ramp (same values, slower)");
  AddExperimentFlags(*app, command->experiment);
  app->AddOption("--output,-o", command->output_path,
                  "Write the simulation results JSON (for liftoff table --sim)");
  app->AddSwitch("--json", command->json, "Print the results JSON instead of the table");
  app->AddOption("--hardware", command->hardware_path,
                  "Trial manifest or 2018 Laika folder: also print the hardware-vs-simulation "
                  "table");
  app->AddOption("--format,-f", command->format, "Hardware table format: md, csv, latex or json")
      ->ShowDefault();
  AddCalibrationFlag(*app, command->calibration);
  AddLookupFlags(*app, command->lookup);
  return RunsWith(app, command, RunSimSweep);
}

void AddSweepFlags(Command& app, SimSweepCommand& command) {
  AddListOption(app, "--feet", command.feet, "Simulated feet, comma-separated");
  AddListOption(app, "--tensions", command.tensions,
                "Simulated tension points, comma-separated names or 0..4, or all");
  app.AddOption("--threads", command.threads, "Sweep worker threads (0: all cores)")
      ->ShowDefault();
}

Subcommand AddSimExportMjcfCommand(Command& sim) {
  auto command = std::make_shared<SimExportMjcfCommand>();
  Command* app = sim.AddSubcommand("export-mjcf", "Write the model as a MuJoCo MJCF file");
  app->AddOption("--output,-o", command->output_path, "MJCF file; - for stdout")->Required();
  app->AddOption("--foot", command->foot, "The experiment's model for this foot")
      ->ShowDefault();
  app->AddOption("--tension", command->tension, "... at this tension point")
      ->ShowDefault();
  app->AddSwitch("--as-is", command->as_is,
                "Export the model file as written (no tension point applied)");
  AddFlags(*app, MjcfFlags(), command->mjcf);
  AddExperimentFlags(*app, command->experiment);
  return RunsWith(app, command, RunSimExportMjcf);
}

}  // namespace liftoff::cli
