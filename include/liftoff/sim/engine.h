// The engine: advances a State of a (constant) Model by one time step.
//
// Integrator (one step of length dt):
//   1. forces at the start of the step: gravity, cables (tension-only spring-dampers,
//      T = k (x - r) + c x' while x > r, with x' the rate of lengthening; with the model's
//      damping cap |c x'| <= k (x - r)), gyroscopic terms;
//   2. velocities, linearly implicit in the cable damping (and, as an option, stiffness):
//      (M - dt D - dt^2 K) (v+ - v) = dt f, with D = df/dv and K = df/dq of the cables
//      (Baraff-Witkin); without damping and with K off this is exactly symplectic Euler,
//      so an undamped spring keeps its energy. A cable taut at the start applies over the
//      step T + c (x'+ - x') (+ dt k x'+ with implicit stiffness), x'+ its rate at the new
//      velocities; the law allows only 0 .. 2 k (x - r) (with the cap; else >= 0), so after
//      steps 2 and 3 a cable whose applied tension left that range is held at the bound it
//      crossed (explicit, constant over the step) and steps 2 and 3 are solved again, until
//      none leaves it (held cables stay held: at most one pass more per cable; in practice
//      a second pass in a few steps of a run, while cables go slack);
//   3. contacts: velocity-level impulses on top of step 2 through the same matrix
//      (restitution r: the normal velocity leaves at >= r times its arrival speed; 0 by
//      default), Coulomb friction in a circular cone, penetration removed by a bias of
//      `contact_bias` x depth per step, approaching contacts caught before they touch;
//      solved by projected Gauss-Seidel on the exact Delassus matrix, warm-started;
//   4. positions from the new velocities (orientation by the exact rotation vector).
// A hinge's child is not a free body: its pose is its parent's turned by the commanded
// angle (kinematic drive; the child's mass and inertia join its parent's, recomputed at
// every step for the current angle, ignoring the tiny inertial effect of the hinge's
// own rate: the paper's ramp turns at 0.026 rad/s).
//
// Deterministic: no threads, no clocks, fixed iteration counts and orders; the same model,
// controls and state give bit-identical results. Step allocates nothing after the first
// call on a State (scratch lives in the State).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "liftoff/core/status.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {

struct EngineOptions {
  /// Time step, s (1e-6 .. 0.01).
  double time_step_s = 1e-3;
  /// Also treat cable stiffness implicitly (more stable for large steps, damps
  /// oscillations numerically; off keeps undamped springs energy-conserving).
  bool implicit_stiffness = false;
  /// Fraction of a contact's penetration removed per step (0 .. 1).
  double contact_bias = 0.2;
  /// Contacts are generated for geometry within this distance above the ground, m (>= 0).
  double contact_margin_m = 0.005;
  /// Projected Gauss-Seidel sweeps per step (1 .. 1000) and the impulse change, N*s,
  /// below which it stops early (>= 0; 0: always all sweeps).
  int solver_iterations = 50;
  double solver_tolerance_n_s = 1e-10;

  Status Validate() const;
};

/// Pose and velocity of one body.
struct BodyState {
  /// Body frame origin in the world, m.
  Vec3 position_m = Vec3::Zero();
  /// Body frame orientation in the world (unit quaternion).
  Quat orientation = Quat::Identity();
  /// Velocity of the body frame origin, m/s, world frame.
  Vec3 velocity_m_per_s = Vec3::Zero();
  /// Angular velocity, rad/s, world frame.
  Vec3 angular_velocity_rad_per_s = Vec3::Zero();
};

