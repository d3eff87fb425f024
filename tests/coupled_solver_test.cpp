// Tests of the coupled direct / retrograde solvers: every sweep-based solver
// against the independent all-at-once solver, the inverse-crime cost curve, the
// adjoint gradient against finite differences, and divergence reporting.
#include "mcrewave/mcre/coupled_solver.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <utility>

#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::kAddressSanitizer;

using testing::BarRunProblem;
using testing::Compare;
using testing::kReferenceModulus;
using testing::MakeSmallCase;
using testing::Options;
using testing::RelativeDifference;
using testing::Solve;
using testing::Solved;
using testing::Weights;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The number after `prefix` in `message`, or NaN when there is none.
double NumberAfter(const std::string& message, const std::string& prefix) {
  const std::size_t at = message.find(prefix);
  if (at == std::string::npos) return std::numeric_limits<double>::quiet_NaN();
  return std::strtod(message.c_str() + at + prefix.size(), nullptr);
}

TEST(CoupledSolverOptionsTest, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(CoupledSolverOptions().IsValid(&why)) << why;
}

TEST(CoupledSolverOptionsTest, InvalidOptionsAreRefusedWithTheKey) {
  std::string why;
  CoupledSolverOptions options;
  options.relaxation_coefficient = 2.5;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.omega"), std::string::npos) << why;
  options = CoupledSolverOptions();
  options.tolerance = 0.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.tolerance"), std::string::npos) << why;
  options = CoupledSolverOptions();
  options.unchecked_tolerance = 0.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.unchecked_tolerance"), std::string::npos) << why;
}

TEST(CoupledSolverTypeTest, NamesRoundTrip) {
  for (CoupledSolverType type :
       {CoupledSolverType::kAllAtOnce, CoupledSolverType::kRelaxation,
        CoupledSolverType::kAdaptiveRelaxation, CoupledSolverType::kConjugateGradient}) {
    CoupledSolverType parsed = CoupledSolverType::kAllAtOnce;
    ASSERT_TRUE(StringToCoupledSolverType(CoupledSolverTypeToString(type), &parsed));
    EXPECT_EQ(parsed, type);
  }
  CoupledSolverType unchanged = CoupledSolverType::kRelaxation;
  EXPECT_FALSE(StringToCoupledSolverType("krylov!", &unchanged));
  EXPECT_EQ(unchanged, CoupledSolverType::kRelaxation);
}

// 20 elements, 200 steps, noisy data from a finer truth: every sweep-based solver
// agrees with the all-at-once solver to 1e-8 relative in U, W and e^2.
struct AgreementCase {
  double w_u;
  double theta;
  CoupledSolverType type;
};

class SolverAgreementTest : public ::testing::TestWithParam<AgreementCase> {};

TEST_P(SolverAgreementTest, AgreesWithAllAtOnce) {
  const AgreementCase& param = GetParam();
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(param.w_u, 1.0), param.theta);
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();
  // The LU solves its space-time system to round-off; in the measure of the other
  // solvers (sweeps of their own round-off) its W is within 1e-10.
  EXPECT_LT(NumberAfter(reference.summary.message, "space-time residual "), 1e-12)
      << reference.summary.message;
  EXPECT_LT(reference.summary.relative_residual, 1e-10);

  CoupledSolverOptions options = Options(param.type, 1e-12);
  if (param.type == CoupledSolverType::kRelaxation) {
    // A fixed omega inside the convergence range, from the adaptive estimate.
    const Solved adaptive = Solve(Options(CoupledSolverType::kAdaptiveRelaxation, 1e-4), &problem);
    options.relaxation_coefficient = 0.9 * adaptive.summary.relaxation_coefficient;
  }
  const Solved solved = Solve(options, &problem);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  const testing::Agreement agreement = Compare(solved, reference);
  EXPECT_LT(agreement.displacement, 1e-8);
  EXPECT_LT(agreement.retrograde, 1e-8);
  EXPECT_LT(agreement.cost, 1e-8);
  EXPECT_NEAR(solved.solution.cost_gradient, reference.solution.cost_gradient,
              1e-7 * std::abs(reference.solution.cost_gradient));
  EXPECT_GT(solved.summary.sweeps, 0);
}

INSTANTIATE_TEST_SUITE_P(
    Methods, SolverAgreementTest,
    ::testing::Values(AgreementCase{1.0, 0.5, CoupledSolverType::kRelaxation},
                      AgreementCase{1.0, 0.5, CoupledSolverType::kAdaptiveRelaxation},
                      AgreementCase{1.0, 0.5, CoupledSolverType::kConjugateGradient},
                      AgreementCase{0.01, 0.5, CoupledSolverType::kAdaptiveRelaxation},
                      AgreementCase{0.01, 0.5, CoupledSolverType::kConjugateGradient},
                      AgreementCase{1.0, 1.0, CoupledSolverType::kConjugateGradient},
                      AgreementCase{1.0, 0.75, CoupledSolverType::kAdaptiveRelaxation}));

