// Tests of the discrete Riccati solver: agreement with the all-at-once reference on
// small noisy cases (both weightings, several theta), agreement with conjugate
// gradients on the paper's case, and the refusal above the memory limit.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::BarRunProblem;
using testing::Compare;
using testing::kReferenceModulus;
using testing::MakeSmallCase;
using testing::Options;
using testing::RelativeDifference;
using testing::SmallCase;
using testing::Solve;
using testing::Solved;
using testing::Weights;

TEST(RiccatiSolverTypeTest, NewNamesRoundTrip) {
  for (CoupledSolverType type : {CoupledSolverType::kRiccati, CoupledSolverType::kSingleShooting,
                                 CoupledSolverType::kMultipleShooting}) {
    CoupledSolverType parsed = CoupledSolverType::kAllAtOnce;
    ASSERT_TRUE(StringToCoupledSolverType(CoupledSolverTypeToString(type), &parsed));
    EXPECT_EQ(parsed, type);
  }
  CoupledSolverType parsed = CoupledSolverType::kAllAtOnce;
  ASSERT_TRUE(StringToCoupledSolverType("riccati", &parsed));
  EXPECT_EQ(parsed, CoupledSolverType::kRiccati);
}

TEST(RiccatiSolverOptionsTest, InvalidDenseOptionsAreRefusedWithTheKey) {
  std::string why;
  CoupledSolverOptions options;
  options.max_dense_solver_bytes = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.max_dense_solver_bytes"), std::string::npos) << why;
  options = CoupledSolverOptions();
  options.shooting_segment_growth = 1.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.shooting_segment_growth"), std::string::npos) << why;
  options = CoupledSolverOptions();
  options.shooting_condition_limit = 0.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.shooting_condition_limit"), std::string::npos) << why;
}

// 20 elements, 200 steps, noisy data from a finer truth (SNR 5).
struct RiccatiCase {
  double w_u;
  double theta;
};

class RiccatiAgreementTest : public ::testing::TestWithParam<RiccatiCase> {};

TEST_P(RiccatiAgreementTest, AgreesWithAllAtOnceToOneInOneHundredMillion) {
  const RiccatiCase& param = GetParam();
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(param.w_u, 1.0), param.theta);
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();

  const Solved riccati = Solve(Options(CoupledSolverType::kRiccati, 1e-10), &problem);
  ASSERT_TRUE(riccati.summary.IsSolutionUsable()) << riccati.summary.FullReport();
  const testing::Agreement agreement = Compare(riccati, reference);
  std::cout << "riccati vs all_at_once (w_u " << param.w_u << ", theta " << param.theta << "): U "
            << agreement.displacement << ", W " << agreement.retrograde << ", e^2 "
            << agreement.cost << ", residual " << riccati.summary.relative_residual << "\n";
  EXPECT_LT(agreement.displacement, 1e-8);
  EXPECT_LT(agreement.retrograde, 1e-8);
  EXPECT_LT(agreement.cost, 1e-8);
  EXPECT_NEAR(riccati.solution.cost_gradient, reference.solution.cost_gradient,
              1e-7 * std::abs(reference.solution.cost_gradient));
  EXPECT_GT(riccati.summary.multiply_accumulates, 0.0);
  EXPECT_EQ(riccati.summary.iterations, 0);
}

INSTANTIATE_TEST_SUITE_P(WeightsAndTheta, RiccatiAgreementTest,
                         ::testing::Values(RiccatiCase{0.01, 0.5}, RiccatiCase{1.0, 0.5},
                                           RiccatiCase{0.01, 1.0}, RiccatiCase{1.0, 0.75}));

TEST(RiccatiSolverTest, AgreesWithConjugateGradientsOnThePapersCase) {
  // 100 elements, 1750 steps (the paper's window), noisy data, default weights.
  BarRunProblem bundle(MakeSmallCase(100, 1750, 10.0, 2), McreWeights());
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved krylov = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-12), &problem);
  ASSERT_TRUE(krylov.summary.IsSolutionUsable()) << krylov.summary.FullReport();
  const Solved riccati = Solve(Options(CoupledSolverType::kRiccati, 1e-10), &problem);
  ASSERT_TRUE(riccati.summary.IsSolutionUsable()) << riccati.summary.FullReport();
  EXPECT_LT(RelativeDifference(riccati.solution.displacement, krylov.solution.displacement), 1e-8);
  EXPECT_LT(RelativeDifference(riccati.solution.retrograde, krylov.solution.retrograde), 1e-8);
  EXPECT_NEAR(riccati.solution.cost, krylov.solution.cost, 1e-8 * krylov.solution.cost);
}

