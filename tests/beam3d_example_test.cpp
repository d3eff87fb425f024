// The committed 3-D example, configs/beam3d (scripts/make_beam3d_example.py, trilinear
// hexahedra assembled by SfePy): the model reads with its four zones, nine sensors and
// element centroids in three coordinates; its static axial stiffness is the bar's E A / L;
// the sparse and band integrators agree on it; the streaming CG solves its coupled problem
// as the stored-field CG does; and configs/beam3d.yaml identifies its four zones.
#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::RunIdentify;
using testing::SourcePath;
using testing::ZoneModulus;

constexpr double kLength = 0.72, kArea = 0.03 * 0.03;  // [m], [m^2]

const MatrixModelData& Beam() {
  static const MatrixModelData beam = ReadMatrixModel(SourcePath("configs/beam3d/model.yaml"));
  return beam;
}

int SensorIndex(const MatrixModelData& model, const std::string& channel) {
  for (std::size_t k = 0; k < model.sensors.size(); ++k) {
    if (model.sensors[k].channel == channel) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no sensor " << channel;
  return 0;
}

TEST(Beam3dExampleTest, TheModelReadsWithFourZonesNineSensorsAndPositionsInThreeCoordinates) {
  const MatrixModelData& beam = Beam();
  EXPECT_EQ(beam.dofs(), 648);  // 24 free cross-sections of 3 x 3 nodes, 3 dofs each
  ASSERT_EQ(beam.zones.size(), 4u);
  EXPECT_EQ(beam.zones[0].name, "s1");
  EXPECT_EQ(beam.zones[3].name, "s4");
  ASSERT_EQ(beam.sensors.size(), 9u);
  EXPECT_EQ(std::count_if(beam.sensors.begin(), beam.sensors.end(),
                          [](const MatrixModelSensor& s) { return s.kind == SensorKind::kStrain; }),
            6);
  ASSERT_EQ(beam.elements.size(), 96u);
  EXPECT_EQ(beam.elements[0].position.size(), 3);
  ASSERT_EQ(beam.loads.size(), 1u);
  // A unit resultant along (1, 0.5, 0.25) / |.|: the components sum to 1.75 / 1.1456.
  EXPECT_NEAR(beam.loads[0].vector.sum(), 1.75 / std::sqrt(1.3125), 1e-14);
  // The consistent mass over the free nodes' x dofs: rho L B H less what the eliminated
  // face's row and column held, 2/3 of an element's mass along x, 1 - 2 / (3 x 24).
  // Measured 1 - 1/36 to 2e-15.
  Vector ones_x = Vector::Zero(beam.dofs());
  for (int i = 0; i < beam.dofs(); i += 3) ones_x[i] = 1.0;
  const double mass = ones_x.dot(beam.mass * ones_x);
  EXPECT_NEAR(mass / (7800.0 * kLength * kArea), 1.0 - 1.0 / 36.0, 2e-14);
}

// Static response to the load's axial component F_x: the tip's mean axial displacement
// is a bar's F_x L / (E A), stiffened a little by the clamp, which holds the Poisson
// contraction of the first cross-section. Measured 0.9961 of the bar's (the centre
// node; the trilinear elements represent a uniform axial strain exactly).
TEST(Beam3dExampleTest, TheStaticAxialStiffnessIsTheBarsEAOverL) {
  const MatrixModelData& beam = Beam();
  const SparseMatrix k = beam.Stiffness(beam.NominalModuli());
  const Eigen::SimplicialLDLT<SparseMatrix> factor(k);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const Vector u = factor.solve(beam.loads[0].vector);
  const double axial_force = 1.0 / std::sqrt(1.3125);  // [N], F_x of the unit resultant
  const double tip = (beam.sensors[SensorIndex(beam, "ux_tip")].row * u)(0);
  const double bar = axial_force * kLength / (200e9 * kArea);
  std::printf("static tip ux / bar's F_x L / (E A): %.6f\n", tip / bar);
  EXPECT_NEAR(tip / bar, 1.0, 0.006);
}

// The theta method on the sparse and the band factorisations, 600 steps of the half-sine
// impact: the same displacements to round-off (measured 7.8e-14 of max |u|).
TEST(Beam3dExampleTest, SparseAndBandPathsAgree) {
  const MatrixModelData& beam = Beam();
  const SparseMatrix k = beam.Stiffness(beam.NominalModuli());
  const testing::SparseAndBandRun run =
      testing::RunSparseAndBandPaths(beam.mass, k, beam.loads[0].vector, 1e-6, 600, 40);
  const double worst = run.worst_difference, scale = run.max_displacement;
  std::printf("beam, 600 steps: sparse vs band %.2e of max |u| (%.3e m)\n", worst / scale, scale);
  EXPECT_LT(worst / scale, 3e-13);
}

// One coupled solve of configs/beam3d.yaml's problem (its synthetic data, SNR 20) at
// moduli off the truth's, by the streaming CG and by the stored-field CG, both to 1e-11.
// Measured: e^2 1.9e-14 apart (relative), the zone gradients 1.5e-12 of their norm,
// the zone maps 8.4e-13 (21 and 20 iterations).
TEST(Beam3dExampleTest, TheStreamingSolveIsTheStoredFieldSolve) {
  const Config config = LoadConfig(SourcePath("configs/beam3d.yaml"));
  const MatrixModelData model = LoadMatrixModel(config);
  const ChannelSet data = LoadMatrixMeasurements(config, model).histories;
  MatrixMcreProblem problem(model, data, config.mcre.weights, config.mcre.reference_modulus,
                            config.time.theta, Factorization::kAutomatic, config.mcre.clamp);
  problem.SetModuli((Vector(4) << 1.9e11, 1.9e11, 1.7e11, 2.0e11).finished());
  CoupledSolverOptions options = config.inner;
  options.tolerance = 1e-11;
  options.type = CoupledSolverType::kConjugateGradient;
  CoupledSolution stored, streamed;
  const CoupledSolverSummary stored_summary = SolveCoupled(options, &problem, nullptr, &stored);
  ASSERT_TRUE(stored_summary.IsSolutionUsable()) << stored_summary.FullReport();
  options.type = CoupledSolverType::kStreamingConjugateGradient;
  const CoupledSolverSummary streamed_summary = SolveCoupled(options, &problem, nullptr, &streamed);
  ASSERT_TRUE(streamed_summary.IsSolutionUsable()) << streamed_summary.FullReport();
  const double cost = std::abs(streamed.cost - stored.cost) / stored.cost;
  const double gradients =
      (streamed.cost_gradients - stored.cost_gradients).norm() / stored.cost_gradients.norm();
  const Vector stored_zones = problem.ZoneErrorMap(stored.retrograde);
  const double zones = (streamed.zone_error_map - stored_zones).norm() / stored_zones.norm();
  std::printf("beam: streamed vs stored e^2 %.2e, gradients %.2e, zone maps %.2e (%d, %d its)\n",
              cost, gradients, zones, streamed_summary.iterations, stored_summary.iterations);
  EXPECT_LT(cost, 1e-13);
  EXPECT_LT(gradients, 1e-11);
  EXPECT_LT(zones, 5e-12);
}

// `identify run configs/beam3d.yaml` as committed: the four zones from the tip's three
// displacements and six gauges at SNR 20. Measured: -0.022, -0.050, -0.175 and
// +0.236 % off the truth (about 35 s).
TEST(Beam3dExampleTest, TheConfigIdentifiesTheFourZones) {
  const std::string dir = FreshDirectory("beam3d_run");
  const testing::RunResult run =
      RunIdentify("run " + SourcePath("configs/beam3d.yaml") + " -q -o " + dir);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const double truth[] = {200e9, 180e9, 150e9, 210e9};
  for (int z = 0; z < 4; ++z) {
    EXPECT_NEAR(ZoneModulus(dir + "/zones.csv", z) / truth[z] - 1.0, 0.0, 0.01) << "zone " << z;
  }
}

}  // namespace
}  // namespace mcrewave
