#include "mcrewave/model/matrix_model_elements.h"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/matrix_model_check.h"

namespace mcrewave {
namespace {

constexpr const char* kBlanks = " \t\r\f\v";

std::string ShortNumber(double value) { return FormatNumber(value, kSixDigits); }

// A data line of an element file: its fields (trimmed) and its line number (1-based).
struct ElementLine {
  std::vector<std::string> fields;
  int line = 0;
};

std::string Trimmed(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(kBlanks);
  if (begin == std::string::npos) return "";
  return text.substr(begin, text.find_last_not_of(kBlanks) - begin + 1);
}

// The data lines of the element file at `path` (`what` says which, for messages): blank
// lines and lines starting with '#' skipped, each other line split at its commas.
std::vector<ElementLine> ReadElementLines(const std::string& path, const std::string& what) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError("cannot read element " + what + " file " + path + ": it is a directory");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read element " + what + " file " + path + ": " + std::strerror(errno));
  }
  std::vector<ElementLine> lines;
  std::string text;
  for (int line = 1; std::getline(file, text); ++line) {
    const std::string trimmed = Trimmed(text);
    if (trimmed.empty() || trimmed[0] == '#') continue;
    ElementLine entry;
    entry.line = line;
    for (std::size_t begin = 0;;) {
      const std::size_t comma = trimmed.find(',', begin);
      entry.fields.push_back(Trimmed(trimmed.substr(begin, comma - begin)));
      if (comma == std::string::npos) break;
      begin = comma + 1;
    }
    lines.push_back(std::move(entry));
  }
  if (file.bad()) throw InputError("cannot read element " + what + " file " + path);
  return lines;
}

std::string FileLine(const std::string& path, const ElementLine& line) {
  return path + ":" + std::to_string(line.line);
}

// Field `index` of `line` as a finite number; refuses anything else naming what it is.
double FiniteField(const std::string& path, const ElementLine& line, std::size_t index,
                   const std::string& what) {
  const std::string& field = line.fields[index];
  char* stop = nullptr;
  errno = 0;
  const double value = field.empty() ? 0.0 : std::strtod(field.c_str(), &stop);
  if (field.empty() || *stop != '\0' || !std::isfinite(value)) {
    throw InputError(FileLine(path, line) + ": field " + std::to_string(index + 1) + " '" + field +
                     "' of " + what + " is not a finite number");
  }
  return value;
}

// Field `index` of a dofs line as a dof in [0, dofs).
int DofField(const std::string& path, const ElementLine& line, std::size_t index, int dofs,
             const std::string& mass_file) {
  const std::string& field = line.fields[index];
  char* stop = nullptr;
  errno = 0;
  const long value = field.empty() ? -1 : std::strtol(field.c_str(), &stop, 10);
  if (field.empty() || *stop != '\0' || errno == ERANGE || value < 0 || value >= dofs) {
    throw InputError(FileLine(path, line) + ": dof '" + field + "' (field " +
                     std::to_string(index + 1) + ") is not a dof of the model, expected an " +
                     "integer from 0 to " + std::to_string(dofs - 1) + " (0-based, the dofs of " +
                     mass_file + ")");
  }
  return static_cast<int>(value);
}

