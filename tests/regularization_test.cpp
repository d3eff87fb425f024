// The jump penalty of optim/regularization.h (its gradient against central differences),
// the discrepancy principle's weight and the L-curve corner on a linear least-squares
// problem whose answer is known in closed form.
#include "mcrewave/optim/regularization.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/core/types.h"
#include "optimizer_choices.h"

namespace mcrewave {
namespace {

using testing::kCeresLbfgs;
using testing::kNloptLbfgs;
using testing::OptimizerChoice;

// The largest gap between JumpPenalty's gradient (lambda 0.7, eps 1e-3) at p and its
// central differences of step 1e-6.
double WorstGradientError(RegularizationKind kind, const std::vector<double>& p,
                          const std::vector<ZonePair>* neighbours) {
  const int n = static_cast<int>(p.size());
  std::vector<double> gradient(n, 0.0);
  JumpPenalty(kind, 0.7, 1e-3, p.data(), n, gradient.data(), neighbours);
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const double step = 1e-6;
    std::vector<double> plus = p, minus = p;
    plus[i] += step;
    minus[i] -= step;
    const double difference = (JumpPenalty(kind, 0.7, 1e-3, plus.data(), n, nullptr, neighbours) -
                               JumpPenalty(kind, 0.7, 1e-3, minus.data(), n, nullptr, neighbours)) /
                              (2.0 * step);
    worst = std::max(worst, std::abs(difference - gradient[i]));
  }
  return worst;
}

TEST(JumpPenaltyTest, GradientMatchesCentralDifferences) {
  const std::vector<double> p{0.1, -0.2, 0.35, 0.35, 0.0004, -0.7, 0.2};
  const int n = static_cast<int>(p.size());
  for (RegularizationKind kind :
       {RegularizationKind::kTikhonov, RegularizationKind::kTotalVariation}) {
    const double worst = WorstGradientError(kind, p, nullptr);
    // Measured: 2.0e-10 (Tikhonov: exact quadratic, round-off only) and 1.5e-10 (TV:
    // the jump of 4e-4 lies within eps = 1e-3, curvature 1 / eps).
    EXPECT_LT(worst, 2e-9) << RegularizationKindToString(kind);
  }
  // The penalty adds to the gradient it is given.
  std::vector<double> gradient(n, 1.0);
  JumpPenalty(RegularizationKind::kNone, 0.7, 1e-3, p.data(), n, gradient.data());
  for (double g : gradient) EXPECT_EQ(g, 1.0);
}

// Pairs of zones with weights (a 2 x 3 grid's edges and a corner): the gradient against
// central differences; the chain given as pairs of weight 1 is the chain's penalty and
// gradient to the bit.
TEST(JumpPenaltyTest, PairsOfNeighbours) {
  const std::vector<double> p{0.1, -0.2, 0.35, 0.35, 0.0004, -0.7};
  const int n = static_cast<int>(p.size());
  const std::vector<ZonePair> grid = {{0, 1, 1.0}, {0, 3, 0.75}, {0, 4, 0.25}, {1, 2, 1.0},
                                      {1, 4, 1.0}, {2, 5, 1.0},  {3, 4, 1.0},  {4, 5, 1.0}};
  for (RegularizationKind kind :
       {RegularizationKind::kTikhonov, RegularizationKind::kTotalVariation}) {
    const double penalty = JumpPenalty(kind, 0.7, 1e-3, p.data(), n, nullptr, &grid);
    double expected = 0.0;
    for (const ZonePair& pair : grid) {
      const double d = p[pair.second] - p[pair.first];
      expected += pair.weight *
                  (kind == RegularizationKind::kTikhonov ? d * d : std::sqrt(d * d + 1e-6) - 1e-3);
    }
    EXPECT_NEAR(penalty, 0.7 * expected, 1e-15);
    // Measured: 1.8e-10 (Tikhonov) and 2.3e-10 (TV), as the chain's.
    EXPECT_LT(WorstGradientError(kind, p, &grid), 2e-9) << RegularizationKindToString(kind);

    std::vector<ZonePair> chain;
    for (int z = 0; z + 1 < n; ++z) chain.push_back({z, z + 1, 1.0});
    std::vector<double> by_pairs(n, 0.5), by_default(n, 0.5);
    EXPECT_EQ(JumpPenalty(kind, 0.7, 1e-3, p.data(), n, by_pairs.data(), &chain),
              JumpPenalty(kind, 0.7, 1e-3, p.data(), n, by_default.data()));
    EXPECT_EQ(by_pairs, by_default);
  }
  RegularizationOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.neighbours = {{0, 1, 1.0}, {1, 1, 1.0}};
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("neighbour pairs must join two distinct zones"), std::string::npos) << error;
  options.neighbours = {{0, 1, 0.0}};
  EXPECT_FALSE(options.IsValid(nullptr));
}

