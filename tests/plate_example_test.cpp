// The committed plate example (configs/plate, scripts/make_plate_example.py): both
// meshes read and pass every check, and the sparse path integrates them like the band
// path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/matrix_model_check.h"

namespace mcrewave {
namespace {

const std::string kPlate = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/";

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
  ThetaIntegratorOptions options;
  options.time_step = 2e-7;
  ThetaIntegrator band, sparse;
  options.factorization = Factorization::kBand;
  band.Init(plate.mass, k, options);
  options.factorization = Factorization::kSparse;
  sparse.Init(plate.mass, k, options);
  const int n = plate.dofs();
  Vector v1 = Vector::Zero(n), u1 = v1, v2 = v1, u2 = v1, v(n), u(n);
  const Eigen::RowVectorXd tip = Matrix(plate.sensors[0].row).row(0);
  double lowest_tip = 0.0;  // [m]
  double worst = 0.0, scale = 0.0;
  for (int step = 0; step < 2000; ++step) {
    const double load = step < 50 ? 1000.0 * std::sin(M_PI * step / 50.0) : 0.0;  // [N]
    band.Step(v1, u1, load * plate.loads[0].vector, v, u);
    v1 = v;
    u1 = u;
    sparse.Step(v2, u2, load * plate.loads[0].vector, v, u);
    v2 = v;
    u2 = u;
    worst = std::max(worst, (u1 - u2).cwiseAbs().maxCoeff());
    scale = std::max(scale, u1.cwiseAbs().maxCoeff());
    lowest_tip = std::min(lowest_tip, tip.dot(u1));
  }
  EXPECT_LT(lowest_tip, -0.1 * scale);  // the -y impact moves the tip down
  std::printf("coarse plate, 2000 steps: sparse vs band %.2e of max |u| (%.3e m)\n", worst / scale,
              scale);
  EXPECT_LT(worst / scale, 1.4e-12);  // measured 1.4e-13
}

}  // namespace
}  // namespace mcrewave
