#include "mcrewave/linalg/band_matrix.h"

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
  lower_ = Matrix::Zero(n, p + 1);
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      const int row = static_cast<int>(it.row()), col = static_cast<int>(it.col());
      if (row >= col) lower_(row, row - col) = it.value();
    }
  }
}

SymmetricBandMatrix SymmetricBandMatrix::LinearCombination(double a, const SymmetricBandMatrix& x,
                                                           double b, const SymmetricBandMatrix& y) {
  assert(x.size() == y.size());
  SymmetricBandMatrix result;
  const int p = std::max(x.half_bandwidth(), y.half_bandwidth());
  result.lower_ = Matrix::Zero(x.size(), p + 1);
  result.lower_.leftCols(x.lower_.cols()) += a * x.lower_;
  result.lower_.leftCols(y.lower_.cols()) += b * y.lower_;
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
    // Rows 1..n-2 without tests, then the two ends (n >= 2: p = 1 needs two rows).
    const double* d = diagonal_data(0);
    const double* l = diagonal_data(1);  // l_i = A(i, i-1)
    for (int i = 1; i + 1 < n; ++i) {
      y[i] += alpha * (d[i] * x[i] + l[i] * x[i - 1] + l[i + 1] * x[i + 1]);
    }
    y[0] += alpha * (d[0] * x[0] + l[1] * x[1]);
    y[n - 1] += alpha * (d[n - 1] * x[n - 1] + l[n - 1] * x[n - 2]);
    return;
  }
  for (int i = 0; i < n; ++i) {
    double s = lower_(i, 0) * x[i];
    for (int d = 1; d <= p; ++d) {
      if (i - d >= 0) s += lower_(i, d) * x[i - d];
      if (i + d < n) s += lower_(i + d, d) * x[i + d];
    }
    y[i] += alpha * s;
  }
}

