#include "liftoff/sim/engine.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "liftoff/sim/experiment.h"
#include "liftoff/sim/model.h"

namespace liftoff::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// A solid sphere body with one node at its centre.
BodyDescription SphereBody(const std::string& name, const Vec3& position_m, double radius_m,
                           double density_kg_per_m3) {
  BodyDescription body;
  body.name = name;
  body.position_m = position_m;
  body.nodes = {{"c", Vec3::Zero()}};
  SphereDescription sphere;
  sphere.name = name;
  sphere.radius_m = radius_m;
  sphere.density_kg_per_m3 = density_kg_per_m3;
  body.spheres.push_back(sphere);
  return body;
}

// A bob of mass m between two very heavy anchors along x, one cable to each, no gravity:
// a spring-mass oscillator along x with stiffness 2k while both cables stay taut.
ModelDescription Oscillator(double stiffness_n_per_m, double damping_n_s_per_m,
                            double pretension_n) {
  ModelDescription model;
  model.name = "oscillator";
  model.gravity_m_per_s2 = Vec3::Zero();
  model.cable_attachment = CableAttachment::kNode;
  // bob: 0.1 kg (radius 0.02 m)
  const double bob_radius = 0.02;
  const double bob_density = 0.1 / (4.0 / 3.0 * kPi * std::pow(bob_radius, 3));
  model.bodies.push_back(SphereBody("left", Vec3(-0.5, 0.0, 1.0), 0.05, 1e12));
  model.bodies.push_back(SphereBody("bob", Vec3(0.0, 0.0, 1.0), bob_radius, bob_density));
  model.bodies.push_back(SphereBody("right", Vec3(0.5, 0.0, 1.0), 0.05, 1e12));
  model.cable_groups.push_back(
      {"spring", "test", stiffness_n_per_m, damping_n_s_per_m, pretension_n});
  model.cables.push_back({"to_left", "spring", "left", "c", "bob", "c"});
  model.cables.push_back({"to_right", "spring", "bob", "c", "right", "c"});
  return model;
}

double TotalEnergy(const Model& model, const State& state) {
  return KineticEnergy(model, state) + PotentialEnergy(model, state);
}

TEST(Engine, UndampedSpringMassKeepsItsEnergyAndPeriod) {
  // k = 200 N/m per cable, 2k on the bob: omega = sqrt(400 / 0.1) = 63.2 rad/s, period
  // 0.0993 s; pretension 4 N (0.02 m stretch) and amplitude 0.01 m keep both taut
  const Result<Model> model = BuildModel(Oscillator(200.0, 0.0, 4.0));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  EXPECT_NEAR(model->bodies[1].mass_kg, 0.1, 1e-12);
  State state = InitialState(*model);
  state.bodies[1].position_m.x() = 0.01;
  EngineOptions options;
  options.time_step_s = 1e-4;
  const double initial_energy = TotalEnergy(*model, state);
  const double period = 2.0 * kPi / std::sqrt(400.0 / 0.1);

  // 100 periods: energy stays within 0.5 % (symplectic Euler: bounded, no drift); count
  // upward zero crossings of x to measure the period
  double previous_x = state.bodies[1].position_m.x();
  std::vector<double> crossings;
  double worst = 0.0;
  const int steps = static_cast<int>(std::round(100.0 * period / options.time_step_s));
  for (int i = 0; i < steps; ++i) {
    Step(*model, options, {}, state);
    worst = std::max(worst, std::abs(TotalEnergy(*model, state) / initial_energy - 1.0));
    const double x = state.bodies[1].position_m.x();
    if (previous_x < 0.0 && x >= 0.0) {
      // linear interpolation of the crossing instant
      crossings.push_back(state.time_s - options.time_step_s * x / (x - previous_x));
    }
    previous_x = x;
  }
  EXPECT_LT(worst, 0.005);
  ASSERT_GE(crossings.size(), 90u);
  const double measured_period =
      (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(measured_period, period, 0.001 * period);
}

TEST(Engine, DampedCableLosesEnergyMonotonicallyAtTheDampingRate) {
  // c = 0.2 N*s/m per cable: energy decays as exp(-(2c/m) t) = exp(-4 t)
  const Result<Model> model = BuildModel(Oscillator(200.0, 0.2, 4.0));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model);
  state.bodies[1].position_m.x() = 0.01;
  EngineOptions options;
  options.time_step_s = 1e-4;
  const double spring_energy_at_rest = PotentialEnergy(*model, InitialState(*model));
  auto oscillation_energy = [&] { return TotalEnergy(*model, state) - spring_energy_at_rest; };
  const double initial = oscillation_energy();
  double previous = initial;
  for (int i = 0; i < 10000; ++i) {  // 1 s
    Step(*model, options, {}, state);
    const double energy = oscillation_energy();
    EXPECT_LE(energy, previous * (1.0 + 1e-12)) << "step " << i;
    previous = energy;
  }
  EXPECT_NEAR(previous / initial, std::exp(-4.0), 0.05 * std::exp(-4.0));
}

