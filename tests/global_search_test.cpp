// Tests of the global search of Identify (scan of cost and gradient, valleys,
// bracketed local refinement) on real MCRE costs of small cases: on a rugged cost
// (low SNR, long window) with at least 5 valleys, found by a dense scan and
// gradient bisection in the test, every optimiser returns the same global
// minimiser, with the pre-filter off and on, scanning the cost itself or (the trusted
// clamp's) through the pinned search functional; the predicted valley spacing matches
// the dense scan's; Ceres' first step follows the curvature; on noise-free data
// from the finer truth the defaults identify E within 0.1 %.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/data/prefilter.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/identification.h"
#include "mcrewave/optim/valley_spacing.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::SmallCase;

constexpr double kReference = 200e9;  // E of the data [Pa]

// The paper's free-free formulation at w_u, whose valleys these tests measure.
McreOptions WeightsOf(double w_u) { return testing::FreeFreeMcre(w_u); }

// The global minimiser of e^2 on [lower, upper] as the test finds it on its own,
// with none of the optimisers under test: e^2 and de^2/dE on a dense grid at a
// tight inner tolerance, then bisection on the sign of the adjoint gradient in
// every bracket [E_i, E_i+1] where it changes from - to +, to 1e-10 relative; the
// lowest of those minima. Writes the minimisers of every valley (sign change) seen.
double DenseGlobalMinimiser(const MatrixModelData& matrices, const ChannelSet& data,
                            const McreOptions& mcre, double lower, double upper, int points,
                            std::vector<double>* valleys) {
  CoupledSolverOptions inner;
  inner.tolerance = 1e-10;
  McreObjective objective = testing::BarObjective(matrices, data, mcre, inner, kReference);
  std::vector<double> moduli, gradients;
  for (int i = 0; i < points; ++i) {
    moduli.push_back(lower + (upper - lower) * i / (points - 1.0));
    const ObjectiveEvaluation& evaluation = objective.EvaluateModulus(moduli.back(), true);
    EXPECT_TRUE(evaluation.usable);
    gradients.push_back(evaluation.cost_gradient);
  }
  valleys->clear();
  double best_modulus = 0.0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int i = 0; i + 1 < points; ++i) {
    if (!(gradients[i] < 0.0 && gradients[i + 1] >= 0.0)) continue;
    double left = moduli[i], right = moduli[i + 1];
    while (right - left > 1e-10 * right) {
      const double middle = 0.5 * (left + right);
      (objective.EvaluateModulus(middle, true).cost_gradient < 0.0 ? left : right) = middle;
    }
    const ObjectiveEvaluation& minimum = objective.EvaluateModulus(0.5 * (left + right), false);
    valleys->push_back(minimum.modulus);
    if (minimum.cost < best_cost) {
      best_cost = minimum.cost;
      best_modulus = minimum.modulus;
    }
  }
  return best_modulus;
}

// A rugged case: 10 elements, 400 steps (a window of 4 wave transits), SNR 1.5,
// data from the 2x finer truth; a dense scan of E in [100, 400] GPa sees 6
// valleys of e^2 with w_u = 0.01 (1 with the pre-filter on).
struct RuggedCase {
  explicit RuggedCase(bool prefilter_enabled = false)
      : small(MakeSmallCase(10, 400, 1.5, 2)),
        model(small.bar),
        data(PrefilterMeasurements(
            MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data),
            [&] {
              PrefilterOptions prefilter;
              prefilter.enabled = prefilter_enabled;
              return prefilter;
            }())),
        matrices(BarRunModel(model, data, {})) {}
  SmallCase small;
  BarModel model;
  ChannelSet data;
  MatrixModelData matrices;  // the bar as the identification solves it
};

struct OptimizerCase {
  OptimizerType optimizer;
  OuterAlgorithm algorithm;
};
constexpr OptimizerCase kEveryOptimizer[] = {
    {OptimizerType::kNlopt, OuterAlgorithm::kBobyqa},
    {OptimizerType::kNlopt, OuterAlgorithm::kLbfgs},
    {OptimizerType::kNlopt, OuterAlgorithm::kBrent},
    {OptimizerType::kNlopt, OuterAlgorithm::kSecant},
    {OptimizerType::kCeres, OuterAlgorithm::kLbfgs},
};

