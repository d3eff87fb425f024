// Tests of the MCRE problem of a structure given by matrices
// (mcre/matrix_mcre_problem.h, docs/matrix_models.md): the bar exported to Matrix
// Market gives the built-in bar's sweeps, e^2 and zone gradients; the assembled
// all-at-once solver and conjugate gradients agree on a general sparse structure;
// every zone's gradient of the plate matches a central difference; the zone map
// sums to the constitutive part.
#include "mcrewave/mcre/matrix_mcre_problem.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::RelativeDifference;
using testing::SmallCase;
using testing::Weights;

const std::string kPlate = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/";

// The bar's measurements as the channels of BarMatrixModel: loads f0, fL; sensors u0,
// uL, then the interior sensors, under the same names (the set itself; this checks it).
ChannelSet BarHistories(const MatrixModelData& matrices, const ChannelSet& data) {
  for (const MatrixModelLoad& load : matrices.loads) EXPECT_GE(data.Find(load.channel), 0);
  for (const MatrixModelSensor& sensor : matrices.sensors) {
    EXPECT_GE(data.Find(sensor.channel), 0) << sensor.channel;
  }
  return data;
}

CoupledSolverOptions Tight(CoupledSolverType type) {
  CoupledSolverOptions options;
  options.type = type;
  options.tolerance = 1e-12;
  return options;
}

// The bar of 30 elements in 3 zones with an interior displacement sensor and a strain
// gauge, SNR 20, built in and through Matrix Market files.
class BarThroughMatricesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SmallCase c = MakeSmallCase(30, 240, 20.0, 2);
    c.data.sensors = {"u@0.25", "e@0.65"};
    std::vector<int> zones(30);
    for (int e = 0; e < 30; ++e) zones[e] = e / 10;
    model_ = std::make_unique<BarModel>(c.bar, zones);
    data_ = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
    const std::vector<BarSensor> sensors = {{SensorKind::kDisplacement, 0.25},
                                            {SensorKind::kStrain, 0.65}};
    const std::string folder = testing::FreshDirectory("bar_through_matrices");
    matrices_ = ReadMatrixModel(WriteMatrixModel(folder, BarMatrixModel(*model_, 200e9, sensors)));
    histories_ = BarHistories(matrices_, data_);
    weights_ = Weights(0.01, 1.0);
    weights_.strain_weight = 0.003;
  }
  std::unique_ptr<BarModel> model_;
  ChannelSet data_;
  MatrixModelData matrices_;
  ChannelSet histories_;
  McreWeights weights_;
};

TEST_F(BarThroughMatricesTest, SweepsWeightsCostAndZoneGradientsAreTheBuiltInBars) {
  testing::BarMcreProblem bar(*model_, data_, weights_, 200e9, 0.5);
  MatrixMcreProblem general(matrices_, histories_, weights_, 200e9, 0.5);
  // The weights from a* = S / L and l* = L are the bar's (the same formulas, the same
  // operations: docs/matrix_models.md section 6).
  EXPECT_EQ(general.alphas()[0], bar.alpha());
  EXPECT_EQ(general.betas()[0], bar.beta());
  EXPECT_EQ(general.betas()[3], bar.strain_beta());
  const Vector moduli = (Vector(3) << 180e9, 200e9, 230e9).finished();
  bar.SetModuli(moduli);
  general.SetModuli(moduli);
  // The bar exported is tridiagonal: the general problem takes the same band path.
  EXPECT_EQ(general.integrator().factorization(), Factorization::kBand);

  // One sweep of each kind from the same input (the general point loads against the
  // bar's end and point loads), the inner products and the cost on the same fields: the
  // same bits (BarMcreProblem computes as MatrixMcreProblem does).
  Matrix w = bar.ZeroField(), u_bar, u_general, w_bar, w_general;
  bar.RetrogradeSweep(bar.ZeroField(), true, &w);
  bar.DirectSweep(w, true, &u_bar);
  general.DirectSweep(w, true, &u_general);
  EXPECT_TRUE(u_general == u_bar);
  bar.RetrogradeSweep(u_bar, true, &w_bar);
  general.RetrogradeSweep(u_bar, true, &w_general);
  EXPECT_TRUE(w_general == w_bar);
  EXPECT_EQ(general.InnerProduct(w_bar, w), bar.InnerProduct(w_bar, w));
  EXPECT_EQ(general.Cost(u_bar, w_bar), bar.Cost(u_bar, w_bar));

  // Solved by CG to 1e-12: the same e^2 and zone gradients, to the bit.
  CoupledSolution bar_solution, general_solution;
  ASSERT_TRUE(
      SolveCoupled(Tight(CoupledSolverType::kConjugateGradient), &bar, nullptr, &bar_solution)
          .IsSolutionUsable());
  ASSERT_TRUE(SolveCoupled(Tight(CoupledSolverType::kConjugateGradient), &general, nullptr,
                           &general_solution)
                  .IsSolutionUsable());
  EXPECT_EQ(general_solution.cost, bar_solution.cost);
  EXPECT_TRUE(general_solution.cost_gradients == bar_solution.cost_gradients);
  // The zone map against the bar's element map summed by zone.
  const Vector elements = bar.ErrorMap(bar_solution.retrograde);
  const Vector zones = general.ZoneErrorMap(general_solution.retrograde);
  for (int z = 0; z < 3; ++z) {
    EXPECT_NEAR(zones[z], elements.segment(10 * z, 10).sum(), 1e-12 * elements.sum());
  }
}

