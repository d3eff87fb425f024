// Tests of supports on structures given by matrices (model/matrix_export.h
// MatrixModelSupport, mcre/matrix_mcre_problem.h, docs/matrix_models.md section 11):
// the bar exported with its clamp as a support gives, under each treatment (measured,
// trusted, pinned), the built-in bar's sweeps, e^2 and zone gradients to the bit; the trusted
// gradient matches central differences on a small 2-D-like lattice; the all-at-once
// solver agrees with CG under every treatment; the bar's trusted reaction averaged over
// model.reaction_length is the mean axial force, its gradients match central differences,
// and it keeps the inner iterations off the mesh; the sensitivity map per element sums
// to the zone gradients and matches central differences; the manifest round trip; each bad
// support refused with a message naming it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/data/matrix_market.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::RelativeDifference;
using testing::SmallCase;
using testing::SupportedLattice;
using testing::SupportedLatticeHistories;
using testing::Weights;

CoupledSolverOptions SupportsTightSolver(CoupledSolverType type) {
  CoupledSolverOptions options;
  options.type = type;
  options.tolerance = 1e-12;
  return options;
}

// The all-at-once solution of `problem` at `moduli`, its zone gradients checked against
// central differences of e^2 (steps 1e-5 E_z) to `tolerance`, relative.
CoupledSolution SolveCheckingGradientsByCentralDifferences(MatrixMcreProblem* problem,
                                                           const Vector& moduli, double tolerance) {
  auto solve = [&](const Vector& at) {
    problem->SetModuli(at);
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(
        SupportsTightSolver(CoupledSolverType::kAllAtOnce), problem, nullptr, &solution);
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    return solution;
  };
  const CoupledSolution at = solve(moduli);
  for (int z = 0; z < moduli.size(); ++z) {
    const double step = 1e-5 * moduli[z];
    Vector plus = moduli, minus = moduli;
    plus[z] += step;
    minus[z] -= step;
    const double difference = (solve(plus).cost - solve(minus).cost) / (2.0 * step);
    EXPECT_NEAR(at.cost_gradients[z], difference, tolerance * std::abs(difference)) << "zone " << z;
  }
  return at;
}

// MatrixMcreProblem::ModelChannels of a solution of the exported bar (30 elements,
// sensors u@0.25 and e@0.65, maybe u@0.02) against the built-in bar's own reading of the
// same fields: U at the ends and at the sensors (interpolated between nodes), the end
// loads F = F~ - W / alpha (alpha_0 at a pinned clamp), a trusted clamp's reaction.
void ExpectTheBarsModelChannels(const ChannelSet& channels, testing::BarMcreProblem& bar,
                                const CoupledSolution& solution, const ChannelSet& data,
                                ClampModel clamp) {
  const Matrix& u = solution.displacement;
  const Matrix& w = solution.retrograde;
  const int last = static_cast<int>(u.rows()) - 1;
  const double h = 1.0 / last;  // the bar's element length [m] (L = 1 m)
  // The exact reads: unit rows and the loads' one coefficient 1.
  EXPECT_TRUE(channels.Values("u0") == u.row(0).transpose());
  EXPECT_TRUE(channels.Values("uL") == u.row(last).transpose());
  EXPECT_TRUE(channels.Values("fL") == data.Values("fL") - w.row(last).transpose() / bar.alpha());
  Vector f0(u.cols());
  for (int j = 0; j < u.cols(); ++j) {
    switch (clamp) {
      case ClampModel::kMeasured:
        f0[j] = data.Values("f0")[j] - w(0, j) / bar.alpha();
        break;
      case ClampModel::kPinned:
        f0[j] = data.Values("f0")[j] - bar.inverse_alpha0() * w(0, j);
        break;
      case ClampModel::kTrusted:
        f0[j] = bar.ClampReaction(u.col(j).data());
        break;
    }
  }
  // Measured at most 3.2e-17 apart, relative (1 / alpha_0 and the bar's f0 gain over
  // alpha_0; the reaction row's sums).
  EXPECT_LT(RelativeDifference(channels.Values("f0"), f0), 3e-16);
  // u@0.25 midway between nodes 7 and 8 and u@0.02 in element 0 (the same products: the
  // same bits), e@0.65 in element 19 (the row's 1 / h against a division by h: measured
  // 1.2e-15 apart).
  const Vector displacement = 0.5 * (u.row(7) + u.row(8)).transpose();
  EXPECT_TRUE(channels.Values("u@0.25") == displacement);
  const Vector strain = (u.row(20) - u.row(19)).transpose() / h;
  EXPECT_LT(RelativeDifference(channels.Values("e@0.65"), strain), 1.2e-14);
  if (channels.Find("u@0.02") >= 0) {
    const Vector first = (0.4 * u.row(0) + 0.6 * u.row(1)).transpose();
    EXPECT_TRUE(channels.Values("u@0.02") == first);
  }
}