TEST(Engine, SlackCableExertsNoForce) {
  // bob between anchors 0.5 m away, rest lengths 0.6 m: both cables slack; the bob
  // coasts at exactly its initial velocity, even while the cables shorten and lengthen
  ModelDescription description = Oscillator(200.0, 10.0, 0.0);
  Result<Model> built = BuildModel(description);
  ASSERT_TRUE(built.ok()) << built.status().ToString();
  Model model = *built;
  for (Cable& cable : model.cables) cable.rest_length_m = 0.6;
  State state = InitialState(model);
  const Vec3 velocity(0.3, 0.0, 0.0);
  state.bodies[1].velocity_m_per_s = velocity;
  EngineOptions options;
  for (int i = 0; i < 300; ++i) {  // 0.3 s: the bob moves 0.09 m, still inside both
    Step(model, options, {}, state);
    ASSERT_EQ(state.bodies[1].velocity_m_per_s, velocity) << "step " << i;
    for (int c = 0; c < 2; ++c) EXPECT_EQ(ReadCable(model, state, c).tension_n, 0.0);
  }
}

TEST(Engine, CableTensionIsZeroWheneverShorterThanRest) {
  // property over a grid, including fast shortening and fast lengthening
  for (double length : {0.05, 0.0999, 0.1}) {
    for (double rate : {-100.0, -1.0, 0.0, 1.0, 100.0}) {
      for (bool cap : {false, true}) {
        EXPECT_EQ(CableTension(length, rate, 0.1, 237.0, 10.0, cap), 0.0);
      }
    }
  }
  // taut: spring plus damper, never negative; the cap bounds the damper by the spring
  EXPECT_DOUBLE_EQ(CableTension(0.11, 0.0, 0.1, 200.0, 10.0, true), 2.0);
  EXPECT_DOUBLE_EQ(CableTension(0.11, 0.1, 0.1, 200.0, 10.0, false), 3.0);
  EXPECT_DOUBLE_EQ(CableTension(0.11, 1.0, 0.1, 200.0, 10.0, true), 4.0);
  EXPECT_DOUBLE_EQ(CableTension(0.11, -1.0, 0.1, 200.0, 10.0, true), 0.0);
  EXPECT_DOUBLE_EQ(CableTension(0.11, -1.0, 0.1, 200.0, 10.0, false), 0.0);
}

// A 1 kg box (0.1 m cube) resting on the ground.
ModelDescription BoxOnGround(double friction, double restitution, double height_m) {
  ModelDescription model;
  model.name = "box";
  model.contact.friction = friction;
  model.contact.restitution = restitution;
  model.contact.spine_ground = true;
  BodyDescription body;
  body.name = "box";
  body.position_m = Vec3(0.0, 0.0, 0.05 + height_m);
  BoxDescription box;
  box.name = "box";
  box.size_m = Vec3(0.1, 0.1, 0.1);
  box.density_kg_per_m3 = 1000.0;
  body.boxes.push_back(box);
  model.bodies.push_back(body);
  return model;
}

TEST(Engine, SlidingBoxStopsAfterTheCoulombDistance) {
  // v0 = 1 m/s, mu = 0.25: stops after v0^2 / (2 mu g) = 0.2039 m
  const Result<Model> model = BuildModel(BoxOnGround(0.25, 0.0, 0.0));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model);
  state.bodies[0].velocity_m_per_s = Vec3(1.0, 0.0, 0.0);
  EngineOptions options;
  options.time_step_s = 1e-4;
  for (int i = 0; i < 10000; ++i) Step(*model, options, {}, state);
  EXPECT_NEAR(state.bodies[0].position_m.x(), 1.0 / (2.0 * 0.25 * 9.81), 0.002);
  EXPECT_LT(state.bodies[0].velocity_m_per_s.norm(), 1e-6);
  EXPECT_NEAR(state.bodies[0].position_m.z(), 0.05, 1e-5);
}