// The elements of the dofs file: zone and dofs of each line.
std::vector<MatrixModelElement> ReadElementDofs(const std::string& path,
                                                const std::vector<std::string>& zone_names,
                                                int dofs, const std::string& mass_file) {
  const std::vector<ElementLine> lines = ReadElementLines(path, "dofs");
  if (lines.empty()) {
    throw InputError(path + ": no elements, expected one a line: its zone, then its dofs");
  }
  std::vector<MatrixModelElement> elements(lines.size());
  for (std::size_t e = 0; e < lines.size(); ++e) {
    const ElementLine& line = lines[e];
    if (line.fields.size() < 2) {
      throw InputError(FileLine(path, line) +
                       ": 1 field, expected the element's zone, then its dofs");
    }
    const auto zone = std::find(zone_names.begin(), zone_names.end(), line.fields[0]);
    if (zone == zone_names.end()) {
      throw InputError(FileLine(path, line) + ": zone '" + line.fields[0] +
                       "' is not a zone of the manifest, expected one of its zones' names");
    }
    MatrixModelElement& element = elements[e];
    element.zone = static_cast<int>(zone - zone_names.begin());
    std::set<int> seen;
    for (std::size_t i = 1; i < line.fields.size(); ++i) {
      element.dofs.push_back(DofField(path, line, i, dofs, mass_file));
      if (!seen.insert(element.dofs.back()).second) {
        throw InputError(FileLine(path, line) + ": dof " + std::to_string(element.dofs.back()) +
                         " given twice, expected each of the element's dofs once");
      }
    }
  }
  return elements;
}

// Refuses a file with other than one data line per element.
void CheckElementCount(const std::string& path, const std::vector<ElementLine>& lines,
                       std::size_t elements, const std::string& dofs_path) {
  if (lines.size() > elements) {
    throw InputError(FileLine(path, lines[elements]) + ": a line past the last element, expected " +
                     std::to_string(elements) + " lines, one per element of " + dofs_path);
  }
  if (lines.size() < elements) {
    throw InputError(path + ": " + std::to_string(lines.size()) + " lines, expected " +
                     std::to_string(elements) + ", one per element of " + dofs_path);
  }
}

// Reads each element's stiffness block: k^2 finite numbers, row by row, symmetric.
void ReadElementBlocks(const std::string& path, const std::string& dofs_path,
                       std::vector<MatrixModelElement>* elements) {
  const std::vector<ElementLine> lines = ReadElementLines(path, "stiffness");
  CheckElementCount(path, lines, elements->size(), dofs_path);
  for (std::size_t e = 0; e < lines.size(); ++e) {
    const ElementLine& line = lines[e];
    MatrixModelElement& element = (*elements)[e];
    const int k = static_cast<int>(element.dofs.size());
    if (line.fields.size() != static_cast<std::size_t>(k) * k) {
      throw InputError(FileLine(path, line) + ": " + std::to_string(line.fields.size()) +
                       " values, expected " + std::to_string(static_cast<std::size_t>(k) * k) +
                       ": the " + std::to_string(k) + " x " + std::to_string(k) +
                       " block, row by row, of element " + std::to_string(e + 1) + " of " +
                       dofs_path + " (" + std::to_string(k) + " dofs)");
    }
    element.stiffness.resize(k, k);
    for (int a = 0; a < k; ++a) {
      for (int b = 0; b < k; ++b) {
        element.stiffness(a, b) =
            FiniteField(path, line, static_cast<std::size_t>(a * k + b), "the element's block");
      }
    }
    const double largest = element.stiffness.cwiseAbs().maxCoeff();
    for (int a = 0; a < k; ++a) {
      for (int b = a + 1; b < k; ++b) {
        const double difference = std::abs(element.stiffness(a, b) - element.stiffness(b, a));
        if (difference > kSymmetryTolerance * largest) {
          throw InputError(FileLine(path, line) + ": the block is not symmetric: entry (" +
                           std::to_string(a + 1) + ", " + std::to_string(b + 1) +
                           ") = " + ShortNumber(element.stiffness(a, b)) + " but (" +
                           std::to_string(b + 1) + ", " + std::to_string(a + 1) +
                           ") = " + ShortNumber(element.stiffness(b, a)) +
                           ", expected a symmetric block (relative tolerance " +
                           ShortNumber(kSymmetryTolerance) + ")");
        }
      }
    }
  }
}

