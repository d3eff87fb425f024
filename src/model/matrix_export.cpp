#include "mcrewave/model/matrix_export.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mcrewave/core/file_util.h"
#include "mcrewave/data/matrix_market.h"
#include "mcrewave/model/matrix_model_check.h"

namespace mcrewave {
namespace {

// A channel name as a file name part: '@' -> "_at_", '/' and spaces -> '_'.
std::string FileSafe(const std::string& name) {
  std::string safe;
  for (const char c : name) {
    if (c == '@') {
      safe += "_at_";
    } else if (c == '/' || c == ' ' || c == '\\') {
      safe += '_';
    } else {
      safe += c;
    }
  }
  return safe;
}

std::string Folder(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

// A file the manifest names: an absolute path as it is, a relative one relative to
// the manifest's folder.
std::string ManifestFile(const std::string& folder, const std::string& name) {
  return std::filesystem::path(name).is_absolute() ? name : folder + "/" + name;
}

std::string Where(const std::string& name, const YAML::Node& node) {
  return name + ":" + std::to_string(node.Mark().line + 1);
}

// The string of key `key` of a map entry.
std::string RequiredString(const std::string& name, const YAML::Node& entry,
                           const std::string& key) {
  const YAML::Node value = entry[key];
  if (!value || !value.IsScalar() || value.Scalar().empty()) {
    throw InputError(Where(name, entry) + ": expected key '" + key + "' (a name)");
  }
  return value.Scalar();
}

// Refuses a list entry that is not a map or has a key outside `keys`.
void CheckEntryKeys(const std::string& name, const YAML::Node& entry,
                    const std::set<std::string>& keys, const std::string& expected) {
  if (!entry.IsMap()) {
    throw InputError(Where(name, entry) + ": expected a map {" + expected + "}");
  }
  for (const auto& key : entry) {
    if (keys.count(key.first.Scalar()) == 0) {
      throw InputError(Where(name, key.first) + ": unknown key '" + key.first.Scalar() +
                       "' (expected " + expected + ")");
    }
  }
}

// The value of top-level key `key`: a finite positive length [m].
double RequiredLength(const std::string& name, const YAML::Node& root, const std::string& key) {
  const YAML::Node value = root[key];
  double length = 0.0;
  if (!value || !YAML::convert<double>::decode(value, length) || !std::isfinite(length) ||
      length <= 0.0) {
    throw InputError((value ? Where(name, value) : name) + ": expected key '" + key +
                     "', a finite positive length [m] (docs/matrix_models.md section 3)");
  }
  return length;
}

void Refuse(const std::string& why) {
  if (!why.empty()) throw InputError(why);
}

// A support's default reaction vector: ones on its dofs.
Vector DefaultSupportReaction(const std::vector<int>& support_dofs, int dofs) {
  Vector reaction = Vector::Zero(dofs);
  for (const int dof : support_dofs) {
    if (dof >= 0 && dof < dofs) reaction[dof] = 1.0;
  }
  return reaction;
}

}  // namespace

SparseMatrix MatrixModelData::Stiffness(const Vector& zone_moduli) const {
  SparseMatrix stiffness(dofs(), dofs());
  for (std::size_t z = 0; z < zones.size(); ++z) {
    stiffness +=
        (zone_moduli[static_cast<Eigen::Index>(z)] / zones[z].nominal_modulus) * zones[z].stiffness;
  }
  return stiffness;
}

Vector MatrixModelData::NominalModuli() const {
  Vector nominal(zones.size());
  for (std::size_t z = 0; z < zones.size(); ++z) {
    nominal[static_cast<Eigen::Index>(z)] = zones[z].nominal_modulus;
  }
  return nominal;
}

SparseMatrix ObservationRowMatrix(const ObservationRow& row, int dofs) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < 2; ++i) {
    if (row.coefficients[i] != 0.0) entries.emplace_back(0, row.nodes[i], row.coefficients[i]);
  }
  SparseMatrix matrix(1, dofs);
  matrix.setFromTriplets(entries.begin(), entries.end());  // a repeated node sums
  return matrix;
}