// The built-in bar with the clamp `clamp` against the bar exported with its clamp as
// a support (dof 0, channels f0, u0; through Matrix Market) and the same treatment: 30
// elements in `num_zones` zones, interior sensors u@0.25 and e@0.65, and with
// `first_element_sensor` u@0.02 too (in the first element: its node-0 coefficient is
// dropped under a trusted clamp). BarMcreProblem computes as MatrixMcreProblem does
// (docs/matrix_models.md section 6): the same bits, but for W when u@0.02 is there, whose
// retrograde loads share dofs 0 and 1 with u0 or the reaction (the bar adds them one by
// one, the matrix problem as one sum per dof). Measured at most (the three treatments,
// 1 and 3 zones) W 1.1e-14 apart, relative.
void ExpectBarSupportIsTheBuiltInClamp(int num_zones, ClampModel clamp, bool first_element_sensor) {
  SCOPED_TRACE(std::string(ClampModelToString(clamp)) + ", " + std::to_string(num_zones) +
               " zones" + (first_element_sensor ? ", u@0.02" : ""));
  SmallCase c = MakeSmallCase(30, 240, 20.0, 2);
  c.data.sensors = {"u@0.25", "e@0.65"};
  std::vector<BarSensor> sensors = {{SensorKind::kDisplacement, 0.25}, {SensorKind::kStrain, 0.65}};
  if (first_element_sensor) {
    c.data.sensors.insert(c.data.sensors.begin(), "u@0.02");
    sensors.insert(sensors.begin(), {SensorKind::kDisplacement, 0.02});
  }
  std::vector<int> zones(30);
  for (int e = 0; e < 30; ++e) zones[e] = e * num_zones / 30;
  const BarModel model(c.bar, zones);
  const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  const std::string folder =
      testing::FreshDirectory("bar_support_" + std::string(ClampModelToString(clamp)) +
                              std::to_string(num_zones) + (first_element_sensor ? "_first" : ""));
  const MatrixModelData matrices = ReadMatrixModel(WriteMatrixModel(
      folder, BarMatrixModel(model, c.bar.modulus, sensors, BarClampExport::kSupport)));
  ASSERT_EQ(matrices.supports.size(), 1u);
  McreWeights weights = Weights(0.01, 1.0);
  weights.strain_weight = 0.003;
  testing::BarMcreProblem bar(model, data, weights, 200e9, 0.5, {}, clamp);
  MatrixMcreProblem general(matrices, data, weights, 200e9, 0.5, Factorization::kAutomatic, clamp);
  Vector moduli = Vector::Constant(num_zones, 187.3e9);
  if (num_zones == 3) moduli << 181.7e9, 203.1e9, 229.9e9;
  bar.SetModuli(moduli);
  general.SetModuli(moduli);
  EXPECT_TRUE(Matrix(general.StiffnessMatrix()) == Matrix(bar.StiffnessMatrix()));
  auto expect_same_retrograde = [first_element_sensor](const Matrix& general_w,
                                                       const Matrix& bar_w) {
    if (first_element_sensor) {
      EXPECT_LT(RelativeDifference(general_w, bar_w), 1e-13);
    } else {
      EXPECT_TRUE(general_w == bar_w);
    }
  };

  // One sweep of each kind from the same input, single and batched, then the inner
  // product, the cost, the zone gradients and J_rest of the same fields.
  Matrix w = bar.ZeroField(), u_bar, u_general, w_bar, w_general;
  bar.RetrogradeSweep(bar.ZeroField(), true, &w);
  bar.DirectSweep(w, true, &u_bar);
  general.DirectSweep(w, true, &u_general);
  EXPECT_TRUE(u_general == u_bar);
  bar.DirectSweep(w, false, &u_bar);
  general.DirectSweep(w, false, &u_general);
  EXPECT_TRUE(u_general == u_bar);
  bar.RetrogradeSweep(u_bar, false, &w_bar);
  general.RetrogradeSweep(u_bar, false, &w_general);
  expect_same_retrograde(w_general, w_bar);
  bar.RetrogradeSweep(u_bar, true, &w_bar);
  general.RetrogradeSweep(u_bar, true, &w_general);
  expect_same_retrograde(w_general, w_bar);
  Matrix batch_bar[3], batch_general[3];
  bar.DirectSweepsWithData({&w, nullptr}, {&batch_bar[0], &batch_bar[1]});
  general.DirectSweepsWithData({&w, nullptr}, {&batch_general[0], &batch_general[1]});
  EXPECT_TRUE(batch_general[0] == batch_bar[0] && batch_general[1] == batch_bar[1]);
  const Matrix data_response = batch_bar[1];
  bar.RetrogradeSweepsWithData({&u_bar, &data_response, nullptr},
                               {&batch_bar[0], &batch_bar[1], &batch_bar[2]});
  general.RetrogradeSweepsWithData({&u_bar, &data_response, nullptr},
                                   {&batch_general[0], &batch_general[1], &batch_general[2]});
  for (int b = 0; b < 3; ++b) expect_same_retrograde(batch_general[b], batch_bar[b]);
  EXPECT_EQ(general.InnerProduct(w_bar, w), bar.InnerProduct(w_bar, w));
  EXPECT_EQ(general.Cost(u_bar, w_bar), bar.Cost(u_bar, w_bar));
  Vector gradient_bar, gradient_general;
  bar.CostGradients(u_bar, w_bar, &gradient_bar);
  general.CostGradients(u_bar, w_bar, &gradient_general);
  EXPECT_TRUE(gradient_general == gradient_bar);
  EXPECT_EQ(general.RestCost(), bar.RestCost());

  // Each solved by the all-at-once solver, which assembles the space-time system from the
  // problems' operators (no sweep): the same bits. And by CG from the same start: the
  // same bits when the sweeps are.
  for (const CoupledSolverType type :
       {CoupledSolverType::kAllAtOnce, CoupledSolverType::kConjugateGradient}) {
    if (type == CoupledSolverType::kConjugateGradient && first_element_sensor) continue;
    CoupledSolution bar_solution, general_solution;
    const CoupledSolverSummary bar_summary =
        SolveCoupled(SupportsTightSolver(type), &bar, &w, &bar_solution);
    ASSERT_TRUE(bar_summary.IsSolutionUsable()) << bar_summary.FullReport();
    const CoupledSolverSummary general_summary =
        SolveCoupled(SupportsTightSolver(type), &general, &w, &general_solution);
    ASSERT_TRUE(general_summary.IsSolutionUsable()) << general_summary.FullReport();
    EXPECT_TRUE(general_solution.displacement == bar_solution.displacement);
    EXPECT_TRUE(general_solution.retrograde == bar_solution.retrograde);
    EXPECT_EQ(general_solution.cost, bar_solution.cost);
    EXPECT_TRUE(general_solution.cost_gradients == bar_solution.cost_gradients);
    // J_rest bounds e^2.
    EXPECT_GT(general.RestCost(), general_solution.cost);
    ExpectTheBarsModelChannels(general.ModelChannels(general_solution), bar, bar_solution, data,
                               clamp);
  }
}

