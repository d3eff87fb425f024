// Tests of the outer loop (Identify) on objectives made for the purpose: every
// algorithm of both optimisers finds a known minimum within bounds; the traps
// of NLopt are guarded (an exception in the objective is reported with its
// message, the best point seen is the one reported, limits are honoured); and
// the options name their keys when invalid.
#include "mcrewave/optim/identification.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

namespace mcrewave {
namespace {

// A scripted objective: cost(x) from a function of x, with its derivative;
// records every x; throws or fails on a chosen evaluation.
class ScriptedObjective : public ModulusObjective {
 public:
  ScriptedObjective(std::function<double(double)> cost, std::function<double(double)> derivative)
      : cost_(std::move(cost)), derivative_(std::move(derivative)) {}

  double modulus_scale() const override { return scale; }
  bool Evaluate(const double* parameters, double* cost, double* gradient) override {
    const double x = parameters[0];
    evaluated.push_back(x);
    const int count = static_cast<int>(evaluated.size());
    if (count == throw_at)
      throw std::runtime_error("disk on fire at evaluation " + std::to_string(count));
    if (count == fail_at || (fails && fails(count, x))) {
      message_ = "the inner solve diverged (scripted)";
      return false;
    }
    if (delay_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
    *cost = cost_(x);
    if (gradient != nullptr) gradient[0] = derivative_(x);
    return true;
  }
  std::string error_message() const override { return message_; }
  double ValleySpacing() override { return valley_spacing; }

  double scale = 1e9;
  double valley_spacing = 0.0;  // the predicted spacing in ln E (0: none)
  int throw_at = -1;
  int fail_at = -1;
  std::function<bool(int count, double x)> fails;  // also fail where this says so
  double delay_s = 0.0;
  std::vector<double> evaluated;

 private:
  std::function<double(double)> cost_;
  std::function<double(double)> derivative_;
  std::string message_;
};

// (x - 1.3)^2 + 0.5, minimum at x = 1.3 (E = 1.3 GPa with scale 1e9).
ScriptedObjective Parabola(double minimum = 1.3) {
  return ScriptedObjective([minimum](double x) { return (x - minimum) * (x - minimum) + 0.5; },
                           [minimum](double x) { return 2.0 * (x - minimum); });
}

IdentificationOptions Options(OptimizerType optimizer, OuterAlgorithm algorithm) {
  IdentificationOptions options;
  options.optimizer = optimizer;
  options.algorithm = algorithm;
  options.lower_bound = 0.5e9;
  options.upper_bound = 2.5e9;
  options.initial = 1.0e9;
  options.relative_tolerance = 1e-8;
  options.max_evaluations = 200;
  options.max_time = 60.0;
  options.scan_points = 0;  // the local optimisers alone (global_search_test.cpp: the scan)
  return options;
}

using Case = std::tuple<OptimizerType, OuterAlgorithm>;

class EveryAlgorithmTest : public ::testing::TestWithParam<Case> {};

TEST_P(EveryAlgorithmTest, FindsTheMinimumOfAParabola) {
  const auto [optimizer, algorithm] = GetParam();
  ScriptedObjective objective = Parabola();
  const IdentificationSummary summary = Identify(Options(optimizer, algorithm), &objective);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  // relative_tolerance 1e-8: measured 0 (BOBYQA, L-BFGS, SLSQP, Brent), 1.4e-9 (MMA),
  // 2.3e-9 (Sbplx), 5.3e-9 (COBYLA), 9.5e-12 (Ceres).
  EXPECT_NEAR(summary.modulus, 1.3e9, 5e-8 * 1.3e9) << summary.FullReport();
  // cost 0.5 + (x - 1.3)^2: measured 0.5 to the last bit for every algorithm; x within
  // 5e-8 would give 4e-15.
  EXPECT_NEAR(summary.cost, 0.5, 1e-14);
  EXPECT_EQ(summary.evaluations, static_cast<int>(objective.evaluated.size()));
  EXPECT_EQ(summary.gradient_evaluations > 0, UsesGradient(optimizer, algorithm, 1));
  EXPECT_EQ(summary.algorithm, ResolveAlgorithm(optimizer, algorithm, 1));
  for (const double x : objective.evaluated) {
    EXPECT_GE(x, 0.5);
    EXPECT_LE(x, 2.5);
  }
}

INSTANTIATE_TEST_SUITE_P(NloptAndCeres, EveryAlgorithmTest,
                         ::testing::Values(Case{OptimizerType::kNlopt, OuterAlgorithm::kDefault},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kCobyla},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kSbplx},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kMma},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kLbfgs},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kSlsqp},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kBrent},
                                           Case{OptimizerType::kNlopt, OuterAlgorithm::kSecant},
                                           Case{OptimizerType::kCeres, OuterAlgorithm::kDefault},
                                           Case{OptimizerType::kCeres, OuterAlgorithm::kBfgs}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(OptimizerTypeToString(std::get<0>(info.param))) +
                                  "_" + OuterAlgorithmToString(std::get<1>(info.param));
                         });

