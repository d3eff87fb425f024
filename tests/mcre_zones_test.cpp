// Tests of the MCRE problem with zones and interior sensors (docs/zones_and_sensors.md):
// one zone and the end sensors give the paper's problem, every zone's adjoint gradient
// against central differences, the inverse crime, the error map, and every coupled
// solver that handles sensors against the all-at-once reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/simulation.h"
#include "reference/bar_mcre_problem.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

using testing::MakeSmallCase;
using testing::Options;
using testing::Solve;
using testing::Solved;
using testing::Weights;

// Interior sensors of the tests: displacements at 0.25 L and 0.5 L, strains at 0.2 L,
// 0.65 L and 0.9 L (off the nodes).
// (Named by their positions to 17 digits: the name gives the position back exactly.)
void AddSensorsAlong(const BarModel& model, int samples, ChannelSet* data) {
  const double length = model.properties().length;
  auto name = [](const char* prefix, double position) {
    std::ostringstream text;
    text << prefix << std::setprecision(17) << position;
    return text.str();
  };
  for (double x : {0.25, 0.5}) {
    data->Add(name("u@", x * length), ChannelKind::kDisplacement, Vector::Zero(samples));
  }
  for (double x : {0.2, 0.6549, 0.9013}) {
    data->Add(name("e@", x * length), ChannelKind::kStrain, Vector::Zero(samples));
  }
}

// The channels that H reads off the displacement field U, with seeded Gaussian noise of
// relative level `noise` (of each channel's RMS; 0: exact).
void ObserveField(const BarModel& model, const Matrix& displacement, double noise,
                  ChannelSet* data) {
  std::mt19937_64 engine(11);
  std::normal_distribution<double> normal;
  auto noisy = [&](Vector values) {
    const double rms = std::sqrt(values.squaredNorm() / values.size());
    for (Eigen::Index k = 0; k < values.size(); ++k) values[k] += noise * rms * normal(engine);
    return values;
  };
  data->Values("u0") = noisy(displacement.row(0).transpose());
  data->Values("uL") = noisy(displacement.row(model.num_nodes() - 1).transpose());
  for (const BarSensor& sensor : BarSensors(*data)) {
    const ObservationRow row = sensor.kind == SensorKind::kStrain
                                   ? model.StrainRow(sensor.position)
                                   : model.DisplacementRow(sensor.position);
    Vector values(displacement.cols());
    for (Eigen::Index j = 0; j < displacement.cols(); ++j) {
      values[j] = row.Apply(displacement.col(j).data());
    }
    data->channels[static_cast<std::size_t>(sensor.index)].values = noisy(values);
  }
}

// A small zoned bar, its data from the response of a zoned "truth" modulus field
// (the model's own discretisation, driven by the measured end forces of the paper's
// experiment), and an MCRE problem on it.
struct ZonedCase {
  ZonedCase(int elements, int steps, const ZoneLayout& layout, const Vector& truth_moduli,
            double noise, EndDisplacementChannels ends = {})
      : small(MakeSmallCase(elements, steps, std::numeric_limits<double>::infinity(), 1)),
        model(small.bar, layout.ElementZones(small.bar)),
        data(MakeSyntheticMeasurements(small.bar, small.load, small.time, small.data)) {
    AddSensorsAlong(model, data.num_samples(), &data);
    // The response of the truth to the measured forces: the direct sweep at W = 0.
    testing::BarMcreProblem truth(model, data, Weights(0.01, 1.0), 200e9, 0.5, ends);
    truth.SetModuli(truth_moduli);
    Matrix displacement;
    truth.DirectSweep(truth.ZeroField(), true, &displacement);
    ObserveField(model, displacement, noise, &data);
    problem = std::make_unique<testing::BarMcreProblem>(model, data, Weights(0.01, 1.0), 200e9, 0.5,
                                                        ends);
  }
  testing::SmallCase small;
  BarModel model;
  ChannelSet data;
  std::unique_ptr<testing::BarMcreProblem> problem;
};

ZoneLayout EqualZones(int count) {
  ZoneLayout layout;
  layout.zone_count = count;
  return layout;
}