TEST(MatrixSupportsTest, BarClampAsASupportIsTheBuiltInClampUnderEveryTreatment) {
  for (const ClampModel clamp :
       {ClampModel::kTrusted, ClampModel::kPinned, ClampModel::kMeasured}) {
    for (const int zones : {1, 3}) {
      for (const bool first_element_sensor : {false, true}) {
        ExpectBarSupportIsTheBuiltInClamp(zones, clamp, first_element_sensor);
      }
    }
  }
}

TEST(MatrixSupportsTest, TrustedGradientMatchesCentralDifferencesOnALattice) {
  const MatrixModelData lattice = SupportedLattice();
  const ChannelSet data = SupportedLatticeHistories(lattice);
  McreWeights weights = Weights(0.01, 1.0);
  weights.reaction_weight = 0.1;  // the reaction's term large enough to matter
  MatrixMcreProblem problem(lattice, data, weights, 2e11, 0.5, Factorization::kSparse,
                            ClampModel::kTrusted);
  const Vector moduli = (Vector(2) << 1.8e11, 2.1e11).finished();
  // Measured: 1.5e-9 (zone 0) and 4.6e-10 (zone 1), relative.
  const CoupledSolution at = SolveCheckingGradientsByCentralDifferences(&problem, moduli, 1e-8);
  // The held dofs stay at rest.
  for (const int dof : lattice.supports[0].dofs) {
    EXPECT_EQ(at.displacement.row(dof).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(at.retrograde.row(dof).cwiseAbs().maxCoeff(), 0.0);
  }
}

// The bar of 60 elements of 16.7 mm in zones 0 (elements 0 to 3) and 1, its trusted
// reaction averaged over reaction_length 100 mm, exported with its clamp as a support
// (`zones` given per element: one zone per element for the central differences), and
// the trusted problem at moduli (183, 207) GPa (or those of `element_moduli` when
// given), the reaction's weight 0.1, large enough to matter.
struct SixtyElementTrustedBar {
  explicit SixtyElementTrustedBar(const std::vector<int>& element_zones = TwoZones())
      : c(Case()),
        zones(element_zones),
        model(c.bar, zones),
        data(MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data)),
        matrices(BarMatrixModel(model, c.bar.modulus, {}, BarClampExport::kSupport)),
        problem(matrices, data, ReactionWeights(), 200e9, 0.5, Factorization::kAutomatic,
                ClampModel::kTrusted) {}
  static SmallCase Case() {
    SmallCase small = MakeSmallCase(60, 120, 20.0, 1);
    small.bar.reaction_length = 0.1;
    return small;
  }
  static std::vector<int> TwoZones() {
    std::vector<int> two(60, 1);
    for (int e = 0; e < 4; ++e) two[e] = 0;
    return two;
  }
  static McreWeights ReactionWeights() {
    McreWeights weights = Weights(0.01, 1.0);
    weights.reaction_weight = 0.1;
    return weights;
  }
  static Vector TwoModuli() { return (Vector(2) << 1.83e11, 2.07e11).finished(); }

  SmallCase c;
  std::vector<int> zones;
  BarModel model;
  ChannelSet data;
  MatrixModelData matrices;
  MatrixMcreProblem problem;
};

