// The MJCF export, read back with a small XML reader (no MuJoCo needed): structure, names,
// masses and inertias against hand-computed shapes, cable sites and rest lengths against
// the documented geometry, friction and collision settings, determinism.
#include "liftoff/sim/mjcf.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "liftoff/sim/experiment.h"
#include "liftoff/sim/model.h"
#include "support/test_support.h"

namespace liftoff::sim {
namespace {

// ---------------------------------------------------------------------------------------
// a small XML reader: elements, double-quoted attributes, comments; anything else fails

struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  const Element* parent = nullptr;
  std::vector<std::unique_ptr<Element>> children;

  std::string Attribute(const std::string& key) const {
    const auto it = attributes.find(key);
    return it == attributes.end() ? std::string() : it->second;
  }
  bool Has(const std::string& key) const { return attributes.count(key) > 0; }
};

bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == ':';
}

// Parses `text`; on failure returns null and says why in `error`.
std::unique_ptr<Element> ParseXml(const std::string& text, std::string& error) {
  std::unique_ptr<Element> root;
  std::vector<Element*> stack;
  size_t i = 0;
  auto fail = [&](const std::string& why) {
    error = why + " at byte " + std::to_string(i);
    return nullptr;
  };
  while (i < text.size()) {
    if (std::isspace(static_cast<unsigned char>(text[i])) != 0) {
      ++i;
      continue;
    }
    if (text[i] != '<') return fail("text outside a tag");
    if (text.compare(i, 4, "<!--") == 0) {
      const size_t end = text.find("-->", i + 4);
      if (end == std::string::npos) return fail("unterminated comment");
      if (text.substr(i + 4, end - i - 4).find("--") != std::string::npos) {
        return fail("\"--\" inside a comment");
      }
      i = end + 3;
      continue;
    }
    if (text.compare(i, 2, "</") == 0) {
      size_t j = i + 2;
      while (j < text.size() && IsNameChar(text[j])) ++j;
      const std::string name = text.substr(i + 2, j - i - 2);
      if (stack.empty() || stack.back()->name != name) return fail("unmatched </" + name + ">");
      if (j >= text.size() || text[j] != '>') return fail("bad closing tag");
      stack.pop_back();
      i = j + 1;
      continue;
    }
    size_t j = i + 1;
    while (j < text.size() && IsNameChar(text[j])) ++j;
    auto element = std::make_unique<Element>();
    element->name = text.substr(i + 1, j - i - 1);
    if (element->name.empty()) return fail("empty tag name");
    bool self_closing = false;
    while (true) {
      while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j])) != 0) ++j;
      if (j >= text.size()) return fail("unterminated tag");
      if (text.compare(j, 2, "/>") == 0) {
        self_closing = true;
        j += 2;
        break;
      }
      if (text[j] == '>') {
        ++j;
        break;
      }
      size_t k = j;
      while (k < text.size() && IsNameChar(text[k])) ++k;
      const std::string key = text.substr(j, k - j);
      if (key.empty() || k + 1 >= text.size() || text[k] != '=' || text[k + 1] != '"') {
        return fail("bad attribute in <" + element->name + ">");
      }
      const size_t close = text.find('"', k + 2);
      if (close == std::string::npos) return fail("unterminated attribute value");
      const std::string value = text.substr(k + 2, close - k - 2);
      if (value.find('<') != std::string::npos) return fail("'<' in an attribute value");
      if (!element->attributes.emplace(key, value).second) return fail("duplicate " + key);
      j = close + 1;
    }
    i = j;
    Element* raw = element.get();
    if (stack.empty()) {
      if (root) return fail("second root element");
      root = std::move(element);
    } else {
      raw->parent = stack.back();
      stack.back()->children.push_back(std::move(element));
    }
    if (!self_closing) stack.push_back(raw);
  }
  if (!stack.empty()) {
    error = "unclosed <" + stack.back()->name + ">";
    return nullptr;
  }
  if (!root) error = "no root element";
  return root;
}

void Collect(const Element& element, const std::string& name, std::vector<const Element*>& out) {
  if (element.name == name) out.push_back(&element);
  for (const auto& child : element.children) Collect(*child, name, out);
}

std::vector<const Element*> All(const Element& root, const std::string& name) {
  std::vector<const Element*> out;
  Collect(root, name, out);
  return out;
}

const Element* Named(const Element& root, const std::string& tag, const std::string& name) {
  for (const Element* element : All(root, tag)) {
    if (element->Attribute("name") == name) return element;
  }
  return nullptr;
}