// Reads each element's position: 1 to 3 finite numbers, as many on every line.
void ReadElementPositions(const std::string& path, const std::string& dofs_path,
                          std::vector<MatrixModelElement>* elements) {
  const std::vector<ElementLine> lines = ReadElementLines(path, "positions");
  CheckElementCount(path, lines, elements->size(), dofs_path);
  const std::size_t dimension = lines[0].fields.size();
  for (std::size_t e = 0; e < lines.size(); ++e) {
    const ElementLine& line = lines[e];
    if (line.fields.size() != dimension || dimension > 3) {
      throw InputError(FileLine(path, line) + ": " + std::to_string(line.fields.size()) +
                       " coordinates, expected " +
                       (dimension > 3 ? std::string("1 to 3")
                                      : std::to_string(dimension) + " (as on the first line)"));
    }
    Vector& position = (*elements)[e].position;
    position.resize(static_cast<Eigen::Index>(dimension));
    for (std::size_t i = 0; i < dimension; ++i) {
      position[static_cast<Eigen::Index>(i)] =
          FiniteField(path, line, i, "the element's position [m]");
    }
  }
}

}  // namespace

std::vector<MatrixModelElement> ReadMatrixModelElements(const MatrixModelElementFiles& files,
                                                        const std::vector<std::string>& zone_names,
                                                        int dofs, const std::string& mass_file) {
  std::vector<MatrixModelElement> elements =
      ReadElementDofs(files.dofs, zone_names, dofs, mass_file);
  ReadElementBlocks(files.stiffness, files.dofs, &elements);
  if (!files.positions.empty()) ReadElementPositions(files.positions, files.dofs, &elements);
  return elements;
}

namespace {

// S_z = sum_{el in z} P_el^T K_el P_el for every zone of data (setFromTriplets sums
// repeated entries), the elements in their order.
std::vector<SparseMatrix> ElementBlockSums(const MatrixModelData& data) {
  const int n = data.dofs();
  std::vector<std::vector<Eigen::Triplet<double>>> entries(data.zones.size());
  for (const MatrixModelElement& element : data.elements) {
    const int k = static_cast<int>(element.dofs.size());
    auto& zone_entries = entries[static_cast<std::size_t>(element.zone)];
    for (int a = 0; a < k; ++a) {
      for (int b = 0; b < k; ++b) {
        zone_entries.emplace_back(element.dofs[a], element.dofs[b], element.stiffness(a, b));
      }
    }
  }
  std::vector<SparseMatrix> sums(data.zones.size(), SparseMatrix(n, n));
  for (std::size_t z = 0; z < sums.size(); ++z) {
    sums[z].setFromTriplets(entries[z].begin(), entries[z].end());
  }
  return sums;
}

}  // namespace

std::string CheckElementBlockSums(const MatrixModelData& data, const std::string& manifest_name,
                                  double relative_tolerance) {
  const std::vector<SparseMatrix> sums = ElementBlockSums(data);
  for (std::size_t z = 0; z < data.zones.size(); ++z) {
    // The blocks' sum S_z against K_z.
    const SparseMatrix& sum = sums[z];
    const SparseMatrix& stiffness = data.zones[z].stiffness;
    const double largest =
        stiffness.nonZeros() > 0 ? stiffness.coeffs().cwiseAbs().maxCoeff() : 0.0;
    const LargestEntry misfit = FindLargestEntry(sum - stiffness);
    const double worst = misfit.magnitude;
    const int row = misfit.row, column = misfit.column;
    if (worst <= relative_tolerance * largest) continue;
    return manifest_name + ": the element blocks of zone '" + data.zones[z].name +
           "' do not sum to its stiffness: entry (" + std::to_string(row + 1) + ", " +
           std::to_string(column + 1) + ") is " + ShortNumber(stiffness.coeff(row, column)) +
           " in K_z but " + ShortNumber(sum.coeff(row, column)) + " in the blocks' sum (misfit " +
           ShortNumber(worst) + ", " + ShortNumber(largest > 0.0 ? worst / largest : INFINITY) +
           " of the largest entry " + ShortNumber(largest) + ", relative tolerance " +
           ShortNumber(relative_tolerance) + ")";
  }
  return "";
}

