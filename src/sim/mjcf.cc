#include "liftoff/sim/mjcf.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/markup.h"
#include "liftoff/core/text.h"

namespace liftoff::sim {
namespace {

// Collision bits: the ground accepts bit 1; spine shapes that hit each other carry bit 2
// both ways; feet carry bit 1 only, so they never hit the spine or each other.
constexpr int kGroundBit = 1;
constexpr int kSpineSelfBit = 2;

size_t Index(int i) { return static_cast<size_t>(i); }

// Shortest text that reads back to the same double; values below 1e-12 (rounding dust
// in positions and products of inertia) as 0.
std::string Num(double value) {
  if (std::abs(value) < 1e-12) value = 0.0;
  char buffer[40];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  if (error != std::errc()) return FormatNumber(value);
  return std::string(buffer, end);
}

std::string Vec(const Vec3& v) { return Num(v.x()) + " " + Num(v.y()) + " " + Num(v.z()); }

std::string QuatText(const Quat& q) {
  return Num(q.w()) + " " + Num(q.x()) + " " + Num(q.y()) + " " + Num(q.z());
}

// Comment text: XML forbids "--" inside a comment.
std::string CommentText(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '-' && !out.empty() && out.back() == '-') out += ' ';
    out += c;
  }
  return out;
}

bool IsIdentityQuat(const Quat& q) {
  return std::abs(q.w() - 1.0) < 1e-15 && std::abs(q.x()) < 1e-15 && std::abs(q.y()) < 1e-15 &&
         std::abs(q.z()) < 1e-15;
}

std::string FootRgba(Foot foot) {
  // the hardware's tape colours: A blue, B orange, C purple, D red
  switch (foot) {
    case Foot::kA: return "0.1 0.3 0.9 1";
    case Foot::kB: return "1 0.55 0.1 1";
    case Foot::kC: return "0.55 0.2 0.75 1";
    case Foot::kD: return "0.85 0.1 0.1 1";
  }
  return "0.5 0.5 0.5 1";
}

std::string CableRgba(std::string_view material) {
  if (material == "silicone") return "0.3 0.7 0.95 1";
  if (material == "buna_n") return "0.15 0.15 0.15 1";
  if (material == "spring") return "0.95 0.8 0.2 1";
  return "0.8 0.8 0.8 1";
}

Status RangeError(std::string_view field, const std::string& expected, double got) {
  return InvalidArgumentError(std::string(field) + ": expected " + expected + ", got " +
                              FormatNumber(got));
}

class Writer {
 public:
  Writer(const Model& model, const MjcfOptions& options) : model_(model), options_(options) {}

  std::string Write() {
    Header();
    out_ << "<mujoco model=\"" << EscapeMarkup(model_.description.name) << "\">\n";
    Settings();
    World();
    Tendons();
    Drive();
    out_ << "</mujoco>\n";
    return out_.str();
  }

 private:
  void Line(int depth, const std::string& text) {
    out_ << std::string(static_cast<size_t>(2 * depth), ' ') << text << "\n";
  }

  void Header() {
    const ContactDescription& contact = model_.contact;
    out_ << "<!--\n"
         << "  " << CommentText(model_.Brief()) << "\n";
    if (!model_.description.description.empty()) {
      out_ << "  " << CommentText(model_.description.description) << "\n";
    }
    out_
        << "  Exported by liftoff (liftoff sim export-mjcf) for MuJoCo 2.2.2. Units SI, angles in\n"
        << "  radians. Frame: x forward (towards the head), y to the robot's left, z up; the\n"
        << "  ground is z = 0. Body frames are liftoff's; every <inertial> is liftoff's mass,\n"
        << "  centre of mass and inertia tensor (geoms carry no mass).\n"
        << "  Cables are spatial tendons between the sites <cable>/from and <cable>/to, with\n"
        << "  stiffness and damping 0: MuJoCo's tendon springs push as well as pull, so a runner\n"
        << "  applies liftoff's tension-only law T = k (x - r) + c x' while x > r as generalised\n"
        << "  forces -T * ten_J (r = springlength; k and c per group in the comments below"
        << (model_.damping_cap ? ";\n  the damping term capped at the spring term's magnitude" : "")
        << ").\n"
        << "  Opened as it is, the robot has no cable forces and slumps.\n"
        << "  Friction: feet on the ground " << Num(contact.friction) << ", other contacts "
        << Num(SpineFriction()) << ", set on each geom (the ground has 0 and MuJoCo takes\n"
        << "  the larger of two geoms' values; condim 3 with an elliptic cone where > 0, else 1).\n"
        << "  Soft contact: solref \"" << Num(ContactTimeConstant()) << " "
        << Num(options_.contact_damping_ratio) << "\" solimp \"" << Num(options_.contact_impedance)
        << " " << Num(options_.contact_impedance) << " " << Num(options_.contact_impedance_width_m)
        << "\" (critically damped: no bounce; a standing foot sinks < 1e-6 m).\n";
    if (contact.restitution > 0.0) {
      out_ << "  The model's restitution " << Num(contact.restitution)
           << " is not represented: MuJoCo has no restitution coefficient.\n";
    }
    out_ << "  Spine-ground contact " << (contact.spine_ground ? "on" : "off")
         << ", spine-spine contact " << (contact.spine_self ? "on" : "off") << "; feet always"
         << " touch the ground.\n";
    if (!model_.hinges.empty()) {
      out_ << "  Hinge drive: "
           << (options_.hinge_drive == MjcfHingeDrive::kEquality
                   ? "an equality constraint <hinge>/drive holds each hinge at polycoef[0]\n"
                     "  (eq_data[0], rad; a runner writes the commanded angle there each step)."
                   : "a position servo <hinge>/servo (ctrl = angle, rad).")
           << "\n";
    }
    if (options_.lift_m > 0.0) {
      out_ << "  Free bodies start " << Num(options_.lift_m)
           << " m above the built pose (the drop).\n";
    }
    out_ << "-->\n";
  }

