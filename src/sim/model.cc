#include "liftoff/sim/model.h"

#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "liftoff/core/field_checker.h"
#include "liftoff/core/json.h"

namespace liftoff::sim {
namespace {

using nlohmann::json;

constexpr std::string_view kFormatName = "liftoff-sim-model";
constexpr int64_t kFormatVersion = 1;
// Two nodes closer than this are the same point (a rod's tip and a cable's node).
constexpr double kSamePointM = 1e-9;

// Physical ranges, not only signs (a stiffness of 1e-320 is positive, and one of 1e300
// diverges any engine): sizes up to 100 m, densities up to 1e15 kg/m^3 (a point mass is a
// tiny, very dense sphere),
// stiffness from 1e-3 to 1e8 N/m, damping up to 1e6 N*s/m, forces up to 1e6 N, friction
// coefficients up to 100.
constexpr NumberRange kSize{.min = 0.0, .max = 100.0, .min_exclusive = true};
constexpr NumberRange kHeight{.min = 0.0, .max = 100.0};
constexpr NumberRange kDensity{.min = 0.0, .max = 1e15};
constexpr NumberRange kStiffness{.min = 1e-3, .max = 1e8};
constexpr NumberRange kDamping{.min = 0.0, .max = 1e6};
constexpr NumberRange kForce{.min = 0.0, .max = 1e6};
constexpr NumberRange kFriction{.min = 0.0, .max = 100.0};
constexpr NumberRange kUnit{.min = 0.0, .max = 1.0};

std::string Join(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) {
    if (!text.empty()) text += ", ";
    text += name;
  }
  return text;
}

// Model-specific checks beside FieldChecker's: a vector of three finite numbers, a name
// usable in an "a/b" reference.
void CheckVector(FieldChecker& check, const std::string& pointer, const Vec3& value) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(value[i])) {
      check.Fail(pointer + "/" + std::to_string(i),
                 "expected a number, got " + FormatNumber(value[i]));
    }
  }
}

void CheckName(FieldChecker& check, const std::string& pointer, const std::string& name) {
  if (name.empty()) check.Fail(pointer, "expected a non-empty name");
  if (name.find('/') != std::string::npos) check.Fail(pointer, "expected a name without '/'");
}

std::string At(std::string_view array, size_t i) {
  return std::string(array) + "/" + std::to_string(i);
}

Vec3 ToVec3(const std::vector<double>& values) {
  if (values.size() != 3) return Vec3::Zero();
  return Vec3(values[0], values[1], values[2]);
}

json ToJson(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

// "rear/top" -> ("rear", "top"); nullopt without exactly one '/'.
std::optional<std::pair<std::string, std::string>> SplitEnd(const std::string& end) {
  const size_t slash = end.find('/');
  if (slash == std::string::npos || end.find('/', slash + 1) != std::string::npos) {
    return std::nullopt;
  }
  return std::make_pair(end.substr(0, slash), end.substr(slash + 1));
}

}  // namespace

std::string_view CableAttachmentName(CableAttachment attachment) {
  return attachment == CableAttachment::kNode ? "node" : "surface";
}

std::string_view RestLengthReferenceName(RestLengthReference reference) {
  return reference == RestLengthReference::kNode ? "node" : "attachment";
}

// ---------------------------------------------------------------------------------------
// mass properties

MassProperties RodMassProperties(const Vec3& from_m, const Vec3& to_m, double radius_m,
                                 double density_kg_per_m3) {
  MassProperties props;
  const Vec3 axis = to_m - from_m;
  const double length = axis.norm();
  props.mass_kg = density_kg_per_m3 * std::numbers::pi * radius_m * radius_m * length;
  props.com_m = 0.5 * (from_m + to_m);
  if (length <= 0.0) return props;
  // solid cylinder: m r^2 / 2 about its axis, m (3 r^2 + L^2) / 12 across it
  const Vec3 d = axis / length;
  const double axial = 0.5 * props.mass_kg * radius_m * radius_m;
  const double across = props.mass_kg * (3.0 * radius_m * radius_m + length * length) / 12.0;
  props.inertia_kg_m2 = across * (Mat3::Identity() - d * d.transpose()) + axial * d * d.transpose();
  return props;
}

MassProperties BoxMassProperties(const Vec3& center_m, const Vec3& size_m,
                                 double density_kg_per_m3) {
  MassProperties props;
  props.mass_kg = density_kg_per_m3 * size_m.x() * size_m.y() * size_m.z();
  props.com_m = center_m;
  const Vec3 s2 = size_m.cwiseProduct(size_m);
  props.inertia_kg_m2 =
      (props.mass_kg / 12.0) * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal();
  return props;
}

MassProperties SphereMassProperties(const Vec3& center_m, double radius_m,
                                    double density_kg_per_m3) {
  MassProperties props;
  props.mass_kg = density_kg_per_m3 * 4.0 / 3.0 * std::numbers::pi * radius_m * radius_m * radius_m;
  props.com_m = center_m;
  props.inertia_kg_m2 = 0.4 * props.mass_kg * radius_m * radius_m * Mat3::Identity();
  return props;
}

