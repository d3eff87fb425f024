#include "mcrewave/linalg/sparse_bilinear_form.h"

#include <cassert>

namespace mcrewave {

SparseBilinearForm::SparseBilinearForm(const SparseMatrix& a) {
  std::vector<int> row_index(static_cast<std::size_t>(a.rows()), -1);
  std::vector<int> column_index(static_cast<std::size_t>(a.cols()), -1);
  for (int column = 0; column < a.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(a, column); entry; ++entry) {
      if (entry.value() == 0.0) continue;
      row_index[static_cast<std::size_t>(entry.row())] = 0;
      column_index[static_cast<std::size_t>(entry.col())] = 0;
    }
  }
  if (a.rows() == a.cols()) {
    // A square A keeps one set, the rows' and columns' union, for Forms.
    for (std::size_t i = 0; i < row_index.size(); ++i) {
      if (row_index[i] == 0 || column_index[i] == 0) row_index[i] = column_index[i] = 0;
    }
  }
  for (std::size_t i = 0; i < row_index.size(); ++i) {
    if (row_index[i] == 0) {
      row_index[i] = static_cast<int>(rows_.size());
      rows_.push_back(static_cast<int>(i));
    }
  }
  for (std::size_t k = 0; k < column_index.size(); ++k) {
    if (column_index[k] == 0) {
      column_index[k] = static_cast<int>(columns_.size());
      columns_.push_back(static_cast<int>(k));
    }
  }
  // A_RC in the same column-major order, entries by increasing row within a column, as
  // A's (the products' sums in the same order).
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < a.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(a, column); entry; ++entry) {
      if (entry.value() == 0.0) continue;
      entries.emplace_back(row_index[static_cast<std::size_t>(entry.row())],
                           column_index[static_cast<std::size_t>(entry.col())], entry.value());
    }
  }
  block_.resize(active_rows(), active_columns());
  block_.setFromTriplets(entries.begin(), entries.end());
  gathered_x_ = Vector::Zero(active_rows());
  gathered_y_ = Vector::Zero(active_columns());
  product_x_ = Vector::Zero(active_rows());
  product_y_ = Vector::Zero(active_rows());
}

double SparseBilinearForm::operator()(const double* x, const double* y) {
  for (int r = 0; r < active_rows(); ++r) gathered_x_[r] = x[rows_[r]];
  for (int c = 0; c < active_columns(); ++c) gathered_y_[c] = y[columns_[c]];
  // x_R^T (A_RC y_C).
  product_y_.noalias() = block_ * gathered_y_;
  return gathered_x_.dot(product_y_);
}

void SparseBilinearForm::Forms(const double* x, const double* y, double* xx, double* xy,
                               double* yy) {
  assert(block_.rows() == block_.cols());
  for (int r = 0; r < active_rows(); ++r) {
    gathered_x_[r] = x[rows_[r]];
    gathered_y_[r] = y[rows_[r]];
  }
  product_x_.noalias() = block_ * gathered_x_;
  product_y_.noalias() = block_ * gathered_y_;
  *xx = gathered_x_.dot(product_x_);
  *xy = gathered_x_.dot(product_y_);
  *yy = gathered_y_.dot(product_y_);
}

}  // namespace mcrewave
