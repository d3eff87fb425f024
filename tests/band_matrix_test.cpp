// SymmetricBandMatrix products and BandLdlt solves against Eigen's dense ones.
#include "mcrewave/band_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "mcrewave/bar_model.h"

namespace mcrewave {
namespace {

// A random symmetric matrix of half bandwidth p, made positive definite by a
// dominant diagonal when spd is true.
SparseMatrix RandomBandMatrix(int n, int p, bool spd, std::mt19937_64* engine) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    // Row sum of |off-diagonal| <= 2 p, so a diagonal in [2 p + 1, 2 p + 2] dominates.
    entries.emplace_back(i, i, spd ? 2.0 * p + 1.5 + 0.5 * uniform(*engine) : uniform(*engine));
    for (int d = 1; d <= p && i + d < n; ++d) {
      const double value = uniform(*engine);
      entries.emplace_back(i + d, i, value);
      entries.emplace_back(i, i + d, value);
    }
  }
  SparseMatrix matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

double RelativeError(const Vector& actual, const Vector& expected) {
  return (actual - expected).norm() / expected.norm();
}

class BandMatrixTest : public ::testing::TestWithParam<int> {};

TEST_P(BandMatrixTest, MultiplyMatchesTheDenseProduct) {
  const int p = GetParam();
  std::mt19937_64 engine(42 + p);
  for (int n : {1, 2, 3, 7, 50}) {
    const SparseMatrix sparse = RandomBandMatrix(n, p, false, &engine);
    const Matrix dense = Matrix(sparse);
    const SymmetricBandMatrix band(sparse);
    ASSERT_EQ(band.size(), n);
    ASSERT_EQ(band.half_bandwidth(), std::min(p, n - 1));
    const Vector x = Vector::Random(n);
    Vector y = Vector::Random(n);  // overwritten
    band.Multiply(x, y);
    EXPECT_LT(RelativeError(y, dense * x), 1e-14) << "n = " << n;

    const Vector y0 = Vector::Random(n);
    y = y0;
    band.MultiplyAdd(-0.7, x, y);
    const Vector expected = y0 - 0.7 * dense * x;
    EXPECT_LT(RelativeError(y, expected), 1e-14) << "n = " << n;
  }
}

TEST_P(BandMatrixTest, LinearCombinationMatchesTheDenseOne) {
  const int p = GetParam();
  std::mt19937_64 engine(7 + p);
  const int n = 20;
  const SparseMatrix a = RandomBandMatrix(n, p, false, &engine);
  const SparseMatrix b = RandomBandMatrix(n, 1, false, &engine);
  const SymmetricBandMatrix combination = SymmetricBandMatrix::LinearCombination(
      2.5, SymmetricBandMatrix(a), -1.5, SymmetricBandMatrix(b));
  EXPECT_EQ(combination.half_bandwidth(), p);
  const Vector x = Vector::Random(n);
  Vector y(n);
  combination.Multiply(x, y);
  EXPECT_LT(RelativeError(y, (2.5 * Matrix(a) - 1.5 * Matrix(b)) * x), 1e-14);
}

TEST_P(BandMatrixTest, LdltSolveMatchesTheDenseLdlt) {
  const int p = GetParam();
  std::mt19937_64 engine(1234 + p);
  for (int n : {1, 2, 3, 7, 50, 400}) {
    const SparseMatrix sparse = RandomBandMatrix(n, p, true, &engine);
    BandLdlt factor;
    ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(sparse))) << "n = " << n;
    EXPECT_TRUE(factor.ok());
    EXPECT_EQ(factor.size(), n);
    const Vector b = Vector::Random(n);
    Vector x = b;
    factor.SolveInPlace(x);
    const Vector expected = Matrix(sparse).ldlt().solve(b);
    EXPECT_LT(RelativeError(x, expected), 1e-12) << "n = " << n;
  }
}

INSTANTIATE_TEST_SUITE_P(HalfBandwidth, BandMatrixTest, ::testing::Values(1, 2));

TEST(BandLdltTest, SolvesTheThetaIterationMatrixOfTheBar) {
  // S = M + h^2 theta^2 K of the paper's bar: the matrix the integrator factorises.
  const BarModel model{BarProperties{}};
  const double h_theta = 0.36e-6 * 0.5;
  const SparseMatrix schur =
      model.mass() + (h_theta * h_theta) * model.Stiffness(model.properties().modulus);
  BandLdlt factor;
  ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(schur)));
  const Vector b = Vector::Random(model.num_nodes());
  Vector x = b;
  factor.SolveInPlace(x);
  EXPECT_LT(RelativeError(x, Matrix(schur).ldlt().solve(b)), 1e-12);
  // The residual is at round-off too.
  EXPECT_LT(RelativeError(Matrix(schur) * x, b), 1e-14);
}

TEST(BandLdltTest, RejectsAnIndefiniteMatrix) {
  // [[1 2 0], [2 1 0], [0 0 1]] has eigenvalues -1, 1, 3 but a positive diagonal.
  SparseMatrix indefinite(3, 3);
  std::vector<Eigen::Triplet<double>> entries{
      {0, 0, 1.0}, {1, 1, 1.0}, {2, 2, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}};
  indefinite.setFromTriplets(entries.begin(), entries.end());
  BandLdlt factor;
  EXPECT_FALSE(factor.Compute(SymmetricBandMatrix(indefinite)));
  EXPECT_FALSE(factor.ok());

  // A previously good factorisation is invalidated by a failed one.
  SparseMatrix identity(3, 3);
  identity.setIdentity();
  ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(identity)));
  EXPECT_TRUE(factor.ok());
  EXPECT_FALSE(factor.Compute(SymmetricBandMatrix(-identity)));
  EXPECT_FALSE(factor.ok());
}

}  // namespace
}  // namespace mcrewave
