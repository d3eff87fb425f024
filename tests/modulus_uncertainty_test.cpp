// Tests of the uncertainty figure's pieces: the noise levels estimated from the
// data, the slope of de^2/dE, and the first-order standard deviation (linear in
// the noise level, unavailable without curvature or noise); then the figure
// against what it predicts, the spread of E identified over noise draws.
#include "mcrewave/mcre/modulus_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/core/random.h"
#include "mcrewave/data/noise.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;

TEST(UncertaintyOptionsTest, SamplesAreChecked) {
  std::string why;
  UncertaintyOptions options;
  EXPECT_TRUE(options.IsValid(&why)) << why;
  options.samples = 1;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("uncertainty.samples"), std::string::npos) << why;
}

TEST(DifferenceNoiseLevelsTest, RecoversTheNoiseAddedToSmoothSignals) {
  // The paper's sampling: 1751 samples of a smooth signal, noise at SNR 5.
  testing::SmallCase c = MakeSmallCase(100, 1750, std::numeric_limits<double>::infinity(), 1);
  ChannelSet data = MakeSyntheticMeasurements(c.bar, c.load, c.time, c.data);
  const double displacement_std = RootMeanSquare(data.Values("uL")) / 5.0;
  const double force_std = RootMeanSquare(data.Values("fL")) / 5.0;
  AddMeasurementNoise(5.0, 11, &data);
  const NoiseLevels levels = DifferenceNoiseLevels(data);
  EXPECT_NEAR(levels.displacement_std, displacement_std, 0.05 * displacement_std);
  EXPECT_NEAR(levels.force_std, force_std, 0.05 * force_std);
}

TEST(CostGradientSlopeTest, FitsTheSlopeWithinTheWindow) {
  // g = 3e-30 (E - 2e11) inside +- 5 %, wild outside (must be ignored).
  std::vector<CostCurvePoint> curve;
  for (double modulus = 1.5e11; modulus <= 2.5e11; modulus += 0.05e11) {
    CostCurvePoint point;
    point.modulus = modulus;
    point.usable = true;
    point.cost_gradient = std::abs(modulus - 2e11) <= 0.1e11 ? 3e-30 * (modulus - 2e11) : 1.0;
    curve.push_back(point);
  }
  int points = 0;
  EXPECT_NEAR(CostGradientSlope(curve, 2e11, 0.05, &points), 3e-30, 1e-42);
  EXPECT_EQ(points, 5);
  std::vector<CostCurvePoint> one(1);
  one[0].usable = true;
  EXPECT_EQ(CostGradientSlope(one, 2e11, 0.05, &points), 0.0);
}

// At the minimum of e^2 for a small noisy case.
class ModulusUncertaintyTest : public ::testing::Test {
 protected:
  ModulusUncertaintyTest()
      : case_(MakeSmallCase(20, 120, 20.0, 2)),
        model_(case_.bar),
        data_(MakeSyntheticMeasurements(case_.bar, case_.load, case_.time, case_.data)),
        problem_(model_, data_, mcre_.weights, mcre_.reference_modulus, case_.time.theta, {},
                 mcre_.clamp),
        matrices_(BarMatrixModel(model_, case_.bar.modulus, {}, BarClampExport::kSupport)) {
    problem_.SetModulus(kModulus);
    SolveCoupled(CoupledSolverOptions(), &problem_, nullptr, &solution_);
  }

  // The figure on the bar exported as matrices, from the built-in bar's solution (the
  // same bits as the exported bar's: matrix_supports_test.cpp).
  ModulusUncertainty Estimate(const NoiseLevels& noise, double curvature) {
    UncertaintyOptions options;
    options.samples = 4;
    return EstimateModulusUncertainty(options, matrices_, data_, mcre_, case_.time.theta,
                                      CoupledSolverOptions(), kModulus, solution_, noise, curvature,
                                      5);
  }

  static constexpr double kModulus = 200e9;
  // The free-free formulation, which these figures were measured in.
  const McreOptions mcre_ = testing::FreeFreeMcre();
  testing::SmallCase case_;
  BarModel model_;
  ChannelSet data_;
  testing::BarMcreProblem problem_;
  MatrixModelData matrices_;
  CoupledSolution solution_;
};