TEST(SecantTest, ConvergesFasterThanBobyqaOnASkewedValley) {
  // exp(x - 1.3) - (x - 1.3): minimum at 1.3, curvature 1 there, skewed (its third
  // derivative 1), from x = 1 without a curvature estimate (no scan): the first step
  // goes halfway to the upper bound, then the secant steps. Independent check: BOBYQA
  // on the same function and tolerance.
  const auto cost = [](double x) { return std::exp(x - 1.3) - (x - 1.3); };
  const auto gradient = [](double x) { return std::exp(x - 1.3) - 1.0; };
  ScriptedObjective secant_objective(cost, gradient);
  ScriptedObjective bobyqa_objective(cost, gradient);
  const IdentificationSummary secant =
      Identify(Options(OptimizerType::kNlopt, OuterAlgorithm::kSecant), &secant_objective);
  const IdentificationSummary bobyqa =
      Identify(Options(OptimizerType::kNlopt, OuterAlgorithm::kBobyqa), &bobyqa_objective);
  ASSERT_TRUE(secant.IsSolutionUsable()) << secant.FullReport();
  ASSERT_TRUE(bobyqa.IsSolutionUsable()) << bobyqa.FullReport();
  // relative_tolerance 1e-8: measured 5.4e-10 from the minimum (secant), BOBYQA's
  // within 1e-9 of it.
  EXPECT_NEAR(secant.modulus, 1.3e9, 5e-9 * 1.3e9);
  EXPECT_NEAR(secant.modulus, bobyqa.modulus, 1e-8 * 1.3e9);
  // Measured 7 evaluations against BOBYQA's 17.
  EXPECT_LE(secant.evaluations, 8);
  EXPECT_LT(2 * secant.evaluations, bobyqa.evaluations);
}

TEST(SecantTest, RefineFromTakesNewtonsStepWithTheGivenCurvature) {
  // The skewed valley above from x = 1.29, 0.01 from its minimum, as the next mesh of a
  // ladder starts (app/identification_run.h). With the curvature there (exp(-0.01),
  // d^2 cost / dx^2 in x) the first step is Newton's: the second point lies 5.0e-5 from
  // the minimum (measured; the cubic term's 0.01^2 / 2), and the secant stops after 4
  // evaluations against 6 without it, whose first step goes halfway to a bound.
  const auto cost = [](double x) { return std::exp(x - 1.3) - (x - 1.3); };
  const auto gradient = [](double x) { return std::exp(x - 1.3) - 1.0; };
  IdentificationOptions options = Options(OptimizerType::kNlopt, OuterAlgorithm::kSecant);
  options.initial = 1.29e9;
  options.scan_points = 41;  // not read: no scan
  ScriptedObjective with_curvature(cost, gradient);
  const IdentificationSummary newton = RefineFrom(options, &with_curvature, std::exp(-0.01));
  ScriptedObjective without(cost, gradient);
  const IdentificationSummary bisection = RefineFrom(options, &without, 0.0);
  ASSERT_TRUE(newton.IsSolutionUsable()) << newton.FullReport();
  ASSERT_TRUE(bisection.IsSolutionUsable()) << bisection.FullReport();
  ASSERT_GE(with_curvature.evaluated.size(), 2u);
  EXPECT_DOUBLE_EQ(with_curvature.evaluated[0], 1.29);
  std::printf("RefineFrom: %d evaluations with the curvature, %d without\n", newton.evaluations,
              bisection.evaluations);
  EXPECT_NEAR(with_curvature.evaluated[1], 1.3, 1e-4);
  EXPECT_NEAR(newton.modulus, 1.3e9, 5e-9 * 1.3e9);
  EXPECT_NEAR(without.evaluated[1], 0.5 * (1.29 + 2.5), 1e-12);
  EXPECT_LT(newton.evaluations, bisection.evaluations);
  EXPECT_EQ(newton.scan_evaluations, 0);
  // Invalid options are refused, as Identify refuses them.
  options.initial = 3e9;
  const IdentificationSummary refused = RefineFrom(options, &without, 1.0);
  EXPECT_EQ(refused.termination, TerminationType::kFailure);
  EXPECT_NE(refused.message.find("invalid options"), std::string::npos) << refused.message;
}

