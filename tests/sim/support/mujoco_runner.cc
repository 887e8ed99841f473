#include "sim/support/mujoco_runner.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <mujoco/mujoco.h>

#include "liftoff/core/json.h"
#include "liftoff/core/text.h"

namespace liftoff::sim::mujoco {
namespace {

// MuJoCo reports errors through a global hook that must not return; ours throws, and
// every entry point below catches at its edge.
struct MujocoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void ThrowMujocoError(const char* message) { throw MujocoError(message); }

thread_local std::string last_warning;
void RememberWarning(const char* message) { last_warning = message; }

// The XML compiler keeps global state in MuJoCo 2.2.2: one load at a time.
std::mutex& LoadMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

void InstallMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowMujocoError;
    mju_user_warning = RememberWarning;
  });
}

MujocoSimulation::MujocoSimulation(const Model& model, const MjcfOptions& options)
    : model_(model), options_(options) {}

MujocoSimulation::~MujocoSimulation() {
  if (mj_data_ != nullptr) mj_deleteData(mj_data_);
  if (mj_model_ != nullptr) mj_deleteModel(mj_model_);
}

Result<std::unique_ptr<MujocoSimulation>> MujocoSimulation::Create(const Model& model,
                                                                   const MjcfOptions& options) {
  InstallMujocoHandlers();
  std::unique_ptr<MujocoSimulation> simulation(new MujocoSimulation(model, options));
  LIFTOFF_ASSIGN_OR_RETURN(simulation->mjcf_, ExportMjcf(model, options));
  LIFTOFF_RETURN_IF_ERROR(simulation->Load());
  return simulation;
}

Status MujocoSimulation::Load() {
  // the text through a virtual file system (the VFS is 2 MB: on the heap)
  constexpr const char* kFileName = "liftoff_model.xml";
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), kFileName, static_cast<int>(mjcf_.size())) != 0) {
    mj_deleteVFS(vfs.get());
    return IoError("mujoco: cannot make a virtual file of " + std::to_string(mjcf_.size()) +
                   " bytes");
  }
  const int file = mj_findFileVFS(vfs.get(), kFileName);
  std::memcpy(vfs->filedata[file], mjcf_.data(), mjcf_.size());
  char error[1024] = "";
  try {
    const std::lock_guard<std::mutex> lock(LoadMutex());
    mj_model_ = mj_loadXML(kFileName, vfs.get(), error, sizeof error);
  } catch (const MujocoError& e) {
    mj_deleteVFS(vfs.get());
    return ParseError(std::string("mujoco: ") + e.what());
  }
  mj_deleteVFS(vfs.get());
  if (mj_model_ == nullptr) return ParseError(std::string("mujoco rejected the MJCF: ") + error);
  mj_data_ = mj_makeData(mj_model_);
  if (mj_data_ == nullptr) return IoError("mujoco: mj_makeData failed");
  sparse_jacobian_ = mj_isSparse(mj_model_) != 0;

  // find everything by the export's names
  auto find = [this](int type, const std::string& name, int& id) -> Status {
    id = mj_name2id(mj_model_, type, name.c_str());
    if (id < 0) return NotFoundError("mujoco model has no \"" + name + "\"");
    return Status::Ok();
  };
  body_id_.resize(model_.bodies.size());
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    LIFTOFF_RETURN_IF_ERROR(find(mjOBJ_BODY, model_.bodies[b].name, body_id_[b]));
  }
  tendon_id_.resize(model_.cables.size());
  for (size_t c = 0; c < model_.cables.size(); ++c) {
    LIFTOFF_RETURN_IF_ERROR(find(mjOBJ_TENDON, model_.cables[c].name, tendon_id_[c]));
  }
  hinge_qpos_.resize(model_.hinges.size());
  hinge_dof_.resize(model_.hinges.size());
  hinge_drive_.resize(model_.hinges.size());
  for (size_t h = 0; h < model_.hinges.size(); ++h) {
    int joint = -1;
    LIFTOFF_RETURN_IF_ERROR(find(mjOBJ_JOINT, model_.hinges[h].name, joint));
    hinge_qpos_[h] = mj_model_->jnt_qposadr[joint];
    hinge_dof_[h] = mj_model_->jnt_dofadr[joint];
    const std::string drive =
        MjcfHingeDriveElementName(model_, static_cast<int>(h), options_.hinge_drive);
    LIFTOFF_RETURN_IF_ERROR(
        find(options_.hinge_drive == MjcfHingeDrive::kEquality ? mjOBJ_EQUALITY : mjOBJ_ACTUATOR,
             drive, hinge_drive_[h]));
  }
  marker_site_.assign(4, -1);
  for (const FootPoint& foot : model_.feet) {
    LIFTOFF_RETURN_IF_ERROR(find(mjOBJ_SITE, MjcfMarkerSiteName(foot.foot),
                                 marker_site_[static_cast<size_t>(foot.foot)]));
  }
  rest_length_m_.resize(model_.cables.size());
  for (size_t c = 0; c < model_.cables.size(); ++c)
    rest_length_m_[c] = model_.cables[c].rest_length_m;
  mj_forward(mj_model_, mj_data_);
  return Status::Ok();
}