std::vector<double> Numbers(const std::string& text) {
  std::vector<double> values;
  std::istringstream in(text);
  double value = 0.0;
  while (in >> value) values.push_back(value);
  return values;
}

Vec3 Vector(const std::string& text) {
  const std::vector<double> v = Numbers(text);
  return v.size() == 3 ? Vec3(v[0], v[1], v[2]) : Vec3::Constant(std::nan(""));
}

// ---------------------------------------------------------------------------------------
// the model and independent figures

Model LaikaModel(const ExperimentOptions& options = {}) {
  auto description = LoadModelDescription(DefaultModelPath());
  EXPECT_TRUE(description.ok()) << description.status().ToString();
  auto model = BuildExperimentModel(*description, options);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return *model;
}

std::unique_ptr<Element> Export(const Model& model, const MjcfOptions& options = {}) {
  auto text = ExportMjcf(model, options);
  EXPECT_TRUE(text.ok()) << text.status().ToString();
  std::string error;
  auto root = ParseXml(*text, error);
  EXPECT_NE(root, nullptr) << error;
  return root;
}

constexpr double kPi = std::numbers::pi;

double RodMass(const Vec3& from, const Vec3& to, double radius, double density) {
  return kPi * radius * radius * (to - from).norm() * density;
}

double BoxMass(double x, double y, double z, double density) { return x * y * z * density; }

double SphereMass(double radius, double density) {
  return 4.0 / 3.0 * kPi * radius * radius * radius * density;
}

// Solid cylinder inertia about the origin: its own about its centre plus the shift.
Mat3 RodInertiaAboutOrigin(const Vec3& from, const Vec3& to, double radius, double density) {
  const double mass = RodMass(from, to, radius, density);
  const double length = (to - from).norm();
  const Vec3 axis = (to - from) / length;
  const Vec3 centre = 0.5 * (from + to);
  const double axial = 0.5 * mass * radius * radius;
  const double across = mass * (3.0 * radius * radius + length * length) / 12.0;
  const Mat3 own =
      across * (Mat3::Identity() - axis * axis.transpose()) + axial * axis * axis.transpose();
  return own + mass * (centre.squaredNorm() * Mat3::Identity() - centre * centre.transpose());
}

// Passive vertebra tips (our frame: x forward, y left, z up).
const Vec3 kTop(0.065, 0.0, 0.096);
const Vec3 kBottom(0.065, 0.0, -0.096);
const Vec3 kRight(-0.065, -0.096, 0.0);
const Vec3 kLeft(-0.065, 0.096, 0.0);

// ---------------------------------------------------------------------------------------

TEST(Mjcf, ExportIsWellFormedXmlWithAMujocoRoot) {
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  EXPECT_EQ(root->name, "mujoco");
  EXPECT_EQ(root->Attribute("model"), "laika-ntrt");
  std::vector<std::string> sections;
  for (const auto& child : root->children) sections.push_back(child->name);
  EXPECT_EQ(sections, (std::vector<std::string>{"compiler", "option", "visual", "default", "asset",
                                                "worldbody", "tendon", "equality"}));
  const Element* compiler = All(*root, "compiler").front();
  EXPECT_EQ(compiler->Attribute("angle"), "radian");
  EXPECT_EQ(compiler->Attribute("inertiafromgeom"), "false");
}

TEST(Mjcf, OptionCarriesTimeStepGravityAndIntegrator) {
  MjcfOptions options;
  options.time_step_s = 5e-4;
  const auto root = Export(LaikaModel(), options);
  ASSERT_NE(root, nullptr);
  const Element* option = All(*root, "option").front();
  EXPECT_DOUBLE_EQ(Numbers(option->Attribute("timestep")).at(0), 5e-4);
  const Vec3 gravity = Vector(option->Attribute("gravity"));
  EXPECT_DOUBLE_EQ(gravity.x(), 0.0);
  EXPECT_DOUBLE_EQ(gravity.y(), 0.0);
  EXPECT_DOUBLE_EQ(gravity.z(), -9.81);
  EXPECT_EQ(option->Attribute("integrator"), "Euler");
  EXPECT_EQ(option->Attribute("cone"), "elliptic");
  // the contact and the hinge drive as stiff as MuJoCo allows: two time steps
  const Element* geom_default = All(*root, "default").front()->children.front().get();
  EXPECT_DOUBLE_EQ(Numbers(geom_default->Attribute("solref")).at(0), 1e-3);
  const Element* drive = Named(*root, "joint", "rotating_vertebra/drive");
  ASSERT_NE(drive, nullptr);
  EXPECT_DOUBLE_EQ(Numbers(drive->Attribute("solref")).at(0), 1e-3);
}

