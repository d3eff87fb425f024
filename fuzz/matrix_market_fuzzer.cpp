// libFuzzer target of the Matrix Market reader (ParseMatrixMarketMatrix and
// ParseMatrixMarketVector, the parsers behind ReadMatrixMarketMatrix/Vector).
//
// The input is the file's text; each input is read four times: as a matrix and as a
// vector, with duplicates refused and with duplicates summed. InputError is the
// expected answer to bad input; anything else escaping (another exception, a crash,
// a sanitizer report, a hang) is a defect. An accepted file must give finite values
// within the dimensions the reader allows (1 to 1e7 rows and columns).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "mcrewave/core/types.h"
#include "mcrewave/data/matrix_market.h"

namespace {

constexpr long kMaxDimension = 10000000L;

bool Finite(const mcrewave::SparseMatrix& matrix) {
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (mcrewave::SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      if (!std::isfinite(it.value())) return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (const bool sum_duplicates : {false, true}) {
    mcrewave::MatrixMarketReadOptions options;
    options.sum_duplicates = sum_duplicates;
    try {
      std::istringstream stream(text);
      const mcrewave::SparseMatrix matrix =
          mcrewave::ParseMatrixMarketMatrix(stream, "fuzz.mtx", options);
      const bool usable = matrix.rows() >= 1 && matrix.rows() <= kMaxDimension &&
                          matrix.cols() >= 1 && matrix.cols() <= kMaxDimension &&
                          matrix.isCompressed() && Finite(matrix);
      if (!usable) __builtin_trap();
    } catch (const mcrewave::InputError&) {
    }
    try {
      std::istringstream stream(text);
      const mcrewave::Vector vector =
          mcrewave::ParseMatrixMarketVector(stream, "fuzz.mtx", options);
      const bool usable =
          vector.size() >= 1 && vector.size() <= kMaxDimension && vector.allFinite();
      if (!usable) __builtin_trap();
    } catch (const mcrewave::InputError&) {
    }
  }
  return 0;
}