Status MujocoSimulation::Step(std::span<const double> rest_length_m, double hinge_angle_rad) {
  mjModel* m = mj_model_;
  mjData* d = mj_data_;
  std::copy(rest_length_m.begin(), rest_length_m.end(), rest_length_m_.begin());
  try {
    // the hinge command
    for (size_t h = 0; h < hinge_drive_.size(); ++h) {
      if (options_.hinge_drive == MjcfHingeDrive::kEquality) {
        m->eq_data[mjNEQDATA * hinge_drive_[h]] = hinge_angle_rad;
      } else {
        d->ctrl[hinge_drive_[h]] = hinge_angle_rad;
      }
    }
    // positions and velocities, then the cables' generalised forces
    mj_step1(m, d);
    const int nv = m->nv;
    std::fill(d->qfrc_applied, d->qfrc_applied + nv, 0.0);
    for (size_t c = 0; c < tendon_id_.size(); ++c) {
      const Cable& cable = model_.cables[c];
      const int tendon = tendon_id_[c];
      const double tension =
          CableTension(d->ten_length[tendon], d->ten_velocity[tendon], rest_length_m_[c],
                       cable.stiffness_n_per_m, cable.damping_n_s_per_m, model_.damping_cap);
      if (tension <= 0.0) continue;
      if (sparse_jacobian_) {
        const int start = d->ten_J_rowadr[tendon];
        for (int k = 0; k < d->ten_J_rownnz[tendon]; ++k) {
          d->qfrc_applied[d->ten_J_colind[start + k]] -= tension * d->ten_J[start + k];
        }
      } else {
        const mjtNum* row = d->ten_J + static_cast<ptrdiff_t>(tendon) * nv;
        for (int j = 0; j < nv; ++j) d->qfrc_applied[j] -= tension * row[j];
      }
    }
    mj_step2(m, d);
  } catch (const MujocoError& e) {
    return OutOfRangeError(std::string("mujoco error at t ") + FormatFixed(d->time, 4) +
                           " s: " + e.what());
  }
  if (d->warning[mjWARN_BADQACC].number > 0 || d->warning[mjWARN_BADQPOS].number > 0 ||
      d->warning[mjWARN_BADQVEL].number > 0) {
    return OutOfRangeError("mujoco diverged at t " + FormatFixed(d->time, 4) + " s" +
                           (last_warning.empty() ? "" : ": " + last_warning));
  }
  if (!hinge_qpos_.empty()) hinge_error_rad_ = hinge_angle_rad - d->qpos[hinge_qpos_[0]];
  return Status::Ok();
}

State MujocoSimulation::Snapshot() const {
  mjModel* m = mj_model_;
  mjData* d = mj_data_;
  // mj_step leaves the kinematics of the step's start: bring them to the current qpos
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  State state;
  state.time_s = d->time;
  state.bodies.resize(model_.bodies.size());
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    const int id = body_id_[b];
    BodyState& body = state.bodies[b];
    body.position_m = Vec3(d->xpos[3 * id], d->xpos[3 * id + 1], d->xpos[3 * id + 2]);
    body.orientation =
        Quat(d->xquat[4 * id], d->xquat[4 * id + 1], d->xquat[4 * id + 2], d->xquat[4 * id + 3]);
    // rotation then translation, world axes, at the body frame's origin (mjOBJ_BODY would
    // give the translation at the centre of mass)
    mjtNum velocity[6];
    mj_objectVelocity(m, d, mjOBJ_XBODY, id, velocity, 0);
    body.angular_velocity_rad_per_s = Vec3(velocity[0], velocity[1], velocity[2]);
    body.velocity_m_per_s = Vec3(velocity[3], velocity[4], velocity[5]);
  }
  state.rest_length_m = rest_length_m_;
  state.hinge_angle_rad.resize(hinge_qpos_.size());
  state.hinge_rate_rad_per_s.resize(hinge_qpos_.size());
  for (size_t h = 0; h < hinge_qpos_.size(); ++h) {
    state.hinge_angle_rad[h] = d->qpos[hinge_qpos_[h]];
    state.hinge_rate_rad_per_s[h] = d->qvel[hinge_dof_[h]];
  }
  state.foot_normal_impulse_n_s.assign(model_.feet.size(), 0.0);
  return state;
}

