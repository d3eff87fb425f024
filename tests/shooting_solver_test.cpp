// Tests of single and multiple shooting: agreement with the all-at-once reference
// on small noisy cases, the breakdown of single shooting on a long window (reported
// as a failure with its condition number) while multiple shooting and Riccati still
// agree with the reference there.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "mcrewave/mcre/coupled_solver.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::BarRunProblem;
using testing::Compare;
using testing::kReferenceModulus;
using testing::MakeSmallCase;
using testing::Options;
using testing::Solve;
using testing::Solved;
using testing::Weights;

struct ShootingCase {
  double w_u;
  double theta;
  int steps;
  CoupledSolverType type;
};

class ShootingAgreementTest : public ::testing::TestWithParam<ShootingCase> {};

TEST_P(ShootingAgreementTest, AgreesWithAllAtOnceToOneInOneHundredMillion) {
  const ShootingCase& param = GetParam();
  BarRunProblem bundle(MakeSmallCase(20, param.steps, 5.0, 2), Weights(param.w_u, 1.0),
                       param.theta);
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();
  const Solved shooting = Solve(Options(param.type, 1e-10), &problem);
  ASSERT_TRUE(shooting.summary.IsSolutionUsable()) << shooting.summary.FullReport();
  const testing::Agreement agreement = Compare(shooting, reference);
  std::cout << CoupledSolverTypeToString(param.type) << " vs all_at_once (w_u " << param.w_u
            << ", theta " << param.theta << ", " << param.steps << " steps): U "
            << agreement.displacement << ", W " << agreement.retrograde << ", e^2 "
            << agreement.cost << "; " << shooting.summary.shooting_segments
            << " segments, condition " << shooting.summary.shooting_condition_number << "\n";
  EXPECT_LT(agreement.displacement, 1e-8);
  EXPECT_LT(agreement.retrograde, 1e-8);
  EXPECT_LT(agreement.cost, 1e-8);
  EXPECT_NEAR(shooting.solution.cost_gradient, reference.solution.cost_gradient,
              1e-7 * std::abs(reference.solution.cost_gradient));
  EXPECT_GT(shooting.summary.shooting_condition_number, 1.0);
  EXPECT_GT(shooting.summary.multiply_accumulates, 0.0);
}

// Single shooting at theta != 1/2 only on short windows: the retrograde step run
// forward in time inverts the numerical damping of the theta method, so its
// fundamental matrix grows by orders of magnitude per step at high frequencies.
INSTANTIATE_TEST_SUITE_P(
    WeightsAndTheta, ShootingAgreementTest,
    ::testing::Values(ShootingCase{0.01, 0.5, 200, CoupledSolverType::kSingleShooting},
                      ShootingCase{1.0, 0.5, 200, CoupledSolverType::kSingleShooting},
                      ShootingCase{1.0, 0.75, 20, CoupledSolverType::kSingleShooting},
                      ShootingCase{0.01, 1.0, 10, CoupledSolverType::kSingleShooting},
                      ShootingCase{0.01, 0.5, 200, CoupledSolverType::kMultipleShooting},
                      ShootingCase{1.0, 0.5, 200, CoupledSolverType::kMultipleShooting},
                      ShootingCase{0.01, 1.0, 200, CoupledSolverType::kMultipleShooting},
                      ShootingCase{1.0, 0.75, 200, CoupledSolverType::kMultipleShooting}));

TEST(ShootingBreakdownTest, LongWindowFailsSingleShootingWhileMultipleShootingAndRiccatiAgree) {
  // 20 elements, 1600 steps: 4.6 times the paper's window, w_u = 1.
  BarRunProblem bundle(MakeSmallCase(20, 1600, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved single = Solve(Options(CoupledSolverType::kSingleShooting, 1e-8), &problem);
  std::cout << "single shooting on 1600 steps: " << single.summary.message << "\n";
  EXPECT_EQ(single.summary.termination, TerminationType::kFailure);
  EXPECT_FALSE(single.summary.IsSolutionUsable());
  EXPECT_GT(single.summary.shooting_condition_number, 1e8);
  EXPECT_NE(single.summary.message.find("single_shooting"), std::string::npos);
  EXPECT_NE(single.summary.message.find("condition number"), std::string::npos);

  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();
  for (CoupledSolverType type :
       {CoupledSolverType::kMultipleShooting, CoupledSolverType::kRiccati}) {
    const Solved solved = Solve(Options(type, 1e-8), &problem);
    ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
    const testing::Agreement agreement = Compare(solved, reference);
    std::cout << CoupledSolverTypeToString(type) << " on 1600 steps vs all_at_once: U "
              << agreement.displacement << ", W " << agreement.retrograde << ", e^2 "
              << agreement.cost << "\n";
    EXPECT_LT(agreement.displacement, 1e-8) << CoupledSolverTypeToString(type);
    EXPECT_LT(agreement.retrograde, 1e-8) << CoupledSolverTypeToString(type);
    EXPECT_LT(agreement.cost, 1e-8) << CoupledSolverTypeToString(type);
  }
}

TEST(ShootingBreakdownTest, SingleShootingAtThetaThreeQuartersOverflowsAndSaysSo) {
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(1.0, 1.0), 0.75);
  const Solved single = Solve(Options(CoupledSolverType::kSingleShooting, 1e-8), &bundle.problem);
  EXPECT_EQ(single.summary.termination, TerminationType::kFailure);
  EXPECT_NE(single.summary.message.find("breaks down"), std::string::npos)
      << single.summary.message;
  EXPECT_NE(single.summary.message.find("use multiple_shooting or riccati"), std::string::npos);
  EXPECT_GT(single.summary.multiply_accumulates, 0.0);
}

TEST(ShootingSolverTest, MultipleShootingRefusesAboveTheMemoryLimit) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kMultipleShooting, 1e-8);
  options.max_dense_solver_bytes = 10000;
  const Solved solved = Solve(options, &bundle.problem);
  EXPECT_EQ(solved.summary.termination, TerminationType::kFailure);
  EXPECT_NE(solved.summary.message.find("needs at least"), std::string::npos)
      << solved.summary.message;
  EXPECT_NE(solved.summary.message.find("inner.max_dense_solver_bytes"), std::string::npos);
}

}  // namespace
}  // namespace mcrewave