// On the bar and on the same bar given by matrices, auto keeps the stored-field CG
// while its fields fit and streams when they do not; a stored-field method named is
// then refused, naming what fits.
TEST_F(BarThroughMatricesTest, AutoStreamsTheBarAndTheMatricesWhenTheirFieldsDoNotFit) {
  testing::BarMcreProblem bar(*model_, data_, weights_, 200e9, 0.5);
  MatrixMcreProblem general(matrices_, histories_, weights_, 200e9, 0.5);
  const Vector moduli = (Vector(3) << 180e9, 200e9, 230e9).finished();
  bar.SetModuli(moduli);
  general.SetModuli(moduli);
  // 31 nodes (dofs), 240 steps: 10 fields of 31 x 241 doubles, 597680 bytes.
  ASSERT_EQ(IterativeSolverFieldBytes(31, 240), 597680.0);
  CoupledSolution stored, automatic;
  ASSERT_TRUE(SolveCoupled(Tight(CoupledSolverType::kConjugateGradient), &general, nullptr, &stored)
                  .IsSolutionUsable());
  const CoupledSolverSummary fits =
      SolveCoupled(Tight(CoupledSolverType::kAuto), &general, nullptr, &automatic);
  EXPECT_EQ(fits.type, CoupledSolverType::kConjugateGradient);
  EXPECT_EQ(automatic.cost, stored.cost);

  CoupledSolverOptions short_of_the_fields = Tight(CoupledSolverType::kAuto);
  short_of_the_fields.max_field_bytes = 597679;
  CoupledSolution on_the_bar, on_matrices, refused;
  const CoupledSolverSummary bar_summary =
      SolveCoupled(short_of_the_fields, &bar, nullptr, &on_the_bar);
  EXPECT_EQ(bar_summary.type, CoupledSolverType::kStreamingConjugateGradient);
  EXPECT_TRUE(bar_summary.IsSolutionUsable()) << bar_summary.message;
  // The bar streamed against the matrices' stored-field CG, both to 1e-12: e^2 measured
  // 5.0e-14 apart.
  EXPECT_NEAR(on_the_bar.cost, stored.cost, 2e-13 * stored.cost);
  const CoupledSolverSummary matrix_summary =
      SolveCoupled(short_of_the_fields, &general, nullptr, &on_matrices);
  EXPECT_EQ(matrix_summary.type, CoupledSolverType::kStreamingConjugateGradient);
  EXPECT_TRUE(matrix_summary.IsSolutionUsable()) << matrix_summary.message;
  EXPECT_FALSE(on_matrices.has_fields());
  // The matrices streamed against their stored-field CG: e^2 measured 3.0e-14 apart,
  // the zone gradients 1.0e-11 of their norm.
  EXPECT_NEAR(on_matrices.cost, stored.cost, 3e-13 * stored.cost);
  EXPECT_LT((on_matrices.cost_gradients - stored.cost_gradients).norm(),
            1e-10 * stored.cost_gradients.norm());
  // A stored-field method named is refused before any work, naming the streaming one.
  const long sweeps = general.sweep_count();
  CoupledSolverOptions named = short_of_the_fields;
  named.type = CoupledSolverType::kConjugateGradient;
  const CoupledSolverSummary stored_refused = SolveCoupled(named, &general, nullptr, &refused);
  EXPECT_EQ(stored_refused.termination, TerminationType::kFailure);
  EXPECT_EQ(general.sweep_count(), sweeps);
  EXPECT_EQ(stored_refused.message,
            "conjugate_gradient needs 597680 bytes (10 fields of n x (m + 1) doubles, n "
            "= 31 nodes, m = 240 steps), above the limit of 597679 bytes (inner.max_field_bytes); "
            "use inner.method: streaming_conjugate_gradient (or auto), which stores no "
            "space-time field, raise inner.max_field_bytes, or use a coarser mesh (fewer dofs; the "
            "bar's model.elements), "
            "a shorter window or a larger time step");
}

