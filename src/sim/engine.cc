#include "liftoff/sim/engine.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

#include "liftoff/core/json.h"
#include "band_cholesky.h"
#include "contact_solver.h"
#include "segments.h"

namespace liftoff::sim {
namespace {

using internal::BandCholesky;
using internal::BandSolveColumns;
using internal::ClosestPointsOfSegments;
using internal::SolveContactImpulses;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Contact keys: kind in the top bits, then body and shape indices.
enum ContactKind : int64_t {
  kFootKind = 1,
  kRodEndKind = 2,
  kBoxCornerKind = 3,
  kSphereKind = 4,
  kRodPairKind = 5
};
int64_t ContactKey(int64_t kind, int64_t body, int64_t shape, int64_t detail) {
  return (kind << 56) | (body << 40) | (shape << 20) | detail;
}

Mat3 Skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

size_t Index(int i) { return static_cast<size_t>(i); }

// system(at + i, at + j) += weight a_i a_j for j <= i (the lower triangle of a block on
// the diagonal).
void AddLowerOuter(Eigen::MatrixXd& system, Eigen::Index at, const Vec6& a, double weight) {
  for (Eigen::Index j = 0; j < 6; ++j) {
    const double scaled = weight * a[j];
    for (Eigen::Index i = j; i < 6; ++i) system(at + i, at + j) += scaled * a[i];
  }
}

// system(row + i, col + j) += weight a_i b_j.
void AddOuter(Eigen::MatrixXd& system, Eigen::Index row, Eigen::Index col, const Vec6& a,
              const Vec6& b, double weight) {
  for (Eigen::Index j = 0; j < 6; ++j) {
    const double scaled = weight * b[j];
    for (Eigen::Index i = 0; i < 6; ++i) system(row + i, col + j) += scaled * a[i];
  }
}

// Sizes the scratch for this model (once) and maps bodies to clusters.
void PrepareScratch(const Model& model, State& state) {
  StepScratch& scratch = state.scratch;
  const size_t bodies = model.bodies.size();
  if (scratch.cluster_of_body.size() == bodies && scratch.dofs > 0) return;
  scratch.cluster_of_body.assign(bodies, -1);
  scratch.cluster_root.clear();
  for (size_t b = 0; b < bodies; ++b) {
    if (model.bodies[b].driving_hinge >= 0) continue;
    scratch.cluster_of_body[b] = static_cast<int>(scratch.cluster_root.size());
    scratch.cluster_root.push_back(static_cast<int>(b));
  }
  for (size_t b = 0; b < bodies; ++b) {
    const int hinge = model.bodies[b].driving_hinge;
    if (hinge < 0) continue;
    scratch.cluster_of_body[b] = scratch.cluster_of_body[Index(model.hinges[Index(hinge)].parent)];
  }
  scratch.dofs = 6 * static_cast<int>(scratch.cluster_root.size());
  // the system's band: cables couple the six velocities of two clusters
  int band = 5;
  for (const Cable& cable : model.cables) {
    const int a = scratch.cluster_of_body[Index(cable.body_a)];
    const int b = scratch.cluster_of_body[Index(cable.body_b)];
    band = std::max(band, 6 * std::abs(a - b) + 5);
  }
  scratch.band = band;
  scratch.rotation.assign(bodies, Mat3::Identity());
  // a sphere around each body's colliding rods (capsules), body frame
  scratch.rod_bound_center.assign(bodies, Vec3::Zero());
  scratch.rod_bound_radius.assign(bodies, -1.0);
  for (size_t b = 0; b < bodies; ++b) {
    Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 high = -low;
    for (const Rod& rod : model.bodies[b].rods) {
      if (!rod.collides) continue;
      low = low.cwiseMin(rod.from_m).cwiseMin(rod.to_m);
      high = high.cwiseMax(rod.from_m).cwiseMax(rod.to_m);
    }
    if (!(low.x() <= high.x())) continue;  // no colliding rods: never a candidate
    const Vec3 center = 0.5 * (low + high);
    double radius = 0.0;
    for (const Rod& rod : model.bodies[b].rods) {
      if (!rod.collides) continue;
      radius = std::max(radius, std::max((rod.from_m - center).norm(), (rod.to_m - center).norm()) +
                                    rod.radius_m);
    }
    scratch.rod_bound_center[b] = center;
    scratch.rod_bound_radius[b] = radius;
  }
  scratch.hinge_axis_world.assign(bodies, Vec3::Zero());
  scratch.hinge_point_world.assign(bodies, Vec3::Zero());
  scratch.hinge_rate.assign(bodies, 0.0);
  scratch.system.setZero(scratch.dofs, scratch.dofs);
  scratch.rhs.setZero(scratch.dofs);
  scratch.velocity.setZero(scratch.dofs);
  scratch.start_velocity.setZero(scratch.dofs);
  scratch.cable_terms.assign(model.cables.size(), CableStepTerm{});
  scratch.contacts.reserve(16);
}

// Makes sure the contact matrices hold `rows` rows (grow only).
void ReserveContactRows(StepScratch& scratch, int rows) {
  if (scratch.contact_jacobian.rows() >= rows && scratch.contact_jacobian.cols() == scratch.dofs &&
      scratch.solution.rows() == scratch.dofs) {
    return;
  }
  const int capacity =
      std::max<int>({rows, 12, 2 * static_cast<int>(scratch.contact_jacobian.rows())});
  scratch.contact_jacobian.setZero(capacity, scratch.dofs);
  scratch.solution.setZero(scratch.dofs, capacity + 1);
  scratch.delassus.setZero(capacity, capacity);
  scratch.row_velocity.setZero(capacity);
  scratch.contact_impulse.setZero(capacity);
}

// Pose of a hinge's child from its parent's pose and the angle.
void PlaceChild(const Model& model, int hinge_index, double angle_rad, State& state) {
  const Hinge& hinge = model.hinges[Index(hinge_index)];
  const BodyState& parent = state.bodies[Index(hinge.parent)];
  BodyState& child = state.bodies[Index(hinge.child)];
  const Quat turn(Eigen::AngleAxisd(angle_rad, hinge.axis));
  const Vec3 in_parent = hinge.point_m + turn * (hinge.child_position_in_parent_m - hinge.point_m);
  child.position_m = parent.position_m + parent.orientation * in_parent;
  child.orientation = (parent.orientation * turn * hinge.child_orientation_in_parent).normalized();
}

// Velocities of a hinge's child from its parent's and the hinge rate.
void ChildVelocity(const Model& model, int hinge_index, double rate_rad_per_s, State& state) {
  const Hinge& hinge = model.hinges[Index(hinge_index)];
  const BodyState& parent = state.bodies[Index(hinge.parent)];
  BodyState& child = state.bodies[Index(hinge.child)];
  const Vec3 axis_world = parent.orientation * hinge.axis;
  const Vec3 point_world = parent.position_m + parent.orientation * hinge.point_m;
  const Vec3 offset = child.position_m - parent.position_m;
  child.angular_velocity_rad_per_s =
      parent.angular_velocity_rad_per_s + rate_rad_per_s * axis_world;
  child.velocity_m_per_s = parent.velocity_m_per_s +
                           parent.angular_velocity_rad_per_s.cross(offset) +
                           rate_rad_per_s * axis_world.cross(child.position_m - point_world);
}

// Velocity of a world point fixed to `body`, from the generalised velocities.
Vec3 PointVelocity(const StepScratch& scratch, const State& state, int body, const Vec3& point,
                   const Eigen::VectorXd& velocity) {
  const int cluster = scratch.cluster_of_body[Index(body)];
  const Vec3& origin = state.bodies[Index(scratch.cluster_root[Index(cluster)])].position_m;
  const Vec3 v = velocity.segment<3>(6 * cluster);
  const Vec3 w = velocity.segment<3>(6 * cluster + 3);
  Vec3 result = v + w.cross(point - origin);
  const double rate = scratch.hinge_rate[Index(body)];
  if (rate != 0.0) {
    result += rate * scratch.hinge_axis_world[Index(body)].cross(
                         point - scratch.hinge_point_world[Index(body)]);
  }
  return result;
}

// d(point velocity . direction) / d(generalised velocity of the body's cluster).
Vec6 PointRow(const StepScratch& scratch, const State& state, int body, const Vec3& point,
              const Vec3& direction) {
  const int cluster = scratch.cluster_of_body[Index(body)];
  const Vec3& origin = state.bodies[Index(scratch.cluster_root[Index(cluster)])].position_m;
  Vec6 row;
  row.head<3>() = direction;
  row.tail<3>() = (point - origin).cross(direction);
  return row;
}

// Candidate ground contacts of one sphere (world centre, radius).
void AddGroundContact(int64_t key, int body, const Vec3& lowest_point, double friction, int foot,
                      double margin_m, std::vector<ContactPoint>& contacts) {
  const double gap = lowest_point.z();
  if (gap > margin_m) return;
  ContactPoint contact;
  contact.key = key;
  contact.body_a = -1;
  contact.body_b = body;
  contact.point_a_m = Vec3(lowest_point.x(), lowest_point.y(), 0.0);
  contact.point_b_m = lowest_point;
  contact.normal = Vec3::UnitZ();
  contact.gap_m = gap;
  contact.friction = friction;
  contact.foot = foot;
  contacts.push_back(contact);
}

// One body's contacts with the ground: its feet (and, with spine_ground, its other
// spheres, its colliding rods' end spheres and its boxes' corners).
void FindGroundContacts(const Model& model, const EngineOptions& options, const State& state,
                        size_t b, std::vector<ContactPoint>& contacts) {
  const double friction = model.contact.friction;
  const double spine_friction = model.contact.spine_friction.value_or(friction);
  const double margin = options.contact_margin_m;
  const Body& body = model.bodies[b];
  const BodyState& pose = state.bodies[b];
  const Mat3& rotation = state.scratch.rotation[b];
  const int body_index = static_cast<int>(b);
  for (size_t s = 0; s < body.spheres.size(); ++s) {
    const Sphere& sphere = body.spheres[s];
    const bool foot = sphere.foot_index >= 0;
    if (!foot && !model.contact.spine_ground) continue;
    const Vec3 center = pose.position_m + rotation * sphere.center_m;
    AddGroundContact(
        ContactKey(foot ? kFootKind : kSphereKind, body_index, static_cast<int64_t>(s), 0),
        body_index, center - Vec3(0.0, 0.0, sphere.radius_m), foot ? friction : spine_friction,
        sphere.foot_index, margin, contacts);
  }
  if (!model.contact.spine_ground) return;
  // rods as capsules: their lowest points are on the end spheres
  for (size_t r = 0; r < body.rods.size(); ++r) {
    const Rod& rod = body.rods[r];
    if (!rod.collides) continue;
    const Vec3 ends[2] = {pose.position_m + rotation * rod.from_m,
                          pose.position_m + rotation * rod.to_m};
    for (int e = 0; e < 2; ++e) {
      AddGroundContact(ContactKey(kRodEndKind, body_index, static_cast<int64_t>(r), e), body_index,
                       ends[e] - Vec3(0.0, 0.0, rod.radius_m), spine_friction, -1, margin,
                       contacts);
    }
  }
  for (size_t x = 0; x < body.boxes.size(); ++x) {
    const Box& box = body.boxes[x];
    if (!box.collides) continue;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 sign((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                      (corner & 4) ? 1.0 : -1.0);
      const Vec3 point =
          pose.position_m + rotation * (box.center_m + sign.cwiseProduct(box.half_size_m));
      AddGroundContact(ContactKey(kBoxCornerKind, body_index, static_cast<int64_t>(x), corner),
                       body_index, point, spine_friction, -1, margin, contacts);
    }
  }
}

// The contacts between the colliding rods of bodies b1 and b2 (capsules), unless their
// rods' bounding spheres are apart by more than the margin.
void FindRodPairContacts(const Model& model, const EngineOptions& options, const State& state,
                         size_t b1, size_t b2, std::vector<ContactPoint>& contacts) {
  const StepScratch& scratch = state.scratch;
  const double margin = options.contact_margin_m;
  const double spine_friction = model.contact.spine_friction.value_or(model.contact.friction);
  if (scratch.rod_bound_radius[b1] < 0.0 || scratch.rod_bound_radius[b2] < 0.0) return;
  const Vec3 center1 =
      state.bodies[b1].position_m + scratch.rotation[b1] * scratch.rod_bound_center[b1];
  const Vec3 center2 =
      state.bodies[b2].position_m + scratch.rotation[b2] * scratch.rod_bound_center[b2];
  const double reach = scratch.rod_bound_radius[b1] + scratch.rod_bound_radius[b2] + margin;
  if ((center1 - center2).squaredNorm() > reach * reach) return;
  const Body& body1 = model.bodies[b1];
  const Body& body2 = model.bodies[b2];
  for (size_t r1 = 0; r1 < body1.rods.size(); ++r1) {
    const Rod& rod1 = body1.rods[r1];
    if (!rod1.collides) continue;
    const Vec3 p1 = state.bodies[b1].position_m + scratch.rotation[b1] * rod1.from_m;
    const Vec3 q1 = state.bodies[b1].position_m + scratch.rotation[b1] * rod1.to_m;
    for (size_t r2 = 0; r2 < body2.rods.size(); ++r2) {
      const Rod& rod2 = body2.rods[r2];
      if (!rod2.collides) continue;
      const Vec3 p2 = state.bodies[b2].position_m + scratch.rotation[b2] * rod2.from_m;
      const Vec3 q2 = state.bodies[b2].position_m + scratch.rotation[b2] * rod2.to_m;
      Vec3 c1;
      Vec3 c2;
      ClosestPointsOfSegments(p1, q1, p2, q2, c1, c2);
      const Vec3 between = c2 - c1;
      const double distance = between.norm();
      const double gap = distance - rod1.radius_m - rod2.radius_m;
      if (gap > margin || distance < 1e-12) continue;
      ContactPoint contact;
      contact.key = ContactKey(kRodPairKind, static_cast<int64_t>(b1 * 256 + b2),
                               static_cast<int64_t>(r1), static_cast<int64_t>(r2));
      contact.body_a = static_cast<int>(b1);
      contact.body_b = static_cast<int>(b2);
      contact.normal = between / distance;
      contact.point_a_m = c1 + contact.normal * rod1.radius_m;
      contact.point_b_m = c2 - contact.normal * rod2.radius_m;
      contact.gap_m = gap;
      contact.friction = spine_friction;
      contacts.push_back(contact);
    }
  }
}

// Every contact within the margin, in a fixed order: each body's with the ground, then
// (with spine_self) those between the rods of bodies that move independently.
void FindContacts(const Model& model, const EngineOptions& options, State& state) {
  std::vector<ContactPoint>& contacts = state.scratch.contacts;
  contacts.clear();
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    FindGroundContacts(model, options, state, b, contacts);
  }
  if (!model.contact.spine_self) return;
  for (size_t b1 = 0; b1 < model.bodies.size(); ++b1) {
    for (size_t b2 = b1 + 1; b2 < model.bodies.size(); ++b2) {
      if (state.scratch.cluster_of_body[b1] == state.scratch.cluster_of_body[b2]) continue;
      FindRodPairContacts(model, options, state, b1, b2, contacts);
    }
  }
}

// Adds one row of a contact: relative velocity of b against a along `direction`.
void FillContactRow(const StepScratch& scratch, const State& state, const ContactPoint& contact,
                    const Vec3& direction, int row, Eigen::MatrixXd& jacobian) {
  jacobian.row(row).head(scratch.dofs).setZero();
  const int cluster_b = scratch.cluster_of_body[Index(contact.body_b)];
  jacobian.block<1, 6>(row, 6 * cluster_b) +=
      PointRow(scratch, state, contact.body_b, contact.point_b_m, direction).transpose();
  if (contact.body_a >= 0) {
    const int cluster_a = scratch.cluster_of_body[Index(contact.body_a)];
    jacobian.block<1, 6>(row, 6 * cluster_a) -=
        PointRow(scratch, state, contact.body_a, contact.point_a_m, direction).transpose();
  }
}

// Relative velocity (b against a) along `direction` for the given generalised velocities.
double RelativeVelocity(const StepScratch& scratch, const State& state, const ContactPoint& contact,
                        const Vec3& direction, const Eigen::VectorXd& velocity) {
  double v =
      direction.dot(PointVelocity(scratch, state, contact.body_b, contact.point_b_m, velocity));
  if (contact.body_a >= 0) {
    v -= direction.dot(PointVelocity(scratch, state, contact.body_a, contact.point_a_m, velocity));
  }
  return v;
}

// Two unit tangents of a unit normal.
void Tangents(const Vec3& normal, Vec3& t1, Vec3& t2) {
  const Vec3 helper = std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  t1 = (helper - normal * normal.dot(helper)).normalized();
  t2 = normal.cross(t1);
}

// Rows of the contact system: Jacobian rows and normal targets. Returns the row count.
int BuildContactRows(const Model& model, const EngineOptions& options, State& state) {
  StepScratch& scratch = state.scratch;
  std::vector<ContactPoint>& contacts = scratch.contacts;
  const double dt = options.time_step_s;
  int rows = 0;
  for (ContactPoint& contact : contacts) {
    contact.first_row = rows;
    contact.rows = contact.friction > 0.0 ? 3 : 1;
    rows += contact.rows;
  }
  ReserveContactRows(scratch, rows);
  Eigen::MatrixXd& jacobian = scratch.contact_jacobian;
  for (ContactPoint& contact : contacts) {
    FillContactRow(scratch, state, contact, contact.normal, contact.first_row, jacobian);
    // target: catch approaching contacts exactly at the surface, push penetration out
    // gradually, bounce by the restitution
    double target =
        contact.gap_m >= 0.0 ? -contact.gap_m / dt : -options.contact_bias * contact.gap_m / dt;
    if (model.contact.restitution > 0.0) {
      // bounce only once the surfaces actually meet within this step
      const double arrival =
          RelativeVelocity(scratch, state, contact, contact.normal, scratch.start_velocity);
      if (arrival < 0.0 && contact.gap_m <= -arrival * dt) {
        target = std::max(target, -model.contact.restitution * arrival);
      }
    }
    contact.target_normal_velocity_m_per_s = target;
    if (contact.rows == 3) {
      Vec3 t1;
      Vec3 t2;
      Tangents(contact.normal, t1, t2);
      FillContactRow(scratch, state, contact, t1, contact.first_row + 1, jacobian);
      FillContactRow(scratch, state, contact, t2, contact.first_row + 2, jacobian);
    }
  }
  return rows;
}

// Impulses that keep contacts from closing (projected Gauss-Seidel, warm-started), added
// to the velocities. Columns 1.. of scratch.solution hold A^-1 J^T.
void SolveContacts(const EngineOptions& options, State& state, int rows) {
  StepScratch& scratch = state.scratch;
  std::vector<ContactPoint>& contacts = scratch.contacts;
  std::fill(state.foot_normal_impulse_n_s.begin(), state.foot_normal_impulse_n_s.end(), 0.0);
  if (rows == 0) {
    state.warm_contact_key.clear();
    state.warm_contact_impulse_n_s.clear();
    return;
  }
  const Eigen::MatrixXd& jacobian = scratch.contact_jacobian;
  // velocities of the rows without contact impulses
  for (const ContactPoint& contact : contacts) {
    scratch.row_velocity[contact.first_row] =
        RelativeVelocity(scratch, state, contact, contact.normal, scratch.velocity);
    if (contact.rows == 3) {
      Vec3 t1;
      Vec3 t2;
      Tangents(contact.normal, t1, t2);
      scratch.row_velocity[contact.first_row + 1] =
          RelativeVelocity(scratch, state, contact, t1, scratch.velocity);
      scratch.row_velocity[contact.first_row + 2] =
          RelativeVelocity(scratch, state, contact, t2, scratch.velocity);
    }
  }
  // Delassus matrix W = J A^-1 J^T; a row touches one or two clusters, six columns each
  const auto y = scratch.solution.middleCols(1, rows);
  auto w = scratch.delassus.topLeftCorner(rows, rows);
  for (const ContactPoint& contact : contacts) {
    const int cluster_b = scratch.cluster_of_body[Index(contact.body_b)];
    const int cluster_a = contact.body_a >= 0 ? scratch.cluster_of_body[Index(contact.body_a)] : -1;
    for (int r = contact.first_row; r < contact.first_row + contact.rows; ++r) {
      w.row(r).noalias() = jacobian.block<1, 6>(r, 6 * cluster_b) * y.middleRows<6>(6 * cluster_b);
      if (cluster_a >= 0) {
        w.row(r).noalias() +=
            jacobian.block<1, 6>(r, 6 * cluster_a) * y.middleRows<6>(6 * cluster_a);
      }
    }
  }

  // warm start from the last step's impulses of the same contacts
  auto impulse = scratch.contact_impulse.head(rows);
  impulse.setZero();
  size_t search_from = 0;
  for (const ContactPoint& contact : contacts) {
    for (size_t k = search_from; k < state.warm_contact_key.size(); ++k) {
      if (state.warm_contact_key[k] != contact.key) continue;
      for (int r = 0; r < contact.rows; ++r) {
        impulse[contact.first_row + r] = state.warm_contact_impulse_n_s[3 * k + Index(r)];
      }
      search_from = k + 1;
      break;
    }
  }

  // projected Gauss-Seidel
  SolveContactImpulses(contacts, w, scratch.row_velocity, options.solver_iterations,
                       options.solver_tolerance_n_s, impulse);
  scratch.velocity.noalias() += y * impulse;

  // remember for the next step
  state.warm_contact_key.resize(contacts.size());
  state.warm_contact_impulse_n_s.assign(3 * contacts.size(), 0.0);
  for (size_t c = 0; c < contacts.size(); ++c) {
    const ContactPoint& contact = contacts[c];
    state.warm_contact_key[c] = contact.key;
    for (int r = 0; r < contact.rows; ++r) {
      state.warm_contact_impulse_n_s[3 * c + Index(r)] = impulse[contact.first_row + r];
    }
    if (contact.foot >= 0) {
      state.foot_normal_impulse_n_s[Index(contact.foot)] += impulse[contact.first_row];
    }
  }
}

// Each cable's part in the step from the start-of-step geometry and velocities.
void PrepareCableTerms(const Model& model, const EngineOptions& options, State& state) {
  StepScratch& scratch = state.scratch;
  const double dt = options.time_step_s;
  if (state.cable_tension_n.size() != model.cables.size()) {
    state.cable_tension_n.assign(model.cables.size(), 0.0);
  }
  for (size_t c = 0; c < model.cables.size(); ++c) {
    const Cable& cable = model.cables[c];
    CableStepTerm& term = scratch.cable_terms[c];
    term = CableStepTerm{};
    term.cluster_a = scratch.cluster_of_body[Index(cable.body_a)];
    term.cluster_b = scratch.cluster_of_body[Index(cable.body_b)];
    const Vec3 pa = state.bodies[Index(cable.body_a)].position_m +
                    scratch.rotation[Index(cable.body_a)] * cable.anchor_a_m;
    const Vec3 pb = state.bodies[Index(cable.body_b)].position_m +
                    scratch.rotation[Index(cable.body_b)] * cable.anchor_b_m;
    const Vec3 u = pb - pa;
    const double length = u.norm();
    const double rest = state.rest_length_m[c];
    if (!(length > rest) || length <= 0.0) continue;  // slack: exactly no force
    const Vec3 n = u / length;
    const Vec3 va = PointVelocity(scratch, state, cable.body_a, pa, scratch.start_velocity);
    const Vec3 vb = PointVelocity(scratch, state, cable.body_b, pb, scratch.start_velocity);
    term.rate_m_per_s = n.dot(vb - va);
    term.stretch_m = length - rest;
    term.tension_n = CableTension(length, term.rate_m_per_s, rest, cable.stiffness_n_per_m,
                                  cable.damping_n_s_per_m, model.damping_cap);
    term.held_tension_n = term.tension_n;
    // inside one rigid cluster: no net effect (its tension is internal)
    if (term.cluster_a == term.cluster_b) continue;
    // gradient of the length rate over the two clusters' velocities
    term.row_a = -PointRow(scratch, state, cable.body_a, pa, n);
    term.row_b = PointRow(scratch, state, cable.body_b, pb, n);
    const double weight = dt * cable.damping_n_s_per_m +
                          (options.implicit_stiffness ? dt * dt * cable.stiffness_n_per_m : 0.0);
    term.mode = weight > 0.0 ? CableStepTerm::kImplicit : CableStepTerm::kHeld;
  }
}

// The step's system matrix (lower triangle) and right-hand side: mass matrices about each
// cluster's origin, gravity, gyroscopic forces, cables (explicit tension, implicit damping
// and stiffness as rank-one updates; held cables at their constant tension).
void AssembleSystem(const Model& model, const EngineOptions& options, State& state) {
  StepScratch& scratch = state.scratch;
  const double dt = options.time_step_s;
  Eigen::MatrixXd& system = scratch.system;
  Eigen::VectorXd& rhs = scratch.rhs;
  system.setZero();
  rhs.setZero();
  for (size_t k = 0; k < scratch.cluster_root.size(); ++k) {
    const Vec3& origin = state.bodies[Index(scratch.cluster_root[k])].position_m;
    double mass = 0.0;
    Vec3 first_moment = Vec3::Zero();
    Mat3 inertia = Mat3::Zero();
    for (size_t b = 0; b < model.bodies.size(); ++b) {
      if (scratch.cluster_of_body[b] != static_cast<int>(k)) continue;
      const Body& body = model.bodies[b];
      const Mat3& rotation = scratch.rotation[b];
      const Vec3 offset = state.bodies[b].position_m + rotation * body.com_m - origin;
      mass += body.mass_kg;
      first_moment += body.mass_kg * offset;
      inertia +=
          rotation * body.inertia_kg_m2 * rotation.transpose() +
          body.mass_kg * (offset.squaredNorm() * Mat3::Identity() - offset * offset.transpose());
    }
    const Eigen::Index at = static_cast<Eigen::Index>(6 * k);
    const Mat3 moment_skew = Skew(first_moment);
    system.block<3, 3>(at, at) = mass * Mat3::Identity();
    system.block<3, 3>(at, at + 3) = -moment_skew;
    system.block<3, 3>(at + 3, at) = moment_skew;
    system.block<3, 3>(at + 3, at + 3) = inertia;
    const Vec3 w = scratch.start_velocity.segment<3>(at + 3);
    const Vec3 force = mass * model.gravity_m_per_s2 - w.cross(w.cross(first_moment));
    const Vec3 torque = first_moment.cross(model.gravity_m_per_s2) - w.cross(inertia * w);
    rhs.segment<3>(at) += dt * force;
    rhs.segment<3>(at + 3) += dt * torque;
  }

  for (size_t c = 0; c < model.cables.size(); ++c) {
    const CableStepTerm& term = scratch.cable_terms[c];
    if (term.mode == CableStepTerm::kNone) continue;
    const Cable& cable = model.cables[c];
    const Vec6& ga = term.row_a;
    const Vec6& gb = term.row_b;
    const Eigen::Index ia = 6 * term.cluster_a;
    const Eigen::Index ib = 6 * term.cluster_b;
    if (term.mode == CableStepTerm::kHeld) {
      rhs.segment<6>(ia) -= dt * term.held_tension_n * ga;
      rhs.segment<6>(ib) -= dt * term.held_tension_n * gb;
      continue;
    }
    rhs.segment<6>(ia) -= dt * term.tension_n * ga;
    rhs.segment<6>(ib) -= dt * term.tension_n * gb;
    double weight = dt * cable.damping_n_s_per_m;
    if (options.implicit_stiffness) {
      weight += dt * dt * cable.stiffness_n_per_m;
      // the spring's own change over the step, evaluated at the new velocity
      rhs.segment<6>(ia) -= dt * dt * cable.stiffness_n_per_m * term.rate_m_per_s * ga;
      rhs.segment<6>(ib) -= dt * dt * cable.stiffness_n_per_m * term.rate_m_per_s * gb;
    }
    // the factorisation reads the lower triangle only
    AddLowerOuter(system, ia, ga, weight);
    AddLowerOuter(system, ib, gb, weight);
    if (ia > ib) {
      AddOuter(system, ia, ib, ga, gb, weight);
    } else {
      AddOuter(system, ib, ia, gb, ga, weight);
    }
  }
}

// Each cable's tension over the step into state.cable_tension_n; an implicit cable whose
// tension left the law's range (below 0, or above 2 k (x - r) with the damping cap) is
// held at the bound it crossed. Returns whether any was.
bool HoldCablesOutOfRange(const Model& model, const EngineOptions& options, State& state) {
  StepScratch& scratch = state.scratch;
  const double dt = options.time_step_s;
  bool held_any = false;
  for (size_t c = 0; c < model.cables.size(); ++c) {
    CableStepTerm& term = scratch.cable_terms[c];
    if (term.mode != CableStepTerm::kImplicit) {
      state.cable_tension_n[c] = term.held_tension_n;
      continue;
    }
    const Cable& cable = model.cables[c];
    const Eigen::Index ia = 6 * term.cluster_a;
    const Eigen::Index ib = 6 * term.cluster_b;
    const double rate_change =
        term.row_a.dot(scratch.velocity.segment<6>(ia) - scratch.start_velocity.segment<6>(ia)) +
        term.row_b.dot(scratch.velocity.segment<6>(ib) - scratch.start_velocity.segment<6>(ib));
    double spring = cable.stiffness_n_per_m * term.stretch_m;
    double applied = term.tension_n + cable.damping_n_s_per_m * rate_change;
    if (options.implicit_stiffness) {
      const double spring_change = dt * cable.stiffness_n_per_m * (term.rate_m_per_s + rate_change);
      spring += spring_change;
      applied += spring_change;
    }
    state.cable_tension_n[c] = applied;
    if (applied < 0.0) {
      term.held_tension_n = 0.0;
    } else if (model.damping_cap && applied > 2.0 * spring) {
      term.held_tension_n = std::max(0.0, 2.0 * spring);
    } else {
      continue;
    }
    term.mode = CableStepTerm::kHeld;
    state.cable_tension_n[c] = term.held_tension_n;
    held_any = true;
  }
  return held_any;
}

}  // namespace