/// One contact of the last step (scratch of Step, also readable for diagnostics).
struct ContactPoint {
  /// Which geometry (a stable key: the same pair of shapes gives the same key).
  int64_t key = 0;
  /// Bodies in contact: body_a is -1 for the ground; body_b is never -1.
  int body_a = -1;
  int body_b = -1;
  /// Contact points on each side, world, m; unit normal from a to b.
  Vec3 point_a_m = Vec3::Zero();
  Vec3 point_b_m = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  /// Signed distance, m (< 0: penetrating).
  double gap_m = 0.0;
  double friction = 0.0;
  /// Index into Model::feet when this is a foot on the ground, else -1.
  int foot = -1;
  /// First row in the contact system and number of rows (1 without friction, else 3).
  int first_row = 0;
  int rows = 1;
  /// Normal velocity the solution must reach at least, m/s.
  double target_normal_velocity_m_per_s = 0.0;
};

/// One cable's part in a step (scratch of Step).
struct CableStepTerm {
  enum Mode { kNone, kImplicit, kHeld };
  /// kNone: slack, or inside one rigid cluster (no net force); kImplicit: in the system
  /// matrix; kHeld: a constant tension `held_tension_n` on the right-hand side.
  Mode mode = kNone;
  int cluster_a = 0;
  int cluster_b = 0;
  /// d(length rate)/d(velocities of cluster a and of cluster b).
  Eigen::Matrix<double, 6, 1> row_a = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> row_b = Eigen::Matrix<double, 6, 1>::Zero();
  /// At the start of the step: tension, N, length rate, m/s, and stretch x - r, m.
  double tension_n = 0.0;
  double rate_m_per_s = 0.0;
  double stretch_m = 0.0;
  double held_tension_n = 0.0;
};

/// Scratch buffers of Step (not part of the physical state; never hashed). Sized on the
/// first step and grown only when more contacts appear than ever before; copying a State
/// copies them (harmless).
struct StepScratch {
  int dofs = 0;
  int band = 5;                          // lower bandwidth of the system matrix
  std::vector<int> cluster_of_body;      // free body (cluster root) each body moves with
  std::vector<int> cluster_root;         // per cluster: its free body
  std::vector<Mat3> rotation;            // per body, world from body
  std::vector<Vec3> rod_bound_center;    // per body: sphere around its colliding rods
  std::vector<double> rod_bound_radius;  // (body frame; radius < 0: no colliding rods)
  std::vector<Vec3> hinge_axis_world;    // per body: axis of its driving hinge (else 0)
  std::vector<Vec3> hinge_point_world;   // per body: a point on that axis
  std::vector<double> hinge_rate;        // per body: rate of its driving hinge, rad/s
  Eigen::MatrixXd system;    // M - dt D - dt^2 K (lower triangle), then its Cholesky factor
  Eigen::VectorXd rhs;       // dt f, then the velocity change
  Eigen::VectorXd velocity;  // generalised velocities (per cluster: origin v, omega)
  Eigen::VectorXd start_velocity;
  std::vector<ContactPoint> contacts;
  Eigen::MatrixXd contact_jacobian;  // rows x dofs (capacity)
  // dofs x (1 + rows) (capacity), row-major: the free velocity change, then A^-1 J^T
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> solution;
  std::vector<CableStepTerm> cable_terms;  // per cable
  Eigen::MatrixXd delassus;                // rows x rows (capacity)
  Eigen::VectorXd row_velocity;            // rows
  Eigen::VectorXd contact_impulse;         // rows
};

/// Everything that changes during a run.
struct State {
  /// Simulated time, s, and steps taken.
  double time_s = 0.0;
  int64_t step_count = 0;
  /// One per Model::bodies (hinge children are kept up to date too).
  std::vector<BodyState> bodies;
  /// Rest length of each cable during the last step, m.
  std::vector<double> rest_length_m;
  /// Angle of each hinge, rad, and its rate over the last step, rad/s.
  std::vector<double> hinge_angle_rad;
  std::vector<double> hinge_rate_rad_per_s;
  /// Normal impulse of each foot's ground contact over the last step, N*s (0: no contact).
  std::vector<double> foot_normal_impulse_n_s;
  /// Tension each cable applied over the last step (its impulse / dt), N: within the
  /// law's range (>= 0, and <= 2 k (x - r) with the damping cap); 0 while slack.
  std::vector<double> cable_tension_n;
  /// Contact impulses of the last step by contact key (warm start of the next step): per
  /// contact its key, and three impulses (normal, two tangents), N*s.
  std::vector<int64_t> warm_contact_key;
  std::vector<double> warm_contact_impulse_n_s;
  StepScratch scratch;
};

