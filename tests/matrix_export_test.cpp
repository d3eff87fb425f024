#include "mcrewave/model/matrix_export.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/data/matrix_market.h"
#include "mcrewave/linalg/theta_integrator.h"

namespace mcrewave {
namespace {

std::string MakeFolder(const std::string& name) {
  const std::string folder = ::testing::TempDir() + name;
  ::mkdir(folder.c_str(), 0755);
  return folder;
}

double MaxDifference(const SparseMatrix& a, const SparseMatrix& b) {
  return (Matrix(a) - Matrix(b)).cwiseAbs().maxCoeff();
}

// A 30-element bar in three zones with two interior sensors.
BarModel ThreeZoneBar() {
  BarProperties bar;
  bar.elements = 30;
  std::vector<int> zones(30);
  for (int e = 0; e < 30; ++e) zones[e] = e / 10;
  return BarModel(bar, zones);
}

const std::vector<BarSensor> kSensors = {{SensorKind::kDisplacement, 0.25},
                                         {SensorKind::kStrain, 0.65}};

TEST(MatrixExportTest, TheBarReadsBackExactly) {
  const BarModel model = ThreeZoneBar();
  const MatrixModelData data = BarMatrixModel(model, 200e9, kSensors);
  ASSERT_EQ(data.zones.size(), 3u);
  ASSERT_EQ(data.loads.size(), 2u);
  ASSERT_EQ(data.sensors.size(), 4u);
  EXPECT_EQ(data.sensors[2].channel, "u@0.25");
  EXPECT_EQ(data.sensors[3].channel, "e@0.65");
  const std::string manifest = WriteMatrixModel(MakeFolder("bar_export"), data);
  const MatrixModelData back = ReadMatrixModel(manifest);
  EXPECT_EQ(MaxDifference(back.mass, data.mass), 0.0);
  // The weights' scales a* = S / L and l* = L (written with 17 digits: the same bits).
  EXPECT_EQ(back.stiffness_length, model.properties().section / model.properties().length);
  EXPECT_EQ(back.length, model.properties().length);
  EXPECT_EQ(back.sensors[2].kind, SensorKind::kDisplacement);
  EXPECT_EQ(back.sensors[3].kind, SensorKind::kStrain);
  for (std::size_t z = 0; z < 3; ++z) {
    EXPECT_EQ(back.zones[z].name, data.zones[z].name);
    EXPECT_EQ(back.zones[z].nominal_modulus, 200e9);
    EXPECT_EQ(MaxDifference(back.zones[z].stiffness, data.zones[z].stiffness), 0.0) << z;
  }
  for (std::size_t i = 0; i < data.loads.size(); ++i) {
    EXPECT_EQ(back.loads[i].channel, data.loads[i].channel);
    EXPECT_EQ(back.loads[i].vector, data.loads[i].vector);
  }
  for (std::size_t i = 0; i < data.sensors.size(); ++i) {
    EXPECT_EQ(back.sensors[i].channel, data.sensors[i].channel);
    EXPECT_EQ(MaxDifference(back.sensors[i].row, data.sensors[i].row), 0.0) << i;
  }
  // The rows are the bar's own observation rows.
  const ObservationRow strain = model.StrainRow(0.65);
  EXPECT_EQ(back.sensors[3].row.coeff(0, strain.nodes[0]), strain.coefficients[0]);
  EXPECT_EQ(back.sensors[3].row.coeff(0, strain.nodes[1]), strain.coefficients[1]);
  // K = sum_z (E_z / E_nominal) K_z equals the bar's sum_z E_z K1_z to round-off.
  const Vector moduli = (Vector(3) << 180e9, 210e9, 250e9).finished();
  const SparseMatrix expected = model.Stiffness(moduli);
  EXPECT_LT(MaxDifference(back.Stiffness(moduli), expected),
            1e-15 * Matrix(expected).cwiseAbs().maxCoeff());
}

// BarRunModel names each interior sensor as its data channel: a name with trailing
// zeros keeps them, and two positions that print alike in 6 digits stay two sensors.
TEST(MatrixExportTest, TheRunsBarNamesItsSensorsAsTheDataDo) {
  const BarModel model = ThreeZoneBar();
  ChannelSet data;
  data.time_step = 1e-6;
  for (const std::string name :
       {"u0", "uL", "f0", "fL", "u@0.50", "u@0.123456", "u@0.1234561", "e@0.650"}) {
    data.channels.push_back({name, ChannelKind::kDisplacement, Vector::Zero(3)});
  }
  const MatrixModelData matrices = BarRunModel(model, data, {});
  ASSERT_EQ(matrices.sensors.size(), 5u);
  const std::vector<std::string> names = {"uL", "u@0.50", "u@0.123456", "u@0.1234561", "e@0.650"};
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(matrices.sensors[i].channel, names[i]);
  EXPECT_EQ(matrices.sensors[4].kind, SensorKind::kStrain);
  // Each row is the bar's own at its position (the two close ones differ).
  const ObservationRow close = model.DisplacementRow(0.1234561);
  const SparseMatrix expected = ObservationRowMatrix(close, model.num_nodes());
  EXPECT_EQ(MaxDifference(matrices.sensors[3].row, expected), 0.0);
  EXPECT_GT(MaxDifference(matrices.sensors[2].row, matrices.sensors[3].row), 0.0);
}

// The bar through its files and the sparse path against the built-in bar and its
// tridiagonal path: 1000 steps of an end load.
TEST(MatrixExportTest, TheExportedBarIntegratesLikeTheBuiltInBar) {
  const BarModel model = ThreeZoneBar();
  const MatrixModelData back =
      ReadMatrixModel(WriteMatrixModel(MakeFolder("bar_export_run"), BarMatrixModel(model, 1e9)));
  const Vector moduli = (Vector(3) << 180e9, 210e9, 250e9).finished();
  ThetaIntegratorOptions options;
  options.time_step = 1e-6;
  ThetaIntegrator built_in, general;
  built_in.Init(model.mass(), model.Stiffness(moduli), options);
  options.factorization = Factorization::kSparse;
  general.Init(back.mass, back.Stiffness(moduli), options);
  const int n = model.num_nodes();
  Vector v1 = Vector::Zero(n), u1 = Vector::Zero(n), v2 = v1, u2 = u1, v(n), u(n);
  double worst = 0.0, scale = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const double load = k < 100 ? 1000.0 * std::sin(M_PI * k / 100.0) : 0.0;
    built_in.StepWithEndLoads(v1, u1, 0.0, load, v, u);
    v1 = v;
    u1 = u;
    general.Step(v2, u2, load * back.loads[1].vector, v, u);
    v2 = v;
    u2 = u;
    worst = std::max(worst, (u1 - u2).cwiseAbs().maxCoeff());
    scale = std::max(scale, u1.cwiseAbs().maxCoeff());
  }
  // Measured 8.2e-14.
  std::printf("exported bar, sparse path vs built-in: %.2e of max |u|\n", worst / scale);
  EXPECT_LT(worst / scale, 1e-12);
}

// Writes `text` into folder/name.
void WriteText(const std::string& folder, const std::string& name, const std::string& text) {
  std::ofstream(folder + "/" + name) << text;
}

// The message of ReadMatrixModel on the exported bar after `spoil` edits its files.
template <typename Spoil>
std::string SpoiledError(const std::string& name, Spoil&& spoil) {
  const std::string folder = MakeFolder(name);
  BarProperties bar;
  bar.elements = 6;
  const std::string manifest = WriteMatrixModel(folder, BarMatrixModel(BarModel(bar), 1.0));
  spoil(folder);
  try {
    ReadMatrixModel(manifest);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

using testing::Contains;

TEST(MatrixExportTest, BadModelsGiveOneClearError) {
  std::string why = SpoiledError("spoil_size", [](const std::string& folder) {
    SparseMatrix k(5, 5);
    k.setIdentity();
    WriteMatrixMarketMatrix(folder + "/K_zone0.mtx", k);
  });
  EXPECT_TRUE(Contains(why, "K_zone0.mtx: 5 x 5, but ") && Contains(why, "M.mtx has 7 dofs"))
      << why;
  why = SpoiledError("spoil_symmetry", [](const std::string& folder) {
    SparseMatrix k(7, 7);
    k.setIdentity();
    k.insert(2, 3) = 0.5;
    WriteMatrixMarketMatrix(folder + "/K_zone0.mtx", k);
  });
  EXPECT_TRUE(Contains(why, "K_zone0.mtx: not symmetric: entry (4, 3) = 0 but (3, 4) = 0.5"))
      << why;
  why = SpoiledError("spoil_mass", [](const std::string& folder) {
    SparseMatrix m(7, 7);
    m.setIdentity();
    m.coeffRef(6, 6) = -1.0;
    WriteMatrixMarketMatrix(folder + "/M.mtx", m);
  });
  EXPECT_TRUE(Contains(why, "M.mtx: not positive definite: LDL^T pivot -1 at dof 7")) << why;
  why = SpoiledError("spoil_sensor", [](const std::string& folder) {
    WriteText(folder, "sensor_uL.mtx",
              "%%MatrixMarket matrix coordinate real general\n1 9 1\n1 9 1\n");
  });
  EXPECT_TRUE(Contains(why, "sensor 'uL' (") &&
              Contains(why, "entry at dof 9, past the last dof 7"))
      << why;
  why = SpoiledError("spoil_load", [](const std::string& folder) {
    WriteText(folder, "load_fL.mtx", "%%MatrixMarket matrix array real general\n2 1\n1\n");
  });
  EXPECT_TRUE(Contains(why, "load_fL.mtx: ends after 1 of the 2 values")) << why;
  why = SpoiledError("spoil_manifest", [](const std::string& folder) {
    WriteText(folder, "model.yaml",
              "mass: M.mtx\nstiffness_length: 1\nlength: 1\n"
              "zones:\n  - {name: a, stiffness: K_zone0.mtx, nominal_modulus: 1}\n"
              "loads:\n  - {channel: fL, vector: load_fL.mtx}\nsensors:\n"
              "  - {channel: fL, row: sensor_uL.mtx}\n");
  });
  EXPECT_TRUE(Contains(why, "model.yaml:9: channel 'fL' given twice")) << why;
  why = SpoiledError("spoil_key", [](const std::string& folder) {
    WriteText(folder, "model.yaml", "mass: M.mtx\nzone: []\n");
  });
  EXPECT_TRUE(Contains(why, "model.yaml:2: unknown key 'zone'")) << why;
  why = SpoiledError("spoil_entry_key", [](const std::string& folder) {
    WriteText(folder, "model.yaml",
              "mass: M.mtx\nstiffness_length: 1\nlength: 1\nzones:\n  - name: a\n"
              "    stiffness: K_zone0.mtx\n"
              "    nominal_modulus: 1\n    modulus: 2\n");
  });
  EXPECT_TRUE(Contains(why, "model.yaml:8: unknown key 'modulus'")) << why;
  why = SpoiledError("spoil_scale", [](const std::string& folder) {
    WriteText(folder, "model.yaml", "mass: M.mtx\nstiffness_length: -1\nlength: 1\n");
  });
  EXPECT_TRUE(Contains(why,
                       "model.yaml:2: expected key 'stiffness_length', a finite positive "
                       "length [m]"))
      << why;
  why = SpoiledError("spoil_kind", [](const std::string& folder) {
    WriteText(folder, "model.yaml",
              "mass: M.mtx\nstiffness_length: 1\nlength: 1\n"
              "zones:\n  - {name: a, stiffness: K_zone0.mtx, nominal_modulus: 1}\n"
              "loads:\n  - {channel: fL, vector: load_fL.mtx}\nsensors:\n"
              "  - {channel: uL, row: sensor_uL.mtx, kind: force}\n");
  });
  EXPECT_TRUE(Contains(why, "model.yaml:9: kind must be displacement or strain, got 'force'"))
      << why;
}

// A manifest naming absolute paths reads them as they are: they were glued onto the
// manifest's folder ("cannot read Matrix Market file /data/plate//data/plate/M.mtx").
// A relative name beside them stays relative to the manifest's folder.
// A model given in code (the Python module's) gets the manifest's checks of its
// contents: the exported bar passes, and each spoiled copy is refused naming the model,
// the part and what was expected.
TEST(MatrixExportTest, AModelGivenInCodeIsCheckedAsAManifestIs) {
  const MatrixModelData bar =
      BarMatrixModel(ThreeZoneBar(), 200e9, kSensors, BarClampExport::kSupport);
  EXPECT_NO_THROW(CheckMatrixModel(bar, "the bar"));
  const auto refused = [&](const std::function<void(MatrixModelData*)>& spoil,
                           const std::string& expected) {
    MatrixModelData spoiled = bar;
    spoil(&spoiled);
    try {
      CheckMatrixModel(spoiled, "the bar");
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()).rfind(expected, 0), 0u) << error.what();
    }
  };
  refused([](MatrixModelData* m) { m->length = 0.0; }, "the bar: length: expected a positive");
  refused([](MatrixModelData* m) { m->mass.coeffRef(0, 1) += 1.0; },
          "the bar: the mass matrix: not symmetric");
  refused([](MatrixModelData* m) { m->zones[1].stiffness.coeffRef(3, 3) = std::nan(""); },
          "the bar: zone 'zone1' stiffness: entry (4, 4) is not a finite number");
  refused([](MatrixModelData* m) { m->zones[2].name = "zone0"; },
          "the bar: zone 'zone0': expected a name, not empty and not another zone's");
  refused([](MatrixModelData* m) { m->zones[0].nominal_modulus = -1.0; },
          "the bar: zone 'zone0': expected a positive nominal modulus");
  refused([](MatrixModelData* m) { m->loads[0].vector.conservativeResize(5); },
          "the bar: load 'fL'");
  refused([](MatrixModelData* m) { m->sensors[1].channel = "fL"; },
          "the bar: sensor channel 'fL': expected a name, not empty and not another channel's");
  refused([](MatrixModelData* m) { m->supports[0].force_channel = "uL"; },
          "the bar: support force channel 'uL'");
  refused([](MatrixModelData* m) { m->supports[0].dofs = {31}; }, "support 'clamp'");
  refused([](MatrixModelData* m) { m->loads.clear(); },
          "the bar: expected at least one load channel");
}

TEST(MatrixExportTest, AbsolutePathsInAManifestAreUsedAsTheyAre) {
  const MatrixModelData data = BarMatrixModel(ThreeZoneBar(), 200e9, kSensors);
  const std::string files = std::filesystem::absolute(MakeFolder("absolute_files")).string();
  std::ifstream written(WriteMatrixModel(files, data));
  std::stringstream text;
  text << written.rdbuf();
  // The manifest in another folder: the zones', loads', sensors' and elements' files named
  // by their absolute paths, the mass by a name relative to that folder (a copy of M.mtx
  // there).
  const std::string manifest_text = std::regex_replace(
      text.str(), std::regex("(K_|load_|sensor_|element_)([A-Za-z0-9_.]+\\.(mtx|csv))"),
      files + "/$1$2");
  ASSERT_NE(manifest_text.find("dofs: " + files + "/element_dofs.csv"), std::string::npos)
      << manifest_text;
  ASSERT_NE(manifest_text.find("stiffness: " + files + "/K_zone0.mtx"), std::string::npos)
      << manifest_text;
  ASSERT_NE(manifest_text.find("row: " + files + "/sensor_e_at_0.65.mtx"), std::string::npos)
      << manifest_text;
  ASSERT_NE(manifest_text.find("mass: M.mtx"), std::string::npos) << manifest_text;
  const std::string elsewhere = MakeFolder("absolute_manifest");
  std::filesystem::copy_file(files + "/M.mtx", elsewhere + "/M.mtx",
                             std::filesystem::copy_options::overwrite_existing);
  WriteText(elsewhere, "model.yaml", manifest_text);

  const MatrixModelData back = ReadMatrixModel(elsewhere + "/model.yaml");
  EXPECT_EQ(MaxDifference(back.mass, data.mass), 0.0);
  ASSERT_EQ(back.zones.size(), data.zones.size());
  for (std::size_t z = 0; z < data.zones.size(); ++z) {
    EXPECT_EQ(MaxDifference(back.zones[z].stiffness, data.zones[z].stiffness), 0.0) << z;
  }
  ASSERT_EQ(back.loads.size(), data.loads.size());
  for (std::size_t i = 0; i < data.loads.size(); ++i) {
    EXPECT_EQ(back.loads[i].vector, data.loads[i].vector) << i;
  }
  ASSERT_EQ(back.sensors.size(), data.sensors.size());
  for (std::size_t i = 0; i < data.sensors.size(); ++i) {
    EXPECT_EQ(MaxDifference(back.sensors[i].row, data.sensors[i].row), 0.0) << i;
  }
  ASSERT_EQ(back.elements.size(), data.elements.size());
  for (std::size_t e = 0; e < data.elements.size(); ++e) {
    EXPECT_EQ(back.elements[e].stiffness, data.elements[e].stiffness) << e;
  }
}

// Expects `read` to be `expected` in its loads and sensors: the same channels in the same
// order, the same load vectors, sensor rows (stored entries and values) and kinds.
void ExpectSameChannels(const MatrixModelData& read, const MatrixModelData& expected) {
  ASSERT_EQ(read.loads.size(), expected.loads.size());
  for (std::size_t i = 0; i < expected.loads.size(); ++i) {
    EXPECT_EQ(read.loads[i].channel, expected.loads[i].channel) << i;
    EXPECT_EQ(read.loads[i].vector, expected.loads[i].vector) << i;
  }
  ASSERT_EQ(read.sensors.size(), expected.sensors.size());
  for (std::size_t i = 0; i < expected.sensors.size(); ++i) {
    const MatrixModelSensor& sensor = read.sensors[i];
    EXPECT_EQ(sensor.channel, expected.sensors[i].channel) << i;
    EXPECT_EQ(sensor.kind, expected.sensors[i].kind) << i;
    ASSERT_EQ(sensor.row.rows(), 1) << i;
    ASSERT_EQ(sensor.row.cols(), expected.sensors[i].row.cols()) << i;
    EXPECT_EQ(sensor.row.nonZeros(), expected.sensors[i].row.nonZeros()) << i;
    EXPECT_EQ(MaxDifference(sensor.row, expected.sensors[i].row), 0.0) << i;
  }
}

// Writes the loads first..last-1 of `data` as the load matrix `matrix` (n x C, general
// storage) and their names, with comments, blank lines and blanks around the names, as
// `channels`.
void WriteLoadMatrixByHand(const std::string& folder, const MatrixModelData& data,
                           std::size_t first, std::size_t last, const std::string& matrix,
                           const std::string& channels) {
  Matrix dense(data.dofs(), static_cast<Eigen::Index>(last - first));
  std::string names = "# load channels, a column each\n\n";
  for (std::size_t c = first; c < last; ++c) {
    dense.col(static_cast<Eigen::Index>(c - first)) = data.loads[c].vector;
    names += "  " + data.loads[c].channel + "\t\n";
  }
  WriteMatrixMarketMatrix(folder + "/" + matrix, SparseMatrix(dense.sparseView()));
  WriteText(folder, channels, names);
}

// Writes the sensors first..last-1 of `data` as the observation matrix `matrix` (S x n)
// and their names as `channels` (CRLF line ends).
void WriteSensorMatrixByHand(const std::string& folder, const MatrixModelData& data,
                             std::size_t first, std::size_t last, const std::string& matrix,
                             const std::string& channels) {
  std::vector<Eigen::Triplet<double>> entries;
  std::string names;
  for (std::size_t k = first; k < last; ++k) {
    const SparseMatrix& row = data.sensors[k].row;
    for (int j = 0; j < row.outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(row, j); it; ++it) {
        entries.emplace_back(static_cast<int>(k - first), static_cast<int>(it.col()), it.value());
      }
    }
    names += data.sensors[k].channel + "\r\n";
  }
  SparseMatrix rows(static_cast<Eigen::Index>(last - first), data.dofs());
  rows.setFromTriplets(entries.begin(), entries.end());
  WriteMatrixMarketMatrix(folder + "/" + matrix, rows);
  WriteText(folder, channels, names);
}