TEST_F(ModulusUncertaintyTest, IsLinearInTheNoiseLevelAndInverseInTheCurvature) {
  const NoiseLevels noise{1e-7, 1.0};
  const ModulusUncertainty base = Estimate(noise, 1e-30);
  ASSERT_TRUE(base.available) << base.message;
  EXPECT_GT(base.std_dev, 0.0);
  EXPECT_EQ(base.samples, 4);
  EXPECT_GT(base.sweeps, 0);
  EXPECT_NEAR(base.relative_std_dev, base.std_dev / kModulus, 1e-15);
  // The same draws at twice the noise: dE is linear in the noise.
  const ModulusUncertainty doubled = Estimate(NoiseLevels{2e-7, 2.0}, 1e-30);
  EXPECT_NEAR(doubled.std_dev, 2.0 * base.std_dev, 1e-6 * base.std_dev);
  const ModulusUncertainty stiffer = Estimate(noise, 2e-30);
  EXPECT_NEAR(stiffer.std_dev, 0.5 * base.std_dev, 1e-9 * base.std_dev);
}

TEST(ModulusUncertaintyTrustedClampTest, TheFirstOrderChangeIsTheDifferenceOverDataPlusMinusNoise) {
  // With a trusted clamp de^2/dE holds the data f0~ itself (the reaction's explicit
  // term). The figure's dE = -dg_1 / k against dg_1 from two full solves on the data
  // d +- n of the same draws: g is a quadratic form of the data, so
  // (g(d + n) - g(d - n)) / 2 is its exact part linear in n.
  const testing::SmallCase small = MakeSmallCase(20, 120, 20.0, 2);
  const BarModel model(small.bar);
  const ChannelSet data = MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data);
  McreOptions mcre;
  mcre.clamp = ClampModel::kTrusted;
  mcre.weights = testing::Weights(0.01, 1.0);
  mcre.weights.reaction_weight = 0.01;
  CoupledSolverOptions inner;
  inner.tolerance = 1e-12;
  constexpr double kModulus = 200e9, kCurvature = 1e-30;
  testing::BarMcreProblem problem(model, data, mcre.weights, mcre.reference_modulus, 0.5, {},
                                  mcre.clamp);
  problem.SetModulus(kModulus);
  CoupledSolution solution;
  ASSERT_TRUE(SolveCoupled(inner, &problem, nullptr, &solution).IsSolutionUsable());
  UncertaintyOptions options;
  options.samples = 2;
  const NoiseLevels noise{1e-7, 1.0};
  const ModulusUncertainty figure = EstimateModulusUncertainty(
      options, BarMatrixModel(model, small.bar.modulus, {}, BarClampExport::kSupport), data, mcre,
      0.5, inner, kModulus, solution, noise, kCurvature, 5);
  ASSERT_TRUE(figure.available) << figure.message;

  // The same draws, in the same order (u0, uL, then f0, fL).
  StandardNormal normal(options.seed);
  double sum_of_squares = 0.0;
  for (int sample = 0; sample < options.samples; ++sample) {
    ChannelSet drawn = data;
    for (Vector* channel : {&drawn.Values("u0"), &drawn.Values("uL")}) {
      for (double& value : *channel) value = noise.displacement_std * normal();
    }
    for (Vector* channel : {&drawn.Values("f0"), &drawn.Values("fL")}) {
      for (double& value : *channel) value = noise.force_std * normal();
    }
    double gradient[2];
    for (int sign = 0; sign < 2; ++sign) {
      const double s = sign == 0 ? 1.0 : -1.0;
      ChannelSet shifted = data;
      shifted.Values("u0") += s * drawn.Values("u0");
      shifted.Values("uL") += s * drawn.Values("uL");
      shifted.Values("f0") += s * drawn.Values("f0");
      shifted.Values("fL") += s * drawn.Values("fL");
      testing::BarMcreProblem shifted_problem(model, shifted, mcre.weights, mcre.reference_modulus,
                                              0.5, {}, mcre.clamp);
      shifted_problem.SetModulus(kModulus);
      CoupledSolution shifted_solution;
      ASSERT_TRUE(
          SolveCoupled(inner, &shifted_problem, nullptr, &shifted_solution).IsSolutionUsable());
      gradient[sign] =
          shifted_problem.CostGradient(shifted_solution.displacement, shifted_solution.retrograde);
    }
    const double modulus_change = -0.5 * (gradient[0] - gradient[1]) / kCurvature;
    sum_of_squares += modulus_change * modulus_change;
  }
  const double expected = std::sqrt(sum_of_squares / options.samples);
  // Measured 3.8e-10 relative (the solves' tolerance 1e-12); an earlier figure whose
  // explicit data term missed two of its three parts was 12 % off.
  EXPECT_NEAR(figure.std_dev, expected, 4e-9 * expected);
}