TEST(Engine, FrictionlessBoxKeepsSliding) {
  const Result<Model> model = BuildModel(BoxOnGround(0.0, 0.0, 0.0));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model);
  state.bodies[0].velocity_m_per_s = Vec3(1.0, 0.0, 0.0);
  EngineOptions options;
  for (int i = 0; i < 1000; ++i) Step(*model, options, {}, state);
  EXPECT_NEAR(state.bodies[0].velocity_m_per_s.x(), 1.0, 1e-9);
  EXPECT_NEAR(state.bodies[0].position_m.x(), 1.0, 1e-6);
}

TEST(Engine, DroppedBoxLandsWithoutBouncingAtZeroRestitution) {
  const Result<Model> model = BuildModel(BoxOnGround(0.5, 0.0, 0.05));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model);
  EngineOptions options;
  bool landed = false;
  for (int i = 0; i < 1000; ++i) {
    Step(*model, options, {}, state);
    const double bottom = state.bodies[0].position_m.z() - 0.05;
    if (bottom < 1e-4) landed = true;
    if (landed) {
      EXPECT_LT(bottom, 1e-4) << "bounced at step " << i;
    }
    EXPECT_GT(bottom, -1e-3) << "sank at step " << i;
  }
  EXPECT_TRUE(landed);
  EXPECT_NEAR(state.bodies[0].position_m.z(), 0.05, 1e-6);
}

TEST(Engine, RestitutionBouncesToTheSquaredHeight) {
  // e = 0.5 from 0.1 m: back up to e^2 h = 0.025 m
  const Result<Model> model = BuildModel(BoxOnGround(0.0, 0.5, 0.1));
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model);
  EngineOptions options;
  options.time_step_s = 1e-4;
  bool landed = false;
  double apex = 0.0;
  for (int i = 0; i < 4000; ++i) {
    Step(*model, options, {}, state);
    const double bottom = state.bodies[0].position_m.z() - 0.05;
    if (bottom < 1e-4) landed = true;
    if (landed && state.time_s < 0.35) apex = std::max(apex, bottom);
  }
  EXPECT_TRUE(landed);
  EXPECT_NEAR(apex, 0.025, 0.0015);
}