TEST(JumpPenaltyTest, ValuesOfBothKinds) {
  const std::vector<double> p{0.0, 0.3, 0.3, -0.1};
  EXPECT_NEAR(JumpPenalty(RegularizationKind::kTikhonov, 2.0, 1e-3, p.data(), 4, nullptr),
              2.0 * (0.09 + 0.0 + 0.16), 1e-15);
  const double eps = 1e-3;
  const double tv = (std::sqrt(0.09 + eps * eps) - eps) + 0.0 + (std::sqrt(0.16 + eps * eps) - eps);
  EXPECT_NEAR(JumpPenalty(RegularizationKind::kTotalVariation, 2.0, eps, p.data(), 4, nullptr),
              2.0 * tv, 1e-15);
}

// 1/2 |A p - b|^2 over 10 parameters.
class LeastSquares : public FirstOrderObjective {
 public:
  LeastSquares(Eigen::MatrixXd a, Eigen::VectorXd b) : a_(std::move(a)), b_(std::move(b)) {}
  int num_parameters() const override { return static_cast<int>(a_.cols()); }
  bool Evaluate(const double* x, double* cost, double* gradient) override {
    const Eigen::Map<const Eigen::VectorXd> p(x, a_.cols());
    const Eigen::VectorXd r = a_ * p - b_;
    *cost = 0.5 * r.squaredNorm();
    if (gradient != nullptr) Eigen::Map<Eigen::VectorXd>(gradient, a_.cols()) = a_.transpose() * r;
    return true;
  }
  // The Tikhonov minimiser of 1/2 |A p - b|^2 + lambda |L p|^2 and its misfit:
  // (A^T A + 2 lambda L^T L) p = A^T b.
  double Misfit(double lambda) const { return MisfitAndRoughness(lambda).first; }
  // The misfit and the roughness |L p|^2 there.
  std::pair<double, double> MisfitAndRoughness(double lambda) const {
    const int n = static_cast<int>(a_.cols());
    Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n - 1, n);
    for (int z = 0; z + 1 < n; ++z) {
      l(z, z) = -1.0;
      l(z, z + 1) = 1.0;
    }
    const Eigen::MatrixXd normal = a_.transpose() * a_ + 2.0 * lambda * l.transpose() * l;
    const Eigen::VectorXd p = normal.ldlt().solve(a_.transpose() * b_);
    return {0.5 * (a_ * p - b_).squaredNorm(), (l * p).squaredNorm()};
  }

 private:
  Eigen::MatrixXd a_;
  Eigen::VectorXd b_;
};

// A (40 x 10, Gaussian kernels) and b = A p_true + white noise of std 0.05 (seed 3),
// p_true piecewise constant (-0.35 on parameter 6).
struct SmoothingProblem {
  static constexpr int m = 40, n = 10;
  static constexpr double sigma = 0.05;
  Eigen::MatrixXd a = Eigen::MatrixXd(m, n);
  Eigen::VectorXd b;
  SmoothingProblem() {
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < n; ++j) a(i, j) = std::exp(-0.5 * std::pow((i / 4.0 - j) / 1.5, 2));
    }
    Eigen::VectorXd truth = Eigen::VectorXd::Zero(n);
    truth[6] = -0.35;
    std::mt19937_64 engine(3);
    std::normal_distribution<double> normal;
    b = a * truth;
    for (int i = 0; i < m; ++i) b[i] += sigma * normal(engine);
  }
};