Status EngineOptions::Validate() const {
  if (!(time_step_s >= 1e-6 && time_step_s <= 0.01)) {
    return InvalidArgumentError("time_step_s: expected a number in [1e-06, 0.01], got " +
                                FormatNumber(time_step_s));
  }
  if (!(contact_bias >= 0.0 && contact_bias <= 1.0)) {
    return InvalidArgumentError("contact_bias: expected a number in [0, 1], got " +
                                FormatNumber(contact_bias));
  }
  if (!(contact_margin_m >= 0.0 && std::isfinite(contact_margin_m))) {
    return InvalidArgumentError("contact_margin_m: expected a number >= 0, got " +
                                FormatNumber(contact_margin_m));
  }
  if (solver_iterations < 1 || solver_iterations > 1000) {
    return InvalidArgumentError("solver_iterations: expected an integer in [1, 1000], got " +
                                std::to_string(solver_iterations));
  }
  if (!(solver_tolerance_n_s >= 0.0 && std::isfinite(solver_tolerance_n_s))) {
    return InvalidArgumentError("solver_tolerance_n_s: expected a number >= 0, got " +
                                FormatNumber(solver_tolerance_n_s));
  }
  return Status::Ok();
}

double CableTension(double length_m, double length_rate_m_per_s, double rest_length_m,
                    double stiffness_n_per_m, double damping_n_s_per_m, bool damping_cap) {
  const double stretch = length_m - rest_length_m;
  if (!(stretch > 0.0)) return 0.0;
  const double spring = stiffness_n_per_m * stretch;
  double damper = damping_n_s_per_m * length_rate_m_per_s;
  if (damping_cap) damper = std::clamp(damper, -spring, spring);
  return std::max(0.0, spring + damper);
}