TEST_F(ModulusUncertaintyTest, NotAvailableWithoutCurvatureOrNoise) {
  const ModulusUncertainty flat = Estimate(NoiseLevels{1e-7, 1.0}, 0.0);
  EXPECT_FALSE(flat.available);
  EXPECT_NE(flat.message.find("not convex"), std::string::npos) << flat.message;
  const ModulusUncertainty quiet = Estimate(NoiseLevels{0.0, 0.0}, 1e-30);
  EXPECT_FALSE(quiet.available);
  EXPECT_NE(quiet.message.find("no noise"), std::string::npos) << quiet.message;
}

TEST_F(ModulusUncertaintyTest, EndMisfitLevelsAreTheRmsEndMisfits) {
  // The model's end channels of the solution: U at both ends, F = F~ - W / alpha.
  const int last = model_.right_node();
  ChannelSet model;
  model.Add("u0", ChannelKind::kDisplacement, solution_.displacement.row(0).transpose());
  model.Add("uL", ChannelKind::kDisplacement, solution_.displacement.row(last).transpose());
  model.Add("f0", ChannelKind::kForce,
            data_.Values("f0") - solution_.retrograde.row(0).transpose() / problem_.alpha());
  model.Add("fL", ChannelKind::kForce,
            data_.Values("fL") - solution_.retrograde.row(last).transpose() / problem_.alpha());
  const NoiseLevels misfit = EndMisfitLevels(data_, model);
  double sum = 0.0, force_sum = 0.0;
  for (int j = 0; j < data_.num_samples(); ++j) {
    sum += std::pow(solution_.displacement(0, j) - data_.Values("u0")[j], 2) +
           std::pow(solution_.displacement(last, j) - data_.Values("uL")[j], 2);
    force_sum += std::pow(solution_.retrograde(0, j) / problem_.alpha(), 2) +
                 std::pow(solution_.retrograde(last, j) / problem_.alpha(), 2);
  }
  const double samples = 2.0 * data_.num_samples();
  EXPECT_NEAR(misfit.displacement_std, std::sqrt(sum / samples), 1e-12 * misfit.displacement_std);
  // F - F~ = -W / alpha, up to the round-off of F~ - W / alpha: measured 9.9e-15 apart.
  EXPECT_NEAR(misfit.force_std, std::sqrt(force_sum / samples), 1e-13 * misfit.force_std);
  EXPECT_GT(misfit.force_std, 0.0);
  // Without uL, the mean is over u0 alone.
  ChannelSet u0_only = model;
  u0_only.channels.erase(u0_only.channels.begin() + u0_only.Find("uL"));
  double u0_sum = 0.0;
  for (int j = 0; j < data_.num_samples(); ++j) {
    u0_sum += std::pow(solution_.displacement(0, j) - data_.Values("u0")[j], 2);
  }
  EXPECT_NEAR(EndMisfitLevels(data_, u0_only).displacement_std,
              std::sqrt(u0_sum / data_.num_samples()), 1e-12 * misfit.displacement_std);
}

}  // namespace
}  // namespace mcrewave

namespace mcrewave {
namespace {

TEST(ModulusUncertaintySpreadTest, MatchesTheSpreadOfEOverNoiseDraws) {
  // The quick case (25 elements, SNR 20), pre-filter off so that the identification
  // sees the white noise the figure assumes: E identified on 24 noise seeds, its
  // sample standard deviation against the mean uncertainty figure.
  std::vector<double> moduli, figures;
  for (int seed = 1; seed <= 24; ++seed) {
    const Config config =
        LoadConfig(testing::SourcePath("configs/quick.yaml"),
                   {"data.seed=" + std::to_string(seed), "prefilter.enabled=false",
                    "output.curve_points=11", "uncertainty.samples=8"});
    const IdentificationRun run = RunIdentification(config, LoadMeasurements(config));
    ASSERT_TRUE(run.IsUsable()) << run.outer.FullReport();
    ASSERT_TRUE(run.uncertainty.available) << run.uncertainty.message;
    moduli.push_back(run.identified_modulus());
    figures.push_back(run.uncertainty.std_dev);
  }
  double mean = 0.0, figure = 0.0;
  for (std::size_t i = 0; i < moduli.size(); ++i) {
    mean += moduli[i] / moduli.size();
    figure += figures[i] / figures.size();
  }
  double variance = 0.0;
  for (const double modulus : moduli) variance += (modulus - mean) * (modulus - mean);
  const double spread = std::sqrt(variance / (moduli.size() - 1));
  // The README's claim: within a factor 1.5. Measured: spread 0.407 %, mean figure
  // 0.356 %, ratio 0.87 (the sample deviation of 24 draws is itself known to 15 %).
  EXPECT_LT(figure / spread, 1.5);
  EXPECT_GT(figure / spread, 1.0 / 1.5);
}

}  // namespace
}  // namespace mcrewave