// Tight stopping tests, so that the weight search, not the minimiser, sets the figures.
BoundedMinimizerOptions TightOptions(OptimizerChoice algorithm) {
  BoundedMinimizerOptions options = algorithm.Apply({});
  options.step_tolerance = 1e-10;
  options.function_tolerance = 0.0;
  return options;
}

TEST(DiscrepancyPrincipleTest, ChoosesTheWeightOfTheClosedForm) {
  // b = A p_true + noise of std 0.05 over 40 rows, p_true piecewise constant; the target
  // is the expected misfit of the truth, 1/2 m sigma^2. The weight whose Tikhonov
  // misfit equals the target, lambda*, by bisection of the closed form; the discrepancy
  // principle's weight lies below it, within a factor of it that the tolerance bounds.
  const SmoothingProblem problem;
  const int m = problem.m, n = problem.n;
  const double sigma = problem.sigma;
  const Eigen::VectorXd& b = problem.b;
  const Eigen::MatrixXd& a = problem.a;
  LeastSquares data(a, b);
  const double target = 0.5 * m * sigma * sigma;
  // The weight whose misfit is `level`: misfit(lambda) increases; bisection in log lambda.
  const auto weight_of_misfit = [&](double level) {
    double low = 1e-10, high = 1e2;
    EXPECT_LT(data.Misfit(low), level);
    EXPECT_GT(data.Misfit(high), level);
    for (int i = 0; i < 200; ++i) {
      const double middle = std::sqrt(low * high);
      (data.Misfit(middle) > level ? high : low) = middle;
    }
    return low;
  };
  const double expected = weight_of_misfit(target);

  // The default tolerance and a tight one.
  for (double tolerance : {RegularizationOptions().weight_tolerance, 1e-3}) {
    for (OptimizerChoice algorithm : {kNloptLbfgs, kCeresLbfgs}) {
      const BoundedMinimizerOptions options = TightOptions(algorithm);
      RegularizationOptions regularization;
      regularization.weight_rule = WeightRule::kDiscrepancy;
      regularization.weight_tolerance = tolerance;
      regularization.refinement_steps = 10;
      // Absolute weights 1e2 down to 1e-10: the options are relative to the start's cost.
      const double start_cost = 0.5 * b.squaredNorm();
      regularization.max_weight = 1e2 / start_cost;
      regularization.min_weight = 1e-10 / start_cost;
      const RegularizedMinimization result =
          MinimizeRegularized(options, regularization, &data, std::vector<double>(n, -5.0),
                              std::vector<double>(n, 5.0), std::vector<double>(n, 0.0), target);
      ASSERT_TRUE(result.IsSolutionUsable()) << result.minimizer.FullReport();
      EXPECT_EQ(result.weight_choice, "discrepancy");
      EXPECT_LE(result.misfit, target);
      EXPECT_LE(result.weight, expected * 1.001);
      // Measured with both minimisers: tolerance 0.25, lambda = 1.3708 against lambda* =
      // 1.4763, 3 minimisations (2 of the grid, 1 of regula falsi; the 4 bisections of
      // log lambda this replaced made 7 for 1.3335); tolerance 1e-3, lambda = 1.47629,
      // 6 minimisations (where bisection would need 11 to bracket lambda* as closely).
      EXPECT_GE(result.weight, expected / (1.0 + tolerance));
      EXPECT_LE(result.path.size(), tolerance > 0.1 ? 3u : 6u);
      // The misfit at the result is the closed form's at that weight.
      EXPECT_NEAR(result.misfit, data.Misfit(result.weight), 1e-6 * target);
    }
  }
}

// 3 parameters fitted to the first 3 of b = (1, ..., 6); rows 3..5 cannot be fitted:
// misfit >= 1/2 (16 + 25 + 36).
LeastSquares WithThreeUnfittableRows() {
  Eigen::VectorXd b(6);
  b << 1, 2, 3, 4, 5, 6;
  return LeastSquares(Eigen::MatrixXd::Identity(6, 3), b);
}