// The bar's trusted reaction over model.reaction_length (docs/boundaries.md section 7):
// on 60 elements of 16.7 mm, 100 mm give m = 6 and phi_i = 1 - i / 6 on nodes 0 to 5. The
// reaction of a direct sweep is the mean axial force -(S / (m l)) sum_{e < m} E_e
// (U_{e+1} - U_e), written out here from the field, across the boundary of zones 0
// (elements 0 to 3) and 1; and its zone gradients match central differences.
TEST(MatrixSupportsTest, TheBarsTrustedReactionIsTheMeanAxialForceOverTheReactionLength) {
  SixtyElementTrustedBar bar;
  const SmallCase& c = bar.c;
  const std::vector<int>& zones = bar.zones;
  const BarModel& model = bar.model;
  const Vector& phi = bar.matrices.supports[0].reaction_test;
  ASSERT_EQ(phi.size(), 61);
  for (int i = 0; i < 61; ++i) EXPECT_EQ(phi[i], i < 6 ? 1.0 - i / 6.0 : 0.0) << i;
  EXPECT_EQ(&TrustedReactionTest(bar.matrices.supports[0]), &phi);

  MatrixMcreProblem& problem = bar.problem;
  const Vector moduli = SixtyElementTrustedBar::TwoModuli();
  problem.SetModuli(moduli);
  Matrix u;
  problem.DirectSweep(problem.ZeroField(), true, &u);
  const Matrix forces = problem.ModelSupportForces();
  ASSERT_EQ(forces.rows(), 1);
  const double l = model.element_length();
  double largest = 0.0, worst = 0.0;
  for (int j = 0; j < u.cols(); ++j) {
    double mean_force = 0.0;
    for (int e = 0; e < 6; ++e) mean_force -= moduli[zones[e]] * (u(e + 1, j) - u(e, j));
    mean_force *= c.bar.section / (6 * l);
    largest = std::max(largest, std::abs(mean_force));
    worst = std::max(worst, std::abs(forces(0, j) - mean_force));
  }
  // Measured: 4.2e-16 of the largest force.
  EXPECT_LT(worst, 1e-14 * largest);

  // Measured: 1.7e-10 (zone 0) and 1.8e-9 (zone 1), relative.
  SolveCheckingGradientsByCentralDifferences(&problem, moduli, 1e-8);
}

