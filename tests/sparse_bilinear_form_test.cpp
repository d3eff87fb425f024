// Tests of SparseBilinearForm (linalg/sparse_bilinear_form.h): on a matrix touching few
// dofs it is the dense x^T A y, its entries stored as 0 left out; on a matrix touching
// every dof, the same bits as Eigen's x.dot(A * y), and Forms the three forms of a
// square matrix in one pass; a rectangular block of reaction rows.
#include "mcrewave/linalg/sparse_bilinear_form.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace mcrewave {
namespace {

// A symmetric n x n matrix with entries on the dofs [first, first + size) only.
SparseMatrix LocalBlock(int n, int first, int size, std::mt19937* generator) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = first; i < first + size; ++i) {
    for (int k = i; k < first + size; ++k) {
      const double a = value(*generator);
      entries.emplace_back(i, k, a);
      if (k != i) entries.emplace_back(k, i, a);
    }
  }
  SparseMatrix matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

Vector RandomVector(int n, std::mt19937* generator) {
  std::normal_distribution<double> value;
  Vector x(n);
  for (double& entry : x) entry = value(*generator);
  return x;
}

TEST(SparseBilinearFormTest, IsTheDenseFormOnAFewDofs) {
  std::mt19937 generator(3);
  const int n = 200;
  const SparseMatrix a = LocalBlock(n, 57, 3, &generator);
  SparseBilinearForm form(a);
  EXPECT_FALSE(form.whole());
  EXPECT_EQ(form.num_entries(), 9);
  const Vector x = RandomVector(n, &generator), y = RandomVector(n, &generator);
  const Matrix dense(a);
  const double expected = x.dot(dense * y);
  // Nine products summed in another order: at most 5.2e-15 apart, relative, over 200
  // seeds (cancellation in x^T A y).
  EXPECT_NEAR(form(x.data(), y.data()), expected, 2e-14 * std::abs(expected));
  double xx = 0.0, xy = 0.0, yy = 0.0;
  form.Forms(x.data(), y.data(), &xx, &xy, &yy);
  EXPECT_EQ(xy, form(x.data(), y.data()));
  EXPECT_NEAR(xx, x.dot(dense * x), 2e-14 * std::abs(x.dot(dense * x)));
  EXPECT_NEAR(yy, y.dot(dense * y), 2e-14 * std::abs(y.dot(dense * y)));
}

TEST(SparseBilinearFormTest, EntriesStoredAsZeroAreNotActive) {
  // A zone's K_z assembled over the whole mesh: zeros stored on every other dof.
  std::mt19937 generator(7);
  const int n = 60;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, 0.0);
  const SparseMatrix block = LocalBlock(n, 20, 2, &generator);
  for (int column = 0; column < n; ++column) {
    for (SparseMatrix::InnerIterator entry(block, column); entry; ++entry) {
      entries.emplace_back(static_cast<int>(entry.row()), column, entry.value());
    }
  }
  SparseMatrix a(n, n);
  a.setFromTriplets(entries.begin(), entries.end());
  ASSERT_EQ(a.nonZeros(), n + 2);  // 60 diagonal entries (two of them nonzero) and two off
  SparseBilinearForm form(a);
  EXPECT_FALSE(form.whole());
  EXPECT_EQ(form.num_entries(), 4);
  const Vector x = RandomVector(n, &generator), y = RandomVector(n, &generator);
  const double expected = x.dot(Matrix(a) * y);
  EXPECT_NEAR(form(x.data(), y.data()), expected, 2e-14 * std::abs(expected));
}

TEST(SparseBilinearFormTest, TouchingEveryDofTheFormIsEigensProductToTheBit) {
  std::mt19937 generator(5);
  const int n = 37;
  const SparseMatrix a = LocalBlock(n, 0, n, &generator);
  SparseBilinearForm form(a);
  EXPECT_TRUE(form.whole());
  const Vector x = RandomVector(n, &generator), y = RandomVector(n, &generator);
  const Vector product = a * y;
  EXPECT_EQ(form(x.data(), y.data()), x.dot(product));
  // Forms sums over the entries in one pass, in another order than the products: apart
  // by at most a few roundings of the sum of the terms' magnitudes, |x|^T |A| |y|
  // (measured 3.3e-17, 1.3e-16 and 9.7e-17).
  double xx = 0.0, xy = 0.0, yy = 0.0;
  form.Forms(x.data(), y.data(), &xx, &xy, &yy);
  const SparseMatrix magnitudes = a.cwiseAbs();
  auto magnitude = [&magnitudes](const Vector& u, const Vector& v) {
    return u.cwiseAbs().dot(magnitudes * v.cwiseAbs());
  };
  EXPECT_NEAR(xx, x.dot(a * x), 1e-15 * magnitude(x, x));
  EXPECT_NEAR(xy, x.dot(product), 1e-15 * magnitude(x, y));
  EXPECT_NEAR(yy, y.dot(product), 1e-15 * magnitude(y, y));
}

TEST(SparseBilinearFormTest, RectangularRowsTakeTheirEntries) {
  // Two reaction rows g_s^T K_z over 50 dofs, the second empty: r^T (A u).
  std::vector<Eigen::Triplet<double>> entries = {{0, 10, 2.0}, {0, 11, -3.0}, {0, 40, 0.5}};
  SparseMatrix a(2, 50);
  a.setFromTriplets(entries.begin(), entries.end());
  SparseBilinearForm form(a);
  EXPECT_FALSE(form.whole());
  EXPECT_EQ(form.num_entries(), 3);
  Vector u = Vector::Zero(50);
  u[10] = 1.0;
  u[11] = 2.0;
  u[40] = 4.0;
  u[12] = 100.0;  // untouched
  const double r[2] = {3.0, 7.0};
  // r_0 (2 - 6 + 2) = -6.
  EXPECT_EQ(form(r, u.data()), -6.0);
}

}  // namespace
}  // namespace mcrewave