MassProperties CombineMassProperties(const std::vector<MassProperties>& parts) {
  MassProperties total;
  for (const MassProperties& part : parts) {
    total.mass_kg += part.mass_kg;
    total.com_m += part.mass_kg * part.com_m;
  }
  if (total.mass_kg <= 0.0) return MassProperties{};
  total.com_m /= total.mass_kg;
  // parallel axis theorem for each part
  for (const MassProperties& part : parts) {
    const Vec3 offset = part.com_m - total.com_m;
    total.inertia_kg_m2 +=
        part.inertia_kg_m2 +
        part.mass_kg * (offset.squaredNorm() * Mat3::Identity() - offset * offset.transpose());
  }
  return total;
}

Vec3 SurfaceAnchor(const Vec3& node, const Vec3& rod_direction, double radius_m,
                   const Vec3& destination) {
  const double rod_length = rod_direction.norm();
  if (rod_length <= 0.0) return node;
  const Vec3 axis = rod_direction / rod_length;
  const Vec3 towards = destination - node;
  // the part of the way to the destination that is perpendicular to the rod
  const Vec3 across = towards - axis * axis.dot(towards);
  const double across_length = across.norm();
  if (across_length <= 1e-12 * std::max(1.0, towards.norm())) return node;
  return node + across * (radius_m / across_length);
}

// ---------------------------------------------------------------------------------------
// reading and writing the file format

namespace {

// ModelDescriptionFromJson's parts, each read from its object in the file's order (so the
// first problem recorded is the first in the file)

RodDescription ReadRod(JsonReader& reader) {
  RodDescription rod;
  rod.name = reader.String("name");
  rod.from_node = reader.String("from");
  rod.to_node = reader.String("to");
  rod.radius_m = reader.Number("radius_m", kSize);
  rod.density_kg_per_m3 = reader.Number("density_kg_per_m3", kDensity);
  rod.collides = reader.OptionalBoolean("collides").value_or(true);
  return rod;
}

BoxDescription ReadBox(JsonReader& reader) {
  BoxDescription box;
  box.name = reader.String("name");
  box.center_m = ToVec3(reader.NumberArray("center_m", 3));
  box.size_m = ToVec3(reader.NumberArray("size_m", 3, kSize));
  box.density_kg_per_m3 = reader.Number("density_kg_per_m3", kDensity);
  box.collides = reader.OptionalBoolean("collides").value_or(true);
  return box;
}

SphereDescription ReadSphere(JsonReader& reader) {
  SphereDescription sphere;
  sphere.name = reader.String("name");
  sphere.center_m = ToVec3(reader.NumberArray("center_m", 3));
  sphere.radius_m = reader.Number("radius_m", kSize);
  sphere.density_kg_per_m3 = reader.Number("density_kg_per_m3", kDensity);
  if (auto foot = reader.OptionalEnum("foot", {"A", "B", "C", "D"})) {
    sphere.foot = static_cast<Foot>(*foot);
  }
  return sphere;
}

// a body: pose, nodes, rods, boxes, spheres
BodyDescription ReadBody(JsonReader& reader) {
  BodyDescription body;
  body.name = reader.String("name");
  body.position_m = ToVec3(reader.NumberArray("position_m", 3));
  if (auto wxyz = reader.OptionalNumberArray("orientation_wxyz", 4)) {
    if (wxyz->size() == 4) body.orientation = Quat((*wxyz)[0], (*wxyz)[1], (*wxyz)[2], (*wxyz)[3]);
  }
  const json* nodes = reader.Raw("nodes");
  if (nodes == nullptr || !nodes->is_object()) {
    reader.Fail("nodes", "expected an object of named points, {\"top\": [x, y, z], ...}");
  } else {
    JsonReader nodes_reader = reader.Object("nodes");
    for (const auto& [node_name, value] : nodes->items()) {
      body.nodes.push_back({node_name, ToVec3(nodes_reader.NumberArray(node_name, 3))});
    }
  }
  if (auto rods = reader.OptionalObjectArray("rods")) {
    for (JsonReader& rod_reader : *rods) body.rods.push_back(ReadRod(rod_reader));
  }
  if (auto boxes = reader.OptionalObjectArray("boxes")) {
    for (JsonReader& box_reader : *boxes) body.boxes.push_back(ReadBox(box_reader));
  }
  if (auto spheres = reader.OptionalObjectArray("spheres")) {
    for (JsonReader& sphere_reader : *spheres) body.spheres.push_back(ReadSphere(sphere_reader));
  }
  return body;
}

HingeDescription ReadHinge(JsonReader& reader) {
  HingeDescription hinge;
  hinge.name = reader.String("name");
  hinge.parent = reader.String("parent");
  hinge.child = reader.String("child");
  hinge.point_m = ToVec3(reader.NumberArray("point_m", 3));
  hinge.axis = ToVec3(reader.NumberArray("axis", 3));
  return hinge;
}

CableGroupDescription ReadCableGroup(JsonReader& reader) {
  CableGroupDescription group;
  group.name = reader.String("name");
  group.material = reader.OptionalString("material").value_or("");
  group.stiffness_n_per_m = reader.Number("stiffness_n_per_m", kStiffness);
  group.damping_n_s_per_m = reader.Number("damping_n_s_per_m", kDamping);
  group.pretension_n = reader.Number("pretension_n", kForce);
  return group;
}

// a cable: its group and its ends, "<body>/<node>" each
CableDescription ReadCable(JsonReader& reader) {
  CableDescription cable;
  cable.name = reader.String("name");
  cable.group = reader.String("group");
  const std::string from = reader.String("from");
  const std::string to = reader.String("to");
  const auto from_end = SplitEnd(from);
  const auto to_end = SplitEnd(to);
  if (!reader.failed() && !from_end) {
    reader.Fail("from", "expected \"<body>/<node>\", got \"" + from + "\"");
  }
  if (!reader.failed() && !to_end) {
    reader.Fail("to", "expected \"<body>/<node>\", got \"" + to + "\"");
  }
  if (from_end) std::tie(cable.from_body, cable.from_node) = *from_end;
  if (to_end) std::tie(cable.to_body, cable.to_node) = *to_end;
  return cable;
}

// the world's settings: contact, cable attachment, rest lengths, damping cap, markers
void ReadWorld(JsonReader& root, ModelDescription& model) {
  if (auto contact = root.OptionalObject("contact")) {
    model.contact.friction = contact->OptionalNumber("friction", kFriction).value_or(0.0);
    model.contact.spine_friction = contact->OptionalNumber("spine_friction", kFriction);
    model.contact.restitution = contact->OptionalNumber("restitution", kUnit).value_or(0.0);
    model.contact.spine_ground = contact->OptionalBoolean("spine_ground").value_or(false);
    model.contact.spine_self = contact->OptionalBoolean("spine_self").value_or(false);
  }
  if (auto attachment = root.OptionalEnum("cable_attachment", {"node", "surface"})) {
    model.cable_attachment = *attachment == 0 ? CableAttachment::kNode : CableAttachment::kSurface;
  }
  if (auto reference = root.OptionalEnum("rest_length_reference", {"attachment", "node"})) {
    model.rest_length_reference =
        *reference == 0 ? RestLengthReference::kAttachment : RestLengthReference::kNode;
  }
  model.damping_cap = root.OptionalBoolean("damping_cap").value_or(true);
  model.foot_marker_height_m = root.OptionalNumber("foot_marker_height_m", kHeight).value_or(0.0);
}

}  // namespace