  // time constants: 0 asks for MuJoCo's floor, two time steps
  double ContactTimeConstant() const {
    return options_.contact_time_constant_s > 0.0 ? options_.contact_time_constant_s
                                                  : 2.0 * options_.time_step_s;
  }
  double HingeTimeConstant() const {
    return options_.hinge_time_constant_s > 0.0 ? options_.hinge_time_constant_s
                                                : 2.0 * options_.time_step_s;
  }

  double SpineFriction() const {
    return model_.contact.spine_friction.value_or(model_.contact.friction);
  }

  // A geom's own friction (a pair takes the larger of its two geoms': the ground has 0).
  static std::string FrictionAttributes(double friction) {
    if (!(friction > 0.0)) return "";
    return " condim=\"3\" friction=\"" + Num(friction) + " 0.005 0.0001\"";
  }

  void Settings() {
    Line(1, "<compiler angle=\"radian\" inertiafromgeom=\"false\"/>");
    Line(1, "<option timestep=\"" + Num(options_.time_step_s) + "\" gravity=\"" +
                Vec(model_.gravity_m_per_s2) + "\" integrator=\"Euler\" cone=\"elliptic\"" +
                (options_.noslip_iterations > 0
                     ? " noslip_iterations=\"" + std::to_string(options_.noslip_iterations) + "\""
                     : std::string()) +
                "/>");
    Line(1, "<visual>");
    Line(2, "<global offwidth=\"1280\" offheight=\"720\"/>");
    Line(1, "</visual>");
    Line(1, "<default>");
    Line(
        2,
        "<geom contype=\"0\" conaffinity=\"0\" condim=\"1\" friction=\"0 0.005 0.0001\" solref=\"" +
            Num(ContactTimeConstant()) + " " + Num(options_.contact_damping_ratio) +
            "\" solimp=\"" + Num(options_.contact_impedance) + " " +
            Num(options_.contact_impedance) + " " + Num(options_.contact_impedance_width_m) +
            "\"/>");
    Line(2, "<site size=\"0.003\" rgba=\"0.9 0.9 0.9 1\"/>");
    Line(2, "<tendon width=\"" + Num(options_.cable_width_m) + "\"/>");
    Line(1, "</default>");
    Line(1, "<asset>");
    Line(2,
         "<texture name=\"ground\" type=\"2d\" builtin=\"checker\" rgb1=\"0.85 0.85 0.82\" "
         "rgb2=\"0.7 0.7 0.68\" width=\"512\" height=\"512\"/>");
    Line(2, "<material name=\"ground\" texture=\"ground\" texrepeat=\"20 20\"/>");
    Line(1, "</asset>");
  }

  void World() {
    Line(1, "<worldbody>");
    Line(2, "<light name=\"sun\" pos=\"0 0 2\" dir=\"0 0 -1\" directional=\"true\"/>");
    Line(2,
         "<geom name=\"ground\" type=\"plane\" size=\"2 2 0.05\" material=\"ground\" "
         "contype=\"0\" conaffinity=\"" +
             std::to_string(kGroundBit) + "\"/>");
    for (size_t b = 0; b < model_.bodies.size(); ++b) {
      if (model_.bodies[b].driving_hinge >= 0) continue;  // written inside its parent
      FreeBody(static_cast<int>(b));
    }
    Line(1, "</worldbody>");
  }

