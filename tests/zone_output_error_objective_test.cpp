// Tests of the output-error least-squares objective with zones and of the zone
// identification on it: one zone against the scalar OutputErrorObjective (another
// code path: its sensitivity input -K z / E), the zones' gradient against central
// differences (10 zones, interior sensors, noisy data), and the inverse crime (data
// of model/simulation.h with the truth's zones on the model's mesh): J = 0 at the
// truth and every zone recovered by IdentifyZoneModuliByLeastSquares (on the bar as
// matrices, MatrixOutputErrorObjective).
#include "mcrewave/least_squares/zone_output_error_objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/data/noise.h"
#include "mcrewave/identification/zone_identification.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/least_squares/output_error_objective.h"
#include "mcrewave/model/simulation.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

constexpr int kZones = 10;

// 10 equal zones of a 30-element bar (3 elements each) whose data come from a truth
// with zone 6 ([0.6, 0.7] L) at 0.7 E and zone 2 at 1.1 E, with interior sensors.
struct ZonedCase {
  explicit ZonedCase(double snr,
                     std::vector<std::string> sensors = {"u@0.25", "u@0.5", "e@0.2", "e@0.65"})
      : small(testing::MakeSmallCase(30, 250, snr, 1)),
        model(small.bar,
              [&] {
                ZoneLayout layout;
                layout.zone_count = kZones;
                return layout.ElementZones(small.bar);
              }()),
        truth(Vector::Constant(kZones, small.bar.modulus)) {
    const double length = small.bar.length;
    truth[6] = 0.7 * small.bar.modulus;
    truth[2] = 1.1 * small.bar.modulus;
    const std::vector<ModulusZone> zones = {{0.2 * length, 0.3 * length, truth[2]},
                                            {0.6 * length, 0.7 * length, truth[6]}};
    data = SimulateClampedBar(small.bar, small.load, small.time, zones, sensors);
    AddMeasurementNoise(snr, 5, &data);
    noise.displacement_std = RootMeanSquare(data.Values("uL"));
    noise.force_std = RootMeanSquare(data.Values("fL"));
    noise.strain_std = 1e-6;
    matrices = BarRunModel(model, data, {});
  }
  testing::SmallCase small;
  BarModel model;
  MatrixModelData matrices;  // the zoned bar as matrices, the zone identification's
  Vector truth;
  ChannelSet data;
  NoiseLevels noise;
};

TEST(ZoneOutputErrorObjectiveTest, OneZoneIsTheScalarObjective) {
  const ZonedCase zoned(10.0);
  const BarModel uniform(zoned.small.bar);
  ZoneOutputErrorObjective zones(uniform, zoned.data, zoned.noise, 0.5, 200e9);
  OutputErrorObjective scalar(uniform, zoned.data, zoned.noise, 0.5, 200e9);
  EXPECT_EQ(zones.rest_cost(), scalar.rest_cost());
  for (const double modulus : {170e9, 200e9, 236e9}) {
    Vector gradient;
    const double cost = zones.Cost(Vector::Constant(1, modulus), &gradient);
    const OutputErrorPrediction& prediction = scalar.Predict(modulus, true);
    // Measured: J the same bits (the same steps in the same order), dJ/dE to 1e-15
    // (the sensitivity inputs -K1 z and -K (z / E) differ by round-off).
    EXPECT_EQ(cost, prediction.cost) << modulus;
    EXPECT_NEAR(gradient[0], prediction.cost_gradient, 1e-14 * std::abs(prediction.cost_gradient))
        << modulus;
  }
}

TEST(ZoneOutputErrorObjectiveTest, ZoneGradientsMatchCentralDifferences) {
  ZonedCase zoned(10.0);
  ZoneOutputErrorObjective objective(zoned.model, zoned.data, zoned.noise, 0.5, 200e9);
  Vector moduli(kZones);
  for (int z = 0; z < kZones; ++z) moduli[z] = 200e9 * (0.85 + 0.03 * z);
  Vector gradient;
  objective.Cost(moduli, &gradient);
  double worst = 0.0;
  for (int z = 0; z < kZones; ++z) {
    const double step = 1e-5 * moduli[z];
    Vector above = moduli, below = moduli;
    above[z] += step;
    below[z] -= step;
    const double difference =
        (objective.Cost(above, nullptr) - objective.Cost(below, nullptr)) / (2.0 * step);
    worst = std::max(worst, std::abs(gradient[z] - difference) / std::abs(gradient[z]));
  }
  // Every component to itself (the smallest is 0.049 of the largest): measured 5.1e-9
  // (the difference's truncation and round-off).
  EXPECT_LT(worst, 5e-8);
  EXPECT_EQ(objective.sweeps(), 1 + kZones + 2 * kZones);
}