TEST(Mjcf, HoldsSixBodiesFiveFreeJointsAndTheHingeInsideItsParent) {
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  std::set<std::string> names;
  for (const Element* body : All(*root, "body")) names.insert(body->Attribute("name"));
  EXPECT_EQ(names, (std::set<std::string>{"rear", "v2", "v3a", "v3b", "v4", "front"}));
  EXPECT_EQ(All(*root, "body").size(), 6u);
  EXPECT_EQ(All(*root, "freejoint").size(), 5u);

  const auto joints = All(*root, "joint");
  // one hinge joint in the bodies, and the equality that drives it (also a <joint>)
  std::vector<const Element*> hinges;
  for (const Element* joint : joints) {
    if (joint->parent->name == "body") hinges.push_back(joint);
  }
  ASSERT_EQ(hinges.size(), 1u);
  const Element* hinge = hinges.front();
  EXPECT_EQ(hinge->Attribute("name"), "rotating_vertebra");
  EXPECT_EQ(hinge->Attribute("type"), "hinge");
  EXPECT_EQ(hinge->parent->Attribute("name"), "v3b");
  EXPECT_EQ(hinge->parent->parent->Attribute("name"), "v3a");
  // the spine axis (x), through the vertebra's centre
  const Vec3 axis = Vector(hinge->Attribute("axis"));
  EXPECT_NEAR(std::abs(axis.x()), 1.0, 1e-12);
  EXPECT_NEAR(axis.y(), 0.0, 1e-12);
  EXPECT_NEAR(axis.z(), 0.0, 1e-12);
  EXPECT_NEAR(Vector(hinge->Attribute("pos")).norm(), 0.0, 1e-12);
  // free joints only on bodies directly under the world
  for (const Element* free : All(*root, "freejoint")) {
    EXPECT_EQ(free->parent->parent->name, "worldbody") << free->Attribute("name");
  }
  const Element* drive = Named(*root, "joint", "rotating_vertebra/drive");
  ASSERT_NE(drive, nullptr);
  EXPECT_EQ(drive->parent->name, "equality");
  EXPECT_EQ(drive->Attribute("joint1"), "rotating_vertebra");
}

TEST(Mjcf, MassesMatchHandComputedShapes) {
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  const double passive_rods = RodMass(Vec3::Zero(), kTop, 0.0064, 2423) * 4.0;
  const Vec3 shaft_a(-0.0075, 0, 0);
  const Vec3 shaft_b(0.0075, 0, 0);
  const double v3a = RodMass(shaft_a, Vec3(-0.065, -0.096, 0), 0.0064, 2620) * 2.0 +
                     RodMass(shaft_a, Vec3(-0.035, 0, 0), 0.03, 2620);
  const double v3b = RodMass(shaft_b, Vec3(0.065, 0, 0.096), 0.0064, 2620) * 2.0;
  const double end_body = passive_rods + BoxMass(0.126, 0.07, 0.06, 425) +
                          2.0 * BoxMass(0.006, 0.0755, 0.06, 425) + 2.0 * SphereMass(0.0125, 425);
  const std::map<std::string, double> expected = {{"rear", end_body},   {"v2", passive_rods},
                                                  {"v3a", v3a},         {"v3b", v3b},
                                                  {"v4", passive_rods}, {"front", end_body}};
  double total = 0.0;
  for (const auto& [name, mass] : expected) {
    const Element* body = Named(*root, "body", name);
    ASSERT_NE(body, nullptr) << name;
    const Element* inertial = nullptr;
    for (const auto& child : body->children) {
      if (child->name == "inertial") inertial = child.get();
    }
    ASSERT_NE(inertial, nullptr) << name;
    const double written = Numbers(inertial->Attribute("mass")).at(0);
    EXPECT_NEAR(written, mass, 1e-12 * mass) << name;
    EXPECT_EQ(Numbers(inertial->Attribute("fullinertia")).size(), 6u) << name;
    total += written;
  }
  // the reference's table: 0.400, 0.1446, 0.279, 0.0755 kg, 1.443 kg in all
  EXPECT_NEAR(total, 1.443, 0.002);
  EXPECT_NEAR(v3a, 0.279, 0.001);
  EXPECT_NEAR(v3b, 0.0755, 0.0005);
}

