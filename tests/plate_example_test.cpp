// The committed plate examples: configs/plate (scripts/make_plate_example.py), both
// meshes read and pass every check, and the sparse path integrates them like the band
// path; configs/plate_zones (scripts/make_plate_zones_example.py, assembled by SfePy),
// the model's manifests and the three truths read with the same channels, and the
// model's full field follows the finer truth's at one modulus.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mcrewave/app/config.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/matrix_model_check.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

const std::string kPlate = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/";
const std::string kPlateZones = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate_zones/";

TEST(PlateExampleTest, BothMeshesReadAndPassTheChecks) {
  const MatrixModelData coarse = ReadMatrixModel(kPlate + "coarse/model.yaml");
  const MatrixModelData fine = ReadMatrixModel(kPlate + "fine/model.yaml");
  EXPECT_EQ(coarse.dofs(), 336);
  EXPECT_EQ(fine.dofs(), 1248);
  for (const MatrixModelData* data : {&coarse, &fine}) {
    ASSERT_EQ(data->zones.size(), 2u);
    EXPECT_EQ(data->zones[0].name, "matrix");
    EXPECT_EQ(data->zones[1].name, "inclusion");
    ASSERT_EQ(data->loads.size(), 1u);
    EXPECT_EQ(data->loads[0].channel, "F");
    EXPECT_NEAR(data->loads[0].vector.sum(), -1.0, 1e-14);  // a unit resultant along -y
    EXPECT_EQ(data->sensors.size(), 5u);
    // The clamped plate is stiff: K positive definite at any positive moduli.
    const SparseMatrix k = data->Stiffness(Vector::Constant(2, 200e9));
    EXPECT_EQ(CheckPositiveDefinite(k, "K"), "");
    // Total mass rho t L H, less the clamped column's share, in each direction:
    // 1'M1 over the x dofs.
    Vector ones_x = Vector::Zero(data->dofs());
    for (int i = 0; i < data->dofs(); i += 2) ones_x[i] = 1.0;
    const double mass = ones_x.dot(data->mass * ones_x);
    EXPECT_GT(mass, 0.9 * 7800.0 * 0.01 * 0.4 * 0.1);
    EXPECT_LT(mass, 7800.0 * 0.01 * 0.4 * 0.1);
  }
}

TEST(PlateExampleTest, SparseAndBandPathsAgreeOnTheCoarsePlate) {
  const MatrixModelData plate = ReadMatrixModel(kPlate + "coarse/model.yaml");
  const SparseMatrix k = plate.Stiffness((Vector(2) << 200e9, 100e9).finished());
  EXPECT_EQ(ChooseFactorization(Factorization::kAutomatic, plate.mass, k),
            Factorization::kSparse);  // half bandwidth 51
  const Eigen::RowVectorXd tip = Matrix(plate.sensors[0].row).row(0);
  double lowest_tip = 0.0;  // [m]
  const testing::SparseAndBandRun run = testing::RunSparseAndBandPaths(
      plate.mass, k, plate.loads[0].vector, 2e-7, 2000, 50,
      [&](const Vector& u) { lowest_tip = std::min(lowest_tip, tip.dot(u)); });
  const double worst = run.worst_difference, scale = run.max_displacement;
  EXPECT_LT(lowest_tip, -0.1 * scale);  // the -y impact moves the tip down
  std::printf("coarse plate, 2000 steps: sparse vs band %.2e of max |u| (%.3e m)\n", worst / scale,
              scale);
  EXPECT_LT(worst / scale, 1.4e-12);  // measured 1.4e-13
}

TEST(PlateZonesExampleTest, TheModelAndItsTruthsReadWithTheSameChannels) {
  const MatrixModelData full = ReadMatrixModel(kPlateZones + "model/full_field.yaml");
  const MatrixModelData points = ReadMatrixModel(kPlateZones + "model/points.yaml");
  const MatrixModelData candidates = ReadMatrixModel(kPlateZones + "model/candidates.yaml");
  for (const MatrixModelData* model : {&full, &points, &candidates}) {
    EXPECT_EQ(model->dofs(), 1248);
    ASSERT_EQ(model->zones.size(), 1u);
    EXPECT_EQ(model->elements.size(), 576u);  // 48 x 12, each with its centroid
    EXPECT_EQ(model->elements[0].position.size(), 2);
    ASSERT_EQ(model->loads.size(), 1u);
    EXPECT_NEAR(model->loads[0].vector.sum(), 1.0, 1e-14);  // a unit resultant along +x
  }
  EXPECT_EQ(full.sensors.size(), 1248u);  // ux, uy at every free node
  // ... and exx on the 48 x 13 horizontal element edges: each gauge reads the slope of a
  // field ux = 1e-3 x [m] (node (i, j) at x = i L / 48; dof 2 (j 48 + i - 1) + 0).
  ASSERT_EQ(candidates.sensors.size(), 1248u + 624u);
  Vector linear = Vector::Zero(1248);
  for (int dof = 0; dof < 1248; dof += 2) linear[dof] = 1e-3 * ((dof / 2) % 48 + 1) * 0.4 / 48;
  int gauges = 0;
  for (const MatrixModelSensor& sensor : candidates.sensors) {
    if (sensor.kind != SensorKind::kStrain) continue;
    ++gauges;
    // Measured: 7.8e-18 at worst (the rows' 17 digits).
    EXPECT_NEAR((sensor.row * linear)(0), 1e-3, 5e-17) << sensor.channel;
  }
  EXPECT_EQ(gauges, 624);
  ASSERT_EQ(points.sensors.size(), 10u);
  EXPECT_EQ(std::count_if(points.sensors.begin(), points.sensors.end(),
                          [](const MatrixModelSensor& s) { return s.kind == SensorKind::kStrain; }),
            5);
  const std::pair<const char*, std::size_t> truths[] = {
      {"soft_inclusion", 2}, {"two_inclusions", 3}, {"soft_band", 2}};
  for (const auto& [name, zones] : truths) {
    SCOPED_TRACE(name);
    const MatrixModelData truth = ReadMatrixModel(kPlateZones + "truth/" + name + ".yaml");
    EXPECT_EQ(truth.dofs(), 4800);
    EXPECT_EQ(truth.zones.size(), zones);
    EXPECT_EQ(truth.sensors.size(), 1872u + 10u);
    for (const MatrixModelData* model : {&full, &points, &candidates}) {
      for (const MatrixModelSensor& sensor : model->sensors) {
        EXPECT_TRUE(std::any_of(truth.sensors.begin(), truth.sensors.end(),
                                [&](const MatrixModelSensor& s) {
                                  return s.channel == sensor.channel && s.kind == sensor.kind;
                                }))
            << sensor.channel;
      }
    }
  }
}

