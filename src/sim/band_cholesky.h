// The engine's linear solve (private to the sim module): Cholesky factor and solve of a
// symmetric positive definite band matrix, the velocity system M - dt D - dt^2 K, whose
// lower triangle is zero more than `band` below the diagonal (cables couple only the
// clusters they join). Eigen's dense LLT does the same job without the band; the engine
// keeps this one for speed (bench/kernels_bench: BandCholesky against Eigen::LLT at the
// engine's sizes) and because it solves many right-hand sides in one pass.
// Tested against Eigen::LLT in tests/sim/band_cholesky_test.cc.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace liftoff::sim::internal {

// In-place Cholesky factor (lower triangle) of a symmetric positive definite matrix whose
// lower triangle is zero more than `band` below the diagonal; the factor keeps the band.
// Only the lower triangle is read or written. Returns false if it is not positive definite.
inline bool BandCholesky(Eigen::MatrixXd& a, Eigen::Index band) {
  const Eigen::Index n = a.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    const double diagonal = a(k, k);
    if (!(diagonal > 0.0)) return false;
    const double pivot = std::sqrt(diagonal);
    a(k, k) = pivot;
    const Eigen::Index end = std::min(n, k + band + 1);
    const double inverse = 1.0 / pivot;
    for (Eigen::Index i = k + 1; i < end; ++i) a(i, k) *= inverse;
    for (Eigen::Index j = k + 1; j < end; ++j) {
      const double factor = a(j, k);
      if (factor == 0.0) continue;
      for (Eigen::Index i = j; i < end; ++i) a(i, j) -= a(i, k) * factor;
    }
  }
  return true;
}

// Solves (L L^T) X = B in place with the factor of BandCholesky, for the first `columns`
// columns of a row-major X (rows of `stride` numbers): the columns share every pass.
inline void BandSolveColumns(const Eigen::MatrixXd& l, Eigen::Index band, double* x,
                             Eigen::Index stride, Eigen::Index columns) {
  const Eigen::Index n = l.rows();
  for (Eigen::Index k = 0; k < n; ++k) {
    double* xk = x + k * stride;
    const double inverse = 1.0 / l(k, k);
    for (Eigen::Index c = 0; c < columns; ++c) xk[c] *= inverse;
    const Eigen::Index end = std::min(n, k + band + 1);
    for (Eigen::Index i = k + 1; i < end; ++i) {
      const double factor = l(i, k);
      double* xi = x + i * stride;
      for (Eigen::Index c = 0; c < columns; ++c) xi[c] -= factor * xk[c];
    }
  }
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    double* xk = x + k * stride;
    const Eigen::Index end = std::min(n, k + band + 1);
    for (Eigen::Index i = k + 1; i < end; ++i) {
      const double factor = l(i, k);
      const double* xi = x + i * stride;
      for (Eigen::Index c = 0; c < columns; ++c) xk[c] -= factor * xi[c];
    }
    const double inverse = 1.0 / l(k, k);
    for (Eigen::Index c = 0; c < columns; ++c) xk[c] *= inverse;
  }
}

}  // namespace liftoff::sim::internal