// The discrepancy principle on the absolute weights 1 down to 1e-3: relative to the
// start's cost 1/2 |b|^2 = 45.5 of WithThreeUnfittableRows.
RegularizationOptions DiscrepancyFromOneToOneThousandth() {
  RegularizationOptions regularization;
  regularization.weight_rule = WeightRule::kDiscrepancy;
  regularization.max_weight = 1.0 / 45.5;
  regularization.min_weight = 1e-3 / 45.5;
  return regularization;
}

TEST(DiscrepancyPrincipleTest, AnUnreachableTargetFallsBackToTheMisfitFloor) {
  LeastSquares data = WithThreeUnfittableRows();
  BoundedMinimizerOptions options;
  const RegularizationOptions regularization = DiscrepancyFromOneToOneThousandth();
  const RegularizedMinimization result =
      MinimizeRegularized(options, regularization, &data, std::vector<double>(3, -10.0),
                          std::vector<double>(3, 10.0), std::vector<double>(3, 0.0), 1.0);
  // The grid 1, 0.01 misses; its floor (0.01's misfit) + 10 % is met at once by weight 1
  // (misfit 38.94 against 38.5 * 1.1): kept, no refinement (nothing missed above it).
  EXPECT_EQ(result.weight_choice, "misfit_floor");
  EXPECT_NEAR(result.weight, 1.0, 1e-12);
  EXPECT_EQ(result.path.size(), 2u);
  EXPECT_GT(result.misfit_floor, 38.5);
  EXPECT_LT(result.misfit, 1.1 * result.misfit_floor);
}

// floor_margin noise_fit on the problem above: the floor F (the misfit at the lightest
// weight, 0.01) + (n + 2 sqrt(2 n)) s^2 / (2 m) for n = 3 parameters, the target's mean
// m = 1 and its draws' standard deviation s; F + 0.1 lies below weight 1's misfit, so the
// regula falsi brings the weight below 1, where ten_percent keeps 1. Without s the
// margin is ten_percent's.
TEST(DiscrepancyPrincipleTest, TheNoiseFitMarginHoldsTheFloorToWhatTheParametersFit) {
  LeastSquares data = WithThreeUnfittableRows();
  BoundedMinimizerOptions options;
  RegularizationOptions regularization = DiscrepancyFromOneToOneThousandth();
  regularization.floor_margin = FloorMargin::kNoiseFit;
  const std::vector<double> lower(3, -10.0), upper(3, 10.0), start(3, 0.0);
  const double n = 3.0, margin = 0.1;
  const double spread = std::sqrt(margin * 2.0 / (n + 2.0 * std::sqrt(2.0 * n)));
  const RegularizedMinimization result =
      MinimizeRegularized(options, regularization, &data, lower, upper, start, 1.0, spread);
  EXPECT_EQ(result.weight_choice, "misfit_floor");
  EXPECT_NEAR(result.floor_target, result.misfit_floor + margin, 1e-12 * result.misfit_floor);
  EXPECT_DOUBLE_EQ(result.AttainableTarget(), result.floor_target);
  EXPECT_LE(result.misfit, result.floor_target);
  // Measured: weight 0.1603 after the grid's 2 weights and 4 regula falsi steps, its
  // misfit 38.5589 against the floor 38.5004 + 0.1.
  EXPECT_LT(result.weight, 0.5);
  EXPECT_GT(result.weight, 0.01);
  EXPECT_EQ(result.path.size(), 6u);
  // The misfit at the weight kept is the closed form's at that weight (measured: 8.5e-11
  // relative).
  EXPECT_NEAR(result.misfit, data.Misfit(result.weight), 1e-9 * result.misfit);

  const RegularizedMinimization unknown =
      MinimizeRegularized(options, regularization, &data, lower, upper, start, 1.0, -1.0);
  EXPECT_NEAR(unknown.floor_target, (1.0 + kMisfitFloorMargin) * unknown.misfit_floor, 1e-15);
  EXPECT_NEAR(unknown.weight, 1.0, 1e-12);
}

