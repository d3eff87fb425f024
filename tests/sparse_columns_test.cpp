// SparseColumns' products against Eigen's sparse products, to the bit, and the point
// loads through a step of the sparse integrator path against the step with the dense
// force.
#include "mcrewave/linalg/sparse_columns.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "mcrewave/linalg/theta_integrator.h"

namespace mcrewave {
namespace {

// An n x c matrix with a few entries per column, rows shared between columns (several
// channels on one dof), and two empty rows and one empty column.
SparseMatrix FewEntryColumns(int n, int c, std::mt19937_64* engine) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_int_distribution<int> row(2, n - 1);
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column + 1 < c; ++column) {
    for (int k = 0; k < 4; ++k) entries.emplace_back(row(*engine), column, uniform(*engine));
  }
  SparseMatrix matrix(n, c);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

// The point loads summed into a zero vector of n entries.
Vector Scattered(const PointLoads& loads, int n) {
  Vector force = Vector::Zero(n);
  for (int i = 0; i < loads.count; ++i) force[loads.nodes[i]] += loads.values[i];
  return force;
}

TEST(SparseColumnsTest, ProductsAreEigensToTheBit) {
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const int n = 40, c = 6;
  const SparseMatrix a = FewEntryColumns(n, c, &engine);
  SparseColumns columns(a);
  EXPECT_EQ(columns.rows(), n);
  EXPECT_EQ(columns.cols(), c);
  const Vector x = Vector::NullaryExpr(n, [&] { return uniform(engine); });
  const Vector weights = Vector::NullaryExpr(c, [&] { return uniform(engine); });
  const SparseMatrix transposed = a.transpose();
  Vector expected_y(c), y(c);
  expected_y.noalias() = transposed * x;
  columns.TransposeMultiply(x.data(), y.data());
  for (int i = 0; i < c; ++i) EXPECT_EQ(y[i], expected_y[i]) << "column " << i;
  Vector expected_force(n);
  expected_force.noalias() = a * weights;
  const PointLoads* loads = columns.Scatter(weights.data());
  // One load per distinct row with entries: fewer than the entries (rows are shared).
  EXPECT_LT(loads->count, static_cast<int>(a.nonZeros()));
  const Vector force = Scattered(*loads, n);
  for (int i = 0; i < n; ++i) EXPECT_EQ(force[i], expected_force[i]) << "row " << i;
  // A copy scatters into its own arrays.
  SparseColumns copy = columns;
  const PointLoads* copied = copy.Scatter(weights.data());
  EXPECT_NE(copied->values, loads->values);
  EXPECT_EQ(Scattered(*copied, n), force);
}

// A step of the sparse path with G c as point loads gives the bits of the step with
// the dense force G c (the MCRE sweeps rely on it: docs/matrix_models.md section 5).
TEST(SparseColumnsTest, PointLoadsStepAsTheDenseForce) {
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const int n = 30;
  std::vector<Eigen::Triplet<double>> mass, stiffness;
  for (int i = 0; i < n; ++i) {
    mass.emplace_back(i, i, 2.0);
    stiffness.emplace_back(i, i, 4.0);
    for (int d : {1, 7}) {  // half bandwidth 7 > 1: the sparse path when asked
      if (i + d >= n) continue;
      stiffness.emplace_back(i, i + d, -1.0);
      stiffness.emplace_back(i + d, i, -1.0);
    }
  }
  SparseMatrix m(n, n), k(n, n);
  m.setFromTriplets(mass.begin(), mass.end());
  k.setFromTriplets(stiffness.begin(), stiffness.end());
  ThetaIntegratorOptions options;
  options.time_step = 0.1;
  options.factorization = Factorization::kSparse;
  ThetaIntegrator integrator;
  integrator.Init(m, k, options);
  const SparseMatrix g = FewEntryColumns(n, 4, &engine);
  SparseColumns columns(g);
  const Vector channels = Vector::NullaryExpr(4, [&] { return uniform(engine); });
  const Vector v = Vector::NullaryExpr(n, [&] { return uniform(engine); });
  const Vector u = Vector::NullaryExpr(n, [&] { return uniform(engine); });
  const Vector z = Vector::NullaryExpr(n, [&] { return uniform(engine); });
  Vector force(n);
  force.noalias() = g * channels;
  Vector v_dense(n), u_dense(n), v_points(n), u_points(n);
  integrator.StepShifted(v, u, z, force, v_dense, u_dense);
  integrator.StepWithEndLoads(v, u, z, 0.0, 0.0, v_points, u_points,
                              columns.Scatter(channels.data()));
  EXPECT_EQ(v_points, v_dense);
  EXPECT_EQ(u_points, u_dense);
}

}  // namespace
}  // namespace mcrewave
