#include "mcrewave/linalg/sparse_columns.h"

namespace mcrewave {

SparseColumns::SparseColumns(const SparseMatrix& a) : rows_(static_cast<int>(a.rows())) {
  const int num_columns = static_cast<int>(a.cols());
  column_start_.assign(1, 0);
  std::vector<std::vector<std::pair<int, double>>> by_row(static_cast<std::size_t>(rows_));
  for (int c = 0; c < num_columns; ++c) {
    for (SparseMatrix::InnerIterator it(a, c); it; ++it) {
      const int row = static_cast<int>(it.row());
      entry_row_.push_back(row);
      entry_value_.push_back(it.value());
      by_row[static_cast<std::size_t>(row)].emplace_back(c, it.value());
    }
    column_start_.push_back(static_cast<int>(entry_row_.size()));
  }
  for (int row = 0; row < rows_; ++row) {
    const auto& entries = by_row[static_cast<std::size_t>(row)];
    if (entries.empty()) continue;
    row_node_.push_back(row);
    for (const auto& [column, value] : entries) {
      row_entry_column_.push_back(column);
      row_entry_value_.push_back(value);
    }
    row_start_.push_back(static_cast<int>(row_entry_column_.size()));
  }
  row_sum_.assign(row_node_.size(), 0.0);
}

const PointLoads* SparseColumns::Scatter(const double* c) {
  // loads_ is set here, not in the constructor, so that a copy points at its own arrays.
  Scatter(c, row_sum_.data(), &loads_);
  return &loads_;
}

}  // namespace mcrewave