TEST(LCurveCornerTest, FindsTheBendOfAnLAndNoneOfALine) {
  // ln misfit 2, 1, 0, 0, 0 against ln roughness 0, 0, 0, 1, 2: a right angle at
  // index 2, 0.707 below the chord (indices 1 and 3: 0.354).
  const std::vector<double> misfits{std::exp(2.0), std::exp(1.0), 1.0, 1.0, 1.0};
  const std::vector<double> roughness{1.0, 1.0, 1.0, std::exp(1.0), std::exp(2.0)};
  EXPECT_EQ(LCurveCorner(misfits, roughness), 2);
  // A straight line bends nowhere; fewer than 3 points or a zero value give none.
  EXPECT_EQ(LCurveCorner({4.0, 2.0, 1.0}, {1.0, 2.0, 4.0}), -1);
  EXPECT_EQ(LCurveCorner({4.0, 1.0}, {1.0, 4.0}), -1);
  EXPECT_EQ(LCurveCorner({4.0, 1.0, 1.0}, {1.0, 0.0, 4.0}), -1);
}

// The closed form's L-curve at the first `points` weights of the grid 1e2, 1, 1e-2, ...
// (the default grid factor, 100).
struct ClosedFormLCurve {
  std::vector<double> weights, misfits, roughness;
};
ClosedFormLCurve ClosedFormOnTheGrid(const LeastSquares& data, int points) {
  ClosedFormLCurve curve;
  double weight = 1e2;
  for (int k = 0; k < points; ++k, weight /= RegularizationOptions().grid_factor) {
    const auto [misfit, rough] = data.MisfitAndRoughness(weight);
    curve.weights.push_back(weight);
    curve.misfits.push_back(misfit);
    curve.roughness.push_back(rough);
  }
  return curve;
}

// The L-curve corner of `data` on the grid 1e2 .. 1e-10 (factor 100) with both
// minimisers and `rule`, against the closed form's corner at the same weights, for a
// `target` no weight meets.
void ExpectTheClosedFormsCorner(const LeastSquares& closed_form, WeightRule rule, double target) {
  LeastSquares data = closed_form;
  const int n = data.num_parameters();
  RegularizationOptions regularization;
  regularization.weight_rule = rule;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  double start_cost = 0.0;
  ASSERT_TRUE(data.Evaluate(zero.data(), &start_cost, nullptr));
  regularization.max_weight = 1e2 / start_cost;
  regularization.min_weight = 1e-10 / start_cost;
  const auto [weights, misfits, roughness] = ClosedFormOnTheGrid(data, 7);  // 1e2 .. 1e-10
  const int corner = LCurveCorner(misfits, roughness);
  ASSERT_GT(corner, 0);
  for (OptimizerChoice algorithm : {kNloptLbfgs, kCeresLbfgs}) {
    const BoundedMinimizerOptions options = TightOptions(algorithm);
    const RegularizedMinimization result =
        MinimizeRegularized(options, regularization, &data, std::vector<double>(n, -5.0),
                            std::vector<double>(n, 5.0), std::vector<double>(n, 0.0), target);
    ASSERT_TRUE(result.IsSolutionUsable()) << result.minimizer.FullReport();
    EXPECT_EQ(result.weight_choice, "l_curve");
    // Measured with both minimisers: the corner at lambda = 1 (7 minimisations), the
    // closed form's to 1e-12.
    EXPECT_NEAR(result.weight, weights[corner], 1e-12 * weights[corner]);
    EXPECT_NEAR(result.misfit, misfits[corner], 1e-6 * misfits[corner]);
    EXPECT_EQ(result.path.size(), weights.size());
    EXPECT_EQ(result.target_misfit, target);
  }
}

// The closed-form test's problem with rows 40..45 that no p fits (b = 1 there, A = 0):
// its misfit floor, 3, exceeds that test's target.
LeastSquares WithUnfittableRows(const SmoothingProblem& problem) {
  const int m = problem.m, n = problem.n;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m + 6, n);
  a.topRows(m) = problem.a;
  Eigen::VectorXd b = Eigen::VectorXd::Ones(m + 6);
  b.head(m) = problem.b;
  return LeastSquares(a, b);
}