State InitialState(const Model& model, double lift_m) {
  State state;
  state.bodies.resize(model.bodies.size());
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    state.bodies[b].position_m = model.bodies[b].initial_position_m + Vec3(0.0, 0.0, lift_m);
    state.bodies[b].orientation = model.bodies[b].initial_orientation;
  }
  state.rest_length_m.resize(model.cables.size());
  for (size_t c = 0; c < model.cables.size(); ++c) {
    state.rest_length_m[c] = model.cables[c].rest_length_m;
  }
  state.hinge_angle_rad.assign(model.hinges.size(), 0.0);
  state.hinge_rate_rad_per_s.assign(model.hinges.size(), 0.0);
  state.foot_normal_impulse_n_s.assign(model.feet.size(), 0.0);
  state.cable_tension_n.assign(model.cables.size(), 0.0);
  return state;
}

namespace {

// commands: rest lengths now, hinge angles at the end of the step (as a rate over it)
void ApplyCommands(const Model& model, const Controls& controls, double dt, State& state) {
  if (!controls.rest_length_m.empty()) {
    std::copy(controls.rest_length_m.begin(), controls.rest_length_m.end(),
              state.rest_length_m.begin());
  }
  for (size_t h = 0; h < model.hinges.size(); ++h) {
    const double target =
        controls.hinge_angle_rad.empty() ? state.hinge_angle_rad[h] : controls.hinge_angle_rad[h];
    state.hinge_rate_rad_per_s[h] = (target - state.hinge_angle_rad[h]) / dt;
  }
}

// kinematics at the start of the step: rotations, hinge frames and rates, the clusters'
// velocities
void StartKinematics(const Model& model, State& state) {
  StepScratch& scratch = state.scratch;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    scratch.rotation[b] = state.bodies[b].orientation.toRotationMatrix();
    const int hinge = model.bodies[b].driving_hinge;
    if (hinge < 0) continue;
    const Hinge& joint = model.hinges[Index(hinge)];
    const BodyState& parent = state.bodies[Index(joint.parent)];
    scratch.hinge_axis_world[b] = parent.orientation * joint.axis;
    scratch.hinge_point_world[b] = parent.position_m + parent.orientation * joint.point_m;
    scratch.hinge_rate[b] = state.hinge_rate_rad_per_s[Index(hinge)];
  }
  for (size_t k = 0; k < scratch.cluster_root.size(); ++k) {
    const BodyState& root = state.bodies[Index(scratch.cluster_root[k])];
    scratch.velocity.segment<3>(static_cast<Eigen::Index>(6 * k)) = root.velocity_m_per_s;
    scratch.velocity.segment<3>(static_cast<Eigen::Index>(6 * k + 3)) =
        root.angular_velocity_rad_per_s;
  }
  scratch.start_velocity = scratch.velocity;
}

