// Tests of OutputErrorModulusObjective and of the Fisher information of
// MatrixOutputErrorObjective: on the bar as matrices (BarRunModel) the one-modulus
// objective gives the bar's own band-model least squares (tests/reference/
// bar_least_squares.h, another code path: the clamped band model, its reaction from the
// clamp's row) in J, dJ/dE, the Fisher information, the outputs and the valley
// spacing; the inverse crime (data simulated by model/simulation.h, an independent code
// path) gives J = 0 at the data's E and predictions equal to the data, and the outer
// loop finds that E with NLopt and Ceres; the gradient against central differences of
// J, with and without interior sensors and for backward Euler; the Fisher information
// of one modulus and the Fisher matrix of three zones are the Gauss-Newton sums of
// central differences of the outputs and the reaction; a clone computes the same bits;
// a trial modulus that is not positive is refused.
#include "mcrewave/least_squares/output_error_modulus_objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mcrewave/data/noise.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/identification.h"
#include "reference/bar_least_squares.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

// A 30-element bar of modulus E [Pa] with interior sensors, its clamped simulation on
// its own mesh and step with noise at snr (seed 11), misfit levels of every kind, and
// the bar as matrices of the run. The default: 200 GPa, a displacement and a strain
// sensor, SNR 20.
struct SensedBar {
  explicit SensedBar(double modulus = 200e9,
                     const std::vector<std::string>& sensors = {"u@0.3", "e@0.55"},
                     double snr = 20.0)
      : small([modulus] {
          testing::SmallCase small = testing::MakeSmallCase(30, 250, INFINITY, 1);
          small.bar.modulus = modulus;
          return small;
        }()),
        model(small.bar),
        data(SimulateClampedBar(small.bar, small.load, small.time, {}, sensors)) {
    AddMeasurementNoise(snr, 11, &data);
    noise.displacement_std = 1e-6;  // [m]
    noise.force_std = 10.0;         // [N]
    noise.strain_std = 1e-6;
    matrices = BarRunModel(model, data, {});
  }
  testing::SmallCase small;
  BarModel model;
  ChannelSet data;
  NoiseLevels noise;
  MatrixModelData matrices;
};

TEST(OutputErrorModulusObjectiveTest, OnTheBarAsMatricesItIsTheBarsOwnObjective) {
  const SensedBar bar;
  OutputErrorModulusObjective general(bar.matrices, bar.data, bar.noise, 0.5, 200e9);
  testing::BarLeastSquares own(bar.model, bar.data, bar.noise, 0.5, 200e9);
  EXPECT_NEAR(general.rest_cost(), own.rest_cost(), 1e-14 * own.rest_cost());
  // The rows of the outputs: uL, then the sensors in the data's order.
  ASSERT_EQ(bar.matrices.sensors.size(), 3u);
  ASSERT_EQ(bar.matrices.sensors[0].channel, "uL");
  for (const double modulus : {170e9, 200e9, 236e9}) {
    const OutputErrorFit fit = general.Predict(modulus, true);
    const testing::OutputErrorPrediction& prediction = own.Predict(modulus, true);
    // Measured over the three moduli, relative: J 4.4e-14, dJ/dE 2.2e-13, I 7.6e-15
    // apart; uL 2.4e-15, f0 1.5e-14 and the sensors 2.0e-14 of their norms.
    EXPECT_NEAR(fit.cost, prediction.cost, 4e-13 * prediction.cost) << modulus;
    EXPECT_NEAR(fit.cost_gradient, prediction.cost_gradient,
                2e-12 * std::abs(prediction.cost_gradient))
        << modulus;
    EXPECT_NEAR(fit.fisher_information, prediction.fisher_information,
                8e-14 * prediction.fisher_information)
        << modulus;
    const Vector uL = fit.outputs.row(0).transpose();
    const Vector f0 = fit.support_forces.row(0).transpose();
    EXPECT_LT((uL - prediction.uL).norm(), 3e-14 * prediction.uL.norm()) << modulus;
    EXPECT_LT((f0 - prediction.f0).norm(), 2e-13 * prediction.f0.norm()) << modulus;
    for (int k = 0; k < 2; ++k) {
      const Vector sensor = fit.outputs.row(1 + k).transpose();
      EXPECT_LT((sensor - prediction.sensors[k]).norm(), 2e-13 * prediction.sensors[k].norm())
          << modulus << " sensor " << k;
    }
    // The optimisers' face: cost J / J_rest, d cost / dx = dJ/dE E_scale / J_rest.
    const double x = modulus / 200e9;
    double cost = 0.0, gradient = 0.0;
    ASSERT_TRUE(general.Evaluate(&x, &cost, &gradient)) << general.error_message();
    EXPECT_EQ(cost, fit.cost / general.cost_scale());
    EXPECT_EQ(gradient, fit.cost_gradient * 200e9 / general.cost_scale());
  }
  // Measured 6.2e-14 relative (the channels summed in another order).
  EXPECT_NEAR(general.ValleySpacing(), own.ValleySpacing(), 6e-13 * own.ValleySpacing());
}