TEST(DiscrepancyPrincipleTest, AnUnreachableTargetTakesTheCornerOfTheClosedFormsLCurve) {
  // The target is out of reach: the weight is the grid's L-curve corner.
  const SmoothingProblem problem;
  const double target = 0.5 * problem.m * problem.sigma * problem.sigma;
  ExpectTheClosedFormsCorner(WithUnfittableRows(problem), WeightRule::kDiscrepancy, target);
  ExpectTheClosedFormsCorner(WithUnfittableRows(problem), WeightRule::kLCurve, target);
}

// The closed-form test's problem by the L-curve rule (Ceres' L-BFGS) on the absolute
// weights 1e2, 1, 1e-2, ... down to 1e-10.
RegularizedMinimization LCurveOnTheGrid(const SmoothingProblem& problem, double target) {
  LeastSquares data(problem.a, problem.b);
  const double start_cost = 0.5 * problem.b.squaredNorm();
  RegularizationOptions regularization;
  regularization.max_weight = 1e2 / start_cost;
  regularization.min_weight = 1e-10 / start_cost;
  return MinimizeRegularized(
      TightOptions(kCeresLbfgs), regularization, &data, std::vector<double>(problem.n, -5.0),
      std::vector<double>(problem.n, 5.0), std::vector<double>(problem.n, 0.0), target);
}

TEST(LCurveRuleTest, KeepsTheLargestWeightWhenItMeetsTheTarget) {
  // The closed-form test's problem with a target above the misfit at the grid's first
  // weight by more than the margin: kept, as the discrepancy principle keeps it, with
  // no other minimisation.
  const SmoothingProblem problem;
  const LeastSquares data(problem.a, problem.b);
  const RegularizedMinimization kept =
      LCurveOnTheGrid(problem, data.Misfit(1e2) / (0.99 * kLCurveTopShare));
  ASSERT_TRUE(kept.IsSolutionUsable()) << kept.minimizer.FullReport();
  EXPECT_EQ(kept.weight_choice, "discrepancy");
  EXPECT_NEAR(kept.weight, 1e2, 1e-10);
  EXPECT_EQ(kept.path.size(), 1u);
  // Within the margin the descent goes on, to the next weight, 1, which meets the
  // target too: two points, no corner, that weight kept.
  const RegularizedMinimization next =
      LCurveOnTheGrid(problem, data.Misfit(1e2) / (1.01 * kLCurveTopShare));
  ASSERT_TRUE(next.IsSolutionUsable()) << next.minimizer.FullReport();
  EXPECT_EQ(next.path.size(), 2u);
  EXPECT_NEAR(next.weight, 1.0, 1e-12);
}

TEST(LCurveRuleTest, StopsAtTheFirstWeightThatMeetsTheTarget) {
  // The closed-form test's problem with targets first met at the grid's weight 1 and
  // at 1e-4: the descent stops there, and the weight is the corner of the points so
  // far (the closed form's), or that weight.
  const SmoothingProblem problem;
  const LeastSquares data(problem.a, problem.b);
  for (int first_met : {1, 3}) {
    const auto [weights, misfits, roughness] = ClosedFormOnTheGrid(data, first_met + 1);
    // Between the misfits at the weight first met and at the one before it.
    const double target = std::sqrt(misfits[first_met] * misfits[first_met - 1]);
    const int corner = LCurveCorner(misfits, roughness);
    const double expected = corner >= 0 ? weights[corner] : weights[first_met];
    const RegularizedMinimization result = LCurveOnTheGrid(problem, target);
    ASSERT_TRUE(result.IsSolutionUsable()) << result.minimizer.FullReport();
    EXPECT_EQ(result.path.size(), static_cast<std::size_t>(first_met + 1));
    EXPECT_EQ(result.weight_choice, corner >= 0 ? "l_curve" : "discrepancy");
    // Measured: no corner of 2 points (weight 1 kept); the corner of 4 at 0.01.
    EXPECT_NEAR(result.weight, expected, 1e-12 * expected);
  }
}