Result<ModelDescription> ModelDescriptionFromJson(const json& document, const std::string& source) {
  if (!document.is_object()) {
    return InvalidArgumentError(source + ": /: expected a JSON object");
  }
  JsonReader root(document, source);
  const std::string format = root.String("format");
  if (!root.failed() && format != kFormatName) {
    return UnsupportedError(root.Where("format") + ": expected \"" + std::string(kFormatName) +
                            "\", got \"" + format + "\"");
  }
  const int64_t version = root.Integer("version", {.min = 1});
  if (!root.failed() && version > kFormatVersion) {
    return UnsupportedError(root.Where("version") + ": version " + std::to_string(version) +
                            " is newer than this program reads (" + std::to_string(kFormatVersion) +
                            ")");
  }

  ModelDescription model;
  model.name = root.String("name");
  model.description = root.OptionalString("description").value_or("");
  model.gravity_m_per_s2 = ToVec3(root.NumberArray("gravity_m_per_s2", 3));
  ReadWorld(root, model);
  for (JsonReader& body_reader : root.ObjectArray("bodies")) {
    model.bodies.push_back(ReadBody(body_reader));
  }
  if (auto hinges = root.OptionalObjectArray("hinges")) {
    for (JsonReader& hinge_reader : *hinges) model.hinges.push_back(ReadHinge(hinge_reader));
  }
  for (JsonReader& group_reader : root.ObjectArray("cable_groups")) {
    model.cable_groups.push_back(ReadCableGroup(group_reader));
  }
  std::vector<JsonReader> cable_readers = root.ObjectArray("cables");
  for (JsonReader& cable_reader : cable_readers) model.cables.push_back(ReadCable(cable_reader));

  LIFTOFF_RETURN_IF_ERROR(root.Finish());
  // the description's own consistency, with the file's pointers
  Result<Model> built = BuildModel(model, source);
  if (!built.ok()) return built.status();
  return model;
}

Result<ModelDescription> LoadModelDescription(const std::filesystem::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(json document, LoadJsonFile(path));
  return ModelDescriptionFromJson(document, path.string());
}