// A soft zone over [0.6, 0.7] L (zone 6 of 10 equal zones) at 0.7 E.
Vector SoftZoneModuli(int zones) {
  Vector moduli = Vector::Constant(zones, 200e9);
  for (int z = 0; z < zones; ++z) {
    const double middle = (z + 0.5) / zones;
    if (middle > 0.6 && middle < 0.7) moduli[z] = 140e9;
  }
  return moduli;
}

TEST(McreZonesTest, DataResponseTracesAreTheDirectSweepAtZeroObservedByH) {
  // The streaming traces of the model driven by the data alone (one sweep, no field)
  // against H applied to the stored direct sweep at W = 0: measured the same bits.
  const ZonedCase zoned(20, 120, EqualZones(2), SoftZoneModuli(2), 0.01);
  testing::BarMcreProblem& problem = *zoned.problem;
  Matrix traces, displacement;
  problem.DataResponseTraces(&traces);
  problem.DirectSweep(problem.ZeroField(), true, &displacement);
  const std::vector<BarSensor> sensors = BarSensors(zoned.data);
  ASSERT_EQ(traces.rows(), 2 + static_cast<int>(sensors.size()));
  ASSERT_EQ(traces.cols(), displacement.cols());
  const int last = problem.num_nodes() - 1;
  for (Eigen::Index j = 0; j < traces.cols(); ++j) {
    EXPECT_EQ(traces(0, j), displacement(0, j)) << j;
    EXPECT_EQ(traces(1, j), displacement(last, j)) << j;
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      const BarSensor& sensor = sensors[k];
      const ObservationRow row = sensor.kind == SensorKind::kStrain
                                     ? zoned.model.StrainRow(sensor.position)
                                     : zoned.model.DisplacementRow(sensor.position);
      EXPECT_EQ(traces(2 + k, j), row.Apply(displacement.col(j).data()))
          << zoned.data.channels[static_cast<std::size_t>(sensor.index)].name << ", " << j;
    }
  }
  // The weights of the rows: beta_u at both ends, beta_u or beta_e per sensor.
  const Vector weights = problem.TraceWeights();
  EXPECT_EQ(weights[0], problem.beta());
  EXPECT_EQ(weights[1], problem.beta());
  EXPECT_EQ(weights[4], problem.strain_beta());
}

TEST(McreZonesTest, EqualZoneModuliGiveTheOneZoneProblem) {
  // The same data on a one-zone and a 10-zone model at equal moduli: e^2 and the
  // gradient agree; measured 0 (e^2: the same K bit for bit) and 3.5e-16 to 2.1e-15 (the
  // gradient summed by element instead of as a band form).
  ZonedCase zoned(40, 120, EqualZones(10), SoftZoneModuli(10), 0.05);
  const BarModel one_zone(zoned.small.bar);
  testing::BarMcreProblem reference(one_zone, zoned.data, Weights(0.01, 1.0), 200e9, 0.5);
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-12);
  for (double modulus : {180e9, 215e9}) {
    zoned.problem->SetModulus(modulus);
    reference.SetModulus(modulus);
    const Solved a = Solve(options, zoned.problem.get());
    const Solved b = Solve(options, &reference);
    ASSERT_TRUE(a.summary.IsSolutionUsable() && b.summary.IsSolutionUsable());
    EXPECT_NEAR(a.solution.cost, b.solution.cost, 1e-15 * b.solution.cost);
    ASSERT_EQ(a.solution.cost_gradients.size(), 10);
    ASSERT_EQ(b.solution.cost_gradients.size(), 1);
    EXPECT_NEAR(a.solution.cost_gradients.sum(), b.solution.cost_gradient,
                2e-14 * std::abs(b.solution.cost_gradient));
  }
}

class ZoneGradientTest : public ::testing::TestWithParam<int> {};

