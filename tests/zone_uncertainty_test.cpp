// EstimateZoneUncertainty (mcre/zone_uncertainty.h) against re-identification: one noise
// draw n, reproduced here, scaled down to stay in the linear regime, moves the moduli
// identified from d + eps n by eps dE, and the estimate with that single draw has the
// covariance dE dE^T; the sensitivity map's noise part against solves of the noisy data
// themselves. The bar of 30 elements in two zones as matrices, free-free (the paper's
// formulation), SNR 20 data with an interior displacement sensor and a strain gauge.
#include "mcrewave/mcre/zone_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "mcrewave/core/random.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

struct TwoZoneBarAsMatrices {
  TwoZoneBarAsMatrices() {
    testing::SmallCase c = testing::MakeSmallCase(30, 240, 20.0, 2);
    c.data.sensors = {"u@0.25", "e@0.65"};
    std::vector<int> zones(30);
    for (int e = 0; e < 30; ++e) zones[e] = e < 12 ? 0 : 1;
    data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
    matrices = BarMatrixModel(BarModel(c.bar, zones), 200e9,
                              {{SensorKind::kDisplacement, 0.25}, {SensorKind::kStrain, 0.65}});
    mcre.weights = testing::Weights(0.01, 1.0);
    mcre.weights.strain_weight = 0.01;
    mcre.clamp = ClampModel::kMeasured;
    inner.tolerance = 1e-12;
  }
  // The moduli minimising e^2 of `set`, from p = 0.
  Vector Identify(const ChannelSet& set) const {
    McreObjective mcre_objective = MatrixMcreObjective(matrices, set, mcre, 0.5, inner);
    ZoneMcreObjective objective(&mcre_objective, matrices.NominalModuli());
    BoundedMinimizerOptions options;
    options.step_tolerance = 1e-12;
    options.function_tolerance = 0.0;
    const BoundedMinimizerSummary summary =
        MinimizeWithinBounds(options, &objective, {-0.7, -0.7}, {0.7, 0.7}, {0.0, 0.0});
    EXPECT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    return objective.Moduli(summary.x.data());
  }
  ChannelSet data;
  MatrixModelData matrices;
  McreOptions mcre;
  CoupledSolverOptions inner;
};

// The seed of the one draw the tests reproduce.
constexpr std::uint64_t kDrawSeed = 5;

// EstimateZoneUncertainty with that one draw, at the levels DifferenceNoiseLevels
// estimates from the bar's data.
ZoneUncertainty OneDrawEstimate(const TwoZoneBarAsMatrices& bar, const Vector& moduli,
                                const CoupledSolution& solution) {
  UncertaintyOptions options;
  options.samples = 1;
  options.seed = kDrawSeed;
  return EstimateZoneUncertainty(options, bar.matrices, bar.data, bar.mcre, 0.5, bar.inner, moduli,
                                 solution, DifferenceNoiseLevels(bar.data));
}

TEST(ZoneUncertaintyTest, OneDrawPredictsTheMovementOfTheReidentifiedModuli) {
  TwoZoneBarAsMatrices bar;
  const Vector moduli = bar.Identify(bar.data);
  MatrixMcreProblem problem(bar.matrices, bar.data, bar.mcre.weights, bar.mcre.reference_modulus,
                            0.5, Factorization::kAutomatic, bar.mcre.clamp);
  problem.SetModuli(moduli);
  CoupledSolution solution;
  ASSERT_TRUE(SolveCoupled(bar.inner, &problem, nullptr, &solution).IsSolutionUsable());
  const NoiseLevels levels = DifferenceNoiseLevels(bar.data);
  const ZoneUncertainty estimate = OneDrawEstimate(bar, moduli, solution);
  ASSERT_TRUE(estimate.available) << estimate.message;
  EXPECT_EQ(estimate.samples, 1);

  // The same draw, in the same order, scaled by eps.
  const double eps = 1e-3;
  ChannelSet noisy = bar.data;
  StandardNormal normal(kDrawSeed);
  for (Channel& channel : noisy.channels) {
    const double level = channel.kind == ChannelKind::kStrain  ? levels.strain_std
                         : channel.kind == ChannelKind::kForce ? levels.force_std
                                                               : levels.displacement_std;
    for (double& value : channel.values) value += eps * level * normal();
  }
  const Vector change = (bar.Identify(noisy) - moduli) / eps;
  // Cov = dE dE^T from one draw: its diagonal the squares, its off-diagonal the product.
  // Measured: the standard deviations 1.7 % and 1.1 % off |dE_z| (2.4 and 1.2 GPa), the
  // covariance 2.8 % off: the estimate's curvature is a secant over +- 5 % of E*.
  for (int z = 0; z < 2; ++z) {
    EXPECT_NEAR(estimate.std_dev[z], std::abs(change[z]), 0.05 * std::abs(change[z])) << z;
  }
  EXPECT_NEAR(estimate.covariance(0, 1), change[0] * change[1],
              0.1 * std::abs(change[0] * change[1]));
}

