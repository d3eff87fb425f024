#include "mcrewave/band_matrix.h"

#include <algorithm>
#include <cassert>

namespace mcrewave {

SymmetricBandMatrix::SymmetricBandMatrix(const SparseMatrix& matrix) {
  assert(matrix.rows() == matrix.cols());
  const int n = static_cast<int>(matrix.rows());
  int p = 0;
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      p = std::max(p, static_cast<int>(std::abs(it.row() - it.col())));
    }
  }
  lower_ = Matrix::Zero(p + 1, n);
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      const int row = static_cast<int>(it.row()), col = static_cast<int>(it.col());
      if (row >= col) lower_(row - col, row) = it.value();
    }
  }
}

SymmetricBandMatrix SymmetricBandMatrix::LinearCombination(double a, const SymmetricBandMatrix& x,
                                                           double b, const SymmetricBandMatrix& y) {
  assert(x.size() == y.size());
  SymmetricBandMatrix result;
  const int p = std::max(x.half_bandwidth(), y.half_bandwidth());
  result.lower_ = Matrix::Zero(p + 1, x.size());
  result.lower_.topRows(x.lower_.rows()) += a * x.lower_;
  result.lower_.topRows(y.lower_.rows()) += b * y.lower_;
  return result;
}

void SymmetricBandMatrix::Multiply(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const {
  y.setZero();
  MultiplyAdd(1.0, x, y);
}

void SymmetricBandMatrix::MultiplyAdd(double alpha, const Eigen::Ref<const Vector>& x,
                                      Eigen::Ref<Vector> y) const {
  const int n = size();
  const int p = half_bandwidth();
  assert(x.size() == n && y.size() == n);
  if (p == 1) {
    // Tridiagonal fast path: y_i += alpha (l_i x_{i-1} + d_i x_i + l_{i+1} x_{i+1}).
    const double* d = lower_.data();  // lower_(0, i) at d[2 i], lower_(1, i) at d[2 i + 1]
    for (int i = 0; i < n; ++i) {
      double s = d[2 * i] * x[i];
      if (i > 0) s += d[2 * i + 1] * x[i - 1];
      if (i + 1 < n) s += d[2 * (i + 1) + 1] * x[i + 1];
      y[i] += alpha * s;
    }
    return;
  }
  for (int i = 0; i < n; ++i) {
    double s = lower_(0, i) * x[i];
    for (int d = 1; d <= p; ++d) {
      if (i - d >= 0) s += lower_(d, i) * x[i - d];
      if (i + d < n) s += lower_(d, i + d) * x[i + d];
    }
    y[i] += alpha * s;
  }
}

void SymmetricBandMatrix::MultiplyPairAdd(const SymmetricBandMatrix& a,
                                          const Eigen::Ref<const Vector>& x, double beta,
                                          const SymmetricBandMatrix& b,
                                          const Eigen::Ref<const Vector>& z, double gamma,
                                          const Eigen::Ref<const Vector>& f, Eigen::Ref<Vector> y) {
  const int n = a.size();
  assert(b.size() == n && x.size() == n && z.size() == n && f.size() == n && y.size() == n);
  if (a.half_bandwidth() == 1 && b.half_bandwidth() == 1) {
    // Tridiagonal fast path, both products in one pass:
    //   y_i = sum_{j=i-1..i+1} (A_ij x_j + beta B_ij z_j) + gamma f_i.
    const double* da = a.lower_.data();
    const double* db = b.lower_.data();
    for (int i = 0; i < n; ++i) {
      double s = da[2 * i] * x[i] + beta * db[2 * i] * z[i];
      if (i > 0) s += da[2 * i + 1] * x[i - 1] + beta * db[2 * i + 1] * z[i - 1];
      if (i + 1 < n) s += da[2 * i + 3] * x[i + 1] + beta * db[2 * i + 3] * z[i + 1];
      y[i] = s + gamma * f[i];
    }
    return;
  }
  a.Multiply(x, y);
  b.MultiplyAdd(beta, z, y);
  y += gamma * f;
}

bool BandLdlt::Compute(const SymmetricBandMatrix& matrix) {
  const int n = matrix.size();
  const int p = matrix.half_bandwidth();
  unit_lower_ = matrix;
  diagonal_.resize(n);
  ok_ = false;
  // Column-oriented LDL^T restricted to the band:
  //   D_j = A_jj - sum_{k<j} L_jk^2 D_k,
  //   L_ij = (A_ij - sum_{k<j} L_ik L_jk D_k) / D_j,  j < i <= j + p.
  for (int j = 0; j < n; ++j) {
    double dj = matrix.lower(0, j);
    for (int k = std::max(0, j - p); k < j; ++k) {
      const double ljk = unit_lower_.lower(j - k, j);
      dj -= ljk * ljk * diagonal_[k];
    }
    if (!(dj > 0.0)) return false;
    diagonal_[j] = dj;
    for (int i = j + 1; i <= std::min(n - 1, j + p); ++i) {
      double lij = matrix.lower(i - j, i);
      for (int k = std::max(0, i - p); k < j; ++k) {
        lij -= unit_lower_.lower(i - k, i) * unit_lower_.lower(j - k, j) * diagonal_[k];
      }
      unit_lower_.lower(i - j, i) = lij / dj;
    }
  }
  inverse_diagonal_ = diagonal_.cwiseInverse();
  ok_ = true;
  return true;
}

void BandLdlt::SolveInPlace(Eigen::Ref<Vector> x) const {
  assert(ok_ && x.size() == size());
  const int n = size();
  const int p = unit_lower_.half_bandwidth();
  if (p == 1) {
    // Tridiagonal fast path (Thomas algorithm on the LDL^T factors):
    //   y_i = b_i - l_i y_{i-1},  z_i = y_i / D_i,  x_i = z_i - l_{i+1} x_{i+1}.
    const double* l = unit_lower_.lower_data();  // l_i = L(i, i-1) at l[2 i + 1]
    const double* inverse_d = inverse_diagonal_.data();
    double previous = x[0];
    for (int i = 1; i < n; ++i) {
      previous = x[i] - l[2 * i + 1] * previous;
      x[i] = previous;
    }
    double next = x[n - 1] * inverse_d[n - 1];
    x[n - 1] = next;
    for (int i = n - 2; i >= 0; --i) {
      next = x[i] * inverse_d[i] - l[2 * (i + 1) + 1] * next;
      x[i] = next;
    }
    return;
  }
  // L y = b (forward), z = D^-1 y, L^T x = z (backward).
  for (int i = 1; i < n; ++i) {
    double s = x[i];
    for (int k = std::max(0, i - p); k < i; ++k) s -= unit_lower_.lower(i - k, i) * x[k];
    x[i] = s;
  }
  for (int i = 0; i < n; ++i) x[i] *= inverse_diagonal_[i];
  for (int i = n - 2; i >= 0; --i) {
    double s = x[i];
    for (int k = i + 1; k <= std::min(n - 1, i + p); ++k) s -= unit_lower_.lower(k - i, k) * x[k];
    x[i] = s;
  }
}

}  // namespace mcrewave
