// The simulated robot: rigid bodies made of rods, boxes and spheres, a driven hinge,
// tension-only spring-damper cables between named nodes, feet on a flat ground.
//
// Two layers:
//   ModelDescription  what the JSON file says, field by field (editable: the experiment
//                     copies it and overrides stiffnesses, attachment, friction, ...);
//   Model             the description plus everything derived from it by BuildModel()
//                     (masses, inertias, cable anchors, rest lengths, indices). Constant
//                     during a run; shared read-only by any number of runs.
//
// World frame (ours, used everywhere in liftoff's simulation): x forward (towards the
// robot's head), y to the robot's left, z up; the ground is the plane z = 0. In the Laika
// file (samples/models/laika.json) the origin is on the ground under vertebra 3's centre.
// (The source model NTRTsim used x backwards, y up, z left: ours = (-x, z, y) of theirs.)
//
// ---------------------------------------------------------------------------------------
// File format "liftoff-sim-model", version 1 (all lengths m, masses kg, angles rad):
//
//   {"format": "liftoff-sim-model", "version": 1,
//    "name": "laika-ntrt", "description": "...",             (description optional)
//    "gravity_m_per_s2": [0, 0, -9.81],
//    "contact": {"friction": 0.0, "spine_friction": 0.5, "restitution": 0.0,
//                "spine_ground": true, "spine_self": true},   (all optional)
//    "cable_attachment": "surface",          ("node" | "surface"; optional, "surface")
//    "rest_length_reference": "attachment",  ("attachment" | "node"; optional)
//    "damping_cap": true,                    (optional, true)
//    "foot_marker_height_m": 0.0,            (optional, 0: markers at the feet's bottoms)
//    "bodies": [
//      {"name": "v2",
//       "position_m": [-0.099, 0, 0.191],      body frame origin in the world at build
//       "orientation_wxyz": [1, 0, 0, 0],      optional unit quaternion, identity
//       "nodes": {"center": [0, 0, 0], "top": [0.065, 0, 0.096], ...},   body frame
//       "rods": [{"name": "top", "from": "center", "to": "top",
//                 "radius_m": 0.0064, "density_kg_per_m3": 2423,
//                 "collides": true}],        (collides optional, true)
//       "boxes": [{"name": "hips", "center_m": [...], "size_m": [lx, ly, lz],
//                  "density_kg_per_m3": 425, "collides": true}],  axes = body axes
//       "spheres": [{"name": "foot_C", "center_m": [...], "radius_m": 0.0125,
//                    "density_kg_per_m3": 425, "foot": "C"}]}],  (foot optional)
//    "hinges": [{"name": "rotating_vertebra", "parent": "v3a", "child": "v3b",
//                "point_m": [0, 0, 0], "axis": [-1, 0, 0]}],      parent body frame
//    "cable_groups": [{"name": "HT", "material": "silicone", "stiffness_n_per_m": 237,
//                      "damping_n_s_per_m": 10, "pretension_n": 1.422}],
//    "cables": [{"name": "HT1", "group": "HT", "from": "rear/top", "to": "v2/top"}]}
//
// Every body needs a positive mass (at least one shape with a positive density), nodes
// are referred to as "<body>/<node>", a hinge's child is driven relative to its parent
// (parent must itself be free: no chains), and a foot letter appears at most once.
// Errors name the file and the JSON pointer: "laika.json: /cables/3/to: unknown node
// \"v2/tip\"; body v2 has bottom, center, left, right, top".
// ---------------------------------------------------------------------------------------
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json_fwd.hpp>

#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"