TEST(AllAtOnceSolverTest, RefusesAboveTheSizeLimitWithAClearMessage) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kAllAtOnce, 1e-8);
  options.max_all_at_once_unknowns = 1000;
  const Solved solved = Solve(options, &bundle.problem);
  EXPECT_EQ(solved.summary.termination, TerminationType::kFailure);
  EXPECT_NE(solved.summary.message.find("2805 unknowns"), std::string::npos)
      << solved.summary.message;
  EXPECT_NE(solved.summary.message.find("inner.max_all_at_once_unknowns"), std::string::npos);
  EXPECT_NE(solved.summary.message.find("and would need about "), std::string::npos)
      << solved.summary.message;
}

TEST(IterativeSolverTest, RefusesAboveTheFieldLimitWithTheBytesItWouldNeed) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  // 10 fields of 11 nodes x 51 steps' doubles: 44880 bytes.
  ASSERT_EQ(IterativeSolverFieldBytes(11, 50), 44880.0);
  for (const CoupledSolverType type :
       {CoupledSolverType::kConjugateGradient, CoupledSolverType::kRelaxation,
        CoupledSolverType::kAdaptiveRelaxation}) {
    ASSERT_TRUE(HoldsIterativeSolverFields(type));
    CoupledSolverOptions options = Options(type, 1e-8);
    options.max_field_bytes = 44879;
    const Solved refused = Solve(options, &bundle.problem);
    EXPECT_EQ(refused.summary.termination, TerminationType::kFailure);
    EXPECT_NE(refused.summary.message.find(
                  "needs 44880 bytes (10 fields of n x (m + 1) doubles, n = 11 nodes, m = 50 "
                  "steps), above the limit of 44879 bytes (inner.max_field_bytes)"),
              std::string::npos)
        << refused.summary.message;
    // At the limit, the method runs.
    options.max_field_bytes = 44880;
    const Solved run = Solve(options, &bundle.problem);
    EXPECT_GT(run.summary.iterations, 0) << run.summary.message;
    EXPECT_EQ(run.summary.message.find("inner.max_field_bytes"), std::string::npos);
  }
  EXPECT_FALSE(HoldsIterativeSolverFields(CoupledSolverType::kAllAtOnce));
  EXPECT_FALSE(HoldsIterativeSolverFields(CoupledSolverType::kRiccati));
}

TEST(IterativeSolverTest, ARefusalForTheFieldsNamesTheStreamingSolverAndTheLimit) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-8);
  options.max_field_bytes = 44879;  // one byte below the 10 fields of 11 x 51 doubles
  const long sweeps = bundle.problem.sweep_count();
  const Solved refused = Solve(options, &bundle.problem);
  const std::string& message = refused.summary.message;
  EXPECT_EQ(refused.summary.termination, TerminationType::kFailure);
  EXPECT_EQ(bundle.problem.sweep_count(), sweeps) << message;  // refused before any work
  EXPECT_EQ(message.rfind("conjugate_gradient needs 44880 bytes", 0), 0u) << message;
  // The ways out: the streaming solver (or auto, which takes it), the limit, the grid.
  EXPECT_NE(message.find("use inner.method: streaming_conjugate_gradient (or auto), which "
                         "stores no space-time field, raise inner.max_field_bytes, or use "
                         "a coarser mesh (fewer dofs; the bar's model.elements), a shorter "
                         "window or a larger time step"),
            std::string::npos)
      << message;
}

TEST(AutoSolverTest, TheDefaultIsAutoAndValid) {
  const CoupledSolverOptions defaults;
  EXPECT_EQ(defaults.type, CoupledSolverType::kAuto);
  std::string why;
  EXPECT_TRUE(defaults.IsValid(&why)) << why;
  CoupledSolverType parsed = CoupledSolverType::kRelaxation;
  ASSERT_TRUE(StringToCoupledSolverType("auto", &parsed));
  EXPECT_EQ(parsed, CoupledSolverType::kAuto);
  EXPECT_STREQ(CoupledSolverTypeToString(CoupledSolverType::kAuto), "auto");
}