TEST_F(BarThroughMatricesTest, TheSparsePathGivesTheSameSolution) {
  MatrixMcreProblem band(matrices_, histories_, weights_, 200e9, 0.5, Factorization::kBand);
  MatrixMcreProblem sparse(matrices_, histories_, weights_, 200e9, 0.5, Factorization::kSparse);
  EXPECT_EQ(sparse.integrator().factorization(), Factorization::kSparse);
  CoupledSolution a, b;
  ASSERT_TRUE(SolveCoupled(Tight(CoupledSolverType::kConjugateGradient), &band, nullptr, &a)
                  .IsSolutionUsable());
  ASSERT_TRUE(SolveCoupled(Tight(CoupledSolverType::kConjugateGradient), &sparse, nullptr, &b)
                  .IsSolutionUsable());
  // Measured 1.7e-14 in e^2, 9.2e-14 in W.
  EXPECT_NEAR(b.cost, a.cost, 1e-13 * a.cost);
  EXPECT_LT(RelativeDifference(b.retrograde, a.retrograde), 1e-12);
}

// A general sparse structure: a 2-D lattice of 7 x 4 free nodes (one dof each, a
// membrane), springs to the 4 neighbours and the diagonals, the column x = 0
// clamped, two zones (x < 4 and x >= 4), a load spread over the last column, a
// displacement sensor and a difference ("strain") row. Numbered column by column so
// that its band is 4 to 5 wide and the sparse path is taken when asked.
MatrixModelData Lattice() {
  constexpr int kColumns = 7, kRows = 4, kDofs = kColumns * kRows;
  auto dof = [](int column, int row) { return (column - 1) * kRows + row; };  // column >= 1
  std::vector<Eigen::Triplet<double>> mass, stiffness[2];
  for (int i = 0; i < kDofs; ++i) {
    mass.emplace_back(i, i, 2.0);
  }
  auto spring = [&](int c0, int r0, int c1, int r1, double k) {
    const int zone = std::max(c0, c1) < 4 ? 0 : 1;
    const int a = c0 >= 1 ? dof(c0, r0) : -1, b = c1 >= 1 ? dof(c1, r1) : -1;
    if (a >= 0) stiffness[zone].emplace_back(a, a, k);
    if (b >= 0) stiffness[zone].emplace_back(b, b, k);
    if (a >= 0 && b >= 0) {
      stiffness[zone].emplace_back(a, b, -k);
      stiffness[zone].emplace_back(b, a, -k);
      mass.emplace_back(a, b, 0.25);
      mass.emplace_back(b, a, 0.25);
    }
  };
  for (int c = 0; c <= kColumns; ++c) {
    for (int r = 0; r < kRows; ++r) {
      if (c < kColumns) spring(c, r, c + 1, r, 3e3);
      if (r + 1 < kRows && c >= 1) spring(c, r, c, r + 1, 1e3);
      if (r + 1 < kRows && c < kColumns) spring(c, r, c + 1, r + 1, 5e2);
    }
  }
  MatrixModelData model = testing::TwoZoneLatticeModel(kDofs, mass, stiffness);
  Vector load = Vector::Zero(kDofs);
  for (int r = 0; r < kRows; ++r) load[dof(kColumns, r)] = 0.25;
  model.loads.push_back({"F", load});
  SparseMatrix tip(1, kDofs), gauge(1, kDofs);
  tip.insert(0, dof(kColumns, 3)) = 1.0;
  gauge.insert(0, dof(3, 0)) = -10.0;
  gauge.insert(0, dof(4, 0)) = 10.0;
  model.sensors.push_back({"u_tip", tip, SensorKind::kDisplacement});
  model.sensors.push_back({"e_mid", gauge, SensorKind::kStrain});
  return model;
}

