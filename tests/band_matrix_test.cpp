// SymmetricBandMatrix products and BandLdlt solves against Eigen's dense ones.
#include "mcrewave/linalg/band_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstring>
#include <random>
#include <vector>

#include "mcrewave/model/bar_model.h"

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

TEST_P(BandMatrixTest, BilinearFormMatchesTheDenseOne) {
  const int p = GetParam();
  std::mt19937_64 engine(314 + p);
  for (int n : {1, 2, 3, 4, 7, 50, 101}) {
    const SparseMatrix sparse = RandomBandMatrix(n, p, false, &engine);
    const SymmetricBandMatrix band(sparse);
    const Vector x = Vector::Random(n);
    const Vector y = Vector::Random(n);
    const double expected = x.dot(Matrix(sparse) * y);
    const double scale = x.cwiseAbs().dot(Matrix(sparse).cwiseAbs() * y.cwiseAbs());
    EXPECT_NEAR(band.BilinearForm(x, y), expected, 1e-14 * scale) << "n = " << n;
    EXPECT_NEAR(band.BilinearForm(y, x), expected, 1e-14 * scale) << "n = " << n;
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

TEST(TwistedTridiagonalLdltTest, SolveMatchesTheDenseLdlt) {
  std::mt19937_64 engine(99);
  // Odd and even sizes: the two eliminations have equal lengths or differ by one.
  for (int n : {1, 2, 3, 4, 5, 8, 50, 101, 400}) {
    const SparseMatrix sparse = RandomBandMatrix(n, 1, true, &engine);
    TwistedTridiagonalLdlt factor;
    ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(sparse))) << "n = " << n;
    EXPECT_TRUE(factor.ok());
    EXPECT_EQ(factor.size(), n);
    const Vector b = Vector::Random(n);
    Vector x = b;
    factor.SolveInPlace(x);
    EXPECT_LT(RelativeError(x, Matrix(sparse).ldlt().solve(b)), 1e-12) << "n = " << n;
    EXPECT_LT(RelativeError(Matrix(sparse) * x, b), 1e-14) << "n = " << n;
  }
}

TEST(TwistedTridiagonalLdltTest, BatchedSolvesMatchSingleSolvesExactly) {
  std::mt19937_64 engine(5);
  for (int n : {1, 2, 3, 4, 7, 50, 101}) {
    TwistedTridiagonalLdlt factor;
    ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(RandomBandMatrix(n, 1, true, &engine))));
    const Vector b0 = Vector::Random(n), b1 = Vector::Random(n), b2 = Vector::Random(n);
    Vector x0 = b0, x1 = b1, x2 = b2;
    factor.SolveInPlace<3>({x0.data(), x1.data(), x2.data()});
    Vector y0 = b0, y1 = b1;
    factor.SolveInPlace<2>({y0.data(), y1.data()});
    for (const auto& [batched, rhs] :
         {std::pair<Vector, Vector>{x0, b0}, {x1, b1}, {x2, b2}, {y0, b0}, {y1, b1}}) {
      Vector single = rhs;
      factor.SolveInPlace(single);
      EXPECT_EQ((batched - single).cwiseAbs().maxCoeff(), 0.0) << "n = " << n;
    }
  }
}