constexpr double kCrimeModulus = 187.3e9;  // [Pa] of the simulated data (off the scan's grid)

TEST(OutputErrorModulusObjectiveTest, DataOfTheSameModelGiveZeroMisfitAtTheirModulus) {
  const SensedBar crime(kCrimeModulus, {"u@0.3", "e@0.55"}, INFINITY);
  OutputErrorModulusObjective objective(crime.matrices, crime.data, crime.noise, 0.5,
                                        kCrimeModulus);
  const OutputErrorFit fit = objective.Predict(kCrimeModulus, true);
  // The outputs' rows: uL, then the sensors in the data's order; f0 the clamp's.
  ASSERT_EQ(fit.outputs.rows(), 3);
  ASSERT_EQ(fit.support_forces.rows(), 1);
  const std::vector<std::string> channels = {"uL", "u@0.3", "e@0.55"};
  for (int i = 0; i < 3; ++i) {
    const Vector& measured = crime.data.Values(channels[static_cast<std::size_t>(i)]);
    const Vector predicted = fit.outputs.row(i).transpose();
    // Measured 4.9e-15 (uL), 2.5e-15 (u@0.3) and 3.3e-14 (e@0.55) of the peaks:
    // another code path than the simulation's (the load through G, the rows).
    EXPECT_LT((predicted - measured).lpNorm<Eigen::Infinity>(),
              3e-13 * measured.lpNorm<Eigen::Infinity>())
        << channels[static_cast<std::size_t>(i)];
  }
  const Vector f0 = fit.support_forces.row(0).transpose();
  // Measured 2.1e-14 of the peak.
  EXPECT_LT((f0 - crime.data.Values("f0")).lpNorm<Eigen::Infinity>(),
            2e-13 * crime.data.Values("f0").lpNorm<Eigen::Infinity>());
  // J / J_rest: measured 1.0e-28.
  EXPECT_LE(fit.cost / objective.rest_cost(), 1e-27);
  // At the minimum the gradient is round-off (measured 5.9e-16 of the gradient 5 %
  // away); there it is not.
  const double far_gradient = objective.Predict(1.05 * kCrimeModulus, true).cost_gradient;
  EXPECT_GT(far_gradient, 0.0);
  EXPECT_LE(std::abs(fit.cost_gradient), 6e-15 * far_gradient);
}

// Relative error of dJ/dE at E against the central difference of J with step 1e-6 E.
double ModulusGradientError(OutputErrorModulusObjective* objective, double modulus) {
  const double step = 1e-6 * modulus;
  const double gradient = objective->Predict(modulus, true).cost_gradient;
  const double above = objective->Predict(modulus + step, false).cost;
  const double below = objective->Predict(modulus - step, false).cost;
  return std::abs(gradient - (above - below) / (2.0 * step)) / std::abs(gradient);
}

TEST(OutputErrorModulusObjectiveTest, GradientMatchesCentralDifferences) {
  const SensedBar ends_only(kCrimeModulus, {}, 10.0);
  OutputErrorModulusObjective objective(ends_only.matrices, ends_only.data, ends_only.noise, 0.5,
                                        kCrimeModulus);
  // Measured 9.7e-11 to 1.2e-9 (the difference's truncation and round-off).
  for (const double factor : {0.8, 0.97, 1.1}) {
    EXPECT_LT(ModulusGradientError(&objective, factor * kCrimeModulus), 1e-8) << factor;
  }
  const SensedBar sensors(kCrimeModulus, {"u@0.3", "e@0.55", "u@0.9"}, 10.0);
  OutputErrorModulusObjective with_sensors(sensors.matrices, sensors.data, sensors.noise, 0.5,
                                           kCrimeModulus);
  for (const double factor : {0.8, 1.1}) {
    EXPECT_LT(ModulusGradientError(&with_sensors, factor * kCrimeModulus), 1e-8) << factor;
  }
  // Backward Euler: the sensitivity follows the scheme, whatever theta.
  OutputErrorModulusObjective implicit(ends_only.matrices, ends_only.data, ends_only.noise, 1.0,
                                       kCrimeModulus);
  EXPECT_LT(ModulusGradientError(&implicit, 0.9 * kCrimeModulus), 1e-8);
}