TEST(Engine, HingeChildFollowsTheCommandedAngle) {
  const Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  const Result<Model> model = BuildModel(*description);
  ASSERT_TRUE(model.ok()) << model.status().ToString();
  State state = InitialState(*model, 0.0);
  Controls controls;
  controls.hinge_angle_rad = {0.3};
  Step(*model, EngineOptions{}, controls, state);
  const Hinge& hinge = model->hinges[0];
  const Quat parent = state.bodies[static_cast<size_t>(hinge.parent)].orientation;
  const Quat child = state.bodies[static_cast<size_t>(hinge.child)].orientation;
  const Eigen::AngleAxisd relative(parent.conjugate() * child);
  EXPECT_NEAR(relative.angle(), 0.3, 1e-12);
  EXPECT_NEAR(std::abs(relative.axis().dot(hinge.axis)), 1.0, 1e-12);
  // a point on the axis stays where the parent has it
  const Vec3 on_axis_parent = WorldPoint(state, hinge.parent, hinge.point_m + hinge.axis);
  const Vec3 on_axis_child =
      WorldPoint(state, hinge.child,
                 hinge.child_orientation_in_parent.conjugate() *
                     (hinge.point_m + hinge.axis - hinge.child_position_in_parent_m));
  EXPECT_LT((on_axis_parent - on_axis_child).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(state.hinge_angle_rad[0], 0.3);
}

// The review's two-cable toy: a 0.1 kg bob at the origin (z 1 m), cable A to a fixed
// anchor at x = -0.5 m barely taut (k 100 N/m, c 10 N*s/m, 1e-4 N: 1e-6 m of stretch),
// cable B (k 1000 N/m, no damping) pulling the bob with 100 N towards A's anchor
// (`b_towards_a`: A shortens, an implicit damper would push) or away from it (A lengthens
// fast, an implicit damper would exceed the cap 2 k (x - r) = 2e-4 N).
ModelDescription TwoCables(bool b_towards_a) {
  ModelDescription model;
  model.name = "two_cables";
  model.gravity_m_per_s2 = Vec3::Zero();
  model.cable_attachment = CableAttachment::kNode;
  const double bob_radius = 0.02;
  const double bob_density = 0.1 / (4.0 / 3.0 * kPi * std::pow(bob_radius, 3));
  model.bodies.push_back(SphereBody("near", Vec3(-0.5, 0.0, 1.0), 0.05, 1e12));
  model.bodies.push_back(SphereBody("far", Vec3(b_towards_a ? -1.0 : 0.5, 0.0, 1.0), 0.05, 1e12));
  model.bodies.push_back(SphereBody("bob", Vec3(0.0, 0.0, 1.0), bob_radius, bob_density));
  model.cable_groups.push_back({"A", "test", 100.0, 10.0, 1e-4});
  model.cable_groups.push_back({"B", "test", 1000.0, 0.0, 100.0});
  model.cables.push_back({"a", "A", "near", "c", "bob", "c"});
  model.cables.push_back({"b", "B", "far", "c", "bob", "c"});
  return model;
}

TEST(Engine, ImplicitDampingNeverMakesACablePushOrExceedTheCap) {
  // A's tension over one step from the bob's momentum: m dv / dt = F_B + F_A along x, with
  // F_A = -T_A (A pulls towards -x) and F_B = -+T_B, B having no damping: T_B = 100 N, or
  // with implicit stiffness its spring at the end of the step, 100 N + dt k_B x'_B. The law
  // allows 0 <= T_A <= 2 k (x - r) (x - r = 1e-6 m, or with implicit stiffness its value at
  // the end of the step, 1e-6 m + dt x'_A). The linearly implicit damper alone gave
  // T_A = -33.3 N (dt 5 ms) and -45.5 N (1 ms) shortening, +33.3 N lengthening.
  for (bool towards : {true, false}) {
    const Result<Model> model = BuildModel(TwoCables(towards));
    ASSERT_TRUE(model.ok()) << model.status().ToString();
    const double mass = model->bodies[2].mass_kg;
    ASSERT_NEAR(mass, 0.1, 1e-12);
    for (bool implicit_stiffness : {false, true}) {
      for (double dt : {0.005, 0.001}) {
        SCOPED_TRACE(testing::Message() << (towards ? "shortening" : "lengthening") << ", dt " << dt
                                        << ", implicit stiffness " << implicit_stiffness);
        State state = InitialState(*model);
        ASSERT_NEAR(ReadCable(*model, state, 0).tension_n, 1e-4, 1e-9);
        ASSERT_NEAR(ReadCable(*model, state, 1).tension_n, 100.0, 1e-9);
        EngineOptions options;
        options.time_step_s = dt;
        options.implicit_stiffness = implicit_stiffness;
        Step(*model, options, {}, state);
        const double v = state.bodies[2].velocity_m_per_s.x();
        // rates of lengthening: A runs from x = -0.5 to the bob, B from its anchor to the bob
        const double rate_a = v;
        const double rate_b = towards ? v : -v;
        const double tension_b = 100.0 + (implicit_stiffness ? dt * 1000.0 * rate_b : 0.0);
        const double force_b = towards ? -tension_b : tension_b;
        const double tension_a = force_b - mass * v / dt;
        const double cap = 2.0 * 100.0 * (1e-6 + (implicit_stiffness ? dt * rate_a : 0.0));
        // (tolerance: the 5e8 kg anchors move by ~1e-9 m/s)
        EXPECT_GE(tension_a, -1e-7);
        EXPECT_LE(tension_a, std::max(0.0, cap) + 1e-7);
        // the reported tension is the one applied
        EXPECT_NEAR(state.cable_tension_n[0], tension_a, 1e-7);
        EXPECT_NEAR(state.cable_tension_n[1], tension_b, 1e-7);
        EXPECT_GE(state.cable_tension_n[0], 0.0);
      }
    }
  }
}

// `poses` with its cluster roots moving at the velocities of `velocities` and each hinge
// child carried by its parent at `velocities`' hinge rate (the engine's kinematics).
State WithVelocities(const Model& model, const State& poses, const State& root_velocities,
                     const std::vector<double>& hinge_rate_rad_per_s) {
  State mixed = poses;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies[b].driving_hinge >= 0) continue;
    mixed.bodies[b].velocity_m_per_s = root_velocities.bodies[b].velocity_m_per_s;
    mixed.bodies[b].angular_velocity_rad_per_s =
        root_velocities.bodies[b].angular_velocity_rad_per_s;
  }
  for (size_t h = 0; h < model.hinges.size(); ++h) {
    const Hinge& hinge = model.hinges[h];
    const BodyState& parent = mixed.bodies[static_cast<size_t>(hinge.parent)];
    BodyState& child = mixed.bodies[static_cast<size_t>(hinge.child)];
    const Vec3 axis = parent.orientation * hinge.axis;
    const Vec3 on_axis = parent.position_m + parent.orientation * hinge.point_m;
    const double rate = hinge_rate_rad_per_s[h];
    child.angular_velocity_rad_per_s = parent.angular_velocity_rad_per_s + rate * axis;
    child.velocity_m_per_s =
        parent.velocity_m_per_s +
        parent.angular_velocity_rad_per_s.cross(child.position_m - parent.position_m) +
        rate * axis.cross(child.position_m - on_axis);
  }
  return mixed;
}

