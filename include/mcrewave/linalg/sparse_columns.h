// The columns of a sparse n x C matrix A (the load vectors G of a structure, or the
// transposed observation rows H^T) for the few-entry products of the MCRE sweeps:
//
//   TransposeMultiply:  y = A^T x   (C entries: a load channel's G^T W, a sensor's H U),
//   Scatter:            A c as the theta integrator's point loads, one per distinct row
//                       of A (the step then adds h (A c)_i at those rows only).
//
// Both sum in the order Eigen's products with a column-major A do: y_c by increasing
// row within column c, (A c)_i by increasing column within row i, each sum starting
// from 0. So `A.transpose() * x` and `A * c` (scattered into a zeroed vector) give the
// same bits, and a step with the point loads the bits of the step with the dense
// force A c on the sparse and general band paths (docs/matrix_models.md section 5).
// The work is O(nnz(A)) per product, not O(n). Neither call allocates.
#pragma once

#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/linalg/theta_integrator.h"

namespace mcrewave {

class SparseColumns {
 public:
  SparseColumns() = default;
  // Copies the entries of a (column-major, compressed or not); allocates.
  explicit SparseColumns(const SparseMatrix& a);

  int rows() const { return rows_; }
  int cols() const { return static_cast<int>(column_start_.size()) - 1; }

  // y = A^T x: x has rows() entries, y cols().
  void TransposeMultiply(const double* x, double* y) const;
  // The point loads A c (c has cols() entries), valid until the next call. Every
  // distinct row of A is one load, zero when its sum is.
  const PointLoads* Scatter(const double* c);
  // The same into the caller's arrays: values receives num_point_loads() sums, and
  // *loads points at them (valid while values lives).
  void Scatter(const double* c, double* values, PointLoads* loads) const;
  // The loads of Scatter: the distinct rows of A with entries.
  int num_point_loads() const { return static_cast<int>(row_node_.size()); }

 private:
  int rows_ = 0;
  // A by columns: the entries of column c are [column_start_[c], column_start_[c + 1]).
  std::vector<int> column_start_{0}, entry_row_;
  std::vector<double> entry_value_;
  // A by rows, only the rows with entries: row_node_[r] and its entries
  // [row_start_[r], row_start_[r + 1]) of (column, value), by increasing column.
  std::vector<int> row_node_, row_start_{0}, row_entry_column_;
  std::vector<double> row_entry_value_, row_sum_;
  PointLoads loads_;
};

// Inline: the sweeps call these at every step with a few entries each.
inline void SparseColumns::TransposeMultiply(const double* x, double* y) const {
  const int num_columns = cols();
  for (int c = 0; c < num_columns; ++c) {
    // y_c = sum_i A_ic x_i, by increasing i.
    double sum = 0.0;
    for (int q = column_start_[c]; q < column_start_[c + 1]; ++q) {
      sum += entry_value_[q] * x[entry_row_[q]];
    }
    y[c] = sum;
  }
}

inline void SparseColumns::Scatter(const double* c, double* values, PointLoads* loads) const {
  const int num_rows = num_point_loads();
  for (int r = 0; r < num_rows; ++r) {
    // (A c)_i = sum_c A_ic c_c, by increasing c.
    double sum = 0.0;
    for (int q = row_start_[r]; q < row_start_[r + 1]; ++q) {
      sum += row_entry_value_[q] * c[row_entry_column_[q]];
    }
    values[r] = sum;
  }
  loads->count = num_rows;
  loads->nodes = row_node_.data();
  loads->values = values;
}

}  // namespace mcrewave