TEST(Mjcf, PassiveVertebraInertiaMatchesCylinderFormulas) {
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  Mat3 expected = Mat3::Zero();
  for (const Vec3& tip : {kTop, kBottom, kRight, kLeft}) {
    expected += RodInertiaAboutOrigin(Vec3::Zero(), tip, 0.0064, 2423);
  }
  const Element* body = Named(*root, "body", "v2");
  ASSERT_NE(body, nullptr);
  const Element* inertial = body->children.at(1).get();
  ASSERT_EQ(inertial->name, "inertial");
  // the X is symmetric: its centre of mass is the vertebra's centre
  EXPECT_NEAR(Vector(inertial->Attribute("pos")).norm(), 0.0, 1e-12);
  const std::vector<double> full = Numbers(inertial->Attribute("fullinertia"));
  ASSERT_EQ(full.size(), 6u);
  const double scale = expected.norm();
  EXPECT_NEAR(full[0], expected(0, 0), 1e-9 * scale);
  EXPECT_NEAR(full[1], expected(1, 1), 1e-9 * scale);
  EXPECT_NEAR(full[2], expected(2, 2), 1e-9 * scale);
  EXPECT_NEAR(full[3], expected(0, 1), 1e-9 * scale);
  EXPECT_NEAR(full[4], expected(0, 2), 1e-9 * scale);
  EXPECT_NEAR(full[5], expected(1, 2), 1e-9 * scale);
}

TEST(Mjcf, ThirtyTwoTendonsRunBetweenTheirOwnAnchorSites) {
  const Model model = LaikaModel();
  const auto root = Export(model);
  ASSERT_NE(root, nullptr);
  const auto tendons = All(*root, "spatial");
  ASSERT_EQ(tendons.size(), 32u);
  std::map<std::string, const Element*> sites;
  for (const Element* site : All(*root, "site")) {
    if (site->Has("name")) sites[site->Attribute("name")] = site;
  }
  std::map<std::string, int> per_group;
  for (const Element* tendon : tendons) {
    const std::string name = tendon->Attribute("name");
    ++per_group[name.substr(0, name.size() - 1)];
    EXPECT_EQ(Numbers(tendon->Attribute("stiffness")).at(0), 0.0) << name;
    EXPECT_EQ(Numbers(tendon->Attribute("damping")).at(0), 0.0) << name;
    ASSERT_EQ(tendon->children.size(), 2u) << name;
    EXPECT_EQ(tendon->children[0]->Attribute("site"), name + "/from");
    EXPECT_EQ(tendon->children[1]->Attribute("site"), name + "/to");
    for (const auto& end : tendon->children) {
      EXPECT_EQ(sites.count(end->Attribute("site")), 1u) << end->Attribute("site");
    }
  }
  EXPECT_EQ(per_group, (std::map<std::string, int>{{"HT", 4},
                                                   {"HB", 4},
                                                   {"HR", 4},
                                                   {"HL", 4},
                                                   {"STR", 4},
                                                   {"STL", 4},
                                                   {"SBR", 4},
                                                   {"SBL", 4}}));
}

TEST(Mjcf, TopCableAnchorsSitOnTheRodSurfacesWithTheDocumentedRestLength) {
  // HT1: rear/top to v2/top, 0.099 apart along x; each end moved by the rod radius
  // perpendicular to the rod, towards the other end
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  const Element* from = Named(*root, "site", "HT1/from");
  const Element* to = Named(*root, "site", "HT1/to");
  ASSERT_NE(from, nullptr);
  ASSERT_NE(to, nullptr);
  EXPECT_EQ(from->parent->Attribute("name"), "rear");
  EXPECT_EQ(to->parent->Attribute("name"), "v2");
  const Vec3 from_world = Vector(from->parent->Attribute("pos")) + Vector(from->Attribute("pos"));
  const Vec3 to_world = Vector(to->parent->Attribute("pos")) + Vector(to->Attribute("pos"));
  const Vec3 rod = kTop.normalized();
  const Vec3 along = Vec3::UnitX();
  const Vec3 towards = (along - along.dot(rod) * rod).normalized();
  const double expected_length = (0.099 * along - 2.0 * 0.0064 * towards).norm();
  EXPECT_NEAR((to_world - from_world).norm(), expected_length, 1e-12);
  EXPECT_NEAR(expected_length, 0.0887, 0.0005);  // the reference's figure
  // rest length: attachment distance minus T0 / k = 0.006 m for HT
  const Element* tendon = Named(*root, "spatial", "HT1");
  ASSERT_NE(tendon, nullptr);
  EXPECT_NEAR(Numbers(tendon->Attribute("springlength")).at(0), expected_length - 0.006, 1e-12);
}

