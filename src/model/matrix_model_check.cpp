#include "mcrewave/model/matrix_model_check.h"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mcrewave/core/format.h"

namespace mcrewave {
namespace {

std::string Short(double value) { return FormatNumber(value, kSixDigits); }

std::string Dimensions(Eigen::Index rows, Eigen::Index columns) {
  return std::to_string(rows) + " x " + std::to_string(columns);
}

}  // namespace

LargestEntry FindLargestEntry(const SparseMatrix& matrix) {
  LargestEntry largest;
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      if (std::abs(it.value()) > largest.magnitude) {
        largest.magnitude = std::abs(it.value());
        largest.row = static_cast<int>(it.row());
        largest.column = static_cast<int>(it.col());
      }
    }
  }
  return largest;
}

std::string CheckSquare(const SparseMatrix& matrix, const std::string& name) {
  if (matrix.rows() == matrix.cols()) return "";
  return name + ": " + Dimensions(matrix.rows(), matrix.cols()) + " matrix, expected a square one";
}

std::string CheckSymmetric(const SparseMatrix& matrix, const std::string& name,
                           double relative_tolerance) {
  const double largest = matrix.nonZeros() > 0 ? matrix.coeffs().cwiseAbs().maxCoeff() : 0.0;
  const SparseMatrix transpose = matrix.transpose();
  const LargestEntry difference = FindLargestEntry(matrix - transpose);
  const double worst = difference.magnitude;
  const int worst_row = difference.row, worst_column = difference.column;
  if (worst <= relative_tolerance * largest) return "";
  return name + ": not symmetric: entry (" + std::to_string(worst_row + 1) + ", " +
         std::to_string(worst_column + 1) + ") = " + Short(matrix.coeff(worst_row, worst_column)) +
         " but (" + std::to_string(worst_column + 1) + ", " + std::to_string(worst_row + 1) +
         ") = " + Short(matrix.coeff(worst_column, worst_row)) + " (difference " + Short(worst) +
         ", largest entry " + Short(largest) + ", relative tolerance " + Short(relative_tolerance) +
         ")";
}

std::string CheckPositiveDefinite(const SparseMatrix& matrix, const std::string& name,
                                  double relative_tolerance) {
  const int n = static_cast<int>(matrix.rows());
  double largest_diagonal = 0.0;
  for (int i = 0; i < n; ++i) {
    largest_diagonal = std::max(largest_diagonal, std::abs(matrix.coeff(i, i)));
  }
  if (!(largest_diagonal > 0.0)) return name + ": not positive definite: the diagonal is zero";
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> factor(matrix);
  const double floor = relative_tolerance * largest_diagonal;
  // Pivots in the factor's (permuted) order; dof = P^-1 of the pivot's index.
  if (factor.info() == Eigen::Success) {
    const Vector& pivots = factor.vectorD();
    int worst = 0;
    for (int i = 1; i < n; ++i) {
      if (pivots[i] < pivots[worst]) worst = i;
    }
    if (pivots[worst] > floor) return "";
    const int dof = factor.permutationPinv().indices()[worst];
    return name + ": not positive definite: LDL^T pivot " + Short(pivots[worst]) + " at dof " +
           std::to_string(dof + 1) + " (largest diagonal entry " + Short(largest_diagonal) +
           "; a dof without mass or stiffness, or a constraint not eliminated?)";
  }
  // The factorisation stopped at the first zero pivot (the pivots before it are set).
  const Vector& pivots = factor.vectorD();
  int zero = 0;
  while (zero + 1 < n && pivots[zero] != 0.0) ++zero;
  const int dof = factor.permutationPinv().indices()[zero];
  return name + ": not positive definite: LDL^T pivot 0 at dof " + std::to_string(dof + 1) +
         " (largest diagonal entry " + Short(largest_diagonal) +
         "; a dof without mass or stiffness, or a constraint not eliminated?)";
}

std::string CheckSameSize(const SparseMatrix& matrix, const std::string& name, int dofs,
                          const std::string& reference_name) {
  if (matrix.rows() == dofs && matrix.cols() == dofs) return "";
  return name + ": " + Dimensions(matrix.rows(), matrix.cols()) + ", but " + reference_name +
         " has " + std::to_string(dofs) + " dofs";
}

std::string CheckVectorSize(const Vector& vector, const std::string& name, int dofs,
                            const std::string& reference_name) {
  if (vector.size() == dofs) return "";
  return name + ": " + std::to_string(vector.size()) + " entries, but " + reference_name + " has " +
         std::to_string(dofs) + " dofs";
}