class EveryOptimizerTest : public ::testing::TestWithParam<bool> {};

TEST_P(EveryOptimizerTest, ReturnsTheGlobalMinimiserOfARuggedCost) {
  const bool filtered = GetParam();
  const RuggedCase rugged(filtered);
  const McreOptions mcre = WeightsOf(0.01);
  const IdentificationOptions defaults;
  std::vector<double> valleys;
  const double global =
      DenseGlobalMinimiser(rugged.matrices, rugged.data, mcre, defaults.lower_bound,
                           defaults.upper_bound, 601, &valleys);
  const int dense_valleys = static_cast<int>(valleys.size());
  // Unfiltered: 6 valleys, the rugged case; filtered: 1.
  ASSERT_GE(dense_valleys, filtered ? 1 : 5) << "the case is not rugged enough";

  for (const OptimizerCase& tried : kEveryOptimizer) {
    IdentificationOptions options;
    options.optimizer = tried.optimizer;
    options.algorithm = tried.algorithm;
    McreObjective objective = testing::BarObjective(rugged.matrices, rugged.data, mcre,
                                                    CoupledSolverOptions(), options.initial);
    const IdentificationSummary summary = Identify(options, &objective);
    const std::string name = std::string(OptimizerTypeToString(tried.optimizer)) + "/" +
                             OuterAlgorithmToString(tried.algorithm);
    ASSERT_TRUE(summary.IsSolutionUsable()) << name << ": " << summary.FullReport();
    // Measured: at most 5.4e-8 from the dense minimiser (Ceres, filtered; NLopt BOBYQA
    // 5e-10, L-BFGS 1.4e-9, Brent 1.5e-8); the goal was 1e-6.
    EXPECT_NEAR(summary.modulus / global, 1.0, 5e-7) << name << ": " << summary.FullReport();
    // The scan sees every valley the dense grid sees (and no fewer).
    EXPECT_GE(summary.local_minima, dense_valleys) << name << ": " << summary.FullReport();
    EXPECT_GT(summary.predicted_valley_spacing, 0.0);
    EXPECT_GE(summary.scan_evaluations, options.scan_points);
    EXPECT_FALSE(summary.scan_resolution_limited);
    if (dense_valleys >= 2) {
      EXPECT_GE(summary.refinements, 2) << name << ": " << summary.FullReport();
      EXPECT_GT(summary.cost_gap, 0.0);
      EXPECT_GT(summary.second_modulus, 0.0);
    }
  }

  if (filtered) return;
  // The unfiltered case needs the global search: a local search from
  // outer.initial alone stops in another valley (measured: the secant 0.5 % away).
  IdentificationOptions local_only;
  local_only.scan_points = 0;
  McreObjective local_objective = testing::BarObjective(rugged.matrices, rugged.data, mcre,
                                                        CoupledSolverOptions(), local_only.initial);
  const IdentificationSummary local = Identify(local_only, &local_objective);
  EXPECT_GT(std::abs(local.modulus / global - 1.0), 1e-3) << local.FullReport();
}

TEST_P(EveryOptimizerTest, InTwoStagesReturnsTheGlobalMinimiserOfTheTrustedCost) {
  // The defaults: the trusted clamp's e^2, scanned through the pinned search
  // functional (IdentifyInTwoStages), against the dense global minimiser of e^2 itself.
  const bool filtered = GetParam();
  const RuggedCase rugged(filtered);
  const McreOptions mcre;
  const SearchOptions search_options;
  const IdentificationOptions defaults;
  std::vector<double> valleys;
  const double global =
      DenseGlobalMinimiser(rugged.matrices, rugged.data, mcre, defaults.lower_bound,
                           defaults.upper_bound, 601, &valleys);
  // Several valleys, filtered or not (measured: 4 unfiltered, 3 filtered).
  ASSERT_GE(valleys.size(), 3u) << "the trusted cost is not rugged enough";
  CoupledSolverOptions search_inner;
  search_inner.tolerance = search_options.inner_tolerance;
  for (const OptimizerCase& tried : kEveryOptimizer) {
    IdentificationOptions options;
    options.optimizer = tried.optimizer;
    options.algorithm = tried.algorithm;
    McreObjective search =
        testing::BarObjective(rugged.matrices, rugged.data, SearchMcreOptions(mcre, search_options),
                              search_inner, options.initial);
    McreObjective objective = testing::BarObjective(rugged.matrices, rugged.data, mcre,
                                                    CoupledSolverOptions(), options.initial);
    const IdentificationSummary summary = IdentifyInTwoStages(
        options, &search, search_options.scan_points, search_options.refine_window, &objective);
    const std::string name = std::string(OptimizerTypeToString(tried.optimizer)) + "/" +
                             OuterAlgorithmToString(tried.algorithm);
    ASSERT_TRUE(summary.IsSolutionUsable()) << name << ": " << summary.FullReport();
    // One valley of the search, its minimiser 0.6 % (unfiltered) and 1.0 % (filtered)
    // from the trusted one, which every optimiser then finds within 1.8e-8 (Brent; NLopt
    // BOBYQA 1.6e-9, L-BFGS 3.2e-11, Ceres 3.7e-11).
    EXPECT_EQ(summary.local_minima, 1) << name << ": " << summary.FullReport();
    EXPECT_TRUE(summary.scan_of_search) << name;
    EXPECT_NEAR(summary.modulus / global, 1.0, 2e-7) << name << ": " << summary.FullReport();
  }
}

