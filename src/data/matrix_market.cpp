#include "mcrewave/data/matrix_market.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"

namespace mcrewave {
namespace {

// The most values or entries reserved ahead from a size line (a few hundred kB).
constexpr long long kReserveLimit = 1LL << 14;

enum class Format { kCoordinate, kArray };
enum class Field { kReal, kInteger, kPattern };

struct Entry {
  int row = 0, column = 0;  // 0-based
  double value = 0.0;
  long line = 0;  // where the file gives it (for messages)
};

// The content of a file, before it becomes a matrix or a vector.
struct ParsedFile {
  Format format = Format::kCoordinate;
  bool symmetric = false;
  long rows = 0, columns = 0;
  std::vector<Entry> entries;  // coordinate: as given (symmetric: one triangle)
  std::vector<double> dense;   // array: column-major
  long size_line = 0;          // line of the size line
};

// Lines of a stream with their numbers; skips comment and blank lines after the banner.
class LineReader {
 public:
  LineReader(std::istream& text, const std::string& name) : text_(text), name_(name) {}

  // The next line (banner included when first), false at the end of the stream.
  bool NextRaw(std::string* line) {
    if (!std::getline(text_, *line)) return false;
    ++line_number_;
    if (!line->empty() && line->back() == '\r') line->pop_back();  // Windows line ends
    return true;
  }
  // The next line that is neither a comment nor blank.
  bool NextData(std::string* line) {
    while (NextRaw(line)) {
      const std::size_t first = line->find_first_not_of(" \t");
      if (first == std::string::npos) continue;  // blank
      if ((*line)[first] == '%') continue;       // comment
      return true;
    }
    return false;
  }
  long line_number() const { return line_number_; }
  [[noreturn]] void Fail(const std::string& what) const { FailAt(line_number_, what); }
  [[noreturn]] void FailAt(long line, const std::string& what) const {
    throw InputError(name_ + ":" + std::to_string(line) + ": " + what);
  }
  [[noreturn]] void FailAtEnd(const std::string& what) const {
    throw InputError(name_ + ": " + what);
  }