// The velocities at the end of the step: one solve for the free velocity change and for
// A^-1 J^T, then the contact impulses; again while a cable's tension over the step leaves
// the law's range (held at the bound from then on).
void SolveVelocities(const Model& model, const EngineOptions& options, int rows, State& state) {
  StepScratch& scratch = state.scratch;
  do {
    AssembleSystem(model, options, state);
    if (!BandCholesky(scratch.system, scratch.band)) {
      // the options' stiffness or damping is beyond what the step resolves: NaN
      // velocities, which the run's divergence check reports
      scratch.velocity.setConstant(std::numeric_limits<double>::quiet_NaN());
      break;
    }
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& solution =
        scratch.solution;
    solution.col(0) = scratch.rhs;
    solution.middleCols(1, rows) = scratch.contact_jacobian.topRows(rows).transpose();
    BandSolveColumns(scratch.system, scratch.band, solution.data(), solution.cols(), rows + 1);
    scratch.velocity = scratch.start_velocity + solution.col(0);
    SolveContacts(options, state, rows);
  } while (HoldCablesOutOfRange(model, options, state));
}

// positions from the new velocities: the clusters' roots, then the hinged children
void Integrate(const Model& model, const Controls& controls, double dt, State& state) {
  StepScratch& scratch = state.scratch;
  for (size_t k = 0; k < scratch.cluster_root.size(); ++k) {
    BodyState& root = state.bodies[Index(scratch.cluster_root[k])];
    const Eigen::Index at = static_cast<Eigen::Index>(6 * k);
    root.velocity_m_per_s = scratch.velocity.segment<3>(at);
    root.angular_velocity_rad_per_s = scratch.velocity.segment<3>(at + 3);
    root.position_m += dt * root.velocity_m_per_s;
    const double angle = root.angular_velocity_rad_per_s.norm() * dt;
    if (angle > 0.0) {
      const Quat turn(Eigen::AngleAxisd(angle, root.angular_velocity_rad_per_s.normalized()));
      root.orientation = (turn * root.orientation).normalized();
    }
  }
  for (size_t h = 0; h < model.hinges.size(); ++h) {
    if (!controls.hinge_angle_rad.empty()) state.hinge_angle_rad[h] = controls.hinge_angle_rad[h];
    PlaceChild(model, static_cast<int>(h), state.hinge_angle_rad[h], state);
    ChildVelocity(model, static_cast<int>(h), state.hinge_rate_rad_per_s[h], state);
  }
}

}  // namespace