INSTANTIATE_TEST_SUITE_P(Prefilter, EveryOptimizerTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("filtered") : std::string("unfiltered");
                         });

TEST(GlobalSearchTest, PredictedValleySpacingMatchesTheDenseScan) {
  // Rice's mean distance between minima (valley_spacing.h) against the mean
  // distance between neighbouring valleys of a dense grid of 601 points on the
  // rugged case: measured 0.114 in ln E for a prediction of 0.0517 (ratio 2.21; on
  // the paper's case 0.78 to 1.35, docs/global_search.md). A prediction below the
  // measured spacing only makes the scan finer; the band is [0.5, 3].
  const RuggedCase rugged;
  const McreOptions mcre = WeightsOf(0.01);
  McreObjective objective =
      testing::BarObjective(rugged.matrices, rugged.data, mcre, CoupledSolverOptions(), 200e9);
  const double predicted = objective.ValleySpacing();
  std::vector<double> valleys;
  DenseGlobalMinimiser(rugged.matrices, rugged.data, mcre, 100e9, 400e9, 601, &valleys);
  ASSERT_GE(valleys.size(), 3u);
  const double measured = std::log(valleys.back() / valleys.front()) / (valleys.size() - 1.0);
  EXPECT_GT(predicted, 0.0);
  EXPECT_GT(measured / predicted, 0.5) << "predicted " << predicted << ", measured " << measured;
  EXPECT_LT(measured / predicted, 3.0) << "predicted " << predicted << ", measured " << measured;
}