TEST(AutoSolverTest, ResolvesToStoredFieldsWhenTheyFitAndToStreamingWhenTheyDoNot) {
  // 11 nodes, 50 steps: 44880 bytes of fields.
  CoupledSolverOptions options;
  options.max_field_bytes = 44880;
  EXPECT_EQ(ResolveCoupledSolverType(options, 11, 50, true), CoupledSolverType::kConjugateGradient);
  options.max_field_bytes = 44879;
  EXPECT_EQ(ResolveCoupledSolverType(options, 11, 50, true),
            CoupledSolverType::kStreamingConjugateGradient);
  // Without the streaming solver (a structure given by matrices): stored fields, which
  // SolveCoupled then refuses.
  EXPECT_EQ(ResolveCoupledSolverType(options, 11, 50, false),
            CoupledSolverType::kConjugateGradient);
  // At the defaults: the paper's bar (101 nodes, 1750 steps: 14 MB) keeps stored fields;
  // 1e5 elements (14 GB) stream.
  EXPECT_EQ(ResolveCoupledSolverType(CoupledSolverOptions(), 101, 1750, true),
            CoupledSolverType::kConjugateGradient);
  EXPECT_EQ(ResolveCoupledSolverType(CoupledSolverOptions(), 100001, 1750, true),
            CoupledSolverType::kStreamingConjugateGradient);
  // A method named is the method used, fields or not.
  for (const CoupledSolverType type :
       {CoupledSolverType::kConjugateGradient, CoupledSolverType::kRelaxation,
        CoupledSolverType::kAllAtOnce, CoupledSolverType::kStreamingConjugateGradient}) {
    options.type = type;
    EXPECT_EQ(ResolveCoupledSolverType(options, 11, 50, true), type);
    EXPECT_EQ(ResolveCoupledSolverType(options, 11, 50, false), type);
    EXPECT_EQ(CoupledSolverName(type, type), CoupledSolverTypeToString(type));
  }
  EXPECT_EQ(CoupledSolverName(CoupledSolverType::kAuto, CoupledSolverType::kConjugateGradient),
            "auto (conjugate_gradient)");
}

TEST(AutoSolverTest, SolvesAsTheMethodItResolvesToAndReportsThatMethod) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.95 * kReferenceModulus);
  const Solved stored = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-10), &problem);
  const Solved streamed =
      Solve(Options(CoupledSolverType::kStreamingConjugateGradient, 1e-10), &problem);
  ASSERT_TRUE(stored.summary.IsSolutionUsable()) << stored.summary.message;
  ASSERT_TRUE(streamed.summary.IsSolutionUsable()) << streamed.summary.message;
  // The fields fit: the stored-field CG, bit for bit.
  CoupledSolverOptions options = Options(CoupledSolverType::kAuto, 1e-10);
  const Solved fits = Solve(options, &problem);
  EXPECT_EQ(fits.summary.type, CoupledSolverType::kConjugateGradient);
  EXPECT_TRUE(fits.solution.has_fields());
  EXPECT_EQ(fits.solution.cost, stored.solution.cost);
  EXPECT_EQ(fits.summary.iterations, stored.summary.iterations);
  EXPECT_EQ(fits.summary.BriefReport().rfind("conjugate_gradient: convergence", 0), 0u)
      << fits.summary.BriefReport();
  // One byte short: the streaming CG, bit for bit, no field stored.
  options.max_field_bytes = 44879;
  const Solved streams = Solve(options, &problem);
  EXPECT_EQ(streams.summary.type, CoupledSolverType::kStreamingConjugateGradient);
  EXPECT_FALSE(streams.solution.has_fields());
  EXPECT_EQ(streams.solution.cost, streamed.solution.cost);
  EXPECT_EQ(streams.summary.iterations, streamed.summary.iterations);
  // The two solvers at the tolerance 1e-10: e^2 measured 8.9e-16 apart, de^2/dE 2.4e-11
  // (6 iterations stored, 7 streamed).
  EXPECT_NEAR(streams.solution.cost, stored.solution.cost, 1e-13 * stored.solution.cost);
  EXPECT_NEAR(streams.solution.cost_gradient, stored.solution.cost_gradient,
              1e-9 * std::abs(stored.solution.cost_gradient));
}

TEST(AllAtOnceSolverTest, RefusesAboveTheMemoryLimitWithTheBytesItWouldNeed) {
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 1), Weights(1.0, 1.0));
  CoupledSolverOptions options = Options(CoupledSolverType::kAllAtOnce, 1e-8);
  options.max_all_at_once_bytes = 1000;
  const long sweeps = bundle.problem.sweep_count();
  const Solved refused = Solve(options, &bundle.problem);
  const std::string& message = refused.summary.message;
  EXPECT_EQ(refused.summary.termination, TerminationType::kFailure);
  EXPECT_EQ(bundle.problem.sweep_count(), sweeps) << message;  // refused before any work
  // 21716 = the entries of the assembled matrix for n = 11 nodes, m = 50 steps
  // (counted from its triplets when the estimate was fitted).
  EXPECT_NE(message.find("the all-at-once solver would need about "), std::string::npos) << message;
  EXPECT_NE(message.find("(matrix 21716 nonzeros"), std::string::npos) << message;
  EXPECT_NE(message.find("above the limit of 1000 bytes (inner.max_all_at_once_bytes)"),
            std::string::npos)
      << message;
  const double bytes = NumberAfter(message, "would need about ");
  // 2805 unknowns: between 1 and 10 kB each.
  EXPECT_GT(bytes, 2805.0 * 1e3) << message;
  EXPECT_LT(bytes, 2805.0 * 1e4) << message;
  // The limit is the estimate itself: the solve runs; one byte less, it is refused.
  options.max_all_at_once_bytes = static_cast<long>(bytes);
  const Solved at_limit = Solve(options, &bundle.problem);
  EXPECT_TRUE(at_limit.summary.IsSolutionUsable()) << at_limit.summary.FullReport();
  options.max_all_at_once_bytes = static_cast<long>(bytes) - 1;
  EXPECT_EQ(Solve(options, &bundle.problem).summary.termination, TerminationType::kFailure);
  // The unknown limit still applies on its own.
  options.max_all_at_once_bytes = static_cast<long>(bytes);
  options.max_all_at_once_unknowns = 2804;
  EXPECT_NE(Solve(options, &bundle.problem).summary.message.find("inner.max_all_at_once_unknowns"),
            std::string::npos);
}