TEST(OutputErrorModulusObjectiveTest, NloptAndCeresFindTheModulusOfNoiseFreeData) {
  const SensedBar crime(kCrimeModulus, {}, INFINITY);
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    IdentificationOptions options;
    options.optimizer = optimizer;
    options.relative_tolerance = 1e-10;
    OutputErrorModulusObjective objective(crime.matrices, crime.data, crime.noise, 0.5,
                                          options.initial);
    const IdentificationSummary summary = Identify(options, &objective);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    // Measured 1.8e-11 (NLopt's default, the secant, which stops on a step below the
    // 1e-10 asked) and 4.4e-16 (Ceres).
    EXPECT_NEAR(summary.modulus / kCrimeModulus, 1.0,
                optimizer == OptimizerType::kNlopt ? 1e-10 : 3e-15)
        << summary.FullReport();
  }
}

TEST(OutputErrorModulusObjectiveTest, FisherInformationIsTheGaussNewtonSumOfCentralDifferences) {
  // I = sum_k c_k sum (dy_k/dE)^2 / s^2 from the forward sensitivity against the same
  // sum of central differences of the predicted outputs and reaction (step 1e-6 E):
  // measured 6.0e-10 relative.
  const SensedBar crime(kCrimeModulus, {"u@0.3", "e@0.55"}, 20.0);
  OutputErrorModulusObjective objective(crime.matrices, crime.data, crime.noise, 0.5,
                                        kCrimeModulus);
  const double modulus = 1.03 * kCrimeModulus;
  const double information = objective.Predict(modulus, true).fisher_information;
  const double step = 1e-6 * modulus;
  const OutputErrorFit plus = objective.Predict(modulus + step, false);
  const OutputErrorFit minus = objective.Predict(modulus - step, false);
  // The levels of the rows uL, u@0.3, e@0.55.
  const double levels[3] = {crime.noise.displacement_std, crime.noise.displacement_std,
                            crime.noise.strain_std};
  double sum = 0.0;
  const int samples = crime.data.num_samples();
  for (int k = 0; k < samples; ++k) {
    const double c = (k == 0 || k == samples - 1) ? 0.5 : 1.0;
    auto term = [&](double up, double down, double level) {
      const double derivative = (up - down) / (2.0 * step);
      return derivative * derivative / (level * level);
    };
    double channels =
        term(plus.support_forces(0, k), minus.support_forces(0, k), crime.noise.force_std);
    for (int i = 0; i < 3; ++i)
      channels += term(plus.outputs(i, k), minus.outputs(i, k), levels[i]);
    sum += c * channels;
  }
  EXPECT_GT(information, 0.0);
  EXPECT_NEAR(information / sum, 1.0, 5e-9) << information << " against " << sum;
}

TEST(OutputErrorModulusObjectiveTest, ACloneComputesTheSameBitsAndABadModulusIsRefused) {
  const SensedBar bar;
  OutputErrorModulusObjective objective(bar.matrices, bar.data, bar.noise, 0.5, 200e9);
  const std::unique_ptr<ModulusObjective> clone = objective.CloneForScan(1e-8);
  ASSERT_NE(clone, nullptr);
  const double x = 0.93;
  double cost = 0.0, gradient = 0.0, clone_cost = 0.0, clone_gradient = 0.0;
  ASSERT_TRUE(objective.Evaluate(&x, &cost, &gradient));
  ASSERT_TRUE(clone->Evaluate(&x, &clone_cost, &clone_gradient));
  EXPECT_EQ(cost, clone_cost);
  EXPECT_EQ(gradient, clone_gradient);
  EXPECT_EQ(objective.sweeps(), 2);  // one simulation and one sensitivity sweep
  const double negative = -0.5;
  EXPECT_FALSE(objective.Evaluate(&negative, &cost, nullptr));
  EXPECT_FALSE(objective.error_message().empty());
}