TEST(Engine, LaikaCablesNeverPushOverARun) {
  // the experiment's steps at the default 5 ms (drop, settle, bend, the ramp past the
  // liftoff), mean tension point: each cable's tension over each step is within the law's
  // range, and for a cable the engine treated implicitly it is the law's value at the new
  // velocities, T + c (x'+ - x') with x' from the start-of-step geometry (so the impulse the
  // cable applied never implies a push)
  const Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  ASSERT_TRUE(description.ok()) << description.status().ToString();
  ExperimentOptions options;
  options.foot = Foot::kA;
  options.tension_point_index = 2;
  const Result<Model> built = BuildExperimentModel(*description, options);
  ASSERT_TRUE(built.ok()) << built.status().ToString();
  const Model& model = *built;
  ASSERT_TRUE(model.damping_cap);
  const Procedure procedure(model, options);
  State state = InitialState(model, options.drop_height_m);
  Controls controls;
  controls.rest_length_m.resize(model.cables.size());
  controls.hinge_angle_rad.resize(1);
  int64_t taut = 0;
  int64_t at_bound = 0;
  double worst_mismatch = 0.0;
  for (int64_t step = 1; step <= procedure.step_count(); ++step) {
    const double t_s = procedure.TimeAt(step);
    procedure.RestLengthsAt(t_s, controls.rest_length_m);
    controls.hinge_angle_rad[0] = procedure.HingeAngleAt(t_s);
    State before = state;
    before.rest_length_m = controls.rest_length_m;
    Step(model, options.engine, controls, state);
    const State start = WithVelocities(model, before, before, state.hinge_rate_rad_per_s);
    const State end = WithVelocities(model, before, state, state.hinge_rate_rad_per_s);
    for (size_t c = 0; c < model.cables.size(); ++c) {
      const Cable& cable = model.cables[c];
      const int index = static_cast<int>(c);
      const CableReading at_start = ReadCable(model, start, index);
      const CableReading at_end = ReadCable(model, end, index);
      const double applied = state.cable_tension_n[c];
      const double stretch = at_start.length_m - controls.rest_length_m[c];
      if (!(stretch > 0.0)) {
        ASSERT_EQ(applied, 0.0) << cable.name << " at " << t_s << " s";
        continue;
      }
      ++taut;
      const double cap = 2.0 * cable.stiffness_n_per_m * stretch;
      ASSERT_GE(applied, 0.0) << cable.name << " at " << t_s << " s";
      ASSERT_LE(applied, cap + 1e-9) << cable.name << " at " << t_s << " s";
      if (applied == 0.0 || applied >= cap - 1e-9) {
        ++at_bound;  // held at a bound (or exactly on it)
        continue;
      }
      const double implied =
          at_start.tension_n +
          cable.damping_n_s_per_m * (at_end.length_rate_m_per_s - at_start.length_rate_m_per_s);
      worst_mismatch = std::max(worst_mismatch, std::abs(applied - implied));
      ASSERT_NEAR(applied, implied, 1e-6 * (1.0 + std::abs(implied)))
          << cable.name << " at " << t_s << " s";
    }
  }
  EXPECT_GT(taut, 100000);
  // the run does reach the bounds (cables going slack in the drop and after the liftoff)
  EXPECT_GT(at_bound, 0);
  std::printf("taut cable-steps %lld, at a bound %lld, worst mismatch %.3g N\n",
              static_cast<long long>(taut), static_cast<long long>(at_bound), worst_mismatch);
}

