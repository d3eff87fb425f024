// Checks of a structure given by matrices (docs/matrix_models.md): the mass M, the
// stiffness K_z of each zone, the load vectors and the sensor rows read from
// Matrix Market files. Each check is a pure function that returns "" when the input
// is usable and otherwise one sentence saying why, naming the file(s) given as
// `name` arguments; the caller turns it into an InputError before anything runs.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

// Default relative tolerance of the symmetry check: |A_ij - A_ji| <= tol max|A|.
// Finite-element codes assemble K_ij and K_ji by the same sums, usually in the same
// order; writing them with 17 digits keeps them equal, with %g's 6 digits not.
constexpr double kSymmetryTolerance = 1e-10;

// The stored entry of largest magnitude and where it sits (0-based); magnitude 0 and
// (0, 0) when none is nonzero. The checks' worst misfit.
struct LargestEntry {
  double magnitude = 0.0;
  int row = 0, column = 0;
};
LargestEntry FindLargestEntry(const SparseMatrix& matrix);

// "" when `matrix` is square; otherwise "NAME: R x C matrix, expected a square one".
std::string CheckSquare(const SparseMatrix& matrix, const std::string& name);

// "" when |A_ij - A_ji| <= relative_tolerance * max|A| for every entry; otherwise the
// worst pair, e.g. "K1.mtx: not symmetric: entry (3, 7) = 1.5 but (7, 3) = 1.2
// (difference 2e-1 of the largest entry |A| = 3, tolerance 1e-10)". Indices 1-based
// (as in the file). Precondition: square.
std::string CheckSymmetric(const SparseMatrix& matrix, const std::string& name,
                           double relative_tolerance = kSymmetryTolerance);

// "" when the symmetric matrix is positive definite (a sparse LDL^T with every pivot
// > relative_tolerance * max|diag|); otherwise which pivot failed and at which dof
// (1-based), e.g. "M.mtx: not positive definite: pivot 0 at dof 12 (a dof without
// mass?)". Precondition: square and symmetric.
std::string CheckPositiveDefinite(const SparseMatrix& matrix, const std::string& name,
                                  double relative_tolerance = 1e-14);

// "" when `matrix` is n x n; otherwise "K2.mtx: 40 x 40, but M.mtx (reference_name)
// has 42 dofs".
std::string CheckSameSize(const SparseMatrix& matrix, const std::string& name, int dofs,
                          const std::string& reference_name);

// "" when `vector` has n entries; otherwise naming both files.
std::string CheckVectorSize(const Vector& vector, const std::string& name, int dofs,
                            const std::string& reference_name);

// A sensor's observation row: a 1 x C (or C x 1) matrix whose entries are the
// coefficients of the dofs it reads. "" when every stored entry lies on a dof of the
// model (index < dofs) and the row has exactly `dofs` columns; otherwise
// "sensor 'e_tip' (e_tip.mtx): entry at dof 812, past the last dof 800 of M.mtx" or
// the size mismatch. A row of only zeros reads nothing: refused too.
std::string CheckSensorRow(const SparseMatrix& row, const std::string& sensor,
                           const std::string& name, int dofs, const std::string& reference_name);
// The same for a row stored by rows (MatrixModelSensor::row), in O(nnz).
std::string CheckSensorRow(const SparseRow& row, const std::string& sensor, const std::string& name,
                           int dofs, const std::string& reference_name);

// A support's held dofs (docs/matrix_models.md section 11): "" when there is at least one,
// each in [0, dofs) and none twice; otherwise e.g. "support 'clamp' of model.yaml: dof 812
// out of range, expected 0 to 799 (0-based, the dofs of M.mtx)". Indices in messages
// 0-based, as the manifest gives them.
std::string CheckSupportDofs(const std::vector<int>& support_dofs, const std::string& support,
                             const std::string& manifest, int dofs,
                             const std::string& reference_name);

// A support's reaction vector g: "" when it has `dofs` entries, is nonzero on at least one
// of `support_dofs` and zero elsewhere; otherwise one sentence naming the support, the
// file (`name`) and the first offending dof (0-based).
std::string CheckSupportReaction(const Vector& reaction, const std::vector<int>& support_dofs,
                                 const std::string& support, const std::string& name, int dofs,
                                 const std::string& reference_name);
// A support's trusted-reaction virtual displacement phi (key reaction_test, file `name`):
// "" when it has `dofs` entries, all finite, equal to g (`reaction`) on the support's dofs;
// otherwise the reason.
std::string CheckSupportReactionTest(const Vector& test, const Vector& reaction,
                                     const std::vector<int>& support_dofs,
                                     const std::string& support, const std::string& name, int dofs,
                                     const std::string& reference_name);

}  // namespace mcrewave
