#include "mcrewave/model/matrix_export.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
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
  const bool support = clamp == BarClampExport::kSupport;
  if (!support) data.loads.push_back({"f0", Vector::Unit(n, model.left_node())});
  data.loads.push_back({"fL", Vector::Unit(n, model.right_node())});
  ObservationRow end;
  end.coefficients[0] = 1.0;
  end.nodes[0] = end.nodes[1] = model.left_node();
  if (!support) data.sensors.push_back({"u0", ObservationRowMatrix(end, n)});
  end.nodes[0] = end.nodes[1] = model.right_node();
  data.sensors.push_back({"uL", ObservationRowMatrix(end, n)});
  for (const BarSensor& sensor : sensors) {
    const ObservationRow row = sensor.kind == SensorKind::kDisplacement
                                   ? model.DisplacementRow(sensor.position)
                                   : model.StrainRow(sensor.position);
    std::ostringstream name;
    name << (sensor.kind == SensorKind::kDisplacement ? "u@" : "e@") << sensor.position;
    data.sensors.push_back({name.str(), ObservationRowMatrix(row, n), sensor.kind});
  }
  if (support) {
    // The clamp: dof 0 held, g = e_0, its force f0 and displacement u0.
    data.supports.push_back(
        {"clamp", {model.left_node()}, Vector::Unit(n, model.left_node()), "f0", "u0"});
  }
  return data;
}

std::string WriteMatrixModel(const std::string& folder, const MatrixModelData& data) {
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
  manifest << YAML::Key << "loads" << YAML::Value << YAML::BeginSeq;
  for (const MatrixModelLoad& load : data.loads) {
    const std::string file = "load_" + FileSafe(load.channel) + ".mtx";
    WriteMatrixMarketVector(folder + "/" + file, load.vector,
                            "spatial vector of load channel " + load.channel);
    manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "channel" << YAML::Value
             << load.channel << YAML::Key << "vector" << YAML::Value << file << YAML::EndMap;
  }
  manifest << YAML::EndSeq;
  manifest << YAML::Key << "sensors" << YAML::Value << YAML::BeginSeq;
  for (const MatrixModelSensor& sensor : data.sensors) {
    const std::string file = "sensor_" + FileSafe(sensor.channel) + ".mtx";
    WriteMatrixMarketMatrix(folder + "/" + file, sensor.row, MatrixMarketStorage::kGeneral,
                            "observation row of sensor channel " + sensor.channel);
    manifest << YAML::Flow << YAML::BeginMap << YAML::Key << "channel" << YAML::Value
             << sensor.channel << YAML::Key << "row" << YAML::Value << file;
    if (sensor.kind == SensorKind::kStrain) {
      manifest << YAML::Key << "kind" << YAML::Value << "strain";
    }
    manifest << YAML::EndMap;
  }
  manifest << YAML::EndSeq;
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
      manifest << YAML::EndMap;
    }
    manifest << YAML::EndSeq;
  }
  manifest << YAML::EndMap;
  const std::string path = folder + "/model.yaml";
  WriteFileAtomically(path, std::string("# mcrewave matrix model (docs/matrix_models.md)\n") +
                                manifest.c_str() + "\n");
  return path;
}

namespace {

// The manifest at manifest_path, checked to be a map of the keys mass,
// stiffness_length, length, zones, loads and sensors only.
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
        name != "loads" && name != "sensors" && name != "supports") {
      throw InputError(Where(manifest_path, key.first) + ": unknown key '" + name +
                       "' (expected mass, stiffness_length, length, zones, loads, sensors, "
                       "supports)");
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

// Appends the manifest's loads to data->loads: each channel not already in
// *channels (then added), its vector file (relative to `folder`) of the mass
// matrix's size (mass_file).
void ReadLoads(const std::string& manifest_path, const YAML::Node& root, const std::string& folder,
               const std::string& mass_file, std::set<std::string>* channels,
               MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry : RequiredList(manifest_path, root, "loads")) {
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

// Appends the manifest's sensors to data->sensors: each of kind displacement
// (the default) or strain, its channel not already in *channels (then added),
// its observation row file (relative to `folder`) checked against the mass
// matrix (mass_file) and stored as a row.
void ReadSensors(const std::string& manifest_path, const YAML::Node& root,
                 const std::string& folder, const std::string& mass_file,
                 std::set<std::string>* channels, MatrixModelData* data) {
  const int n = data->dofs();
  for (const YAML::Node& entry : RequiredList(manifest_path, root, "sensors")) {
    CheckEntryKeys(manifest_path, entry, {"channel", "row", "kind"}, "channel, row, kind");
    MatrixModelSensor sensor;
    sensor.channel = RequiredString(manifest_path, entry, "channel");
    if (entry["kind"]) {
      const std::string kind = RequiredString(manifest_path, entry, "kind");
      if (kind == "strain") {
        sensor.kind = SensorKind::kStrain;
      } else if (kind != "displacement") {
        throw InputError(Where(manifest_path, entry["kind"]) +
                         ": kind must be displacement or "
                         "strain, got '" +
                         kind + "'");
      }
    }
    if (!channels->insert(sensor.channel).second) {
      throw InputError(Where(manifest_path, entry) + ": channel '" + sensor.channel +
                       "' given twice");
    }
    const std::string file = ManifestFile(folder, RequiredString(manifest_path, entry, "row"));
    SparseMatrix row = ReadMatrixMarketMatrix(file);
    Refuse(CheckSensorRow(row, sensor.channel, file, n, mass_file));
    if (row.rows() != 1) row = SparseMatrix(row.transpose());
    sensor.row = std::move(row);
    data->sensors.push_back(std::move(sensor));
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
          name != "displacement_channel" && name != "reaction") {
        throw InputError(which + ": unknown key '" + name +
                         "' (expected name, dofs, force_channel, displacement_channel, "
                         "reaction)");
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
  // Load and sensor channels share one namespace.
  std::set<std::string> channels;
  ReadLoads(manifest_path, root, folder, mass_file, &channels, &data);
  ReadSensors(manifest_path, root, folder, mass_file, &channels, &data);
  ReadSupports(manifest_path, root, folder, mass_file, &channels, &data);
  return data;
}

}  // namespace mcrewave
