// The bilinear form x^T A y of a sparse matrix whose entries touch few of the n dofs (a
// zone's K_z, the rows g_s^T K_z of a support's reaction), in O(nnz(A) + its active
// rows and columns) rather than the O(n) of Eigen's sparse product, which visits every
// column: the zone sums of the MCRE's gradients and maps (mcre/matrix_mcre_problem.h,
// mcre/mcre_problem.h) then cost O(n) per sample over all zones, not O(n Z).
//
// The active rows R and columns C are those holding a nonzero entry (entries stored as
// 0, as a zone's K_z assembled over the whole mesh has, are dropped; for a square A, R
// and C are both the union of the two); A_RC is kept as a
// compressed matrix of their order, and x^T A y = x_R^T (A_RC y_C) with x_R, y_C the
// gathered entries. When every row and column is active and no entry is 0, A_RC is A
// and the products and dot products are Eigen's on the full vectors: the same bits as
// x.dot(A * y).
// No call allocates but the constructor.
#pragma once

#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

class SparseBilinearForm {
 public:
  SparseBilinearForm() = default;
  // Copies the entries of a (column-major); allocates the scratch.
  explicit SparseBilinearForm(const SparseMatrix& a);

  int active_rows() const { return static_cast<int>(rows_.size()); }
  int active_columns() const { return static_cast<int>(columns_.size()); }

  // x^T A y: x has A's rows entries, y its columns'.
  double operator()(const double* x, const double* y);
  // For a square A (a zone's K_z): x^T A x, x^T A y and y^T A y from one product of x
  // and one of y.
  void Forms(const double* x, const double* y, double* xx, double* xy, double* yy);

 private:
  std::vector<int> rows_, columns_;  // the active ones, increasing
  SparseMatrix block_;               // A_RC
  Vector gathered_x_, gathered_y_, product_x_, product_y_;
};

}  // namespace mcrewave