// Peak resident memory of this process so far [bytes].
double PeakResidentBytes() {
  struct rusage usage = {};
  ::getrusage(RUSAGE_SELF, &usage);
  return 1024.0 * usage.ru_maxrss;
}

// ||T(W) - W||_P, ||T(0)||_P and the round-off floor 1e-11 ||Retrograde(0)||_P of
// a returned W, computed here from the sweeps (coupled_solver.h).
struct FixedPointResidual {
  double residual, rhs, floor;
};

FixedPointResidual Residual(CoupledProblem* problem, const Matrix& retrograde) {
  Matrix scratch, rhs, image, data_response;
  problem->FixedPointMap(problem->ZeroField(), &scratch, &rhs);
  problem->FixedPointMap(retrograde, &scratch, &image);
  problem->RetrogradeSweep(problem->ZeroField(), true, &data_response);
  return {problem->Norm(image - retrograde), problem->Norm(rhs),
          1e-11 * problem->Norm(data_response)};
}

TEST(AllAtOnceSolverTest, ReportsTheResidualOfTheOtherSolversAndClaimsNoMoreThanItMeets) {
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved solved = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  const FixedPointResidual check = Residual(&problem, solved.solution.retrograde);
  const double relative = check.residual / check.rhs;
  EXPECT_NEAR(solved.summary.relative_residual, relative, 1e-6 * relative);
  EXPECT_LE(relative, 1e-8);
  EXPECT_EQ(solved.summary.residual_history.size(), 1u);
  // A tolerance below round-off: converged only if the residual is at the floor.
  const Solved strict = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-30), &problem);
  std::cout << "all_at_once: relative residual " << relative << ", floor "
            << check.floor / check.rhs << " relative; at tolerance 1e-30: "
            << TerminationTypeToString(strict.summary.termination) << "\n";
  EXPECT_EQ(strict.summary.IsSolutionUsable(), check.residual <= check.floor)
      << strict.summary.FullReport();
}

TEST(AllAtOnceSolverTest, FailsWhenItsSolutionMissesTheToleranceThoughTheLuResidualIsTiny) {
  // w_u / w_f = 1e28: the space-time system is so ill-conditioned that its LU
  // solution, with a residual at round-off, is 1e-3 from a fixed point of the
  // sweeps (10 elements, 50 steps).
  BarRunProblem bundle(MakeSmallCase(10, 50, 5.0, 2), Weights(1e14, 1e-14));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved solved = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  const std::string& message = solved.summary.message;
  EXPECT_FALSE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  EXPECT_EQ(solved.summary.termination, TerminationType::kFailure);
  EXPECT_LT(NumberAfter(message, "space-time residual "), 1e-12) << message;
  EXPECT_GT(solved.summary.relative_residual, 1e-6);
  const FixedPointResidual check = Residual(&problem, solved.solution.retrograde);
  EXPECT_NEAR(solved.summary.relative_residual, check.residual / check.rhs,
              1e-6 * solved.summary.relative_residual);
  EXPECT_GT(check.residual, 1e3 * check.floor);
  EXPECT_NE(message.find("but the solution fails its check (relative residual "), std::string::npos)
      << message;
  EXPECT_NE(message.find("tolerance 1.000e-08"), std::string::npos) << message;
  // The tolerance decides: at 0.1 the same solution is accepted.
  const Solved loose = Solve(Options(CoupledSolverType::kAllAtOnce, 0.1), &problem);
  EXPECT_TRUE(loose.summary.IsSolutionUsable()) << loose.summary.FullReport();
  EXPECT_NEAR(loose.summary.relative_residual, solved.summary.relative_residual,
              1e-6 * solved.summary.relative_residual);
}

// 21 nodes, 400 steps (42105 unknowns, about 150 MB), both mass matrices and two
// theta (the pivots, hence the fill, depend on the values). One case per test, so
// that under ctest each has a process, and a high-water mark, of its own.
class AllAtOnceMemoryTest : public ::testing::TestWithParam<std::pair<MassType, double>> {};