TEST(IdentificationSummaryTest, ReportsSayNoSecondValleyInsteadOfANan) {
  IdentificationSummary summary;
  summary.scan_moduli = {1e11, 2e11, 3e11};
  summary.local_minima = 1;
  for (const std::string& report : {summary.BriefReport(), summary.FullReport()}) {
    EXPECT_EQ(report.find("nan"), std::string::npos) << report;
    EXPECT_NE(report.find("second valley"), std::string::npos) << report;
  }
  summary.local_minima = 2;
  summary.second_modulus = 2.5e11;
  summary.cost_gap = 0.125;
  EXPECT_NE(summary.BriefReport().find("scaled cost gap to the second 0.125"), std::string::npos);
  EXPECT_NE(summary.FullReport().find("second minimum         2.5e+11 Pa"), std::string::npos);
}

TEST(IdentificationTest, CeresNeedsFewerEvaluationsThanBobyqaOnASmoothMinimum) {
  ScriptedObjective for_nlopt = Parabola();
  ScriptedObjective for_ceres = Parabola();
  const IdentificationSummary nlopt =
      Identify(Options(OptimizerType::kNlopt, OuterAlgorithm::kBobyqa), &for_nlopt);
  const IdentificationSummary ceres =
      Identify(Options(OptimizerType::kCeres, OuterAlgorithm::kDefault), &for_ceres);
  ASSERT_TRUE(nlopt.IsSolutionUsable() && ceres.IsSolutionUsable());
  EXPECT_LT(ceres.evaluations, nlopt.evaluations);
  // Measured 9.5e-12 apart, relative.
  EXPECT_NEAR(ceres.modulus, nlopt.modulus, 1e-10 * nlopt.modulus);
}

TEST(IdentificationTest, MinimumBeyondABoundStaysInsideTheBounds) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    ScriptedObjective objective = Parabola(3.0);
    const IdentificationSummary summary =
        Identify(Options(optimizer, OuterAlgorithm::kDefault), &objective);
    EXPECT_LE(summary.modulus, 2.5e9) << summary.FullReport();
    // Measured: on the bound (NLopt) and 6.7e-9 below it (Ceres).
    EXPECT_GT(summary.modulus, (1.0 - 5e-8) * 2.5e9) << summary.FullReport();
    for (const double x : objective.evaluated) EXPECT_LE(x, 2.5);
  }
}

TEST(IdentificationTest, ExceptionInTheObjectiveUnderNloptKeepsItsMessageAndTheBestPoint) {
  ScriptedObjective objective = Parabola();
  objective.throw_at = 6;
  const IdentificationSummary summary =
      Identify(Options(OptimizerType::kNlopt, OuterAlgorithm::kBobyqa), &objective);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_FALSE(summary.IsSolutionUsable());
  EXPECT_NE(summary.message.find("the objective threw: disk on fire at evaluation 6"),
            std::string::npos)
      << summary.message;
  // NLopt stopped at once, and the best of the first five is reported.
  ASSERT_EQ(objective.evaluated.size(), 6u);
  double best_x = objective.evaluated[0];
  for (int i = 1; i < 5; ++i) {
    if (std::abs(objective.evaluated[i] - 1.3) < std::abs(best_x - 1.3)) {
      best_x = objective.evaluated[i];
    }
  }
  EXPECT_DOUBLE_EQ(summary.modulus, best_x * 1e9);
}