// Histories on m steps of h: a half-sine load of `duration` and outputs of `truth`'s
// model at `truth_moduli` (its own mesh: model outputs) plus a deterministic wiggle of
// relative size `spoil` (so that the data are not the model's).
ChannelSet Histories(const MatrixModelData& truth, const Vector& truth_moduli, int steps,
                     double time_step, double duration, double spoil) {
  const Matrix loads = testing::HalfSineLoadRow(steps, time_step, duration);
  const ChannelSet at_rest = MatrixChannelSet(
      truth, time_step, loads, Matrix::Zero(static_cast<int>(truth.sensors.size()), steps + 1));
  MatrixMcreProblem simulation(truth, at_rest, Weights(0.01, 1.0), 2e11, 0.5);
  simulation.SetModuli(truth_moduli);
  Matrix outputs = simulation.ModelOutputs();
  for (int k = 0; k < outputs.rows(); ++k) {
    const double scale = outputs.row(k).cwiseAbs().maxCoeff();
    for (int j = 0; j <= steps; ++j) {
      outputs(k, j) += spoil * scale * std::sin(0.37 * j + k);
    }
  }
  return MatrixChannelSet(truth, time_step, loads, outputs);
}

// Batched sweeps give the bits of the single sweeps, null inputs the zero field's, and
// count as that many sweeps.
void ExpectBatchedSweepsAreTheSingleSweeps(MatrixMcreProblem* problem) {
  std::mt19937 engine(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random_field = [&] {
    Matrix field = problem->ZeroField();
    for (Eigen::Index i = 0; i < field.size(); ++i) field.data()[i] = 1e-6 * uniform(engine);
    return field;
  };
  const Matrix zero = problem->ZeroField(), w1 = random_field(), w2 = random_field();
  Matrix u1, u2, u3, expected;
  const long sweeps = problem->sweep_count();
  problem->DirectSweepsWithData({&w1, nullptr, &w2}, {&u1, &u2, &u3});
  EXPECT_EQ(problem->sweep_count(), sweeps + 3);
  problem->DirectSweep(w1, true, &expected);
  EXPECT_EQ(u1, expected);
  problem->DirectSweep(zero, true, &expected);
  EXPECT_EQ(u2, expected);
  problem->DirectSweep(w2, true, &expected);
  EXPECT_EQ(u3, expected);
  EXPECT_GT(u3.cwiseAbs().maxCoeff(), 0.0);
  Matrix r1, r2, r3;
  problem->RetrogradeSweepsWithData({&u1, &u3, nullptr}, {&r1, &r2, &r3});
  problem->RetrogradeSweep(u1, true, &expected);
  EXPECT_EQ(r1, expected);
  problem->RetrogradeSweep(u3, true, &expected);
  EXPECT_EQ(r2, expected);
  problem->RetrogradeSweep(zero, true, &expected);
  EXPECT_EQ(r3, expected);
  EXPECT_GT(r3.cwiseAbs().maxCoeff(), 0.0);
  problem->RetrogradeSweepsWithData({nullptr, &u2}, {&r1, &r2});
  EXPECT_EQ(r1, expected);
  problem->RetrogradeSweep(u2, true, &expected);
  EXPECT_EQ(r2, expected);
  problem->DirectSweepsWithData({&r1, &r2}, {&u1, &u2});
  problem->DirectSweep(r2, true, &expected);
  EXPECT_EQ(u2, expected);
}

TEST_F(BarThroughMatricesTest, BatchedSweepsAreTheSingleSweeps) {
  for (ClampModel supports : {ClampModel::kMeasured, ClampModel::kTrusted}) {
    MatrixMcreProblem problem(matrices_, histories_, weights_, 200e9, 0.5,
                              Factorization::kAutomatic, supports);
    problem.SetModuli(Vector::Constant(3, 210e9));
    ExpectBatchedSweepsAreTheSingleSweeps(&problem);
  }
}

// The bar exported as matrices (BarMatrixModel, 3 zones, an interior displacement
// sensor and a strain gauge): Riccati and both shootings as on any structure.
TEST_F(BarThroughMatricesTest, RiccatiAndShootingSolveTheBarAsMatrices) {
  MatrixMcreProblem general(matrices_, histories_, weights_, 200e9, 0.5);
  general.SetModuli((Vector(3) << 180e9, 200e9, 230e9).finished());
  // Measured, the largest difference in U, W or e^2 over the three solvers: 2.0e-12 to
  // all_at_once (single shooting's W; Riccati 3.3e-13), 8.6e-12 to CG (W).
  testing::ExpectDenseSolversAgree("bar as matrices", &general, 1e-10, 2e-11, 8e-11);
}

TEST(MatrixMcreProblemTest, AllAtOnceAndIterativeSolversAgreeOnASparseLattice) {
  const MatrixModelData lattice = Lattice();
  const Vector truth = (Vector(2) << 2e11, 1.6e11).finished();
  const ChannelSet data = Histories(lattice, truth, 120, 2e-3, 0.05, 0.05);
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse);
  problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
  CoupledSolution reference;
  const CoupledSolverSummary direct =
      SolveCoupled(Tight(CoupledSolverType::kAllAtOnce), &problem, nullptr, &reference);
  ASSERT_TRUE(direct.IsSolutionUsable()) << direct.FullReport();
  for (const CoupledSolverType type :
       {CoupledSolverType::kConjugateGradient, CoupledSolverType::kAdaptiveRelaxation}) {
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(Tight(type), &problem, nullptr, &solution);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    // Measured: W 1.7e-11 (CG) and 1.0e-11 (adaptive relaxation) apart, U 4.2e-14 and
    // 2.1e-14, e^2 4.7e-15 and 3.6e-15, the gradients 3.1e-12 and 8.6e-12.
    EXPECT_LT(RelativeDifference(solution.retrograde, reference.retrograde), 1e-10)
        << CoupledSolverTypeToString(type);
    EXPECT_LT(RelativeDifference(solution.displacement, reference.displacement), 1e-12);
    EXPECT_NEAR(solution.cost, reference.cost, 3e-14 * reference.cost);
    EXPECT_LT((solution.cost_gradients - reference.cost_gradients).norm(),
              5e-11 * reference.cost_gradients.norm());
  }
  // The zone map sums to the constitutive part 1/2 sum_j c_j h W^T K W, and the dof
  // map to the same.
  const Vector zones = problem.ZoneErrorMap(reference.retrograde);
  const Vector dofs = problem.DofErrorMap(reference.retrograde);
  EXPECT_NEAR(dofs.sum(), zones.sum(), 1e-13 * zones.sum());
  EXPECT_GT(zones.minCoeff(), 0.0);
}