TEST_P(AllAtOnceMemoryTest, EstimateBoundsTheFactorsAndThePeak) {
  const auto [mass, theta] = GetParam();
  testing::SmallCase small = MakeSmallCase(20, 400, 5.0, 1);
  small.bar.mass = mass;
  BarRunProblem bundle(small, Weights(1.0, 1.0), theta);
  bundle.problem.SetModulus(0.9 * kReferenceModulus);
  CoupledSolverOptions options = Options(CoupledSolverType::kAllAtOnce, 1e-8);
  options.max_all_at_once_bytes = 1;
  const double estimate =
      NumberAfter(Solve(options, &bundle.problem).summary.message, "would need about ");
  options.max_all_at_once_bytes = CoupledSolverOptions().max_all_at_once_bytes;
  const double peak_before = PeakResidentBytes();
  const Solved solved = Solve(options, &bundle.problem);
  // Growth of the high-water mark: at most what the solve held at its peak.
  const double peak_growth = PeakResidentBytes() - peak_before;
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
  const std::string& message = solved.summary.message;
  const double factors = NumberAfter(message, "unknowns, ");
  const double estimated_factors = NumberAfter(message, "nonzeros in L and U (");
  std::cout << MassTypeToString(mass) << ", theta " << theta << ": " << factors
            << " nonzeros in L and U for " << estimated_factors << " estimated; peak growth "
            << peak_growth << " bytes for " << estimate << " estimated\n";
  EXPECT_LE(factors, estimated_factors) << message;
  EXPECT_GE(factors, 0.8 * estimated_factors) << message;
  if (!kAddressSanitizer) {
    EXPECT_LE(peak_growth, estimate);
  }
}

INSTANTIATE_TEST_SUITE_P(MassAndTheta, AllAtOnceMemoryTest,
                         ::testing::Values(std::pair{MassType::kConsistent, 0.5},
                                           std::pair{MassType::kLumped, 1.0}));

TEST(CostCurveTest, InverseCrimeDataHaveTheirMinimumAtTheReferenceModulus) {
  // Data from the model's own discretisation, noise-free.
  BarRunProblem bundle(MakeSmallCase(20, 400, kInfinity, 1), Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-10);
  auto cost = [&](double factor) {
    problem.SetModulus(factor * kReferenceModulus);
    const Solved solved = Solve(options, &problem);
    EXPECT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
    return solved.solution.cost;
  };
  const double at_reference = cost(1.0);
  const double at_110 = cost(1.1);
  EXPECT_LE(at_reference, 1e-10 * at_110) << at_reference << " vs " << at_110;
  int best = -1;
  double best_cost = kInfinity;
  for (int i = 0; i <= 40; ++i) {
    const double c = cost(0.5 + i * 0.025);
    if (c < best_cost) {
      best_cost = c;
      best = i;
    }
  }
  EXPECT_EQ(best, 20) << "minimum of the 41-point curve at E = " << 0.5 + best * 0.025 << " E_ref";
}

TEST(CostCurveTest, ExactSolutionDataIdentifyTheModulusToItsDiscretisationBias) {
  // The paper's case at 100 elements, noise-free data from the exact
  // solution: the minimiser of e^2, found by golden-section search, is the
  // discretisation bias only.
  testing::SmallCase paper = MakeSmallCase(100, 1750, kInfinity, 1);
  paper.data.truth = TruthModel::kExact;
  BarRunProblem bundle(paper, Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-8);
  auto cost = [&](double factor) {
    problem.SetModulus(factor * kReferenceModulus);
    const Solved solved = Solve(options, &problem);
    EXPECT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.FullReport();
    return solved.solution.cost;
  };
  const double golden = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = 0.9, b = 1.1;
  double x1 = b - golden * (b - a), x2 = a + golden * (b - a);
  double f1 = cost(x1), f2 = cost(x2);
  while (b - a > 1e-6) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - golden * (b - a), f1 = cost(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + golden * (b - a), f2 = cost(x2);
    }
  }
  const double identified = 0.5 * (a + b);
  RecordProperty("identified_over_reference", std::to_string(identified));
  // Measured E / E_ref - 1 = -5.70e-6 (the search resolves 5e-7).
  EXPECT_NEAR(identified, 1.0, 3e-5);
}

class GradientTest : public ::testing::TestWithParam<double> {};

TEST_P(GradientTest, AdjointGradientMatchesCentralDifference) {
  const double factor = GetParam();
  BarRunProblem bundle(MakeSmallCase(16, 160, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  // The all-at-once solver is exact to round-off, so the difference quotient
  // measures the discrete derivative only. This checks the formula de^2/dE =
  // -(1/2) sum_j c_j h W_j^T K1 (W_j + 2 U_j) (MatrixMcreProblem::CostGradients) against
  // e^2 itself. Step 1e-6 E: measured 7e-12 to 3.5e-10 relative (with step 1e-4 E
  // the truncation error reached 6.3e-7).
  const CoupledSolverOptions options = Options(CoupledSolverType::kAllAtOnce, 1e-8);
  const double modulus = factor * kReferenceModulus;
  const double step = 1e-6 * modulus;
  problem.SetModulus(modulus + step);
  const double plus = Solve(options, &problem).solution.cost;
  problem.SetModulus(modulus - step);
  const double minus = Solve(options, &problem).solution.cost;
  problem.SetModulus(modulus);
  const Solved at = Solve(options, &problem);
  const double central = (plus - minus) / (2.0 * step);
  EXPECT_NEAR(at.solution.cost_gradient, central, 3e-9 * std::abs(central))
      << "adjoint " << at.solution.cost_gradient << ", central difference " << central;
  // The same gradient from conjugate gradients at a tight tolerance: measured 4.7e-12 to
  // 3.5e-10 relative to the central difference.
  const Solved krylov = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-12), &problem);
  EXPECT_NEAR(krylov.solution.cost_gradient, central, 3e-9 * std::abs(central));
}