// The sensitivity map s_el = de^2/d ln E_el (MatrixMcreProblem::ElementSensitivities,
// mcre/element_error_map.h) on the same bar, its trusted reaction averaged over 100 mm:
// the elements of each zone sum to E_z de^2/dE_z, and an element's value is E_el times
// the central difference of e^2 in that element's modulus alone (the bar with one zone
// per element), inside the reaction's region (elements 2 and 4, either side of the zone
// boundary) and away from it (element 40).
TEST(MatrixSupportsTest, TheSensitivityMapIsEachElementsGradientInLogE) {
  SixtyElementTrustedBar bar;
  const std::vector<int>& zones = bar.zones;
  MatrixMcreProblem& problem = bar.problem;
  const Vector moduli = SixtyElementTrustedBar::TwoModuli();
  problem.SetModuli(moduli);
  CoupledSolution at;
  ASSERT_TRUE(
      SolveCoupled(SupportsTightSolver(CoupledSolverType::kAllAtOnce), &problem, nullptr, &at)
          .IsSolutionUsable());
  Vector sensitivity;
  problem.ElementSensitivities(at.displacement, at.retrograde, &sensitivity);
  ASSERT_EQ(sensitivity.size(), 60);
  for (int z = 0; z < 2; ++z) {
    double sum = 0.0;
    for (int e = 0; e < 60; ++e) sum += zones[e] == z ? sensitivity[e] : 0.0;
    // Measured: 3.6e-16 and 3.7e-16, relative.
    EXPECT_NEAR(sum, moduli[z] * at.cost_gradients[z],
                4e-15 * std::abs(moduli[z] * at.cost_gradients[z]))
        << "zone " << z;
  }

  std::vector<int> own(60);
  for (int e = 0; e < 60; ++e) own[e] = e;
  SixtyElementTrustedBar one_zone_per_element(own);
  MatrixMcreProblem& per_element = one_zone_per_element.problem;
  Vector element_moduli(60);
  for (int e = 0; e < 60; ++e) element_moduli[e] = moduli[zones[e]];
  auto cost_at = [&](const Vector& at_moduli) {
    per_element.SetModuli(at_moduli);
    CoupledSolution solution;
    EXPECT_TRUE(SolveCoupled(SupportsTightSolver(CoupledSolverType::kConjugateGradient),
                             &per_element, nullptr, &solution)
                    .IsSolutionUsable());
    return solution.cost;
  };
  for (const int e : {2, 4, 40}) {
    const double step = 1e-5 * element_moduli[e];
    Vector plus = element_moduli, minus = element_moduli;
    plus[e] += step;
    minus[e] -= step;
    const double difference = element_moduli[e] * (cost_at(plus) - cost_at(minus)) / (2.0 * step);
    // Measured: 2.7e-10, 6.9e-10 and 2.7e-10, relative.
    EXPECT_NEAR(sensitivity[e], difference, 7e-9 * std::abs(difference)) << "element " << e;
  }
}

// The inner CG's iterations from zero at the paper's defaults (w_u = 1e-7, w_r = 1e-6,
// the clamp trusted) on 100 and 3200 elements over the same window and time step: with
// the reaction the mean force over 10 mm they stay within 1.3 times; with the first
// element's stress (reaction_length 0), whose gain grows as N, they grow.
TEST(MatrixSupportsTest, ATrustedReactionOverAFixedLengthKeepsTheInnerIterationsOffTheMesh) {
  auto iterations = [](int elements, double reaction_length) {
    SmallCase c = MakeSmallCase(100, 1750, 20.0, 1);
    c.bar.elements = elements;
    c.bar.reaction_length = reaction_length;
    const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
    const MatrixModelData matrices =
        BarMatrixModel(BarModel(c.bar), c.bar.modulus, {}, BarClampExport::kSupport);
    McreWeights weights = Weights(1e-7, 1.0);
    weights.reaction_weight = 1e-6;
    MatrixMcreProblem problem(matrices, data, weights, 200e9, 0.5, Factorization::kAutomatic,
                              ClampModel::kTrusted);
    problem.SetModuli(Vector::Constant(1, 1.9e11));
    CoupledSolverOptions options;
    options.type = CoupledSolverType::kConjugateGradient;
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &solution);
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    return summary.iterations;
  };
  const int coarse = iterations(100, 0.01);
  const int fine = iterations(3200, 0.01);
  const int fine_first_element = iterations(3200, 0.0);
  // Measured: 7, 6 and 11 iterations.
  EXPECT_LE(fine, 1.3 * coarse) << coarse << " " << fine;
  EXPECT_GE(fine_first_element, 1.5 * fine) << fine << " " << fine_first_element;
}

