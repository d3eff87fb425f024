#include "mcrewave/data/matrix_market.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace mcrewave {
namespace {

SparseMatrix Parse(const std::string& text, const MatrixMarketReadOptions& options = {}) {
  std::istringstream stream(text);
  return ParseMatrixMarketMatrix(stream, "k.mtx", options);
}

Vector ParseVector(const std::string& text) {
  std::istringstream stream(text);
  return ParseMatrixMarketVector(stream, "f.mtx");
}

// The message of the InputError that parsing `text` throws ("" if none).
std::string MatrixError(const std::string& text, const MatrixMarketReadOptions& options = {}) {
  try {
    Parse(text, options);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

std::string VectorError(const std::string& text) {
  try {
    ParseVector(text);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(MatrixMarketTest, ReadsAGeneralCoordinateFileWithCommentsAndBlankLines) {
  const SparseMatrix a = Parse(
      "%%MatrixMarket matrix coordinate real general\r\n"
      "% written by hand\n"
      "\n"
      "2 3 3\n"
      "1 1 1.5\n"
      "%  a comment between entries\n"
      "2 3 -2e-3\n"
      "   \t\n"
      "1 2 0\n");
  ASSERT_EQ(a.rows(), 2);
  ASSERT_EQ(a.cols(), 3);
  EXPECT_EQ(a.coeff(0, 0), 1.5);
  EXPECT_EQ(a.coeff(1, 2), -2e-3);
  EXPECT_EQ(a.nonZeros(), 3);  // the explicit zero is kept
}

TEST(MatrixMarketTest, ExpandsSymmetricStorageFromEitherTriangle) {
  const SparseMatrix lower = Parse(
      "%%MatrixMarket matrix coordinate real symmetric\n3 3 4\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n");
  const SparseMatrix upper = Parse(
      "%%MATRIXMARKET Matrix Coordinate Real Symmetric\n3 3 4\n1 1 2\n1 2 -1\n2 2 2\n2 3 -1\n");
  EXPECT_EQ(lower.coeff(0, 1), -1.0);
  EXPECT_EQ(lower.coeff(1, 0), -1.0);
  EXPECT_EQ(lower.coeff(2, 1), -1.0);
  EXPECT_EQ(lower.coeff(1, 2), -1.0);
  EXPECT_EQ(lower.coeff(2, 2), 0.0);
  EXPECT_EQ(lower.nonZeros(), 6);
  EXPECT_EQ((Matrix(lower) - Matrix(upper)).norm(), 0.0);
}

TEST(MatrixMarketTest, ReadsPatternAndIntegerFields) {
  const SparseMatrix pattern =
      Parse("%%MatrixMarket matrix coordinate pattern general\n2 2 2\n1 2\n2 1\n");
  EXPECT_EQ(pattern.coeff(0, 1), 1.0);
  EXPECT_EQ(pattern.coeff(1, 0), 1.0);
  const SparseMatrix integer =
      Parse("%%MatrixMarket matrix coordinate integer general\n2 2 1\n2 2 -7\n");
  EXPECT_EQ(integer.coeff(1, 1), -7.0);
}

TEST(MatrixMarketTest, ReadsVectorsAsArraysOrCoordinates) {
  const Vector array = ParseVector("%%MatrixMarket matrix array real general\n3 1\n1\n-2.5\n0\n");
  EXPECT_EQ(array, Vector((Vector(3) << 1.0, -2.5, 0.0).finished()));
  const Vector row = ParseVector("%%MatrixMarket matrix array real general\n1 2\n4\n5\n");
  EXPECT_EQ(row, Vector((Vector(2) << 4.0, 5.0).finished()));
  // A point load as a sparse column and as a sparse row: absent entries are zero.
  const Vector column =
      ParseVector("%%MatrixMarket matrix coordinate real general\n4 1 1\n3 1 2.5\n");
  EXPECT_EQ(column, Vector((Vector(4) << 0.0, 0.0, 2.5, 0.0).finished()));
  const Vector sparse_row =
      ParseVector("%%MatrixMarket matrix coordinate real general\n1 4 1\n1 4 -1\n");
  EXPECT_EQ(sparse_row, Vector((Vector(4) << 0.0, 0.0, 0.0, -1.0).finished()));
}

TEST(MatrixMarketTest, AnArrayFileIsADenseMatrix) {
  const SparseMatrix a =
      Parse("%%MatrixMarket matrix array real general\n2 2\n1\n0\n3\n4\n");  // column-major
  EXPECT_EQ(a.coeff(0, 0), 1.0);
  EXPECT_EQ(a.coeff(1, 0), 0.0);
  EXPECT_EQ(a.coeff(0, 1), 3.0);
  EXPECT_EQ(a.coeff(1, 1), 4.0);
}

// A random sparse matrix with values spanning many decades, and its symmetric part.
SparseMatrix RandomSparse(int n, bool symmetric, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> index(0, n - 1);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0), exponent(-300.0, 300.0);
  std::vector<Eigen::Triplet<double>> triplets;
  for (int k = 0; k < 4 * n; ++k) {
    const int i = index(generator), j = index(generator);
    const double value = mantissa(generator) * std::pow(10.0, exponent(generator));
    triplets.emplace_back(i, j, value);
    if (symmetric && i != j) triplets.emplace_back(j, i, value);
  }
  SparseMatrix matrix(n, n);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  return matrix;
}

TEST(MatrixMarketTest, WrittenMatricesAndVectorsReadBackBitForBit) {
  for (const bool symmetric : {false, true}) {
    const SparseMatrix a = RandomSparse(50, symmetric, symmetric ? 2u : 1u);
    const std::string text = FormatMatrixMarketMatrix(
        a, symmetric ? MatrixMarketStorage::kSymmetric : MatrixMarketStorage::kGeneral,
        "two comment lines\nsecond");
    const SparseMatrix b = Parse(text);
    ASSERT_EQ(b.nonZeros(), a.nonZeros()) << symmetric;
    EXPECT_EQ((Matrix(a) - Matrix(b)).cwiseAbs().maxCoeff(), 0.0) << symmetric;
  }
  Vector v(5);
  v << 1.0 / 3.0, -0.0, 1e-300, -2.5e300, 4.9e-324;
  const std::string path = ::testing::TempDir() + "matrix_market_vector.mtx";
  WriteMatrixMarketVector(path, v, "a load vector");
  const Vector w = ReadMatrixMarketVector(path);
  ASSERT_EQ(w.size(), v.size());
  for (int i = 0; i < v.size(); ++i) EXPECT_EQ(w[i], v[i]) << i;
  const std::string matrix_path = ::testing::TempDir() + "matrix_market_matrix.mtx";
  const SparseMatrix a = RandomSparse(30, true, 3u);
  WriteMatrixMarketMatrix(matrix_path, a, MatrixMarketStorage::kSymmetric);
  EXPECT_EQ((Matrix(ReadMatrixMarketMatrix(matrix_path)) - Matrix(a)).norm(), 0.0);
  std::remove(path.c_str());
  std::remove(matrix_path.c_str());
}

struct MalformedCase {
  const char* what;
  const char* text;
  const char* expected;  // a part of the message, file and line included
};

TEST(MatrixMarketTest, MalformedFilesGiveTheFileTheLineAndWhatWasExpected) {
  const MalformedCase cases[] = {
      {"empty", "", "k.mtx: empty file"},
      {"bad banner", "%MatrixMarket matrix coordinate real general\n1 1 1\n1 1 1\n",
       "k.mtx:1: expected the banner"},
      {"banner object", "%%MatrixMarket vector coordinate real general\n", "k.mtx:1: expected"},
      {"complex", "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n",
       "k.mtx:1: field 'complex'"},
      {"skew", "%%MatrixMarket matrix coordinate real skew-symmetric\n",
       "k.mtx:1: symmetry 'skew-symmetric'"},
      {"array symmetric", "%%MatrixMarket matrix array real symmetric\n",
       "k.mtx:1: symmetry 'symmetric'"},
      {"no size line", "%%MatrixMarket matrix coordinate real general\n% only a comment\n",
       "k.mtx: ends after the banner"},
      {"short size line", "%%MatrixMarket matrix coordinate real general\n%\n3 3\n",
       "k.mtx:3: expected the size line 'rows columns entries'"},
      {"bad size", "%%MatrixMarket matrix coordinate real general\n3 x 1\n",
       "k.mtx:2: size line 'rows columns entries': 'x' is not a non-negative integer"},
      {"zero rows", "%%MatrixMarket matrix coordinate real general\n0 3 0\n",
       "k.mtx:2: size line: rows and columns must lie in [1, 1e7]"},
      {"huge", "%%MatrixMarket matrix coordinate real general\n1 3000000000 0\n",
       "k.mtx:2: size line: rows and columns must lie in [1, 1e7], got 1 x 3000000000"},
      {"symmetric not square", "%%MatrixMarket matrix coordinate real symmetric\n2 3 1\n",
       "k.mtx:2: a symmetric matrix must be square"},
      {"too many declared", "%%MatrixMarket matrix coordinate real general\n2 2 5\n",
       "k.mtx:2: size line declares 5 entries, more than the 4"},
      {"too few entries", "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1\n2 2 1\n",
       "k.mtx: ends after 2 of the 3 entries declared on line 2"},
      {"too many entries", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n\n2 2 1\n",
       "k.mtx:5: entry beyond the 1 declared on line 2"},
      {"row out of range", "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1\n",
       "k.mtx:3: row index 3 out of range: expected 1..2"},
      {"zero index", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 0 1\n",
       "k.mtx:3: column index 0 out of range: expected 1..2 (indices are 1-based)"},
      {"real index", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1.5 1 1\n",
       "k.mtx:3: expected an integer row index, got '1.5'"},
      {"missing value", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1\n",
       "k.mtx:3: expected an entry 'row column value', got '1 1'"},
      {"extra token", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1 0\n",
       "k.mtx:3: expected an entry 'row column value'"},
      {"bad value", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1,5\n",
       "k.mtx:3: expected a real value, got '1,5'"},
      {"nan", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 nan\n",
       "k.mtx:3: value 'nan' is not finite"},
      {"inf", "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 -1e400\n",
       "k.mtx:3: value '-1e400' is not finite"},
      {"integer field", "%%MatrixMarket matrix coordinate integer general\n2 2 1\n1 1 2.5\n",
       "k.mtx:3: expected an integer value (the banner says integer), got '2.5'"},
      {"duplicate", "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 2 1\n1 2 3\n",
       "k.mtx:4: duplicate entry (1, 2), already given on line 3"},
      {"mirrored duplicate",
       "%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 1\n%\n1 2 1\n",
       "k.mtx:5: duplicate entry (2, 1) or its mirror, already given on line 3"},
      {"array short", "%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n",
       "k.mtx: ends after 3 of the 4 values declared on line 2"},
      {"array long", "%%MatrixMarket matrix array real general\n1 1\n1\n2\n",
       "k.mtx:4: value beyond the 1 (1 x 1) declared on line 2"},
      {"array two per line", "%%MatrixMarket matrix array real general\n2 1\n1 2\n",
       "k.mtx:3: expected one value per line"},
  };
  for (const MalformedCase& c : cases) {
    const std::string message = MatrixError(c.text);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << c.what << ": got \"" << message << "\", expected \"" << c.expected << "\"";
  }
}

TEST(MatrixMarketTest, DuplicatesAreSummedOnRequest) {
  MatrixMarketReadOptions options;
  options.sum_duplicates = true;
  const SparseMatrix a =
      Parse("%%MatrixMarket matrix coordinate real general\n2 2 3\n1 2 1\n2 2 4\n1 2 3\n", options);
  EXPECT_EQ(a.coeff(0, 1), 4.0);
  EXPECT_EQ(a.coeff(1, 1), 4.0);
  EXPECT_EQ(a.nonZeros(), 2);
}

// Found by fuzz/matrix_market_fuzzer (its seed duplicates.mtx): two finite duplicates
// whose sum overflows gave an accepted matrix (and vector) holding inf.
TEST(MatrixMarketTest, DuplicatesWhoseSumIsNotFiniteAreRefused) {
  MatrixMarketReadOptions options;
  options.sum_duplicates = true;
  const std::string text =
      "%%MatrixMarket matrix coordinate real general\n1 3 3\n1 1 1e308\n1 2 4\n% a comment\n"
      "1 1 1e308\n";
  const std::string expected =
      "k.mtx:6: duplicate entry (1, 1): its sum with the same entry on earlier lines is not "
      "finite (expected duplicates that sum to a finite value)";
  EXPECT_EQ(MatrixError(text, options), expected);
  std::istringstream stream(text);
  try {
    ParseMatrixMarketVector(stream, "k.mtx", options);
    ADD_FAILURE() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.what(), expected);
  }
  EXPECT_NE(MatrixError("%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n2 1 -1e308\n"
                        "1 2 -1e308\n",
                        options)
                .find("k.mtx:4: duplicate entry (2, 1) or its mirror: its sum"),
            std::string::npos);
}

// A size line of 1e8 x 1e8 (then the limit) in a 68-byte file made the reader allocate
// 1.6 GB in all (785 MB resident, 1.5 s at -O2; over a minute in
// fuzz/matrix_market_fuzzer, whose time limit is 10 s). The limit is now 1e7, and the
// largest empty matrix reads (tests/allocation_test.cpp checks what it allocates).
TEST(MatrixMarketTest, TheLargestSizeLineReadsAndOneMoreIsRefused) {
  const SparseMatrix empty =
      Parse("%%MatrixMarket matrix coordinate real general\n10000000 10000000 0\n");
  EXPECT_EQ(empty.rows(), 10000000);
  EXPECT_EQ(empty.cols(), 10000000);
  EXPECT_EQ(empty.nonZeros(), 0);
  EXPECT_EQ(MatrixError("%%MatrixMarket matrix coordinate real general\n10000001 1 0\n"),
            "k.mtx:2: size line: rows and columns must lie in [1, 1e7], got 10000001 x 1");
  EXPECT_EQ(MatrixError("%%MatrixMarket matrix coordinate real general\n1 100000000 0\n"),
            "k.mtx:2: size line: rows and columns must lie in [1, 1e7], got 1 x 100000000");
}

TEST(MatrixMarketTest, AVectorFileMustHoldOneColumnOrOneRow) {
  EXPECT_NE(VectorError("%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n4\n")
                .find("f.mtx:2: expected a vector (one column or one row), the size line gives "
                      "2 x 2"),
            std::string::npos);
  EXPECT_NE(VectorError("%%MatrixMarket matrix array real general\n3 1\n1\ninf\n3\n")
                .find("f.mtx:4: value 'inf' is not finite"),
            std::string::npos);
}

TEST(MatrixMarketTest, AMissingFileIsNamed) {
  try {
    ReadMatrixMarketMatrix("/nonexistent/k.mtx");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("cannot read Matrix Market file /nonexistent/k.mtx"),
              std::string::npos);
  }
  // A directory opens, and reads as an empty file ("empty file: expected the banner").
  try {
    ReadMatrixMarketVector(::testing::TempDir());
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()),
              "cannot read Matrix Market file " + ::testing::TempDir() + ": it is a directory");
  }
}

}  // namespace
}  // namespace mcrewave