INSTANTIATE_TEST_SUITE_P(Moduli, GradientTest, ::testing::Values(0.7, 0.95, 1.05, 1.4));

TEST(WarmStartTest, ASolveAfterAOnePercentChangeNeedsFewerSweeps) {
  BarRunProblem bundle(MakeSmallCase(20, 300, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-8);
  problem.SetModulus(kReferenceModulus);
  const Solved previous = Solve(options, &problem);
  problem.SetModulus(1.01 * kReferenceModulus);
  const Solved cold = Solve(options, &problem);
  const Solved warm = Solve(options, &problem, &previous.solution.retrograde);
  ASSERT_TRUE(cold.summary.IsSolutionUsable() && warm.summary.IsSolutionUsable());
  EXPECT_LT(warm.summary.sweeps, cold.summary.sweeps);
  EXPECT_NEAR(warm.solution.cost, cold.solution.cost, 1e-6 * cold.solution.cost);
}

// A loose CG solve that ends on its recursive residual (unchecked_tolerance) takes the
// checked solve's iterates and saves its final check's 2 sweeps; its U, kept along W,
// is Direct(W) to round-off, and U, W, e^2 and the gradient are the checked solve's.
// Measured on 20 elements and 300 steps at 1e-3: 18 iterations, U within 2.7e-15 of
// Direct(W) and of the checked U, e^2 within 1.5e-15 of the checked, 6.9e-6 of the
// all-at-once e^2.
TEST(ConjugateGradientTest, AnUncheckedLooseSolveIsTheCheckedOneWithoutItsFinalSweeps) {
  BarRunProblem bundle(MakeSmallCase(20, 300, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.95 * kReferenceModulus);
  CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-3);
  options.unchecked_tolerance = 1.0;
  const Solved checked = Solve(options, &problem);
  options.unchecked_tolerance = 1e-6;
  const Solved unchecked = Solve(options, &problem);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-10), &problem);
  ASSERT_TRUE(checked.summary.IsSolutionUsable() && unchecked.summary.IsSolutionUsable() &&
              reference.summary.IsSolutionUsable());
  EXPECT_EQ(unchecked.summary.iterations, checked.summary.iterations);
  EXPECT_EQ(unchecked.summary.sweeps, checked.summary.sweeps - 2);
  EXPECT_LE(unchecked.summary.relative_residual, 1e-3);
  Matrix direct;
  problem.DirectSweep(unchecked.solution.retrograde, true, &direct);
  EXPECT_LT(RelativeDifference(unchecked.solution.displacement, direct), 2e-14);
  const testing::Agreement agreement = Compare(unchecked, checked);
  EXPECT_LT(agreement.displacement, 2e-14);
  EXPECT_EQ(agreement.retrograde, 0.0);
  EXPECT_LT(agreement.cost, 1e-14);
  EXPECT_NEAR(unchecked.solution.cost_gradient, checked.solution.cost_gradient,
              1e-12 * std::abs(checked.solution.cost_gradient));
  EXPECT_LT(Compare(unchecked, reference).cost, 7e-5);
  std::cout << "unchecked CG at 1e-3: " << unchecked.summary.iterations << " iterations, U "
            << RelativeDifference(unchecked.solution.displacement, direct) << " from Direct(W), "
            << agreement.displacement << " from the checked U, e^2 " << agreement.cost
            << " from the checked, " << Compare(unchecked, reference).cost << " from all-at-once\n";
  // A tight solve is checked whatever unchecked_tolerance says.
  options.tolerance = 1e-8;
  const Solved tight = Solve(options, &problem);
  options.unchecked_tolerance = 1.0;
  const Solved tight_checked = Solve(options, &problem);
  EXPECT_EQ(tight.summary.sweeps, tight_checked.summary.sweeps);
  EXPECT_EQ(Compare(tight, tight_checked).displacement, 0.0);
}