void Step(const Model& model, const EngineOptions& options, const Controls& controls,
          State& state) {
  assert(controls.rest_length_m.empty() || controls.rest_length_m.size() == model.cables.size());
  assert(controls.hinge_angle_rad.empty() ||
         controls.hinge_angle_rad.size() == model.hinges.size());
  assert(state.bodies.size() == model.bodies.size());
  PrepareScratch(model, state);
  const double dt = options.time_step_s;

  ApplyCommands(model, controls, dt, state);
  StartKinematics(model, state);
  PrepareCableTerms(model, options, state);
  // contacts at the start of the step, then the velocities and positions at its end
  FindContacts(model, options, state);
  const int rows = BuildContactRows(model, options, state);
  SolveVelocities(model, options, rows, state);
  Integrate(model, controls, dt, state);
  state.time_s += dt;
  ++state.step_count;
}

std::string DescribeDivergence(const Model& model, const State& state) {
  for (size_t b = 0; b < state.bodies.size(); ++b) {
    const BodyState& body = state.bodies[b];
    const std::string name =
        "body \"" + (b < model.bodies.size() ? model.bodies[b].name : std::to_string(b)) + "\": ";
    if (!body.position_m.allFinite() || !body.orientation.coeffs().allFinite()) {
      return name + "position is not finite";
    }
    if (!body.velocity_m_per_s.allFinite() || !body.angular_velocity_rad_per_s.allFinite()) {
      return name + "velocity is not finite";
    }
    if (body.position_m.norm() > kMaxPhysicalDistance_m) {
      return name + FormatNumber(body.position_m.norm()) + " m from the origin (at most " +
             FormatNumber(kMaxPhysicalDistance_m) + " m is physical)";
    }
    if (body.velocity_m_per_s.norm() > kMaxPhysicalSpeed_m_per_s) {
      return name + "speed " + FormatNumber(body.velocity_m_per_s.norm()) + " m/s (at most " +
             FormatNumber(kMaxPhysicalSpeed_m_per_s) + " m/s is physical)";
    }
    if (body.angular_velocity_rad_per_s.norm() > kMaxPhysicalAngularSpeed_rad_per_s) {
      return name + "angular speed " + FormatNumber(body.angular_velocity_rad_per_s.norm()) +
             " rad/s (at most " + FormatNumber(kMaxPhysicalAngularSpeed_rad_per_s) +
             " rad/s is physical)";
    }
  }
  for (size_t h = 0; h < state.hinge_angle_rad.size(); ++h) {
    if (!std::isfinite(state.hinge_angle_rad[h])) {
      return "hinge " + std::to_string(h) + ": angle is not finite";
    }
  }
  for (size_t c = 0; c < state.rest_length_m.size(); ++c) {
    if (!std::isfinite(state.rest_length_m[c])) {
      return "cable " + std::to_string(c) + ": rest length is not finite";
    }
  }
  return {};
}