// The data cost of `data` until `limit` evaluations, then failures: a minimisation
// that cannot converge.
class FailingAfter : public FirstOrderObjective {
 public:
  FailingAfter(FirstOrderObjective* data, int limit) : data_(data), limit_(limit) {}
  int num_parameters() const override { return data_->num_parameters(); }
  bool Evaluate(const double* x, double* cost, double* gradient) override {
    if (++count_ > limit_) return false;
    return data_->Evaluate(x, cost, gradient);
  }

 private:
  FirstOrderObjective* data_;
  int limit_;
  int count_ = 0;
};

TEST(DiscrepancyPrincipleTest, AMinimisationThatFailsBelowTheGridsTopEndsTheDescent) {
  // The unreachable target of the L-curve test. A first search stops the grid at its
  // third weight (1e2, 1, 1e-2); a second one runs the whole grid on data that fail
  // once the first search's evaluations are spent, so that the minimisation at 1e-4
  // fails: the descent stops there and chooses among the three converged weights,
  // as the first search did, instead of returning the failure.
  const SmoothingProblem problem;
  const int n = problem.n;
  LeastSquares data = WithUnfittableRows(problem);
  const double target = 0.5 * problem.m * problem.sigma * problem.sigma;
  const std::vector<double> lower(n, -5.0), upper(n, 5.0), start(n, 0.0);
  double start_cost = 0.0;
  ASSERT_TRUE(data.Evaluate(start.data(), &start_cost, nullptr));
  const BoundedMinimizerOptions options = TightOptions(kCeresLbfgs);
  RegularizationOptions regularization;
  regularization.max_weight = 1e2 / start_cost;
  regularization.min_weight = 1e-2 / start_cost;
  const RegularizedMinimization three =
      MinimizeRegularized(options, regularization, &data, lower, upper, start, target);
  ASSERT_TRUE(three.IsSolutionUsable()) << three.minimizer.FullReport();
  ASSERT_EQ(three.path.size(), 3u);

  regularization.min_weight = 1e-10 / start_cost;
  FailingAfter failing(&data, three.evaluations);
  const RegularizedMinimization stopped =
      MinimizeRegularized(options, regularization, &failing, lower, upper, start, target);
  ASSERT_TRUE(stopped.IsSolutionUsable()) << stopped.minimizer.FullReport();
  EXPECT_EQ(stopped.path.size(), 4u);
  EXPECT_FALSE(stopped.path.back().termination == TerminationType::kConvergence);
  EXPECT_EQ(stopped.weight_choice, three.weight_choice);
  EXPECT_EQ(stopped.weight, three.weight);
  EXPECT_EQ(stopped.misfit, three.misfit);
}

// Merging on 1/2 |p - b|^2 (A = I): the refit of a group is the mean of its b, its
// misfit 1/2 sum_z (b_z - mean)^2, in closed form. b = p_true + white noise of std
// 0.02 (seed 5), p_true piecewise constant with -0.35 on zones 3 and 4; the target is
// the truth's expected misfit 1/2 n sigma^2.
struct MergeProblem {
  static constexpr int n = 8;
  static constexpr double sigma = 0.02;
  Eigen::VectorXd b = Eigen::VectorXd(n);
  MergeProblem() {
    std::mt19937_64 engine(5);
    std::normal_distribution<double> normal;
    for (int z = 0; z < n; ++z) b[z] = (z == 3 || z == 4 ? -0.35 : 0.0) + sigma * normal(engine);
  }
  // The closed-form misfit of the groups that start at the zones of `starts`.
  double Misfit(unsigned starts) const {
    double misfit = 0.0;
    for (int first = 0; first < n;) {
      int last = first + 1;
      while (last < n && !(starts >> last & 1u)) ++last;
      const double mean = b.segment(first, last - first).mean();
      misfit += 0.5 * (b.segment(first, last - first).array() - mean).square().sum();
      first = last;
    }
    return misfit;
  }
};

