// The engine's contact impulses (src/sim/contact_solver.h): projected Gauss-Seidel on
// problems whose solutions are known in closed form, and the complementarity conditions of
// the frictionless problem (impulse >= 0, velocity >= target, one of them tight) on seeded
// random ones.
#include "contact_solver.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

namespace liftoff::sim::internal {
namespace {

constexpr int kSweeps = 10000;
constexpr double kTolerance = 1e-14;

// Contacts on consecutive rows: 1 row each without friction, 3 with.
std::vector<ContactPoint> Contacts(const std::vector<double>& friction) {
  std::vector<ContactPoint> contacts;
  int row = 0;
  for (const double mu : friction) {
    ContactPoint contact;
    contact.first_row = row;
    contact.rows = mu > 0 ? 3 : 1;
    contact.friction = mu;
    row += contact.rows;
    contacts.push_back(contact);
  }
  return contacts;
}

Eigen::VectorXd Solve(const std::vector<ContactPoint>& contacts, const Eigen::MatrixXd& w,
                      const Eigen::VectorXd& free_velocity) {
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(w.rows());
  SolveContactImpulses(contacts, w, free_velocity, kSweeps, kTolerance, impulse);
  return impulse;
}

TEST(SolveContactImpulses, StopsAnApproachingContactAndLeavesASeparatingOne) {
  const std::vector<ContactPoint> one = Contacts({0.0});
  const Eigen::MatrixXd w = Eigen::MatrixXd::Constant(1, 1, 2.0);
  EXPECT_NEAR(Solve(one, w, Eigen::VectorXd::Constant(1, -3.0))[0], 1.5, 1e-15);
  EXPECT_EQ(Solve(one, w, Eigen::VectorXd::Constant(1, 1.0))[0], 0.0);
  // a target velocity (restitution): W impulse + v = target
  std::vector<ContactPoint> bouncing = one;
  bouncing[0].target_normal_velocity_m_per_s = 0.5;
  EXPECT_NEAR(Solve(bouncing, w, Eigen::VectorXd::Constant(1, -3.0))[0], 1.75, 1e-15);
}

TEST(SolveContactImpulses, SolvesCoupledContacts) {
  const std::vector<ContactPoint> two = Contacts({0.0, 0.0});
  Eigen::MatrixXd w(2, 2);
  w << 2.0, 1.0, 1.0, 2.0;
  // both pushed: W impulse = 3 each, impulse (1, 1)
  const Eigen::VectorXd both = Solve(two, w, Eigen::Vector2d(-3.0, -3.0));
  EXPECT_NEAR(both[0], 1.0, 1e-12);
  EXPECT_NEAR(both[1], 1.0, 1e-12);
  // the second separating even with the first's push: impulse (1.5, 0)
  const Eigen::VectorXd one = Solve(two, w, Eigen::Vector2d(-3.0, 5.0));
  EXPECT_NEAR(one[0], 1.5, 1e-12);
  EXPECT_EQ(one[1], 0.0);
}

// One contact, decoupled rows: the normal impulse stops the approach; the tangent impulse
// stops the sliding when the cone allows, else it is the cone's edge against the sliding.
TEST(SolveContactImpulses, KeepsFrictionInsideTheCoulombCone) {
  const Eigen::MatrixXd w = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::Vector3d free_velocity(-2.0, -3.0, 4.0);
  const Eigen::VectorXd sliding = Solve(Contacts({0.5}), w, free_velocity);
  EXPECT_NEAR(sliding[0], 2.0, 1e-12);
  EXPECT_NEAR(sliding[1], 0.5 * 2.0 * 0.6, 1e-12);
  EXPECT_NEAR(sliding[2], -0.5 * 2.0 * 0.8, 1e-12);
  // just outside the cone (1.5 times its edge): scaled back onto it
  const Eigen::VectorXd edge = Solve(Contacts({0.5}), w, Eigen::Vector3d(-2.0, -0.9, 1.2));
  EXPECT_NEAR(edge[1], 0.6, 1e-12);
  EXPECT_NEAR(edge[2], -0.8, 1e-12);
  const Eigen::VectorXd sticking = Solve(Contacts({10.0}), w, free_velocity);
  EXPECT_NEAR(sticking[0], 2.0, 1e-12);
  EXPECT_NEAR(sticking[1], 3.0, 1e-12);
  EXPECT_NEAR(sticking[2], -4.0, 1e-12);
}

TEST(SolveContactImpulses, MeetsTheComplementarityConditionsOnRandomProblems) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 2 + trial % 5;
    Eigen::MatrixXd j(n, n + 2);
    for (Eigen::Index i = 0; i < j.size(); ++i) j.data()[i] = entry(rng);
    const Eigen::MatrixXd w = j * j.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd free_velocity(n);
    for (int i = 0; i < n; ++i) free_velocity[i] = 2.0 * entry(rng);
    const Eigen::VectorXd impulse =
        Solve(Contacts(std::vector<double>(static_cast<size_t>(n), 0.0)), w, free_velocity);
    const Eigen::VectorXd velocity = w * impulse + free_velocity;
    for (int i = 0; i < n; ++i) {
      EXPECT_GE(impulse[i], 0.0) << "trial " << trial << " row " << i;
      EXPECT_GE(velocity[i], -1e-9) << "trial " << trial << " row " << i;
      EXPECT_NEAR(impulse[i] * velocity[i], 0.0, 1e-9) << "trial " << trial << " row " << i;
    }
  }
}

TEST(SolveContactImpulses, StopsAfterTheSweepLimitOrOnceSettled) {
  const std::vector<ContactPoint> one = Contacts({0.0});
  const Eigen::MatrixXd w = Eigen::MatrixXd::Constant(1, 1, 2.0);
  Eigen::VectorXd impulse = Eigen::VectorXd::Zero(1);
  // one sweep finds it, the second changes nothing
  EXPECT_EQ(SolveContactImpulses(one, w, Eigen::VectorXd::Constant(1, -3.0), 100, 0.0, impulse), 2);
  Eigen::MatrixXd coupled(2, 2);
  coupled << 2.0, 1.9, 1.9, 2.0;
  Eigen::VectorXd two = Eigen::VectorXd::Zero(2);
  EXPECT_EQ(
      SolveContactImpulses(Contacts({0.0, 0.0}), coupled, Eigen::Vector2d(-3.0, -3.0), 3, 0.0, two),
      3);
}

}  // namespace
}  // namespace liftoff::sim::internal
