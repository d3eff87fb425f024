// Tests of the built-in bar's own band-model MCRE problem (testing::BarMcreProblem,
// tests/reference/bar_mcre_problem.h), the reference the one road's MatrixMcreProblem is
// checked against: weights, the adjoint structure of the two sweeps, the cost at
// consistent data, the trusted clamp (ClampModel::kTrusted) and the pinned clamp
// (ClampModel::kPinned).
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "mcrewave/model/simulation.h"
#include "reference/bar_mcre_problem.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::Options;
using testing::ProblemBundle;
using testing::RelativeDifference;
using testing::Solve;
using testing::Solved;
using testing::Weights;

Matrix RandomField(const testing::BarMcreProblem& problem, unsigned seed) {
  std::mt19937 engine(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix field = problem.ZeroField();
  for (Eigen::Index i = 0; i < field.size(); ++i) field.data()[i] = 1e-6 * uniform(engine);
  return field;
}

// <x, G y> = <G x, y> to `tolerance` of ||x||_P ||G y||_P, and <x, G x>, <y, G y> < 0;
// returns G x.
Matrix ExpectSelfAdjointAndNegative(testing::BarMcreProblem& problem, const Matrix& x,
                                    const Matrix& y, double tolerance) {
  Matrix gx, gy, scratch;
  problem.ApplyIterationMap(x, &scratch, &gx);
  problem.ApplyIterationMap(y, &scratch, &gy);
  const double xgy = problem.InnerProduct(x, gy);
  const double gxy = problem.InnerProduct(gx, y);
  const double scale = problem.Norm(x) * problem.Norm(gy);
  EXPECT_LT(std::abs(xgy - gxy), tolerance * scale) << "<x,Gy> = " << xgy << ", <Gx,y> = " << gxy;
  EXPECT_LT(problem.InnerProduct(x, gx), 0.0);
  EXPECT_LT(problem.InnerProduct(y, gy), 0.0);
  return gx;
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
  testing::BarMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * 200e9);
  ExpectSelfAdjointAndNegative(problem, RandomField(problem, 1), RandomField(problem, 2), 1e-11);
}

INSTANTIATE_TEST_SUITE_P(Theta, IterationMapTest, ::testing::Values(0.5, 0.75, 1.0));

// The batched sweeps (the coupled solvers' start) give the single sweeps' results
// bit for bit, for 2 and 3 fields, zero inputs (null) included, odd and even n.
class BatchedSweepsTest : public ::testing::TestWithParam<int> {};

TEST_P(BatchedSweepsTest, MatchTheSingleSweepsExactly) {
  ProblemBundle bundle(MakeSmallCase(GetParam(), 40, 5.0, 2), Weights(0.3, 1.0));
  testing::BarMcreProblem& problem = bundle.problem;
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
  testing::BarMcreProblem& problem = bundle.problem;
  const Matrix zero = problem.ZeroField();
  Matrix displacement, image;
  problem.FixedPointMap(zero, &displacement, &image);
  // The free bar driven by the measured forces reproduces the clamped motion...
  EXPECT_LT(displacement.row(0).cwiseAbs().maxCoeff(),
            1e-9 * bundle.data.Values("uL").cwiseAbs().maxCoeff());
  EXPECT_LT((displacement.row(16).transpose() - bundle.data.Values("uL")).cwiseAbs().maxCoeff(),
            1e-9 * bundle.data.Values("uL").cwiseAbs().maxCoeff());
  // ...so T(0) = 0 and the cost vanishes.
  EXPECT_LT(problem.Cost(displacement, zero), 1e-18);
  EXPECT_EQ(problem.sweep_count(), 2);
}

// --- Trusted clamp ---

// The data of a small case with an interior displacement sensor inside the first
// element (its node-0 part must be dropped) and a strain gauge further on.
ChannelSet WithClampSideSensors(const ChannelSet& data) {
  ChannelSet with = data;
  with.Add("u@0.03", ChannelKind::kDisplacement, 0.02 * data.Values("uL"));
  with.Add("e@0.6", ChannelKind::kStrain, 1e-3 * data.Values("uL"));
  return with;
}