TEST_P(ZoneGradientTest, EveryZoneMatchesACentralDifference) {
  // 10 zones on 40 elements, and one zone per element on 100 elements; interior
  // displacement and strain sensors, 5 % noise, trial moduli away from the truth.
  const int elements = GetParam();
  ZoneLayout layout = EqualZones(10);
  if (elements == 100) layout.zoning = Zoning::kPerElement;
  const int zones = elements == 100 ? elements : 10;
  const ZonedCase zoned(elements, 2 * elements, layout, SoftZoneModuli(zones), 0.05);
  testing::BarMcreProblem& problem = *zoned.problem;
  ASSERT_EQ(problem.num_zones(), zones);
  Vector trial(zones);
  for (int z = 0; z < zones; ++z) trial[z] = 200e9 * (0.9 + 0.2 * std::sin(1.0 + 3.0 * z));
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-13);
  problem.SetModuli(trial);
  const Solved at_trial = Solve(options, &problem);
  ASSERT_TRUE(at_trial.summary.IsSolutionUsable()) << at_trial.summary.message;
  const Vector gradient = at_trial.solution.cost_gradients;
  double worst = 0.0;
  for (int z = 0; z < zones; z += (zones > 10 ? 7 : 1)) {
    const double step = 1e-4 * trial[z];
    Vector plus = trial, minus = trial;
    plus[z] += step;
    minus[z] -= step;
    problem.SetModuli(plus);
    const double cost_plus = Solve(options, &problem, &at_trial.solution.retrograde).solution.cost;
    problem.SetModuli(minus);
    const double cost_minus = Solve(options, &problem, &at_trial.solution.retrograde).solution.cost;
    const double difference = (cost_plus - cost_minus) / (2.0 * step);
    // Relative to the largest component: small zones' gradients are differences of
    // large terms.
    worst = std::max(worst, std::abs(gradient[z] - difference) / gradient.cwiseAbs().maxCoeff());
  }
  // Measured: 1.0e-7 (10 zones), 2.3e-9 (100 zones, every 7th zone checked).
  EXPECT_LT(worst, zones == 10 ? 1e-6 : 2e-8) << zones << " zones";
}

INSTANTIATE_TEST_SUITE_P(TenZonesAndPerElement, ZoneGradientTest, ::testing::Values(40, 100));

TEST(McreZonesTest, InverseCrimeCostVanishesAtTheTruthOnly) {
  // Noise-free data of the model itself: e^2 vanishes at the truth's moduli (measured
  // exactly 0: the data are the sweep's own response, so the solve from W = 0 stops at
  // once) and not at a 5 % error of the soft zone alone.
  ZonedCase zoned(40, 120, EqualZones(10), SoftZoneModuli(10), 0.0);
  const CoupledSolverOptions options = Options(CoupledSolverType::kConjugateGradient, 1e-12);
  zoned.problem->SetModuli(SoftZoneModuli(10));
  const double at_truth = Solve(options, zoned.problem.get()).solution.cost;
  Vector off = SoftZoneModuli(10);
  off[6] *= 1.05;
  zoned.problem->SetModuli(off);
  const double nearby = Solve(options, zoned.problem.get()).solution.cost;
  EXPECT_GT(nearby, 0.0);
  EXPECT_LT(at_truth, 1e-25 * nearby);
}