CableReading ReadCable(const Model& model, const State& state, int cable_index) {
  const Cable& cable = model.cables[Index(cable_index)];
  const BodyState& a = state.bodies[Index(cable.body_a)];
  const BodyState& b = state.bodies[Index(cable.body_b)];
  CableReading reading;
  reading.anchor_a_world_m = a.position_m + a.orientation * cable.anchor_a_m;
  reading.anchor_b_world_m = b.position_m + b.orientation * cable.anchor_b_m;
  const Vec3 u = reading.anchor_b_world_m - reading.anchor_a_world_m;
  reading.length_m = u.norm();
  const Vec3 va = a.velocity_m_per_s +
                  a.angular_velocity_rad_per_s.cross(reading.anchor_a_world_m - a.position_m);
  const Vec3 vb = b.velocity_m_per_s +
                  b.angular_velocity_rad_per_s.cross(reading.anchor_b_world_m - b.position_m);
  if (reading.length_m > 0.0) reading.length_rate_m_per_s = u.dot(vb - va) / reading.length_m;
  reading.tension_n = CableTension(reading.length_m, reading.length_rate_m_per_s,
                                   state.rest_length_m[Index(cable_index)], cable.stiffness_n_per_m,
                                   cable.damping_n_s_per_m, model.damping_cap);
  return reading;
}