MatrixModelData BarMatrixModel(const BarModel& model, double nominal_modulus,
                               const std::vector<BarSensor>& sensors, BarClampExport clamp) {
  MatrixModelData data;
  const int n = model.num_nodes();
  data.mass = model.mass();
  data.stiffness_length = model.properties().section / model.properties().length;
  data.length = model.properties().length;
  for (int z = 0; z < model.num_zones(); ++z) {
    MatrixModelZone zone;
    zone.name = "zone" + std::to_string(z);
    zone.nominal_modulus = nominal_modulus;
    zone.stiffness = model.Stiffness(Vector::Unit(model.num_zones(), z) * nominal_modulus);
    data.zones.push_back(std::move(zone));
  }
  for (int e = 0; e < model.num_elements(); ++e) {
    // nominal_modulus K1_e = nominal_modulus k1_e [1 -1; -1 1] on nodes (e, e + 1), as
    // BarModel::StiffnessOfElements assembles it.
    const double k = nominal_modulus * model.element_unit_stiffness(e);
    MatrixModelElement element;
    element.dofs = {e, e + 1};
    element.zone = model.element_zone(e);
    element.stiffness = (Matrix(2, 2) << k, -k, -k, k).finished();
    element.position = Vector::Constant(1, model.element_midpoint(e));
    data.elements.push_back(std::move(element));
  }
  const bool support = clamp == BarClampExport::kSupport;
  if (!support) data.loads.push_back({"f0", Vector::Unit(n, model.left_node())});
  data.loads.push_back({"fL", Vector::Unit(n, model.right_node())});
  ObservationRow end;
  end.coefficients[0] = 1.0;
  end.nodes[0] = end.nodes[1] = model.left_node();
  if (!support) data.sensors.push_back({"u0", SparseRow(ObservationRowMatrix(end, n))});
  end.nodes[0] = end.nodes[1] = model.right_node();
  data.sensors.push_back({"uL", SparseRow(ObservationRowMatrix(end, n))});
  for (const BarSensor& sensor : sensors) {
    const ObservationRow row = sensor.kind == SensorKind::kDisplacement
                                   ? model.DisplacementRow(sensor.position)
                                   : model.StrainRow(sensor.position);
    std::ostringstream name;
    name << (sensor.kind == SensorKind::kDisplacement ? "u@" : "e@") << sensor.position;
    data.sensors.push_back({name.str(), SparseRow(ObservationRowMatrix(row, n)), sensor.kind});
  }
  if (support) {
    // The clamp: dof 0 held, g = e_0, its force f0 and displacement u0.
    MatrixModelSupport clamp{
        "clamp", {model.left_node()}, Vector::Unit(n, model.left_node()), "f0", "u0", Vector()};
    // Its trusted reaction's virtual displacement phi, linear from 1 at x = 0 to 0 at the
    // node m nearest to model.reaction_length: phi^T K U = -(S / (m l)) sum_{e < m} E_e
    // (U_{e+1} - U_e), the axial force averaged over [0, m l] (docs/boundaries.md
    // section 7). m = 1 leaves g alone.
    const BarProperties& bar = model.properties();
    const double element_length = bar.length / bar.elements;
    const int m =
        std::min(bar.elements,
                 std::max(1, static_cast<int>(std::lround(bar.reaction_length / element_length))));
    if (m > 1) {
      clamp.reaction_test = Vector::Zero(n);
      for (int i = 0; i < m; ++i) clamp.reaction_test[model.left_node() + i] = 1.0 - double(i) / m;
    }
    data.supports.push_back(std::move(clamp));
  }
  return data;
}

namespace {

// Writes a file per load vector and per sensor row and their manifest lists `loads` and
// `sensors`.
void WriteChannelFiles(const std::string& folder, const MatrixModelData& data,
                       YAML::Emitter* manifest) {
  *manifest << YAML::Key << "loads" << YAML::Value << YAML::BeginSeq;
  for (const MatrixModelLoad& load : data.loads) {
    const std::string file = "load_" + FileSafe(load.channel) + ".mtx";
    WriteMatrixMarketVector(folder + "/" + file, load.vector,
                            "spatial vector of load channel " + load.channel);
    *manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "channel" << YAML::Value
              << load.channel << YAML::Key << "vector" << YAML::Value << file << YAML::EndMap;
  }
  *manifest << YAML::EndSeq;
  *manifest << YAML::Key << "sensors" << YAML::Value << YAML::BeginSeq;
  for (const MatrixModelSensor& sensor : data.sensors) {
    const std::string file = "sensor_" + FileSafe(sensor.channel) + ".mtx";
    WriteMatrixMarketMatrix(folder + "/" + file, SparseMatrix(sensor.row),
                            MatrixMarketStorage::kGeneral,
                            "observation row of sensor channel " + sensor.channel);
    *manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "channel" << YAML::Value
              << sensor.channel << YAML::Key << "row" << YAML::Value << file;
    if (sensor.kind == SensorKind::kStrain) {
      *manifest << YAML::Key << "kind" << YAML::Value << "strain";
    }
    *manifest << YAML::EndMap;
  }
  *manifest << YAML::EndSeq;
}

// The text of a channels file naming `channels`, one a line. Throws std::runtime_error
// naming `path` when a name would not read back as it is.
std::string ChannelsText(const std::string& path, const std::vector<std::string>& channels) {
  std::string text = "# mcrewave channel names, one a line (docs/matrix_models.md)\n";
  for (const std::string& channel : channels) {
    if (channel.empty() || channel[0] == '#' || channel.find('\n') != std::string::npos ||
        channel.find_first_of(" \t\r\f\v") == 0 ||
        channel.find_last_of(" \t\r\f\v") == channel.size() - 1) {
      throw std::runtime_error("cannot write " + path + ": channel '" + channel +
                               "' is empty, starts with '#', holds a line break or starts or "
                               "ends with a blank, so a channels file cannot name it");
    }
    text += channel + "\n";
  }
  return text;
}

// Writes the load matrix G.mtx (n x C, column c the vector of load c) with
// load_channels.txt, and an observation matrix H_<i>.mtx (S_i x n) with
// sensor_channels_<i>.txt per run of consecutive sensors of one kind, and their manifest
// keys `loads_matrix` and `sensors_matrix`.
void WriteChannelMatrices(const std::string& folder, const MatrixModelData& data,
                          YAML::Emitter* manifest) {
  const int n = data.dofs();
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<std::string> channels;
  for (const MatrixModelLoad& load : data.loads) {
    for (Eigen::Index i = 0; i < load.vector.size(); ++i) {
      if (load.vector[i] != 0.0) {
        entries.emplace_back(static_cast<int>(i), static_cast<int>(channels.size()),
                             load.vector[i]);
      }
    }
    channels.push_back(load.channel);
  }
  SparseMatrix loads(n, static_cast<Eigen::Index>(channels.size()));
  loads.setFromTriplets(entries.begin(), entries.end());
  WriteFileAtomically(folder + "/load_channels.txt",
                      ChannelsText(folder + "/load_channels.txt", channels));
  WriteMatrixMarketMatrix(folder + "/G.mtx", loads, MatrixMarketStorage::kGeneral,
                          "load matrix G: column c is the spatial vector of load channel c");
  *manifest << YAML::Key << "loads_matrix" << YAML::Value << YAML::Flow << YAML::BeginMap
            << YAML::Key << "matrix" << YAML::Value << "G.mtx" << YAML::Key << "channels"
            << YAML::Value << "load_channels.txt" << YAML::EndMap;
  *manifest << YAML::Key << "sensors_matrix" << YAML::Value << YAML::BeginSeq;
  for (std::size_t first = 0, run = 1; first < data.sensors.size(); ++run) {
    const SensorKind kind = data.sensors[first].kind;
    entries.clear();
    channels.clear();
    for (; first < data.sensors.size() && data.sensors[first].kind == kind; ++first) {
      const SparseRow& row = data.sensors[first].row;
      for (int j = 0; j < row.outerSize(); ++j) {
        for (SparseRow::InnerIterator it(row, j); it; ++it) {
          entries.emplace_back(static_cast<int>(channels.size()), static_cast<int>(it.col()),
                               it.value());
        }
      }
      channels.push_back(data.sensors[first].channel);
    }
    SparseMatrix rows(static_cast<Eigen::Index>(channels.size()), n);
    rows.setFromTriplets(entries.begin(), entries.end());
    const std::string matrix = "H_" + std::to_string(run) + ".mtx";
    const std::string names = "sensor_channels_" + std::to_string(run) + ".txt";
    WriteFileAtomically(folder + "/" + names, ChannelsText(folder + "/" + names, channels));
    WriteMatrixMarketMatrix(folder + "/" + matrix, rows, MatrixMarketStorage::kGeneral,
                            "observation matrix H: row k is the row of sensor channel k");
    *manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "matrix" << YAML::Value << matrix
              << YAML::Key << "channels" << YAML::Value << names;
    if (kind == SensorKind::kStrain) *manifest << YAML::Key << "kind" << YAML::Value << "strain";
    *manifest << YAML::EndMap;
  }
  *manifest << YAML::EndSeq;
}

}  // namespace