// Riccati and both shootings on structures given by matrices, against the all-at-once
// solver and CG (docs/riccati_shooting.md section 5): the sparse lattice with two zones
// (band 5, an observed displacement and a difference row: W_obs not diagonal), and the
// supported lattice of test_problems.h with its support trusted (held dofs decoupled,
// the reaction a row of H).
TEST(MatrixMcreProblemTest, RiccatiAndShootingSolveASparseLattice) {
  const MatrixModelData lattice = Lattice();
  const Vector truth = (Vector(2) << 2e11, 1.6e11).finished();
  const ChannelSet data = Histories(lattice, truth, 120, 2e-3, 0.05, 0.05);
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse);
  problem.SetModuli((Vector(2) << 1.8e11, 2.1e11).finished());
  // Measured, the largest difference in U, W or e^2 over the three solvers: 6.2e-15 to
  // all_at_once, 1.7e-11 to CG (W); relative residuals 4.3e-15..6.5e-15.
  testing::ExpectDenseSolversAgree("lattice", &problem, 1e-12, 6e-14, 1.7e-10);
}

TEST(MatrixMcreProblemTest, RiccatiAndShootingSolveASupportedLatticeWithItsSupportTrusted) {
  const MatrixModelData lattice = testing::SupportedLattice();
  const ChannelSet data = testing::SupportedLatticeHistories(lattice);
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse,
                            ClampModel::kTrusted);
  problem.SetModuli((Vector(2) << 1.9e11, 1.7e11).finished());
  // Measured, the largest difference in U, W or e^2 over the three solvers: 7.5e-14 to
  // all_at_once, 1.4e-10 to CG (W); relative residuals 8.2e-14..1.1e-13.
  testing::ExpectDenseSolversAgree("supported lattice, trusted", &problem, 1e-12, 7e-13, 1.4e-9);
}

