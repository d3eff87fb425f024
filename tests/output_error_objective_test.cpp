// Tests of the output-error least-squares objective: the inverse crime (data
// simulated by model/simulation.h on the model's own mesh and step, an independent
// code path) gives J = 0 at the data's E and predictions equal to the data; the
// forward-sensitivity gradient against central differences of J, with and without
// interior sensors; the outer loop finds the data's E with NLopt and Ceres.
#include "mcrewave/least_squares/output_error_objective.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mcrewave/data/noise.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/identification.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

constexpr double kModulus = 187.3e9;  // [Pa] of the simulated data (off the scan's grid)

testing::SmallCase WithModulus(testing::SmallCase small) {
  small.bar.modulus = kModulus;
  return small;
}

struct InverseCrime {
  explicit InverseCrime(const std::vector<std::string>& sensors = {}, double snr = INFINITY)
      : small(WithModulus(testing::MakeSmallCase(30, 250, snr, 1))),
        model(small.bar),
        data(SimulateClampedBar(small.bar, small.load, small.time, {}, sensors)) {
    AddMeasurementNoise(snr, 11, &data);
    noise.displacement_std = 1e-6;  // [m]
    noise.force_std = 10.0;         // [N]
    noise.strain_std = 1e-6;
  }
  testing::SmallCase small;
  BarModel model;
  ChannelSet data;
  NoiseLevels noise;
};

TEST(OutputErrorObjectiveTest, DataOfTheSameModelGiveZeroMisfitAtTheirModulus) {
  const InverseCrime crime({"u@0.3", "e@0.55"});
  OutputErrorObjective objective(crime.model, crime.data, crime.noise, 0.5, kModulus);
  const OutputErrorPrediction& prediction = objective.Predict(kModulus, true);
  // Measured: uL, f0 and the sensors the same bits as the simulation's (the same
  // steps in the same order); 1e-15 of their peaks leaves room for another order.
  EXPECT_LE((prediction.uL - crime.data.Values("uL")).lpNorm<Eigen::Infinity>(),
            1e-15 * crime.data.Values("uL").lpNorm<Eigen::Infinity>());
  EXPECT_LE((prediction.f0 - crime.data.Values("f0")).lpNorm<Eigen::Infinity>(),
            1e-15 * crime.data.Values("f0").lpNorm<Eigen::Infinity>());
  const std::vector<BarSensor> sensors = BarSensors(crime.data);
  ASSERT_EQ(sensors.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Channel& channel = crime.data.channels[static_cast<std::size_t>(sensors[i].index)];
    EXPECT_LT((prediction.sensors[i] - channel.values).lpNorm<Eigen::Infinity>(),
              1e-15 * channel.values.lpNorm<Eigen::Infinity>())
        << channel.name;
  }
  // J / J_rest: measured 0; 1e-30 is (1e-15)^2.
  EXPECT_LE(prediction.cost / objective.rest_cost(), 1e-30);
  // At the minimum the gradient vanishes (measured 0); 5 % away it does not.
  const double far_gradient = objective.Predict(1.05 * kModulus, true).cost_gradient;
  EXPECT_GT(far_gradient, 0.0);
  EXPECT_LE(std::abs(objective.Predict(kModulus, true).cost_gradient), 1e-14 * far_gradient);
}

// Relative error of the gradient at E against the central difference of J with
// step 1e-6 E.
double GradientError(OutputErrorObjective* objective, double modulus) {
  const double step = 1e-6 * modulus;
  const double gradient = objective->Predict(modulus, true).cost_gradient;
  const double above = objective->Predict(modulus + step, false).cost;
  const double below = objective->Predict(modulus - step, false).cost;
  return std::abs(gradient - (above - below) / (2.0 * step)) / std::abs(gradient);
}

TEST(OutputErrorObjectiveTest, GradientMatchesCentralDifferences) {
  const InverseCrime ends_only({}, 10.0);
  OutputErrorObjective objective(ends_only.model, ends_only.data, ends_only.noise, 0.5, kModulus);
  // Measured 1e-10 to 1.1e-9 (the difference's truncation and round-off).
  for (const double factor : {0.8, 0.97, 1.1}) {
    EXPECT_LT(GradientError(&objective, factor * kModulus), 1e-8) << factor;
  }
  const InverseCrime sensors({"u@0.3", "e@0.55", "u@0.9"}, 10.0);
  OutputErrorObjective with_sensors(sensors.model, sensors.data, sensors.noise, 0.5, kModulus);
  for (const double factor : {0.8, 1.1}) {
    EXPECT_LT(GradientError(&with_sensors, factor * kModulus), 1e-8) << factor;
  }
  // Backward Euler: the sensitivity follows the scheme, whatever theta.
  OutputErrorObjective implicit(ends_only.model, ends_only.data, ends_only.noise, 1.0, kModulus);
  EXPECT_LT(GradientError(&implicit, 0.9 * kModulus), 1e-8);
}

TEST(OutputErrorObjectiveTest, NloptAndCeresFindTheModulusOfNoiseFreeData) {
  const InverseCrime crime;
  for (const OptimizerType optimizer : {OptimizerType::kNlopt, OptimizerType::kCeres}) {
    IdentificationOptions options;
    options.optimizer = optimizer;
    options.relative_tolerance = 1e-10;
    OutputErrorObjective objective(crime.model, crime.data, crime.noise, 0.5, options.initial);
    const IdentificationSummary summary = Identify(options, &objective);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    // Measured 3e-16 with both.
    EXPECT_NEAR(summary.modulus / kModulus, 1.0, 3e-15) << summary.FullReport();
  }
}

TEST(OutputErrorObjectiveTest, FisherInformationIsTheGaussNewtonSumOfCentralDifferences) {
  // I = sum_k c_k sum (dy_k/dE)^2 / s^2 from the forward sensitivity against the same
  // sum of central differences of the predicted outputs (step 1e-6 E): measured
  // 5.9e-10 relative.
  const InverseCrime crime({"u@0.3", "e@0.55"}, 20.0);
  OutputErrorObjective objective(crime.model, crime.data, crime.noise, 0.5, kModulus);
  const double modulus = 1.03 * kModulus;
  const double information = objective.Predict(modulus, true).fisher_information;
  const double step = 1e-6 * modulus;
  const OutputErrorPrediction plus = objective.Predict(modulus + step, false);
  const OutputErrorPrediction minus = objective.Predict(modulus - step, false);
  double sum = 0.0;
  const int samples = crime.data.num_samples();
  for (int k = 0; k < samples; ++k) {
    const double c = (k == 0 || k == samples - 1) ? 0.5 : 1.0;
    auto term = [&](double up, double down, double level) {
      const double derivative = (up - down) / (2.0 * step);
      return derivative * derivative / (level * level);
    };
    double channels = term(plus.uL[k], minus.uL[k], crime.noise.displacement_std) +
                      term(plus.f0[k], minus.f0[k], crime.noise.force_std);
    channels += term(plus.sensors[0][k], minus.sensors[0][k], crime.noise.displacement_std);
    channels += term(plus.sensors[1][k], minus.sensors[1][k], crime.noise.strain_std);
    sum += c * channels;
  }
  EXPECT_GT(information, 0.0);
  EXPECT_NEAR(information / sum, 1.0, 5e-9) << information << " against " << sum;
}

}  // namespace
}  // namespace mcrewave