namespace liftoff::sim {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

/// Where a cable's end sits on its body.
enum class CableAttachment {
  /// Exactly on the named node (a rod's tip).
  kNode,
  /// On the surface of the rod that ends at the node, as NTRTsim built it: the node moved
  /// by the rod radius perpendicular to the rod, towards the cable's other node (a
  /// horizontal Laika cable is then 0.0887 m long instead of 0.099 m). Nodes that end no
  /// rod, or end several, are used as they are.
  kSurface,
};
/// "node" or "surface".
std::string_view CableAttachmentName(CableAttachment attachment);

/// Which distance a cable's rest length is computed from: rest = distance - T0 / k.
enum class RestLengthReference {
  /// The distance between the cable's two attachment points at build (NTRTsim's rule:
  /// the pretension is exactly T0 in the built pose, whatever the attachment).
  kAttachment,
  /// The node-to-node distance, whatever the attachment (with surface attachment the
  /// cables start about 0.01 m slacker than T0 / k: what a re-implementation gets when it
  /// takes the documented lengths at face value).
  kNode,
};
/// "attachment" or "node".
std::string_view RestLengthReferenceName(RestLengthReference reference);

// ---------------------------------------------------------------------------------------
// description: what the file says

struct RodDescription {
  std::string name;
  /// Node names (in the same body) of the rod's ends.
  std::string from_node;
  std::string to_node;
  /// Radius, m (> 0), and density, kg/m^3 (>= 0; 0: massless). A solid cylinder without
  /// end caps for the mass; a capsule (cylinder plus end hemispheres) for contact.
  double radius_m = 0.0;
  double density_kg_per_m3 = 0.0;
  /// Takes part in spine-ground and spine-spine contact when those are enabled.
  bool collides = true;
};

struct BoxDescription {
  std::string name;
  /// Centre, m, in the body frame; edges parallel to the body axes.
  Vec3 center_m = Vec3::Zero();
  /// Full edge lengths along the body's x, y, z, m (each > 0).
  Vec3 size_m = Vec3::Zero();
  double density_kg_per_m3 = 0.0;
  bool collides = true;
};

struct SphereDescription {
  std::string name;
  /// Centre, m, in the body frame.
  Vec3 center_m = Vec3::Zero();
  double radius_m = 0.0;
  double density_kg_per_m3 = 0.0;
  /// When set, this sphere is that foot: it always collides with the ground and carries
  /// the foot's marker (its lowest point in the built pose).
  std::optional<Foot> foot;
};

struct NodeDescription {
  std::string name;
  /// Position, m, in the body frame.
  Vec3 position_m = Vec3::Zero();
};

struct BodyDescription {
  std::string name;
  /// Body frame origin in the world when the model is built, m.
  Vec3 position_m = Vec3::Zero();
  /// Body frame orientation in the world when built (unit quaternion).
  Quat orientation = Quat::Identity();
  std::vector<NodeDescription> nodes;
  std::vector<RodDescription> rods;
  std::vector<BoxDescription> boxes;
  std::vector<SphereDescription> spheres;
};

/// A hinge whose relative angle is commanded: the child's pose is the parent's, turned by
/// the angle about the axis through the point (both in the parent's frame), times the
/// child's built pose relative to the parent. Angle 0 is the built pose.
struct HingeDescription {
  std::string name;
  std::string parent;
  std::string child;
  /// A point on the axis, m, in the parent's body frame.
  Vec3 point_m = Vec3::Zero();
  /// Axis direction in the parent's body frame (normalised on build; not zero). A
  /// positive angle turns the child by the right-hand rule about the axis
  /// (counter-clockwise seen from the axis' tip).
  Vec3 axis = Vec3::UnitX();
};

/// Properties shared by all cables of a group.
struct CableGroupDescription {
  std::string name;
  /// Free text naming the material ("silicone", "buna_n", "spring").
  std::string material;
  /// Spring constant k, N/m (> 0), and damping c, N*s/m (>= 0).
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
  /// Tension in the built pose, N (>= 0): rest length = reference distance - T0 / k.
  double pretension_n = 0.0;
};

struct CableDescription {
  std::string name;
  std::string group;
  /// Ends: body and node names.
  std::string from_body;
  std::string from_node;
  std::string to_body;
  std::string to_node;
};

/// The ground and which geometry collides.
struct ContactDescription {
  /// Coulomb friction coefficient between feet (or any colliding geometry) and ground
  /// (>= 0). 0: frictionless, as in the runs behind the paper's Tables III/IV.
  double friction = 0.0;
  /// Friction coefficient of every other contact (spine and hips on the ground, rod on
  /// rod), >= 0; unset: `friction`. (NTRTsim's rods and boxes kept their own friction
  /// while the feet had none.)
  std::optional<double> spine_friction;
  /// Restitution (0 .. 1). 0: a foot that lands stays.
  double restitution = 0.0;
  /// Rods, boxes and non-foot spheres collide with the ground (feet always do).
  bool spine_ground = false;
  /// Rods of different bodies collide with each other (not a hinge's parent and child).
  bool spine_self = false;
};

struct ModelDescription {
  std::string name;
  std::string description;
  /// Gravity, m/s^2, world frame.
  Vec3 gravity_m_per_s2 = Vec3(0.0, 0.0, -9.81);
  ContactDescription contact;
  CableAttachment cable_attachment = CableAttachment::kSurface;
  RestLengthReference rest_length_reference = RestLengthReference::kAttachment;
  /// Cap the damping term of a cable's tension at the spring term's magnitude (NTRTsim).
  bool damping_cap = true;
  /// Height of each foot's marker above the foot's lowest point in the built pose, m
  /// (>= 0). 0: the marker is the foot's bottom. The marker stays fixed to the foot's body,
  /// so a raised marker also moves when that body pitches or rolls. (The logs behind the
  /// paper's Table IV put it 1.5 m up: an offset meant as 1.5 cm, kept when the model
  /// moved to metres.)
  double foot_marker_height_m = 0.0;
  std::vector<BodyDescription> bodies;
  std::vector<HingeDescription> hinges;
  std::vector<CableGroupDescription> cable_groups;
  std::vector<CableDescription> cables;
};

/// Parses a model file. kNotFound, kIo, kParse as LoadJsonFile; kInvalidArgument naming
/// file and JSON pointer for a bad, missing or unknown field; kUnsupported for another
/// format or a newer version. The result has passed BuildModel's checks too.
Result<ModelDescription> LoadModelDescription(const std::filesystem::path& path);
/// The same from parsed JSON; `source` names it in errors.
Result<ModelDescription> ModelDescriptionFromJson(const nlohmann::json& document,
                                                  const std::string& source);
/// The description in the file format (loads back to the same description).
nlohmann::json ModelDescriptionToJson(const ModelDescription& description);

// ---------------------------------------------------------------------------------------
// model: description plus derived quantities

/// A rod in its body's frame (for contact and export).
struct Rod {
  std::string name;
  Vec3 from_m = Vec3::Zero();
  Vec3 to_m = Vec3::Zero();
  double radius_m = 0.0;
  double mass_kg = 0.0;
  bool collides = true;
};

struct Box {
  std::string name;
  Vec3 center_m = Vec3::Zero();
  /// Half edge lengths along the body axes, m.
  Vec3 half_size_m = Vec3::Zero();
  double mass_kg = 0.0;
  bool collides = true;
};

struct Sphere {
  std::string name;
  Vec3 center_m = Vec3::Zero();
  double radius_m = 0.0;
  double mass_kg = 0.0;
  /// Index into Model::feet, or -1 for a sphere that is not a foot.
  int foot_index = -1;
  bool collides = true;
};

struct Body {
  std::string name;
  /// Sum of the shapes' masses, kg (> 0).
  double mass_kg = 0.0;
  /// Centre of mass, m, in the body frame.
  Vec3 com_m = Vec3::Zero();
  /// Inertia tensor about the centre of mass, body axes, kg*m^2.
  Mat3 inertia_kg_m2 = Mat3::Zero();
  /// Built pose in the world: frame origin, m, and orientation.
  Vec3 initial_position_m = Vec3::Zero();
  Quat initial_orientation = Quat::Identity();
  /// Index into Model::hinges of the hinge driving this body, or -1 for a free body.
  int driving_hinge = -1;
  std::vector<NodeDescription> nodes;
  std::vector<Rod> rods;
  std::vector<Box> boxes;
  std::vector<Sphere> spheres;
};

struct Hinge {
  std::string name;
  int parent = -1;
  int child = -1;
  /// Axis point, m, and unit axis, both in the parent's frame.
  Vec3 point_m = Vec3::Zero();
  Vec3 axis = Vec3::UnitX();
  /// Child frame relative to the parent frame at angle 0 (the built pose).
  Vec3 child_position_in_parent_m = Vec3::Zero();
  Quat child_orientation_in_parent = Quat::Identity();
};

struct Cable {
  std::string name;
  /// Index into Model::cable_groups (the group's name is cable_groups[group].name).
  int group = -1;
  /// Bodies and attachment points (anchors) in each body's frame, m.
  int body_a = -1;
  int body_b = -1;
  Vec3 anchor_a_m = Vec3::Zero();
  Vec3 anchor_b_m = Vec3::Zero();
  /// The named nodes themselves, body frames, m (equal to the anchors with kNode).
  Vec3 node_a_m = Vec3::Zero();
  Vec3 node_b_m = Vec3::Zero();
  /// From the group: k, N/m; c, N*s/m; T0, N.
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
  double pretension_n = 0.0;
  /// Anchor-to-anchor and node-to-node distances in the built pose, m.
  double initial_length_m = 0.0;
  double initial_node_length_m = 0.0;
  /// Rest length at the start of every run, m (> 0): reference distance - T0 / k.
  double rest_length_m = 0.0;
};

/// A foot: a sphere on a body, with a marker fixed to the body: the sphere's lowest point
/// in the built pose, raised by ModelDescription::foot_marker_height_m (what the paper's
/// foot-height curves track).
struct FootPoint {
  Foot foot = Foot::kA;
  int body = -1;
  /// Sphere centre and radius, body frame, m.
  Vec3 center_m = Vec3::Zero();
  double radius_m = 0.0;
  /// The marker, body frame, m.
  Vec3 marker_m = Vec3::Zero();
  /// The sphere's lowest point in the built pose, body frame, m.
  Vec3 bottom_m = Vec3::Zero();
};

struct Model {
  /// What it was built from (kept so a variant can be rebuilt with a change).
  ModelDescription description;
  std::vector<Body> bodies;
  std::vector<Hinge> hinges;
  std::vector<CableGroupDescription> cable_groups;
  std::vector<Cable> cables;
  std::vector<FootPoint> feet;
  /// Index into `feet` of each foot letter (by static_cast<int>(Foot)), -1 when absent.
  std::array<int, 4> foot_index = {-1, -1, -1, -1};
  /// Copies of the description's world settings.
  Vec3 gravity_m_per_s2 = Vec3::Zero();
  ContactDescription contact;
  bool damping_cap = true;
  /// Sum over bodies, kg.
  double total_mass_kg = 0.0;