TEST(TrustedClampTest, HoldsTheClampAndDrivesTheBarByFLAlone) {
  // Noise-free data of the model's own discretisation: with W = 0 the model driven by
  // fL alone is the clamped bar of the data.
  const testing::SmallCase small = MakeSmallCase(16, 120, std::numeric_limits<double>::infinity(), 1);
  const BarModel model(small.bar);
  const ChannelSet data = MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data);
  testing::BarMcreProblem problem(model, data, Weights(0.01, 1.0), 200e9, 0.5, {},
                                  ClampModel::kTrusted);
  EXPECT_FALSE(problem.end_channels().u0);
  EXPECT_EQ(problem.num_interior_sensors(), 1);  // the reaction
  const Matrix zero = problem.ZeroField();
  Matrix displacement, retrograde;
  problem.DirectSweep(zero, true, &displacement);
  EXPECT_EQ(displacement.row(0).cwiseAbs().maxCoeff(), 0.0);
  const double uL_scale = data.Values("uL").cwiseAbs().maxCoeff();
  EXPECT_LT((displacement.row(16).transpose() - data.Values("uL")).cwiseAbs().maxCoeff(),
            1e-9 * uL_scale);
  // The reaction row K_01 U_1 against the data's f0 = row_0(M a + K u): they differ by
  // the inertia of the first element, O(l^2) at a fixed end (measured 65.5 N, 3.3 %
  // of max |f0|, on 16 elements).
  double largest_gap = 0.0;
  for (int j = 0; j <= problem.num_steps(); ++j) {
    largest_gap = std::max(largest_gap, std::abs(problem.ClampReaction(displacement.col(j).data()) -
                                                 data.Values("f0")[j]));
  }
  EXPECT_LT(largest_gap, 0.1 * data.Values("f0").cwiseAbs().maxCoeff())
      << data.Values("f0").cwiseAbs().maxCoeff();
  EXPECT_GT(largest_gap, 0.0);
  problem.RetrogradeSweep(displacement, true, &retrograde);
  EXPECT_EQ(retrograde.row(0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(retrograde.cwiseAbs().maxCoeff(), 0.0);
}

class TrustedClampMapTest : public ::testing::TestWithParam<double> {};

TEST_P(TrustedClampMapTest, IsSelfAdjointAndNegativeInPInnerProduct) {
  const double theta = GetParam();
  ProblemBundle bundle(MakeSmallCase(12, 60, 5.0, 2), Weights(1.0, 1.0), theta);
  const ChannelSet data = WithClampSideSensors(bundle.data);
  McreWeights weights = Weights(1.0, 1.0);
  weights.reaction_weight = 0.1;
  testing::BarMcreProblem problem(bundle.model, data, weights, 200e9, theta, {},
                                  ClampModel::kTrusted);
  problem.SetModulus(0.9 * 200e9);
  Matrix x = RandomField(problem, 1), y = RandomField(problem, 2);
  // Fields of the clamped problem: W_0 = 0.
  x.row(0).setZero();
  y.row(0).setZero();
  // Measured 8.7e-17 (theta 1/2) and 1.1e-17 (theta 1) of the scale.
  const Matrix gx = ExpectSelfAdjointAndNegative(problem, x, y, 1e-15);
  EXPECT_EQ(gx.row(0).cwiseAbs().maxCoeff(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Theta, TrustedClampMapTest, ::testing::Values(0.5, 1.0));

// Solves `problem` by CG (tolerance 1e-12) and by the all-at-once sparse LU, expects
// them to agree within `bounds` (relative differences of U, W and e^2) and returns
// the all-at-once solution.
Solved ExpectConjugateGradientsAgreeWithAllAtOnce(testing::BarMcreProblem* problem,
                                                  const testing::Agreement& bounds) {
  Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), problem);
  const Solved solved = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-12), problem);
  EXPECT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();
  EXPECT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  if (!reference.summary.IsSolutionUsable() || !solved.summary.IsSolutionUsable()) {
    return reference;
  }
  const testing::Agreement agreement = testing::Compare(solved, reference);
  EXPECT_LT(agreement.displacement, bounds.displacement);
  EXPECT_LT(agreement.retrograde, bounds.retrograde);
  EXPECT_LT(agreement.cost, bounds.cost);
  return reference;
}

TEST(TrustedClampTest, ConjugateGradientsAgreeWithTheAllAtOnceSolve) {
  ProblemBundle bundle(MakeSmallCase(12, 80, 5.0, 2), Weights(0.01, 1.0));
  const ChannelSet data = WithClampSideSensors(bundle.data);
  McreWeights weights = Weights(0.01, 1.0);
  weights.reaction_weight = 0.01;
  testing::BarMcreProblem problem(bundle.model, data, weights, 200e9, 0.5, {},
                                  ClampModel::kTrusted);
  problem.SetModulus(0.95 * 200e9);
  // Measured 1.5e-13 (U), 2.6e-12 (W), 1.7e-15 (e^2).
  ExpectConjugateGradientsAgreeWithAllAtOnce(&problem, {1e-12, 2e-11, 1e-14});
}