namespace {

// one body of the file: pose, nodes, and its rods, boxes and spheres when it has any
json BodyToJson(const BodyDescription& body) {
  json entry = {{"name", body.name}, {"position_m", ToJson(body.position_m)}};
  const Quat& q = body.orientation;
  if (!q.coeffs().isApprox(Quat::Identity().coeffs(), 0.0)) {
    entry["orientation_wxyz"] = json::array({q.w(), q.x(), q.y(), q.z()});
  }
  json nodes = json::object();
  for (const NodeDescription& node : body.nodes) nodes[node.name] = ToJson(node.position_m);
  entry["nodes"] = nodes;
  json rods = json::array();
  for (const RodDescription& rod : body.rods) {
    rods.push_back({{"name", rod.name},
                    {"from", rod.from_node},
                    {"to", rod.to_node},
                    {"radius_m", rod.radius_m},
                    {"density_kg_per_m3", rod.density_kg_per_m3},
                    {"collides", rod.collides}});
  }
  if (!rods.empty()) entry["rods"] = rods;
  json boxes = json::array();
  for (const BoxDescription& box : body.boxes) {
    boxes.push_back({{"name", box.name},
                     {"center_m", ToJson(box.center_m)},
                     {"size_m", ToJson(box.size_m)},
                     {"density_kg_per_m3", box.density_kg_per_m3},
                     {"collides", box.collides}});
  }
  if (!boxes.empty()) entry["boxes"] = boxes;
  json spheres = json::array();
  for (const SphereDescription& sphere : body.spheres) {
    json item = {{"name", sphere.name},
                 {"center_m", ToJson(sphere.center_m)},
                 {"radius_m", sphere.radius_m},
                 {"density_kg_per_m3", sphere.density_kg_per_m3}};
    if (sphere.foot) item["foot"] = std::string(FootName(*sphere.foot));
    spheres.push_back(item);
  }
  if (!spheres.empty()) entry["spheres"] = spheres;
  return entry;
}

}  // namespace

json ModelDescriptionToJson(const ModelDescription& model) {
  json document = json::object();
  document["format"] = kFormatName;
  document["version"] = kFormatVersion;
  document["name"] = model.name;
  if (!model.description.empty()) document["description"] = model.description;
  document["gravity_m_per_s2"] = ToJson(model.gravity_m_per_s2);
  document["contact"] = {{"friction", model.contact.friction},
                         {"restitution", model.contact.restitution},
                         {"spine_ground", model.contact.spine_ground},
                         {"spine_self", model.contact.spine_self}};
  if (model.contact.spine_friction) {
    document["contact"]["spine_friction"] = *model.contact.spine_friction;
  }
  document["cable_attachment"] = std::string(CableAttachmentName(model.cable_attachment));
  document["rest_length_reference"] =
      std::string(RestLengthReferenceName(model.rest_length_reference));
  document["damping_cap"] = model.damping_cap;
  document["foot_marker_height_m"] = model.foot_marker_height_m;
  json bodies = json::array();
  for (const BodyDescription& body : model.bodies) bodies.push_back(BodyToJson(body));
  document["bodies"] = bodies;
  json hinges = json::array();
  for (const HingeDescription& hinge : model.hinges) {
    hinges.push_back({{"name", hinge.name},
                      {"parent", hinge.parent},
                      {"child", hinge.child},
                      {"point_m", ToJson(hinge.point_m)},
                      {"axis", ToJson(hinge.axis)}});
  }
  if (!hinges.empty()) document["hinges"] = hinges;
  json groups = json::array();
  for (const CableGroupDescription& group : model.cable_groups) {
    json entry = {{"name", group.name},
                  {"stiffness_n_per_m", group.stiffness_n_per_m},
                  {"damping_n_s_per_m", group.damping_n_s_per_m},
                  {"pretension_n", group.pretension_n}};
    if (!group.material.empty()) entry["material"] = group.material;
    groups.push_back(entry);
  }
  document["cable_groups"] = groups;
  json cables = json::array();
  for (const CableDescription& cable : model.cables) {
    cables.push_back({{"name", cable.name},
                      {"group", cable.group},
                      {"from", cable.from_body + "/" + cable.from_node},
                      {"to", cable.to_body + "/" + cable.to_node}});
  }
  document["cables"] = cables;
  return document;
}

// ---------------------------------------------------------------------------------------
// building