// The manifest `folder`/model.yaml (as WriteMatrixModel wrote it) with its keys of loads
// and sensors (loads, sensors, loads_matrix, sensors_matrix) replaced by `channels`, YAML
// text of the new keys.
void ReplaceChannelKeys(const std::string& folder, const std::string& channels) {
  YAML::Node root = YAML::LoadFile(folder + "/model.yaml");
  for (const char* key : {"loads", "sensors", "loads_matrix", "sensors_matrix"}) root.remove(key);
  YAML::Emitter out;
  out << root;
  WriteText(folder, "model.yaml", std::string(out.c_str()) + "\n" + channels);
}

// The bar with two interior sensors, its loads as one matrix and its sensors as two (the
// displacement rows, then the strain row), files written here, reads to the model of the
// per-file manifest: the same load vectors, sensor rows, kinds and names.
TEST(MatrixExportTest, LoadAndObservationMatricesReadToThePerFileModel) {
  const MatrixModelData data = BarMatrixModel(ThreeZoneBar(), 200e9, kSensors);
  ASSERT_EQ(data.sensors.size(), 4u);  // u0, uL, u@0.25, e@0.65
  const MatrixModelData files =
      ReadMatrixModel(WriteMatrixModel(MakeFolder("channels_files"), data));
  const std::string folder = MakeFolder("channels_matrices");
  WriteMatrixModel(folder, data);
  WriteLoadMatrixByHand(folder, data, 0, 2, "G.mtx", "load_channels.txt");
  WriteSensorMatrixByHand(folder, data, 0, 3, "H_u.mtx", "sensor_channels_u.txt");
  WriteSensorMatrixByHand(folder, data, 3, 4, "H_e.mtx", "sensor_channels_e.txt");
  ReplaceChannelKeys(folder,
                     "loads_matrix: {matrix: G.mtx, channels: load_channels.txt}\n"
                     "sensors_matrix:\n"
                     "  - {matrix: H_u.mtx, channels: sensor_channels_u.txt, kind: displacement}\n"
                     "  - {matrix: H_e.mtx, channels: sensor_channels_e.txt, kind: strain}\n");
  const MatrixModelData matrices = ReadMatrixModel(folder + "/model.yaml");
  EXPECT_EQ(matrices.sensors[3].kind, SensorKind::kStrain);
  ExpectSameChannels(matrices, files);
  EXPECT_EQ(MaxDifference(matrices.mass, files.mass), 0.0);
  ASSERT_EQ(matrices.zones.size(), files.zones.size());

  // One map for the sensors (a single kind): the strain sensor dropped on both sides.
  WriteSensorMatrixByHand(folder, data, 0, 3, "H_u.mtx", "sensor_channels_u.txt");
  ReplaceChannelKeys(folder,
                     "loads_matrix: [{matrix: G.mtx, channels: load_channels.txt}]\n"
                     "sensors_matrix: {matrix: H_u.mtx, channels: sensor_channels_u.txt}\n");
  MatrixModelData without_strain = files;
  without_strain.sensors.pop_back();
  ExpectSameChannels(ReadMatrixModel(folder + "/model.yaml"), without_strain);
}