TEST(IdentificationTest, ExceptionInTheObjectiveUnderCeresKeepsItsMessage) {
  ScriptedObjective objective = Parabola();
  objective.throw_at = 3;
  const IdentificationSummary summary =
      Identify(Options(OptimizerType::kCeres, OuterAlgorithm::kDefault), &objective);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_NE(summary.message.find("disk on fire at evaluation 3"), std::string::npos)
      << summary.message;
  EXPECT_EQ(objective.evaluated.size(), 3u);
  EXPECT_GT(summary.modulus, 0.0);
}

TEST(IdentificationTest, FailedEvaluationStopsWithTheObjectiveMessage) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    // The second evaluation fails: NLopt's default, the secant, converges on the
    // parabola in 3.
    ScriptedObjective objective = Parabola();
    objective.fail_at = 2;
    const IdentificationSummary summary =
        Identify(Options(optimizer, OuterAlgorithm::kDefault), &objective);
    EXPECT_EQ(summary.termination, TerminationType::kFailure) << summary.FullReport();
    EXPECT_NE(summary.message.find("the inner solve diverged (scripted)"), std::string::npos)
        << summary.message;
    EXPECT_EQ(objective.evaluated.size(), 2u);
  }
}

TEST(IdentificationTest, FailureAtTheFirstEvaluationLeavesNoModulus) {
  ScriptedObjective objective = Parabola();
  objective.fail_at = 1;
  const IdentificationSummary summary =
      Identify(Options(OptimizerType::kNlopt, OuterAlgorithm::kDefault), &objective);
  EXPECT_FALSE(summary.IsSolutionUsable());
  EXPECT_EQ(summary.modulus, -1.0);
}

TEST(IdentificationTest, EvaluationLimitIsHonouredAndTheBestPointReported) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    // A narrow minimum far from the start: not reached in 5 evaluations.
    ScriptedObjective objective(
        [](double x) { return 1.0 - std::exp(-std::pow((x - 2.2) / 0.01, 2)) + 0.1 * x; },
        [](double x) {
          return 2.0 * (x - 2.2) / 1e-4 * std::exp(-std::pow((x - 2.2) / 0.01, 2)) + 0.1;
        });
    IdentificationOptions options = Options(optimizer, OuterAlgorithm::kDefault);
    options.max_evaluations = 5;
    const IdentificationSummary summary = Identify(options, &objective);
    EXPECT_EQ(summary.termination, TerminationType::kNoConvergence) << summary.FullReport();
    EXPECT_NE(summary.message.find("outer.max_evaluations (5)"), std::string::npos)
        << summary.message;
    EXPECT_LE(objective.evaluated.size(), 5u);
    // The cost decreases with x away from 2.2: the best point is the least x seen.
    double least = objective.evaluated[0];
    for (const double x : objective.evaluated) least = std::min(least, x);
    EXPECT_DOUBLE_EQ(summary.modulus, least * 1e9);
  }
}

TEST(IdentificationTest, TimeLimitIsHonoured) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    // 0.05 s an evaluation: the secant's 3 on the parabola take longer than 0.1 s.
    ScriptedObjective objective = Parabola();
    objective.delay_s = 0.05;
    IdentificationOptions options = Options(optimizer, OuterAlgorithm::kDefault);
    options.max_time = 0.1;
    const IdentificationSummary summary = Identify(options, &objective);
    EXPECT_EQ(summary.termination, TerminationType::kNoConvergence) << summary.FullReport();
    EXPECT_LT(summary.wall_time_s, 0.1 + 0.1);
    EXPECT_LE(objective.evaluated.size(), 3u);
  }
}

TEST(IdentificationTest, EvaluationLimitCountsTheScanAndCoversEveryRefinement) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    // A quartic, so that the scan's cubic Hermite estimate is not its minimum.
    ScriptedObjective objective(
        [](double x) { return std::pow(x - 1.3, 2) + std::pow(x - 1.3, 4); },
        [](double x) { return 2.0 * (x - 1.3) + 4.0 * std::pow(x - 1.3, 3); });
    IdentificationOptions options = Options(optimizer, OuterAlgorithm::kDefault);
    options.scan_points = 11;
    options.max_evaluations = 13;  // 2 left to the refinement: not enough to 1e-8
    const IdentificationSummary summary = Identify(options, &objective);
    EXPECT_EQ(summary.termination, TerminationType::kNoConvergence) << summary.FullReport();
    EXPECT_NE(summary.message.find("outer.max_evaluations (13, the scan's 11 included) reached"),
              std::string::npos)
        << summary.message;
    EXPECT_EQ(objective.evaluated.size(), 13u);
    EXPECT_EQ(summary.scan_evaluations + summary.evaluations, 13);
  }
}