  void FreeBody(int b) {
    const Body& body = model_.bodies[Index(b)];
    const Vec3 position = body.initial_position_m + Vec3(0.0, 0.0, options_.lift_m);
    std::string open =
        "<body name=\"" + EscapeMarkup(body.name) + "\" pos=\"" + Vec(position) + "\"";
    if (!IsIdentityQuat(body.initial_orientation)) {
      open += " quat=\"" + QuatText(body.initial_orientation) + "\"";
    }
    Line(2, open + ">");
    Line(3, "<freejoint name=\"" + EscapeMarkup(MjcfFreeJointName(model_, b)) + "\"/>");
    BodyContents(b, 3);
    // hinge children of this body
    for (size_t h = 0; h < model_.hinges.size(); ++h) {
      if (model_.hinges[h].parent == b) HingeChild(static_cast<int>(h), 3);
    }
    Line(2, "</body>");
  }

  void HingeChild(int h, int depth) {
    const Hinge& hinge = model_.hinges[Index(h)];
    const Body& child = model_.bodies[Index(hinge.child)];
    std::string open = "<body name=\"" + EscapeMarkup(child.name) + "\" pos=\"" +
                       Vec(hinge.child_position_in_parent_m) + "\"";
    if (!IsIdentityQuat(hinge.child_orientation_in_parent)) {
      open += " quat=\"" + QuatText(hinge.child_orientation_in_parent) + "\"";
    }
    Line(depth, open + ">");
    // the joint's point and axis are given in the child's own frame
    const Quat child_from_parent = hinge.child_orientation_in_parent.conjugate();
    const Vec3 point = child_from_parent * (hinge.point_m - hinge.child_position_in_parent_m);
    const Vec3 axis = child_from_parent * hinge.axis;
    std::string joint = "<joint name=\"" + EscapeMarkup(hinge.name) + "\" type=\"hinge\" pos=\"" +
                        Vec(point) + "\" axis=\"" + Vec(axis) + "\"";
    if (options_.hinge_drive == MjcfHingeDrive::kPositionActuator) {
      joint += " damping=\"" + Num(options_.hinge_damping_n_m_s_per_rad) + "\"";
    }
    Line(depth + 1, joint + "/>");
    BodyContents(hinge.child, depth + 1);
    Line(depth, "</body>");
  }

  void BodyContents(int b, int depth) {
    const Body& body = model_.bodies[Index(b)];
    const ContactDescription& contact = model_.contact;
    const Mat3& inertia = body.inertia_kg_m2;
    Line(depth, "<inertial pos=\"" + Vec(body.com_m) + "\" mass=\"" + Num(body.mass_kg) +
                    "\" fullinertia=\"" + Num(inertia(0, 0)) + " " + Num(inertia(1, 1)) + " " +
                    Num(inertia(2, 2)) + " " + Num(inertia(0, 1)) + " " + Num(inertia(0, 2)) + " " +
                    Num(inertia(1, 2)) + "\"/>");
    const std::string prefix = EscapeMarkup(body.name) + "/";
    for (const Rod& rod : body.rods) {
      const int type =
          rod.collides
              ? ((contact.spine_ground ? kGroundBit : 0) | (contact.spine_self ? kSpineSelfBit : 0))
              : 0;
      const int affinity = rod.collides && contact.spine_self ? kSpineSelfBit : 0;
      Line(depth, "<geom name=\"" + prefix + EscapeMarkup(rod.name) +
                      "\" type=\"capsule\" fromto=\"" + Vec(rod.from_m) + " " + Vec(rod.to_m) +
                      "\" size=\"" + Num(rod.radius_m) + "\"" + Collision(type, affinity) +
                      (type != 0 ? FrictionAttributes(SpineFriction()) : "") +
                      " rgba=\"0.55 0.55 0.6 1\"/>");
    }
    for (const Box& box : body.boxes) {
      const int type = box.collides && contact.spine_ground ? kGroundBit : 0;
      Line(depth, "<geom name=\"" + prefix + EscapeMarkup(box.name) + "\" type=\"box\" pos=\"" +
                      Vec(box.center_m) + "\" size=\"" + Vec(box.half_size_m) + "\"" +
                      Collision(type, 0) + (type != 0 ? FrictionAttributes(SpineFriction()) : "") +
                      (box.collides ? " rgba=\"0.8 0.65 0.45 1\"" : " rgba=\"0.8 0.65 0.45 0.5\"") +
                      "/>");
    }
    for (const Sphere& sphere : body.spheres) {
      const bool foot = sphere.foot_index >= 0;
      const int type = foot || (sphere.collides && contact.spine_ground) ? kGroundBit : 0;
      const std::string rgba =
          foot ? FootRgba(model_.feet[Index(sphere.foot_index)].foot) : "0.8 0.65 0.45 1";
      Line(depth,
           "<geom name=\"" + prefix + EscapeMarkup(sphere.name) + "\" type=\"sphere\" pos=\"" +
               Vec(sphere.center_m) + "\" size=\"" + Num(sphere.radius_m) + "\"" +
               Collision(type, 0) +
               (type != 0 ? FrictionAttributes(foot ? contact.friction : SpineFriction()) : "") +
               " rgba=\"" + rgba + "\"/>");
    }
    // foot markers
    for (const FootPoint& foot : model_.feet) {
      if (foot.body != b) continue;
      Line(depth, "<site name=\"" + MjcfMarkerSiteName(foot.foot) + "\" pos=\"" +
                      Vec(foot.marker_m) + "\" size=\"0.004\" rgba=\"" + FootRgba(foot.foot) +
                      "\"/>");
    }
    // cable anchors
    for (size_t c = 0; c < model_.cables.size(); ++c) {
      const Cable& cable = model_.cables[c];
      for (bool from_end : {true, false}) {
        if ((from_end ? cable.body_a : cable.body_b) != b) continue;
        Line(depth, "<site name=\"" +
                        EscapeMarkup(MjcfCableSiteName(model_, static_cast<int>(c), from_end)) +
                        "\" pos=\"" + Vec(from_end ? cable.anchor_a_m : cable.anchor_b_m) + "\"/>");
      }
    }
  }