// Laika built at a tension point with the experiment's rule, settled for `settle_s`.
struct SettledLaika {
  Model model;
  State state;
};
SettledLaika SettleLaika(int tension_point, double settle_s) {
  const Result<ModelDescription> description = LoadModelDescription(DefaultModelPath());
  EXPECT_TRUE(description.ok()) << description.status().ToString();
  ExperimentOptions options;
  options.tension_point_index = tension_point;
  Result<Model> model = BuildExperimentModel(*description, options);
  EXPECT_TRUE(model.ok()) << model.status().ToString();
  SettledLaika laika{*model, InitialState(*model, 0.01)};
  const int steps = static_cast<int>(std::round(settle_s / options.engine.time_step_s));
  for (int i = 0; i < steps; ++i) Step(laika.model, options.engine, {}, laika.state);
  return laika;
}

TEST(Engine, RestingRobotStaysAtRestForSixtySeconds) {
  // settled for 10 s, then 60 s more: no body drifts by more than 0.1 mm or turns by more
  // than 0.1 mrad, and the kinetic energy stays below 1 uJ
  SettledLaika laika = SettleLaika(4, 10.0);
  const State before = laika.state;
  EngineOptions options;
  options.time_step_s = 0.005;
  double most_kinetic = 0.0;
  for (int i = 0; i < 12000; ++i) {
    Step(laika.model, options, {}, laika.state);
    most_kinetic = std::max(most_kinetic, KineticEnergy(laika.model, laika.state));
  }
  for (size_t b = 0; b < laika.state.bodies.size(); ++b) {
    const BodyState& now = laika.state.bodies[b];
    const BodyState& then = before.bodies[b];
    EXPECT_LT((now.position_m - then.position_m).norm(), 1e-4) << laika.model.bodies[b].name;
    EXPECT_LT(now.orientation.angularDistance(then.orientation), 1e-4)
        << laika.model.bodies[b].name;
  }
  EXPECT_LT(most_kinetic, 1e-6);
  // and it stands on its four feet, nothing else touching
  EXPECT_GT(LowestNonFootPoint(laika.model, laika.state), 0.05);
  for (double impulse : laika.state.foot_normal_impulse_n_s) EXPECT_GT(impulse, 0.0);
}

TEST(Engine, SameInputGivesBitIdenticalStates) {
  SettledLaika first = SettleLaika(2, 1.0);
  SettledLaika second = SettleLaika(2, 1.0);
  EXPECT_EQ(StateHash(first.state), StateHash(second.state));
  // and the hash sees a one-ulp difference
  State nudged = first.state;
  nudged.bodies[3].position_m.x() = std::nextafter(nudged.bodies[3].position_m.x(), 1.0);
  EXPECT_NE(StateHash(first.state), StateHash(nudged));
}

TEST(Engine, ScratchIsNotPartOfTheHash) {
  SettledLaika laika = SettleLaika(2, 0.1);
  State copy = laika.state;
  copy.scratch = StepScratch{};
  EXPECT_EQ(StateHash(laika.state), StateHash(copy));
  // a fresh scratch gives the same next step
  Step(laika.model, EngineOptions{.time_step_s = 0.005}, {}, laika.state);
  Step(laika.model, EngineOptions{.time_step_s = 0.005}, {}, copy);
  EXPECT_EQ(StateHash(laika.state), StateHash(copy));
}

TEST(Engine, OptionsValidateNameTheField) {
  EngineOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.time_step_s = 0.1;
  EXPECT_NE(options.Validate().message().find("time_step_s"), std::string::npos);
  options = EngineOptions{};
  options.solver_iterations = 0;
  EXPECT_NE(options.Validate().message().find("solver_iterations"), std::string::npos);
}

}  // namespace
}  // namespace liftoff::sim