TEST(IdentificationTest, TimeLimitCoversTheScan) {
  ScriptedObjective objective = Parabola();
  objective.delay_s = 0.02;
  IdentificationOptions options = Options(OptimizerType::kNlopt, OuterAlgorithm::kDefault);
  options.scan_points = 41;
  options.max_time = 0.1;
  const IdentificationSummary summary = Identify(options, &objective);
  EXPECT_EQ(summary.termination, TerminationType::kNoConvergence) << summary.FullReport();
  EXPECT_NE(summary.message.find("outer.max_time"), std::string::npos) << summary.message;
  EXPECT_LT(summary.wall_time_s, 0.1 + 0.1);
  EXPECT_LE(objective.evaluated.size(), 7u);
}

// Scan of 11 log-spaced points on [0.5, 2.5]: 0.5, 0.587, 0.690, 0.810, 0.951,
// 1.117, 1.312, 1.541, 1.810, 2.126, 2.5.
IdentificationOptions ScanOptions(OptimizerType optimizer) {
  IdentificationOptions options = Options(optimizer, OuterAlgorithm::kDefault);
  options.scan_points = 11;
  return options;
}

TEST(IdentificationTest, AFailedScanSampleIsNoEvidenceOfAMinimum) {
  // The parabola decreases up to 1.3; the sample at 0.810 fails, so 0.690 is
  // below its left neighbour only: not a minimum.
  ScriptedObjective objective = Parabola();
  objective.fail_at = 4;
  const IdentificationSummary summary = Identify(ScanOptions(OptimizerType::kNlopt), &objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_EQ(summary.scan_failures, 1);
  EXPECT_TRUE(std::isnan(summary.scan_costs[3]));
  EXPECT_EQ(summary.local_minima, 1);
  EXPECT_EQ(summary.refinements, 1);
  // Measured 1.1e-15 from the minimum, relative.
  EXPECT_NEAR(summary.modulus, 1.3e9, 1e-14 * 1.3e9);
}

TEST(IdentificationTest, AValleyHiddenBetweenTwoSamplesOfOneSlopeIsSeen) {
  // p(x) = -(x - 1.03)^3 + 0.0027 (x - 1.03) falls everywhere but on (1.0, 1.06),
  // between the samples 0.951 and 1.117, where both gradients are negative: the
  // costs alone show no minimum there; the Hermite interpolant of costs and
  // gradients (here the cubic itself) has its minimum at 1.0. The cost keeps
  // falling to the upper bound, a valley at the bound and the global minimum.
  ScriptedObjective objective([](double x) { return -std::pow(x - 1.03, 3) + 0.0027 * (x - 1.03); },
                              [](double x) { return -3.0 * std::pow(x - 1.03, 2) + 0.0027; });
  const IdentificationSummary summary = Identify(ScanOptions(OptimizerType::kNlopt), &objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  ASSERT_EQ(summary.local_minima, 2) << summary.FullReport();
  EXPECT_NEAR(summary.modulus, 2.5e9, 1e-7 * 2.5e9);
  // Lowest first: the bound, then the hidden valley at x = 1.03 - 0.03.
  EXPECT_NEAR(summary.valleys[1].estimated_modulus, 1.0e9, 1e-9 * 1e9);
  EXPECT_NEAR(summary.valleys[1].lower_modulus, 0.951e9, 1e-3 * 1e9);
  EXPECT_FALSE(summary.valleys[1].refined);  // far above the bound's cost
}

// A rugged objective: a parabola of minimum `minimum` plus ripple of 5 valleys per unit x,
// d/dx included.
ScriptedObjective Rippled(double minimum) {
  return ScriptedObjective(
      [minimum](double x) {
        return (x - minimum) * (x - minimum) + 0.02 * (1.0 - std::cos(10.0 * M_PI * (x - minimum)));
      },
      [minimum](double x) {
        return 2.0 * (x - minimum) + 0.2 * M_PI * std::sin(10.0 * M_PI * (x - minimum));
      });
}

TEST(IdentificationTest, TwoStagesRefineTheObjectiveNearTheSearchsMinimum) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    SCOPED_TRACE(OptimizerTypeToString(optimizer));
    // The search: one valley at 1.31; the objective: several valleys, the lowest at 1.3,
    // 0.8 % from the search's minimum (inside a window of 3 %).
    ScriptedObjective search = Parabola(1.31);
    ScriptedObjective objective = Rippled(1.3);
    IdentificationOptions options = ScanOptions(optimizer);
    options.relative_tolerance = 1e-9;
    const IdentificationSummary summary =
        IdentifyInTwoStages(options, &search, 7, 0.03, &objective);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    EXPECT_TRUE(summary.scan_of_search);
    // The search's scan (7 points, one valley at 1.31) and the objective's minimum.
    EXPECT_EQ(summary.scan_moduli.size(), 7u);
    EXPECT_EQ(summary.local_minima, 1);
    EXPECT_NEAR(summary.search_modulus, 1.31e9, 1e-6 * 1.31e9);
    EXPECT_NEAR(summary.modulus, 1.3e9, 1e-6 * 1.3e9);
    // Every objective evaluation within the window around the search's minimum.
    for (const double x : objective.evaluated) {
      EXPECT_GE(x * objective.scale, summary.search_modulus * 0.97);
      EXPECT_LE(x * objective.scale, summary.search_modulus * 1.03);
    }
    // The objective's window scan (on the objective itself: it has no copies) counts
    // with the search's evaluations.
    EXPECT_EQ(summary.evaluations + SearchRefinement().window_points,
              static_cast<int>(objective.evaluated.size()));
    EXPECT_EQ(summary.scan_evaluations,
              static_cast<int>(search.evaluated.size()) + SearchRefinement().window_points);
  }
}

