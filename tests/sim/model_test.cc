#include "liftoff/sim/model.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/core/json.h"
#include "liftoff/sim/experiment.h"

namespace liftoff::sim {
namespace {

constexpr double kPi = std::numbers::pi;

Model LoadLaika() {
  Result<Model> model = LoadModel(DefaultModelPath());
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  return model.ok() ? *model : Model{};
}

const Body& BodyNamed(const Model& model, const std::string& name) {
  const int index = model.BodyIndex(name);
  EXPECT_GE(index, 0) << name;
  return model.bodies[static_cast<size_t>(std::max(index, 0))];
}

TEST(Model, BundledLaikaHasTheDocumentedParts) {
  const Model model = LoadLaika();
  EXPECT_EQ(model.bodies.size(), 6u);
  EXPECT_EQ(model.hinges.size(), 1u);
  EXPECT_EQ(model.cables.size(), 32u);
  EXPECT_EQ(model.feet.size(), 4u);
  for (const char* group : {"HT", "HB", "HR", "HL", "STR", "STL", "SBR", "SBL"}) {
    EXPECT_EQ(model.CablesInGroup(group).size(), 4u) << group;
  }
  // feet 0.648 apart front to back and 0.151 left to right, bottoms on the ground
  const auto foot = [&](Foot f) {
    const FootPoint& point =
        model.feet[static_cast<size_t>(model.foot_index[static_cast<size_t>(f)])];
    const Body& body = model.bodies[static_cast<size_t>(point.body)];
    return Vec3(body.initial_position_m + body.initial_orientation * point.bottom_m);
  };
  EXPECT_NEAR(foot(Foot::kA).x() - foot(Foot::kC).x(), 0.648, 1e-12);
  EXPECT_NEAR(foot(Foot::kB).y() - foot(Foot::kA).y(), 0.151, 1e-12);
  EXPECT_NEAR(foot(Foot::kD).y() - foot(Foot::kC).y(), 0.151, 1e-12);
  EXPECT_GT(foot(Foot::kA).y(), -1.0);  // A is on the right: y < 0 (y to the left)
  EXPECT_LT(foot(Foot::kA).y(), 0.0);
  for (Foot f : kAllFeet) EXPECT_NEAR(foot(f).z(), 0.0, 1e-12) << FootName(f);
}

TEST(Model, EveryCableJoinsTheDocumentedNodes) {
  // independent table: gap g (1..4) joins vertebra g - 1 (from) to vertebra g (to), in the
  // order rear, v2, v3, v4, front; horizontal cables join like nodes, saddle cables run
  // from the forward tip (top or bottom) to the back tip (right or left) of the next
  // vertebra; on v3, top and bottom belong to v3b, right and left to v3a. Nodes in the
  // body frame (x forward, y to the left): tips 0.065 m forward or back of the centre,
  // 0.096 m out.
  struct Ends {
    const char* group;
    const char* from_node;
    const char* to_node;
  };
  const Ends table[] = {{"HT", "top", "top"},       {"HB", "bottom", "bottom"},
                        {"HR", "right", "right"},   {"HL", "left", "left"},
                        {"STR", "top", "right"},    {"STL", "top", "left"},
                        {"SBR", "bottom", "right"}, {"SBL", "bottom", "left"}};
  const char* vertebrae[] = {"rear", "v2", "v3", "v4", "front"};
  const auto body_of = [](const std::string& vertebra, const std::string& node) {
    if (vertebra != "v3") return vertebra;
    return std::string(node == "top" || node == "bottom" ? "v3b" : "v3a");
  };
  const auto node_at = [](const std::string& node) {
    if (node == "top") return Vec3(0.065, 0.0, 0.096);
    if (node == "bottom") return Vec3(0.065, 0.0, -0.096);
    if (node == "right") return Vec3(-0.065, -0.096, 0.0);
    return Vec3(-0.065, 0.096, 0.0);  // left
  };
  const Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  const Model model = LoadLaika();
  ASSERT_EQ(model.cables.size(), 32u);
  ASSERT_EQ(description->cables.size(), 32u);
  int checked = 0;
  for (const Ends& ends : table) {
    for (int gap = 1; gap <= 4; ++gap) {
      const std::string name = std::string(ends.group) + std::to_string(gap);
      SCOPED_TRACE(name);
      const std::string from_body = body_of(vertebrae[gap - 1], ends.from_node);
      const std::string to_body = body_of(vertebrae[gap], ends.to_node);
      int found = 0;
      for (size_t c = 0; c < model.cables.size(); ++c) {
        const Cable& cable = model.cables[c];
        if (cable.name != name) continue;
        ++found;
        EXPECT_EQ(model.cable_groups[static_cast<size_t>(cable.group)].name, ends.group);
        EXPECT_EQ(cable.body_a, model.BodyIndex(from_body));
        EXPECT_EQ(cable.body_b, model.BodyIndex(to_body));
        EXPECT_LT((cable.node_a_m - node_at(ends.from_node)).norm(), 1e-12);
        EXPECT_LT((cable.node_b_m - node_at(ends.to_node)).norm(), 1e-12);
        const CableDescription& written = description->cables[c];
        EXPECT_EQ(written.name, name);
        EXPECT_EQ(written.from_body, from_body);
        EXPECT_EQ(written.from_node, ends.from_node);
        EXPECT_EQ(written.to_body, to_body);
        EXPECT_EQ(written.to_node, ends.to_node);
      }
      EXPECT_EQ(found, 1);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 32);
}

TEST(Model, MassesMatchTheReferenceTable) {
  const Model model = LoadLaika();
  // by hand: solid cylinders pi r^2 L rho, boxes and spheres
  const double passive_rod = kPi * 0.0064 * 0.0064 * std::hypot(0.065, 0.096) * 2423.0;
  const double v3_rod = kPi * 0.0064 * 0.0064 * std::hypot(0.0575, 0.096) * 2620.0;
  const double motor = kPi * 0.03 * 0.03 * 0.0275 * 2620.0;
  const double end_body = 0.126 * 0.07 * 0.06 * 425.0 + 2.0 * 0.0755 * 0.006 * 0.06 * 425.0 +
                          2.0 * 4.0 / 3.0 * kPi * std::pow(0.0125, 3) * 425.0 + 4.0 * passive_rod;
  EXPECT_NEAR(BodyNamed(model, "rear").mass_kg, end_body, 1e-12);
  EXPECT_NEAR(BodyNamed(model, "v2").mass_kg, 4.0 * passive_rod, 1e-12);
  EXPECT_NEAR(BodyNamed(model, "v3a").mass_kg, 2.0 * v3_rod + motor, 1e-12);
  EXPECT_NEAR(BodyNamed(model, "v3b").mass_kg, 2.0 * v3_rod, 1e-12);
  // and the table in laika-model.md (rounded there)
  EXPECT_NEAR(BodyNamed(model, "rear").mass_kg, 0.400, 0.0005);
  EXPECT_NEAR(BodyNamed(model, "v2").mass_kg, 0.1446, 0.00005);
  EXPECT_NEAR(BodyNamed(model, "v3a").mass_kg, 0.279, 0.0005);
  EXPECT_NEAR(BodyNamed(model, "v3b").mass_kg, 0.0755, 0.00005);
  EXPECT_NEAR(BodyNamed(model, "v4").mass_kg, 0.1446, 0.00005);
  EXPECT_NEAR(BodyNamed(model, "front").mass_kg, 0.400, 0.0005);
  EXPECT_NEAR(model.total_mass_kg, 1.443, 0.0005);
}

TEST(Model, PassiveVertebraInertiaMatchesHandComputation) {
  // four rods from the centre: about the centre each is m (L^2/3 + r^2/4) across its axis
  // and m r^2 / 2 along it; the tips sum to zero so the centre is the centre of mass
  const Model model = LoadLaika();
  const Body& v2 = BodyNamed(model, "v2");
  EXPECT_LT(v2.com_m.norm(), 1e-15);
  const double length = std::hypot(0.065, 0.096);
  const double mass = kPi * 0.0064 * 0.0064 * length * 2423.0;
  const double across = mass * (length * length / 3.0 + 0.0064 * 0.0064 / 4.0);
  const double along = mass * 0.0064 * 0.0064 / 2.0;
  const double x_share = 0.065 * 0.065 / (length * length);  // d_x^2 of every rod
  EXPECT_NEAR(v2.inertia_kg_m2(0, 0), 4.0 * (across * (1.0 - x_share) + along * x_share), 1e-12);
  // about y: top/bottom rods have d_y = 0, right/left d_y^2 = 0.096^2 / L^2
  const double y_share = 0.096 * 0.096 / (length * length);
  EXPECT_NEAR(v2.inertia_kg_m2(1, 1),
              2.0 * across + 2.0 * (across * (1.0 - y_share) + along * y_share), 1e-12);
  // symmetric: no products of inertia about the body axes
  EXPECT_NEAR(v2.inertia_kg_m2(0, 1), 0.0, 1e-15);
  EXPECT_NEAR(v2.inertia_kg_m2(1, 2), 0.0, 1e-15);
}

TEST(Model, MassPropertiesOfSimpleShapes) {
  // a rod along x: m r^2 / 2 about x, m (3 r^2 + L^2) / 12 about y and z
  const MassProperties rod = RodMassProperties(Vec3(0, 0, 0), Vec3(2, 0, 0), 0.1, 100.0);
  const double m = kPi * 0.01 * 2.0 * 100.0;
  EXPECT_NEAR(rod.mass_kg, m, 1e-12);
  EXPECT_NEAR(rod.inertia_kg_m2(0, 0), m * 0.01 / 2.0, 1e-12);
  EXPECT_NEAR(rod.inertia_kg_m2(1, 1), m * (0.03 + 4.0) / 12.0, 1e-12);
  EXPECT_TRUE(rod.com_m.isApprox(Vec3(1, 0, 0)));
  // two unit spheres 2 m apart: parallel axes add m d^2 about the axes across the line
  const MassProperties sphere = SphereMassProperties(Vec3(1, 0, 0), 1.0, 1.0);
  const MassProperties other = SphereMassProperties(Vec3(-1, 0, 0), 1.0, 1.0);
  const MassProperties pair = CombineMassProperties({sphere, other});
  const double ms = 4.0 / 3.0 * kPi;
  EXPECT_NEAR(pair.inertia_kg_m2(0, 0), 2.0 * 0.4 * ms, 1e-12);
  EXPECT_NEAR(pair.inertia_kg_m2(1, 1), 2.0 * (0.4 * ms + ms * 1.0), 1e-12);
  // a box
  const MassProperties box = BoxMassProperties(Vec3::Zero(), Vec3(1, 2, 3), 2.0);
  EXPECT_NEAR(box.mass_kg, 12.0, 1e-12);
  EXPECT_NEAR(box.inertia_kg_m2(0, 0), 12.0 * (4.0 + 9.0) / 12.0, 1e-12);
}

TEST(Model, SurfaceAttachmentShortensHorizontalCablesAsNtrtDid) {
  // a horizontal cable between equal rods (direction d = (0.065, 0, 0.096) / L) ends r
  // from each node, perpendicular to the rod towards the other node: by hand, the
  // perpendicular part of x is (1, 0, 0) - d d_x
  const Model model = LoadLaika();
  const Cable& top = model.cables[static_cast<size_t>(model.CablesInGroup("HT")[0])];
  const double length = std::hypot(0.065, 0.096);
  const Vec3 d(0.065 / length, 0.0, 0.096 / length);
  const Vec3 across = (Vec3(1, 0, 0) - d * d.x()).normalized() * 0.0064;
  const double expected = (Vec3(0.099, 0, 0) - 2.0 * across).norm();
  EXPECT_NEAR(top.initial_length_m, expected, 1e-12);
  EXPECT_NEAR(top.initial_length_m, 0.0887, 0.0001);
  EXPECT_NEAR(top.initial_node_length_m, 0.099, 1e-12);
  // the bundled file is at the mean point: HT's T0 = 0.006 * 237 N, so rest = x - 0.006
  EXPECT_NEAR(top.rest_length_m, expected - 0.006, 1e-12);
  // saddles: about 0.139 node to node
  const Cable& saddle = model.cables[static_cast<size_t>(model.CablesInGroup("STR")[0])];
  EXPECT_NEAR(saddle.initial_node_length_m, std::sqrt(0.031 * 0.031 + 2 * 0.096 * 0.096), 1e-12);
}

TEST(Model, NodeAttachmentAndNodeRestLengths) {
  Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  description->cable_attachment = CableAttachment::kNode;
  Result<Model> node = BuildModel(*description);
  ASSERT_TRUE(node.ok()) << node.status().ToString();
  const Cable& top = node->cables[static_cast<size_t>(node->CablesInGroup("HT")[0])];
  EXPECT_EQ(top.anchor_a_m, top.node_a_m);
  EXPECT_NEAR(top.initial_length_m, 0.099, 1e-12);
  EXPECT_NEAR(top.rest_length_m, 0.099 - 0.006, 1e-12);
  // surface anchors with node-based rest lengths: slacker by the 0.0103 m difference
  description->cable_attachment = CableAttachment::kSurface;
  description->rest_length_reference = RestLengthReference::kNode;
  Result<Model> slack = BuildModel(*description);
  ASSERT_TRUE(slack.ok()) << slack.status().ToString();
  const Cable& slack_top = slack->cables[static_cast<size_t>(slack->CablesInGroup("HT")[0])];
  EXPECT_NEAR(slack_top.rest_length_m, 0.099 - 0.006, 1e-12);
  EXPECT_LT(slack_top.initial_length_m, slack_top.rest_length_m);
}

TEST(Model, SurfaceAnchorIsPerpendicularToTheRod) {
  const Vec3 node(1, 0, 0);
  const Vec3 anchor = SurfaceAnchor(node, Vec3(1, 0, 0), 0.1, Vec3(3, 2, 0));
  EXPECT_TRUE(anchor.isApprox(Vec3(1, 0.1, 0)));
  // a destination on the rod's line: the node itself
  EXPECT_TRUE(SurfaceAnchor(node, Vec3(1, 0, 0), 0.1, Vec3(5, 0, 0)).isApprox(node));
}

TEST(Model, RaisedFootMarkersSitAboveTheFeet) {
  Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  ASSERT_TRUE(description.ok());
  description->foot_marker_height_m = 1.5;
  Result<Model> model = BuildModel(*description);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  for (const FootPoint& foot : model->feet) {
    EXPECT_TRUE((foot.marker_m - foot.bottom_m).isApprox(Vec3(0, 0, 1.5)));
  }
}

// A two-body model in the file format, for the error tests.
nlohmann::json TinyModel() {
  return nlohmann::json::parse(R"({
    "format": "liftoff-sim-model", "version": 1, "name": "tiny",
    "gravity_m_per_s2": [0, 0, -9.81],
    "bodies": [
      {"name": "a", "position_m": [0, 0, 1], "nodes": {"c": [0, 0, 0], "tip": [0.1, 0, 0]},
       "rods": [{"name": "r", "from": "c", "to": "tip", "radius_m": 0.01,
                 "density_kg_per_m3": 1000}]},
      {"name": "b", "position_m": [0.3, 0, 1], "nodes": {"c": [0, 0, 0]},
       "spheres": [{"name": "s", "center_m": [0, 0, 0], "radius_m": 0.02,
                    "density_kg_per_m3": 1000, "foot": "A"}]}
    ],
    "cable_groups": [{"name": "g", "stiffness_n_per_m": 100, "damping_n_s_per_m": 1,
                      "pretension_n": 1}],
    "cables": [{"name": "k", "group": "g", "from": "a/tip", "to": "b/c"}]
  })");
}

Status LoadError(const nlohmann::json& document) {
  const Result<ModelDescription> description = ModelDescriptionFromJson(document, "tiny.json");
  return description.ok() ? Status::Ok() : description.status();
}

TEST(Model, TinyModelLoadsAndRoundTrips) {
  const Result<ModelDescription> description = ModelDescriptionFromJson(TinyModel(), "tiny.json");
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  const nlohmann::json written = ModelDescriptionToJson(*description);
  const Result<ModelDescription> again = ModelDescriptionFromJson(written, "again");
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  EXPECT_EQ(ModelDescriptionToJson(*again), written);
}

TEST(Model, UnknownNodeIsNamedWithItsPointer) {
  nlohmann::json document = TinyModel();
  document["cables"][0]["to"] = "b/tip";
  const Status status = LoadError(document);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("tiny.json: /cables/0/to: unknown node \"b/tip\""),
            std::string::npos)
      << status.message();
  document["cables"][0]["to"] = "nobody/c";
  EXPECT_NE(LoadError(document).message().find("/cables/0/to: unknown node \"nobody/c\": no body"),
            std::string::npos);
  document["cables"][0]["to"] = "a/c";
  EXPECT_NE(LoadError(document).message().find("/cables/0/to: expected a node on another body"),
            std::string::npos);
}

TEST(Model, NegativeStiffnessIsNamedWithItsPointer) {
  nlohmann::json document = TinyModel();
  document["cable_groups"][0]["stiffness_n_per_m"] = -5;
  const Status status = LoadError(document);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("tiny.json: /cable_groups/0/stiffness_n_per_m: expected a "
                                  "number in [0.001, 1e+08], got -5"),
            std::string::npos)
      << status.message();
}