  static std::string Collision(int type, int affinity) {
    if (type == 0 && affinity == 0) return "";  // the default: visual only
    return " contype=\"" + std::to_string(type) + "\" conaffinity=\"" + std::to_string(affinity) +
           "\"";
  }

  void Tendons() {
    if (model_.cables.empty()) return;
    Line(1, "<tendon>");
    int last_group = -1;
    for (size_t c = 0; c < model_.cables.size(); ++c) {
      const Cable& cable = model_.cables[c];
      if (cable.group != last_group) {
        const CableGroupDescription& group = model_.cable_groups[Index(cable.group)];
        Line(2, "<!-- " + CommentText(group.name) + " (" + CommentText(group.material) +
                    "): k = " + FormatNumber(group.stiffness_n_per_m) +
                    " N/m, c = " + FormatNumber(group.damping_n_s_per_m) + " N*s/m, pretension " +
                    FormatNumber(group.pretension_n) + " N -->");
        last_group = cable.group;
      }
      const std::string& material = model_.cable_groups[Index(cable.group)].material;
      Line(2, "<spatial name=\"" + EscapeMarkup(cable.name) + "\" springlength=\"" +
                  Num(cable.rest_length_m) + "\" stiffness=\"0\" damping=\"0\" rgba=\"" +
                  CableRgba(material) + "\">");
      Line(3, "<site site=\"" + EscapeMarkup(MjcfCableSiteName(model_, static_cast<int>(c), true)) +
                  "\"/>");
      Line(3, "<site site=\"" +
                  EscapeMarkup(MjcfCableSiteName(model_, static_cast<int>(c), false)) + "\"/>");
      Line(2, "</spatial>");
    }
    Line(1, "</tendon>");
  }

  void Drive() {
    if (model_.hinges.empty()) return;
    if (options_.hinge_drive == MjcfHingeDrive::kEquality) {
      Line(1, "<equality>");
      for (size_t h = 0; h < model_.hinges.size(); ++h) {
        const Hinge& hinge = model_.hinges[h];
        Line(2, "<joint name=\"" +
                    EscapeMarkup(MjcfHingeDriveElementName(model_, static_cast<int>(h),
                                                           options_.hinge_drive)) +
                    "\" joint1=\"" + EscapeMarkup(hinge.name) +
                    "\" polycoef=\"0 0 0 0 0\" solref=\"" + Num(HingeTimeConstant()) +
                    " 1\" solimp=\"" + Num(options_.hinge_impedance) + " " +
                    Num(options_.hinge_impedance) + " 0.001\"/>");
      }
      Line(1, "</equality>");
      return;
    }
    Line(1, "<actuator>");
    for (size_t h = 0; h < model_.hinges.size(); ++h) {
      const Hinge& hinge = model_.hinges[h];
      Line(2, "<position name=\"" +
                  EscapeMarkup(MjcfHingeDriveElementName(model_, static_cast<int>(h),
                                                         options_.hinge_drive)) +
                  "\" joint=\"" + EscapeMarkup(hinge.name) + "\" kp=\"" +
                  Num(options_.hinge_gain_n_m_per_rad) +
                  "\" ctrllimited=\"true\" ctrlrange=\"-3.14159 3.14159\"/>");
    }
    Line(1, "</actuator>");
  }