TEST(IdentificationTest, TheSearchsOwnRefinementOnlyPlacesTheWindow) {
  // The search refined by BOBYQA to the options' 1e-9, against BOBYQA and the secant
  // (the default) to 1e-3: fewer search evaluations, E_s within about 1e-3 of its
  // minimum, and the objective's minimum as accurate.
  IdentificationOptions options = ScanOptions(OptimizerType::kNlopt);
  options.relative_tolerance = 1e-9;
  ScriptedObjective tight_search = Parabola(1.31);
  ScriptedObjective tight_objective = Rippled(1.3);
  const IdentificationSummary tight = IdentifyInTwoStages(
      options, &tight_search, 7, 0.03, &tight_objective, {OuterAlgorithm::kBobyqa, 0.0});
  ASSERT_TRUE(tight.IsSolutionUsable()) << tight.FullReport();
  EXPECT_NEAR(tight.modulus, 1.3e9, 1e-6 * 1.3e9);
  for (const OuterAlgorithm algorithm : {OuterAlgorithm::kBobyqa, OuterAlgorithm::kSecant}) {
    SCOPED_TRACE(OuterAlgorithmToString(algorithm));
    ScriptedObjective loose_search = Parabola(1.31);
    ScriptedObjective loose_objective = Rippled(1.3);
    const IdentificationSummary loose =
        IdentifyInTwoStages(options, &loose_search, 7, 0.03, &loose_objective, {algorithm, 1e-3});
    ASSERT_TRUE(loose.IsSolutionUsable()) << loose.FullReport();
    EXPECT_LT(loose_search.evaluated.size(), tight_search.evaluated.size());
    EXPECT_NEAR(loose.search_modulus, 1.31e9, 1e-3 * 1.31e9);
    EXPECT_NEAR(loose.modulus, 1.3e9, 1e-6 * 1.3e9);
  }
}