Sample MujocoSimulation::SampleNow() const { return SampleState(model_, Snapshot()); }

std::array<double, 4> MujocoSimulation::MarkerSiteHeights() const {
  mj_kinematics(mj_model_, mj_data_);
  std::array<double, 4> heights;
  for (size_t f = 0; f < 4; ++f) {
    const int site = marker_site_[f];
    heights[f] = site < 0 ? std::nan("") : mj_data_->site_xpos[3 * site + 2];
  }
  return heights;
}

double MujocoSimulation::time_s() const { return mj_data_->time; }
int MujocoSimulation::contact_count() const { return mj_data_->ncon; }
int MujocoSimulation::constraint_rows() const { return mj_data_->nefc; }

double MujocoSimulation::max_penetration_m() const {
  double deepest = 0.0;
  for (int i = 0; i < mj_data_->ncon; ++i) deepest = std::max(deepest, -mj_data_->contact[i].dist);
  return deepest;
}

Result<ExperimentResult> RunExperimentInMujoco(const ModelDescription& description,
                                               const ExperimentOptions& options,
                                               const MujocoRunOptions& run_options,
                                               MujocoRunDiagnostics* diagnostics) {
  if (run_options.substeps < 1 || run_options.substeps > 1000) {
    return InvalidArgumentError("substeps: expected an integer in [1, 1000], got " +
                                std::to_string(run_options.substeps));
  }
  LIFTOFF_ASSIGN_OR_RETURN(Model model, BuildExperimentModel(description, options));
  const Procedure procedure(model, options);
  LiftoffRecorder recorder(model, options);
  MjcfOptions mjcf = run_options.mjcf;
  mjcf.time_step_s = procedure.time_step_s() / run_options.substeps;
  mjcf.lift_m = options.drop_height_m;
  // MuJoCo's floor for constraint time constants: two of its steps
  if (mjcf.contact_time_constant_s > 0.0) {
    mjcf.contact_time_constant_s = std::max(mjcf.contact_time_constant_s, 2.0 * mjcf.time_step_s);
  }
  if (mjcf.hinge_time_constant_s > 0.0) {
    mjcf.hinge_time_constant_s = std::max(mjcf.hinge_time_constant_s, 2.0 * mjcf.time_step_s);
  }
  LIFTOFF_ASSIGN_OR_RETURN(std::unique_ptr<MujocoSimulation> simulation,
                           MujocoSimulation::Create(model, mjcf));
  MujocoRunDiagnostics report;
  std::vector<double> rest(model.cables.size());
  // deepest penetration per sample period, to cut at the first liftoff afterwards
  std::vector<std::pair<double, double>> penetration_by_sample;
  double deepest_m = 0.0;
  int64_t step = 1;
  for (; step <= procedure.step_count(); ++step) {
    for (int sub = 1; sub <= run_options.substeps; ++sub) {
      // each MuJoCo step commanded at its own end time
      const double t_s =
          procedure.TimeAt(step - 1) + procedure.time_step_s() * sub / run_options.substeps;
      procedure.RestLengthsAt(t_s, rest);
      const double angle_rad = procedure.HingeAngleAt(t_s);
      LIFTOFF_RETURN_IF_ERROR(simulation->Step(rest, angle_rad));
      ++report.mujoco_steps;
      if (t_s >= options.ramp_start_s) {
        report.max_hinge_error_rad =
            std::max(report.max_hinge_error_rad, std::abs(simulation->hinge_error_rad()));
      }
      if (t_s >= 1.0) deepest_m = std::max(deepest_m, simulation->max_penetration_m());
    }
    if (procedure.IsSampleStep(step)) {
      penetration_by_sample.emplace_back(procedure.TimeAt(step), deepest_m);
      deepest_m = 0.0;
      Sample sample = simulation->SampleNow();
      sample.time_s = procedure.TimeAt(step);  // the procedure's clock, as RunExperiment
      recorder.Add(sample);
      if (recorder.CanStop()) break;
    }
  }
  ExperimentResult result = recorder.Finish();
  result.steps = std::min(step, procedure.step_count());
  double first_liftoff_s = std::numeric_limits<double>::infinity();
  for (const FootLiftoff& foot : result.feet) {
    if (foot.lifted) first_liftoff_s = std::min(first_liftoff_s, foot.time_s);
  }
  for (const auto& [time_s, depth_m] : penetration_by_sample) {
    if (time_s <= first_liftoff_s)
      report.max_penetration_m = std::max(report.max_penetration_m, depth_m);
  }
  if (diagnostics != nullptr) *diagnostics = report;
  return result;
}

}  // namespace liftoff::sim::mujoco