// Files and matrices combine: the channels of `loads` (`sensors`) first, then the
// matrices'; the channel names stay distinct across both forms.
TEST(MatrixExportTest, ChannelFilesAndMatricesCombineInTheManifestsOrder) {
  const MatrixModelData data = BarMatrixModel(ThreeZoneBar(), 200e9, kSensors);
  const std::string folder = MakeFolder("channels_combined");
  WriteMatrixModel(folder, data);
  WriteLoadMatrixByHand(folder, data, 1, 2, "G.mtx", "load_channels.txt");
  WriteSensorMatrixByHand(folder, data, 2, 4, "H.mtx", "sensor_channels.txt");
  const std::string channels =
      "loads:\n  - {channel: f0, vector: load_f0.mtx}\n"
      "loads_matrix: {matrix: G.mtx, channels: load_channels.txt}\n"
      "sensors_matrix:\n  - {matrix: H.mtx, channels: sensor_channels.txt}\n"
      "sensors:\n  - {channel: u0, row: sensor_u0.mtx}\n  - {channel: uL, row: sensor_uL.mtx}\n";
  ReplaceChannelKeys(folder, channels);
  MatrixModelData expected = data;
  expected.sensors[3].kind = SensorKind::kDisplacement;  // H.mtx's kind: the default
  ExpectSameChannels(ReadMatrixModel(folder + "/model.yaml"), expected);

  // uL in a per-file entry and on the matrix's names file: refused on the names file.
  WriteText(folder, "sensor_channels.txt", "u@0.25\nuL\n");
  ReplaceChannelKeys(folder, channels);
  std::string why;
  try {
    ReadMatrixModel(folder + "/model.yaml");
  } catch (const InputError& error) {
    why = error.what();
  }
  EXPECT_TRUE(Contains(why, "sensor_channels.txt:2: channel 'uL' given twice: already a channel"))
      << why;
}