TEST(McreZonesTest, ErrorMapSharesTheConstitutivePartAndPointsAtTheSoftZone) {
  // At the homogeneous E of the truth's background, the gap concentrates where the
  // modulus is wrong: the map's largest element lies in the soft zone [0.6, 0.7] L.
  ZonedCase zoned(50, 150, EqualZones(1), Vector::Constant(1, 200e9), 0.0);
  // Data of a soft zone over [0.6, 0.7] L: a per-element truth on the same mesh.
  ZoneLayout per_element;
  per_element.zoning = Zoning::kPerElement;
  const BarModel truth_model(zoned.small.bar, per_element.ElementZones(zoned.small.bar));
  testing::BarMcreProblem truth(truth_model, zoned.data, Weights(0.01, 1.0), 200e9, 0.5);
  Vector truth_moduli = Vector::Constant(50, 200e9);
  truth_moduli.segment(30, 5).setConstant(140e9);
  truth.SetModuli(truth_moduli);
  Matrix displacement;
  truth.DirectSweep(truth.ZeroField(), true, &displacement);
  ObserveField(truth_model, displacement, 0.0, &zoned.data);
  testing::BarMcreProblem problem(zoned.model, zoned.data, Weights(0.01, 1.0), 200e9, 0.5);
  problem.SetModulus(200e9);
  const Solved solved = Solve(Options(CoupledSolverType::kConjugateGradient, 1e-10), &problem);
  ASSERT_TRUE(solved.summary.IsSolutionUsable());
  const Vector map = problem.ErrorMap(solved.solution.retrograde);
  ASSERT_EQ(map.size(), 50);
  EXPECT_GE(map.minCoeff(), 0.0);
  // The sum is the constitutive part 1/2 sum_j c_j h W_j^T K W_j.
  double constitutive = 0.0;
  const SparseMatrix stiffness = zoned.model.Stiffness(200e9);
  for (int j = 0; j <= problem.num_steps(); ++j) {
    const Vector w = solved.solution.retrograde.col(j);
    constitutive += problem.QuadratureWeight(j) * problem.time_step() * 0.5 * w.dot(stiffness * w);
  }
  // Measured 3.6e-16.
  EXPECT_NEAR(map.sum(), constitutive, 4e-15 * constitutive);
  Eigen::Index peak = 0;
  map.maxCoeff(&peak);
  EXPECT_GE(peak, 30);
  EXPECT_LT(peak, 35);
}

struct SensorCase {
  const char* name;
  EndDisplacementChannels ends;
  CoupledSolverType type;
};

class SensorSolverTest : public ::testing::TestWithParam<SensorCase> {};

TEST_P(SensorSolverTest, AgreesWithAllAtOnce) {
  // 4 zones, interior sensors, 5 % noise, trial moduli off the truth: each iterative
  // solver against the space-time LU. Measured at most 1.5e-12 in U, 8.4e-11 in W,
  // 4.4e-15 in e^2 and 7.2e-11 in the zone gradients (adaptive relaxation the largest).
  const SensorCase& param = GetParam();
  ZonedCase zoned(16, 60, EqualZones(4), Vector::Constant(4, 200e9), 0.05, param.ends);
  testing::BarMcreProblem& problem = *zoned.problem;
  Vector trial(4);
  trial << 190e9, 230e9, 150e9, 210e9;
  problem.SetModuli(trial);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-10), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.message;
  const Solved solved = Solve(Options(param.type, 1e-12), &problem);
  ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
  const testing::Agreement agreement = testing::Compare(solved, reference);
  EXPECT_LT(agreement.displacement, 2e-11);
  EXPECT_LT(agreement.retrograde, 1e-9);
  EXPECT_LT(agreement.cost, 5e-14);
  EXPECT_LT((solved.solution.cost_gradients - reference.solution.cost_gradients).norm(),
            1e-9 * reference.solution.cost_gradients.norm());
}

INSTANTIATE_TEST_SUITE_P(
    Sensors, SensorSolverTest,
    ::testing::Values(
        SensorCase{
            "BothEndsConjugateGradient", {true, true}, CoupledSolverType::kConjugateGradient},
        SensorCase{"NoU0ConjugateGradient", {false, true}, CoupledSolverType::kConjugateGradient},
        SensorCase{
            "BothEndsAdaptiveRelaxation", {true, true}, CoupledSolverType::kAdaptiveRelaxation}),
    [](const ::testing::TestParamInfo<SensorCase>& info) { return std::string(info.param.name); });