 private:
  std::istream& text_;
  const std::string& name_;
  long line_number_ = 0;
};

// Splits a line at spaces and tabs into at most `max_tokens` tokens (pointers into the
// line, each ended by a space, a tab or the line's end); returns the number found, or
// max_tokens + 1 when there are more.
int Tokenize(const std::string& line, int max_tokens, const char** begin, const char** end) {
  const char* p = line.c_str();
  int count = 0;
  while (true) {
    while (*p == ' ' || *p == '\t') ++p;
    if (*p == '\0') return count;
    if (count == max_tokens) return max_tokens + 1;
    begin[count] = p;
    while (*p != '\0' && *p != ' ' && *p != '\t') ++p;
    end[count] = p;
    ++count;
  }
}

std::string Quote(const char* begin, const char* end) {
  return "'" + std::string(begin, end) + "'";
}

// A whole token as a decimal integer.
bool ParseInteger(const char* begin, const char* end, long long* value) {
  errno = 0;
  char* stop = nullptr;
  *value = std::strtoll(begin, &stop, 10);
  return stop == end && stop != begin && errno == 0;
}

// A whole token as a finite or non-finite double (the caller checks finiteness).
bool ParseReal(const char* begin, const char* end, double* value) {
  char* stop = nullptr;
  *value = std::strtod(begin, &stop);
  return stop == end && stop != begin;
}

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// Value token of an entry (real or integer field), checked finite.
double ParseValue(const LineReader& reader, Field field, const char* begin, const char* end) {
  double value = 0.0;
  if (field == Field::kInteger) {
    long long integer = 0;
    if (!ParseInteger(begin, end, &integer)) {
      reader.Fail("expected an integer value (the banner says integer), got " + Quote(begin, end));
    }
    value = static_cast<double>(integer);
  } else if (!ParseReal(begin, end, &value)) {
    reader.Fail("expected a real value, got " + Quote(begin, end));
  }
  if (!std::isfinite(value)) reader.Fail("value " + Quote(begin, end) + " is not finite");
  return value;
}

// Reads the banner '%%MatrixMarket matrix format field symmetry' (the first line)
// into file->format and file->symmetric; returns its field. Fails on a banner of
// another form, or a format, field or symmetry the reader does not take.
Field ParseBanner(LineReader& reader, ParsedFile* file) {
  std::string line;
  if (!reader.NextRaw(&line)) {
    reader.FailAtEnd("empty file: expected the banner '%%MatrixMarket matrix ...'");
  }
  // Banner: %%MatrixMarket matrix format field symmetry.
  const char* begin[5];
  const char* end[5];
  const int banner_tokens = Tokenize(line, 5, begin, end);
  const char* expected_banner =
      "expected the banner '%%MatrixMarket matrix coordinate real|integer|pattern "
      "general|symmetric' or '%%MatrixMarket matrix array real|integer general'";
  if (banner_tokens != 5 || Lower(std::string(begin[0], end[0])) != "%%matrixmarket" ||
      Lower(std::string(begin[1], end[1])) != "matrix") {
    reader.Fail(expected_banner + std::string(", got '") + line + "'");
  }
  const std::string format = Lower(std::string(begin[2], end[2]));
  const std::string field_name = Lower(std::string(begin[3], end[3]));
  const std::string symmetry = Lower(std::string(begin[4], end[4]));
  if (format == "coordinate") {
    file->format = Format::kCoordinate;
  } else if (format == "array") {
    file->format = Format::kArray;
  } else {
    reader.Fail("format " + Quote(begin[2], end[2]) + ": expected coordinate or array");
  }
  Field field = Field::kReal;
  if (field_name == "real" || field_name == "double") {
    field = Field::kReal;
  } else if (field_name == "integer") {
    field = Field::kInteger;
  } else if (field_name == "pattern" && file->format == Format::kCoordinate) {
    field = Field::kPattern;
  } else {
    reader.Fail("field " + Quote(begin[3], end[3]) + ": expected real, integer" +
                (file->format == Format::kCoordinate ? " or pattern" : "") +
                " (complex matrices are not structural matrices)");
  }
  if (symmetry == "general") {
    file->symmetric = false;
  } else if (symmetry == "symmetric" && file->format == Format::kCoordinate) {
    file->symmetric = true;
  } else {
    reader.Fail("symmetry " + Quote(begin[4], end[4]) + ": expected general" +
                (file->format == Format::kCoordinate ? " or symmetric" : " (array files)"));
  }
  return field;
}

// Reads the size line after the banner ('rows columns entries', coordinate, or
// 'rows columns', array) into file->size_line, rows and columns; returns the
// entries it declares (0 for an array). Fails on a malformed line, a dimension
// outside [1, 1e7] or a symmetric matrix that is not square.
long long ParseSizeLine(LineReader& reader, ParsedFile* file) {
  std::string line;
  if (!reader.NextData(&line)) {
    reader.FailAtEnd("ends after the banner: expected the size line");
  }
  file->size_line = reader.line_number();
  const int size_count = file->format == Format::kCoordinate ? 3 : 2;
  const char* size_form =
      file->format == Format::kCoordinate ? "'rows columns entries'" : "'rows columns'";
  const char* begin[3] = {};
  const char* end[3] = {};
  long long sizes[3] = {0, 0, 0};
  if (Tokenize(line, size_count, begin, end) != size_count) {
    reader.Fail(std::string("expected the size line ") + size_form + " (" +
                std::to_string(size_count) + " integers), got '" + line + "'");
  }
  for (int i = 0; i < size_count; ++i) {
    if (!ParseInteger(begin[i], end[i], &sizes[i]) || sizes[i] < 0) {
      reader.Fail(std::string("size line ") + size_form + ": " + Quote(begin[i], end[i]) +
                  " is not a non-negative integer");
    }
  }
  // At most 1e7 rows and columns: ten times the largest model of the benchmarks (1e6
  // dofs, docs/matrix_models.md), and a bound on what a mistyped size line makes the
  // reader allocate before the entries: a matrix's column starts (4 bytes a column) or
  // a vector (8 bytes an entry), 80 MB at most.
  constexpr long long kMaxDimension = 10000000LL;
  if (sizes[0] < 1 || sizes[1] < 1 || sizes[0] > kMaxDimension || sizes[1] > kMaxDimension) {
    reader.Fail("size line: rows and columns must lie in [1, 1e7], got " +
                std::to_string(sizes[0]) + " x " + std::to_string(sizes[1]));
  }
  file->rows = static_cast<long>(sizes[0]);
  file->columns = static_cast<long>(sizes[1]);
  if (file->symmetric && file->rows != file->columns) {
    reader.Fail("a symmetric matrix must be square, the size line gives " +
                std::to_string(file->rows) + " x " + std::to_string(file->columns));
  }
  return sizes[2];
}

// Reads the values of an array file after its size line, one a line, into
// file->dense (column-major). Fails unless there are exactly rows x columns, at
// most 5e8.
void ReadArrayValues(LineReader& reader, Field field, ParsedFile* file) {
  std::string line;
  const char* begin[1] = {};
  const char* end[1] = {};
  const long long count = static_cast<long long>(file->rows) * file->columns;
  if (count > 500000000LL) {
    reader.Fail("array of " + std::to_string(count) + " values: too large for a dense file");
  }
  file->dense.reserve(static_cast<std::size_t>(std::min<long long>(count, kReserveLimit)));
  while (reader.NextData(&line)) {
    if (static_cast<long long>(file->dense.size()) == count) {
      reader.Fail("value beyond the " + std::to_string(count) + " (" + std::to_string(file->rows) +
                  " x " + std::to_string(file->columns) + ") declared on line " +
                  std::to_string(file->size_line));
    }
    if (Tokenize(line, 1, begin, end) != 1) {
      reader.Fail("expected one value per line, got '" + line + "'");
    }
    file->dense.push_back(ParseValue(reader, field, begin[0], end[0]));
  }
  if (static_cast<long long>(file->dense.size()) != count) {
    reader.FailAtEnd("ends after " + std::to_string(file->dense.size()) + " of the " +
                     std::to_string(count) + " values declared on line " +
                     std::to_string(file->size_line));
  }
}

// Reads the entries of a coordinate file after its size line into file->entries
// (0-based; symmetric: normalised to the lower triangle). Fails unless there are
// exactly `declared`, at most what the matrix holds, each with indices in range.
void ReadCoordinateEntries(LineReader& reader, Field field, long long declared, ParsedFile* file) {
  std::string line;
  const char* begin[3] = {};
  const char* end[3] = {};
  const long long rows = file->rows, columns = file->columns;
  const long long capacity =
      file->symmetric ? rows * (rows + 1) / 2 : rows * columns;  // no overflow: < 2^62
  if (declared > capacity) {
    reader.Fail("size line declares " + std::to_string(declared) + " entries, more than the " +
                std::to_string(capacity) + " a " + std::to_string(file->rows) + " x " +
                std::to_string(file->columns) + (file->symmetric ? " symmetric" : "") +
                " matrix holds");
  }
  // Room for what the size line declares, up to kReserveLimit: beyond, the entries
  // grow with what the file holds, not with what a mistyped size line claims.
  file->entries.reserve(static_cast<std::size_t>(std::min<long long>(declared, kReserveLimit)));
  const int entry_tokens = field == Field::kPattern ? 2 : 3;
  const std::string entry_form = field == Field::kPattern ? "'row column'" : "'row column value'";
  while (reader.NextData(&line)) {
    if (static_cast<long long>(file->entries.size()) == declared) {
      reader.Fail("entry beyond the " + std::to_string(declared) + " declared on line " +
                  std::to_string(file->size_line));
    }
    if (Tokenize(line, entry_tokens, begin, end) != entry_tokens) {
      reader.Fail("expected an entry " + entry_form + ", got '" + line + "'");
    }
    long long index[2] = {0, 0};
    const long bound[2] = {file->rows, file->columns};
    const char* what[2] = {"row", "column"};
    for (int i = 0; i < 2; ++i) {
      if (!ParseInteger(begin[i], end[i], &index[i])) {
        reader.Fail(std::string("expected an integer ") + what[i] + " index, got " +
                    Quote(begin[i], end[i]));
      }
      if (index[i] < 1 || index[i] > bound[i]) {
        reader.Fail(std::string(what[i]) + " index " + std::to_string(index[i]) +
                    " out of range: expected 1.." + std::to_string(bound[i]) +
                    " (indices are 1-based)");
      }
    }
    Entry entry;
    entry.row = static_cast<int>(index[0] - 1);
    entry.column = static_cast<int>(index[1] - 1);
    entry.value = field == Field::kPattern ? 1.0 : ParseValue(reader, field, begin[2], end[2]);
    entry.line = reader.line_number();
    // Symmetric storage: one triangle, normalised to the lower one.
    if (file->symmetric && entry.row < entry.column) std::swap(entry.row, entry.column);
    file->entries.push_back(entry);
  }
  if (static_cast<long long>(file->entries.size()) != declared) {
    reader.FailAtEnd("ends after " + std::to_string(file->entries.size()) + " of the " +
                     std::to_string(declared) + " entries declared on line " +
                     std::to_string(file->size_line));
  }
}

ParsedFile ParseFile(std::istream& text, const std::string& name) {
  LineReader reader(text, name);
  ParsedFile file;
  const Field field = ParseBanner(reader, &file);
  const long long declared = ParseSizeLine(reader, &file);
  if (file.format == Format::kArray) {
    ReadArrayValues(reader, field, &file);
  } else {
    ReadCoordinateEntries(reader, field, declared, &file);
  }
  return file;
}

// Sorts the entries by (column, row) and refuses or sums duplicates.
void MergeDuplicates(const std::string& name, bool symmetric, bool sum_duplicates,
                     std::vector<Entry>* entries) {
  std::stable_sort(entries->begin(), entries->end(), [](const Entry& a, const Entry& b) {
    return a.column != b.column ? a.column < b.column : a.row < b.row;
  });
  std::size_t kept = 0;
  for (std::size_t i = 0; i < entries->size(); ++i) {
    Entry& entry = (*entries)[i];
    if (kept > 0) {
      Entry& previous = (*entries)[kept - 1];
      if (previous.row == entry.row && previous.column == entry.column) {
        if (!sum_duplicates) {
          const Entry& later = previous.line > entry.line ? previous : entry;
          const Entry& earlier = previous.line > entry.line ? entry : previous;
          throw InputError(name + ":" + std::to_string(later.line) + ": duplicate entry (" +
                           std::to_string(entry.row + 1) + ", " + std::to_string(entry.column + 1) +
                           ")" + (symmetric && entry.row != entry.column ? " or its mirror" : "") +
                           ", already given on line " + std::to_string(earlier.line) +
                           " (an assembled matrix has each entry once" +
                           (symmetric ? "; a symmetric file stores one triangle" : "") + ")");
        }
        previous.value += entry.value;
        if (!std::isfinite(previous.value)) {
          const Entry& later = previous.line > entry.line ? previous : entry;
          throw InputError(name + ":" + std::to_string(later.line) + ": duplicate entry (" +
                           std::to_string(entry.row + 1) + ", " + std::to_string(entry.column + 1) +
                           ")" + (symmetric && entry.row != entry.column ? " or its mirror" : "") +
                           ": its sum with the same entry on earlier lines is not finite "
                           "(expected duplicates that sum to a finite value)");
        }
        continue;
      }
    }
    (*entries)[kept++] = entry;
  }
  entries->resize(kept);
}

// The compressed matrix of `entries`, sorted by (column, row), each position once. Built
// directly: the only array of the matrix's size is its column starts (no triplet
// pass, whose work and temporaries grow with both dimensions).
SparseMatrix Compress(long rows, long columns, const std::vector<Entry>& entries) {
  SparseMatrix matrix(static_cast<int>(rows), static_cast<int>(columns));
  matrix.resizeNonZeros(static_cast<Eigen::Index>(entries.size()));
  int* starts = matrix.outerIndexPtr();  // columns + 1, zero
  for (const Entry& entry : entries) ++starts[entry.column + 1];
  for (long j = 0; j < columns; ++j) starts[j + 1] += starts[j];
  for (std::size_t k = 0; k < entries.size(); ++k) {
    matrix.innerIndexPtr()[k] = entries[k].row;
    matrix.valuePtr()[k] = entries[k].value;
  }
  return matrix;
}

SparseMatrix ToSparse(const std::string& name, const MatrixMarketReadOptions& options,
                      ParsedFile* file) {
  std::vector<Entry>& entries = file->entries;
  if (file->format == Format::kArray) {  // column-major: already in (column, row) order
    for (long j = 0; j < file->columns; ++j) {
      for (long i = 0; i < file->rows; ++i) {
        const double value = file->dense[static_cast<std::size_t>(j * file->rows + i)];
        if (value != 0.0) entries.push_back({static_cast<int>(i), static_cast<int>(j), value, 0});
      }
    }
    std::vector<double>().swap(file->dense);
    return Compress(file->rows, file->columns, entries);
  }
  MergeDuplicates(name, file->symmetric, options.sum_duplicates, &entries);
  if (file->symmetric) {  // the mirrored upper triangle, then (column, row) order again
    const std::size_t stored = entries.size();
    for (std::size_t k = 0; k < stored; ++k) {
      if (entries[k].row != entries[k].column) {
        entries.push_back({entries[k].column, entries[k].row, entries[k].value, entries[k].line});
      }
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return a.column != b.column ? a.column < b.column : a.row < b.row;
    });
  }
  return Compress(file->rows, file->columns, entries);
}

std::ifstream OpenForReading(const std::string& path) {
  std::error_code status_error;
  if (std::filesystem::is_directory(path, status_error)) {  // it opens, and reads as empty
    throw InputError("cannot read Matrix Market file " + path + ": it is a directory");
  }
  std::ifstream file(path);
  if (!file) {
    throw InputError("cannot read Matrix Market file " + path + ": " + std::strerror(errno));
  }
  return file;
}

std::string CommentLines(const std::string& comment) {
  if (comment.empty()) return "";
  std::string lines;
  std::size_t start = 0;
  while (start <= comment.size()) {
    const std::size_t stop = comment.find('\n', start);
    lines += "% " +
             comment.substr(start, stop == std::string::npos ? std::string::npos : stop - start) +
             "\n";
    if (stop == std::string::npos) break;
    start = stop + 1;
  }
  return lines;
}

}  // namespace