std::string WriteMatrixModel(const std::string& folder, const MatrixModelData& data,
                             MatrixModelLayout layout) {
  YAML::Emitter manifest;
  manifest.SetDoublePrecision(17);
  manifest << YAML::BeginMap;
  manifest << YAML::Key << "mass" << YAML::Value << "M.mtx";
  manifest << YAML::Key << "stiffness_length" << YAML::Value << data.stiffness_length;
  manifest << YAML::Key << "length" << YAML::Value << data.length;
  WriteMatrixMarketMatrix(folder + "/M.mtx", data.mass, MatrixMarketStorage::kSymmetric,
                          "mass matrix M [kg]");
  manifest << YAML::Key << "zones" << YAML::Value << YAML::BeginSeq;
  for (const MatrixModelZone& zone : data.zones) {
    const std::string file = "K_" + FileSafe(zone.name) + ".mtx";
    WriteMatrixMarketMatrix(folder + "/" + file, zone.stiffness, MatrixMarketStorage::kSymmetric,
                            "stiffness of zone " + zone.name + " [N/m] at its nominal modulus");
    manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << zone.name
             << YAML::Key << "stiffness" << YAML::Value << file << YAML::Key << "nominal_modulus"
             << YAML::Value << zone.nominal_modulus << YAML::EndMap;
  }
  manifest << YAML::EndSeq;
  if (layout == MatrixModelLayout::kMatrices) {
    WriteChannelMatrices(folder, data, &manifest);
  } else {
    WriteChannelFiles(folder, data, &manifest);
  }
  if (!data.supports.empty()) {
    manifest << YAML::Key << "supports" << YAML::Value << YAML::BeginSeq;
    for (const MatrixModelSupport& support : data.supports) {
      manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << support.name
               << YAML::Key << "dofs" << YAML::Value << YAML::Flow << support.dofs << YAML::Key
               << "force_channel" << YAML::Value << support.force_channel;
      if (!support.displacement_channel.empty()) {
        manifest << YAML::Key << "displacement_channel" << YAML::Value
                 << support.displacement_channel;
      }
      if (support.reaction != DefaultSupportReaction(support.dofs, data.dofs())) {
        const std::string file = "support_" + FileSafe(support.name) + ".mtx";
        WriteMatrixMarketVector(folder + "/" + file, support.reaction,
                                "reaction vector g of support " + support.name);
        manifest << YAML::Key << "reaction" << YAML::Value << file;
      }
      if (support.reaction_test.size() > 0) {
        const std::string file = "support_" + FileSafe(support.name) + "_reaction_test.mtx";
        WriteMatrixMarketVector(
            folder + "/" + file, support.reaction_test,
            "virtual displacement phi of support " + support.name + "'s trusted reaction");
        manifest << YAML::Key << "reaction_test" << YAML::Value << file;
      }
      manifest << YAML::EndMap;
    }
    manifest << YAML::EndSeq;
  }
  if (!data.elements.empty()) {
    const MatrixModelElementFiles files = WriteMatrixModelElements(folder, data);
    manifest << YAML::Key << "elements" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
             << "dofs" << YAML::Value << files.dofs << YAML::Key << "stiffness" << YAML::Value
             << files.stiffness;
    if (!files.positions.empty()) {
      manifest << YAML::Key << "positions" << YAML::Value << files.positions;
    }
    manifest << YAML::EndMap;
  }
  manifest << YAML::EndMap;
  const std::string path = folder + "/model.yaml";
  WriteFileAtomically(path, std::string("# mcrewave matrix model (docs/matrix_models.md)\n") +
                                manifest.c_str() + "\n");
  return path;
}

