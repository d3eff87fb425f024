// Tests of the outer loop's objective: McreObjective evaluates e^2(E) scaled,
// with or without the adjoint gradient, warm-starts, records every evaluation,
// keeps the best, and reports an unusable inner solve as false with a message.
#include "mcrewave/mcre/objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/identification.h"
#include "reference/bar_mcre_problem.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::Weights;

// A small noisy case: 20 elements, 120 steps, SNR 20, truth refined twice.
class ObjectiveTest : public ::testing::Test {
 protected:
  ObjectiveTest()
      : case_(MakeSmallCase(20, 120, 20.0, 2)),
        model_(case_.bar),
        data_(MakeSyntheticMeasurements(case_.bar, case_.load, case_.time, case_.data)),
        matrices_(BarRunModel(model_, data_, {})) {}

  McreObjective MakeObjective(const CoupledSolverOptions& inner = CoupledSolverOptions()) const {
    return testing::BarObjective(matrices_, data_, McreOptions(), inner, kScale, case_.time.theta);
  }

  static constexpr double kScale = 160e9;  // E per unit of x [Pa]
  testing::SmallCase case_;
  BarModel model_;
  ChannelSet data_;
  MatrixModelData matrices_;  // the bar as the identification solves it
};

TEST(McreOptionsTest, DefaultsAreValidAndBadValuesNameTheirKey) {
  std::string why;
  McreOptions options;
  EXPECT_TRUE(options.IsValid(&why)) << why;
  options.reference_modulus = 0.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("mcre.reference_modulus"), std::string::npos) << why;
  options = McreOptions();
  options.weights.displacement_weight = -1.0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("mcre.w_u"), std::string::npos) << why;
}

TEST_F(ObjectiveTest, CostIsTheScaledMcreCostWithOrWithoutGradient) {
  McreObjective objective = MakeObjective();
  const double x = 1.2;
  double cost_alone = -1.0;
  ASSERT_TRUE(objective.Evaluate(&x, &cost_alone, nullptr)) << objective.error_message();
  double cost = -1.0;
  double gradient = 0.0;
  ASSERT_TRUE(objective.Evaluate(&x, &cost, &gradient)) << objective.error_message();

  ASSERT_EQ(objective.evaluations().size(), 2u);
  const ObjectiveEvaluation& first = objective.evaluations()[0];
  const ObjectiveEvaluation& second = objective.evaluations()[1];
  EXPECT_FALSE(first.gradient_requested);
  EXPECT_TRUE(second.gradient_requested);
  EXPECT_DOUBLE_EQ(first.modulus, x * kScale);
  EXPECT_TRUE(first.usable && second.usable);
  // cost = e^2 / J_rest, gradient = de^2/dE * E_scale / J_rest
  EXPECT_NEAR(cost_alone, first.cost / objective.rest_cost(), 1e-15);
  EXPECT_NEAR(cost, cost_alone, 1e-8 * cost);
  EXPECT_NEAR(gradient, second.cost_gradient * kScale / objective.rest_cost(),
              1e-12 * std::abs(gradient));
  // The bar at rest is admissible for every E: 0 <= e^2 <= J_rest.
  EXPECT_GT(cost, 0.0);
  EXPECT_LT(cost, 1.0);
}