// The solve with the theta step's update fused into its back-substitutions gives the
// bits of the plain solve followed by the update's own loop, single and batched.
TEST(TwistedTridiagonalLdltTest, TheFusedUpdateIsTheSolveThenTheUpdate) {
  std::mt19937_64 engine(8);
  // Distinct coefficients, so that a swapped pair shows.
  const double a = 0.1e-6, b = 0.3e-6;
  for (int n : {1, 2, 3, 4, 7, 50, 101}) {
    TwistedTridiagonalLdlt factor;
    ASSERT_TRUE(factor.Compute(SymmetricBandMatrix(RandomBandMatrix(n, 1, true, &engine))));
    Vector rhs[3], u[3], v[3], x[3], u_next[3];
    for (int r = 0; r < 3; ++r) {
      rhs[r] = Vector::Random(n);
      u[r] = Vector::Random(n);
      v[r] = Vector::Random(n);
      x[r] = rhs[r];
      u_next[r] = Vector::Zero(n);
    }
    auto update = [&](int r) {
      return TwistedTridiagonalLdlt::Update{u[r].data(), v[r].data(), a, b, u_next[r].data()};
    };
    auto expect_solve_then_update = [&](int r, const char* what) {
      Vector solved = rhs[r];
      factor.SolveInPlace(solved);
      const Vector updated = u[r] + a * v[r] + b * solved;
      // Bit for bit (memcmp also tells -0 from +0).
      EXPECT_EQ(std::memcmp(x[r].data(), solved.data(), sizeof(double) * n), 0)
          << what << ", n = " << n;
      EXPECT_EQ(std::memcmp(u_next[r].data(), updated.data(), sizeof(double) * n), 0)
          << what << ", n = " << n;
    };
    factor.SolveInPlace(x[0].data(), update(0));
    expect_solve_then_update(0, "single");
    for (int r = 0; r < 3; ++r) x[r] = rhs[r];
    factor.SolveInPlace<3>({x[0].data(), x[1].data(), x[2].data()},
                           {update(0), update(1), update(2)});
    for (int r = 0; r < 3; ++r) expect_solve_then_update(r, "batch of 3");
    for (int r = 0; r < 2; ++r) x[r] = rhs[r];
    factor.SolveInPlace<2>({x[0].data(), x[1].data()}, {update(0), update(1)});
    for (int r = 0; r < 2; ++r) expect_solve_then_update(r, "batch of 2");
  }
}

TEST(TwistedTridiagonalLdltTest, AgreesWithBandLdltOnTheThetaIterationMatrixOfTheBar) {
  const BarModel model{BarProperties{}};
  const double h_theta = 0.36e-6 * 0.5;
  const SymmetricBandMatrix schur(model.mass() + (h_theta * h_theta) *
                                                     model.Stiffness(model.properties().modulus));
  BandLdlt thomas;
  TwistedTridiagonalLdlt twisted;
  ASSERT_TRUE(thomas.Compute(schur));
  ASSERT_TRUE(twisted.Compute(schur));
  const Vector b = Vector::Random(model.num_nodes());
  Vector x_thomas = b, x_twisted = b;
  thomas.SolveInPlace(x_thomas);
  twisted.SolveInPlace(x_twisted);
  EXPECT_LT(RelativeError(x_twisted, x_thomas), 1e-14);
}

TEST(TwistedTridiagonalLdltTest, RejectsAnIndefiniteMatrix) {
  // [[1 2 0], [2 1 0], [0 0 1]]: eigenvalues -1, 1, 3; the middle pivot is 1 - 4 < 0.
  SparseMatrix indefinite(3, 3);
  std::vector<Eigen::Triplet<double>> entries{
      {0, 0, 1.0}, {1, 1, 1.0}, {2, 2, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}};
  indefinite.setFromTriplets(entries.begin(), entries.end());
  TwistedTridiagonalLdlt factor;
  EXPECT_FALSE(factor.Compute(SymmetricBandMatrix(indefinite)));
  EXPECT_FALSE(factor.ok());
  // The indefinite block at the bottom end: caught by the bottom elimination.
  SparseMatrix bottom(5, 5);
  std::vector<Eigen::Triplet<double>> bottom_entries{
      {0, 0, 1.0}, {1, 1, 1.0}, {2, 2, 1.0}, {3, 3, 1.0}, {4, 4, 1.0}, {4, 3, 2.0}, {3, 4, 2.0}};
  bottom.setFromTriplets(bottom_entries.begin(), bottom_entries.end());
  EXPECT_FALSE(factor.Compute(SymmetricBandMatrix(bottom)));
  SparseMatrix identity(4, 4);
  identity.setIdentity();
  EXPECT_TRUE(factor.Compute(SymmetricBandMatrix(identity)));
  EXPECT_TRUE(factor.ok());
}

}  // namespace
}  // namespace mcrewave