  const Model& model_;
  const MjcfOptions& options_;
  std::ostringstream out_;
};

}  // namespace

std::string_view MjcfHingeDriveName(MjcfHingeDrive drive) {
  return drive == MjcfHingeDrive::kEquality ? "equality" : "actuator";
}

Status MjcfOptions::Validate() const {
  if (!(time_step_s >= 1e-6 && time_step_s <= 0.01)) {
    return RangeError("time_step_s", "a number in [1e-06, 0.01]", time_step_s);
  }
  if (!(lift_m >= 0.0 && lift_m <= 1.0)) return RangeError("lift_m", "a number in [0, 1]", lift_m);
  if (contact_time_constant_s != 0.0 &&
      !(contact_time_constant_s >= 2.0 * time_step_s && contact_time_constant_s <= 10.0)) {
    return RangeError("contact_time_constant_s",
                      "a number in [2 x time_step_s = " + FormatNumber(2.0 * time_step_s) +
                          ", 10] (MuJoCo raises shorter ones to 2 time steps)",
                      contact_time_constant_s);
  }
  if (!(contact_damping_ratio > 0.0 && contact_damping_ratio <= 100.0)) {
    return RangeError("contact_damping_ratio", "a number in (0, 100]", contact_damping_ratio);
  }
  if (!(contact_impedance > 0.0 && contact_impedance <= 0.9999)) {
    return RangeError("contact_impedance", "a number in (0, 0.9999]", contact_impedance);
  }
  if (!(contact_impedance_width_m > 0.0 && contact_impedance_width_m <= 1.0)) {
    return RangeError("contact_impedance_width_m", "a number in (0, 1]", contact_impedance_width_m);
  }
  if (noslip_iterations < 0 || noslip_iterations > 1000) {
    return RangeError("noslip_iterations", "an integer in [0, 1000]", noslip_iterations);
  }
  if (hinge_time_constant_s != 0.0 &&
      !(hinge_time_constant_s >= 2.0 * time_step_s && hinge_time_constant_s <= 10.0)) {
    return RangeError("hinge_time_constant_s",
                      "a number in [2 x time_step_s = " + FormatNumber(2.0 * time_step_s) + ", 10]",
                      hinge_time_constant_s);
  }
  if (!(hinge_impedance > 0.0 && hinge_impedance <= 0.9999)) {
    return RangeError("hinge_impedance", "a number in (0, 0.9999]", hinge_impedance);
  }
  if (!(hinge_gain_n_m_per_rad > 0.0 && std::isfinite(hinge_gain_n_m_per_rad))) {
    return RangeError("hinge_gain_n_m_per_rad", "a number > 0", hinge_gain_n_m_per_rad);
  }
  if (!(hinge_damping_n_m_s_per_rad >= 0.0 && std::isfinite(hinge_damping_n_m_s_per_rad))) {
    return RangeError("hinge_damping_n_m_s_per_rad", "a number >= 0", hinge_damping_n_m_s_per_rad);
  }
  if (!(cable_width_m > 0.0 && cable_width_m <= 0.1)) {
    return RangeError("cable_width_m", "a number in (0, 0.1]", cable_width_m);
  }
  return Status::Ok();
}

std::string MjcfFreeJointName(const Model& model, int body) {
  return model.bodies[Index(body)].name + "/free";
}

std::string MjcfCableSiteName(const Model& model, int cable, bool from_end) {
  return model.cables[Index(cable)].name + (from_end ? "/from" : "/to");
}

std::string MjcfMarkerSiteName(Foot foot) { return "marker_" + std::string(FootName(foot)); }

std::string MjcfHingeDriveElementName(const Model& model, int hinge, MjcfHingeDrive drive) {
  return model.hinges[Index(hinge)].name +
         (drive == MjcfHingeDrive::kEquality ? "/drive" : "/servo");
}

Result<std::string> ExportMjcf(const Model& model, const MjcfOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate().WithContext("mjcf options"));
  return Writer(model, options).Write();
}

Status WriteMjcf(const std::filesystem::path& path, const Model& model,
                 const MjcfOptions& options) {
  LIFTOFF_ASSIGN_OR_RETURN(std::string text, ExportMjcf(model, options));
  return WriteFileAtomically(path, text);
}

}  // namespace liftoff::sim