Vec3 WorldPoint(const State& state, int body, const Vec3& point_body_m) {
  const BodyState& pose = state.bodies[Index(body)];
  return pose.position_m + pose.orientation * point_body_m;
}

std::array<double, 4> FootMarkerHeights(const Model& model, const State& state) {
  std::array<double, 4> heights;
  for (size_t f = 0; f < 4; ++f) {
    const int index = model.foot_index[f];
    if (index < 0) {
      heights[f] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const FootPoint& foot = model.feet[Index(index)];
    heights[f] = WorldPoint(state, foot.body, foot.marker_m).z();
  }
  return heights;
}

double LowestNonFootPoint(const Model& model, const State& state) {
  double lowest = kInfinity;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& body = model.bodies[b];
    const BodyState& pose = state.bodies[b];
    const Mat3 rotation = pose.orientation.toRotationMatrix();
    for (const Rod& rod : body.rods) {
      if (!rod.collides) continue;
      const double from = (pose.position_m + rotation * rod.from_m).z();
      const double to = (pose.position_m + rotation * rod.to_m).z();
      lowest = std::min(lowest, std::min(from, to) - rod.radius_m);
    }
    for (const Box& box : body.boxes) {
      if (!box.collides) continue;
      // lowest corner: centre height minus the box's vertical half extent
      const Vec3 center = pose.position_m + rotation * box.center_m;
      const double reach = std::abs(rotation(2, 0)) * box.half_size_m.x() +
                           std::abs(rotation(2, 1)) * box.half_size_m.y() +
                           std::abs(rotation(2, 2)) * box.half_size_m.z();
      lowest = std::min(lowest, center.z() - reach);
    }
    for (const Sphere& sphere : body.spheres) {
      if (sphere.foot_index >= 0) continue;
      lowest =
          std::min(lowest, (pose.position_m + rotation * sphere.center_m).z() - sphere.radius_m);
    }
  }
  return lowest;
}