// Conjugate gradients report the extreme Ritz values of their Lanczos process; against
// the eigenvalues of A = I - G assembled column by column (A e_i = e_i - G e_i) on a bar
// small enough to hold A (11 nodes, 61 samples: 671 unknowns), at weights 1 so that the
// spectrum is wide. Measured: a in [1 - 3e-15, 46.02], CG to 1e-12 in 30 iterations,
// its Ritz extremes 1.0061 and a_max to 2.2e-14 relative; the streaming CG in 35,
// 1.0006 and a_max to 2.3e-14.
TEST(ConjugateGradientTest, ItsRitzExtremesBracketTheSpectrumOfIMinusGFromInside) {
  BarRunProblem bundle(MakeSmallCase(10, 60, 10.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  const Matrix zero = problem.ZeroField();
  const Eigen::Index unknowns = zero.size();
  Matrix operator_a(unknowns, unknowns), unit = zero, scratch, image;
  for (Eigen::Index i = 0; i < unknowns; ++i) {
    unit.setZero();
    unit.data()[i] = 1.0;
    problem.ApplyIterationMap(unit, &scratch, &image);
    image = unit - image;
    operator_a.col(i) = Eigen::Map<const Vector>(image.data(), unknowns);
  }
  // A is self-adjoint in <.,.>_P, so its eigenvalues are real (imaginary parts: round-off).
  const Eigen::VectorXcd eigenvalues = Eigen::EigenSolver<Matrix>(operator_a, false).eigenvalues();
  const double a_max = eigenvalues.real().maxCoeff();
  const double a_min = eigenvalues.real().minCoeff();
  const Solved cg = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-12), &problem);
  ASSERT_TRUE(cg.summary.IsSolutionUsable()) << cg.summary.message;
  EXPECT_GE(a_min, 1.0 - 1e-12);  // G's eigenvalues are <= 0 (docs/formulation.md section 4)
  EXPECT_GT(a_max, 10.0);
  // Ritz values lie inside the spectrum, and the largest converges first.
  EXPECT_GE(cg.summary.spectrum_min, a_min - 1e-12);
  EXPECT_LE(cg.summary.spectrum_max, a_max * (1.0 + 1e-12));
  EXPECT_NEAR(cg.summary.spectrum_max, a_max, 3e-13 * a_max);
  // The streaming CG iterates on the traces, I - L, whose spectrum is A's but for
  // eigenvalues 1.
  const Solved streaming =
      Solve(Options(CoupledSolverType::kStreamingConjugateGradient, 1e-12), &problem);
  ASSERT_TRUE(streaming.summary.IsSolutionUsable()) << streaming.summary.message;
  EXPECT_GE(streaming.summary.spectrum_min, a_min - 1e-12);
  EXPECT_NEAR(streaming.summary.spectrum_max, a_max, 3e-13 * a_max);
}