TEST(Mjcf, WithoutSpineCollisionsOnlyTheFourFeetTouchTheGround) {
  ExperimentOptions experiment;
  experiment.spine_ground_collisions = false;
  experiment.spine_self_collisions = false;
  const auto root = Export(LaikaModel(experiment));
  ASSERT_NE(root, nullptr);
  const Element* ground = Named(*root, "geom", "ground");
  ASSERT_NE(ground, nullptr);
  EXPECT_EQ(ground->Attribute("type"), "plane");
  EXPECT_EQ(ground->Attribute("conaffinity"), "1");
  std::set<std::string> colliding;
  for (const Element* geom : All(*root, "geom")) {
    if (geom->parent->name != "body") continue;
    if (geom->Has("contype") && geom->Attribute("contype") != "0") {
      colliding.insert(geom->Attribute("name"));
      EXPECT_EQ(geom->Attribute("type"), "sphere");
      EXPECT_DOUBLE_EQ(Numbers(geom->Attribute("size")).at(0), 0.0125);
    }
  }
  EXPECT_EQ(colliding,
            (std::set<std::string>{"front/foot_A", "front/foot_B", "rear/foot_C", "rear/foot_D"}));
  // the default geom collides with nothing and is frictionless (condim 1)
  const Element* defaults = All(*root, "default").front();
  const Element* geom_default = defaults->children.front().get();
  ASSERT_EQ(geom_default->name, "geom");
  EXPECT_EQ(geom_default->Attribute("contype"), "0");
  EXPECT_EQ(geom_default->Attribute("conaffinity"), "0");
  EXPECT_EQ(geom_default->Attribute("condim"), "1");
  EXPECT_DOUBLE_EQ(Numbers(geom_default->Attribute("friction")).at(0), 0.0);
}

TEST(Mjcf, FrictionGoesOnTheFeetAndSpineFrictionOnTheSpine) {
  ExperimentOptions experiment;
  experiment.friction = 0.25;
  experiment.spine_friction = 0.5;
  experiment.spine_ground_collisions = true;
  experiment.spine_self_collisions = true;
  const auto root = Export(LaikaModel(experiment));
  ASSERT_NE(root, nullptr);
  const Element* foot = Named(*root, "geom", "front/foot_A");
  ASSERT_NE(foot, nullptr);
  EXPECT_EQ(foot->Attribute("condim"), "3");
  EXPECT_DOUBLE_EQ(Numbers(foot->Attribute("friction")).at(0), 0.25);
  // rods: on the ground (bit 1) and on each other (bit 2), with the spine's friction
  const Element* rod = Named(*root, "geom", "v2/top");
  ASSERT_NE(rod, nullptr);
  EXPECT_EQ(rod->Attribute("contype"), "3");
  EXPECT_EQ(rod->Attribute("conaffinity"), "2");
  EXPECT_DOUBLE_EQ(Numbers(rod->Attribute("friction")).at(0), 0.5);
  // boxes on the ground only; the massless legs never
  const Element* hips = Named(*root, "geom", "rear/hips");
  ASSERT_NE(hips, nullptr);
  EXPECT_EQ(hips->Attribute("contype"), "1");
  EXPECT_EQ(hips->Attribute("conaffinity"), "0");
  const Element* leg = Named(*root, "geom", "rear/leg_C");
  ASSERT_NE(leg, nullptr);
  EXPECT_FALSE(leg->Has("contype"));
  // the ground keeps the default 0, so each pair gets its geom's value (MuJoCo: maximum)
  EXPECT_FALSE(Named(*root, "geom", "ground")->Has("friction"));
}