namespace {

// The manifest at manifest_path, checked to be a map of the keys mass,
// stiffness_length, length, zones, loads, sensors, loads_matrix, sensors_matrix,
// supports and elements only.
YAML::Node LoadManifest(const std::string& manifest_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(manifest_path);
  } catch (const YAML::BadFile&) {
    throw InputError("cannot read matrix model manifest " + manifest_path);
  } catch (const YAML::Exception& error) {
    throw InputError(manifest_path + ":" + std::to_string(error.mark.line + 1) + ": " + error.msg);
  }
  if (!root.IsMap()) throw InputError(manifest_path + ":1: expected a map (mass, zones, ...)");
  for (const auto& key : root) {
    const std::string name = key.first.Scalar();
    if (name != "mass" && name != "stiffness_length" && name != "length" && name != "zones" &&
        name != "loads" && name != "sensors" && name != "loads_matrix" &&
        name != "sensors_matrix" && name != "supports" && name != "elements") {
      throw InputError(Where(manifest_path, key.first) + ": unknown key '" + name +
                       "' (expected mass, stiffness_length, length, zones, loads, sensors, "
                       "loads_matrix, sensors_matrix, supports, elements)");
    }
  }
  return root;
}

// The value of top-level key `key`: a non-empty list.
YAML::Node RequiredList(const std::string& manifest_path, const YAML::Node& root, const char* key) {
  const YAML::Node node = root[key];
  if (!node || !node.IsSequence() || node.size() == 0) {
    throw InputError(manifest_path + ": expected '" + key + "', a non-empty list");
  }
  return node;
}

// Appends the manifest's zones to data->zones: each named once, its stiffness
// file (relative to `folder`) symmetric and of the mass matrix's size (mass_file),
// its nominal modulus finite and positive.
void ReadZones(const std::string& manifest_path, const YAML::Node& root, const std::string& folder,
               const std::string& mass_file, MatrixModelData* data) {
  const int n = data->dofs();
  std::set<std::string> names;
  for (const YAML::Node& entry : RequiredList(manifest_path, root, "zones")) {
    CheckEntryKeys(manifest_path, entry, {"name", "stiffness", "nominal_modulus"},
                   "name, stiffness, nominal_modulus");
    MatrixModelZone zone;
    zone.name = RequiredString(manifest_path, entry, "name");
    if (!names.insert(zone.name).second) {
      throw InputError(Where(manifest_path, entry) + ": zone '" + zone.name + "' given twice");
    }
    const std::string file =
        ManifestFile(folder, RequiredString(manifest_path, entry, "stiffness"));
    double modulus = 0.0;
    if (!entry["nominal_modulus"] ||
        !YAML::convert<double>::decode(entry["nominal_modulus"], modulus) ||
        !std::isfinite(modulus) || modulus <= 0.0) {
      throw InputError(Where(manifest_path, entry) +
                       ": expected nominal_modulus, a finite positive modulus [Pa]");
    }
    zone.nominal_modulus = modulus;
    zone.stiffness = ReadMatrixMarketMatrix(file);
    Refuse(CheckSameSize(zone.stiffness, file, n, mass_file));
    Refuse(CheckSymmetric(zone.stiffness, file));
    data->zones.push_back(std::move(zone));
  }
}

// The value of top-level key `key` when given: a list (a map, where `map_allowed`,
// stands for the list of that one entry); an empty sequence when absent.
YAML::Node OptionalList(const std::string& manifest_path, const YAML::Node& root, const char* key,
                        const std::string& expected, bool map_allowed = false) {
  const YAML::Node node = root[key];
  if (!node) return YAML::Node(YAML::NodeType::Sequence);
  if (map_allowed && node.IsMap()) {
    YAML::Node list(YAML::NodeType::Sequence);
    list.push_back(node);
    return list;
  }
  if (!node.IsSequence()) {
    throw InputError(Where(manifest_path, node) + ": expected '" + key + "', " + expected);
  }
  return node;
}

// Appends the manifest's loads (an optional list) to data->loads: each channel not
// already in *channels (then added), its vector file (relative to `folder`) of the mass
// matrix's size (mass_file).
void ReadLoads(const std::string& manifest_path, const YAML::Node& root, const std::string& folder,
               const std::string& mass_file, std::set<std::string>* channels,
               MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry :
       OptionalList(manifest_path, root, "loads", "a list of {channel, vector}")) {
    CheckEntryKeys(manifest_path, entry, {"channel", "vector"}, "channel, vector");
    MatrixModelLoad load;
    load.channel = RequiredString(manifest_path, entry, "channel");
    if (!channels->insert(load.channel).second) {
      throw InputError(Where(manifest_path, entry) + ": channel '" + load.channel +
                       "' given twice");
    }
    const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "vector"));
    load.vector = ReadMatrixMarketVector(file);
    Refuse(CheckVectorSize(load.vector, file, n, mass_file));
    data->loads.push_back(std::move(load));
  }
}

// The sensor kind of a map entry's optional key `kind`: displacement (the default) or
// strain.
SensorKind KindOf(const std::string& manifest_path, const YAML::Node& entry) {
  if (!entry["kind"]) return SensorKind::kDisplacement;
  const std::string kind = RequiredString(manifest_path, entry, "kind");
  if (kind == "strain") return SensorKind::kStrain;
  if (kind != "displacement") {
    throw InputError(Where(manifest_path, entry["kind"]) +
                     ": kind must be displacement or strain, got '" + kind + "'");
  }
  return SensorKind::kDisplacement;
}