// configs/plate_zones.yaml regroups the model's 576 elements into a 16 x 4 grid: 64
// zones of 3 x 3 elements, whose stiffness at 200 GPa is the manifest's K (the blocks
// summed in another order: measured 2.4e-16 of the largest entry apart).
TEST(PlateZonesExampleTest, TheConfigRegroupsTheModelInto64Zones) {
  const Config config = LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate_zones.yaml");
  EXPECT_EQ(config.zones.zoning, Zoning::kGrid);
  const MatrixModelData model = LoadMatrixModel(config);
  ASSERT_EQ(model.zones.size(), 64u);
  EXPECT_EQ(model.zones[0].name, "grid_0_0");
  EXPECT_EQ(model.zones[63].name, "grid_15_3");
  std::vector<int> count(64, 0);
  for (const MatrixModelElement& element : model.elements) ++count[element.zone];
  EXPECT_EQ(count, std::vector<int>(64, 9));
  const MatrixModelData manifest = ReadMatrixModel(kPlateZones + "model/full_field.yaml");
  const SparseMatrix difference =
      model.Stiffness(Vector::Constant(64, 200e9)) - manifest.Stiffness(Vector::Constant(1, 200e9));
  EXPECT_LT(difference.coeffs().cwiseAbs().maxCoeff(),
            3e-15 * manifest.zones[0].stiffness.coeffs().cwiseAbs().maxCoeff());
}

// The model (48 x 12) and the truth (96 x 24) at one modulus, 200 GPa everywhere, driven
// by the same half-sine: every channel of the model's full field and point sensors
// against the truth's channel of the same name. They differ by the coarse mesh's
// discretisation error alone (a channel named at the wrong node would differ by its
// whole size): measured 1.2 % rms over every displacement channel, checked to 3 %.
TEST(PlateZonesExampleTest, TheModelsFullFieldFollowsTheTruthsAtOneModulus) {
  MatrixModelData model = ReadMatrixModel(kPlateZones + "model/full_field.yaml");
  const MatrixModelData points = ReadMatrixModel(kPlateZones + "model/points.yaml");
  model.sensors.insert(model.sensors.end(), points.sensors.begin(), points.sensors.end());
  const MatrixModelData truth = ReadMatrixModel(kPlateZones + "truth/soft_inclusion.yaml");
  const int steps = 120;
  const double time_step = 1e-6;
  Matrix loads = Matrix::Zero(1, steps + 1);
  for (int j = 0; j <= steps; ++j) {
    const double t = j * time_step;
    loads(0, j) = t < 2e-5 ? 1000.0 * std::sin(M_PI * t / 2e-5) : 0.0;
  }
  const Matrix coarse =
      SimulateMatrixModel(model, Vector::Constant(1, 200e9), loads, time_step, 0.5);
  const Matrix fine = SimulateMatrixModel(truth, Vector::Constant(2, 200e9), loads, time_step, 0.5);
  double difference = 0.0, size = 0.0;
  for (std::size_t k = 0; k < model.sensors.size(); ++k) {
    std::size_t t = 0;
    while (truth.sensors[t].channel != model.sensors[k].channel) ++t;
    if (model.sensors[k].kind != SensorKind::kDisplacement) continue;
    difference +=
        (coarse.row(static_cast<Eigen::Index>(k)) - fine.row(static_cast<Eigen::Index>(t)))
            .squaredNorm();
    size += fine.row(static_cast<Eigen::Index>(t)).squaredNorm();
  }
  const double relative = std::sqrt(difference / size);
  EXPECT_GT(relative, 1e-3);
  EXPECT_LT(relative, 0.03);
}

}  // namespace
}  // namespace mcrewave