// WriteMatrixModel with MatrixModelLayout::kMatrices writes G, one H per run of a kind
// and their names files; they read back to the model.
TEST(MatrixExportTest, TheMatricesLayoutReadsBackExactly) {
  const MatrixModelData data = BarMatrixModel(ThreeZoneBar(), 200e9, kSensors);
  const std::string folder = MakeFolder("channels_layout");
  const MatrixModelData back =
      ReadMatrixModel(WriteMatrixModel(folder, data, MatrixModelLayout::kMatrices));
  for (const char* file : {"G.mtx", "load_channels.txt", "H_1.mtx", "sensor_channels_1.txt",
                           "H_2.mtx", "sensor_channels_2.txt"}) {
    EXPECT_TRUE(std::filesystem::exists(folder + "/" + file)) << file;
  }
  EXPECT_FALSE(std::filesystem::exists(folder + "/H_3.mtx"));
  EXPECT_FALSE(std::filesystem::exists(folder + "/load_fL.mtx"));
  ExpectSameChannels(back, data);
  // A channel name a names file cannot hold.
  MatrixModelData blank = data;
  blank.loads[0].channel = "f0 ";
  EXPECT_THROW(
      WriteMatrixModel(MakeFolder("channels_layout_blank"), blank, MatrixModelLayout::kMatrices),
      std::runtime_error);
}

