// Tests of the zone-moduli objective of a structure given by matrices
// (mcre/matrix_zone_objective.h): the inverse crime on the coarse plate recovers
// both zones from the nominal start; a solve that fails is reported, not thrown.
#include "mcrewave/mcre/matrix_zone_objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::Weights;

// The coarse plate with data of its own model (inverse crime) at `truth`: a 20 us
// half-sine impact of 1 kN, 100 steps of 1 us.
struct PlateInverseCrime {
  explicit PlateInverseCrime(const Vector& truth)
      : plate(ReadMatrixModel(std::string(MCREWAVE_SOURCE_DIR) +
                              "/configs/plate/coarse/model.yaml")) {
    Matrix loads = Matrix::Zero(1, 101);
    for (int j = 0; j * 1e-6 < 2e-5; ++j) loads(0, j) = 1e3 * std::sin(M_PI * j / 20.0);
    const ChannelSet at_rest = MatrixChannelSet(
        plate, 1e-6, loads, Matrix::Zero(static_cast<int>(plate.sensors.size()), 101));
    MatrixMcreProblem simulation(plate, at_rest, Weights(0.01, 1.0), 2e11, 0.5);
    simulation.SetModuli(truth);
    data = MatrixChannelSet(plate, 1e-6, loads, simulation.ModelOutputs());
  }
  MatrixModelData plate;
  ChannelSet data;
};

TEST(MatrixZoneObjectiveTest, InverseCrimeOnThePlateRecoversBothZones) {
  const Vector truth = (Vector(2) << 2.1e11, 1.5e11).finished();
  PlateInverseCrime crime(truth);
  MatrixMcreProblem problem(crime.plate, crime.data, Weights(0.01, 1.0), 2e11, 0.5);
  CoupledSolverOptions inner;
  inner.tolerance = 1e-10;
  MatrixZoneObjective objective(&problem, inner);
  // At the truth e^2 = 0 to round-off (measured exactly 0).
  const double at_truth[2] = {std::log(truth[0] / 2e11), std::log(truth[1] / 2e11)};
  double cost = -1.0;
  ASSERT_TRUE(objective.Evaluate(at_truth, &cost, nullptr)) << objective.error_message();
  EXPECT_LT(cost, 1e-20);

  const BoundedMinimizerSummary summary = testing::MinimizeWithinHalfAndTwice(&objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const Vector found = objective.Moduli(summary.x.data());
  // Measured: 5.0e-12 (matrix) and 1.2e-12 (inclusion) off, in 14 evaluations; the
  // issue asks for 1e-6.
  for (int z = 0; z < 2; ++z) {
    EXPECT_NEAR(found[z], truth[z], 5e-11 * truth[z]) << crime.plate.zones[z].name;
  }
}

TEST(MatrixZoneObjectiveTest, AFailedSolveIsReportedNotThrown) {
  PlateInverseCrime crime((Vector(2) << 2e11, 2e11).finished());
  MatrixMcreProblem problem(crime.plate, crime.data, Weights(0.01, 1.0), 2e11, 0.5);
  CoupledSolverOptions inner;
  inner.max_iterations = 1;
  MatrixZoneObjective objective(&problem, inner);
  const double p[2] = {0.1, -0.2};
  double cost = -1.0, gradient[2] = {0.0, 0.0};
  EXPECT_FALSE(objective.Evaluate(p, &cost, gradient));
  EXPECT_NE(objective.error_message().find("coupled solve of evaluation 1 is not usable"),
            std::string::npos)
      << objective.error_message();
}

}  // namespace
}  // namespace mcrewave
