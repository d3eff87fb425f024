#include "mcrewave/model/matrix_export.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
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
TEST(MatrixExportTest, AbsolutePathsInAManifestAreUsedAsTheyAre) {
  const MatrixModelData data = BarMatrixModel(ThreeZoneBar(), 200e9, kSensors);
  const std::string files = std::filesystem::absolute(MakeFolder("absolute_files")).string();
  std::ifstream written(WriteMatrixModel(files, data));
  std::stringstream text;
  text << written.rdbuf();
  // The manifest in another folder: the zones', loads' and sensors' files named by their
  // absolute paths, the mass by a name relative to that folder (a copy of M.mtx there).
  const std::string manifest_text = std::regex_replace(
      text.str(), std::regex("(K_|load_|sensor_)([A-Za-z0-9_.]+\\.mtx)"), files + "/$1$2");
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
}

}  // namespace
}  // namespace mcrewave
