// The engine's band Cholesky (src/sim/band_cholesky.h) against Eigen's dense LLT on seeded
// random SPD band matrices, against the closed-form factor of the second-difference matrix,
// and on solves with known solutions.
#include "band_cholesky.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace liftoff::sim::internal {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// L L^T for a random lower-band L (entries in [-1, 1], diagonal in [1, 2]): symmetric
// positive definite with exactly `band` sub-diagonals (the last one non-zero).
Eigen::MatrixXd RandomSpdBand(Eigen::Index n, Eigen::Index band, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  std::uniform_real_distribution<double> diagonal(1.0, 2.0);
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    l(j, j) = diagonal(rng);
    for (Eigen::Index i = j + 1; i < std::min(n, j + band + 1); ++i) l(i, j) = entry(rng);
    if (j + band < n) l(j + band, j) = band > 0 ? 0.5 + 0.5 * std::abs(entry(rng)) : l(j, j);
  }
  return l * l.transpose();
}

// The lower triangle of `a` with the strict upper one set to NaN (which must not be read).
Eigen::MatrixXd LowerWithPoisonedUpper(const Eigen::MatrixXd& a) {
  Eigen::MatrixXd lower = a;
  for (Eigen::Index j = 1; j < a.cols(); ++j) {
    for (Eigen::Index i = 0; i < j; ++i) lower(i, j) = std::numeric_limits<double>::quiet_NaN();
  }
  return lower;
}

TEST(BandCholesky, MatchesEigenLltOnRandomBandMatrices) {
  std::mt19937_64 rng(20261126);
  for (const Eigen::Index n : {1, 2, 7, 30, 72}) {
    for (const Eigen::Index band : {0, 1, 5, 11, 17, 71}) {
      const Eigen::MatrixXd a = RandomSpdBand(n, std::min(band, n - 1), rng);
      Eigen::MatrixXd factor = LowerWithPoisonedUpper(a);
      ASSERT_TRUE(BandCholesky(factor, band)) << "n " << n << " band " << band;
      const Eigen::MatrixXd expected = a.llt().matrixL();
      for (Eigen::Index j = 0; j < n; ++j) {
        for (Eigen::Index i = j; i < n; ++i) {
          EXPECT_NEAR(factor(i, j), expected(i, j), 1e-9 * (1.0 + std::abs(expected(i, j))))
              << "n " << n << " band " << band << " at (" << i << ", " << j << ")";
          if (i - j > band) {
            EXPECT_EQ(factor(i, j), 0.0) << "outside the band";
          }
        }
      }
    }
  }
}

// Second differences, tridiagonal 2, -1: L(k, k) = sqrt((k + 2) / (k + 1)),
// L(k + 1, k) = -sqrt((k + 1) / (k + 2)).
TEST(BandCholesky, FactorsTheSecondDifferenceMatrixExactly) {
  constexpr Eigen::Index kN = 40;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(kN, kN);
  for (Eigen::Index k = 0; k < kN; ++k) {
    a(k, k) = 2.0;
    if (k + 1 < kN) a(k + 1, k) = -1.0;
  }
  ASSERT_TRUE(BandCholesky(a, 1));
  for (Eigen::Index k = 0; k < kN; ++k) {
    const double kk = static_cast<double>(k);
    EXPECT_NEAR(a(k, k), std::sqrt((kk + 2) / (kk + 1)), 1e-14) << k;
    if (k + 1 < kN) {
      EXPECT_NEAR(a(k + 1, k), -std::sqrt((kk + 1) / (kk + 2)), 1e-14) << k;
    }
  }
}

TEST(BandCholesky, RefusesMatricesThatAreNotPositiveDefinite) {
  Eigen::MatrixXd indefinite(2, 2);
  indefinite << 1.0, 0.0, 2.0, 1.0;  // lower triangle of [1 2; 2 1], eigenvalues 3 and -1
  EXPECT_FALSE(BandCholesky(indefinite, 1));
  Eigen::MatrixXd singular = Eigen::MatrixXd::Zero(3, 3);
  singular(0, 0) = 1.0;
  EXPECT_FALSE(BandCholesky(singular, 2));
  Eigen::MatrixXd not_a_number = Eigen::MatrixXd::Identity(2, 2);
  not_a_number(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(BandCholesky(not_a_number, 1));
}

// Several right-hand sides at once, in a row-major block wider than the columns solved
// (the engine's solution matrix): each column solved, the columns beyond left alone.
TEST(BandSolveColumns, SolvesKnownSolutionsColumnByColumn) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> entry(-3.0, 3.0);
  for (const Eigen::Index n : {1, 6, 42, 72}) {
    const Eigen::Index band = std::min<Eigen::Index>(n - 1, 11);
    const Eigen::MatrixXd a = RandomSpdBand(n, band, rng);
    RowMajorMatrix truth(n, 4);
    for (Eigen::Index i = 0; i < truth.size(); ++i) truth.data()[i] = entry(rng);
    RowMajorMatrix x(n, 5);
    x.leftCols(4) = a * truth;
    x.col(4).setConstant(123.0);
    Eigen::MatrixXd factor = a;
    ASSERT_TRUE(BandCholesky(factor, band));
    BandSolveColumns(factor, band, x.data(), x.cols(), 4);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index c = 0; c < 4; ++c) {
        EXPECT_NEAR(x(i, c), truth(i, c), 1e-10 * (1.0 + std::abs(truth(i, c))))
            << "n " << n << " row " << i << " column " << c;
      }
      EXPECT_EQ(x(i, 4), 123.0) << "a column beyond those solved was changed";
    }
    // and the same as Eigen's dense solve
    const Eigen::MatrixXd eigen = a.llt().solve(Eigen::MatrixXd(a * truth));
    EXPECT_LT((Eigen::MatrixXd(x.leftCols(4)) - eigen).cwiseAbs().maxCoeff(), 1e-10);
  }
}

}  // namespace
}  // namespace liftoff::sim::internal