// Appends the manifest's sensors (an optional list) to data->sensors: each of kind
// displacement (the default) or strain, its channel not already in *channels (then
// added), its observation row file (relative to `folder`) checked against the mass
// matrix (mass_file) and stored as a row.
void ReadSensors(const std::string& manifest_path, const YAML::Node& root,
                 const std::string& folder, const std::string& mass_file,
                 std::set<std::string>* channels, MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry :
       OptionalList(manifest_path, root, "sensors", "a list of {channel, row, kind}")) {
    CheckEntryKeys(manifest_path, entry, {"channel", "row", "kind"}, "channel, row, kind");
    MatrixModelSensor sensor;
    sensor.channel = RequiredString(manifest_path, entry, "channel");
    sensor.kind = KindOf(manifest_path, entry);
    if (!channels->insert(sensor.channel).second) {
      throw InputError(Where(manifest_path, entry) + ": channel '" + sensor.channel +
                       "' given twice");
    }
    const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "row"));
    SparseMatrix row = ReadMatrixMarketMatrix(file);
    Refuse(CheckSensorRow(row, sensor.channel, file, n, mass_file));
    if (row.rows() != 1) row = SparseMatrix(row.transpose());
    sensor.row = SparseRow(row);
    data->sensors.push_back(std::move(sensor));
  }
}

// A channel name of a channels file and the file's line it is on (1-based).
struct ListedChannel {
  std::string name;
  int line = 0;
};

// The channel names of the file at `path`: one a line, trimmed; blank lines and lines
// starting with '#' skipped. Refuses a file that cannot be read, holds no name, or names a
// channel twice ("FILE:LINE: ...").
std::vector<ListedChannel> ReadChannelNames(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    throw InputError("cannot read channel names file " + path + ": it is a directory");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read channel names file " + path + ": " + std::strerror(errno));
  }
  std::vector<ListedChannel> names;
  std::map<std::string, int> lines;
  std::string text;
  for (int line = 1; std::getline(file, text); ++line) {
    const std::size_t begin = text.find_first_not_of(" \t\r\f\v");
    if (begin == std::string::npos || text[begin] == '#') continue;
    const std::size_t end = text.find_last_not_of(" \t\r\f\v");
    ListedChannel name{text.substr(begin, end - begin + 1), line};
    const auto first = lines.emplace(name.name, line);
    if (!first.second) {
      throw InputError(path + ":" + std::to_string(line) + ": channel '" + name.name +
                       "' given twice (first on line " + std::to_string(first.first->second) +
                       "), expected each channel once");
    }
    names.push_back(std::move(name));
  }
  if (file.bad()) throw InputError("cannot read channel names file " + path);
  if (names.empty()) {
    throw InputError(path +
                     ": no channel names, expected one a line (blank lines and lines starting "
                     "with '#' are skipped)");
  }
  return names;
}

// The channel names of a matrix entry (key `channels`, a file relative to `folder`),
// `count` of them (the matrix `matrix_file`'s `what`, columns or rows), each not already in
// *channels (then added).
std::vector<ListedChannel> ReadMatrixChannels(const std::string& manifest_path,
                                              const YAML::Node& entry, const std::string& folder,
                                              Eigen::Index count, const std::string& matrix_file,
                                              const std::string& what,
                                              std::set<std::string>* channels) {
  const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "channels"));
  std::vector<ListedChannel> names = ReadChannelNames(file);
  if (static_cast<Eigen::Index>(names.size()) != count) {
    throw InputError(file + ": " + std::to_string(names.size()) + " channel names, but " +
                     matrix_file + " has " + std::to_string(count) + " " + what +
                     ", expected one name per " + what.substr(0, what.size() - 1));
  }
  for (const ListedChannel& name : names) {
    if (!channels->insert(name.name).second) {
      throw InputError(file + ":" + std::to_string(name.line) + ": channel '" + name.name +
                       "' given twice: already a channel of the model (a load's or a "
                       "sensor's), expected a channel of its own");
    }
  }
  return names;
}

// Appends the channels of the manifest's load matrices (key loads_matrix: a map
// {matrix, channels} or a list of them) to data->loads, in their order: column c of the
// n x C matrix (a file relative to `folder`, n the dofs of mass_file) is the vector of the
// channels file's c-th name.
void ReadLoadMatrices(const std::string& manifest_path, const YAML::Node& root,
                      const std::string& folder, const std::string& mass_file,
                      std::set<std::string>* channels, MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry : OptionalList(manifest_path, root, "loads_matrix",
                                              "a map {matrix, channels} or a list of them", true)) {
    CheckEntryKeys(manifest_path, entry, {"matrix", "channels"}, "matrix, channels");
    const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "matrix"));
    const SparseMatrix matrix = ReadMatrixMarketMatrix(file);
    if (matrix.rows() != n) {
      throw InputError(file + ": " + std::to_string(matrix.rows()) + " x " +
                       std::to_string(matrix.cols()) + ", but " + mass_file + " has " +
                       std::to_string(n) + " dofs, expected " + std::to_string(n) +
                       " rows (a column per load channel)");
    }
    const std::vector<ListedChannel> names =
        ReadMatrixChannels(manifest_path, entry, folder, matrix.cols(), file, "columns", channels);
    for (std::size_t c = 0; c < names.size(); ++c) {
      data->loads.push_back({names[c].name, Vector(matrix.col(static_cast<Eigen::Index>(c)))});
    }
  }
}