// positive is not enough: a stiffness of 1e-320 or 1e300 passes "> 0" and breaks the engine
TEST(Model, FieldsOutsidePhysicalRangesAreNamedWithTheirPointer) {
  struct Case {
    std::string pointer;
    double value;
    std::string range;  // as docs/sim.md gives it
  };
  for (const Case& c :
       {Case{"/cable_groups/0/stiffness_n_per_m", 1e-320, "[0.001, 1e+08]"},
        Case{"/cable_groups/0/stiffness_n_per_m", 1e300, "[0.001, 1e+08]"},
        Case{"/cable_groups/0/damping_n_s_per_m", 1e300, "[0, 1e+06]"},
        Case{"/cable_groups/0/pretension_n", 1e300, "[0, 1e+06]"},
        Case{"/bodies/1/spheres/0/radius_m", 1e3, "(0, 100]"},
        Case{"/bodies/1/spheres/0/density_kg_per_m3", 1e16, "[0, 1e+15]"}}) {
    SCOPED_TRACE(c.pointer);
    nlohmann::json document = TinyModel();
    document[nlohmann::json::json_pointer(c.pointer)] = c.value;
    const Status status = LoadError(document);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(status.message().find("tiny.json: " + c.pointer + ": expected a number in " + c.range),
              std::string::npos)
        << status.message();
  }
}