TEST(IdentificationTest, TheSearchsSamplesPerValleyAndTheWindowsPointsAreHonoured) {
  // A search whose predicted spacing 0.25 in ln E asks, over the bounds' ln 5 = 1.61, for
  // ceil(1.61 / 0.25 * 4) + 1 = 27 samples at the options' 4 per spacing and
  // ceil(1.61 / 0.25 * 2) + 1 = 14 at 2; the window then scanned on 3 points, not 5.
  IdentificationOptions options = ScanOptions(OptimizerType::kNlopt);
  options.scan_samples_per_valley = 4.0;
  const int expected_points[] = {27, 14};
  const double samples_per_valley[] = {0.0, 2.0};
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(samples_per_valley[k]);
    ScriptedObjective search = Parabola(1.31);
    search.valley_spacing = 0.25;
    ScriptedObjective objective = Rippled(1.3);
    SearchRefinement refinement;
    refinement.samples_per_valley = samples_per_valley[k];
    refinement.window_points = 3;
    const IdentificationSummary summary =
        IdentifyInTwoStages(options, &search, 7, 0.03, &objective, refinement);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    EXPECT_EQ(static_cast<int>(summary.scan_moduli.size()), expected_points[k]);
    EXPECT_EQ(summary.evaluations + 3, static_cast<int>(objective.evaluated.size()));
    EXPECT_NEAR(summary.modulus, 1.3e9, 1e-6 * 1.3e9);
  }
}

TEST(IdentificationTest, TwoStagesScanTheObjectiveWhenItsMinimumLiesBeyondTheWindow) {
  // The objective's minimum at 1.3 lies 13 % from the search's at 1.5: the refinement
  // ends on the window's lower edge, and the objective's own scan finds 1.3.
  ScriptedObjective search = Parabola(1.5);
  ScriptedObjective objective = Parabola(1.3);
  IdentificationOptions options = ScanOptions(OptimizerType::kNlopt);
  options.scan_points = 41;
  const IdentificationSummary summary = IdentifyInTwoStages(options, &search, 7, 0.03, &objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_FALSE(summary.scan_of_search);
  EXPECT_NEAR(summary.search_modulus, 1.5e9, 1e-6 * 1.5e9);
  EXPECT_EQ(summary.scan_moduli.size(), 41u);
  EXPECT_EQ(summary.local_minima, 1);
  EXPECT_NEAR(summary.modulus, 1.3e9, 1e-6 * 1.3e9);
  EXPECT_EQ(summary.evaluations + SearchRefinement().window_points + 41,
            static_cast<int>(objective.evaluated.size()));
  EXPECT_EQ(summary.scan_evaluations,
            static_cast<int>(search.evaluated.size()) + SearchRefinement().window_points + 41);
}

TEST(IdentificationTest, TwoStagesStopWithTheSearchsFailure) {
  ScriptedObjective search = Parabola(1.31);
  search.fails = [](int, double) { return true; };
  ScriptedObjective objective = Parabola(1.3);
  const IdentificationSummary summary =
      IdentifyInTwoStages(ScanOptions(OptimizerType::kNlopt), &search, 7, 0.03, &objective);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_EQ(summary.message.rfind("the global search: no usable evaluation in the scan", 0), 0u)
      << summary.message;
  EXPECT_TRUE(objective.evaluated.empty());
}

TEST(IdentificationTest, TwoStagesShareTheEvaluationLimit) {
  // 7 scan samples and the search's refinement leave fewer than the window scan's 3 + 2
  // of 9 evaluations.
  ScriptedObjective search = Parabola(1.31);
  ScriptedObjective objective = Parabola(1.3);
  IdentificationOptions options = ScanOptions(OptimizerType::kNlopt);
  options.max_evaluations = 9;
  const IdentificationSummary summary = IdentifyInTwoStages(options, &search, 7, 0.03, &objective);
  EXPECT_EQ(summary.termination, TerminationType::kNoConvergence) << summary.FullReport();
  EXPECT_LE(static_cast<int>(search.evaluated.size() + objective.evaluated.size()), 9);
}

TEST(IdentificationTest, AFailedRefinementOfAnyValleyFailsTheIdentification) {
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    // Two valleys: the deeper at x = 2 (cost 1), the other at x = 0.8 (cost 1.1,
    // within refine_margin 0.2 of it), refined second; every evaluation below x = 1
    // after the scan fails.
    ScriptedObjective objective(
        [](double x) { return 1.0 + std::min((x - 0.8) * (x - 0.8) + 0.1, (x - 2.0) * (x - 2.0)); },
        [](double x) {
          return (x - 0.8) * (x - 0.8) + 0.1 < (x - 2.0) * (x - 2.0) ? 2.0 * (x - 0.8)
                                                                     : 2.0 * (x - 2.0);
        });
    objective.fails = [](int count, double x) { return count > 11 && x < 1.0; };
    IdentificationOptions options = ScanOptions(optimizer);
    options.refine_margin = 0.2;
    const IdentificationSummary summary = Identify(options, &objective);
    EXPECT_EQ(summary.local_minima, 2);
    EXPECT_EQ(summary.termination, TerminationType::kFailure) << summary.FullReport();
    EXPECT_NE(summary.message.find("the refinement of valley 2"), std::string::npos)
        << summary.message;
    EXPECT_NE(summary.message.find("scripted"), std::string::npos) << summary.message;
  }
}