// Appends the channels of the manifest's observation matrices (key sensors_matrix: a map
// {matrix, channels, kind} or a list of them) to data->sensors, in their order: row k of
// the S x n matrix (a file relative to `folder`, n the dofs of mass_file) is the
// observation row of the channels file's k-th name, every row of the entry's kind
// (displacement by default, or strain). Each row is built from its own entries: no dense
// S x n work.
void ReadSensorMatrices(const std::string& manifest_path, const YAML::Node& root,
                        const std::string& folder, const std::string& mass_file,
                        std::set<std::string>* channels, MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry :
       OptionalList(manifest_path, root, "sensors_matrix",
                    "a map {matrix, channels, kind} or a list of them", true)) {
    CheckEntryKeys(manifest_path, entry, {"matrix", "channels", "kind"}, "matrix, channels, kind");
    const SensorKind kind = KindOf(manifest_path, entry);
    const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "matrix"));
    const SparseRow matrix = ReadMatrixMarketMatrix(file);
    if (matrix.cols() != n) {
      throw InputError(file + ": " + std::to_string(matrix.rows()) + " x " +
                       std::to_string(matrix.cols()) + ", but " + mass_file + " has " +
                       std::to_string(n) + " dofs, expected " + std::to_string(n) +
                       " columns (a row per sensor channel)");
    }
    const std::vector<ListedChannel> names =
        ReadMatrixChannels(manifest_path, entry, folder, matrix.rows(), file, "rows", channels);
    for (Eigen::Index k = 0; k < matrix.rows(); ++k) {
      MatrixModelSensor sensor;
      sensor.channel = names[static_cast<std::size_t>(k)].name;
      sensor.kind = kind;
      // Row k's own entries, O(nnz): matrix is stored by rows.
      sensor.row = matrix.row(k);
      Refuse(CheckSensorRow(sensor.row, sensor.channel, file + " row " + std::to_string(k + 1), n,
                            mass_file));
      data->sensors.push_back(std::move(sensor));
    }
  }
}

// Appends the manifest's supports (an optional list) to data->supports: each named once
// (a map of name, dofs, force_channel and the optional displacement_channel and
// reaction), its dofs distinct, in range and held by no other support, its reaction
// vector (a file relative to `folder`, default ones on the dofs) checked against them,
// its channels not already in *channels (then added).
void ReadSupports(const std::string& manifest_path, const YAML::Node& root,
                  const std::string& folder, const std::string& mass_file,
                  std::set<std::string>* channels, MatrixModelData* data) {
  const YAML::Node list = root["supports"];
  if (!list) return;
  if (!list.IsSequence()) {
    throw InputError(Where(manifest_path, list) +
                     ": expected 'supports', a list of {name, dofs, force_channel, ...}");
  }
  const int n = data->dofs();
  std::set<std::string> names;
  std::set<int> held;
  for (const YAML::Node& entry : list) {
    if (!entry.IsMap()) {
      throw InputError(Where(manifest_path, entry) +
                       ": expected a support, a map {name, dofs, force_channel, ...}");
    }
    MatrixModelSupport support;
    support.name = RequiredString(manifest_path, entry, "name");
    const std::string which = Where(manifest_path, entry) + ": support '" + support.name + "'";
    for (const auto& key : entry) {
      const std::string& name = key.first.Scalar();
      if (name != "name" && name != "dofs" && name != "force_channel" &&
          name != "displacement_channel" && name != "reaction" && name != "reaction_test") {
        throw InputError(which + ": unknown key '" + name +
                         "' (expected name, dofs, force_channel, displacement_channel, "
                         "reaction, reaction_test)");
      }
    }
    // The string of key `key` (a channel or file name).
    auto string_of = [&](const char* key) {
      const YAML::Node value = entry[key];
      if (!value || !value.IsScalar() || value.Scalar().empty()) {
        throw InputError(which + ": expected key '" + key + "' (a name)");
      }
      return value.Scalar();
    };
    if (!names.insert(support.name).second) throw InputError(which + " given twice");
    const YAML::Node dofs = entry["dofs"];
    if (!dofs || !dofs.IsSequence()) {
      throw InputError(which + ": expected dofs, a list of held dofs (0-based integers)");
    }
    for (const YAML::Node& dof : dofs) {
      int index = 0;
      if (!dof.IsScalar() || !YAML::convert<int>::decode(dof, index)) {
        throw InputError(which + ": dofs: expected 0-based integers, got '" +
                         (dof.IsScalar() ? dof.Scalar() : std::string("a list or map")) + "'");
      }
      support.dofs.push_back(index);
    }
    const std::string bad_dofs =
        CheckSupportDofs(support.dofs, support.name, manifest_path, n, mass_file);
    if (!bad_dofs.empty()) throw InputError(Where(manifest_path, entry) + ": " + bad_dofs);
    for (const int dof : support.dofs) {
      if (!held.insert(dof).second) {
        throw InputError(which + ": dof " + std::to_string(dof) +
                         " is held by another support, expected each dof in one support");
      }
    }
    if (entry["reaction"]) {
      const std::string file = ManifestFile(folder, string_of("reaction"));
      support.reaction = ReadMatrixMarketVector(file);
      const std::string bad_reaction =
          CheckSupportReaction(support.reaction, support.dofs, support.name, file, n, mass_file);
      if (!bad_reaction.empty()) {
        throw InputError(Where(manifest_path, entry) + ": " + bad_reaction);
      }
    } else {
      support.reaction = DefaultSupportReaction(support.dofs, n);
    }
    if (entry["reaction_test"]) {
      const std::string file = ManifestFile(folder, string_of("reaction_test"));
      support.reaction_test = ReadMatrixMarketVector(file);
      const std::string bad_test = CheckSupportReactionTest(
          support.reaction_test, support.reaction, support.dofs, support.name, file, n, mass_file);
      if (!bad_test.empty()) throw InputError(Where(manifest_path, entry) + ": " + bad_test);
    }
    support.force_channel = string_of("force_channel");
    if (entry["displacement_channel"]) {
      support.displacement_channel = string_of("displacement_channel");
    }
    for (const std::string* channel : {&support.force_channel, &support.displacement_channel}) {
      if (channel->empty()) continue;
      if (!channels->insert(*channel).second) {
        throw InputError(which + ": channel '" + *channel +
                         "' is already a channel of the model (a load's, a sensor's or a "
                         "support's), expected a channel of its own");
      }
    }
    data->supports.push_back(std::move(support));
  }
}