TEST(MatrixMcreProblemTest, RiccatiAndShootingRefuseAboveTheDenseLimitNamingTheWayOut) {
  const MatrixModelData lattice = Lattice();
  const ChannelSet data = Histories(lattice, Vector::Constant(2, 2e11), 120, 2e-3, 0.05, 0.05);
  MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, Factorization::kSparse);
  for (CoupledSolverType type : testing::kDenseSolvers) {
    CoupledSolverOptions options = Tight(type);
    // 28 dofs: Riccati needs 8 (120 (2 * 28^2 + 28) + 32 * 28^2 + 5 * 28 * 3) bytes,
    // a shooting segment 8 (32 * 28^2 + ...); both above 100 kB.
    options.max_dense_solver_bytes = 100000;
    CoupledSolution refused;
    const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &refused);
    EXPECT_EQ(summary.termination, TerminationType::kFailure) << CoupledSolverTypeToString(type);
    EXPECT_NE(summary.message.find("above the limit of 100000 bytes "
                                   "(inner.max_dense_solver_bytes); use inner.method: "
                                   "conjugate_gradient or auto"),
              std::string::npos)
        << summary.message;
    EXPECT_EQ(problem.sweep_count(), 0) << "refused before any work";
  }
}

TEST(MatrixMcreProblemTest, EveryZoneGradientOfThePlateMatchesACentralDifference) {
  const MatrixModelData coarse = ReadMatrixModel(kPlate + "coarse/model.yaml");
  const MatrixModelData fine = ReadMatrixModel(kPlate + "fine/model.yaml");
  // Data from the fine mesh (inclusion 25 % softer), 150 steps of 1 us.
  const ChannelSet data =
      Histories(fine, (Vector(2) << 2e11, 1.5e11).finished(), 150, 1e-6, 2e-5, 0.0);
  MatrixMcreProblem problem(coarse, data, Weights(0.01, 1.0), 2e11, 0.5);
  const Vector moduli = (Vector(2) << 1.9e11, 1.7e11).finished();
  // CG to 1e-9 (e^2 is then exact to about 1e-18 relative: its error is quadratic in
  // the residual), warm-started from the solution at the centre.
  CoupledSolverOptions options = Tight(CoupledSolverType::kConjugateGradient);
  options.tolerance = 1e-9;
  Matrix centre;
  auto solve = [&](const Vector& at) {
    problem.SetModuli(at);
    CoupledSolution solution;
    EXPECT_TRUE(SolveCoupled(options, &problem, centre.size() > 0 ? &centre : nullptr, &solution)
                    .IsSolutionUsable());
    return solution;
  };
  const CoupledSolution at = solve(moduli);
  centre = at.retrograde;
  for (int z = 0; z < 2; ++z) {
    // Central difference of step 1e-4 E_z.
    const double step = 1e-4 * moduli[z];
    Vector plus = moduli, minus = moduli;
    plus[z] += step;
    minus[z] -= step;
    const double difference = (solve(plus).cost - solve(minus).cost) / (2.0 * step);
    // Measured 1.65e-7 (matrix) and 1.8e-8 (inclusion) relative; the issue asks 1e-6.
    EXPECT_NEAR(at.cost_gradients[z], difference, (z == 0 ? 1e-6 : 1.5e-7) * std::abs(difference))
        << "zone " << z;
  }
}

TEST(MatrixMcreProblemTest, BatchedSweepsAreTheSingleSweepsOnASparseLattice) {
  const MatrixModelData lattice = Lattice();
  const ChannelSet data = Histories(lattice, lattice.NominalModuli(), 60, 1e-3, 0.02, 0.05);
  for (Factorization path : {Factorization::kSparse, Factorization::kBand}) {
    MatrixMcreProblem problem(lattice, data, Weights(0.01, 1.0), 2e11, 0.5, path);
    ExpectBatchedSweepsAreTheSingleSweeps(&problem);
  }
}

}  // namespace
}  // namespace mcrewave