TEST(MatrixSupportsTest, AllAtOnceAndConjugateGradientsAgreeUnderEveryTreatment) {
  const MatrixModelData lattice = SupportedLattice();
  const ChannelSet data = SupportedLatticeHistories(lattice);
  for (const ClampModel clamp :
       {ClampModel::kTrusted, ClampModel::kPinned, ClampModel::kMeasured}) {
    SCOPED_TRACE(ClampModelToString(clamp));
    MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                              clamp);
    problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
    CoupledSolution reference, solution;
    ASSERT_TRUE(SolveCoupled(SupportsTightSolver(CoupledSolverType::kAllAtOnce), &problem, nullptr,
                             &reference)
                    .IsSolutionUsable());
    ASSERT_TRUE(SolveCoupled(SupportsTightSolver(CoupledSolverType::kConjugateGradient), &problem,
                             nullptr, &solution)
                    .IsSolutionUsable());
    // CG to 1e-12 against the direct solution. Measured (W, e^2, gradients): trusted
    // 4.8e-11, 4.1e-16, 3.4e-11; pinned 1.4e-9, 1.4e-14, 3.0e-9 (the stiffest: the
    // datum's weight against a soft lattice); measured 2.1e-13, 1.6e-15, 3.9e-14.
    EXPECT_LT(RelativeDifference(solution.retrograde, reference.retrograde), 1e-8);
    EXPECT_NEAR(solution.cost, reference.cost, 1e-13 * reference.cost);
    EXPECT_LT((solution.cost_gradients - reference.cost_gradients).norm(),
              1e-8 * reference.cost_gradients.norm());
    EXPECT_LT(solution.cost, problem.RestCost());
  }
}

void ExpectSameModel(const MatrixModelData& a, const MatrixModelData& b) {
  EXPECT_EQ(Matrix(a.mass), Matrix(b.mass));
  ASSERT_EQ(a.zones.size(), b.zones.size());
  for (std::size_t z = 0; z < a.zones.size(); ++z) {
    EXPECT_EQ(Matrix(a.zones[z].stiffness), Matrix(b.zones[z].stiffness));
  }
  ASSERT_EQ(a.sensors.size(), b.sensors.size());
  ASSERT_EQ(a.loads.size(), b.loads.size());
  ASSERT_EQ(a.supports.size(), b.supports.size());
  for (std::size_t s = 0; s < a.supports.size(); ++s) {
    EXPECT_EQ(a.supports[s].name, b.supports[s].name);
    EXPECT_EQ(a.supports[s].dofs, b.supports[s].dofs);
    EXPECT_EQ(a.supports[s].reaction, b.supports[s].reaction);
    EXPECT_EQ(a.supports[s].reaction_test, b.supports[s].reaction_test);
    EXPECT_EQ(a.supports[s].force_channel, b.supports[s].force_channel);
    EXPECT_EQ(a.supports[s].displacement_channel, b.supports[s].displacement_channel);
  }
}