std::vector<int> RegroupedElementZones(const MatrixModelData& data, const ZoneLayout& layout,
                                       const std::string& manifest_name,
                                       std::vector<std::string>* zone_names) {
  assert(layout.RegroupsElements());
  const std::string zoning = ZoningToString(layout.zoning);
  const auto elements = static_cast<int>(data.elements.size());
  if (elements == 0) {
    throw InputError("model.zoning '" + zoning + "' regroups the element blocks of the manifest " +
                     manifest_name +
                     ", which has none: give them (key elements, docs/matrix_models.md section "
                     "4) or leave model.zoning out to identify the manifest's zones");
  }
  std::vector<int> zones(static_cast<std::size_t>(elements), 0);
  zone_names->clear();
  if (layout.zoning == Zoning::kPerElement) {
    for (int e = 0; e < elements; ++e) {
      zones[static_cast<std::size_t>(e)] = e;
      zone_names->push_back("element" + std::to_string(e));
    }
    return zones;
  }
  const Eigen::Index dimension = data.elements[0].position.size();
  if (dimension == 0) {
    throw InputError(
        "model.zoning 'grid' places the elements by their positions, and the "
        "manifest " +
        manifest_name +
        " gives none: add elements.positions (docs/matrix_models.md section 4) or "
        "use model.zoning: per_element");
  }
  const std::vector<int>& counts = layout.zone_grid;
  if (static_cast<Eigen::Index>(counts.size()) != dimension ||
      std::any_of(counts.begin(), counts.end(),
                  [&](int count) { return count < 1 || count > elements; })) {
    throw InputError(
        "model.zone_grid must hold one positive count per coordinate of the "
        "element positions of " +
        manifest_name + " (" + std::to_string(dimension) + " coordinate" +
        (dimension == 1 ? "" : "s") + "), each at most its " + std::to_string(elements) +
        " elements, got " + std::to_string(counts.size()) + " values");
  }
  Eigen::ArrayXd low = data.elements[0].position.array(), high = low;
  for (const MatrixModelElement& element : data.elements) {
    low = low.min(element.position.array());
    high = high.max(element.position.array());
  }
  // Box index along d: floor((x_d - min_d) / (max_d - min_d) n_d), the last box closed;
  // the flat index runs over the boxes with the first coordinate fastest.
  // At most elements^3 boxes: within 64 bits for any model that fits in memory.
  std::vector<std::int64_t> box_of(static_cast<std::size_t>(elements), 0);
  for (int e = 0; e < elements; ++e) {
    const Vector& x = data.elements[static_cast<std::size_t>(e)].position;
    std::int64_t flat = 0, stride = 1;
    for (Eigen::Index d = 0; d < dimension; ++d) {
      const int n = counts[static_cast<std::size_t>(d)];
      const double extent = high[d] - low[d];
      const int box =
          extent > 0.0 ? std::min(n - 1, static_cast<int>(std::floor((x[d] - low[d]) / extent * n)))
                       : 0;
      flat += box * stride;
      stride *= n;
    }
    box_of[static_cast<std::size_t>(e)] = flat;
  }
  // The boxes that hold an element, in flat order, become zones 0, 1, ...
  std::map<std::int64_t, int> zone_of_box;
  for (std::int64_t box : box_of) zone_of_box.emplace(box, 0);
  for (auto& [box, zone] : zone_of_box) {
    zone = static_cast<int>(zone_names->size());
    std::string name = "grid";
    std::int64_t rest = box;
    for (const int count : counts) {
      name += "_" + std::to_string(rest % count);
      rest /= count;
    }
    zone_names->push_back(std::move(name));
  }
  for (int e = 0; e < elements; ++e) {
    zones[static_cast<std::size_t>(e)] = zone_of_box.at(box_of[static_cast<std::size_t>(e)]);
  }
  return zones;
}