TEST(GlobalSearchTest, CeresFirstStepFollowsTheCurvature) {
  // Ceres' parameter is scaled so that its first step is the Newton step of the
  // scan's Hermite interpolant: the second evaluation of the refinement lands
  // much closer to the minimiser than the first (measured: 0.097 of the distance).
  const RuggedCase rugged;
  const McreOptions mcre = WeightsOf(0.01);
  IdentificationOptions options;
  options.optimizer = OptimizerType::kCeres;
  options.refine_candidates = 1;
  McreObjective objective = testing::BarObjective(rugged.matrices, rugged.data, mcre,
                                                  CoupledSolverOptions(), options.initial);
  const IdentificationSummary summary = Identify(options, &objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const std::vector<ObjectiveEvaluation>& evaluations = objective.evaluations();
  ASSERT_GE(evaluations.size(), 3u);
  const double first = std::abs(evaluations[0].modulus - summary.modulus);
  const double second = std::abs(evaluations[1].modulus - summary.modulus);
  EXPECT_LT(second, 0.3 * first) << "first " << evaluations[0].modulus << ", second "
                                 << evaluations[1].modulus << ", minimiser " << summary.modulus;
}

TEST(GlobalSearchTest, ScanResultsDoNotDependOnTheThreads) {
  // Every scan cost, the refined E and the sweeps: the same bits on 1, 2 and 4
  // threads (before the scan was cut into fixed chunks, the costs differed by
  // 8e-7 relative between 1 and 2 threads, 1.7e-6 between 1 and 4).
  const RuggedCase rugged;
  const McreOptions mcre = WeightsOf(0.01);
  std::vector<IdentificationSummary> summaries;
  for (const int threads : {1, 2, 4}) {
    IdentificationOptions options;
    options.scan_threads = threads;
    options.scan_points = 21;
    options.scan_samples_per_valley = 0.0;  // 21 points: the chunks, not the count, are tested
    McreObjective objective = testing::BarObjective(rugged.matrices, rugged.data, mcre,
                                                    CoupledSolverOptions(), options.initial);
    summaries.push_back(Identify(options, &objective));
    const IdentificationSummary& summary = summaries.back();
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    // The scan runs on copies of the objective; their sweeps are counted, at
    // least one retrograde and one direct sweep per scan point.
    EXPECT_GE(summary.scan_sweeps, 2L * options.scan_points) << summary.FullReport();
  }
  for (std::size_t k = 1; k < summaries.size(); ++k) {
    const IdentificationSummary& one = summaries[0];
    const IdentificationSummary& other = summaries[k];
    ASSERT_EQ(one.scan_costs.size(), other.scan_costs.size());
    for (std::size_t i = 0; i < one.scan_costs.size(); ++i) {
      EXPECT_EQ(one.scan_costs[i], other.scan_costs[i]) << "scan point " << i;
    }
    EXPECT_EQ(one.scan_sweeps, other.scan_sweeps);
    EXPECT_EQ(one.modulus, other.modulus);
    EXPECT_EQ(one.cost, other.cost);
    EXPECT_EQ(one.evaluations, other.evaluations);
  }
}

// Noise-free data from the 4x finer truth: the relative error of E identified
// with the outer loop's defaults and the MCRE options `mcre`, the pre-filter as given.
double NoiseFreeError(const McreOptions& mcre, bool prefilter_enabled, double* cutoff) {
  const SmallCase small = MakeSmallCase(30, 300, std::numeric_limits<double>::infinity(), 4);
  const BarModel model(small.bar);
  PrefilterOptions prefilter;
  prefilter.enabled = prefilter_enabled;
  const ChannelSet data = PrefilterMeasurements(
      MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data), prefilter, cutoff);
  const IdentificationOptions options;
  const MatrixModelData matrices = BarRunModel(model, data, {});
  McreObjective objective =
      testing::BarObjective(matrices, data, mcre, CoupledSolverOptions(), options.initial);
  const IdentificationSummary summary = Identify(options, &objective);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_EQ(summary.local_minima, 1) << summary.FullReport();
  // relative error = (E* - E_ref) / E_ref
  return (summary.modulus - kReference) / kReference;
}

TEST(GlobalSearchTest, NoiseFreeDataFromTheFinerTruthGiveEWithinATenthOfAPercent) {
  // The discretisation bias of 30 elements against the 4x finer truth, in the paper's
  // free-free formulation: measured -2.51e-4.
  double cutoff = 0.0;
  EXPECT_LE(std::abs(NoiseFreeError(testing::FreeFreeMcre(), false, &cutoff)), 1e-3);
}

TEST(GlobalSearchTest, NoiseFreeDataAtTheDefaultsKeepTheTrustedClampsReactionBias) {
  // The same data at the defaults (the clamp trusted): measured 1.53e-3 in size, most
  // of it the kinematic clamp reaction's O(l^2) error on 30 elements
  // (docs/trusted_clamp.md section 1).
  double cutoff = 0.0;
  EXPECT_LE(std::abs(NoiseFreeError(McreOptions(), false, &cutoff)), 2e-3);
}

TEST(GlobalSearchTest, PrefilterDoesNotBiasNoiseFreeIdentification) {
  double cutoff = 0.0;
  const double filtered = NoiseFreeError(testing::FreeFreeMcre(), true, &cutoff);
  EXPECT_GT(cutoff, 0.0);
  EXPECT_LE(std::abs(filtered), 1e-3);
  // The pre-filter's own bias: measured 5.1e-8 (filtered -2.50965e-4, unfiltered
  // -2.51016e-4).
  double unused = 0.0;
  EXPECT_LE(std::abs(filtered - NoiseFreeError(testing::FreeFreeMcre(), false, &unused)), 5e-7);
}

}  // namespace
}  // namespace mcrewave