  /// Index of the body or cable group with that name, -1 when none.
  int BodyIndex(std::string_view name) const;
  int CableGroupIndex(std::string_view name) const;
  /// Indices of the cables of a group, in file order (empty for an unknown group).
  std::vector<int> CablesInGroup(std::string_view group) const;
  /// "laika-ntrt: 6 bodies (1.443 kg), 1 hinge, 32 cables, 4 feet, surface attachment".
  std::string Brief() const;
};

/// Checks a description and derives the model. kInvalidArgument naming the JSON pointer
/// of the offending field (a negative stiffness, NaN, an unknown node or group, a body
/// without mass, a cable with both ends on one body, ...); kUnsupported for hinge chains.
/// `source` prefixes error messages (a file name; may be empty).
Result<Model> BuildModel(const ModelDescription& description, const std::string& source = "");
/// LoadModelDescription + BuildModel.
Result<Model> LoadModel(const std::filesystem::path& path);

/// Mass, centre of mass (body frame) and inertia about it (body axes) of a body's shapes.
struct MassProperties {
  double mass_kg = 0.0;
  Vec3 com_m = Vec3::Zero();
  Mat3 inertia_kg_m2 = Mat3::Zero();
};
/// Solid cylinder from `from_m` to `to_m` (no end caps), solid box, solid sphere.
MassProperties RodMassProperties(const Vec3& from_m, const Vec3& to_m, double radius_m,
                                 double density_kg_per_m3);
MassProperties BoxMassProperties(const Vec3& center_m, const Vec3& size_m,
                                 double density_kg_per_m3);
MassProperties SphereMassProperties(const Vec3& center_m, double radius_m,
                                    double density_kg_per_m3);
/// Sum of parts about their common centre of mass.
MassProperties CombineMassProperties(const std::vector<MassProperties>& parts);

/// The surface anchor of NTRTsim's tgRodInfo::getConnectionPoint: `node` moved by
/// `radius_m` perpendicular to the rod direction `rod_direction`, towards `destination`
/// (unchanged when the destination lies on the rod's axis line).
Vec3 SurfaceAnchor(const Vec3& node, const Vec3& rod_direction, double radius_m,
                   const Vec3& destination);

}  // namespace liftoff::sim
