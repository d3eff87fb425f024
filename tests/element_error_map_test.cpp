// Tests of the element error map of a matrix model (mcre/element_error_map.h): the
// bar exported with its elements gives the bar's own map (mcre/error_map.h) from the
// same retrograde field at the same zone moduli; a tiny model against its closed form;
// the shifted quadratic form on a nearly rigid field.
#include "mcrewave/mcre/element_error_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mcrewave/model/matrix_export.h"
#include "reference/bar_error_map.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

// The retrograde field of the MCRE solution of a 60-element bar in three zones at
// moduli off the truth's, on 300 steps (the paper's Courant number), and the model.
struct BarField {
  BarModel model;
  Vector moduli;
  double time_step;
  Matrix retrograde;
};

BarField SolvedThreeZoneBar() {
  const testing::SmallCase c = testing::MakeSmallCase(60, 300, 20.0, 2);
  ZoneLayout layout;
  layout.zone_count = 3;
  BarField field{BarModel(c.bar, layout.ElementZones(c.bar)), Vector(3), c.time.step, Matrix()};
  const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  testing::BarMcreProblem problem(field.model, data, testing::Weights(0.01, 1.0), c.bar.modulus,
                                  0.5);
  field.moduli << 0.8 * c.bar.modulus, 1.1 * c.bar.modulus, 1.3 * c.bar.modulus;
  problem.SetModuli(field.moduli);
  const testing::Solved solved =
      testing::Solve(testing::Options(CoupledSolverType::kConjugateGradient, 1e-10), &problem);
  EXPECT_TRUE(solved.summary.IsSolutionUsable());
  field.retrograde = solved.solution.retrograde;
  EXPECT_GT(field.retrograde.cwiseAbs().maxCoeff(), 0.0);
  return field;
}

TEST(ElementErrorMapTest, TheExportedBarGivesTheBarsErrorMap) {
  const BarField bar = SolvedThreeZoneBar();
  const ErrorMap expected =
      testing::ComputeErrorMap(bar.model, bar.moduli, bar.retrograde, bar.time_step);
  // The elements exported at a nominal modulus of their own: E_z / E_z,nom rescales.
  const MatrixModelData exported = BarMatrixModel(bar.model, 2.1e11);
  const ErrorMap map = ComputeElementErrorMap(exported, bar.moduli, bar.retrograde, bar.time_step);
  ASSERT_EQ(map.share.size(), expected.share.size());
  EXPECT_EQ(map.position, expected.position);
  EXPECT_EQ(map.times, expected.times);
  EXPECT_EQ(map.density_position, expected.density_position);
  // Element by element, relative to the element's own share: measured 3.3e-16.
  double worst_share = 0.0;
  for (Eigen::Index e = 0; e < map.share.size(); ++e) {
    ASSERT_GT(expected.share[e], 0.0) << e;
    worst_share = std::max(worst_share, std::abs(map.share[e] / expected.share[e] - 1.0));
  }
  EXPECT_LT(worst_share, 4e-15);
  EXPECT_EQ(map.PeakElement(), expected.PeakElement());
  // The picture in J per element, the bar's in J/m: over h_e they agree to 3.0e-16 of
  // the largest density (measured).
  ASSERT_EQ(map.density.rows(), expected.density.rows());
  ASSERT_EQ(map.density.cols(), expected.density.cols());
  const Matrix per_length = map.density / bar.model.element_length();
  EXPECT_LT((per_length - expected.density).cwiseAbs().maxCoeff(),
            4e-15 * expected.density.cwiseAbs().maxCoeff());
}