double SymmetricBandMatrix::BilinearForm(const double* x, const double* y) const {
  const int n = size();
  const int p = half_bandwidth();
  if (n == 0) return 0.0;
  if (p <= 1) {
    // x^T A y = sum_i a_i x_i y_i + sum_{i>=1} s_i (x_i y_{i-1} + x_{i-1} y_i),
    // a_i = A(i, i), s_i = A(i, i-1): Eigen's vectorised reductions over the diagonals.
    using ConstArrayMap = Eigen::Map<const Eigen::ArrayXd>;
    const ConstArrayMap a(diagonal_data(0), n), xs(x, n), ys(y, n);
    double sum = (a * xs * ys).sum();
    if (p == 1) {
      const ConstArrayMap s(diagonal_data(1) + 1, n - 1);
      sum += (s * (xs.tail(n - 1) * ys.head(n - 1) + xs.head(n - 1) * ys.tail(n - 1))).sum();
    }
    return sum;
  }
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    double row = lower_(i, 0) * y[i];
    for (int d = 1; d <= p; ++d) {
      if (i - d >= 0) row += lower_(i, d) * y[i - d];
      if (i + d < n) row += lower_(i + d, d) * y[i + d];
    }
    sum += x[i] * row;
  }
  return sum;
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
    const double* da = a.diagonal_data(0);
    const double* la = a.diagonal_data(1);
    const double* db = b.diagonal_data(0);
    const double* lb = b.diagonal_data(1);
    for (int i = 0; i < n; ++i) {
      double s = da[i] * x[i] + beta * db[i] * z[i];
      if (i > 0) s += la[i] * x[i - 1] + beta * lb[i] * z[i - 1];
      if (i + 1 < n) s += la[i + 1] * x[i + 1] + beta * lb[i + 1] * z[i + 1];
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
    const double* l = unit_lower_.diagonal_data(1);  // l_i = L(i, i-1)
    const double* inverse_d = inverse_diagonal_.data();
    double previous = x[0];
    for (int i = 1; i < n; ++i) {
      previous = x[i] - l[i] * previous;
      x[i] = previous;
    }
    double next = x[n - 1] * inverse_d[n - 1];
    x[n - 1] = next;
    for (int i = n - 2; i >= 0; --i) {
      next = x[i] * inverse_d[i] - l[i + 1] * next;
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

bool TwistedTridiagonalLdlt::Compute(const SymmetricBandMatrix& matrix) {
  assert(matrix.half_bandwidth() <= 1);
  const int n = matrix.size();
  const int k = (n - 1) / 2;
  middle_ = k;
  top_ = Vector::Zero(n);
  bottom_ = Vector::Zero(n);
  inverse_pivot_ = Vector::Zero(n);
  ok_ = false;
  auto diagonal = [&](int i) { return matrix.lower(0, i); };
  const bool banded = matrix.half_bandwidth() == 1;
  auto sub = [&](int i) { return banded ? matrix.lower(1, i) : 0.0; };  // A(i, i-1)
  // Top: d_0 = a_0, l_i = s_i / d_{i-1}, d_i = a_i - l_i s_i.
  for (int i = 0; i < k; ++i) {
    double pivot = diagonal(i);
    if (i > 0) {
      top_[i] = sub(i) * inverse_pivot_[i - 1];
      pivot -= top_[i] * sub(i);
    }
    if (!(pivot > 0.0)) return false;
    inverse_pivot_[i] = 1.0 / pivot;
  }
  // Bottom: e_{n-1} = a_{n-1}, m_i = s_{i+1} / e_{i+1}, e_i = a_i - m_i s_{i+1}.
  for (int i = n - 1; i > k; --i) {
    double pivot = diagonal(i);
    if (i < n - 1) {
      bottom_[i] = sub(i + 1) * inverse_pivot_[i + 1];
      pivot -= bottom_[i] * sub(i + 1);
    }
    if (!(pivot > 0.0)) return false;
    inverse_pivot_[i] = 1.0 / pivot;
  }
  // Middle: g_k = a_k - l_k s_k - m_k s_{k+1}.
  double pivot = diagonal(k);
  if (k > 0) {
    top_[k] = sub(k) * inverse_pivot_[k - 1];
    pivot -= top_[k] * sub(k);
  }
  if (k < n - 1) {
    bottom_[k] = sub(k + 1) * inverse_pivot_[k + 1];
    pivot -= bottom_[k] * sub(k + 1);
  }
  if (!(pivot > 0.0)) return false;
  inverse_pivot_[k] = 1.0 / pivot;
  ok_ = true;
  return true;
}

template <typename OnSolved>
void TwistedTridiagonalLdlt::Solve(double* x, OnSolved&& on_solved) const {
  assert(ok_);
  const int n = size();
  const int k = middle_;
  const double* l = top_.data();
  const double* m = bottom_.data();
  const double* inverse_pivot = inverse_pivot_.data();
  // Eliminations from both ends, side by side:
  //   y_i = b_i - l_i y_{i-1} (i = 1..k-1),  z_j = b_j - m_j z_{j+1} (j = n-2..k+1).
  // The top has k - 1 rows, the bottom n - 2 - k >= k - 1 (one more when n is even).
  // The recurrences carry their last value in a register (no store-to-load latency).
  double up = x[0], down = x[n - 1];
  int i = 1, j = n - 2;
  for (; i < k; ++i, --j) {
    up = x[i] - l[i] * up;
    down = x[j] - m[j] * down;
    x[i] = up;
    x[j] = down;
  }
  for (; j > k; --j) {
    down = x[j] - m[j] * down;
    x[j] = down;
  }
  // Middle: x_k = (b_k - l_k y_{k-1} - m_k z_{k+1}) / g_k.
  double middle = x[k];
  if (k > 0) middle -= l[k] * up;
  if (k < n - 1) middle -= m[k] * down;
  middle *= inverse_pivot[k];
  x[k] = middle;
  on_solved(0, k);
  // Back-substitutions outward, side by side:
  //   x_i = y_i / d_i - l_{i+1} x_{i+1} (i = k-1..0),  x_j = z_j / e_j - m_{j-1} x_{j-1} (j =
  //   k+1..n-1).
  up = middle;
  down = middle;
  i = k - 1;
  j = k + 1;
  for (; i >= 0; --i, ++j) {
    up = x[i] * inverse_pivot[i] - l[i + 1] * up;
    down = x[j] * inverse_pivot[j] - m[j - 1] * down;
    x[i] = up;
    x[j] = down;
    on_solved(0, i);
    on_solved(0, j);
  }
  for (; j < n; ++j) {
    down = x[j] * inverse_pivot[j] - m[j - 1] * down;
    x[j] = down;
    on_solved(0, j);
  }
}

template <int B, typename OnSolved>
void TwistedTridiagonalLdlt::Solve(double* const (&x)[B], OnSolved&& on_solved) const {
  assert(ok_);
  const int n = size();
  const int k = middle_;
  const double* l = top_.data();
  const double* m = bottom_.data();
  const double* inverse_pivot = inverse_pivot_.data();
  // The recurrences of the single solve, once per right-hand side b.
  double up[B], down[B], middle[B];
  for (int b = 0; b < B; ++b) {
    up[b] = x[b][0];
    down[b] = x[b][n - 1];
  }
  int i = 1, j = n - 2;
  for (; i < k; ++i, --j) {
    for (int b = 0; b < B; ++b) {
      up[b] = x[b][i] - l[i] * up[b];
      down[b] = x[b][j] - m[j] * down[b];
      x[b][i] = up[b];
      x[b][j] = down[b];
    }
  }
  for (; j > k; --j) {
    for (int b = 0; b < B; ++b) {
      down[b] = x[b][j] - m[j] * down[b];
      x[b][j] = down[b];
    }
  }
  for (int b = 0; b < B; ++b) {
    middle[b] = x[b][k];
    if (k > 0) middle[b] -= l[k] * up[b];
    if (k < n - 1) middle[b] -= m[k] * down[b];
    middle[b] *= inverse_pivot[k];
    x[b][k] = middle[b];
    on_solved(b, k);
    up[b] = middle[b];
    down[b] = middle[b];
  }
  i = k - 1;
  j = k + 1;
  for (; i >= 0; --i, ++j) {
    for (int b = 0; b < B; ++b) {
      up[b] = x[b][i] * inverse_pivot[i] - l[i + 1] * up[b];
      down[b] = x[b][j] * inverse_pivot[j] - m[j - 1] * down[b];
      x[b][i] = up[b];
      x[b][j] = down[b];
      on_solved(b, i);
      on_solved(b, j);
    }
  }
  for (; j < n; ++j) {
    for (int b = 0; b < B; ++b) {
      down[b] = x[b][j] * inverse_pivot[j] - m[j - 1] * down[b];
      x[b][j] = down[b];
      on_solved(b, j);
    }
  }
}

void TwistedTridiagonalLdlt::SolveInPlace(double* x) const {
  Solve(x, [](int, int) {});
}

void TwistedTridiagonalLdlt::SolveInPlace(double* x, const Update& update) const {
  const double *u = update.u, *v = update.v;
  const double a = update.a, b = update.b;
  double* u_next = update.u_next;
  // u_next_i = u_i + a v_i + b x_i, as the theta step's own loop writes it.
  Solve(x, [&](int, int i) { u_next[i] = u[i] + a * v[i] + b * x[i]; });
}

template <int B>
void TwistedTridiagonalLdlt::SolveInPlace(double* const (&x)[B]) const {
  Solve(x, [](int, int) {});
}

template <int B>
void TwistedTridiagonalLdlt::SolveInPlace(double* const (&x)[B], const Update (&update)[B]) const {
  // u_next_i = u_i + a v_i + b x_i for each right-hand side.
  Solve(x, [&](int r, int i) {
    const Update& w = update[r];
    w.u_next[i] = w.u[i] + w.a * w.v[i] + w.b * x[r][i];
  });
}

template void TwistedTridiagonalLdlt::SolveInPlace<2>(double* const (&x)[2]) const;
template void TwistedTridiagonalLdlt::SolveInPlace<3>(double* const (&x)[3]) const;
template void TwistedTridiagonalLdlt::SolveInPlace<2>(double* const (&x)[2],
                                                      const Update (&update)[2]) const;
template void TwistedTridiagonalLdlt::SolveInPlace<3>(double* const (&x)[3],
                                                      const Update (&update)[3]) const;

}  // namespace mcrewave
