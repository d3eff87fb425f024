// Matrix Market files: the exchange format of sparse matrices and vectors that scipy
// (scipy.io.mmwrite), MATLAB (mmwrite.m), PETSc, FEniCS, Code_Aster and most
// finite-element codes write (https://math.nist.gov/MatrixMarket/formats.html).
//
// What is read:
//   %%MatrixMarket matrix coordinate real|integer|pattern general|symmetric
//       a sparse matrix: the size line "rows columns entries", then one line
//       "i j [value]" per entry, indices 1-based; pattern entries are 1.
//       Symmetric storage lists one triangle; each off-diagonal entry (i, j) also
//       stands for (j, i). The standard stores the lower triangle; an upper
//       triangle is accepted too (some writers use it), but an entry given in both
//       triangles is a duplicate.
//   %%MatrixMarket matrix array real|integer general
//       a dense matrix, the size line "rows columns", then rows x columns values in
//       column-major order, one per line: the form of a dense vector (columns = 1).
// The banner is matched without regard to case (as the standard allows); comment
// lines start with '%' and may appear anywhere after the banner; blank lines are
// skipped. complex, hermitian and skew-symmetric files are refused.
//
// Duplicate entries (the same (i, j) twice, counting mirrored symmetric ones) are
// refused by default, naming both lines: an assembled matrix has none, and a
// duplicate usually means a file written twice or both triangles of a symmetric
// matrix. MatrixMarketReadOptions::sum_duplicates sums them instead (the convention
// of scipy's coo_matrix.tocsr, for unassembled element contributions); a sum that
// overflows to infinity is refused like a value that is not finite.
//
// Rows and columns are limited to 1e7 (ten times the largest benchmarked model; a bound
// on what a mistyped size line makes the reader allocate: a matrix's column starts or a
// vector, 80 MB at most, the rest grows with the entries the file holds). Every error is
// an InputError "FILE:LINE: what was found, what was expected" (no line for a file that
// cannot be opened or ends early: "FILE: ...").
#pragma once

#include <istream>
#include <string>

#include "mcrewave/core/types.h"

namespace mcrewave {

struct MatrixMarketReadOptions {
  bool sum_duplicates = false;  // false: a duplicate entry is an error (see above)
};

// Sparse matrix of a coordinate file (symmetric storage expanded to both triangles),
// compressed, explicit zeros of the file kept. An array file is read as a dense
// matrix and stored sparse (its zeros dropped).
SparseMatrix ReadMatrixMarketMatrix(const std::string& path,
                                    const MatrixMarketReadOptions& options = {});
// The same from a stream; `name` stands for the file name in messages.
SparseMatrix ParseMatrixMarketMatrix(std::istream& text, const std::string& name,
                                     const MatrixMarketReadOptions& options = {});

// A vector: an array file of one column (or one row), or a coordinate file of one
// column (or one row; absent entries are zero), general storage.
Vector ReadMatrixMarketVector(const std::string& path, const MatrixMarketReadOptions& options = {});
Vector ParseMatrixMarketVector(std::istream& text, const std::string& name,
                               const MatrixMarketReadOptions& options = {});

// The text of a coordinate real file of `matrix` (its stored entries, explicit zeros
// included, column by column), every value with 17 significant digits, so that it
// reads back bit for bit. `comment` (may hold several lines, may be empty) goes on
// '%' lines after the banner.
std::string FormatMatrixMarketMatrix(const SparseMatrix& matrix,
                                     MatrixMarketStorage storage = MatrixMarketStorage::kGeneral,
                                     const std::string& comment = "");
// The text of an array real general file of one column.
std::string FormatMatrixMarketVector(const Vector& vector, const std::string& comment = "");

// Writes the same atomically (core/file_util.h: a reader never sees half a file; an
// earlier file at path is left intact on failure). Throws std::runtime_error naming
// the path when it cannot be written.
void WriteMatrixMarketMatrix(const std::string& path, const SparseMatrix& matrix,
                             MatrixMarketStorage storage = MatrixMarketStorage::kGeneral,
                             const std::string& comment = "");
void WriteMatrixMarketVector(const std::string& path, const Vector& vector,
                             const std::string& comment = "");

}  // namespace mcrewave