// The message of ReadMatrixModel on the 6-element bar written with its loads and sensors
// as matrices (G.mtx: 7 x 2, f0 and fL; H_1.mtx: 2 x 7, u0 and uL) after `spoil` edits
// its files, given the folder and the manifest's text.
template <typename Spoil>
std::string SpoiledMatricesError(const std::string& name, Spoil&& spoil) {
  const std::string folder = MakeFolder(name);
  BarProperties bar;
  bar.elements = 6;
  const std::string manifest =
      WriteMatrixModel(folder, BarMatrixModel(BarModel(bar), 1.0), MatrixModelLayout::kMatrices);
  std::ifstream written(manifest);
  std::stringstream text;
  text << written.rdbuf();
  spoil(folder, text.str());
  try {
    ReadMatrixModel(manifest);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// `text` with `from` replaced by `to` (once, where it must be), and the 1-based line it is on.
std::pair<std::string, int> ReplacedOnLine(std::string text, const std::string& from,
                                           const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " in\n" << text;
  if (at == std::string::npos) return {text, 0};
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  return {text.replace(at, from.size(), to), line};
}

TEST(MatrixExportTest, BadChannelMatricesGiveOneClearError) {
  std::string why =
      SpoiledMatricesError("matrices_count", [](const std::string& folder, const std::string&) {
        WriteText(folder, "load_channels.txt", "f0\nfL\n# a third\nf2\n");
      });
  EXPECT_TRUE(Contains(why, "load_channels.txt: 3 channel names, but ") &&
              Contains(why, "G.mtx has 2 columns, expected one name per column"))
      << why;
  why = SpoiledMatricesError("matrices_rows_count",
                             [](const std::string& folder, const std::string&) {
                               WriteText(folder, "sensor_channels_1.txt", "uL\n");
                             });
  EXPECT_TRUE(Contains(why, "sensor_channels_1.txt: 1 channel names, but ") &&
              Contains(why, "H_1.mtx has 2 rows, expected one name per row"))
      << why;
  why =
      SpoiledMatricesError("matrices_duplicate", [](const std::string& folder, const std::string&) {
        WriteText(folder, "sensor_channels_1.txt", "u0\n\n  u0\n");
      });
  EXPECT_TRUE(Contains(why, "sensor_channels_1.txt:3: channel 'u0' given twice (first on line 1)"))
      << why;
  why = SpoiledMatricesError("matrices_duplicate_load",
                             [](const std::string& folder, const std::string&) {
                               WriteText(folder, "load_channels.txt", "f0\nuL\n");
                             });
  // Line 3: the written names file starts with a comment line.
  EXPECT_TRUE(Contains(why,
                       "sensor_channels_1.txt:3: channel 'uL' given twice: already a "
                       "channel of the model"))
      << why;
  why = SpoiledMatricesError("matrices_empty", [](const std::string& folder, const std::string&) {
    WriteText(folder, "load_channels.txt", "# no names\n\n   \n");
  });
  EXPECT_TRUE(Contains(why, "load_channels.txt: no channel names, expected one a line")) << why;
  why = SpoiledMatricesError("matrices_g_rows", [](const std::string& folder, const std::string&) {
    SparseMatrix g(5, 2);
    g.insert(0, 0) = 1.0;
    WriteMatrixMarketMatrix(folder + "/G.mtx", g);
  });
  EXPECT_TRUE(Contains(why, "G.mtx: 5 x 2, but ") &&
              Contains(why, "M.mtx has 7 dofs, expected 7 rows (a column per load channel)"))
      << why;
  why =
      SpoiledMatricesError("matrices_h_columns", [](const std::string& folder, const std::string&) {
        SparseMatrix h(2, 9);
        h.insert(0, 0) = 1.0;
        h.insert(1, 6) = 1.0;
        WriteMatrixMarketMatrix(folder + "/H_1.mtx", h);
      });
  EXPECT_TRUE(Contains(why, "H_1.mtx: 2 x 9, but ") &&
              Contains(why, "M.mtx has 7 dofs, expected 7 columns (a row per sensor channel)"))
      << why;
  why = SpoiledMatricesError("matrices_h_zero_row",
                             [](const std::string& folder, const std::string&) {
                               SparseMatrix h(2, 7);
                               h.insert(0, 0) = 1.0;
                               WriteMatrixMarketMatrix(folder + "/H_1.mtx", h);
                             });
  EXPECT_TRUE(Contains(why, "sensor 'uL' (") &&
              Contains(why, "H_1.mtx row 2): every coefficient is zero"))
      << why;
  int line = 0;
  why = SpoiledMatricesError(
      "matrices_key", [&line](const std::string& folder, const std::string& text) {
        const auto spoiled = ReplacedOnLine(text, "channels: load_channels.txt}",
                                            "channels: load_channels.txt, "
                                            "columns: 2}");
        line = spoiled.second;
        WriteText(folder, "model.yaml", spoiled.first);
      });
  EXPECT_TRUE(Contains(why, "model.yaml:" + std::to_string(line) +
                                ": unknown key 'columns' (expected matrix, channels)"))
      << why;
  why = SpoiledMatricesError(
      "matrices_kind", [&line](const std::string& folder, const std::string& text) {
        const auto spoiled = ReplacedOnLine(text, "channels: sensor_channels_1.txt}",
                                            "channels: sensor_channels_1.txt, kind: force}");
        line = spoiled.second;
        WriteText(folder, "model.yaml", spoiled.first);
      });
  EXPECT_TRUE(Contains(why, "model.yaml:" + std::to_string(line) +
                                ": kind must be displacement or strain, got 'force'"))
      << why;
  why = SpoiledMatricesError("matrices_missing_names",
                             [](const std::string& folder, const std::string&) {
                               std::remove((folder + "/load_channels.txt").c_str());
                             });
  EXPECT_TRUE(Contains(why, "cannot read channel names file ") &&
              Contains(why, "load_channels.txt: No such file"))
      << why;
  why = SpoiledMatricesError("matrices_missing_matrix",
                             [](const std::string& folder, const std::string&) {
                               std::remove((folder + "/H_1.mtx").c_str());
                             });
  EXPECT_TRUE(Contains(why, "cannot read Matrix Market file ") && Contains(why, "H_1.mtx")) << why;
  why = SpoiledMatricesError("matrices_no_loads_at_all",
                             [](const std::string& folder, const std::string&) {
                               ReplaceChannelKeys(folder,
                                                  "sensors_matrix: {matrix: H_1.mtx, channels: "
                                                  "sensor_channels_1.txt}\n");
                             });
  EXPECT_TRUE(Contains(why, "model.yaml: expected 'loads', a non-empty list, or 'loads_matrix'"))
      << why;
}

}  // namespace
}  // namespace mcrewave
