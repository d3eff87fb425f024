// Symmetric band matrices: storage, product and LDL^T factorisation. Every operation
// is O(n p), p the half bandwidth (p = 1 for the bar's linear elements). The band is
// kept densely, one contiguous array per diagonal:
//   lower(d, i) = A(i, i - d),  d = 0..p,  i = d..n-1  (entries i < d unused, zero).
#pragma once

#include "mcrewave/core/types.h"

namespace mcrewave {

class SymmetricBandMatrix {
 public:
  SymmetricBandMatrix() = default;
  // Copies the lower band of a symmetric sparse matrix; the half bandwidth is
  // the largest |i - j| of a stored entry. Precondition: matrix is square.
  explicit SymmetricBandMatrix(const SparseMatrix& matrix);

  int size() const { return static_cast<int>(lower_.rows()); }
  int half_bandwidth() const { return static_cast<int>(lower_.cols()) - 1; }
  double& lower(int d, int i) { return lower_(i, d); }
  double lower(int d, int i) const { return lower_(i, d); }
  // Diagonal d, contiguous: lower(d, i) at [i], i = 0..n-1 (zero for i < d).
  const double* diagonal_data(int d) const { return lower_.col(d).data(); }

  // this = a * x + b * y, entry-wise on the bands (same size and bandwidth assumed
  // only up to the larger bandwidth of the two).
  static SymmetricBandMatrix LinearCombination(double a, const SymmetricBandMatrix& x, double b,
                                               const SymmetricBandMatrix& y);

  // y = A x. No allocation; y must not alias x.
  void Multiply(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const;
  // y += alpha A x. No allocation; y must not alias x.
  void MultiplyAdd(double alpha, const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const;
  // x^T A y over size() contiguous doubles each. No allocation.
  double BilinearForm(const double* x, const double* y) const;
  double BilinearForm(const Eigen::Ref<const Vector>& x, const Eigen::Ref<const Vector>& y) const {
    return BilinearForm(x.data(), y.data());
  }
  // y = A x + beta B z + gamma f in one pass (a time step's right-hand side). A and B
  // of the same size. No allocation; y must not alias x, z or f.
  static void MultiplyPairAdd(const SymmetricBandMatrix& a, const Eigen::Ref<const Vector>& x,
                              double beta, const SymmetricBandMatrix& b,
                              const Eigen::Ref<const Vector>& z, double gamma,
                              const Eigen::Ref<const Vector>& f, Eigen::Ref<Vector> y);

 private:
  Matrix lower_;  // n x (p + 1), column d = diagonal d
};

// LDL^T factorisation of a symmetric positive definite band matrix, without
// pivoting (the iteration matrices here are SPD). The factors keep the band.
class BandLdlt {
 public:
  // Factorises. Returns false when a pivot is not positive (the matrix is not SPD);
  // the factorisation is then unusable.
  bool Compute(const SymmetricBandMatrix& matrix);
  bool ok() const { return ok_; }
  int size() const { return static_cast<int>(diagonal_.size()); }
  // Solves A x = b in place (x holds b on entry). No allocation.
  void SolveInPlace(Eigen::Ref<Vector> x) const;

 private:
  SymmetricBandMatrix unit_lower_;  // L, unit diagonal not stored (lower(0, .) unused)
  Vector diagonal_;                 // D
  Vector inverse_diagonal_;         // D^-1, so that a solve has no division
  bool ok_ = false;
};

// Twisted ("burn at both ends") factorisation of a symmetric positive definite
// tridiagonal matrix A (diagonal a_i, sub-diagonal s_i = A(i, i-1)): rows above the
// middle row k = (n - 1) / 2 are eliminated downward (LDL^T), rows below it upward
// (UDU^T), and the two meet at row k:
//
//   top     d_0 = a_0,
//           l_i = s_i / d_{i-1},          d_i = a_i - l_i s_i,          i = 1..k-1;
//   bottom  e_{n-1} = a_{n-1},
//           m_i = s_{i+1} / e_{i+1},      e_i = a_i - m_i s_{i+1},      i = n-2..k+1;
//   middle  l_k = s_k / d_{k-1},  m_k = s_{k+1} / e_{k+1},
//           g_k = a_k - l_k s_k - m_k s_{k+1}.
//
// A solve runs the two eliminations, then the two back-substitutions, side by side: two
// independent recurrences of about n/2 steps instead of the Thomas algorithm's one of n,
// so the latency of the dependency chain is halved. The solution differs from BandLdlt's
// by round-off only. The pivots are Schur complements of A, positive when A is SPD.
class TwistedTridiagonalLdlt {
 public:
  // Factorises. Precondition: matrix.half_bandwidth() <= 1. Returns false when a
  // pivot is not positive (the matrix is not SPD); the factorisation is then
  // unusable.
  bool Compute(const SymmetricBandMatrix& matrix);
  bool ok() const { return ok_; }
  int size() const { return static_cast<int>(inverse_pivot_.size()); }
  // Solves A x = b in place (x holds b on entry). No allocation.
  void SolveInPlace(Eigen::Ref<Vector> x) const { SolveInPlace(x.data()); }
  // The same on size() contiguous doubles.
  void SolveInPlace(double* x) const;
  // B right-hand sides at once (size() contiguous doubles each, distinct arrays),
  // their recurrences interleaved: the same results as B solves, in about the
  // latency of one. Instantiated for B = 2 and 3.
  template <int B>
  void SolveInPlace(double* const (&x)[B]) const;

  // u_next = u + a v + b x, entry by entry, the theta step's displacement update
  // (theta_integrator.h) from the solution x of its iteration matrix.
  struct Update {
    const double* u;
    const double* v;
    double a, b;
    double* u_next;
  };
  // SolveInPlace, then the update of each solution, computed as each x_i is final
  // inside the back-substitutions: their dependency chains leave the arithmetic units
  // idle, so the update costs almost nothing there. The same bits as SolveInPlace
  // followed by the update's own loop. update's arrays distinct from every x; the
  // batched form instantiated for B = 2 and 3.
  void SolveInPlace(double* x, const Update& update) const;
  template <int B>
  void SolveInPlace(double* const (&x)[B], const Update (&update)[B]) const;

 private:
  // The solves, with on_solved(b, i) called once x_b[i] is final.
  template <typename OnSolved>
  void Solve(double* x, OnSolved&& on_solved) const;
  template <int B, typename OnSolved>
  void Solve(double* const (&x)[B], OnSolved&& on_solved) const;

  int middle_ = 0;        // k
  Vector top_;            // l_i at i = 1..k (entry 0 unused)
  Vector bottom_;         // m_i at i = k..n-2 (entry n-1 unused)
  Vector inverse_pivot_;  // 1/d_i (i < k), 1/g_k, 1/e_i (i > k)
  bool ok_ = false;
};

}  // namespace mcrewave