// The relative differences between the adjoint de^2/dE_z and central differences of
// e^2, z = 0, 1, on two zones of the small case under `clamp` with `weights`.
std::vector<double> ZoneGradientErrors(const McreWeights& weights, ClampModel clamp) {
  const testing::SmallCase small = MakeSmallCase(12, 80, 5.0, 2);
  ZoneLayout layout;
  layout.zone_count = 2;
  const BarModel model(small.bar, layout.ElementZones(small.bar));
  const ChannelSet data = MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data);
  testing::BarMcreProblem problem(model, data, weights, 200e9, 0.5, {}, clamp);
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-13);
  Vector moduli(2);
  moduli << 0.93 * 200e9, 1.04 * 200e9;
  problem.SetModuli(moduli);
  const Solved at = Solve(options, &problem);
  EXPECT_TRUE(at.summary.IsSolutionUsable()) << at.summary.FullReport();
  std::vector<double> errors(2, std::numeric_limits<double>::infinity());
  if (!at.summary.IsSolutionUsable()) return errors;
  for (int z = 0; z < 2; ++z) {
    const double step = 1e-5 * moduli[z];
    Vector plus = moduli, minus = moduli;
    plus[z] += step;
    minus[z] -= step;
    problem.SetModuli(plus);
    const double cost_plus = Solve(options, &problem).solution.cost;
    problem.SetModuli(minus);
    const double cost_minus = Solve(options, &problem).solution.cost;
    const double difference = (cost_plus - cost_minus) / (2.0 * step);
    errors[z] = std::abs(at.solution.cost_gradients[z] - difference) / std::abs(difference);
  }
  return errors;
}

TEST(TrustedClampTest, AdjointGradientsMatchFiniteDifferencesOfTheCost) {
  // Two zones: the reaction's explicit term belongs to the first.
  McreWeights weights = Weights(0.01, 1.0);
  weights.reaction_weight = 0.01;
  const std::vector<double> errors = ZoneGradientErrors(weights, ClampModel::kTrusted);
  // Measured relative differences 1.8e-9 (zone 0, with the reaction term) and 4.4e-9.
  EXPECT_LT(errors[0], 2e-8);
  EXPECT_LT(errors[1], 2e-8);
}

// --- Pinned clamp ---

// Weights of the pinned clamp's tests: u0's datum 0 with w_u0, f0 a load with w_r.
McreWeights PinnedWeights() {
  McreWeights weights = Weights(0.01, 1.0);
  weights.clamp_displacement_weight = 0.1;
  weights.reaction_weight = 0.1;
  return weights;
}

TEST(PinnedClampTest, WeighsTheKnownZeroAndTheReactionLoadWithTheirOwnWeights) {
  ProblemBundle bundle(MakeSmallCase(12, 60, 5.0, 2), Weights(0.01, 1.0));
  // w_u0 and w_r unequal, so that a swap of the two shows.
  McreWeights weights = PinnedWeights();
  weights.clamp_displacement_weight = 0.3;
  weights.reaction_weight = 0.05;
  testing::BarMcreProblem problem(bundle.model, bundle.data, weights, 200e9, 0.5, {},
                                  ClampModel::kPinned);
  problem.SetModulus(0.9 * 200e9);
  // alpha_0 = w_r L / (S E0), beta_0 = w_u0 S E0 / L (S = 1e-4, L = 1, E0 = 200 GPa).
  const double alpha0 = 0.05 / (1e-4 * 200e9), beta0 = 0.3 * 1e-4 * 200e9;
  EXPECT_DOUBLE_EQ(problem.inverse_alpha0(), 1.0 / alpha0);
  const SparseMatrix penalty = problem.PenaltyMatrix(), stiffness = problem.StiffnessMatrix();
  EXPECT_DOUBLE_EQ(penalty.coeff(0, 0), stiffness.coeff(0, 0) + 1.0 / alpha0);
  EXPECT_DOUBLE_EQ(penalty.coeff(12, 12), stiffness.coeff(12, 12) + 1.0 / problem.alpha());
  // At W = 0 the cost is the output misfit: u0 against 0 with beta_0, uL against its
  // data with beta, whatever the measured u0.
  const Matrix zero = problem.ZeroField();
  Matrix displacement;
  problem.DirectSweep(zero, true, &displacement);
  double expected = 0.0;
  for (int j = 0; j <= problem.num_steps(); ++j) {
    const double uL_misfit = displacement(12, j) - bundle.data.Values("uL")[j];
    expected += problem.QuadratureWeight(j) * problem.time_step() * 0.5 *
                (beta0 * displacement(0, j) * displacement(0, j) +
                 problem.beta() * uL_misfit * uL_misfit);
  }
  EXPECT_GT(bundle.data.Values("u0").cwiseAbs().maxCoeff(), 0.0);
  // Measured: equal to the last bit.
  EXPECT_NEAR(problem.Cost(displacement, zero), expected, 1e-15 * expected);
}

class PinnedClampMapTest : public ::testing::TestWithParam<double> {};