TEST(DivergenceTest, PaperCaseWithOmegaOneIsReportedAsDivergingAndAdaptiveConverges) {
  // The paper's case (100 elements, 1750 steps), data from a finer truth with noise.
  BarRunProblem bundle(MakeSmallCase(100, 1750, 10.0, 2), Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  CoupledSolverOptions options = Options(CoupledSolverType::kRelaxation, 1e-8);
  options.relaxation_coefficient = 1.0;
  const Solved diverged = Solve(options, &problem);
  EXPECT_EQ(diverged.summary.termination, TerminationType::kDivergence)
      << diverged.summary.FullReport();
  EXPECT_LT(diverged.summary.iterations, 20);
  EXPECT_NE(diverged.summary.message.find("diverge"), std::string::npos);
  EXPECT_FALSE(diverged.summary.IsSolutionUsable());

  const Solved adaptive = Solve(Options(CoupledSolverType::kAdaptiveRelaxation, 1e-8), &problem);
  EXPECT_TRUE(adaptive.summary.IsSolutionUsable()) << adaptive.summary.FullReport();
  // Its omega lies inside the convergence range 2 / a_max of the estimate.
  EXPECT_LT(adaptive.summary.relaxation_coefficient,
            2.0 / (adaptive.summary.spectrum_max / options.spectrum_safety_factor));
}

// A = I - G applied to x: 2 sweeps.
Matrix ApplyReducedOperator(CoupledProblem* problem, const Matrix& x) {
  Matrix scratch, image;
  problem->ApplyIterationMap(x, &scratch, &image);
  return x - image;
}

// The adaptive relaxation's safeguard: when the Lanczos estimate misses a_max, the
// residual grows, omega is re-chosen from the observed growth, and the solve still
// converges to the all-at-once solution.
//
// Small spectrum_steps and a unit safety factor alone do not miss a_max here: the
// rigid-body eigenvector of a_max dominates the start residual c (measured: 99 % of
// ||c||_P at w_u = 1, 20 elements, 200 steps), so 2 Lanczos steps find a_max = 343
// to 5 digits and no restart occurs. The start is therefore warm, W^(0) = W* + d with
// W* the all-at-once solution and d = c minus its P-projection on that eigenvector:
// the start residual -A d has no component along it, so the estimate sees only the
// rest of the spectrum (next eigenvalue 21), omega comes out far too large and
// the component that round-off puts back grows until the safeguard re-chooses omega
// (measured: 1 restart, a_max re-estimated at 342.6).
TEST(AdaptiveRelaxationTest, SafeguardRestartsAfterAnUnderestimatedSpectrumAndConverges) {
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(1.0, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-8), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.FullReport();

  // c = T(0), and the eigenvector of a_max by power iteration from c (the next
  // eigenvalue is 16x smaller: 12 iterations converge it to round-off).
  Matrix displacement, rhs;
  problem.FixedPointMap(problem.ZeroField(), &displacement, &rhs);
  Matrix top = rhs / problem.Norm(rhs);
  double a_max = 0.0;
  for (int i = 0; i < 12; ++i) {
    const Matrix image = ApplyReducedOperator(&problem, top);
    a_max = problem.InnerProduct(top, image);
    top = image / problem.Norm(image);
  }
  ASSERT_GT(a_max, 100.0);  // w_u = 1: a_max is large (3.4e2)
  const Matrix deflated = rhs - problem.InnerProduct(rhs, top) * top;
  const Matrix warm_start = reference.solution.retrograde + deflated;

  CoupledSolverOptions options = Options(CoupledSolverType::kAdaptiveRelaxation, 1e-12);
  options.spectrum_estimation_steps = 2;
  options.spectrum_safety_factor = 1.0;
  const Solved adaptive = Solve(options, &problem, &warm_start);
  const CoupledSolverSummary& summary = adaptive.summary;
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_GE(summary.safeguard_restarts, 1) << summary.FullReport();
  // The final omega lies inside the convergence range 2 / a_max of the true spectrum.
  EXPECT_LT(summary.relaxation_coefficient, 2.0 / a_max) << summary.FullReport();
  EXPECT_GE(summary.spectrum_max, 0.9 * a_max) << summary.FullReport();

  const testing::Agreement agreement = Compare(adaptive, reference);
  EXPECT_LT(agreement.displacement, 1e-8);
  EXPECT_LT(agreement.retrograde, 1e-8);
  EXPECT_LT(agreement.cost, 1e-8);

  // Sweeps as src/mcre/iterative_coupled_solvers.cpp spends them: 5 for a warm start
  // (Start: T(W^(0)), c and W_u), 2 per Lanczos step, and 2 per iteration, the
  // iterations that restart from the best iterate included (each is one
  // FixedPointMap); the last iteration only tests convergence.
  constexpr int kWarmStartSweeps = 5;
  EXPECT_EQ(summary.sweeps,
            kWarmStartSweeps + 2 * options.spectrum_estimation_steps + 2L * summary.iterations)
      << summary.FullReport();
  EXPECT_EQ(summary.residual_history.size(), static_cast<std::size_t>(summary.iterations) + 1);
}

// The same accounting from a cold start: 3 sweeps (Direct(0); T(0) = c and W_u
// batched), 2 per Lanczos step, 2 per iteration.
TEST(AdaptiveRelaxationTest, SweepsAreStartLanczosAndTwoPerIteration) {
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  problem.SetModulus(0.9 * kReferenceModulus);
  CoupledSolverOptions options = Options(CoupledSolverType::kAdaptiveRelaxation, 1e-10);
  options.spectrum_estimation_steps = 5;
  const Solved adaptive = Solve(options, &problem);
  const CoupledSolverSummary& summary = adaptive.summary;
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_EQ(summary.safeguard_restarts, 0);
  constexpr int kColdStartSweeps = 3;
  EXPECT_EQ(summary.sweeps,
            kColdStartSweeps + 2 * options.spectrum_estimation_steps + 2L * summary.iterations)
      << summary.FullReport();
}

// The integrator is factorised once per (E, h): by SetModulus, never by a solve.
TEST(FactorisationCountTest, OnePerModulusWhateverTheSolvesAtThatModulus) {
  BarRunProblem bundle(MakeSmallCase(20, 200, 5.0, 2), Weights(0.01, 1.0));
  MatrixMcreProblem& problem = bundle.problem;
  const int after_construction = problem.factorization_count();
  EXPECT_EQ(after_construction, 1);  // the constructor sets the reference modulus

  problem.SetModulus(0.9 * kReferenceModulus);
  EXPECT_EQ(problem.factorization_count(), after_construction + 1);
  const Solved cg = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-10), &problem);
  ASSERT_TRUE(cg.summary.IsSolutionUsable()) << cg.summary.FullReport();
  const Solved adaptive = Solve(Options(CoupledSolverType::kAdaptiveRelaxation, 1e-10), &problem);
  ASSERT_TRUE(adaptive.summary.IsSolutionUsable()) << adaptive.summary.FullReport();
  EXPECT_GT(cg.summary.sweeps + adaptive.summary.sweeps, 100);  // many sweeps, no factorisation
  // Setting the same modulus again does not refactorise either.
  problem.SetModulus(0.9 * kReferenceModulus);
  EXPECT_EQ(problem.factorization_count(), after_construction + 1);

  problem.SetModulus(1.1 * kReferenceModulus);
  EXPECT_EQ(problem.factorization_count(), after_construction + 2);
  const Solved warm = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-10), &problem,
                            &cg.solution.retrograde);
  ASSERT_TRUE(warm.summary.IsSolutionUsable()) << warm.summary.FullReport();
  EXPECT_EQ(problem.factorization_count(), after_construction + 2);
}

}  // namespace
}  // namespace mcrewave