TEST(MatrixSupportsTest, ManifestRoundTripKeepsTheSupports) {
  const MatrixModelData lattice = SupportedLattice();
  const std::string folder = testing::FreshDirectory("supports_round_trip");
  const std::string manifest = WriteMatrixModel(folder, lattice);
  const MatrixModelData again = ReadMatrixModel(manifest);
  ExpectSameModel(lattice, again);
  // Written again: the same manifest, text for text.
  const std::string second = testing::FreshDirectory("supports_round_trip_again");
  EXPECT_EQ(testing::ReadText(WriteMatrixModel(second, again)), testing::ReadText(manifest));
  // The bar's clamp as a support: default reaction e_0, no reaction file.
  BarProperties bar;
  bar.elements = 6;
  const MatrixModelData exported = BarMatrixModel(BarModel(bar), 1e9, {}, BarClampExport::kSupport);
  const std::string bar_folder = testing::FreshDirectory("supports_round_trip_bar");
  const std::string bar_manifest = WriteMatrixModel(bar_folder, exported);
  EXPECT_NE(testing::ReadText(bar_manifest)
                .find("{name: clamp, dofs: [0], force_channel: f0, displacement_channel: u0}"),
            std::string::npos)
      << testing::ReadText(bar_manifest);
  ExpectSameModel(exported, ReadMatrixModel(bar_manifest));
  // Its trusted reaction over 100 mm of 60 elements: phi in a file of its own.
  bar.elements = 60;
  bar.reaction_length = 0.1;
  const MatrixModelData averaged = BarMatrixModel(BarModel(bar), 1e9, {}, BarClampExport::kSupport);
  const std::string averaged_manifest =
      WriteMatrixModel(testing::FreshDirectory("supports_round_trip_averaged"), averaged);
  EXPECT_NE(
      testing::ReadText(averaged_manifest).find("reaction_test: support_clamp_reaction_test.mtx}"),
      std::string::npos)
      << testing::ReadText(averaged_manifest);
  ExpectSameModel(averaged, ReadMatrixModel(averaged_manifest));
}

// The message of ReadMatrixModel on the lattice's manifest with its supports: section
// replaced by `supports` (files written beside it by `extra`).
std::string BadSupportsError(const std::string& name, const std::string& supports) {
  const std::string folder = testing::FreshDirectory("bad_supports_" + name);
  MatrixModelData lattice = SupportedLattice();
  const std::string manifest = WriteMatrixModel(folder, lattice);
  std::string text = testing::ReadText(manifest);
  text = text.substr(0, text.find("supports:")) + supports;
  std::ofstream(manifest) << text;
  Vector off = Vector::Zero(lattice.dofs());
  off[7] = 1.0;
  WriteMatrixMarketVector(folder + "/off.mtx", off, "a reaction off the support's dofs");
  WriteMatrixMarketVector(folder + "/short.mtx", Vector::Ones(5), "a reaction too short");
  try {
    ReadMatrixModel(manifest);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(MatrixSupportsTest, EachBadSupportIsRefusedNamingIt) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"supports:\n  - {name: left, dofs: [0, 40], force_channel: R}\n",
       {"support 'left'", "dof 40 out of range, expected 0 to 17"}},
      {"supports:\n  - {name: left, dofs: [1, 1], force_channel: R}\n",
       {"support 'left'", "dof 1 given twice"}},
      {"supports:\n  - {name: left, dofs: [], force_channel: R}\n",
       {"support 'left'", "non-empty list"}},
      {"supports:\n  - {name: left, dofs: [a], force_channel: R}\n",
       {"support 'left'", "0-based integers, got 'a'"}},
      {"supports:\n  - {name: left, dofs: [0]}\n", {"expected key 'force_channel'"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: u_tip}\n",
       {"support 'left'", "channel 'u_tip' is already a channel of the model"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, displacement_channel: F}\n",
       {"support 'left'", "channel 'F' is already"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R}\n"
       "  - {name: right, dofs: [0], force_channel: R2}\n",
       {"support 'right'", "dof 0 is held by another support"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R}\n"
       "  - {name: left, dofs: [1], force_channel: R2}\n",
       {"support 'left' given twice"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, reaction: off.mtx}\n",
       {"support 'left'", "off.mtx", "at dof 7, which the support does not hold"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, reaction: short.mtx}\n",
       {"support 'left'", "short.mtx", "5 entries"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, reaction_test: off.mtx}\n",
       {"support 'left'", "off.mtx", "entry 0 at held dof 0, expected the support's reaction"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, reaction_test: short.mtx}\n",
       {"support 'left'", "short.mtx", "5 entries"}},
      {"supports:\n  - {name: left, dofs: [0], force_channel: R, stiffness: 3}\n",
       {"unknown key 'stiffness'"}},
      {"supports: {name: left}\n", {"expected 'supports', a list"}},
  };
  int index = 0;
  for (const auto& [supports, expected] : cases) {
    const std::string why = BadSupportsError("case" + std::to_string(index++), supports);
    ASSERT_FALSE(why.empty()) << supports;
    EXPECT_NE(why.find("model.yaml"), std::string::npos) << why;
    for (const std::string& part : expected) {
      EXPECT_NE(why.find(part), std::string::npos) << why << "\n(expected: " << part << ")";
    }
  }
}

}  // namespace
}  // namespace mcrewave
