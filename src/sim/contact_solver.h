// The engine's contact impulses (private to the sim module): projected Gauss-Seidel on the
// Delassus matrix W = J A^-1 J^T of the step's contact rows, each contact a normal row
// (the impulse >= 0, the normal velocity reaching at least the contact's target) and,
// with friction, two tangent rows kept inside the Coulomb cone of the normal impulse.
// Tested on problems with known solutions in tests/sim/contact_solver_test.cc.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "liftoff/sim/engine.h"

namespace liftoff::sim::internal {

// Sweeps until no impulse changes by more than `tolerance_n_s` or `max_sweeps` are done.
// `w`: rows x rows; `free_velocity`: each row's velocity without contact impulses;
// `impulse`: the warm start in, the solution out. Returns the sweeps run.
template <typename Delassus, typename Impulse>
int SolveContactImpulses(const std::vector<ContactPoint>& contacts, const Delassus& w,
                         const Eigen::VectorXd& free_velocity, int max_sweeps, double tolerance_n_s,
                         Impulse& impulse) {
  int sweeps = 0;
  while (sweeps < max_sweeps) {
    ++sweeps;
    double largest_change = 0.0;
    for (const ContactPoint& contact : contacts) {
      const int n = contact.first_row;
      const double normal_velocity = free_velocity[n] + w.row(n).dot(impulse);
      const double updated = std::max(
          0.0, impulse[n] + (contact.target_normal_velocity_m_per_s - normal_velocity) / w(n, n));
      largest_change = std::max(largest_change, std::abs(updated - impulse[n]));
      impulse[n] = updated;
      if (contact.rows == 1) continue;
      double t[2];
      for (int k = 0; k < 2; ++k) {
        const int row = n + 1 + k;
        const double tangent_velocity = free_velocity[row] + w.row(row).dot(impulse);
        t[k] = impulse[row] - tangent_velocity / w(row, row);
      }
      // Coulomb: inside the cone of the current normal impulse
      const double limit = contact.friction * impulse[n];
      const double magnitude = std::hypot(t[0], t[1]);
      if (magnitude > limit) {
        const double scale = magnitude > 0.0 ? limit / magnitude : 0.0;
        t[0] *= scale;
        t[1] *= scale;
      }
      for (int k = 0; k < 2; ++k) {
        largest_change = std::max(largest_change, std::abs(t[k] - impulse[n + 1 + k]));
        impulse[n + 1 + k] = t[k];
      }
    }
    if (largest_change <= tolerance_n_s) break;
  }
  return sweeps;
}

}  // namespace liftoff::sim::internal