TEST(IdentificationTest, ANonFiniteGradientStopsTheSearch) {
  ScriptedObjective objective([](double x) { return (x - 1.3) * (x - 1.3); },
                              [](double) { return std::nan(""); });
  const IdentificationSummary summary =
      Identify(Options(OptimizerType::kCeres, OuterAlgorithm::kDefault), &objective);
  EXPECT_EQ(summary.termination, TerminationType::kFailure) << summary.FullReport();
  EXPECT_NE(summary.message.find("non-finite gradient"), std::string::npos) << summary.message;
}

TEST(IdentificationOptionsTest, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(IdentificationOptions().IsValid(&why)) << why;
}

TEST(IdentificationOptionsTest, InvalidOptionsNameTheirKeys) {
  const std::vector<std::pair<std::function<void(IdentificationOptions*)>, std::string>> cases = {
      {[](IdentificationOptions* o) { o->lower_bound = 0.0; }, "outer.lower_bound"},
      {[](IdentificationOptions* o) { o->upper_bound = o->lower_bound; }, "outer.upper_bound"},
      {[](IdentificationOptions* o) { o->initial = o->upper_bound; }, "outer.initial"},
      {[](IdentificationOptions* o) { o->relative_tolerance = 0.0; }, "outer.relative_tolerance"},
      {[](IdentificationOptions* o) { o->max_evaluations = 1; }, "outer.max_evaluations"},
      {[](IdentificationOptions* o) { o->max_time = -1.0; }, "outer.max_time"},
      {[](IdentificationOptions* o) { o->max_evaluations = o->scan_points + 1; },
       "outer.max_evaluations (42) must exceed outer.scan_points (41) by at least 2"},
      {[](IdentificationOptions* o) {
         o->optimizer = OptimizerType::kCeres;
         o->algorithm = OuterAlgorithm::kCobyla;
       },
       "outer.algorithm 'cobyla' is not available with outer.optimizer 'ceres'; choose default, "
       "lbfgs or bfgs"},
  };
  for (const auto& [spoil, fragment] : cases) {
    IdentificationOptions options;
    spoil(&options);
    std::string why;
    EXPECT_FALSE(options.IsValid(&why)) << fragment;
    EXPECT_NE(why.find(fragment), std::string::npos) << why;
  }
}

TEST(IdentificationOptionsTest, NamesRoundTrip) {
  for (const OptimizerType type : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    OptimizerType parsed;
    ASSERT_TRUE(StringToOptimizerType(OptimizerTypeToString(type), &parsed));
    EXPECT_EQ(parsed, type);
  }
  for (const OuterAlgorithm algorithm :
       {OuterAlgorithm::kDefault, OuterAlgorithm::kBobyqa, OuterAlgorithm::kCobyla,
        OuterAlgorithm::kSbplx, OuterAlgorithm::kMma, OuterAlgorithm::kLbfgs,
        OuterAlgorithm::kBfgs}) {
    OuterAlgorithm parsed;
    ASSERT_TRUE(StringToOuterAlgorithm(OuterAlgorithmToString(algorithm), &parsed));
    EXPECT_EQ(parsed, algorithm);
  }
  OuterAlgorithm unchanged = OuterAlgorithm::kBfgs;
  EXPECT_FALSE(StringToOuterAlgorithm("newton", &unchanged));
  EXPECT_EQ(unchanged, OuterAlgorithm::kBfgs);
}

TEST(IdentificationTest, InvalidOptionsAreReportedNotRun) {
  ScriptedObjective objective = Parabola();
  IdentificationOptions options;
  options.initial = 1.0;
  const IdentificationSummary summary = Identify(options, &objective);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_NE(summary.message.find("invalid options: outer.initial"), std::string::npos)
      << summary.message;
  EXPECT_TRUE(objective.evaluated.empty());
}

}  // namespace
}  // namespace mcrewave