// Reads the manifest's optional element blocks (key elements: a map {dofs, stiffness,
// positions}, files relative to `folder`) into data->elements and checks that each zone's
// blocks sum to its K_z.
void ReadElements(const std::string& manifest_path, const YAML::Node& root,
                  const std::string& folder, const std::string& mass_file, MatrixModelData* data) {
  const YAML::Node entry = root["elements"];
  if (!entry) return;
  CheckEntryKeys(manifest_path, entry, {"dofs", "stiffness", "positions"},
                 "dofs, stiffness, positions");
  MatrixModelElementFiles files;
  files.dofs = ManifestFile(folder, RequiredString(manifest_path, entry, "dofs"));
  files.stiffness = ManifestFile(folder, RequiredString(manifest_path, entry, "stiffness"));
  if (entry["positions"]) {
    files.positions = ManifestFile(folder, RequiredString(manifest_path, entry, "positions"));
  }
  std::vector<std::string> zone_names;
  for (const MatrixModelZone& zone : data->zones) zone_names.push_back(zone.name);
  data->elements = ReadMatrixModelElements(files, zone_names, data->dofs(), mass_file);
  Refuse(CheckElementBlockSums(*data, Where(manifest_path, entry) + " (" + files.stiffness + ")"));
}

}  // namespace

MatrixModelData ReadMatrixModel(const std::string& manifest_path) {
  const YAML::Node root = LoadManifest(manifest_path);
  const std::string folder = Folder(manifest_path);
  MatrixModelData data;
  data.stiffness_length = RequiredLength(manifest_path, root, "stiffness_length");
  data.length = RequiredLength(manifest_path, root, "length");
  const std::string mass_file = ManifestFile(folder, RequiredString(manifest_path, root, "mass"));
  data.mass = ReadMatrixMarketMatrix(mass_file);
  Refuse(CheckSquare(data.mass, mass_file));
  Refuse(CheckSymmetric(data.mass, mass_file));
  Refuse(CheckPositiveDefinite(data.mass, mass_file));
  ReadZones(manifest_path, root, folder, mass_file, &data);
  // Load and sensor channels share one namespace; each list's files, then its matrices.
  std::set<std::string> channels;
  ReadLoads(manifest_path, root, folder, mass_file, &channels, &data);
  ReadLoadMatrices(manifest_path, root, folder, mass_file, &channels, &data);
  if (data.loads.empty()) {
    throw InputError(manifest_path +
                     ": expected 'loads', a non-empty list, or 'loads_matrix', a load matrix "
                     "and its channel names");
  }
  ReadSensors(manifest_path, root, folder, mass_file, &channels, &data);
  ReadSensorMatrices(manifest_path, root, folder, mass_file, &channels, &data);
  if (data.sensors.empty()) {
    throw InputError(manifest_path +
                     ": expected 'sensors', a non-empty list, or 'sensors_matrix', an "
                     "observation matrix and its channel names");
  }
  ReadSupports(manifest_path, root, folder, mass_file, &channels, &data);
  ReadElements(manifest_path, root, folder, mass_file, &data);
  return data;
}

namespace {

// "" when every stored entry of `matrix` is finite, else the first that is not.
std::string CheckFinite(const SparseMatrix& matrix, const std::string& name) {
  for (int column = 0; column < matrix.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator it(matrix, column); it; ++it) {
      if (!std::isfinite(it.value())) {
        return name + ": entry (" + std::to_string(it.row() + 1) + ", " +
               std::to_string(it.col() + 1) + ") is not a finite number";
      }
    }
  }
  return "";
}

std::string CheckFinite(const Vector& vector, const std::string& name) {
  for (Eigen::Index i = 0; i < vector.size(); ++i) {
    if (!std::isfinite(vector[i])) {
      return name + ": entry " + std::to_string(i + 1) + " is not a finite number";
    }
  }
  return "";
}

}  // namespace

