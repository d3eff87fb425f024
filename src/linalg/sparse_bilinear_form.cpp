#include "mcrewave/linalg/sparse_bilinear_form.h"

#include <cassert>

namespace mcrewave {

SparseBilinearForm::SparseBilinearForm(const SparseMatrix& a)
    : rows_(static_cast<int>(a.rows())), columns_(static_cast<int>(a.cols())) {
  std::vector<char> active_row(static_cast<std::size_t>(a.rows()), 0);
  std::vector<char> active_column(static_cast<std::size_t>(a.cols()), 0);
  for (int column = 0; column < a.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(a, column); entry; ++entry) {
      if (entry.value() == 0.0) continue;
      entry_row_.push_back(static_cast<int>(entry.row()));
      entry_column_.push_back(column);
      entry_value_.push_back(entry.value());
      active_row[static_cast<std::size_t>(entry.row())] = 1;
      active_column[static_cast<std::size_t>(column)] = 1;
    }
  }
  int rows = 0, columns = 0;
  for (const char active : active_row) rows += active;
  for (const char active : active_column) columns += active;
  whole_ = rows == a.rows() && columns == a.cols() &&
           static_cast<Eigen::Index>(entry_value_.size()) == a.nonZeros();
  if (whole_) {
    // Eigen's product and dot product on the full vectors.
    whole_matrix_ = a;
    whole_matrix_.makeCompressed();
    product_y_ = Vector::Zero(a.rows());
    entry_row_.clear();
    entry_column_.clear();
    entry_value_.clear();
  }
}

double SparseBilinearForm::operator()(const double* x, const double* y) {
  if (whole_) {
    product_y_.noalias() = whole_matrix_ * Eigen::Map<const Vector>(y, columns_);
    return Eigen::Map<const Vector>(x, rows_).dot(product_y_);
  }
  // sum over the nonzero entries a_rc x_r y_c, column by column.
  double sum = 0.0;
  for (std::size_t q = 0; q < entry_value_.size(); ++q) {
    sum += entry_value_[q] * x[entry_row_[q]] * y[entry_column_[q]];
  }
  return sum;
}

void SparseBilinearForm::Forms(const double* x, const double* y, double* xx, double* xy,
                               double* yy) {
  assert(rows_ == columns_);
  // sum over the nonzero entries a_rc x_r x_c, a_rc x_r y_c and a_rc y_r y_c, column
  // by column, in one pass over A: whole() reads its compressed columns, in place of
  // two products and three dot products over the full vectors.
  double sum_xx = 0.0, sum_xy = 0.0, sum_yy = 0.0;
  auto add = [&](double value, int row, int column) {
    const double x_row = x[row], y_column = y[column];
    sum_xx += value * x_row * x[column];
    sum_xy += value * x_row * y_column;
    sum_yy += value * y[row] * y_column;
  };
  if (whole_) {
    const int* starts = whole_matrix_.outerIndexPtr();
    const int* rows = whole_matrix_.innerIndexPtr();
    const double* values = whole_matrix_.valuePtr();
    for (int column = 0; column < columns_; ++column) {
      for (int q = starts[column]; q < starts[column + 1]; ++q) add(values[q], rows[q], column);
    }
  } else {
    for (std::size_t q = 0; q < entry_value_.size(); ++q) {
      add(entry_value_[q], entry_row_[q], entry_column_[q]);
    }
  }
  *xx = sum_xx;
  *xy = sum_xy;
  *yy = sum_yy;
}

}  // namespace mcrewave