// Three dofs, two elements of two zones (blocks whose rows do not sum to zero, the
// second's dofs out of order), three samples.
MatrixModelData TinyTwoElementModel() {
  MatrixModelData model;
  model.mass = SparseMatrix(3, 3);
  model.mass.setIdentity();
  model.stiffness_length = 1.0;
  model.length = 1.0;
  MatrixModelElement first, second;
  first.dofs = {0, 1};
  first.zone = 0;
  first.stiffness = (Matrix(2, 2) << 2.0, -1.0, -1.0, 3.0).finished();
  first.position = (Vector(2) << 0.25, 0.0).finished();
  second.dofs = {2, 1};
  second.zone = 1;
  second.stiffness = (Matrix(2, 2) << 4.0, 1.0, 1.0, 5.0).finished();
  second.position = (Vector(2) << 0.75, 1.0).finished();
  model.elements = {first, second};
  for (int z = 0; z < 2; ++z) {
    MatrixModelZone zone;
    zone.name = "zone" + std::to_string(z);
    zone.nominal_modulus = z == 0 ? 2e11 : 7e10;
    zone.stiffness = SparseMatrix(3, 3);
    model.zones.push_back(zone);
  }
  return model;
}

TEST(ElementErrorMapTest, ATinyModelGivesItsClosedForm) {
  const MatrixModelData model = TinyTwoElementModel();
  Matrix retrograde(3, 3);
  retrograde << 1.0, -1.0, 0.0,  //
      2.0, 0.5, 1.0,             //
      3.0, 2.0, -2.0;
  const Vector moduli = (Vector(2) << 4e11, 3.5e10).finished();  // factors 2 and 1/2
  const double h = 0.1;
  const ErrorMap map = ComputeElementErrorMap(model, moduli, retrograde, h, 2);
  // Element 0, 1/2 (2 a^2 - 2 a b + 3 b^2) at (a, b) = (1, 2), (-1, 0.5), (0, 1): 5,
  // 1.875, 1.5; times 2 h with c = (1/2, 1, 1/2): 2 * 0.1 * 5.125 = 1.025. Element 1,
  // 1/2 (4 a^2 + 2 a b + 5 b^2) at (3, 2), (2, 0.5), (-2, 1): 34, 9.625, 8.5; times
  // h / 2: 0.05 * 30.875 = 1.54375.
  ASSERT_EQ(map.share.size(), 2);
  EXPECT_NEAR(map.share[0], 1.025, 1e-15);
  EXPECT_NEAR(map.share[1], 1.54375, 1e-15);
  EXPECT_EQ(map.position, (Vector(2) << 0.25, 0.75).finished());
  // Two samples of m = 2 steps: stride 2, samples 0 and 2; one element a column.
  ASSERT_EQ(map.density.rows(), 2);
  ASSERT_EQ(map.density.cols(), 2);
  EXPECT_EQ(map.times, (Vector(2) << 0.0, 0.2).finished());
  EXPECT_NEAR(map.density(0, 0), 10.0, 1e-14);
  EXPECT_NEAR(map.density(0, 1), 17.0, 1e-14);
  EXPECT_NEAR(map.density(1, 0), 3.0, 1e-14);
  EXPECT_NEAR(map.density(1, 1), 4.25, 1e-14);
  EXPECT_NEAR(map.Fractions().sum(), 1.0, 1e-15);
}

TEST(ElementErrorMapTest, ElementsWithoutPositionsAreAtTheirIndex) {
  MatrixModelData model = TinyTwoElementModel();
  for (MatrixModelElement& element : model.elements) element.position.resize(0);
  EXPECT_EQ(ElementMapPositions(model), (Vector(2) << 0.0, 1.0).finished());
  EXPECT_EQ(ElementColumnPositions(model), (Vector(2) << 0.0, 1.0).finished());
}

TEST(ElementErrorMapTest, TheShiftedFormKeepsTheGapOfANearlyRigidField) {
  // A bar element under W = (1e8, 1e8 + 1e-3): 1/2 k (1e-3)^2 = 5e-7 k. The plain
  // form 1/2 W^T K W would lose it in round-off (W^T K W ~ 1e16 k eps ~ k).
  MatrixModelElement element;
  element.dofs = {1, 0};
  const double k = 3e9;
  element.stiffness = (Matrix(2, 2) << k, -k, -k, k).finished();
  const double retrograde[2] = {1e8 + 1e-3, 1e8};
  const double jump = retrograde[0] - retrograde[1];
  EXPECT_NEAR(ElementGapEnergy(element, retrograde), 0.5 * k * jump * jump,
              1e-15 * 0.5 * k * jump * jump);
}

}  // namespace
}  // namespace mcrewave
