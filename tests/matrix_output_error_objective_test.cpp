// Tests of output-error least squares on a structure given by matrices
// (least_squares/matrix_output_error_objective.h): the clamped bar given as matrices
// against the bar's own band-model least squares (tests/reference/) on the same data,
// with zones and with one, and the bar exported with its clamp as a support (its
// reaction f0 an output) likewise; the supported lattice's gradient against central differences
// and, without mass coupling to its held dofs, its reaction against the trusted MCRE's; every
// zone's gradient of the coarse plate against a central difference; the adjoint's gradient
// against the forward sensitivities' on the zoned bar, the coarse plate and the supported
// lattice; the inverse crime on the coarse plate recovers both zones. On the run's bar
// (BarRunModel) with 10 zones and interior sensors: one zone and equal zones against the bar's
// scalar reference, the zones' gradient against central differences, the inverse crime recovered by
// IdentifyZoneModuliByLeastSquares, and its noise target against the mean J of noisy data.
#include "mcrewave/least_squares/matrix_output_error_objective.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/data/noise.h"
#include "mcrewave/identification/zone_identification.h"
#include "mcrewave/model/simulation.h"
#include "reference/bar_least_squares.h"
#include "reference/bar_zone_least_squares.h"
#include "test_problems.h"

namespace mcrewave {
namespace {

// The bar as the bar's least squares sees it, as matrices: BarMatrixModel (free-free,
// loads f0 and fL, rows u0, uL and the interior sensors) with node 0 removed from M,
// every K_z, the loads and the rows; the load f0 and the row u0 go with it. What is
// left is the clamped model of testing::BarLeastSquares driven by fL~ alone, its outputs
// uL and the interior sensors (whose node-0 coefficient the clamp drops).
MatrixModelData LsClampedBarMatrices(const BarModel& model, double nominal_modulus,
                                     const std::vector<BarSensor>& sensors) {
  const MatrixModelData full = BarMatrixModel(model, nominal_modulus, sensors);
  const int n = full.dofs() - 1;
  MatrixModelData clamped;
  clamped.mass = full.mass.bottomRightCorner(n, n);
  clamped.stiffness_length = full.stiffness_length;
  clamped.length = full.length;
  for (const MatrixModelZone& zone : full.zones) {
    clamped.zones.push_back(
        {zone.name, zone.stiffness.bottomRightCorner(n, n), zone.nominal_modulus});
  }
  for (const MatrixModelLoad& load : full.loads) {
    if (load.channel != "f0") clamped.loads.push_back({load.channel, load.vector.tail(n)});
  }
  for (const MatrixModelSensor& sensor : full.sensors) {
    if (sensor.channel != "u0") {
      clamped.sensors.push_back({sensor.channel, sensor.row.rightCols(n), sensor.kind});
    }
  }
  return clamped;
}

// A 30-element bar in 3 zones (10 elements each), data of the clamped simulation with
// zone 1 at 0.8 E, an interior displacement sensor and a gauge, SNR 10.
struct LsBarCase {
  LsBarCase()
      : small(testing::MakeSmallCase(30, 250, 10.0, 1)),
        zoned(small.bar,
              [] {
                std::vector<int> zones(30);
                for (int e = 0; e < 30; ++e) zones[e] = e / 10;
                return zones;
              }()),
        uniform(small.bar) {
    const double length = small.bar.length;
    const std::vector<ModulusZone> truth = {{length / 3.0, 2.0 * length / 3.0, 0.8 * 200e9}};
    data = SimulateClampedBar(small.bar, small.load, small.time, truth, {"u@0.25", "e@0.65"});
    AddMeasurementNoise(10.0, 3, &data);
    noise.displacement_std = RootMeanSquare(data.Values("uL"));
    noise.strain_std = RootMeanSquare(data.Values("e@0.65"));
    // The clamp reaction f0 (an output of the bar's model, inertia included) is not a
    // row of U: a level of 1e30 N takes its term out of the bar's J (1e-54 of it).
    noise.force_std = 1e30;
  }
  testing::SmallCase small;
  BarModel zoned, uniform;
  ChannelSet data;
  NoiseLevels noise;
  const std::vector<BarSensor> sensors = {{SensorKind::kDisplacement, 0.25},
                                          {SensorKind::kStrain, 0.65}};
};

TEST(MatrixOutputErrorObjectiveTest, TheClampedBarAsMatricesIsTheBarsZoneObjective) {
  const LsBarCase bar;
  const MatrixModelData matrices = LsClampedBarMatrices(bar.zoned, 200e9, bar.sensors);
  ASSERT_EQ(matrices.sensors.size(), 3u);  // uL, u@0.25, e@0.65
  MatrixOutputErrorObjective general(matrices, bar.data, bar.noise, 0.5);
  testing::BarZoneLeastSquares own(bar.zoned, bar.data, bar.noise, 0.5);
  EXPECT_NEAR(general.rest_cost(), own.rest_cost(), 1e-14 * own.rest_cost());
  const Vector moduli = (Vector(3) << 185e9, 170e9, 215e9).finished();
  Vector general_gradient, own_gradient;
  const double general_cost = general.Cost(moduli, &general_gradient);
  const double own_cost = own.Cost(moduli, &own_gradient);
  // The same tridiagonal band path, load and sensitivity inputs that differ by
  // round-off (G F~ against the end load; K_z / E_z,nom against K1_z). Measured: J
  // 2.2e-16 apart, the gradients 0 (the same bits); checked to 1e-14 and 1e-12.
  EXPECT_EQ(general.integrator().factorization(), Factorization::kBand);
  EXPECT_NEAR(general_cost, own_cost, 1e-14 * own_cost);
  for (int z = 0; z < 3; ++z) {
    EXPECT_NEAR(general_gradient[z], own_gradient[z], 1e-12 * own_gradient.norm()) << z;
  }
  // The optimisers' view: p_z = log(E_z / 200 GPa), cost J / J_rest and
  // d cost / dp_z = dJ/dE_z E_z / J_rest, from the reference's J and dJ/dE_z.
  double p[3], general_scaled = 0.0, general_dp[3];
  for (int z = 0; z < 3; ++z) p[z] = std::log(moduli[z] / 200e9);
  ASSERT_TRUE(general.Evaluate(p, &general_scaled, general_dp));
  EXPECT_NEAR(general_scaled, own_cost / own.cost_scale(), 1e-14 * general_scaled);
  for (int z = 0; z < 3; ++z) {
    const double own_dp = own_gradient[z] * moduli[z] / own.cost_scale();
    EXPECT_NEAR(general_dp[z], own_dp, 1e-12 * std::abs(general_dp[0])) << z;
  }
}

// One zone of `general` against the bar's scalar reference at 170, 200 and 236 GPa: J
// and dJ/dE to the relative tolerances, and uL (the first output row) to uL_tolerance
// of its norm.
void ExpectOneZoneIsTheScalarReference(MatrixOutputErrorObjective* general,
                                       testing::BarLeastSquares* own, double cost_tolerance,
                                       double gradient_tolerance, double uL_tolerance) {
  for (const double modulus : {170e9, 200e9, 236e9}) {
    Vector gradient;
    const double cost = general->Cost(Vector::Constant(1, modulus), &gradient);
    const testing::OutputErrorPrediction& prediction = own->Predict(modulus, true);
    EXPECT_NEAR(cost, prediction.cost, cost_tolerance * prediction.cost) << modulus;
    EXPECT_NEAR(gradient[0], prediction.cost_gradient,
                gradient_tolerance * std::abs(prediction.cost_gradient))
        << modulus;
    const Vector predicted_uL = general->outputs().row(0).transpose();
    EXPECT_LT((predicted_uL - prediction.uL).norm(), uL_tolerance * prediction.uL.norm())
        << modulus;
  }
}

TEST(MatrixOutputErrorObjectiveTest, OneZoneIsTheBarsScalarObjective) {
  const LsBarCase bar;
  const MatrixModelData matrices = LsClampedBarMatrices(bar.uniform, 200e9, bar.sensors);
  MatrixOutputErrorObjective general(matrices, bar.data, bar.noise, 0.5);
  testing::BarLeastSquares own(bar.uniform, bar.data, bar.noise, 0.5, 200e9);
  // Measured: J and dJ/dE at most 2.2e-16 apart; checked to 1e-14 and 1e-12. The
  // model's uL is the bar's prediction (measured 0, the same bits; checked to 1e-13).
  ExpectOneZoneIsTheScalarReference(&general, &own, 1e-14, 1e-12, 1e-13);
}

// dJ/dE_z by central differences of J, step 1e-5 E_z, for every zone.
Vector LsCentralDifferences(MatrixOutputErrorObjective* objective, const Vector& moduli) {
  Vector differences(moduli.size());
  for (Eigen::Index z = 0; z < moduli.size(); ++z) {
    const double step = 1e-5 * moduli[z];
    Vector above = moduli, below = moduli;
    above[z] += step;
    below[z] -= step;
    differences[z] =
        (objective->Cost(above, nullptr) - objective->Cost(below, nullptr)) / (2.0 * step);
  }
  return differences;
}

// Levels for the bar with its clamp as a support: the case's s_u and s_e, and s_f of the
// synthetic data's SNR 10 on fL (the bar's convention: the loads' noise).
NoiseLevels LsSupportLevels(const LsBarCase& bar) {
  NoiseLevels levels = bar.noise;
  levels.force_std = RootMeanSquare(bar.data.Values("fL")) / 10.0;
  return levels;
}

TEST(MatrixOutputErrorObjectiveTest, TheBarWithItsClampAsASupportIsTheBarsZoneObjective) {
  const LsBarCase bar;
  const NoiseLevels levels = LsSupportLevels(bar);
  for (const int zones : {1, 3}) {
    SCOPED_TRACE(zones);
    const BarModel& model = zones == 1 ? bar.uniform : bar.zoned;
    const MatrixModelData matrices =
        BarMatrixModel(model, 200e9, bar.sensors, BarClampExport::kSupport);
    ASSERT_EQ(matrices.supports.size(), 1u);  // "clamp": dof 0, f0 and u0
    ASSERT_EQ(matrices.sensors.size(), 3u);   // uL, u@0.25, e@0.65
    MatrixOutputErrorObjective general(matrices, bar.data, levels, 0.5);
    testing::BarZoneLeastSquares own(model, bar.data, levels, 0.5);
    EXPECT_NEAR(general.rest_cost(), own.rest_cost(), 1e-14 * own.rest_cost());
    const Vector moduli =
        zones == 1 ? Vector::Constant(1, 185e9) : (Vector(3) << 185e9, 170e9, 215e9).finished();
    Vector general_gradient, own_gradient;
    const double general_cost = general.Cost(moduli, &general_gradient);
    const double own_cost = own.Cost(moduli, &own_gradient);
    // f0's term is a fair share of J (the level s_f of SNR 10 on fL).
    NoiseLevels without_f0 = levels;
    without_f0.force_std = 1e30;
    MatrixOutputErrorObjective sensors_only(matrices, bar.data, without_f0, 0.5);
    EXPECT_LT(sensors_only.Cost(moduli, nullptr), 0.9 * general_cost);
    // The same discrete J: f0 = M_01 a_1 + K_01 u_1 with a_1 from one solve of M_r per
    // sample against q^T U + p fL~ with q, p from one solve in the constructor; dof 0
    // decoupled (n dofs) against removed (n - 1). Measured: J 6.1e-14 (1 zone) and
    // 1.9e-14 (3 zones) apart, relative; the gradients 1.9e-13 and 1.4e-14 of their
    // norm; checked to 5e-13 and 2e-12.
    EXPECT_NEAR(general_cost, own_cost, 5e-13 * own_cost);
    for (int z = 0; z < zones; ++z) {
      EXPECT_NEAR(general_gradient[z], own_gradient[z], 2e-12 * own_gradient.norm()) << z;
    }
  }
}

TEST(MatrixOutputErrorObjectiveTest, TheClampsReactionIsTheBarsF0) {
  const LsBarCase bar;
  const NoiseLevels levels = LsSupportLevels(bar);
  const MatrixModelData matrices =
      BarMatrixModel(bar.uniform, 200e9, bar.sensors, BarClampExport::kSupport);
  MatrixOutputErrorObjective general(matrices, bar.data, levels, 0.5);
  testing::BarLeastSquares own(bar.uniform, bar.data, levels, 0.5, 200e9);
  for (const double modulus : {170e9, 236e9}) {
    Vector gradient;
    const double cost = general.Cost(Vector::Constant(1, modulus), &gradient);
    const testing::OutputErrorPrediction& prediction = own.Predict(modulus, true);
    const Vector f0 = general.support_forces().row(0).transpose();
    // Measured: J 2.4e-15, dJ/dE 6.6e-15 and f0 1.7e-14 apart at most, relative;
    // checked to 2e-14, 5e-14 and 2e-13.
    EXPECT_NEAR(cost, prediction.cost, 2e-14 * prediction.cost) << modulus;
    EXPECT_NEAR(gradient[0], prediction.cost_gradient, 5e-14 * std::abs(prediction.cost_gradient))
        << modulus;
    EXPECT_LT((f0 - prediction.f0).norm(), 2e-13 * prediction.f0.norm()) << modulus;
  }
}

// A matrix truth's synthetic support force (SimulateMatrixModel, the data of identify run)
// is the reaction a held support measures, inertia included: on the bar with its clamp
// as a support, the clamped bar's own f0 = row_0(M a + K u) (model/simulation.h), with
// its outputs, from the same fL.
TEST(MatrixOutputErrorObjectiveTest, ASimulatedSupportForceIsTheClampedBarsF0) {
  const LsBarCase bar;
  const double length = bar.small.bar.length;
  const std::vector<ModulusZone> truth = {{length / 3.0, 2.0 * length / 3.0, 0.8 * 200e9}};
  const ChannelSet clamped = SimulateClampedBar(bar.small.bar, bar.small.load, bar.small.time,
                                                truth, {"u@0.25", "e@0.65"});
  const MatrixModelData matrices =
      BarMatrixModel(bar.zoned, 200e9, bar.sensors, BarClampExport::kSupport);
  const Matrix loads = clamped.Values("fL").transpose();
  Matrix forces;
  const Matrix outputs =
      SimulateMatrixModel(matrices, (Vector(3) << 200e9, 160e9, 200e9).finished(), loads,
                          bar.small.time.step, bar.small.time.theta, &forces);
  ASSERT_EQ(forces.rows(), 1);
  const Vector f0 = clamped.Values("f0");
  // Measured: f0 1.3e-14 apart, the outputs 3.1e-15 (uL), 2.7e-15 (u@0.25) and 1.4e-14
  // (e@0.65), relative; checked to 1e-13.
  EXPECT_LT((forces.row(0).transpose() - f0).norm(), 1e-13 * f0.norm());
  int k = 0;
  for (const char* channel : {"uL", "u@0.25", "e@0.65"}) {
    const Vector values = clamped.Values(channel);
    EXPECT_LT((outputs.row(k++).transpose() - values).norm(), 1e-13 * values.norm()) << channel;
  }
}

const std::string kLsPlate = std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate/";

// The coarse plate's channels from rest under a 20 us half sine of 1 kN on 150 steps of
// 1 us: the outputs of `truth` (a manifest of the same channels) at truth_moduli, with
// noise at `snr`.
ChannelSet LsPlateData(const MatrixModelData& model, const MatrixModelData& truth,
                       const Vector& truth_moduli, double snr) {
  Matrix loads = Matrix::Zero(1, 151);
  for (int j = 0; j * 1e-6 < 2e-5; ++j) loads(0, j) = 1e3 * std::sin(M_PI * j / 20.0);
  ChannelSet data = MatrixChannelSet(model, 1e-6, loads,
                                     SimulateMatrixModel(truth, truth_moduli, loads, 1e-6, 0.5));
  AddMatrixModelNoise(model, snr, 1, &data);
  return data;
}

// Each kind's level: the RMS of its sensors' data.
NoiseLevels LsPlateLevels(const MatrixModelData& model, const ChannelSet& data) {
  double displacement = 0.0, strain = 0.0;
  int displacements = 0, strains = 0;
  for (const MatrixModelSensor& sensor : model.sensors) {
    const double mean_square = data.Values(sensor.channel).squaredNorm() / data.num_samples();
    if (sensor.kind == SensorKind::kStrain) {
      strain += mean_square;
      ++strains;
    } else {
      displacement += mean_square;
      ++displacements;
    }
  }
  NoiseLevels levels;
  levels.displacement_std = std::sqrt(displacement / displacements);
  levels.strain_std = std::sqrt(strain / strains);
  return levels;
}

// The supported lattice's levels: the RMS of each sensor kind's data and of R's.
NoiseLevels LsLatticeLevels(const MatrixModelData& model, const ChannelSet& data) {
  NoiseLevels levels = LsPlateLevels(model, data);
  levels.force_std = std::sqrt(data.Values("R").squaredNorm() / data.num_samples());
  return levels;
}

TEST(MatrixOutputErrorObjectiveTest, TheSupportedLatticesGradientMatchesACentralDifference) {
  const MatrixModelData model = testing::SupportedLattice();
  const ChannelSet data = testing::SupportedLatticeHistories(model);
  MatrixOutputErrorObjective objective(model, data, LsLatticeLevels(model, data), 0.5);
  const Vector moduli = (Vector(2) << 1.9e11, 1.7e11).finished();
  Vector gradient;
  objective.Cost(moduli, &gradient);
  const Vector differences = LsCentralDifferences(&objective, moduli);
  for (int z = 0; z < 2; ++z) {
    // Measured: 1.1e-8 (zone 0) and 5.9e-9 (zone 1) of the component; checked to 1e-7.
    EXPECT_NEAR(gradient[z], differences[z], 1e-7 * std::abs(gradient[z])) << model.zones[z].name;
  }
}

// With a support the sensors' parts of the Fisher information and the supports' own, the
// information of the same model without its sensors, sum to the model's (the base every
// layout has in least_squares/sensor_placement.h).
TEST(MatrixOutputErrorObjectiveTest, TheSupportedLatticesSensorsAndSupportSumToItsInformation) {
  const MatrixModelData model = testing::SupportedLattice();
  const ChannelSet data = testing::SupportedLatticeHistories(model);
  const NoiseLevels levels = LsLatticeLevels(model, data);
  MatrixOutputErrorObjective objective(model, data, levels, 0.5);
  MatrixModelData sensorless = model;
  sensorless.sensors.clear();
  MatrixOutputErrorObjective support_only(sensorless, data, levels, 0.5);
  const Vector moduli = (Vector(2) << 1.9e11, 1.7e11).finished();
  Vector gradient;
  Matrix total, support;
  std::vector<Matrix> sensors;
  objective.Cost(moduli, &gradient, &total, &sensors);
  support_only.Cost(moduli, &gradient, &support);
  ASSERT_EQ(sensors.size(), model.sensors.size());
  Matrix sum = support;
  for (const Matrix& sensor : sensors) sum += sensor;
  // The support's force informs: measured 0.60 of the norm.
  EXPECT_GT(support.norm(), 0.3 * total.norm());
  // Measured: 2.2e-16 of the largest entry.
  EXPECT_LT((sum - total).cwiseAbs().maxCoeff(), 2e-15 * total.cwiseAbs().maxCoeff());
}

// Without mass between the held and the free dofs (m_s = 0) the reaction is the trusted
// MCRE's g^T K U: the lattice's outputs and support force against ModelOutputs and
// ModelSupportForces of the same U.
TEST(MatrixOutputErrorObjectiveTest, WithoutInertiaCouplingTheReactionIsTheTrustedMcres) {
  MatrixModelData model = testing::SupportedLattice();
  std::vector<char> held(static_cast<std::size_t>(model.dofs()), 0);
  for (const int dof : model.supports[0].dofs) held[static_cast<std::size_t>(dof)] = 1;
  model.mass = WithHeldDofs(model.mass, held);
  const ChannelSet data = testing::SupportedLatticeHistories(model);
  MatrixOutputErrorObjective objective(model, data, LsLatticeLevels(model, data), 0.5,
                                       Factorization::kSparse);
  const Vector moduli = (Vector(2) << 1.9e11, 1.7e11).finished();
  objective.Cost(moduli, nullptr);
  MatrixMcreProblem trusted(model, data, testing::Weights(0.01, 1.0), 2e11, 0.5,
                            Factorization::kSparse, ClampModel::kTrusted);
  trusted.SetModuli(moduli);
  const Matrix outputs = trusted.ModelOutputs();
  const Matrix forces = trusted.ModelSupportForces();
  // The same steps on the same matrices: measured 0 apart (the same bits) for both;
  // checked to 1e-14.
  EXPECT_LE((objective.outputs() - outputs).norm(), 1e-14 * outputs.norm());
  EXPECT_LE((objective.support_forces() - forces).norm(), 1e-14 * forces.norm());
}

// MatrixLeastSquaresMisfitLevels with a support (the lattice: load F, sensors u_tip,
// u_mid (displacement), e_top (strain), support force R and displacement uR): s_f from
// the load's synthetic noise, from the differences of F and R, or from F's RMS on
// noise-free data; s_u's differences take uR in; without the support s_f is 0.
TEST(MatrixOutputErrorObjectiveTest, TheMisfitLevelsOfASupportedModelGiveTheForceLevel) {
  const MatrixModelData model = testing::SupportedLattice();
  const ChannelSet data = testing::SupportedLatticeHistories(model);
  MatrixMeasurements measurements;
  measurements.histories = data;
  Config config;
  config.data.source = DataSource::kSynthetic;
  config.data.snr = 20.0;
  measurements.noise.displacement_std = 1e-3;
  measurements.noise.strain_std = 2e-3;
  measurements.noise.force_std = 3.0;
  std::string source;
  NoiseLevels levels = MatrixLeastSquaresMisfitLevels(config, model, measurements, data, &source);
  EXPECT_EQ(source, "synthetic_snr");
  EXPECT_EQ(levels.force_std, 3.0);
  EXPECT_EQ(levels.displacement_std, 1e-3);
  MatrixModelData unsupported = model;
  unsupported.supports.clear();
  EXPECT_EQ(
      MatrixLeastSquaresMisfitLevels(config, unsupported, measurements, data, &source).force_std,
      0.0);
  // CSV data: s^2 of the second differences averaged per kind, over F and R for s_f and
  // with uR among the displacements.
  config.data.source = DataSource::kCsv;
  levels = MatrixLeastSquaresMisfitLevels(config, model, measurements, data, &source);
  EXPECT_EQ(source, "data_differences");
  auto variance = [&](const char* channel) {
    return std::pow(DifferenceNoiseStd(data.Values(channel)), 2);
  };
  EXPECT_EQ(levels.force_std, std::sqrt((variance("F") + variance("R")) / 2));
  EXPECT_EQ(levels.displacement_std,
            std::sqrt((variance("u_tip") + variance("u_mid") + variance("uR")) / 3));
  EXPECT_EQ(levels.strain_std, std::sqrt(variance("e_top") / 1));
  // Noise-free data (a level 0): the RMS of the load F for s_f.
  ChannelSet quiet = data;
  for (Channel& channel : quiet.channels) channel.values.setZero();
  measurements.histories = quiet;
  levels = MatrixLeastSquaresMisfitLevels(config, model, measurements, data, &source);
  EXPECT_EQ(source, "channel_rms");
  EXPECT_EQ(levels.force_std, std::sqrt(data.Values("F").squaredNorm() / data.num_samples() / 1));
}

// The coarse plate with data of the fine one (inclusion at 140 GPa) at SNR 20.
struct LsPlateCase {
  MatrixModelData coarse = ReadMatrixModel(kLsPlate + "coarse/model_axial.yaml");
  MatrixModelData fine = ReadMatrixModel(kLsPlate + "fine/model_axial.yaml");
  ChannelSet data = LsPlateData(coarse, fine, (Vector(2) << 200e9, 140e9).finished(), 20.0);
};

TEST(MatrixOutputErrorObjectiveTest, EveryZoneGradientOfThePlateMatchesACentralDifference) {
  const LsPlateCase plate;
  const MatrixModelData& coarse = plate.coarse;
  MatrixOutputErrorObjective objective(coarse, plate.data, LsPlateLevels(coarse, plate.data), 0.5);
  const Vector moduli = (Vector(2) << 190e9, 160e9).finished();
  Vector gradient;
  objective.Cost(moduli, &gradient);
  EXPECT_EQ(objective.integrator().factorization(), Factorization::kSparse);
  for (int z = 0; z < 2; ++z) {
    const double step = 1e-5 * moduli[z];
    Vector above = moduli, below = moduli;
    above[z] += step;
    below[z] -= step;
    const double difference =
        (objective.Cost(above, nullptr) - objective.Cost(below, nullptr)) / (2.0 * step);
    // Measured: 5.7e-8 of the component for the matrix (near its minimum, the smaller
    // component; the difference's truncation: 5.7e-6 with a step of 1e-4), 5.8e-8 for
    // the inclusion with a step of 1e-4.
    EXPECT_NEAR(gradient[z], difference, 5e-7 * std::abs(gradient[z])) << coarse.zones[z].name;
  }
  EXPECT_EQ(objective.sweeps(), 3 + 4);
}

// Each sensor's Fisher information (sensor_information) of the coarse plate against
// the one built from central differences of its outputs, sum_j c_j w_k s_kz s_kz',
// s_kz = (h_k U_j(E + d_z) - h_k U_j(E - d_z)) / (2 d_z); the sensors' sum is the Fisher
// information of the model (no supports).
TEST(MatrixOutputErrorObjectiveTest, EachSensorsInformationMatchesCentralDifferences) {
  const LsPlateCase plate;
  const MatrixModelData& coarse = plate.coarse;
  MatrixOutputErrorObjective objective(coarse, plate.data, LsPlateLevels(coarse, plate.data), 0.5);
  const Vector moduli = (Vector(2) << 190e9, 160e9).finished();
  Vector gradient;
  Matrix total;
  std::vector<Matrix> information;
  objective.Cost(moduli, &gradient, &total, &information);
  const auto sensors = static_cast<Eigen::Index>(coarse.sensors.size());
  ASSERT_EQ(static_cast<Eigen::Index>(information.size()), sensors);
  std::vector<Matrix> derivatives;  // per zone: d outputs / dE_z, sensors x samples
  for (int z = 0; z < 2; ++z) {
    const double step = 1e-5 * moduli[z];
    Vector above = moduli, below = moduli;
    above[z] += step;
    below[z] -= step;
    objective.Cost(above, nullptr);
    const Matrix up = objective.outputs();
    objective.Cost(below, nullptr);
    derivatives.push_back((up - objective.outputs()) / (2.0 * step));
  }
  Matrix sum = Matrix::Zero(2, 2);
  for (Eigen::Index k = 0; k < sensors; ++k) {
    Matrix expected = Matrix::Zero(2, 2);
    const Eigen::Index samples = derivatives[0].cols();
    for (Eigen::Index j = 0; j < samples; ++j) {
      const double c = (j == 0 || j == samples - 1) ? 0.5 : 1.0;
      const Eigen::Vector2d s(derivatives[0](k, j), derivatives[1](k, j));
      expected += c * objective.sensor_weights()[k] * s * s.transpose();
    }
    const Matrix& actual = information[static_cast<std::size_t>(k)];
    EXPECT_EQ(actual, actual.transpose()) << coarse.sensors[k].channel;
    // Measured: 5.6e-9 of the largest entry at worst over the sensors (the central
    // difference's truncation and round-off).
    EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 3e-8 * expected.cwiseAbs().maxCoeff())
        << coarse.sensors[k].channel << "\n"
        << actual << "\n"
        << expected;
    sum += actual;
  }
  // The same sums in another order: the model's information to round-off (measured
  // 2.9e-16 of its largest entry).
  EXPECT_LT((sum - total).cwiseAbs().maxCoeff(), 2e-15 * total.cwiseAbs().maxCoeff());
}

TEST(MatrixOutputErrorObjectiveTest, InverseCrimeOnThePlateRecoversBothZones) {
  const MatrixModelData coarse = ReadMatrixModel(kLsPlate + "coarse/model_axial.yaml");
  const Vector truth = (Vector(2) << 2.1e11, 1.5e11).finished();
  const ChannelSet data =
      LsPlateData(coarse, coarse, truth, std::numeric_limits<double>::infinity());
  MatrixOutputErrorObjective objective(coarse, data, LsPlateLevels(coarse, data), 0.5);
  // At the truth J = 0 to round-off (the simulation's steps in the same order).
  EXPECT_LE(objective.Cost(truth, nullptr), 1e-24 * objective.rest_cost());
  EXPECT_GT(objective.Cost(objective.reference_moduli(), nullptr), 1e-3 * objective.rest_cost());

  const BoundedMinimizerSummary summary = testing::MinimizeWithinHalfAndTwice(&objective);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const Vector found = objective.Moduli(summary.x.data());
  // Measured: 2.0e-15 (matrix) and 2.6e-14 (inclusion) off in 12 evaluations.
  for (int z = 0; z < 2; ++z) {
    EXPECT_NEAR(found[z], truth[z], 1e-8 * truth[z]) << coarse.zones[z].name;
  }
}

constexpr int kLsZones = 10;

// 10 equal zones of a 30-element bar (3 elements each) whose data come from a truth
// with zone 6 ([0.6, 0.7] L) at 0.7 E and zone 2 at 1.1 E, with interior sensors.
struct LsZonedCase {
  explicit LsZonedCase(double snr,
                       std::vector<std::string> sensors = {"u@0.25", "u@0.5", "e@0.2", "e@0.65"})
      : small(testing::MakeSmallCase(30, 250, snr, 1)),
        model(small.bar,
              [&] {
                ZoneLayout layout;
                layout.zone_count = kLsZones;
                return layout.ElementZones(small.bar);
              }()),
        truth(Vector::Constant(kLsZones, small.bar.modulus)) {
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

TEST(MatrixOutputErrorObjectiveTest, OneZoneOfTheRunsBarIsTheBarsScalarReference) {
  const LsZonedCase zoned(10.0);
  const BarModel uniform(zoned.small.bar);
  const MatrixModelData matrices = BarRunModel(uniform, zoned.data, {});
  MatrixOutputErrorObjective zones(matrices, zoned.data, zoned.noise, 0.5);
  testing::BarLeastSquares scalar(uniform, zoned.data, zoned.noise, 0.5, 200e9);
  // Measured 4.4e-16 apart, relative.
  EXPECT_NEAR(zones.rest_cost(), scalar.rest_cost(), 5e-15 * scalar.rest_cost());
  // Measured: J 3.6e-15, dJ/dE 3.1e-15 apart at most, relative (the reaction from the
  // support's row against the clamp's, the sensitivity inputs -K_z / E_z,nom u and
  // -K (u / E)); uL 3.5e-15 of its norm.
  ExpectOneZoneIsTheScalarReference(&zones, &scalar, 4e-14, 4e-14, 4e-14);
}

TEST(MatrixOutputErrorObjectiveTest, TheZonedBarsGradientsMatchCentralDifferences) {
  LsZonedCase zoned(10.0);
  MatrixOutputErrorObjective objective(zoned.matrices, zoned.data, zoned.noise, 0.5);
  Vector moduli(kLsZones);
  for (int z = 0; z < kLsZones; ++z) moduli[z] = 200e9 * (0.85 + 0.03 * z);
  Vector gradient;
  objective.Cost(moduli, &gradient);
  const Vector differences = LsCentralDifferences(&objective, moduli);
  double worst = 0.0;
  for (int z = 0; z < kLsZones; ++z) {
    worst = std::max(worst, std::abs(gradient[z] - differences[z]) / std::abs(gradient[z]));
  }
  // Every component to itself (the smallest is 0.049 of the largest): measured 6.0e-9
  // (the difference's truncation and round-off).
  EXPECT_LT(worst, 5e-8);
  EXPECT_EQ(objective.sweeps(), 1 + kLsZones + 2 * kLsZones);
}

TEST(MatrixOutputErrorObjectiveTest, EqualZonesOfTheBarSumToTheScalarReferenceGradient) {
  const LsZonedCase zoned(20.0);
  MatrixOutputErrorObjective zones(zoned.matrices, zoned.data, zoned.noise, 0.5);
  const BarModel uniform(zoned.small.bar);
  testing::BarLeastSquares scalar(uniform, zoned.data, zoned.noise, 0.5, 200e9);
  Vector gradient;
  const double cost = zones.Cost(Vector::Constant(kLsZones, 190e9), &gradient);
  const testing::OutputErrorPrediction& prediction = scalar.Predict(190e9, true);
  // sum_z dJ/dE_z = dJ/dE at equal moduli. Measured: J 2.4e-15, the sum 8.4e-15 apart.
  EXPECT_NEAR(cost, prediction.cost, 3e-14 * prediction.cost);
  EXPECT_NEAR(gradient.sum(), prediction.cost_gradient, 9e-14 * std::abs(prediction.cost_gradient));
}

TEST(ZoneIdentificationTest, LeastSquaresInverseCrimeOnTheBarRecoversEveryZone) {
  const LsZonedCase zoned(std::numeric_limits<double>::infinity());
  MatrixOutputErrorObjective objective(zoned.matrices, zoned.data, zoned.noise, 0.5);
  // The data of the truth's zones on the model's own mesh and step: J = 0 there
  // (measured 2.6e-28 J_rest: another code path than the simulation's) and not at the
  // homogeneous modulus (measured 0.117 J_rest).
  EXPECT_LE(objective.Cost(zoned.truth, nullptr), 3e-27 * objective.rest_cost());
  EXPECT_GT(objective.Cost(Vector::Constant(kLsZones, 200e9), nullptr),
            1e-2 * objective.rest_cost());

  ZoneIdentificationOptions options;
  options.regularization.kind = RegularizationKind::kNone;
  const ZoneIdentificationSummary summary =
      IdentifyZoneModuliByLeastSquares(options, zoned.matrices, zoned.data, zoned.noise, 0.5, 195e9,
                                       100e9, 400e9, NoiseLevels(), PrefilterOptions{});
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.message;
  ASSERT_EQ(summary.moduli.size(), kLsZones);
  double worst = 0.0;
  for (int z = 0; z < kLsZones; ++z) {
    worst = std::max(worst, std::abs(summary.moduli[z] / zoned.truth[z] - 1.0));
  }
  // Measured 8.3e-10 (Ceres L-BFGS from 195 GPa, 31 evaluations).
  EXPECT_LT(worst, 1e-8);
  EXPECT_TRUE(summary.least_squares);
  MatrixOutputErrorObjective fresh(zoned.matrices, zoned.data, zoned.noise, 0.5);
  EXPECT_EQ(summary.homogeneous_cost, fresh.Cost(Vector::Constant(kLsZones, 195e9), nullptr));
  // One sweep for the cost at E*, then 1 (cost) or 1 + 10 (with the gradient) each.
  EXPECT_GE(summary.sweeps, 1 + summary.evaluations);
  EXPECT_LE(summary.sweeps, 1 + (1 + kLsZones) * summary.evaluations);

  // The same identification with the adjoint's gradient: 1 or 2 sweeps an evaluation, the
  // same moduli up to round-off (measured: 30 evaluations each, the moduli 7.7e-14 apart
  // at most, relative).
  options.least_squares_gradient = LeastSquaresGradient::kAdjoint;
  const ZoneIdentificationSummary adjoint =
      IdentifyZoneModuliByLeastSquares(options, zoned.matrices, zoned.data, zoned.noise, 0.5, 195e9,
                                       100e9, 400e9, NoiseLevels(), PrefilterOptions{});
  ASSERT_TRUE(adjoint.IsSolutionUsable()) << adjoint.message;
  EXPECT_LE(adjoint.sweeps, 1 + 2 * adjoint.evaluations);
  double apart = 0.0;
  for (int z = 0; z < kLsZones; ++z) {
    apart = std::max(apart, std::abs(adjoint.moduli[z] / summary.moduli[z] - 1.0));
  }
  EXPECT_LT(apart, 1e-12);
}

// ExpectedLeastSquaresNoiseCost: the discrepancy target's J of noise alone is the mean J at the
// truth of noisy data: the model is linear in the load, so at the truth the clean part of the
// residual vanishes and J(truth; clean + noise) = J(noise alone), the load's noise driving the
// model. Two independent means over 400 draws each (AddMeasurementNoise's levels).
TEST(ZoneIdentificationTest, LeastSquaresNoiseTargetIsTheMeanCostAtTheTruthOfNoisyData) {
  const LsZonedCase zoned(std::numeric_limits<double>::infinity());
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
  const testing::BarZoneLeastSquares clean(zoned.model, zoned.data, noise, 0.5);
  const double scale = clean.cost_scale();
  PrefilterOptions no_prefilter;
  no_prefilter.enabled = false;
  const double target = ExpectedLeastSquaresNoiseCost(
      zoned.matrices, zoned.data, noise, 0.5, zoned.truth, noise, no_prefilter, kDraws, 1, scale);
  double mean = 0.0;
  for (int seed = 1; seed <= kDraws; ++seed) {
    ChannelSet noisy = zoned.data;
    AddMeasurementNoise(kSnr, 1000 + seed, &noisy);
    testing::BarZoneLeastSquares objective(zoned.model, noisy, noise, 0.5);
    mean += objective.Cost(zoned.truth, nullptr) / scale / kDraws;
  }
  // Measured: the two means 0.5 % apart (the target's J of the bar as matrices, the
  // mean's of the bar's own band model); the noisy data's mean without the load's
  // noise is 1.40 times smaller (the model driven by that noise is 29 % of J).
  EXPECT_NEAR(target / mean, 1.0, 0.03);
}

// The adjoint's gradient (LeastSquaresGradient::kAdjoint) against the forward
// sensitivities' on the same discrete J, as max_z |difference| / max_z |dJ/dE_z|, and
// the adjoint's cost the same bits (the same forward sweep).
double AdjointGradientMismatch(const MatrixModelData& model, const ChannelSet& data,
                               const NoiseLevels& levels, double theta, const Vector& moduli) {
  MatrixOutputErrorObjective forward(model, data, levels, theta);
  MatrixOutputErrorObjective adjoint(model, data, levels, theta);
  adjoint.SetGradientMethod(LeastSquaresGradient::kAdjoint);
  EXPECT_EQ(adjoint.gradient_method(), LeastSquaresGradient::kAdjoint);
  Vector forward_gradient, adjoint_gradient;
  const double forward_cost = forward.Cost(moduli, &forward_gradient);
  EXPECT_EQ(adjoint.Cost(moduli, &adjoint_gradient), forward_cost);
  EXPECT_EQ(adjoint.sweeps(), 2);
  EXPECT_EQ(forward.sweeps(), 1 + moduli.size());
  return (adjoint_gradient - forward_gradient).lpNorm<Eigen::Infinity>() /
         forward_gradient.lpNorm<Eigen::Infinity>();
}

TEST(MatrixOutputErrorObjectiveTest, TheAdjointGradientIsTheForwardSensitivitiesGradient) {
  // The run's bar in 10 zones (tridiagonal path), at the trapezoidal rule and backward Euler.
  const LsZonedCase zoned(10.0);
  const Vector bar_moduli = zoned.truth * 1.05;
  // Measured: 1.3e-15 (theta 1/2) and 1.7e-15 (theta 1).
  EXPECT_LT(AdjointGradientMismatch(zoned.matrices, zoned.data, zoned.noise, 0.5, bar_moduli),
            2e-14);
  EXPECT_LT(AdjointGradientMismatch(zoned.matrices, zoned.data, zoned.noise, 1.0, bar_moduli),
            2e-14);
  // The coarse plate (sparse path).
  const LsPlateCase plate;
  // Measured: 8.5e-16.
  EXPECT_LT(
      AdjointGradientMismatch(plate.coarse, plate.data, LsPlateLevels(plate.coarse, plate.data),
                              0.5, (Vector(2) << 190e9, 160e9).finished()),
      1e-14);
  // The supported lattice: the supports' reactions in J.
  const MatrixModelData lattice = testing::SupportedLattice();
  const ChannelSet lattice_data = testing::SupportedLatticeHistories(lattice);
  // Measured: 3.8e-16.
  EXPECT_LT(AdjointGradientMismatch(lattice, lattice_data, LsLatticeLevels(lattice, lattice_data),
                                    0.5, (Vector(2) << 1.9e11, 1.7e11).finished()),
            5e-15);
}
}  // namespace
}  // namespace mcrewave