double KineticEnergy(const Model& model, const State& state) {
  double energy = 0.0;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& body = model.bodies[b];
    const BodyState& s = state.bodies[b];
    const Mat3 rotation = s.orientation.toRotationMatrix();
    const Vec3 com_velocity =
        s.velocity_m_per_s + s.angular_velocity_rad_per_s.cross(rotation * body.com_m);
    const Vec3& w = s.angular_velocity_rad_per_s;
    energy += 0.5 * body.mass_kg * com_velocity.squaredNorm() +
              0.5 * w.dot(rotation * body.inertia_kg_m2 * rotation.transpose() * w);
  }
  return energy;
}

double PotentialEnergy(const Model& model, const State& state) {
  double energy = 0.0;
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& body = model.bodies[b];
    const Vec3 com = WorldPoint(state, static_cast<int>(b), body.com_m);
    energy -= body.mass_kg * model.gravity_m_per_s2.dot(com);
  }
  for (size_t c = 0; c < model.cables.size(); ++c) {
    const Cable& cable = model.cables[c];
    const double length = (WorldPoint(state, cable.body_b, cable.anchor_b_m) -
                           WorldPoint(state, cable.body_a, cable.anchor_a_m))
                              .norm();
    const double stretch = length - state.rest_length_m[c];
    if (stretch > 0.0) energy += 0.5 * cable.stiffness_n_per_m * stretch * stretch;
  }
  return energy;
}

uint64_t StateHash(const State& state) {
  uint64_t hash = 1469598103934665603ULL;
  auto mix_bytes = [&hash](const void* data, size_t size) {
    const unsigned char* bytes = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      hash ^= bytes[i];
      hash *= 1099511628211ULL;
    }
  };
  auto mix = [&mix_bytes](double value) { mix_bytes(&value, sizeof(value)); };
  mix(state.time_s);
  mix_bytes(&state.step_count, sizeof(state.step_count));
  for (const BodyState& body : state.bodies) {
    for (int i = 0; i < 3; ++i) mix(body.position_m[i]);
    for (int i = 0; i < 4; ++i) mix(body.orientation.coeffs()[i]);
    for (int i = 0; i < 3; ++i) mix(body.velocity_m_per_s[i]);
    for (int i = 0; i < 3; ++i) mix(body.angular_velocity_rad_per_s[i]);
  }
  for (double value : state.rest_length_m) mix(value);
  for (double value : state.hinge_angle_rad) mix(value);
  for (double value : state.hinge_rate_rad_per_s) mix(value);
  for (double value : state.foot_normal_impulse_n_s) mix(value);
  for (double value : state.cable_tension_n) mix(value);
  for (int64_t key : state.warm_contact_key) mix_bytes(&key, sizeof(key));
  for (double value : state.warm_contact_impulse_n_s) mix(value);
  return hash;
}

}  // namespace liftoff::sim