TEST(ZoneOutputErrorObjectiveTest, EqualZonesSumToTheScalarGradient) {
  const ZonedCase zoned(20.0);
  ZoneOutputErrorObjective zones(zoned.model, zoned.data, zoned.noise, 0.5, 200e9);
  OutputErrorObjective scalar(BarModel(zoned.small.bar), zoned.data, zoned.noise, 0.5, 200e9);
  Vector gradient;
  const double cost = zones.Cost(Vector::Constant(kZones, 190e9), &gradient);
  const OutputErrorPrediction& prediction = scalar.Predict(190e9, true);
  // sum_z dJ/dE_z = dJ/dE at equal moduli. Measured: J the same bits, the sum to 1.4e-15.
  EXPECT_EQ(cost, prediction.cost);
  EXPECT_NEAR(gradient.sum(), prediction.cost_gradient, 1e-14 * std::abs(prediction.cost_gradient));
}

TEST(ZoneOutputErrorObjectiveTest, InverseCrimeRecoversEveryZone) {
  const ZonedCase zoned(std::numeric_limits<double>::infinity());
  ZoneOutputErrorObjective objective(zoned.model, zoned.data, zoned.noise, 0.5, 200e9);
  // The data of the truth's zones on the model's own mesh and step: J = 0 there
  // (measured 0: the simulation's steps in the same order) and not at the homogeneous
  // modulus (measured 0.117 J_rest).
  EXPECT_LE(objective.Cost(zoned.truth, nullptr), 1e-30 * objective.rest_cost());
  EXPECT_GT(objective.Cost(Vector::Constant(kZones, 200e9), nullptr), 1e-2 * objective.rest_cost());

  ZoneIdentificationOptions options;
  options.regularization.kind = RegularizationKind::kNone;
  const ZoneIdentificationSummary summary =
      IdentifyZoneModuliByLeastSquares(options, zoned.matrices, zoned.data, zoned.noise, 0.5, 195e9,
                                       100e9, 400e9, NoiseLevels(), PrefilterOptions{});
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  ASSERT_EQ(summary.moduli.size(), kZones);
  double worst = 0.0;
  for (int z = 0; z < kZones; ++z) {
    worst = std::max(worst, std::abs(summary.moduli[z] / zoned.truth[z] - 1.0));
  }
  // Measured 8.3e-10 (Ceres L-BFGS from 195 GPa, 31 evaluations).
  EXPECT_LT(worst, 1e-8);
  EXPECT_TRUE(summary.least_squares);
  MatrixOutputErrorObjective fresh(zoned.matrices, zoned.data, zoned.noise, 0.5);
  EXPECT_EQ(summary.homogeneous_cost, fresh.Cost(Vector::Constant(kZones, 195e9), nullptr));
  // One sweep for the cost at E*, then 1 (cost) or 1 + 10 (with the gradient) each.
  EXPECT_GE(summary.sweeps, 1 + summary.evaluations);
  EXPECT_LE(summary.sweeps, 1 + (1 + kZones) * summary.evaluations);
}

// The discrepancy target's J of noise alone is the mean J at the truth of noisy data:
// the model is linear in the load, so at the truth the clean part of the residual
// vanishes and J(truth; clean + noise) = J(noise alone), the load's noise driving the
// model. Two independent means over 400 draws each (AddMeasurementNoise's levels).
TEST(ZoneOutputErrorObjectiveTest, NoiseTargetIsTheMeanCostAtTheTruthOfNoisyData) {
  const ZonedCase zoned(std::numeric_limits<double>::infinity());
  constexpr double kSnr = 10.0;
  constexpr int kDraws = 400;
  NoiseLevels noise;
  noise.displacement_std = RootMeanSquare(zoned.data.Values("uL")) / kSnr;
  noise.force_std = RootMeanSquare(zoned.data.Values("fL")) / kSnr;
  double strain_squares = 0.0;
  int strain_samples = 0;
  for (const BarSensor& sensor : BarSensors(zoned.data)) {
    if (sensor.kind != SensorKind::kStrain) continue;
    const Vector& values = zoned.data.channels[static_cast<std::size_t>(sensor.index)].values;
    strain_squares += values.squaredNorm();
    strain_samples += static_cast<int>(values.size());
  }
  noise.strain_std = std::sqrt(strain_squares / strain_samples) / kSnr;
  const ZoneOutputErrorObjective clean(zoned.model, zoned.data, noise, 0.5, 200e9);
  const double scale = clean.cost_scale();
  PrefilterOptions no_prefilter;
  no_prefilter.enabled = false;
  const double target = ExpectedLeastSquaresNoiseCost(
      zoned.matrices, zoned.data, noise, 0.5, zoned.truth, noise, no_prefilter, kDraws, 1, scale);
  double mean = 0.0;
  for (int seed = 1; seed <= kDraws; ++seed) {
    ChannelSet noisy = zoned.data;
    AddMeasurementNoise(kSnr, 1000 + seed, &noisy);
    ZoneOutputErrorObjective objective(zoned.model, noisy, noise, 0.5, 200e9);
    mean += objective.Cost(zoned.truth, nullptr) / scale / kDraws;
  }
  // Measured: the two means 0.5 % apart (the target's J of the bar as matrices, the
  // mean's of this objective); the noisy data's mean without the load's
  // noise is 1.40 times smaller (the model driven by that noise is 29 % of J).
  EXPECT_NEAR(target / mean, 1.0, 0.03);
}

}  // namespace
}  // namespace mcrewave