/// What to command during a step: values in effect at the end of the step.
struct Controls {
  /// Rest length of each cable, m (> 0); empty: keep the state's.
  std::vector<double> rest_length_m;
  /// Angle of each hinge at the end of the step, rad; empty: keep the state's.
  std::vector<double> hinge_angle_rad;
};

/// The built pose raised by `lift_m` (the drop height), at rest, with the model's rest
/// lengths and every hinge at angle 0.
State InitialState(const Model& model, double lift_m = 0.0);

/// Advances `state` by options.time_step_s. Controls are checked only by assert (sizes);
/// options must have passed Validate().
/// A step whose system cannot be solved (stiffness or damping beyond what the time step
/// resolves) leaves NaN velocities, which DescribeDivergence reports.
void Step(const Model& model, const EngineOptions& options, const Controls& controls, State& state);

/// Bounds of a physical state: body origins within this distance of the world origin, m,
/// and speeds below these (the robot is a metre across and moves at centimetres a second).
inline constexpr double kMaxPhysicalDistance_m = 1e3;
inline constexpr double kMaxPhysicalSpeed_m_per_s = 1e3;
inline constexpr double kMaxPhysicalAngularSpeed_rad_per_s = 1e5;

/// Empty when `state` is physical: every body's position, orientation and velocities
/// finite and within the bounds above, every hinge angle and rest length finite. Else what
/// is not, naming the body: "body \"pelvis\": velocity is not finite". Checked in every
/// build type (not an assert): a diverged run is an outcome a user's options can cause.
std::string DescribeDivergence(const Model& model, const State& state);

/// One cable's current geometry and tension.
struct CableReading {
  /// Anchor-to-anchor length, m, and its rate of change, m/s.
  double length_m = 0.0;
  double length_rate_m_per_s = 0.0;
  /// Tension, N (>= 0; exactly 0 while length <= rest length).
  double tension_n = 0.0;
  /// World positions of the two anchors, m.
  Vec3 anchor_a_world_m = Vec3::Zero();
  Vec3 anchor_b_world_m = Vec3::Zero();
};
CableReading ReadCable(const Model& model, const State& state, int cable);

/// The tension law on its own: k (x - r) + c x' for x > r (damping term capped at the
/// spring term's magnitude when `damping_cap`), never below 0, and exactly 0 for x <= r.
double CableTension(double length_m, double length_rate_m_per_s, double rest_length_m,
                    double stiffness_n_per_m, double damping_n_s_per_m, bool damping_cap);

/// World position of a point given in a body's frame, m.
Vec3 WorldPoint(const State& state, int body, const Vec3& point_body_m);
/// Height above the ground of each foot's marker, m, indexed by Foot (NaN when the model
/// has no such foot).
std::array<double, 4> FootMarkerHeights(const Model& model, const State& state);
/// Lowest point of any colliding geometry that is not a foot sphere (rods as capsules,
/// boxes, other spheres; shapes with collides false are left out), m above the ground;
/// +infinity when there is none.
double LowestNonFootPoint(const Model& model, const State& state);

/// Kinetic energy, J, and potential energy of gravity and of the cables' springs, J
/// (relative to zero height and slack cables).
double KineticEnergy(const Model& model, const State& state);
double PotentialEnergy(const Model& model, const State& state);

/// FNV-1a hash of the physical state's bytes (time, poses, velocities, rest lengths,
/// hinge angles and rates, foot and cable diagnostics of the last step, warm-start
/// impulses); scratch excluded. Equal states give
/// equal hashes; any bit of difference almost surely changes it.
uint64_t StateHash(const State& state);

}  // namespace liftoff::sim
