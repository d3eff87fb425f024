// Tests of the discrete MCRE problem: weights, the adjoint structure of the two
// sweeps, and the cost at consistent data.
#include "mcrewave/mcre/mcre_problem.h"

#include <gtest/gtest.h>

#include <random>

#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::ProblemBundle;
using testing::Weights;

Matrix RandomField(const McreProblem& problem, unsigned seed) {
  std::mt19937 engine(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix field = problem.ZeroField();
  for (Eigen::Index i = 0; i < field.size(); ++i) field.data()[i] = 1e-6 * uniform(engine);
  return field;
}

TEST(McreWeightsTest, DefaultWeightsAreValid) {
  std::string why;
  EXPECT_TRUE(McreWeights().IsValid(&why)) << why;
  EXPECT_FALSE(Weights(0.0, 1.0).IsValid(&why));
  EXPECT_NE(why.find("mcre.w_u"), std::string::npos);
  EXPECT_FALSE(Weights(1.0, -1.0).IsValid(&why));
  EXPECT_NE(why.find("mcre.w_f"), std::string::npos);
}

TEST(McreProblemTest, WeightsFollowTheFormulation) {
  // beta = w_u S E0 / L, alpha = w_f L / (S E0) with E0 = 200 GPa, S = 1e-4, L = 1.
  ProblemBundle bundle(MakeSmallCase(10, 20, 10.0, 1), Weights(0.5, 2.0));
  EXPECT_DOUBLE_EQ(bundle.problem.beta(), 0.5 * 1e-4 * 200e9 / 1.0);
  EXPECT_DOUBLE_EQ(bundle.problem.alpha(), 2.0 * 1.0 / (1e-4 * 200e9));
}

// G = T(.) - T(0) is self-adjoint and negative semi-definite in <.,.>_P: this holds
// only if the retrograde sweep is the exact adjoint of the direct sweep.
class IterationMapTest : public ::testing::TestWithParam<double> {};

TEST_P(IterationMapTest, IsSelfAdjointAndNegativeInPInnerProduct) {
  const double theta = GetParam();
  ProblemBundle bundle(MakeSmallCase(12, 60, 5.0, 2), Weights(1.0, 1.0), theta);
  McreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * 200e9);
  const Matrix x = RandomField(problem, 1), y = RandomField(problem, 2);
  Matrix gx, gy, scratch;
  problem.ApplyIterationMap(x, &scratch, &gx);
  problem.ApplyIterationMap(y, &scratch, &gy);
  const double xgy = problem.InnerProduct(x, gy);
  const double gxy = problem.InnerProduct(gx, y);
  const double scale = problem.Norm(x) * problem.Norm(gy);
  EXPECT_LT(std::abs(xgy - gxy), 1e-11 * scale) << "<x,Gy> = " << xgy << ", <Gx,y> = " << gxy;
  EXPECT_LT(problem.InnerProduct(x, gx), 0.0);
  EXPECT_LT(problem.InnerProduct(y, gy), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Theta, IterationMapTest, ::testing::Values(0.5, 0.75, 1.0));

// The batched sweeps (the coupled solvers' start) give the single sweeps' results
// bit for bit, for 2 and 3 fields, zero inputs (null) included, odd and even n.
class BatchedSweepsTest : public ::testing::TestWithParam<int> {};

TEST_P(BatchedSweepsTest, MatchTheSingleSweepsExactly) {
  ProblemBundle bundle(MakeSmallCase(GetParam(), 40, 5.0, 2), Weights(0.3, 1.0));
  McreProblem& problem = bundle.problem;
  problem.SetModulus(1.1 * 200e9);
  const Matrix zero = problem.ZeroField();
  const Matrix w1 = RandomField(problem, 3), w2 = RandomField(problem, 4);
  Matrix u1, u2, u3, expected;
  const long sweeps = problem.sweep_count();
  problem.DirectSweepsWithData({&w1, nullptr, &w2}, {&u1, &u2, &u3});
  EXPECT_EQ(problem.sweep_count(), sweeps + 3);
  problem.DirectSweep(w1, true, &expected);
  EXPECT_EQ((u1 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.DirectSweep(zero, true, &expected);
  EXPECT_EQ((u2 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.DirectSweep(w2, true, &expected);
  EXPECT_EQ((u3 - expected).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(u3.cwiseAbs().maxCoeff(), 0.0);

  Matrix r1, r2, r3;
  problem.RetrogradeSweepsWithData({&u1, &u3, nullptr}, {&r1, &r2, &r3});
  problem.RetrogradeSweep(u1, true, &expected);
  EXPECT_EQ((r1 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.RetrogradeSweep(u3, true, &expected);
  EXPECT_EQ((r2 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.RetrogradeSweep(zero, true, &expected);
  EXPECT_EQ((r3 - expected).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(r3.cwiseAbs().maxCoeff(), 0.0);

  problem.RetrogradeSweepsWithData({nullptr, &u2}, {&r1, &r2});
  EXPECT_EQ((r1 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.RetrogradeSweep(u2, true, &expected);
  EXPECT_EQ((r2 - expected).cwiseAbs().maxCoeff(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Elements, BatchedSweepsTest, ::testing::Values(9, 12));

TEST(McreProblemTest, ConsistentDataGiveZeroCostAtZeroRetrogradeField) {
  // Inverse crime: data from the model's own discretisation, no noise.
  ProblemBundle bundle(MakeSmallCase(16, 120, std::numeric_limits<double>::infinity(), 1),
                       Weights(1.0, 1.0));
  McreProblem& problem = bundle.problem;
  const Matrix zero = problem.ZeroField();
  Matrix displacement, image;
  problem.FixedPointMap(zero, &displacement, &image);
  // The free bar driven by the measured forces reproduces the clamped motion...
  EXPECT_LT(displacement.row(0).cwiseAbs().maxCoeff(), 1e-9 * bundle.data.uL.cwiseAbs().maxCoeff());
  EXPECT_LT((displacement.row(16).transpose() - bundle.data.uL).cwiseAbs().maxCoeff(),
            1e-9 * bundle.data.uL.cwiseAbs().maxCoeff());
  // ...so T(0) = 0 and the cost vanishes.
  EXPECT_LT(problem.Cost(displacement, zero), 1e-18);
  EXPECT_EQ(problem.sweep_count(), 2);
}

}  // namespace
}  // namespace mcrewave
