// The bilinear form x^T A y of a sparse matrix whose entries touch few of the n dofs (a
// zone's K_z, the rows g_s^T K_z of a support's reaction), in O(nnz(A)) rather than
// the O(n) of Eigen's sparse product, which visits every column: the zone sums of the
// MCRE's gradients and maps (mcre/matrix_mcre_problem.h) then cost
// O(n) per sample over all zones, not O(n Z).
//
// Entries stored as 0 (a zone's K_z assembled over the whole mesh has them) are
// dropped, and x^T A y is summed over the nonzero entries, a_rc x_r y_c, column by
// column. When every row and column holds a nonzero entry and none is stored as 0, it
// is Eigen's x.dot(A * y) on the full vectors instead: a structure of one zone keeps
// the bits of that product. No call allocates but the constructor.
#pragma once

#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

class SparseBilinearForm {
 public:
  SparseBilinearForm() = default;
  // Copies the nonzero entries of a (column-major); allocates the scratch.
  explicit SparseBilinearForm(const SparseMatrix& a);

  // Whether x^T A y is Eigen's product (every row and column active, no zero stored).
  bool whole() const { return whole_; }
  // The nonzero entries summed (0 when whole()).
  int num_entries() const { return static_cast<int>(entry_value_.size()); }

  // x^T A y: x has A's rows entries, y its columns'.
  double operator()(const double* x, const double* y);
  // For a square A (a zone's K_z): x^T A x, x^T A y and y^T A y in one pass over
  // its entries, whole() or not.
  void Forms(const double* x, const double* y, double* xx, double* xy, double* yy);

 private:
  int rows_ = 0, columns_ = 0;
  bool whole_ = false;
  // The nonzero entries, column by column (empty when whole()).
  std::vector<int> entry_row_, entry_column_;
  std::vector<double> entry_value_;
  // whole(): A and the scratch of its products.
  SparseMatrix whole_matrix_;
  Vector product_y_;
};

}  // namespace mcrewave