TEST(McreZonesTest, BatchedRetrogradeSweepsWithSensorsMatchTheSingleSweepsExactly) {
  // The coupled solvers start with batched sweeps: with interior sensors their point
  // loads must be those of the single sweeps, bit for bit, zero inputs included.
  ZonedCase zoned(17, 50, EqualZones(3), Vector::Constant(3, 200e9), 0.05);
  testing::BarMcreProblem& problem = *zoned.problem;
  Vector trial(3);
  trial << 190e9, 230e9, 150e9;
  problem.SetModuli(trial);
  Matrix u1, u2, expected;
  problem.DirectSweep(problem.ZeroField(), true, &u1);
  problem.DirectSweep(0.5 * u1, true, &u2);
  Matrix r1, r2, r3;
  problem.RetrogradeSweepsWithData({&u1, nullptr, &u2}, {&r1, &r2, &r3});
  problem.RetrogradeSweep(u1, true, &expected);
  EXPECT_EQ((r1 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.RetrogradeSweep(problem.ZeroField(), true, &expected);
  EXPECT_EQ((r2 - expected).cwiseAbs().maxCoeff(), 0.0);
  problem.RetrogradeSweep(u2, true, &expected);
  EXPECT_EQ((r3 - expected).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(r3.cwiseAbs().maxCoeff(), 0.0);
}

TEST(McreZonesTest, RiccatiAndShootingSolveZonedBarsWithEndSensors) {
  // The comparators take K from the zone moduli: 3 zones, end sensors only, against
  // the space-time LU. Measured at most 5.4e-15 in e^2 and 2.8e-14 in W (Riccati; the
  // shootings 4.4e-16 and 6.6e-15).
  ZonedCase zoned(12, 40, EqualZones(3), Vector::Constant(3, 200e9), 0.05);
  // Without the interior channels (u@X, e@X).
  std::vector<Channel>& channels = zoned.data.channels;
  channels.erase(
      std::remove_if(channels.begin(), channels.end(),
                     [](const Channel& c) { return c.name.find('@') != std::string::npos; }),
      channels.end());
  testing::BarMcreProblem problem(zoned.model, zoned.data, Weights(0.01, 1.0), 200e9, 0.5);
  Vector trial(3);
  trial << 190e9, 230e9, 150e9;
  problem.SetModuli(trial);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-10), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.message;
  for (CoupledSolverType type : {CoupledSolverType::kRiccati, CoupledSolverType::kSingleShooting,
                                 CoupledSolverType::kMultipleShooting}) {
    const Solved solved = Solve(Options(type, 1e-10), &problem);
    ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
    const testing::Agreement agreement = testing::Compare(solved, reference);
    EXPECT_LT(agreement.cost, 5e-14) << CoupledSolverTypeToString(type);
    EXPECT_LT(agreement.retrograde, 3e-13) << CoupledSolverTypeToString(type);
  }
}

TEST(McreZonesTest, RiccatiAndShootingSolveBarsWithInteriorSensors) {
  // They refused interior sensors until they took the general data term W_obs =
  // H^T diag(beta) H (docs/riccati_shooting.md). Measured against the space-time LU:
  // e^2 1.8e-15, W 1.1e-14 (Riccati), e^2 3.1e-15, W 4.0e-14 (both shootings).
  ZonedCase zoned(10, 30, EqualZones(1), Vector::Constant(1, 200e9), 0.0);
  testing::BarMcreProblem& problem = *zoned.problem;
  ASSERT_GT(problem.num_interior_sensors(), 0);
  problem.SetModulus(180e9);
  const Solved reference = Solve(Options(CoupledSolverType::kAllAtOnce, 1e-10), &problem);
  ASSERT_TRUE(reference.summary.IsSolutionUsable()) << reference.summary.message;
  for (CoupledSolverType type : {CoupledSolverType::kRiccati, CoupledSolverType::kSingleShooting,
                                 CoupledSolverType::kMultipleShooting}) {
    const Solved solved = Solve(Options(type, 1e-10), &problem);
    ASSERT_TRUE(solved.summary.IsSolutionUsable()) << solved.summary.message;
    const testing::Agreement agreement = testing::Compare(solved, reference);
    std::cout << CoupledSolverTypeToString(type) << " vs all_at_once, interior sensors: e^2 "
              << agreement.cost << ", W " << agreement.retrograde << "\n";
    EXPECT_LT(agreement.cost, 3e-14) << CoupledSolverTypeToString(type);
    EXPECT_LT(agreement.retrograde, 4e-13) << CoupledSolverTypeToString(type);
  }
}

}  // namespace
}  // namespace mcrewave