// On a bar in 6 zones (the homogeneous stage of a zone identification), dJ/dE by the
// adjoint (2 sweeps) against the forward sensitivities (1 + 6), and a clone of the
// adjoint's objective computes its bits.
TEST(OutputErrorModulusObjectiveTest, TheAdjointsGradientIsTheSensitivitiesAndClonesKeepIt) {
  const SensedBar bar;
  ZoneLayout layout;
  layout.zone_count = 6;
  const MatrixModelData zoned =
      BarRunModel(BarModel(bar.small.bar, layout.ElementZones(bar.small.bar)), bar.data, {});
  OutputErrorModulusObjective forward(zoned, bar.data, bar.noise, 0.5, 200e9);
  OutputErrorModulusObjective adjoint(zoned, bar.data, bar.noise, 0.5, 200e9);
  adjoint.SetGradientMethod(LeastSquaresGradient::kAdjoint);
  const double x = 0.93;
  double cost = 0.0, gradient = 0.0, adjoint_cost = 0.0, adjoint_gradient = 0.0;
  ASSERT_TRUE(forward.Evaluate(&x, &cost, &gradient));
  ASSERT_TRUE(adjoint.Evaluate(&x, &adjoint_cost, &adjoint_gradient));
  EXPECT_EQ(cost, adjoint_cost);
  // Measured 8.9e-16 apart, relative.
  EXPECT_NEAR(adjoint_gradient, gradient, 1e-14 * std::abs(gradient));
  EXPECT_EQ(forward.sweeps(), 1 + 6);
  EXPECT_EQ(adjoint.sweeps(), 2);
  const std::unique_ptr<ModulusObjective> clone = adjoint.CloneForScan(1e-8);
  double clone_cost = 0.0, clone_gradient = 0.0;
  ASSERT_TRUE(clone->Evaluate(&x, &clone_cost, &clone_gradient));
  EXPECT_EQ(clone_cost, adjoint_cost);
  EXPECT_EQ(clone_gradient, adjoint_gradient);
  EXPECT_EQ(clone->sweeps(), 2);
}

TEST(MatrixOutputErrorObjectiveTest, TheFisherMatrixIsTheGaussNewtonSumOfCentralDifferences) {
  // Three zones of the sensed bar, its clamp held (a reaction output): I_zz' from the
  // forward sensitivities against sum_j c_j [sum_k w_k dy_k/dE_z dy_k/dE_z'
  // + w_f dr/dE_z dr/dE_z'] with central differences of the outputs and the reaction
  // (step 1e-6 E_z).
  const SensedBar bar;
  ZoneLayout layout;
  layout.zone_count = 3;
  const BarModel zoned(bar.small.bar, layout.ElementZones(bar.small.bar));
  const MatrixModelData matrices = BarRunModel(zoned, bar.data, {});
  MatrixOutputErrorObjective objective(matrices, bar.data, bar.noise, 0.5);
  const Vector moduli = (Vector(3) << 190e9, 214e9, 201e9).finished();
  Vector gradient;
  Matrix information;
  objective.Cost(moduli, &gradient, &information);
  ASSERT_EQ(information.rows(), 3);
  ASSERT_EQ(information.cols(), 3);
  const int samples = bar.data.num_samples();
  std::vector<Matrix> output_rates, force_rates;
  for (int z = 0; z < 3; ++z) {
    const double step = 1e-6 * moduli[z];
    Vector plus = moduli, minus = moduli;
    plus[z] += step;
    minus[z] -= step;
    objective.Cost(plus, nullptr);
    const Matrix outputs_plus = objective.outputs(), forces_plus = objective.support_forces();
    objective.Cost(minus, nullptr);
    output_rates.push_back((outputs_plus - objective.outputs()) / (2.0 * step));
    force_rates.push_back((forces_plus - objective.support_forces()) / (2.0 * step));
  }
  const double force_weight = 1.0 / (bar.noise.force_std * bar.noise.force_std);
  Matrix differences = Matrix::Zero(3, 3);
  for (int j = 0; j < samples; ++j) {
    const double c = (j == 0 || j == samples - 1) ? 0.5 : 1.0;
    for (int z = 0; z < 3; ++z) {
      for (int y = 0; y < 3; ++y) {
        differences(z, y) += c * (output_rates[z].col(j).cwiseProduct(objective.sensor_weights()))
                                     .dot(output_rates[y].col(j)) +
                             c * force_weight * force_rates[z].col(j).dot(force_rates[y].col(j));
      }
    }
  }
  // Measured: 7.1e-10 relative to the largest entry.
  EXPECT_LT((information - differences).cwiseAbs().maxCoeff(),
            7e-9 * differences.cwiseAbs().maxCoeff())
      << information << "\nagainst\n"
      << differences;
  EXPECT_LT((information - information.transpose()).norm(), 1e-14 * information.norm());
}

}  // namespace
}  // namespace mcrewave
