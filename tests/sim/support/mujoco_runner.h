// Test and benchmark support, not product: liftoff's experiment run in MuJoCo 2.2.2 on the
// model ExportMjcf writes, so the two engines can be compared on the same rigid bodies,
// cables, contacts and commands. Built (target liftoff_mujoco_runner) only where CMake
// finds MuJoCo.
//
// Per MuJoCo step (mj_step1 / mj_step2 split, so the forces see this step's state):
//   1. the commanded hinge angle goes into the drive (eq_data[0] of the equality, or the
//      servo's ctrl);
//   2. mj_step1: positions, tendon lengths ten_length and Jacobians ten_J, velocities
//      ten_velocity;
//   3. each cable's tension from liftoff's own law, CableTension(ten_length, ten_velocity,
//      commanded rest length, k, c, damping cap), applied as generalised forces
//      qfrc_applied = -sum_i T_i * ten_J_i (explicit: MuJoCo has no implicit path for
//      applied forces);
//   4. mj_step2: constraint forces (contacts, hinge), semi-implicit Euler.
// Samples convert MuJoCo's body poses (xpos, xquat: the export keeps liftoff's body
// frames) into a liftoff State and call the experiment's SampleState, so both engines'
// samples come from the same code.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "liftoff/core/status.h"
#include "liftoff/sim/engine.h"
#include "liftoff/sim/experiment.h"
#include "liftoff/sim/mjcf.h"
#include "liftoff/sim/model.h"

struct mjModel_;
struct mjData_;

namespace liftoff::sim::mujoco {

/// Installs handlers for MuJoCo's errors (thrown as exceptions and turned into a Status
/// at this library's edge; MuJoCo's default waits for Enter) and warnings (counted).
/// Called by everything below; safe to call more than once.
void InstallMujocoHandlers();

/// A MuJoCo model and data loaded from ExportMjcf's text (in memory, through a virtual
/// file system), stepping with liftoff's cable law.
class MujocoSimulation {
 public:
  /// Exports `model` with `options` and loads it. `model` must outlive the simulation.
  /// kInvalidArgument for bad options; kParse when MuJoCo rejects the file (its message).
  static Result<std::unique_ptr<MujocoSimulation>> Create(const Model& model,
                                                          const MjcfOptions& options);
  ~MujocoSimulation();
  MujocoSimulation(const MujocoSimulation&) = delete;
  MujocoSimulation& operator=(const MujocoSimulation&) = delete;

  /// One MuJoCo step with these commands: each cable's rest length, m (one per model
  /// cable), and the hinge angle, rad (every hinge gets the same; the experiment has one).
  /// kOutOfRange when MuJoCo flags a diverging state (bad qacc) or a MuJoCo error.
  Status Step(std::span<const double> rest_length_m, double hinge_angle_rad);

  /// The current state as liftoff's State: body poses from xpos/xquat, velocities from
  /// mj_objectVelocity, hinge angle from qpos, `rest_length_m` as last commanded. Brings
  /// MuJoCo's kinematics up to the current qpos first (mj_step leaves those of the step's
  /// start), which is why it mutates the MuJoCo data.
  State Snapshot() const;
  /// SampleState of Snapshot(), at MuJoCo's time.
  Sample SampleNow() const;
  /// Height of each foot's marker site, m, indexed by Foot (the site itself, not liftoff's
  /// computation: checks the export's geometry).
  std::array<double, 4> MarkerSiteHeights() const;

  /// MuJoCo's time, s; contacts and constraint rows in the last step.
  double time_s() const;
  int contact_count() const;
  int constraint_rows() const;
  /// Largest penetration of any contact in the last step, m (>= 0).
  double max_penetration_m() const;
  /// Commanded minus actual hinge angle at the last step, rad.
  double hinge_error_rad() const { return hinge_error_rad_; }

  /// The MuJoCo objects (for benchmarks), and the exported text.
  const mjModel_* mujoco_model() const { return mj_model_; }
  mjData_* mujoco_data() const { return mj_data_; }
  const std::string& mjcf() const { return mjcf_; }

 private:
  MujocoSimulation(const Model& model, const MjcfOptions& options);
  Status Load();

  const Model& model_;
  MjcfOptions options_;
  std::string mjcf_;
  mjModel_* mj_model_ = nullptr;
  mjData_* mj_data_ = nullptr;
  bool sparse_jacobian_ = false;
  std::vector<int> body_id_;      // per model body
  std::vector<int> tendon_id_;    // per model cable
  std::vector<int> hinge_qpos_;   // per model hinge: qpos address
  std::vector<int> hinge_dof_;    // per model hinge: dof address
  std::vector<int> hinge_drive_;  // per model hinge: equality or actuator id
  std::vector<int> marker_site_;  // per Foot (-1 when absent)
  std::vector<double> rest_length_m_;
  double hinge_error_rad_ = 0.0;
};

struct MujocoRunOptions {
  /// The export's contact and drive settings; its time_step_s and lift_m are replaced by
  /// the experiment's (time step / substeps, drop height), and its time constants raised
  /// to at least two MuJoCo steps (MuJoCo's own floor).
  MjcfOptions mjcf;
  /// MuJoCo steps per liftoff time step (>= 1); commands follow the Procedure at each
  /// MuJoCo step's own time.
  int substeps = 1;
};

/// What the MuJoCo run looked like, beyond the result.
struct MujocoRunDiagnostics {
  /// Largest |commanded - actual| hinge angle during the ramp, rad.
  double max_hinge_error_rad = 0.0;
  /// Largest contact penetration from t = 1 s to the first liftoff (or the end), m:
  /// transients of feet landing; standing feet sink < 1e-6 m.
  double max_penetration_m = 0.0;
  /// MuJoCo steps taken.
  int64_t mujoco_steps = 0;
};

/// RunExperiment's twin in MuJoCo: BuildExperimentModel, Procedure, LiftoffRecorder, the
/// same stop rule. kOutOfRange when MuJoCo diverges.
Result<ExperimentResult> RunExperimentInMujoco(const ModelDescription& description,
                                               const ExperimentOptions& options,
                                               const MujocoRunOptions& run_options = {},
                                               MujocoRunDiagnostics* diagnostics = nullptr);

}  // namespace liftoff::sim::mujoco