// J_rest, the cost of the bar at rest (U = W = 0), written out term by term for each
// clamp (docs/discrete_mcre.md section 1, docs/trusted_clamp.md sections 1 and 9):
// measured: alpha/2 (f0~^2 + fL~^2) + beta/2 (u0~^2 + uL~^2); pinned: alpha_0/2 f0~^2
// + alpha/2 fL~^2 + beta/2 uL~^2 (u0's datum is the known 0); trusted: alpha_r/2 f0~^2
// (the reaction r(0) = 0 against f0~) + alpha/2 fL~^2 + beta/2 uL~^2. w_u0 and w_r
// differ so that a swap of the two shows.
TEST_F(ObjectiveTest, RestCostIsTheCostOfTheBarAtRestForEveryClamp) {
  const BarProperties& bar = model_.properties();
  const double reference_modulus = 200e9;
  const double beta = 0.01 * bar.section * reference_modulus / bar.length;
  const double alpha = 1.0 * bar.length / (bar.section * reference_modulus);
  const double alpha_w_r = 0.05 * bar.length / (bar.section * reference_modulus);
  for (ClampModel clamp : {ClampModel::kMeasured, ClampModel::kPinned, ClampModel::kTrusted}) {
    SCOPED_TRACE(ClampModelToString(clamp));
    McreOptions options;
    options.weights.displacement_weight = 0.01;
    options.weights.strain_weight = 0.01;
    options.weights.force_weight = 1.0;
    options.weights.clamp_displacement_weight = 0.3;
    options.weights.reaction_weight = 0.05;
    options.reference_modulus = reference_modulus;
    options.clamp = clamp;
    const McreObjective objective = testing::BarObjective(
        matrices_, data_, options, CoupledSolverOptions(), kScale, case_.time.theta);
    double expected = 0.0;
    for (int j = 0; j <= data_.num_steps(); ++j) {
      const double c = (j == 0 || j == data_.num_steps()) ? 0.5 : 1.0;
      const double f0 = data_.Values("f0")[j], fL = data_.Values("fL")[j],
                   u0 = data_.Values("u0")[j], uL = data_.Values("uL")[j];
      const double clamp_terms = clamp == ClampModel::kMeasured ? alpha * f0 * f0 + beta * u0 * u0
                                                                : alpha_w_r * f0 * f0;
      expected += c * data_.time_step * 0.5 * (clamp_terms + alpha * fL * fL + beta * uL * uL);
    }
    // The same sum in another order: measured 0.9e-15 to 1.3e-15 of it.
    EXPECT_NEAR(objective.rest_cost(), expected, 1e-14 * expected);
  }
}

TEST_F(ObjectiveTest, GradientMatchesCentralDifferencesOfTheScaledCost) {
  CoupledSolverOptions inner;
  inner.tolerance = 1e-12;
  McreObjective objective = MakeObjective(inner);
  const double x = 1.1;
  const double step = 1e-4;
  double cost = 0.0;
  double gradient = 0.0;
  ASSERT_TRUE(objective.Evaluate(&x, &cost, &gradient));
  const double x_plus = x + step;
  const double x_minus = x - step;
  double cost_plus = 0.0;
  double cost_minus = 0.0;
  ASSERT_TRUE(objective.Evaluate(&x_plus, &cost_plus, nullptr));
  ASSERT_TRUE(objective.Evaluate(&x_minus, &cost_minus, nullptr));
  const double difference = (cost_plus - cost_minus) / (2.0 * step);
  EXPECT_NEAR(gradient, difference, 1e-5 * std::abs(gradient));
}

TEST_F(ObjectiveTest, WarmStartFromThePreviousSolutionSavesIterations) {
  McreObjective cold = MakeObjective();
  McreObjective warm = MakeObjective();
  const double start = 1.25;
  const double next = 1.2501;
  double cost = 0.0;
  ASSERT_TRUE(warm.Evaluate(&start, &cost, nullptr));
  ASSERT_TRUE(warm.Evaluate(&next, &cost, nullptr));
  ASSERT_TRUE(cold.Evaluate(&next, &cost, nullptr));
  EXPECT_LT(warm.evaluations()[1].inner.iterations, cold.evaluations()[0].inner.iterations);
}

TEST_F(ObjectiveTest, KeepsTheBestEvaluationAndItsSolution) {
  McreObjective objective = MakeObjective();
  double cost = 0.0;
  for (const double x : {0.8, 1.25, 1.6}) ASSERT_TRUE(objective.Evaluate(&x, &cost, nullptr));
  // The data were made with E = 200 GPa = 1.25 E_scale.
  EXPECT_EQ(objective.best_index(), 1);
  EXPECT_EQ(objective.best_solution().cost, objective.evaluations()[1].cost);
  EXPECT_EQ(objective.best_solution().displacement.cols(), data_.num_samples());
  EXPECT_GT(objective.sweeps(), 0);
}

TEST_F(ObjectiveTest, NonPositiveParameterIsRefusedWithAMessage) {
  McreObjective objective = MakeObjective();
  double cost = 0.0;
  const double x = -0.5;
  EXPECT_FALSE(objective.Evaluate(&x, &cost, nullptr));
  EXPECT_NE(objective.error_message().find("not a positive finite number"), std::string::npos)
      << objective.error_message();
  EXPECT_TRUE(objective.evaluations().empty());
}