TEST_P(PinnedClampMapTest, IsSelfAdjointAndNegativeInPInnerProduct) {
  const double theta = GetParam();
  ProblemBundle bundle(MakeSmallCase(12, 60, 5.0, 2), Weights(1.0, 1.0), theta);
  const ChannelSet data = WithClampSideSensors(bundle.data);
  testing::BarMcreProblem problem(bundle.model, data, PinnedWeights(), 200e9, theta, {},
                                  ClampModel::kPinned);
  problem.SetModulus(0.9 * 200e9);
  // Measured 8.9e-17 (theta 1/2) and 4.4e-17 (theta 1) of the scale.
  ExpectSelfAdjointAndNegative(problem, RandomField(problem, 1), RandomField(problem, 2), 5e-16);
}

INSTANTIATE_TEST_SUITE_P(Theta, PinnedClampMapTest, ::testing::Values(0.5, 1.0));

TEST(PinnedClampTest, ConjugateGradientsAgreeWithTheAllAtOnceSolve) {
  ProblemBundle bundle(MakeSmallCase(12, 80, 5.0, 2), Weights(0.01, 1.0));
  const ChannelSet data = WithClampSideSensors(bundle.data);
  testing::BarMcreProblem problem(bundle.model, data, PinnedWeights(), 200e9, 0.5, {},
                                  ClampModel::kPinned);
  problem.SetModulus(0.95 * 200e9);
  // Measured 1.8e-13 (U), 3.6e-12 (W), 6.8e-16 (e^2).
  const Solved reference =
      ExpectConjugateGradientsAgreeWithAllAtOnce(&problem, {1e-12, 2e-11, 5e-15});
  // The streaming solver (traces, O(n) memory) solves the same problem.
  const Solved streamed =
      Solve(Options(CoupledSolverType::kStreamingConjugateGradient, 1e-12), &problem);
  ASSERT_TRUE(streamed.summary.IsSolutionUsable()) << streamed.summary.FullReport();
  // Measured 2.7e-16.
  EXPECT_NEAR(streamed.solution.cost, reference.solution.cost, 2e-15 * reference.solution.cost);
}

TEST(PinnedClampTest, TheMeasuredU0DoesNotEnter) {
  ProblemBundle bundle(MakeSmallCase(12, 80, 5.0, 2), Weights(0.01, 1.0));
  ChannelSet other = bundle.data;
  other.Values("u0") *= -3.0;
  testing::BarMcreProblem problem(bundle.model, bundle.data, PinnedWeights(), 200e9, 0.5, {},
                                  ClampModel::kPinned);
  testing::BarMcreProblem other_problem(bundle.model, other, PinnedWeights(), 200e9, 0.5, {},
                                        ClampModel::kPinned);
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-10);
  const Solved solved = Solve(options, &problem);
  const Solved other_solved = Solve(options, &other_problem);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  EXPECT_EQ(solved.solution.cost, other_solved.solution.cost);
  EXPECT_EQ(solved.solution.displacement, other_solved.solution.displacement);
  EXPECT_EQ(solved.solution.retrograde, other_solved.solution.retrograde);
}

TEST(PinnedClampTest, AdjointGradientsMatchFiniteDifferencesOfTheCost) {
  const std::vector<double> errors = ZoneGradientErrors(PinnedWeights(), ClampModel::kPinned);
  // Measured relative differences 2.4e-9 (zone 0) and 2.9e-9.
  EXPECT_LT(errors[0], 2e-8);
  EXPECT_LT(errors[1], 2e-8);
}

TEST(PinnedClampTest, RiccatiAndShootingSolveIt) {
  // A pinned clamp is another P and W_obs (docs/riccati_shooting.md section 5); they
  // refused it before. Measured against the space-time LU: U 8.2e-16, W 1.6e-14, e^2
  // 2.7e-15 (Riccati; both shootings 5.4e-16, 5.5e-15, 2.5e-15).
  ProblemBundle bundle(MakeSmallCase(8, 40, 5.0, 2), Weights(0.01, 1.0));
  testing::BarMcreProblem problem(bundle.model, bundle.data, PinnedWeights(), 200e9, 0.5, {},
                                  ClampModel::kPinned);
  problem.SetModulus(180e9);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-12), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();
  for (const CoupledSolverType type :
       {CoupledSolverType::kRiccati, CoupledSolverType::kSingleShooting,
        CoupledSolverType::kMultipleShooting}) {
    const Solved solved = Solve(Options(type, 1e-10), &problem);
    ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
    const testing::Agreement agreement = testing::Compare(solved, reference);
    std::cout << CoupledSolverTypeToString(type) << " vs all_at_once, pinned clamp: U "
              << agreement.displacement << ", W " << agreement.retrograde << ", e^2 "
              << agreement.cost << "\n";
    EXPECT_LT(agreement.displacement, 1e-14);
    EXPECT_LT(agreement.retrograde, 1.5e-13);
    EXPECT_LT(agreement.cost, 3e-14);
  }
}

}  // namespace
}  // namespace mcrewave