TEST(Mjcf, FootMarkersSitAtTheFeetBottomsAndTheLiftRaisesFreeBodiesOnly) {
  const Model model = LaikaModel();
  MjcfOptions options;
  options.lift_m = 0.05;
  const auto root = Export(model, options);
  ASSERT_NE(root, nullptr);
  for (const char* name : {"marker_A", "marker_B", "marker_C", "marker_D"}) {
    const Element* site = Named(*root, "site", name);
    ASSERT_NE(site, nullptr) << name;
    const double z =
        Vector(site->parent->Attribute("pos")).z() + Vector(site->Attribute("pos")).z();
    // the built pose has the feet on the ground: bottom at z = 0, raised by the lift
    EXPECT_NEAR(z, 0.05 + model.description.foot_marker_height_m, 1e-12) << name;
  }
  EXPECT_NEAR(Vector(Named(*root, "body", "v2")->Attribute("pos")).z(), 0.191 + 0.05, 1e-12);
  // the hinge child stays where it is relative to its parent
  EXPECT_NEAR(Vector(Named(*root, "body", "v3b")->Attribute("pos")).norm(), 0.0, 1e-12);
}

TEST(Mjcf, EverythingIsNamedOnce) {
  const auto root = Export(LaikaModel());
  ASSERT_NE(root, nullptr);
  for (const char* tag :
       {"body", "geom", "site", "spatial", "freejoint", "light", "texture", "material"}) {
    std::set<std::string> names;
    for (const Element* element : All(*root, tag)) {
      // a tendon's reference to a site, and the defaults, are not objects
      if (element->parent->name == "spatial" || element->parent->name == "default") continue;
      EXPECT_TRUE(element->Has("name")) << "<" << tag << "> without a name";
      EXPECT_TRUE(names.insert(element->Attribute("name")).second)
          << tag << " " << element->Attribute("name") << " twice";
    }
  }
  // 6 bodies' shapes: 4 rods each on the passive vertebrae and the ends, 3 + 2 on the
  // rotating halves, 5 boxes and 2 feet on each end body, plus the ground
  const auto geoms = All(*root, "geom");
  EXPECT_EQ(std::count_if(geoms.begin(), geoms.end(),
                          [](const Element* geom) { return geom->parent->name != "default"; }),
            4 * 4 + 3 + 2 + 2 * 7 + 1);
}

TEST(Mjcf, TextIsDeterministicAndFollowsTheModel) {
  const Model model = LaikaModel();
  auto first = ExportMjcf(model);
  auto second = ExportMjcf(model);
  ASSERT_TRUE(first.ok());
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(*first, *second);
  ExperimentOptions low;
  low.tension_point_index = 0;
  auto other = ExportMjcf(LaikaModel(low));
  ASSERT_TRUE(other.ok());
  EXPECT_NE(*first, *other);
  EXPECT_NE(other->find("k = 216 N/m"), std::string::npos);  // the low point's silicone
}

TEST(Mjcf, PositionActuatorReplacesTheEquality) {
  MjcfOptions options;
  options.hinge_drive = MjcfHingeDrive::kPositionActuator;
  options.hinge_gain_n_m_per_rad = 150.0;
  const auto root = Export(LaikaModel(), options);
  ASSERT_NE(root, nullptr);
  EXPECT_TRUE(All(*root, "equality").empty());
  const auto servos = All(*root, "position");
  ASSERT_EQ(servos.size(), 1u);
  EXPECT_EQ(servos.front()->Attribute("name"), "rotating_vertebra/servo");
  EXPECT_EQ(servos.front()->Attribute("joint"), "rotating_vertebra");
  EXPECT_DOUBLE_EQ(Numbers(servos.front()->Attribute("kp")).at(0), 150.0);
  EXPECT_TRUE(Named(*root, "joint", "rotating_vertebra")->Has("damping"));
}

TEST(Mjcf, WritesTheFile) {
  testing::ScratchDir scratch;
  const Model model = LaikaModel();
  ASSERT_TRUE(WriteMjcf(scratch / "out" / "laika.xml", model).ok());
  EXPECT_EQ(testing::ReadFile(scratch / "out" / "laika.xml"), *ExportMjcf(model));
}

TEST(Mjcf, RejectsOptionsMujocoWouldChange) {
  const Model model = LaikaModel();
  MjcfOptions options;
  options.time_step_s = 0.002;
  options.contact_time_constant_s = 0.002;  // < 2 steps: MuJoCo would raise it
  auto text = ExportMjcf(model, options);
  ASSERT_FALSE(text.ok());
  EXPECT_EQ(text.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(text.status().message().find("contact_time_constant_s"), std::string::npos)
      << text.status().message();
  options = MjcfOptions();
  options.contact_impedance = 1.0;
  EXPECT_FALSE(ExportMjcf(model, options).ok());
  options = MjcfOptions();
  options.time_step_s = 0.0;
  EXPECT_FALSE(ExportMjcf(model, options).ok());
}

}  // namespace
}  // namespace liftoff::sim