// The bar as every run solves it (BarRunModel), with interior sensors (u@0.3, e@0.7)
// under a trusted and a pinned clamp, which the comparators refused before they took the general data term
// W_obs = H^T diag(beta) H: 20 elements, SNR 10, three zones; the pinned clamp's stiff
// spring 1 / alpha_0 (clamp_displacement_weight 0.1) on a shorter window, where single
// shooting's condition number stays moderate (1.4e10 on 200 steps, where it fails its
// residual check, as on long windows: section 3 of docs/riccati_shooting.md).
struct BarClampCase {
  ClampModel clamp;
  int steps;
  double tolerance;  // of the dense solvers' residual check
  double lu_bound;   // on the differences in U, W and e^2 to all_at_once
  double cg_bound;   // and to conjugate gradients
};

class DenseSolversOnTheBarTest : public ::testing::TestWithParam<BarClampCase> {};

TEST_P(DenseSolversOnTheBarTest, AgreeWithAllAtOnceAndConjugateGradients) {
  const BarClampCase& param = GetParam();
  SmallCase c = MakeSmallCase(20, param.steps, 10.0, 2);
  c.data.sensors = {"u@0.3", "e@0.7"};
  std::vector<int> zones(20);
  for (int e = 0; e < 20; ++e) zones[e] = e * 3 / 20;
  const BarModel model(c.bar, zones);
  const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  McreWeights weights = Weights(0.01, 1.0);
  weights.strain_weight = 0.003;
  weights.clamp_displacement_weight = 0.1;  // the pinned clamp's alpha_0
  const MatrixModelData matrices = BarRunModel(model, data, {});
  MatrixMcreProblem problem(matrices, data, weights, kReferenceModulus, 0.5,
                            Factorization::kAutomatic, param.clamp);
  ASSERT_GT(matrices.sensors.size(), 1u);  // uL and the interior sensors
  problem.SetModuli((Vector(3) << 180e9, 210e9, 230e9).finished());
  testing::ExpectDenseSolversAgree(std::string("bar, clamp ") + ClampModelToString(param.clamp),
                                   &problem, param.tolerance, param.lu_bound, param.cg_bound);
}

// Measured, the largest difference in U, W or e^2 over the three solvers: trusted
// (200 steps) 6.2e-14 to all_at_once, 1.5e-11 to CG (in W; relative residuals
// 1.0e-13..2.1e-13); pinned (60 steps) 3.5e-12 and 3.4e-10 (W; residuals
// 5.1e-13..1.5e-11, Riccati the largest).
INSTANTIATE_TEST_SUITE_P(
    TrustedAndPinned, DenseSolversOnTheBarTest,
    ::testing::Values(BarClampCase{ClampModel::kTrusted, 200, 1e-12, 5e-13, 1.5e-10},
                      BarClampCase{ClampModel::kPinned, 60, 1e-10, 3e-11, 3e-9}));

TEST(RiccatiSolverTest, RefusesAboveTheMemoryLimitWithTheBytesItNeeds) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kRiccati, 1e-8);
  options.max_dense_solver_bytes = 100000;
  const Solved solved = Solve(options, &bundle.problem);
  EXPECT_EQ(solved.summary.termination, TerminationType::kFailure);
  EXPECT_FALSE(solved.summary.IsSolutionUsable());
  // n = 11 nodes, m = 50 steps, s = 2 observed dofs:
  // 8 (50 (2 * 121 + 11) + 32 * 121 + 5 * 11 * 2) = 133056 bytes.
  EXPECT_NE(solved.summary.message.find("needs 133056 bytes"), std::string::npos)
      << solved.summary.message;
  EXPECT_NE(solved.summary.message.find("inner.max_dense_solver_bytes"), std::string::npos);
}

}  // namespace
}  // namespace mcrewave