TEST_F(ObjectiveTest, UnusableInnerSolveReturnsFalseAndKeepsTheSolverMessage) {
  CoupledSolverOptions inner;
  inner.max_iterations = 1;
  inner.tolerance = 1e-14;
  McreObjective objective = MakeObjective(inner);
  double cost = 0.0;
  double gradient = 0.0;
  const double x = 1.0;
  EXPECT_FALSE(objective.Evaluate(&x, &cost, &gradient));
  EXPECT_NE(objective.error_message().find("not usable"), std::string::npos)
      << objective.error_message();
  EXPECT_NE(objective.error_message().find("no_convergence"), std::string::npos)
      << objective.error_message();
  ASSERT_EQ(objective.evaluations().size(), 1u);
  EXPECT_FALSE(objective.evaluations()[0].usable);
  EXPECT_EQ(objective.best_index(), -1);
}

// The coarse plate with data of its own model (inverse crime) at `truth`: a 20 us
// half-sine impact of 1 kN, 100 steps of 1 us.
struct PlateInverseCrime {
  explicit PlateInverseCrime(const Vector& truth)
      : plate(ReadMatrixModel(std::string(MCREWAVE_SOURCE_DIR) +
                              "/configs/plate/coarse/model.yaml")) {
    Matrix loads = Matrix::Zero(1, 101);
    for (int j = 0; j * 1e-6 < 2e-5; ++j) loads(0, j) = 1e3 * std::sin(M_PI * j / 20.0);
    const ChannelSet at_rest = MatrixChannelSet(
        plate, 1e-6, loads, Matrix::Zero(static_cast<int>(plate.sensors.size()), 101));
    MatrixMcreProblem simulation(plate, at_rest, Weights(0.01, 1.0), 2e11, 0.5);
    simulation.SetModuli(truth);
    data = MatrixChannelSet(plate, 1e-6, loads, simulation.ModelOutputs());
  }
  MatrixModelData plate;
  ChannelSet data;
};

// The plate's weights: w_u = 0.01, w_f = 1, E0 = 2e11 Pa (no supports to treat).
McreOptions PlateMcre() {
  McreOptions mcre;
  mcre.weights = Weights(0.01, 1.0);
  mcre.reference_modulus = 2e11;
  return mcre;
}