int Model::BodyIndex(std::string_view name) const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Model::CableGroupIndex(std::string_view name) const {
  for (size_t i = 0; i < cable_groups.size(); ++i) {
    if (cable_groups[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> Model::CablesInGroup(std::string_view group) const {
  std::vector<int> indices;
  const int index = CableGroupIndex(group);
  if (index < 0) return indices;
  for (size_t i = 0; i < cables.size(); ++i) {
    if (cables[i].group == index) indices.push_back(static_cast<int>(i));
  }
  return indices;
}

std::string Model::Brief() const {
  std::ostringstream out;
  out << description.name << ": " << bodies.size() << (bodies.size() == 1 ? " body" : " bodies")
      << " (" << FormatNumber(std::round(total_mass_kg * 1e4) / 1e4) << " kg), " << hinges.size()
      << (hinges.size() == 1 ? " hinge, " : " hinges, ") << cables.size()
      << (cables.size() == 1 ? " cable, " : " cables, ") << feet.size()
      << (feet.size() == 1 ? " foot, " : " feet, ")
      << CableAttachmentName(description.cable_attachment) << " attachment";
  return out.str();
}

namespace {

using NodeMap = std::map<std::string, Vec3, std::less<>>;
using NameIndex = std::map<std::string, int, std::less<>>;

// BuildModel's stages in turn (world, bodies, hinges, cable groups, cables), each adding
// to the model and recording the first problem in the checker. The stages run in the order
// the file lists the parts, so the first problem reported is the first in the file.
class ModelBuilder {
 public:
  ModelBuilder(const ModelDescription& description, const std::string& source)
      : description_(description), check_(source) {}

  Result<Model> Build() {
    model_.description = description_;
    model_.gravity_m_per_s2 = description_.gravity_m_per_s2;
    model_.contact = description_.contact;
    model_.damping_cap = description_.damping_cap;
    CheckWorld();
    for (size_t b = 0; b < description_.bodies.size(); ++b) AddBody(b);
    if (!check_.ok()) return check_.status();
    for (size_t h = 0; h < description_.hinges.size(); ++h) AddHinge(h);
    CheckHingeParentsAndMasses();
    if (!check_.ok()) return check_.status();
    AddCableGroups();
    if (!check_.ok()) return check_.status();
    for (size_t c = 0; c < description_.cables.size(); ++c) AddCable(c);
    if (!check_.ok()) return check_.status();
    return std::move(model_);
  }

 private:
  // one end of a cable: its body and node (body frame)
  struct CableEnd {
    int body = -1;
    Vec3 node = Vec3::Zero();
  };

  void CheckWorld();
  void AddBody(size_t b);
  NodeMap CheckNodes(const BodyDescription& in, const std::string& where);
  void AddRods(const BodyDescription& in, const std::string& where, const NodeMap& nodes,
               Body& body, std::vector<MassProperties>& parts);
  void AddBoxes(const BodyDescription& in, const std::string& where, Body& body,
                std::vector<MassProperties>& parts);
  void AddSpheres(const BodyDescription& in, size_t b, const std::string& where, Body& body,
                  std::vector<MassProperties>& parts);
  void AddFoot(const SphereDescription& sphere_in, size_t b, const std::string& sphere_where,
               const Body& body, Sphere& sphere);
  void AddHinge(size_t h);
  void CheckHingeParentsAndMasses();
  void AddCableGroups();
  void AddCable(size_t c);
  std::optional<CableEnd> FindCableEnd(const std::string& where, const std::string& key,
                                       const std::string& body_name, const std::string& node_name);
  Vec3 WorldPoint(int body, const Vec3& local) const;
  Vec3 CableAnchor(int body, const Vec3& node, const Vec3& destination_world) const;

  const ModelDescription& description_;
  FieldChecker check_;
  Model model_;
  NameIndex body_index_;
  std::vector<std::string> body_names_;
  NameIndex group_index_;
  std::vector<std::string> group_names_;
  std::set<std::string, std::less<>> cable_names_;
};

void ModelBuilder::CheckWorld() {
  CheckName(check_, "/name", description_.name);
  CheckVector(check_, "/gravity_m_per_s2", description_.gravity_m_per_s2);
  check_.Number("/contact/friction", description_.contact.friction, kFriction);
  check_.Number("/contact/restitution", description_.contact.restitution, kUnit);
  check_.Number("/foot_marker_height_m", description_.foot_marker_height_m, kHeight);
  if (description_.contact.spine_friction) {
    check_.Number("/contact/spine_friction", *description_.contact.spine_friction, kFriction);
  }
  if (description_.bodies.empty()) check_.Fail("/bodies", "expected at least one body");
}

// a body: name, pose, nodes, shapes and the mass properties they add up to
void ModelBuilder::AddBody(size_t b) {
  const BodyDescription& in = description_.bodies[b];
  const std::string where = At("/bodies", b);
  CheckName(check_, where + "/name", in.name);
  if (!body_index_.emplace(in.name, static_cast<int>(b)).second) {
    check_.Fail(where + "/name", "body \"" + in.name + "\" is listed twice");
  }
  body_names_.push_back(in.name);
  CheckVector(check_, where + "/position_m", in.position_m);
  const double q_norm = in.orientation.norm();
  if (!in.orientation.coeffs().allFinite() || std::abs(q_norm - 1.0) > 1e-6) {
    check_.Fail(where + "/orientation_wxyz", "expected a unit quaternion [w, x, y, z]");
  }

  Body body;
  body.name = in.name;
  body.initial_position_m = in.position_m;
  body.initial_orientation = q_norm > 0.0 ? in.orientation.normalized() : Quat::Identity();
  body.nodes = in.nodes;
  const NodeMap nodes = CheckNodes(in, where);
  std::vector<MassProperties> parts;
  AddRods(in, where, nodes, body, parts);
  AddBoxes(in, where, body, parts);
  AddSpheres(in, b, where, body, parts);
  const MassProperties total = CombineMassProperties(parts);
  body.mass_kg = total.mass_kg;
  body.com_m = total.com_m;
  body.inertia_kg_m2 = total.inertia_kg_m2;
  model_.total_mass_kg += total.mass_kg;
  model_.bodies.push_back(std::move(body));
}

// the body's nodes by name, each named once
NodeMap ModelBuilder::CheckNodes(const BodyDescription& in, const std::string& where) {
  NodeMap nodes;
  for (const NodeDescription& node : in.nodes) {
    const std::string node_where = where + "/nodes/" + JsonPointerEscape(node.name);
    CheckName(check_, node_where, node.name);
    CheckVector(check_, node_where, node.position_m);
    if (!nodes.emplace(node.name, node.position_m).second) {
      check_.Fail(node_where, "node \"" + node.name + "\" is listed twice");
    }
  }
  return nodes;
}

void ModelBuilder::AddRods(const BodyDescription& in, const std::string& where,
                           const NodeMap& nodes, Body& body, std::vector<MassProperties>& parts) {
  const auto node_names = [&]() {
    std::vector<std::string> names;
    for (const auto& [name, position] : nodes) names.push_back(name);
    return Join(names);
  };
  for (size_t r = 0; r < in.rods.size(); ++r) {
    const RodDescription& rod_in = in.rods[r];
    const std::string rod_where = At(where + "/rods", r);
    check_.Number(rod_where + "/radius_m", rod_in.radius_m, kSize);
    check_.Number(rod_where + "/density_kg_per_m3", rod_in.density_kg_per_m3, kDensity);
    const auto from = nodes.find(rod_in.from_node);
    const auto to = nodes.find(rod_in.to_node);
    if (from == nodes.end()) {
      check_.Fail(rod_where + "/from", "unknown node \"" + rod_in.from_node + "\"; body " +
                                           in.name + " has " + node_names());
      continue;
    }
    if (to == nodes.end()) {
      check_.Fail(rod_where + "/to", "unknown node \"" + rod_in.to_node + "\"; body " + in.name +
                                         " has " + node_names());
      continue;
    }
    if ((to->second - from->second).norm() <= kSamePointM) {
      check_.Fail(rod_where, "expected a rod of positive length (from and to coincide)");
      continue;
    }
    const MassProperties props =
        RodMassProperties(from->second, to->second, rod_in.radius_m, rod_in.density_kg_per_m3);
    parts.push_back(props);
    body.rods.push_back(
        {rod_in.name, from->second, to->second, rod_in.radius_m, props.mass_kg, rod_in.collides});
  }
}

void ModelBuilder::AddBoxes(const BodyDescription& in, const std::string& where, Body& body,
                            std::vector<MassProperties>& parts) {
  for (size_t x = 0; x < in.boxes.size(); ++x) {
    const BoxDescription& box_in = in.boxes[x];
    const std::string box_where = At(where + "/boxes", x);
    CheckVector(check_, box_where + "/center_m", box_in.center_m);
    for (int i = 0; i < 3; ++i) {
      check_.Number(box_where + "/size_m/" + std::to_string(i), box_in.size_m[i], kSize);
    }
    check_.Number(box_where + "/density_kg_per_m3", box_in.density_kg_per_m3, kDensity);
    const MassProperties props =
        BoxMassProperties(box_in.center_m, box_in.size_m, box_in.density_kg_per_m3);
    parts.push_back(props);
    body.boxes.push_back(
        {box_in.name, box_in.center_m, 0.5 * box_in.size_m, props.mass_kg, box_in.collides});
  }
}

void ModelBuilder::AddSpheres(const BodyDescription& in, size_t b, const std::string& where,
                              Body& body, std::vector<MassProperties>& parts) {
  for (size_t s = 0; s < in.spheres.size(); ++s) {
    const SphereDescription& sphere_in = in.spheres[s];
    const std::string sphere_where = At(where + "/spheres", s);
    CheckVector(check_, sphere_where + "/center_m", sphere_in.center_m);
    check_.Number(sphere_where + "/radius_m", sphere_in.radius_m, kSize);
    check_.Number(sphere_where + "/density_kg_per_m3", sphere_in.density_kg_per_m3, kDensity);
    const MassProperties props =
        SphereMassProperties(sphere_in.center_m, sphere_in.radius_m, sphere_in.density_kg_per_m3);
    parts.push_back(props);
    Sphere sphere{sphere_in.name, sphere_in.center_m, sphere_in.radius_m, props.mass_kg, -1, true};
    if (sphere_in.foot) AddFoot(sphere_in, b, sphere_where, body, sphere);
    body.spheres.push_back(sphere);
  }
}

// a sphere marked as a foot: its lowest point in the built pose, fixed to the body from
// then on, and the marker above it
void ModelBuilder::AddFoot(const SphereDescription& sphere_in, size_t b,
                           const std::string& sphere_where, const Body& body, Sphere& sphere) {
  const auto letter = static_cast<size_t>(*sphere_in.foot);
  if (model_.foot_index[letter] >= 0) {
    check_.Fail(sphere_where + "/foot",
                "foot " + std::string(FootName(*sphere_in.foot)) + " is given twice");
    return;
  }
  FootPoint foot;
  foot.foot = *sphere_in.foot;
  foot.body = static_cast<int>(b);
  foot.center_m = sphere_in.center_m;
  foot.radius_m = sphere_in.radius_m;
  const Quat body_from_world = body.initial_orientation.conjugate();
  foot.bottom_m = sphere_in.center_m + body_from_world * Vec3(0.0, 0.0, -sphere_in.radius_m);
  foot.marker_m =
      foot.bottom_m + body_from_world * Vec3(0.0, 0.0, description_.foot_marker_height_m);
  sphere.foot_index = static_cast<int>(model_.feet.size());
  model_.foot_index[letter] = sphere.foot_index;
  model_.feet.push_back(foot);
}

// a hinge: a child driven by its parent
void ModelBuilder::AddHinge(size_t h) {
  const HingeDescription& in = description_.hinges[h];
  const std::string where = At("/hinges", h);
  CheckName(check_, where + "/name", in.name);
  const auto parent = body_index_.find(in.parent);
  const auto child = body_index_.find(in.child);
  if (parent == body_index_.end()) {
    check_.Fail(where + "/parent",
                "unknown body \"" + in.parent + "\"; bodies are " + Join(body_names_));
    return;
  }
  if (child == body_index_.end()) {
    check_.Fail(where + "/child",
                "unknown body \"" + in.child + "\"; bodies are " + Join(body_names_));
    return;
  }
  if (parent->second == child->second) {
    check_.Fail(where + "/child", "expected a body other than the parent");
    return;
  }
  CheckVector(check_, where + "/point_m", in.point_m);
  CheckVector(check_, where + "/axis", in.axis);
  if (check_.ok() && in.axis.norm() < 1e-12) {
    check_.Fail(where + "/axis", "expected a non-zero axis");
  }
  Body& child_body = model_.bodies[static_cast<size_t>(child->second)];
  if (child_body.driving_hinge >= 0) {
    check_.Fail(where + "/child", "body \"" + in.child + "\" is already driven by a hinge");
    return;
  }
  child_body.driving_hinge = static_cast<int>(h);
  Hinge hinge;
  hinge.name = in.name;
  hinge.parent = parent->second;
  hinge.child = child->second;
  hinge.point_m = in.point_m;
  hinge.axis = in.axis.norm() > 0.0 ? in.axis.normalized() : Vec3::UnitX();
  const Body& parent_body = model_.bodies[static_cast<size_t>(parent->second)];
  const Quat parent_inverse = parent_body.initial_orientation.conjugate();
  hinge.child_position_in_parent_m =
      parent_inverse * (child_body.initial_position_m - parent_body.initial_position_m);
  hinge.child_orientation_in_parent = parent_inverse * child_body.initial_orientation;
  model_.hinges.push_back(hinge);
}

// a hinge's parent must be free; a free body must have mass
void ModelBuilder::CheckHingeParentsAndMasses() {
  for (size_t h = 0; h < model_.hinges.size(); ++h) {
    const Hinge& hinge = model_.hinges[h];
    if (model_.bodies[static_cast<size_t>(hinge.parent)].driving_hinge >= 0) {
      check_.Unsupported(At("/hinges", h) + "/parent",
                         "a hinge's parent must be a free body (chains of hinges are not "
                         "supported)");
    }
  }
  for (size_t b = 0; b < model_.bodies.size(); ++b) {
    const Body& body = model_.bodies[b];
    if (body.driving_hinge < 0 && !(body.mass_kg > 0.0)) {
      check_.Fail(At("/bodies", b),
                  "body \"" + body.name + "\" has no mass; give it a shape with a density > 0");
    }
  }
}

void ModelBuilder::AddCableGroups() {
  for (size_t g = 0; g < description_.cable_groups.size(); ++g) {
    const CableGroupDescription& group = description_.cable_groups[g];
    const std::string where = At("/cable_groups", g);
    CheckName(check_, where + "/name", group.name);
    if (!group_index_.emplace(group.name, static_cast<int>(g)).second) {
      check_.Fail(where + "/name", "cable group \"" + group.name + "\" is listed twice");
    }
    group_names_.push_back(group.name);
    check_.Number(where + "/stiffness_n_per_m", group.stiffness_n_per_m, kStiffness);
    check_.Number(where + "/damping_n_s_per_m", group.damping_n_s_per_m, kDamping);
    check_.Number(where + "/pretension_n", group.pretension_n, kForce);
  }
  model_.cable_groups = description_.cable_groups;
}

// a cable: its ends, anchors and rest length
void ModelBuilder::AddCable(size_t c) {
  const CableDescription& in = description_.cables[c];
  const std::string where = At("/cables", c);
  CheckName(check_, where + "/name", in.name);
  if (!cable_names_.insert(in.name).second) {
    check_.Fail(where + "/name", "cable \"" + in.name + "\" is listed twice");
  }
  const auto group = group_index_.find(in.group);
  if (group == group_index_.end()) {
    check_.Fail(where + "/group",
                "unknown cable group \"" + in.group + "\"; groups are " + Join(group_names_));
    return;
  }
  const std::optional<CableEnd> a = FindCableEnd(where, "from", in.from_body, in.from_node);
  const std::optional<CableEnd> b = FindCableEnd(where, "to", in.to_body, in.to_node);
  if (!a || !b) return;
  if (a->body == b->body) {
    check_.Fail(where + "/to",
                "expected a node on another body than the cable's start (" + in.from_body + ")");
    return;
  }
  const CableGroupDescription& group_in =
      description_.cable_groups[static_cast<size_t>(group->second)];
  Cable cable;
  cable.name = in.name;
  cable.group = group->second;
  cable.body_a = a->body;
  cable.body_b = b->body;
  cable.node_a_m = a->node;
  cable.node_b_m = b->node;
  cable.stiffness_n_per_m = group_in.stiffness_n_per_m;
  cable.damping_n_s_per_m = group_in.damping_n_s_per_m;
  cable.pretension_n = group_in.pretension_n;
  const Vec3 node_a_world = WorldPoint(a->body, a->node);
  const Vec3 node_b_world = WorldPoint(b->body, b->node);
  cable.initial_node_length_m = (node_b_world - node_a_world).norm();
  if (cable.initial_node_length_m <= kSamePointM) {
    check_.Fail(where, "expected its two nodes apart in the built pose");
    return;
  }
  cable.anchor_a_m = CableAnchor(a->body, a->node, node_b_world);
  cable.anchor_b_m = CableAnchor(b->body, b->node, node_a_world);
  cable.initial_length_m =
      (WorldPoint(b->body, cable.anchor_b_m) - WorldPoint(a->body, cable.anchor_a_m)).norm();
  const double reference = description_.rest_length_reference == RestLengthReference::kNode
                               ? cable.initial_node_length_m
                               : cable.initial_length_m;
  cable.rest_length_m = reference - cable.pretension_n / cable.stiffness_n_per_m;
  if (!(cable.rest_length_m > 0.0)) {
    check_.Fail(where, "its pretension " + FormatNumber(cable.pretension_n) + " N over k " +
                           FormatNumber(cable.stiffness_n_per_m) + " N/m exceeds its length " +
                           FormatNumber(reference) + " m: the rest length would be <= 0");
    return;
  }
  model_.cables.push_back(std::move(cable));
}

// a cable's end "body/node" (key: "from" or "to"); nullopt, the problem recorded, when
// either is unknown
std::optional<ModelBuilder::CableEnd> ModelBuilder::FindCableEnd(const std::string& where,
                                                                 const std::string& key,
                                                                 const std::string& body_name,
                                                                 const std::string& node_name) {
  const auto body = body_index_.find(body_name);
  if (body == body_index_.end()) {
    check_.Fail(where + "/" + key, "unknown node \"" + body_name + "/" + node_name +
                                       "\": no body \"" + body_name + "\"; bodies are " +
                                       Join(body_names_));
    return std::nullopt;
  }
  const Body& owner = model_.bodies[static_cast<size_t>(body->second)];
  std::vector<std::string> names;
  for (const NodeDescription& node : owner.nodes) {
    if (node.name == node_name) return CableEnd{body->second, node.position_m};
    names.push_back(node.name);
  }
  check_.Fail(where + "/" + key, "unknown node \"" + body_name + "/" + node_name + "\"; body " +
                                     body_name + " has " + Join(names));
  return std::nullopt;
}

// a point of a body in the built pose, world frame
Vec3 ModelBuilder::WorldPoint(int body, const Vec3& local) const {
  const Body& b = model_.bodies[static_cast<size_t>(body)];
  return Vec3(b.initial_position_m + b.initial_orientation * local);
}

// where a cable pulls on a body: its node, or with surface attachment the surface of the
// one rod ending at the node, moved towards the other end
Vec3 ModelBuilder::CableAnchor(int body, const Vec3& node, const Vec3& destination_world) const {
  if (description_.cable_attachment == CableAttachment::kNode) return node;
  const Body& owner = model_.bodies[static_cast<size_t>(body)];
  const Rod* tip_of = nullptr;
  int tips = 0;
  for (const Rod& rod : owner.rods) {
    const bool at_from = (rod.from_m - node).norm() <= kSamePointM;
    const bool at_to = (rod.to_m - node).norm() <= kSamePointM;
    if (at_from || at_to) {
      ++tips;
      tip_of = &rod;
    }
  }
  if (tips != 1 || tip_of == nullptr) return node;
  const Vec3 destination =
      owner.initial_orientation.conjugate() * (destination_world - owner.initial_position_m);
  return SurfaceAnchor(node, tip_of->to_m - tip_of->from_m, tip_of->radius_m, destination);
}

}  // namespace

Result<Model> BuildModel(const ModelDescription& description, const std::string& source) {
  return ModelBuilder(description, source).Build();
}

Result<Model> LoadModel(const std::filesystem::path& path) {
  LIFTOFF_ASSIGN_OR_RETURN(ModelDescription description, LoadModelDescription(path));
  return BuildModel(description, path.string());
}

}  // namespace liftoff::sim
