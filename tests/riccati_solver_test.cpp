// Tests of the discrete Riccati solver: agreement with the all-at-once reference on
// small noisy cases (both weightings, several theta), agreement with conjugate
// gradients on the paper's case, and the refusal above the memory limit.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::Compare;
using testing::kReferenceModulus;
using testing::MakeSmallCase;
using testing::Options;
using testing::ProblemBundle;
using testing::RelativeDifference;
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
  ProblemBundle bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(param.w_u, 1.0), param.theta);
  McreProblem& problem = bundle.problem;
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
  ProblemBundle bundle(MakeSmallCase(100, 1750, 10.0, 2), McreWeights());
  McreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved krylov = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-12), &problem);
  ASSERT_TRUE(krylov.summary.IsSolutionUsable()) << krylov.summary.FullReport();
  const Solved riccati = Solve(Options(CoupledSolverType::kRiccati, 1e-10), &problem);
  ASSERT_TRUE(riccati.summary.IsSolutionUsable()) << riccati.summary.FullReport();
  EXPECT_LT(RelativeDifference(riccati.solution.displacement, krylov.solution.displacement), 1e-8);
  EXPECT_LT(RelativeDifference(riccati.solution.retrograde, krylov.solution.retrograde), 1e-8);
  EXPECT_NEAR(riccati.solution.cost, krylov.solution.cost, 1e-8 * krylov.solution.cost);
}

TEST(RiccatiSolverTest, RefusesAboveTheMemoryLimitWithTheBytesItNeeds) {
  ProblemBundle bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kRiccati, 1e-8);
  options.max_dense_solver_bytes = 100000;
  const Solved solved = Solve(options, &bundle.problem);
  EXPECT_EQ(solved.summary.termination, TerminationType::kFailure);
  EXPECT_FALSE(solved.summary.IsSolutionUsable());
  // n = 11 nodes, m = 50 steps: 8 (50 (2 * 121 + 11) + 32 * 121) = 132176 bytes.
  EXPECT_NE(solved.summary.message.find("needs 132176 bytes"), std::string::npos)
      << solved.summary.message;
  EXPECT_NE(solved.summary.message.find("inner.max_dense_solver_bytes"), std::string::npos);
}

}  // namespace
}  // namespace mcrewave