// The sensitivity map's noise part (zone_uncertainty.h) against solves of the noisy data
// themselves: with one draw n, reproduced here at full level, std(s_el) is
// |s_el(d + n) - s_el(d - n)| / 2, each map from a coupled solve of d + n or d - n at the
// same moduli (the estimate: from superposition, s_d +- s_n).
TEST(ZoneUncertaintyTest, OneDrawGivesTheSensitivityMapsChangeUnderThatNoise) {
  TwoZoneBarAsMatrices bar;
  ASSERT_EQ(bar.matrices.elements.size(), 30u);
  const Vector moduli = (Vector(2) << 1.98e11, 2.03e11).finished();
  auto sensitivity_of = [&](const ChannelSet& set, CoupledSolution* solution) {
    MatrixMcreProblem problem(bar.matrices, set, bar.mcre.weights, bar.mcre.reference_modulus, 0.5,
                              Factorization::kAutomatic, bar.mcre.clamp);
    problem.SetModuli(moduli);
    EXPECT_TRUE(SolveCoupled(bar.inner, &problem, nullptr, solution).IsSolutionUsable());
    Vector sensitivity;
    problem.ElementSensitivities(solution->displacement, solution->retrograde, &sensitivity);
    return sensitivity;
  };
  CoupledSolution solution;
  sensitivity_of(bar.data, &solution);
  const NoiseLevels levels = DifferenceNoiseLevels(bar.data);
  const ZoneUncertainty estimate = OneDrawEstimate(bar, moduli, solution);
  ASSERT_TRUE(estimate.available) << estimate.message;
  ASSERT_EQ(estimate.sensitivity_std.size(), 30);

  ChannelSet plus = bar.data, minus = bar.data;
  StandardNormal normal(kDrawSeed);
  for (std::size_t c = 0; c < plus.channels.size(); ++c) {
    const double level = NoiseLevel(levels, plus.channels[c].kind);
    for (Eigen::Index j = 0; j < plus.channels[c].values.size(); ++j) {
      const double draw = level * normal();
      plus.channels[c].values[j] += draw;
      minus.channels[c].values[j] -= draw;
    }
  }
  CoupledSolution scratch;
  const Vector expected =
      0.5 * (sensitivity_of(plus, &scratch) - sensitivity_of(minus, &scratch)).cwiseAbs();
  // Relative to the largest: measured 3.5e-11 (the solves' tolerance 1e-12).
  EXPECT_LT((estimate.sensitivity_std - expected).cwiseAbs().maxCoeff(),
            4e-10 * expected.maxCoeff());
}

// A streaming solution (traces, no fields; the preconditioned CG of dense_traces) gives
// the stored-field solution's figure: dg from the plus and minus problems' maps at
// y_d +- y_n instead of their fields.
TEST(ZoneUncertaintyTest, AStreamingSolutionGivesTheStoredFieldFigure) {
  TwoZoneBarAsMatrices bar;
  const Vector moduli = (Vector(2) << 1.98e11, 2.03e11).finished();
  const NoiseLevels levels = DifferenceNoiseLevels(bar.data);
  UncertaintyOptions options;
  options.samples = 3;
  ZoneUncertainty estimates[2];
  for (int streamed = 0; streamed < 2; ++streamed) {
    CoupledSolverOptions inner = bar.inner;
    if (streamed == 1) {
      inner.type = CoupledSolverType::kStreamingConjugateGradient;
      inner.preconditioner = TracePreconditioner::kDenseTraces;
      inner.max_preconditioner_traces = 1 << 20;
    }
    MatrixMcreProblem problem(bar.matrices, bar.data, bar.mcre.weights, bar.mcre.reference_modulus,
                              0.5, Factorization::kAutomatic, bar.mcre.clamp);
    problem.SetModuli(moduli);
    CoupledSolution solution;
    ASSERT_TRUE(SolveCoupled(inner, &problem, nullptr, &solution).IsSolutionUsable());
    EXPECT_EQ(solution.has_fields(), streamed == 0);
    estimates[streamed] = EstimateZoneUncertainty(options, bar.matrices, bar.data, bar.mcre, 0.5,
                                                  inner, moduli, solution, levels);
    ASSERT_TRUE(estimates[streamed].available) << estimates[streamed].message;
  }
  // Measured 4.5e-12 and 4.5e-11 relative (the solves' tolerance 1e-12).
  for (int z = 0; z < 2; ++z) {
    EXPECT_NEAR(estimates[1].std_dev[z], estimates[0].std_dev[z], 4e-10 * estimates[0].std_dev[z])
        << z;
  }
  // The sensitivity map's std, relative to the largest: measured 2.2e-11.
  ASSERT_EQ(estimates[1].sensitivity_std.size(), 30);
  const Vector& stored = estimates[0].sensitivity_std;
  EXPECT_LT((estimates[1].sensitivity_std - stored).cwiseAbs().maxCoeff(),
            2e-10 * stored.maxCoeff());
}

TEST(ZoneUncertaintyTest, NoNoiseIsNotAFigure) {
  TwoZoneBarAsMatrices bar;
  const Vector moduli = Vector::Constant(2, 200e9);
  CoupledSolution solution;
  const ZoneUncertainty estimate =
      EstimateZoneUncertainty(UncertaintyOptions(), bar.matrices, bar.data, bar.mcre, 0.5,
                              bar.inner, moduli, solution, NoiseLevels());
  EXPECT_FALSE(estimate.available);
  EXPECT_EQ(estimate.message, "no noise to propagate (every noise level is 0)");
}

}  // namespace
}  // namespace mcrewave