TEST(MergeNeighbouringZonesTest, KeepsTheFewestGroupsTheNoiseExplains) {
  const MergeProblem problem;
  const int n = problem.n;
  LeastSquares data(Eigen::MatrixXd::Identity(n, n), problem.b);
  const std::vector<double> lower(n, -5.0), upper(n, 5.0);
  const std::vector<double> start(problem.b.data(), problem.b.data() + n);
  const double target = 0.5 * n * problem.sigma * problem.sigma;
  // The independent reference: every partition into runs of neighbours (bit z of
  // `starts`: a group starts at zone z), the fewest groups within the target.
  int fewest = n + 1;
  unsigned best = 0;
  for (unsigned starts = 1; starts < (1u << n); starts += 2) {
    const int groups = __builtin_popcount(starts);
    if (problem.Misfit(starts) <= target && groups < fewest) {
      fewest = groups;
      best = starts;
    }
  }
  // The truth's three groups: [0, 2], [3, 4], [5, 7].
  ASSERT_EQ(best, 1u | 1u << 3 | 1u << 5);

  const ZoneMerge merge =
      MergeNeighbouringZones(TightOptions(kCeresLbfgs), &data, lower, upper, start, target);
  EXPECT_EQ(merge.groups, 3);
  EXPECT_EQ(merge.merges, n - 3);
  EXPECT_EQ(merge.group_of, (std::vector<int>{0, 0, 0, 1, 1, 2, 2, 2}));
  ASSERT_EQ(merge.x.size(), static_cast<std::size_t>(n));
  double worst = 0.0;
  for (int z = 0; z < n; ++z) {
    const int first = z < 3 ? 0 : z < 5 ? 3 : 5;
    const int size = z < 3 ? 3 : z < 5 ? 2 : 3;
    worst = std::max(worst, std::abs(merge.x[z] - problem.b.segment(first, size).mean()));
  }
  // Measured: 2.8e-16 in x here, 4.7e-13 for the single group below (after seven
  // refits, each stopped by the step tolerance 1e-10); the misfit to round-off.
  EXPECT_LT(worst, 3e-15);
  EXPECT_NEAR(merge.misfit, problem.Misfit(best), 1e-14 * problem.Misfit(best));

  // No merge meets a target of 0: the regularised point stands (x empty).
  const ZoneMerge none =
      MergeNeighbouringZones(TightOptions(kCeresLbfgs), &data, lower, upper, start, 0.0);
  EXPECT_EQ(none.merges, 0);
  EXPECT_EQ(none.groups, n);
  EXPECT_EQ(none.refits, n - 1);
  EXPECT_TRUE(none.x.empty());
  // A target above the homogeneous misfit merges every zone into b's mean.
  const ZoneMerge all =
      MergeNeighbouringZones(TightOptions(kCeresLbfgs), &data, lower, upper, start, 1.0);
  EXPECT_EQ(all.groups, 1);
  ASSERT_EQ(all.x.size(), static_cast<std::size_t>(n));
  EXPECT_NEAR(all.x[0], problem.b.mean(), 5e-12);
}

TEST(RegularizationOptionsTest, NamesAndMessages) {
  RegularizationKind kind = RegularizationKind::kNone;
  ASSERT_TRUE(StringToRegularizationKind("total_variation", &kind));
  EXPECT_EQ(kind, RegularizationKind::kTotalVariation);
  EXPECT_STREQ(RegularizationKindToString(RegularizationKind::kTikhonov), "tikhonov");
  EXPECT_FALSE(StringToRegularizationKind("tv", &kind));
  for (WeightRule rule : {WeightRule::kLCurve, WeightRule::kDiscrepancy}) {
    WeightRule back = rule == WeightRule::kLCurve ? WeightRule::kDiscrepancy : WeightRule::kLCurve;
    ASSERT_TRUE(StringToWeightRule(WeightRuleToString(rule), &back));
    EXPECT_EQ(back, rule);
  }
  WeightRule rule = WeightRule::kLCurve;
  EXPECT_FALSE(StringToWeightRule("lcurve", &rule));
  RegularizationOptions options;
  EXPECT_EQ(options.weight_rule, WeightRule::kLCurve);
  std::string error;
  EXPECT_TRUE(options.IsValid(&error));
  options.grid_factor = 1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("zone_identification.grid_factor"), std::string::npos);
}

}  // namespace
}  // namespace mcrewave
