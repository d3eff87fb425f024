// Symmetric band matrices: storage, product and LDL^T factorisation.
//
// The FE matrices of the bar are tridiagonal (linear elements), so every
// operation of a time step is O(n p) with p the half bandwidth. Eigen's general
// sparse classes pay an index indirection per entry; these classes keep the band
// densely, as LAPACK's packed band storage does:
//   lower(d, i) = A(i, i - d),  d = 0..p,  i = d..n-1.
#pragma once

#include "mcrewave/types.h"

namespace mcrewave {

class SymmetricBandMatrix {
 public:
  SymmetricBandMatrix() = default;
  // Copies the lower band of a symmetric sparse matrix; the half bandwidth is
  // the largest |i - j| of a stored entry. Precondition: matrix is square.
  explicit SymmetricBandMatrix(const SparseMatrix& matrix);

  int size() const { return static_cast<int>(lower_.cols()); }
  int half_bandwidth() const { return static_cast<int>(lower_.rows()) - 1; }
  double& lower(int d, int i) { return lower_(d, i); }
  double lower(int d, int i) const { return lower_(d, i); }
  // The band storage, column-major (p + 1) x n: lower(d, i) at [i (p + 1) + d].
  const double* lower_data() const { return lower_.data(); }

  // this = a * x + b * y, entry-wise on the bands (same size and bandwidth assumed
  // only up to the larger bandwidth of the two).
  static SymmetricBandMatrix LinearCombination(double a, const SymmetricBandMatrix& x, double b,
                                               const SymmetricBandMatrix& y);

  // y = A x. No allocation; y must not alias x.
  void Multiply(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const;
  // y += alpha A x. No allocation; y must not alias x.
  void MultiplyAdd(double alpha, const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const;
  // y = A x + beta B z + gamma f in one pass (a time step's right-hand side). A and B
  // of the same size. No allocation; y must not alias x, z or f.
  static void MultiplyPairAdd(const SymmetricBandMatrix& a, const Eigen::Ref<const Vector>& x,
                              double beta, const SymmetricBandMatrix& b,
                              const Eigen::Ref<const Vector>& z, double gamma,
                              const Eigen::Ref<const Vector>& f, Eigen::Ref<Vector> y);

 private:
  Matrix lower_;  // (p + 1) x n
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

}  // namespace mcrewave