SparseMatrix ParseMatrixMarketMatrix(std::istream& text, const std::string& name,
                                     const MatrixMarketReadOptions& options) {
  ParsedFile file = ParseFile(text, name);
  return ToSparse(name, options, &file);
}

SparseMatrix ReadMatrixMarketMatrix(const std::string& path,
                                    const MatrixMarketReadOptions& options) {
  std::ifstream file = OpenForReading(path);
  return ParseMatrixMarketMatrix(file, path, options);
}

Vector ParseMatrixMarketVector(std::istream& text, const std::string& name,
                               const MatrixMarketReadOptions& options) {
  ParsedFile file = ParseFile(text, name);
  if (file.rows != 1 && file.columns != 1) {
    throw InputError(name + ":" + std::to_string(file.size_line) +
                     ": expected a vector (one column or one row), the size line gives " +
                     std::to_string(file.rows) + " x " + std::to_string(file.columns));
  }
  if (file.symmetric && file.rows > 1) {  // 1 x 1 symmetric is a vector too
    throw InputError(name + ":1: a vector file must be general, not symmetric");
  }
  const long size = std::max(file.rows, file.columns);
  if (file.format == Format::kArray) {
    return Eigen::Map<const Vector>(file.dense.data(), size);
  }
  MergeDuplicates(name, file.symmetric, options.sum_duplicates, &file.entries);
  Vector vector = Vector::Zero(size);
  for (const Entry& entry : file.entries) vector[std::max(entry.row, entry.column)] = entry.value;
  return vector;
}