// ZoneMcreObjective on a structure given by matrices: the inverse crime on the coarse
// plate recovers both zones from the nominal start; a solve that fails is reported,
// not thrown.
TEST(ZoneMcreObjectiveTest, InverseCrimeOnThePlateRecoversBothZones) {
  const Vector truth = (Vector(2) << 2.1e11, 1.5e11).finished();
  PlateInverseCrime crime(truth);
  CoupledSolverOptions inner;
  inner.tolerance = 1e-10;
  McreObjective mcre_objective =
      MatrixMcreObjective(crime.plate, crime.data, PlateMcre(), 0.5, inner);
  ZoneMcreObjective objective(&mcre_objective, crime.plate.NominalModuli());
  // At the truth e^2 = 0 to round-off (measured exactly 0).
  const double at_truth[2] = {std::log(truth[0] / 2e11), std::log(truth[1] / 2e11)};
  double cost = -1.0;
  ASSERT_TRUE(objective.Evaluate(at_truth, &cost, nullptr)) << objective.error_message();
  EXPECT_LT(cost, 1e-20);

  const BoundedMinimizerSummary summary = testing::MinimizeWithinHalfAndTwice(&objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const Vector found = objective.Moduli(summary.x.data());
  // Measured: 5.0e-12 (matrix) and 1.2e-12 (inclusion) off, in 14 evaluations; the
  // issue asks for 1e-6.
  for (int z = 0; z < 2; ++z) {
    EXPECT_NEAR(found[z], truth[z], 5e-11 * truth[z]) << crime.plate.zones[z].name;
  }
}

TEST(ZoneMcreObjectiveTest, AFailedSolveIsReportedNotThrown) {
  PlateInverseCrime crime((Vector(2) << 2e11, 2e11).finished());
  CoupledSolverOptions inner;
  inner.max_iterations = 1;
  McreObjective mcre_objective =
      MatrixMcreObjective(crime.plate, crime.data, PlateMcre(), 0.5, inner);
  ZoneMcreObjective objective(&mcre_objective, crime.plate.NominalModuli());
  const double p[2] = {0.1, -0.2};
  double cost = -1.0, gradient[2] = {0.0, 0.0};
  EXPECT_FALSE(objective.Evaluate(p, &cost, gradient));
  EXPECT_NE(objective.error_message().find("of evaluation 1 is not usable"), std::string::npos)
      << objective.error_message();
}

// The search functional is e^2 itself when its weights are mcre's and there are no
// supports, or mcre's clamp is pinned at the search's w_u0 and w_r.
TEST(McreObjectiveTest, TheSearchIsTheObjectiveOnlyWhereItPosesTheSameProblem) {
  const SearchOptions search;
  McreOptions mcre;  // the config's defaults: w_u = 1e-7, the clamp trusted
  EXPECT_FALSE(SearchIsTheObjective(mcre, search, false));
  mcre.weights.displacement_weight = search.displacement_weight;
  mcre.weights.strain_weight = search.strain_weight;
  EXPECT_TRUE(SearchIsTheObjective(mcre, search, false));
  EXPECT_FALSE(SearchIsTheObjective(mcre, search, true));  // trusted, not pinned
  mcre.clamp = ClampModel::kPinned;
  mcre.weights.clamp_displacement_weight = search.clamp_displacement_weight;
  mcre.weights.reaction_weight = search.reaction_weight;
  EXPECT_TRUE(SearchIsTheObjective(mcre, search, true));
  mcre.weights.reaction_weight = 2.0 * search.reaction_weight;
  EXPECT_FALSE(SearchIsTheObjective(mcre, search, true));
  EXPECT_TRUE(SearchIsTheObjective(mcre, search, false));
}

// The bar's identification on the one road: the two-stage search of configs/paper_bar.yaml
// (the pinned clamp's e^2 scanned and refined, then the trusted clamp's e^2 refined
// within 3 % of it) run once on the built-in bar and once on the same bar exported as
// matrices with its clamp as a support, from the same data, E per unit of x the same:
// the same evaluations and the same modulus, to the bit (BarMcreProblem computes as
// MatrixMcreProblem does, docs/matrix_models.md section 6).
TEST(McreObjectiveTest, TheBarAsMatricesIdentifiesTheBuiltInBarsModulus) {
  const testing::SmallCase c = MakeSmallCase(20, 350, 10.0, 2);
  const BarModel model(c.bar);
  const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  const MatrixModelData matrices =
      BarMatrixModel(model, c.bar.modulus, {}, BarClampExport::kSupport);
  McreOptions mcre;  // the config's defaults: the clamp trusted, w_u = 1e-7, w_r = 1e-6
  const McreOptions search = SearchMcreOptions(mcre, SearchOptions());
  CoupledSolverOptions inner;
  CoupledSolverOptions search_inner;
  search_inner.tolerance = SearchOptions().inner_tolerance;
  IdentificationOptions options;
  options.scan_threads = 1;
  std::vector<IdentificationSummary> summaries;
  std::vector<std::vector<ObjectiveEvaluation>> evaluations;
  for (const bool as_matrices : {false, true}) {
    McreObjective objective =
        as_matrices ? MatrixMcreObjective(matrices, data, mcre, 0.5, inner,
                                          Factorization::kAutomatic, options.initial)
                    : testing::BarMcreObjective(model, data, mcre, 0.5, inner, options.initial);
    McreObjective search_objective =
        as_matrices
            ? MatrixMcreObjective(matrices, data, search, 0.5, search_inner,
                                  Factorization::kAutomatic, options.initial)
            : testing::BarMcreObjective(model, data, search, 0.5, search_inner, options.initial);
    summaries.push_back(IdentifyInTwoStages(options, &search_objective, SearchOptions().scan_points,
                                            SearchOptions().refine_window, &objective));
    ASSERT_TRUE(summaries.back().IsSolutionUsable()) << summaries.back().FullReport();
    evaluations.push_back(objective.evaluations());
  }
  EXPECT_EQ(summaries[1].search_modulus, summaries[0].search_modulus);
  EXPECT_EQ(summaries[1].modulus, summaries[0].modulus);
  EXPECT_EQ(summaries[1].evaluations, summaries[0].evaluations);
  ASSERT_EQ(evaluations[1].size(), evaluations[0].size());
  for (std::size_t i = 0; i < evaluations[0].size(); ++i) {
    EXPECT_EQ(evaluations[1][i].modulus, evaluations[0][i].modulus) << "evaluation " << i;
    EXPECT_EQ(evaluations[1][i].cost, evaluations[0][i].cost) << "evaluation " << i;
    EXPECT_EQ(evaluations[1][i].cost_gradient, evaluations[0][i].cost_gradient)
        << "evaluation " << i;
  }
}

// The streaming CG's round-off floor, remembered (McreObjective::kFloorMargin): the bar
// of 400 elements at Courant number 9 and inner.tolerance 1e-12, below what its sweeps
// reach. The first solve is accepted at its floor f after two restarts (measured: f =
// 4.2e-12 in 6 iterations), the tolerance becomes 2 f, and a solve at the same modulus
// from that solution needs no iteration, one at a modulus 1 % off fewer than the first
// (measured: 2).
TEST(McreObjectiveTest, ARoundOffFloorMetOnceIsNotConfirmedAgain) {
  testing::SmallCase c = MakeSmallCase(400, 120, 20.0, 1);
  c.time.step = 1.44e-6;  // c h / l = 9.1
  c.time.window = 120 * c.time.step;
  c.load.duration = 0.1e-3 * c.time.window / 0.63e-3;
  const ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  const MatrixModelData matrices = BarMatrixModel(BarModel(c.bar), c.bar.modulus);
  CoupledSolverOptions inner;
  inner.type = CoupledSolverType::kStreamingConjugateGradient;
  inner.tolerance = 1e-12;
  McreObjective objective = MatrixMcreObjective(matrices, data, McreOptions(), 0.5, inner);
  const ObjectiveEvaluation first = objective.EvaluateModulus(2e11);
  ASSERT_TRUE(first.usable) << first.inner.FullReport();
  EXPECT_TRUE(first.inner.at_round_off_floor) << first.inner.message;
  EXPECT_GT(first.inner.relative_residual, inner.tolerance);
  EXPECT_EQ(objective.inner_tolerance(),
            McreObjective::kFloorMargin * first.inner.relative_residual);
  const ObjectiveEvaluation again = objective.EvaluateModulus(2e11);
  ASSERT_TRUE(again.usable) << again.inner.FullReport();
  EXPECT_EQ(again.inner.iterations, 0) << again.inner.message;
  EXPECT_FALSE(again.inner.at_round_off_floor);
  const ObjectiveEvaluation nearby = objective.EvaluateModulus(2.02e11);
  ASSERT_TRUE(nearby.usable) << nearby.inner.FullReport();
  EXPECT_LT(nearby.inner.iterations, first.inner.iterations);
}

TEST(McreObjectiveTest, AScanCopyStartedAfreshEvaluatesAsAFreshCopy) {
  // The scan reuses one CloneForScan copy for several chunks of points, StartAfresh
  // before each: its next evaluation must be a fresh copy's to the bit, the warm starts
  // and the trace preconditioner (kept within 2 % of the moduli it was built at)
  // forgotten. The plate, its streaming CG preconditioned, at E 1 % apart.
  PlateInverseCrime crime((Vector(2) << 2.1e11, 1.5e11).finished());
  CoupledSolverOptions inner;
  inner.type = CoupledSolverType::kStreamingConjugateGradient;
  inner.preconditioner = TracePreconditioner::kDenseTraces;
  const McreObjective objective =
      MatrixMcreObjective(crime.plate, crime.data, PlateMcre(), 0.5, inner);
  const double first = 1.0, second = 1.01;  // x = E / 2e11
  struct Value {
    double cost = 0.0, gradient = 0.0;
  };
  auto evaluate = [](ModulusObjective* copy, double x) {
    Value value;
    EXPECT_TRUE(copy->Evaluate(&x, &value.cost, &value.gradient)) << copy->error_message();
    return value;
  };
  const std::unique_ptr<ModulusObjective> fresh = objective.CloneForScan(1e-6);
  const Value expected = evaluate(fresh.get(), second);
  const std::unique_ptr<ModulusObjective> reused = objective.CloneForScan(1e-6);
  evaluate(reused.get(), first);
  reused->StartAfresh();
  const Value actual = evaluate(reused.get(), second);
  EXPECT_EQ(actual.cost, expected.cost);
  EXPECT_EQ(actual.gradient, expected.gradient);
  // Without StartAfresh the second evaluation starts from the first's solution and
  // factor: other bits.
  const std::unique_ptr<ModulusObjective> warm = objective.CloneForScan(1e-6);
  evaluate(warm.get(), first);
  EXPECT_NE(evaluate(warm.get(), second).cost, expected.cost);
}

}  // namespace
}  // namespace mcrewave
