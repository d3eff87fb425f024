// BarModel: the assembled M, K1, K = E K1 and B against their closed forms for
// linear elements, on a bar whose dimensions are all different from the defaults.
#include "mcrewave/model/bar_model.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace mcrewave {
namespace {

// L, S, rho, E of a steel-like bar, none a round number, and 13 elements.
BarProperties TestBar(MassType mass) {
  BarProperties bar;
  bar.length = 0.73;     // L [m]
  bar.section = 3.1e-4;  // S [m^2]
  bar.density = 7850.0;  // rho [kg/m^3]
  bar.modulus = 205e9;   // E [Pa]
  bar.elements = 13;     // N
  bar.mass = mass;
  return bar;
}

// Relative tolerance of sums over a few dozen entries of order one.
constexpr double kRoundOff = 1e-13;

// Nodal coordinates x_i = i L / N [m].
Vector NodalCoordinates(const BarModel& model) {
  return Vector::LinSpaced(model.num_nodes(), 0.0, model.properties().length);
}

class BarModelMassTest : public ::testing::TestWithParam<MassType> {};

TEST_P(BarModelMassTest, TotalMassIsRhoSL) {
  const BarProperties bar = TestBar(GetParam());
  const BarModel model(bar);
  const Matrix mass = Matrix(model.mass());
  ASSERT_EQ(mass.rows(), bar.elements + 1);
  ASSERT_EQ(mass.cols(), bar.elements + 1);
  // The sum of all entries is 1^T M 1, the kinetic energy form of a unit rigid velocity.
  const double total_mass = bar.density * bar.section * bar.length;  // [kg]
  EXPECT_NEAR(mass.sum(), total_mass, kRoundOff * total_mass);
  EXPECT_NEAR((mass - mass.transpose()).cwiseAbs().maxCoeff(), 0.0, kRoundOff * total_mass);
}

TEST_P(BarModelMassTest, EntriesAreThoseOfTheLinearElement) {
  const BarProperties bar = TestBar(GetParam());
  const BarModel model(bar);
  const Matrix mass = Matrix(model.mass());
  const int last = model.right_node();
  const double element_mass = bar.density * bar.section * bar.length / bar.elements;  // [kg]
  const bool consistent = GetParam() == MassType::kConsistent;
  // Consistent: rho S h_e / 6 [2 1; 1 2] per element; lumped: rho S h_e / 2 I.
  const double end_diagonal = consistent ? element_mass / 3.0 : element_mass / 2.0;
  const double off_diagonal = consistent ? element_mass / 6.0 : 0.0;
  EXPECT_NEAR(mass(0, 0), end_diagonal, kRoundOff * element_mass);
  EXPECT_NEAR(mass(last, last), end_diagonal, kRoundOff * element_mass);
  for (int i = 1; i < last; ++i) {
    EXPECT_NEAR(mass(i, i), 2.0 * end_diagonal, kRoundOff * element_mass) << "node " << i;
  }
  for (int i = 0; i < last; ++i) {
    EXPECT_NEAR(mass(i, i + 1), off_diagonal, kRoundOff * element_mass) << "node " << i;
  }
  // Tridiagonal: nothing beyond the first off-diagonal.
  for (int i = 0; i + 2 <= last; ++i) {
    EXPECT_EQ(mass.row(i).tail(last - i - 1).cwiseAbs().maxCoeff(), 0.0) << "row " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(ConsistentAndLumped, BarModelMassTest,
                         ::testing::Values(MassType::kConsistent, MassType::kLumped),
                         [](const ::testing::TestParamInfo<MassType>& info) {
                           return std::string(MassTypeToString(info.param));
                         });

// The consistent mass integrates v^2 exactly for a linear velocity v = x:
// v^T M v = rho S int_0^L x^2 dx = rho S L^3 / 3. The lumped mass does not (it gives
// rho S L^3 (1/3 + 1/(6 N^2))): the check tells the two apart.
TEST(BarModelTest, ConsistentMassIntegratesALinearVelocityExactly) {
  const BarProperties consistent = TestBar(MassType::kConsistent);
  const BarModel model(consistent);
  const Vector x = NodalCoordinates(model);
  const double exact =
      consistent.density * consistent.section * std::pow(consistent.length, 3) / 3.0;  // [kg m^2]
  EXPECT_NEAR(x.dot(model.mass() * x), exact, kRoundOff * exact);

  const BarModel lumped(TestBar(MassType::kLumped));
  const double lumped_value =
      exact * (1.0 + 0.5 / (consistent.elements * consistent.elements));  // [kg m^2]
  EXPECT_NEAR(x.dot(lumped.mass() * x), lumped_value, kRoundOff * exact);
}

TEST(BarModelTest, UnitStiffnessRowsSumToZero) {
  const BarProperties bar = TestBar(MassType::kConsistent);
  const BarModel model(bar);
  const Matrix unit_stiffness = Matrix(model.unit_stiffness());
  const double element_stiffness = bar.section * bar.elements / bar.length;  // S / h_e [m]
  // Rigid translations are in the kernel: K1 1 = 0, row by row.
  const Vector row_sums = unit_stiffness.rowwise().sum();
  EXPECT_LE(row_sums.cwiseAbs().maxCoeff(), kRoundOff * element_stiffness);
  // S / h_e [1 -1; -1 1] per element.
  const int last = model.right_node();
  EXPECT_NEAR(unit_stiffness(0, 0), element_stiffness, kRoundOff * element_stiffness);
  EXPECT_NEAR(unit_stiffness(last, last), element_stiffness, kRoundOff * element_stiffness);
  for (int i = 1; i < last; ++i) {
    EXPECT_NEAR(unit_stiffness(i, i), 2.0 * element_stiffness, kRoundOff * element_stiffness);
  }
  for (int i = 0; i < last; ++i) {
    EXPECT_NEAR(unit_stiffness(i, i + 1), -element_stiffness, kRoundOff * element_stiffness);
    EXPECT_NEAR(unit_stiffness(i + 1, i), -element_stiffness, kRoundOff * element_stiffness);
  }
}

TEST(BarModelTest, StiffnessIsTheModulusTimesTheUnitStiffness) {
  const BarProperties bar = TestBar(MassType::kConsistent);
  const BarModel model(bar);
  for (double modulus : {1e9, bar.modulus, 3.3e11}) {
    const Matrix stiffness = Matrix(model.Stiffness(modulus));
    const Matrix expected = modulus * Matrix(model.unit_stiffness());
    EXPECT_LE((stiffness - expected).cwiseAbs().maxCoeff(),
              kRoundOff * expected.cwiseAbs().maxCoeff())
        << "E = " << modulus;
  }
}

// A linear displacement has uniform strain, which linear elements represent exactly:
// u^T K u = int_0^L E S (u')^2 dx. For u = x / L (unit displacement of the end x = L,
// strain 1 / L) this is E S / L [N/m]; for u = x (strain 1), E S L [N m]; for a rigid
// translation, 0.
TEST(BarModelTest, StrainEnergyOfALinearDisplacementIsExact) {
  const BarProperties bar = TestBar(MassType::kConsistent);
  const BarModel model(bar);
  const SparseMatrix stiffness = model.Stiffness(bar.modulus);
  const Vector x = NodalCoordinates(model);
  const Vector unit_end_displacement = x / bar.length;
  const double axial_stiffness = bar.modulus * bar.section / bar.length;  // E S / L [N/m]
  EXPECT_NEAR(unit_end_displacement.dot(stiffness * unit_end_displacement), axial_stiffness,
              kRoundOff * axial_stiffness);
  const double unit_strain = bar.modulus * bar.section * bar.length;  // E S L [N m]
  EXPECT_NEAR(x.dot(stiffness * x), unit_strain, kRoundOff * unit_strain);
  const Vector translation = Vector::Constant(model.num_nodes(), 2.5e-3);  // [m]
  EXPECT_NEAR(translation.dot(stiffness * translation), 0.0,
              kRoundOff * axial_stiffness * translation.squaredNorm());
}

TEST(BarModelTest, BoundarySelectorPicksTheTwoEndNodes) {
  const BarModel model(TestBar(MassType::kConsistent));
  EXPECT_EQ(model.left_node(), 0);
  EXPECT_EQ(model.right_node(), model.num_elements());
  const Matrix selector = Matrix(model.boundary_selector());
  // B = e_0 e_0^T + e_N e_N^T.
  Matrix expected = Matrix::Zero(model.num_nodes(), model.num_nodes());
  expected(model.left_node(), model.left_node()) = 1.0;
  expected(model.right_node(), model.right_node()) = 1.0;
  EXPECT_EQ(selector, expected);
  // B u keeps u_0 and u_N and zeroes the interior.
  const Vector u = Vector::LinSpaced(model.num_nodes(), 1.0, 2.0);
  const Vector selected = model.boundary_selector() * u;
  EXPECT_EQ(selected[0], u[0]);
  EXPECT_EQ(selected[model.right_node()], u[model.right_node()]);
  EXPECT_EQ(selected.segment(1, model.num_nodes() - 2).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BarModelTest, GeometryAndWaveSpeed) {
  const BarProperties bar = TestBar(MassType::kLumped);
  const BarModel model(bar);
  EXPECT_EQ(model.num_elements(), 13);
  EXPECT_EQ(model.num_nodes(), 14);
  EXPECT_NEAR(model.element_length(), 0.73 / 13.0, 1e-16);
  // c = sqrt(E / rho) [m/s]: 5110.249 m/s for 205 GPa and 7850 kg/m^3.
  EXPECT_NEAR(model.WaveSpeed(205e9), 5110.249, 1e-3);
  EXPECT_NEAR(model.WaveSpeed(4.0 * 205e9), 2.0 * model.WaveSpeed(205e9), 1e-9);
}

TEST(BarPropertiesTest, InvalidPropertiesAreRefusedWithTheKey) {
  std::string why;
  EXPECT_TRUE(TestBar(MassType::kConsistent).IsValid(&why)) << why;
  BarProperties bar = TestBar(MassType::kConsistent);
  bar.section = 0.0;
  EXPECT_FALSE(bar.IsValid(&why));
  EXPECT_NE(why.find("model.section"), std::string::npos) << why;
  bar = TestBar(MassType::kConsistent);
  bar.density = std::nan("");
  EXPECT_FALSE(bar.IsValid(&why));
  EXPECT_NE(why.find("model.density"), std::string::npos) << why;
  bar = TestBar(MassType::kConsistent);
  bar.elements = 0;
  EXPECT_FALSE(bar.IsValid(&why));
  EXPECT_NE(why.find("model.elements"), std::string::npos) << why;
}

}  // namespace
}  // namespace mcrewave

namespace mcrewave {
namespace {

BarProperties TenElementBar() {
  BarProperties bar;
  bar.elements = 10;  // h_e = 0.1 m
  return bar;
}

TEST(BarZonesTest, ElementsBelongToTheZoneOfTheirMidpoint) {
  const BarProperties bar = TenElementBar();
  ZoneLayout layout;
  layout.zone_count = 3;  // boundaries 1/3, 2/3: midpoints 0.05 .. 0.95
  EXPECT_EQ(layout.Validate(bar), "");
  EXPECT_EQ(layout.ElementZones(bar), (std::vector<int>{0, 0, 0, 1, 1, 1, 1, 2, 2, 2}));
  layout.zoning = Zoning::kBoundaries;
  layout.zone_boundaries = {0.6, 0.7};
  EXPECT_EQ(layout.Validate(bar), "");
  EXPECT_EQ(layout.ElementZones(bar), (std::vector<int>{0, 0, 0, 0, 0, 0, 1, 2, 2, 2}));
  layout.zoning = Zoning::kPerElement;
  EXPECT_EQ(layout.ElementZones(bar), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  // A grid of one count along the bar: equal zones.
  layout.zoning = Zoning::kGrid;
  layout.zone_grid = {3};
  EXPECT_EQ(layout.Validate(bar), "");
  EXPECT_EQ(layout.ElementZones(bar), (std::vector<int>{0, 0, 0, 1, 1, 1, 1, 2, 2, 2}));
  layout.zone_grid = {3, 2};
  EXPECT_NE(layout.Validate(bar).find("model.zone_grid must hold one count"), std::string::npos);
  layout.zone_grid = {11};
  EXPECT_NE(layout.Validate(bar).find("model.zone_grid must hold one count"), std::string::npos);
}

TEST(BarZonesTest, LayoutsWithoutAnElementInAZoneAreRefusedNamingTheKey) {
  const BarProperties bar = TenElementBar();
  ZoneLayout layout;
  layout.zone_count = 11;
  EXPECT_NE(layout.Validate(bar).find("model.zone_count"), std::string::npos);
  layout.zoning = Zoning::kBoundaries;
  layout.zone_boundaries = {0.61, 0.64};  // no midpoint in [0.61, 0.64)
  EXPECT_NE(layout.Validate(bar).find("holds no element"), std::string::npos);
  layout.zone_boundaries = {0.7, 0.6};
  EXPECT_NE(layout.Validate(bar).find("model.zone_boundaries[1]"), std::string::npos);
  layout.zone_boundaries = {1.2};
  EXPECT_NE(layout.Validate(bar).find("model.zone_boundaries[0]"), std::string::npos);
}

TEST(BarZonesTest, ZoneStiffnessIsTheSumOfScaledZoneMatrices) {
  const BarProperties bar = TenElementBar();
  ZoneLayout layout;
  layout.zone_count = 2;
  const BarModel model(bar, layout.ElementZones(bar));
  ASSERT_EQ(model.num_zones(), 2);
  Vector moduli(2);
  moduli << 100e9, 300e9;
  const Matrix k = Matrix(model.Stiffness(moduli));
  // Node 5 joins element 4 (zone 0) and element 5 (zone 1): (E_0 + E_1) S / h_e.
  EXPECT_DOUBLE_EQ(k(5, 5), (100e9 + 300e9) * bar.section / 0.1);
  EXPECT_DOUBLE_EQ(k(2, 3), -100e9 * bar.section / 0.1);
  EXPECT_DOUBLE_EQ(k(7, 8), -300e9 * bar.section / 0.1);
  // Equal moduli: E K1.
  EXPECT_LT(
      (Matrix(model.Stiffness(Vector::Constant(2, 2e11))) - Matrix(model.Stiffness(2e11))).norm(),
      1e-6 * k.norm());
}

TEST(BarZonesTest, TruthModuliPutPartlyCoveredElementsInSeries) {
  const BarProperties bar = TenElementBar();
  // A zone of 100 GPa over [0.6, 0.75]: element 6 fully, element 7 half covered.
  const Vector moduli = ElementModuli(bar, {{0.6, 0.75, 100e9}});
  EXPECT_DOUBLE_EQ(moduli[5], bar.modulus);
  EXPECT_DOUBLE_EQ(moduli[6], 100e9);
  // 1 / E = 0.5 / 100 GPa + 0.5 / 200 GPa.
  // Measured exact (the pieces' lengths carry the round-off of 0.75 - 0.7, which once
  // gave 7e-16).
  EXPECT_NEAR(moduli[7], 1.0 / (0.5 / 100e9 + 0.5 / 200e9), 2e-15 * moduli[7]);
  EXPECT_DOUBLE_EQ(moduli[8], bar.modulus);
  EXPECT_NE(
      ValidateModulusZones(bar, {{0.5, 1.5, 1e9}}, "data.truth_zones").find("data.truth_zones[0]"),
      std::string::npos);
}

TEST(BarZonesTest, AZonesTruthModulusIsItsElementsInSeries) {
  const BarProperties bar = TenElementBar();
  ZoneLayout layout;
  layout.zone_count = 2;
  const BarModel model(bar, layout.ElementZones(bar));
  Vector element_moduli = Vector::Constant(10, 200e9);
  element_moduli.head(5) << 300e9, 100e9, 100e9, 100e9, 100e9;
  const std::vector<double> zones = ZoneModuliInSeries(model, element_moduli);
  ASSERT_EQ(zones.size(), 2u);
  // 1 / E_0 = (1 / 300 + 4 / 100) / 5 per GPa: 115.38 GPa, not the arithmetic 140 GPa.
  EXPECT_NEAR(zones[0], 5.0 / (1.0 / 300e9 + 4.0 / 100e9), 1e-15 * zones[0]);
  EXPECT_NEAR(zones[1], 200e9, 1e-15 * 200e9);  // measured 1 ulp off
}

TEST(BarSensorsTest, RowsInterpolateDisplacementAndDifferentiateForStrain) {
  const BarModel model(TenElementBar());
  // A linear field u = 2 x + 1: u(0.25) = 1.5, strain 2 everywhere.
  Vector u(11);
  for (int i = 0; i <= 10; ++i) u[i] = 2.0 * model.node_position(i) + 1.0;
  EXPECT_NEAR(model.DisplacementRow(0.25).Apply(u.data()), 1.5, 1e-15);
  EXPECT_NEAR(model.DisplacementRow(1.0).Apply(u.data()), 3.0, 1e-15);
  EXPECT_NEAR(model.StrainRow(0.65).Apply(u.data()), 2.0, 1e-13);
  EXPECT_NEAR(model.StrainRow(0.0).Apply(u.data()), 2.0, 1e-13);
  // A node belongs to the element on its right; x = L to the last element.
  EXPECT_EQ(model.ElementAt(0.3), 3);
  EXPECT_EQ(model.ElementAt(1.0), 9);
  EXPECT_EQ(model.StrainRow(0.35).nodes[0], 3);
}

// u = x^2, strain 2 x: a gauge on an interior node reads the mean of its two elements,
// exact there; inside an element, that element's strain, exact at its midpoint; at the
// ends, the end element's, h_e off.
TEST(BarSensorsTest, AGaugeOnANodeReadsBothItsElements) {
  const BarModel model(TenElementBar());
  Vector u(11);
  for (int i = 0; i <= 10; ++i) u[i] = model.node_position(i) * model.node_position(i);
  EXPECT_EQ(model.StrainRow(0.3).nodes[0], 2);
  EXPECT_EQ(model.StrainRow(0.3).nodes[1], 4);
  // 0.3 / 0.1 = 2.9999999999999996 and 0.1 * 3 / 0.1 = 3.0000000000000004: both the node.
  EXPECT_NEAR(model.StrainRow(0.3).Apply(u.data()), 0.6, 1e-13);
  EXPECT_NEAR(model.StrainRow(0.1 * 3).Apply(u.data()), 0.6, 1e-13);
  EXPECT_NEAR(model.StrainRow(0.35).Apply(u.data()), 0.7, 1e-13);
  EXPECT_NEAR(model.StrainRow(0.31).Apply(u.data()), 0.7, 1e-13);
  EXPECT_NEAR(model.StrainRow(0.0).Apply(u.data()), 0.1, 1e-13);
  EXPECT_NEAR(model.StrainRow(1.0).Apply(u.data()), 1.9, 1e-13);
}

}  // namespace
}  // namespace mcrewave
