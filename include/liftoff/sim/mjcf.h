// The simulation model as a MuJoCo 2.2.2 MJCF file: text only (no MuJoCo dependency), so
// users can open the robot in MuJoCo's `simulate` and so liftoff's engine can be checked
// against an established one (tests/sim/mujoco_test.cc runs the file through the
// experiment's Procedure).
//
// What the file holds (names in quotes; <...> is a name from the model):
//   bodies        every free body a <body name="<body>"> under the world with a
//                 <freejoint name="<body>/free"/>; a hinge's child a <body> nested in its
//                 parent with a <joint type="hinge" name="<hinge>">. Body frames are
//                 liftoff's body frames (pos/quat of the built pose, free bodies raised by
//                 lift_m), so MuJoCo's xpos/xquat are liftoff's BodyState poses.
//   inertia       an explicit <inertial> per body with liftoff's mass, centre of mass and
//                 full inertia tensor (compiler inertiafromgeom="false": the geoms carry
//                 no mass), so both engines integrate the same rigid bodies. A hinge child
//                 keeps its own inertia (liftoff merges it into the parent, see engine.h).
//   geoms         "<body>/<shape>": rods as capsules (size = radius, fromto = the rod's
//                 ends), boxes, spheres. Feet collide with the ground; other shapes
//                 collide with the ground only with the model's spine_ground, rods of
//                 different bodies with each other only with spine_self (MuJoCo itself
//                 never collides a body with its parent, as liftoff's hinge parent and
//                 child never collide). Shapes with collides=false are visual only.
//   ground        geom "ground": the plane z = 0.
//   friction      the model's coefficient on every geom (MuJoCo combines two geoms'
//                 friction by taking the larger, so the pair gets exactly that value);
//                 condim 1 (frictionless) when it is 0, else condim 3 with an elliptic
//                 (circular) cone like liftoff's.
//   contact       MuJoCo's contacts are soft: solref = (contact_time_constant_s, damping
//                 ratio), solimp = (impedance, impedance, width). The defaults (two time
//                 steps = 2 ms at the default 1 ms step, critically damped, 0.99) make a stiff
//                 contact that does not bounce (liftoff's restitution 0): a standing foot sinks
//                 2e-7 .. 5e-7 m, far below the 1 mm liftoff threshold (a foot landing at speed
//                 sinks up to about its speed x 2 ms for a few steps). A restitution above 0 is
//                 written as a comment only: MuJoCo has no restitution coefficient.
//   markers       sites "marker_<foot>" at each foot's marker (what the liftoff rule reads).
//   cables        sites "<cable>/from" and "<cable>/to" at the cable's anchors, and a
//                 <spatial> tendon "<cable>" through them, springlength = the model's rest
//                 length, stiffness 0 and damping 0: MuJoCo's tendon springs push as well as
//                 pull, so a runner applies the tension-only law (CableTension) itself,
//                 e.g. qfrc_applied = -T * ten_J row. A comment per group gives k, c, T0.
//   hinge drive   kEquality: an equality constraint "<hinge>/drive" holding the hinge at
//                 polycoef[0] (eq_data[0], rad); a runner writes the commanded angle there
//                 every step (stiff: solref two time steps, solimp 0.9999). kPositionActuator: a
//                 position servo "<hinge>/servo" (ctrl = angle, rad) with the joint's own
//                 damping, for playing with the slider in `simulate`.
//   world         <option timestep, gravity, integrator Euler, cone elliptic>.
// The text is deterministic: the same model and options give the same bytes.
#pragma once

#include <filesystem>
#include <string>

#include "liftoff/core/status.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {

/// How the MJCF drives a hinge to its commanded angle.
enum class MjcfHingeDrive {
  /// An equality constraint holding the joint at a value a runner sets each step
  /// (closest to liftoff's kinematic drive).
  kEquality,
  /// A position actuator (ctrl = angle) and joint damping.
  kPositionActuator,
};
/// "equality" or "actuator".
std::string_view MjcfHingeDriveName(MjcfHingeDrive drive);

struct MjcfOptions {
  /// MuJoCo's time step, s (1e-6 .. 0.01; liftoff's EngineOptions default is 1e-3).
  double time_step_s = 1e-3;
  /// Free bodies are raised by this much above the built pose, m (0 .. 1; the experiment's
  /// drop height makes the file start the drop; 0: feet on the ground).
  double lift_m = 0.0;

  /// Contact solref: time constant, s (0: two time steps, MuJoCo's own floor and the
  /// stiffest it allows; else >= 2 x time_step_s), and damping ratio (> 0; 1: critically
  /// damped, no bounce).
  double contact_time_constant_s = 0.0;
  double contact_damping_ratio = 1.0;
  /// Contact solimp: impedance at any penetration (0 .. 0.9999; closer to 1 is harder)
  /// and the width over which MuJoCo would blend it, m (> 0).
  double contact_impedance = 0.99;
  double contact_impedance_width_m = 0.001;

  /// MuJoCo's noslip iterations (0 .. 1000; 0: off): a post-pass that removes the slip
  /// soft friction allows, for contacts closer to liftoff's rigid Coulomb friction.
  int noslip_iterations = 0;

  MjcfHingeDrive hinge_drive = MjcfHingeDrive::kEquality;
  /// kEquality: the constraint's solref time constant, s (0: two time steps; else
  /// >= 2 x time_step_s), and solimp impedance (0 .. 0.9999).
  double hinge_time_constant_s = 0.0;
  double hinge_impedance = 0.9999;
  /// kPositionActuator: servo gain, N*m/rad (> 0), and joint damping, N*m*s/rad (>= 0).
  double hinge_gain_n_m_per_rad = 200.0;
  double hinge_damping_n_m_s_per_rad = 1.0;

  /// Drawn width of the cables, m (> 0; no physical effect).
  double cable_width_m = 0.002;

  Status Validate() const;
};

/// The model as MJCF text. kInvalidArgument for bad options. The model is what
/// BuildModel (or the experiment's BuildExperimentModel, which applies a tension point
/// and the pulled side) made; rest lengths, stiffnesses and pretensions are the model's.
Result<std::string> ExportMjcf(const Model& model, const MjcfOptions& options = {});

/// ExportMjcf written to `path` (atomically; parent folders created). kIo when writing
/// fails.
Status WriteMjcf(const std::filesystem::path& path, const Model& model,
                 const MjcfOptions& options = {});

/// Names the export gives, for runners that look things up in the loaded model.
std::string MjcfFreeJointName(const Model& model, int body);
std::string MjcfCableSiteName(const Model& model, int cable, bool from_end);
std::string MjcfMarkerSiteName(Foot foot);
std::string MjcfHingeDriveElementName(const Model& model, int hinge, MjcfHingeDrive drive);

}  // namespace liftoff::sim