TEST(Model, NotANumberIsNamedWithItsPointer) {
  // JSON has no NaN: it comes from code, through BuildModel
  Result<ModelDescription> description = ModelDescriptionFromJson(TinyModel(), "tiny.json");
  ASSERT_TRUE(description.ok());
  description->bodies[1].position_m.y() = std::numeric_limits<double>::quiet_NaN();
  const Result<Model> model = BuildModel(*description, "code");
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.status().message().find("code: /bodies/1/position_m/1: expected a number, got"),
            std::string::npos)
      << model.status().message();
  description->bodies[1].position_m.y() = 0.0;
  description->cable_groups[0].damping_n_s_per_m = std::numeric_limits<double>::infinity();
  EXPECT_NE(BuildModel(*description).status().message().find("/cable_groups/0/damping_n_s_per_m"),
            std::string::npos);
}

TEST(Model, OtherMistakesAreRejected) {
  nlohmann::json document = TinyModel();
  document["bodies"][0]["rods"][0]["radius_mm"] = 10;  // a misspelt key
  EXPECT_NE(LoadError(document).message().find("/bodies/0/rods/0/radius_mm: unknown key"),
            std::string::npos)
      << LoadError(document).message();

  document = TinyModel();
  document["cable_groups"][0]["pretension_n"] = 100;  // T0 / k = 1 m > the cable's length
  EXPECT_NE(LoadError(document).message().find("/cables/0: its pretension"), std::string::npos);

  document = TinyModel();
  document["bodies"][1]["spheres"][0]["density_kg_per_m3"] = 0;  // a body without mass
  EXPECT_NE(LoadError(document).message().find("/bodies/1: body \"b\" has no mass"),
            std::string::npos);

  document = TinyModel();
  document["format"] = "something-else";
  EXPECT_EQ(LoadError(document).code(), StatusCode::kUnsupported);

  document = TinyModel();
  document["version"] = 2;
  EXPECT_EQ(LoadError(document).code(), StatusCode::kUnsupported);

  document = TinyModel();
  document["cables"][0]["group"] = "h";
  EXPECT_NE(LoadError(document).message().find("/cables/0/group: unknown cable group \"h\""),
            std::string::npos);

  document = TinyModel();
  document["bodies"][1]["name"] = "a";
  EXPECT_NE(LoadError(document).message().find("/bodies/1/name: body \"a\" is listed twice"),
            std::string::npos);
}

TEST(Model, MissingFileIsNotFound) {
  EXPECT_EQ(LoadModel("/nonexistent/laika.json").status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace liftoff::sim