void CheckMatrixModel(const MatrixModelData& data, const std::string& name) {
  const auto positive = [&](double value, const std::string& key) {
    if (!(value > 0.0 && std::isfinite(value))) {
      throw InputError(name + ": " + key + ": expected a positive length [m], got " +
                       std::to_string(value));
    }
  };
  positive(data.stiffness_length, "stiffness_length");
  positive(data.length, "length");
  const std::string mass = name + ": the mass matrix";
  Refuse(CheckFinite(data.mass, mass));
  Refuse(CheckSquare(data.mass, mass));
  Refuse(CheckSymmetric(data.mass, mass));
  Refuse(CheckPositiveDefinite(data.mass, mass));
  const int n = data.dofs();
  if (data.zones.empty()) throw InputError(name + ": expected at least one zone");
  std::set<std::string> zone_names;
  for (const MatrixModelZone& zone : data.zones) {
    const std::string which = name + ": zone '" + zone.name + "'";
    if (zone.name.empty() || !zone_names.insert(zone.name).second) {
      throw InputError(which + ": expected a name, not empty and not another zone's");
    }
    if (!(zone.nominal_modulus > 0.0 && std::isfinite(zone.nominal_modulus))) {
      throw InputError(which + ": expected a positive nominal modulus [Pa], got " +
                       std::to_string(zone.nominal_modulus));
    }
    Refuse(CheckFinite(zone.stiffness, which + " stiffness"));
    Refuse(CheckSameSize(zone.stiffness, which + " stiffness", n, mass));
    Refuse(CheckSymmetric(zone.stiffness, which + " stiffness"));
  }
  if (data.loads.empty()) throw InputError(name + ": expected at least one load channel");
  if (data.sensors.empty()) throw InputError(name + ": expected at least one sensor channel");
  std::set<std::string> channels;
  const auto add_channel = [&](const std::string& channel, const std::string& whose) {
    if (channel.empty() || !channels.insert(channel).second) {
      throw InputError(name + ": " + whose + " channel '" + channel +
                       "': expected a name, not empty and not another channel's (a load's, a "
                       "sensor's or a support's)");
    }
  };
  for (const MatrixModelLoad& load : data.loads) {
    add_channel(load.channel, "load");
    const std::string which = name + ": load '" + load.channel + "'";
    Refuse(CheckVectorSize(load.vector, which, n, mass));
    Refuse(CheckFinite(load.vector, which));
  }
  for (const MatrixModelSensor& sensor : data.sensors) {
    add_channel(sensor.channel, "sensor");
    const std::string which = name + ": sensor '" + sensor.channel + "'";
    Refuse(CheckFinite(SparseMatrix(sensor.row), which));
    Refuse(CheckSensorRow(sensor.row, sensor.channel, name, n, mass));
  }
  std::set<std::string> support_names;
  std::set<int> held;
  for (const MatrixModelSupport& support : data.supports) {
    const std::string which = name + ": support '" + support.name + "'";
    if (support.name.empty() || !support_names.insert(support.name).second) {
      throw InputError(which + ": expected a name, not empty and not another support's");
    }
    Refuse(CheckSupportDofs(support.dofs, support.name, name, n, mass));
    for (const int dof : support.dofs) {
      if (!held.insert(dof).second) {
        throw InputError(which + ": dof " + std::to_string(dof) +
                         " is held by another support, expected each dof in one support");
      }
    }
    Refuse(CheckSupportReaction(support.reaction, support.dofs, support.name, which + " reaction",
                                n, mass));
    if (support.reaction_test.size() > 0) {
      Refuse(CheckSupportReactionTest(support.reaction_test, support.reaction, support.dofs,
                                      support.name, which + " reaction_test", n, mass));
    }
    add_channel(support.force_channel, "support force");
    if (!support.displacement_channel.empty()) {
      add_channel(support.displacement_channel, "support displacement");
    }
  }
  const std::size_t dimension = data.elements.empty() ? 0 : data.elements.front().position.size();
  for (std::size_t e = 0; e < data.elements.size(); ++e) {
    const MatrixModelElement& element = data.elements[e];
    const std::string which = name + ": element " + std::to_string(e);
    const auto k = static_cast<Eigen::Index>(element.dofs.size());
    if (element.zone < 0 || element.zone >= static_cast<int>(data.zones.size())) {
      throw InputError(which + ": zone index " + std::to_string(element.zone) +
                       " out of range, expected 0 to " + std::to_string(data.zones.size() - 1));
    }
    std::set<int> distinct(element.dofs.begin(), element.dofs.end());
    if (k == 0 || distinct.size() != element.dofs.size() || *distinct.begin() < 0 ||
        *distinct.rbegin() >= n) {
      throw InputError(which + ": expected at least one dof, each in [0, " + std::to_string(n) +
                       ") and none twice");
    }
    if (element.stiffness.rows() != k || element.stiffness.cols() != k ||
        !element.stiffness.allFinite()) {
      throw InputError(which + ": expected a finite " + std::to_string(k) + " x " +
                       std::to_string(k) + " stiffness block (its dofs' count)");
    }
    if (static_cast<std::size_t>(element.position.size()) != dimension || dimension > 3 ||
        !element.position.allFinite()) {
      throw InputError(which +
                       ": expected a position of 1 to 3 finite coordinates for every "
                       "element, or none for every element");
    }
  }
  if (!data.elements.empty()) {
    Refuse(CheckElementBlockSums(data, name + " (the element blocks)"));
  }
}

const Vector& TrustedReactionTest(const MatrixModelSupport& support) {
  return support.reaction_test.size() > 0 ? support.reaction_test : support.reaction;
}

MatrixModelData BarRunModel(const BarModel& model, const ChannelSet& data,
                            EndDisplacementChannels ends) {
  const std::vector<BarSensor> sensors = BarSensors(data);
  MatrixModelData matrices =
      BarMatrixModel(model, model.properties().modulus, sensors, BarClampExport::kSupport);
  // The interior sensors follow uL, in the data's order: each takes its data channel's
  // own name (u@0.50 stays u@0.50; positions that print alike stay apart).
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    matrices.sensors[1 + i].channel =
        data.channels[static_cast<std::size_t>(sensors[i].index)].name;
  }
  if (!ends.uL) {
    matrices.sensors.erase(
        std::find_if(matrices.sensors.begin(), matrices.sensors.end(),
                     [](const MatrixModelSensor& sensor) { return sensor.channel == "uL"; }));
  }
  if (!ends.u0) matrices.supports.front().displacement_channel.clear();
  return matrices;
}

}  // namespace mcrewave