MatrixModelData RezonedMatrixModel(const MatrixModelData& data,
                                   const std::vector<int>& element_zones,
                                   const std::vector<std::string>& zone_names) {
  assert(!data.elements.empty() && element_zones.size() == data.elements.size());
  const auto zones = zone_names.size();
  MatrixModelData rezoned = data;  // mass, scales, loads, sensors and supports kept
  rezoned.zones.assign(zones, MatrixModelZone{});
  rezoned.elements.clear();
  std::vector<bool> named(zones, false);
  rezoned.elements.reserve(data.elements.size());
  for (std::size_t e = 0; e < data.elements.size(); ++e) {
    const MatrixModelElement& element = data.elements[e];
    const auto z = static_cast<std::size_t>(element_zones[e]);
    assert(z < zones);
    const double element_nominal =
        data.zones[static_cast<std::size_t>(element.zone)].nominal_modulus;
    if (!named[z]) {
      rezoned.zones[z].name = zone_names[z];
      rezoned.zones[z].nominal_modulus = element_nominal;
      named[z] = true;
    }
    // The block at the new zone's nominal modulus: (E_z',nom / E_zone(e),nom) K_e.
    MatrixModelElement moved = element;
    moved.zone = static_cast<int>(z);
    moved.stiffness *= rezoned.zones[z].nominal_modulus / element_nominal;
    rezoned.elements.push_back(std::move(moved));
  }
  std::vector<SparseMatrix> sums = ElementBlockSums(rezoned);
  for (std::size_t z = 0; z < zones; ++z) {
    assert(named[z]);
    rezoned.zones[z].stiffness = std::move(sums[z]);
  }
  return rezoned;
}

namespace {

const NumberFormat kElementRoundTrip{NumberFormat::Notation::kRoundTrip};

// Refuses a zone name that would not read back as a dofs file's first field.
void CheckZoneField(const std::string& path, const std::string& zone) {
  if (zone.empty() || zone[0] == '#' || zone.find_first_of(",\n") != std::string::npos ||
      zone.find_first_of(kBlanks) == 0 || zone.find_last_of(kBlanks) == zone.size() - 1) {
    throw std::runtime_error("cannot write " + path + ": zone '" + zone +
                             "' is empty, starts with '#', holds a comma or a line break or "
                             "starts or ends with a blank, so a dofs file cannot name it");
  }
}

}  // namespace

MatrixModelElementFiles WriteMatrixModelElements(const std::string& folder,
                                                 const MatrixModelData& data) {
  MatrixModelElementFiles files{"element_dofs.csv", "element_stiffness.csv", ""};
  std::string dofs = "# mcrewave element dofs: zone, then the element's dofs (0-based)\n";
  std::string blocks =
      "# mcrewave element stiffness blocks [N/m] at the zone's nominal "
      "modulus, row by row\n";
  std::string positions = "# mcrewave element positions [m]\n";
  const bool with_positions = data.elements.front().position.size() > 0;
  for (const MatrixModelElement& element : data.elements) {
    const std::string& zone = data.zones[static_cast<std::size_t>(element.zone)].name;
    CheckZoneField(folder + "/" + files.dofs, zone);
    dofs += zone;
    for (const int dof : element.dofs) dofs += ", " + std::to_string(dof);
    dofs += "\n";
    const Eigen::Index k = element.stiffness.rows();
    for (Eigen::Index a = 0; a < k; ++a) {
      for (Eigen::Index b = 0; b < k; ++b) {
        blocks +=
            (a + b == 0 ? "" : ", ") + FormatNumber(element.stiffness(a, b), kElementRoundTrip);
      }
    }
    blocks += "\n";
    for (Eigen::Index i = 0; with_positions && i < element.position.size(); ++i) {
      positions += (i == 0 ? "" : ", ") + FormatNumber(element.position[i], kElementRoundTrip);
    }
    positions += "\n";
  }
  WriteFileAtomically(folder + "/" + files.dofs, dofs);
  WriteFileAtomically(folder + "/" + files.stiffness, blocks);
  if (with_positions) {
    files.positions = "element_positions.csv";
    WriteFileAtomically(folder + "/" + files.positions, positions);
  }
  return files;
}

}  // namespace mcrewave