Vector ReadMatrixMarketVector(const std::string& path, const MatrixMarketReadOptions& options) {
  std::ifstream file = OpenForReading(path);
  return ParseMatrixMarketVector(file, path, options);
}

std::string FormatMatrixMarketMatrix(const SparseMatrix& matrix, MatrixMarketStorage storage,
                                     const std::string& comment) {
  const bool symmetric = storage == MatrixMarketStorage::kSymmetric;
  long count = 0;
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      if (!symmetric || it.row() >= it.col()) ++count;
    }
  }
  std::string text = std::string("%%MatrixMarket matrix coordinate real ") +
                     (symmetric ? "symmetric" : "general") + "\n" + CommentLines(comment) +
                     std::to_string(matrix.rows()) + " " + std::to_string(matrix.cols()) + " " +
                     std::to_string(count) + "\n";
  text.reserve(text.size() + static_cast<std::size_t>(count) * 40);
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      if (symmetric && it.row() < it.col()) continue;
      text += std::to_string(it.row() + 1) + ' ' + std::to_string(it.col() + 1) + ' ' +
              FormatNumber(it.value(), kSeventeenDigits) + '\n';
    }
  }
  return text;
}

std::string FormatMatrixMarketVector(const Vector& vector, const std::string& comment) {
  std::string text = "%%MatrixMarket matrix array real general\n" + CommentLines(comment) +
                     std::to_string(vector.size()) + " 1\n";
  for (Eigen::Index i = 0; i < vector.size(); ++i) {
    text += FormatNumber(vector[i], kSeventeenDigits);
    text += '\n';
  }
  return text;
}

void WriteMatrixMarketMatrix(const std::string& path, const SparseMatrix& matrix,
                             MatrixMarketStorage storage, const std::string& comment) {
  WriteFileAtomically(path, FormatMatrixMarketMatrix(matrix, storage, comment));
}

void WriteMatrixMarketVector(const std::string& path, const Vector& vector,
                             const std::string& comment) {
  WriteFileAtomically(path, FormatMatrixMarketVector(vector, comment));
}

}  // namespace mcrewave