namespace {

template <typename Row>
std::string CheckSensorRowOf(const Row& row, const std::string& sensor, const std::string& name,
                             int dofs, const std::string& reference_name) {
  const std::string which = "sensor '" + sensor + "' (" + name + ")";
  if (row.rows() != 1 && row.cols() != 1) {
    return which + ": " + Dimensions(row.rows(), row.cols()) +
           ", expected one row (1 x dofs) or one column";
  }
  // The largest dof holding a non-zero coefficient.
  int last = -1;
  for (int j = 0; j < row.outerSize(); ++j) {
    for (typename Row::InnerIterator it(row, j); it; ++it) {
      if (it.value() != 0.0) {
        last = std::max(last, static_cast<int>(std::max(it.row(), it.col())));
      }
    }
  }
  if (last >= dofs) {
    return which + ": entry at dof " + std::to_string(last + 1) + ", past the last dof " +
           std::to_string(dofs) + " of " + reference_name;
  }
  const Eigen::Index length = std::max(row.rows(), row.cols());
  if (length != dofs) {
    return which + ": " + std::to_string(length) + " entries, but " + reference_name + " has " +
           std::to_string(dofs) + " dofs";
  }
  if (last < 0) return which + ": every coefficient is zero, the sensor reads nothing";
  return "";
}

}  // namespace

std::string CheckSensorRow(const SparseMatrix& row, const std::string& sensor,
                           const std::string& name, int dofs, const std::string& reference_name) {
  return CheckSensorRowOf(row, sensor, name, dofs, reference_name);
}

std::string CheckSensorRow(const SparseRow& row, const std::string& sensor, const std::string& name,
                           int dofs, const std::string& reference_name) {
  return CheckSensorRowOf(row, sensor, name, dofs, reference_name);
}

std::string CheckSupportDofs(const std::vector<int>& support_dofs, const std::string& support,
                             const std::string& manifest, int dofs,
                             const std::string& reference_name) {
  const std::string which = "support '" + support + "' of " + manifest;
  if (support_dofs.empty()) return which + ": expected dofs, a non-empty list of held dofs";
  for (std::size_t a = 0; a < support_dofs.size(); ++a) {
    const int dof = support_dofs[a];
    if (dof < 0 || dof >= dofs) {
      return which + ": dof " + std::to_string(dof) + " out of range, expected 0 to " +
             std::to_string(dofs - 1) + " (0-based, the dofs of " + reference_name + ")";
    }
    for (std::size_t b = 0; b < a; ++b) {
      if (support_dofs[b] == dof) {
        return which + ": dof " + std::to_string(dof) + " given twice, expected distinct dofs";
      }
    }
  }
  return "";
}

std::string CheckSupportReaction(const Vector& reaction, const std::vector<int>& support_dofs,
                                 const std::string& support, const std::string& name, int dofs,
                                 const std::string& reference_name) {
  const std::string which = "support '" + support + "' (" + name + ")";
  if (reaction.size() != dofs) {
    return which + ": " + std::to_string(reaction.size()) + " entries, but " + reference_name +
           " has " + std::to_string(dofs) + " dofs";
  }
  bool held = false;
  for (int i = 0; i < dofs; ++i) {
    if (reaction[i] == 0.0) continue;
    if (std::find(support_dofs.begin(), support_dofs.end(), i) == support_dofs.end()) {
      return which + ": entry " + Short(reaction[i]) + " at dof " + std::to_string(i) +
             ", which the support does not hold (expected nonzero entries on its dofs only)";
    }
    held = true;
  }
  if (!held) return which + ": every entry on the support's dofs is zero, expected a nonzero one";
  return "";
}

std::string CheckSupportReactionTest(const Vector& test, const Vector& reaction,
                                     const std::vector<int>& support_dofs,
                                     const std::string& support, const std::string& name, int dofs,
                                     const std::string& reference_name) {
  const std::string which = "support '" + support + "' (" + name + ")";
  if (test.size() != dofs) {
    return which + ": " + std::to_string(test.size()) + " entries, but " + reference_name +
           " has " + std::to_string(dofs) + " dofs";
  }
  for (int i = 0; i < dofs; ++i) {
    if (!std::isfinite(test[i])) {
      return which + ": entry " + Short(test[i]) + " at dof " + std::to_string(i) +
             ", expected finite entries";
    }
  }
  for (const int dof : support_dofs) {
    if (test[dof] != reaction[dof]) {
      return which + ": entry " + Short(test[dof]) + " at held dof " + std::to_string(dof) +
             ", expected the support's reaction vector g there (" + Short(reaction[dof]) + ")";
    }
  }
  return "";
}

}  // namespace mcrewave
