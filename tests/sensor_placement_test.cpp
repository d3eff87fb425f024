// Tests of sensor placement (least_squares/sensor_placement.h) and `identify sensors`
// (app/sensor_placement_run.h): the Cramer-Rao std against a closed form; the greedy
// choice against an exhaustive search of the first pick and against the closed form of
// diagonal information; its gains against log det computed from determinants; refusals;
// end to end on the plate's full field, the chosen sensors' std against a second run on
// them alone; configs/plate_zones_gauges.yaml's gauges are the design's choice.
#include "mcrewave/least_squares/sensor_placement.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/core/random.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::ReadText;
using testing::RunIdentify;
using testing::RunResult;
using testing::SourcePath;

// Random symmetric positive semi-definite Z x Z matrices of rank `rank`, B B^T.
std::vector<Matrix> RandomInformation(int candidates, int zones, int rank, std::uint64_t seed) {
  StandardNormal normal(seed);
  std::vector<Matrix> information;
  for (int k = 0; k < candidates; ++k) {
    Matrix factor(zones, rank);
    for (int i = 0; i < zones; ++i) {
      for (int r = 0; r < rank; ++r) factor(i, r) = normal();
    }
    information.push_back(factor * factor.transpose());
  }
  return information;
}

TEST(SensorPlacementTest, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(SensorPlacementOptions().IsValid(&why)) << why;
  SensorPlacementOptions options;
  options.count = 0;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("count must be at least 1"), std::string::npos) << why;
  options = SensorPlacementOptions();
  options.prior_log_modulus_std = 0.0;
  EXPECT_FALSE(options.IsValid(&why));
}

TEST(SensorPlacementTest, CramerRaoStdIsTheInversesDiagonal) {
  // [[4, 2], [2, 3]]^-1 = [[3, -2], [-2, 4]] / 8
  Matrix information(2, 2);
  information << 4, 2, 2, 3;
  const Vector std = CramerRaoStd(information);
  EXPECT_NEAR(std[0], std::sqrt(3.0 / 8.0), 1e-15);
  EXPECT_NEAR(std[1], std::sqrt(4.0 / 8.0), 1e-15);
}

// Diagonal information, candidate k informing zone k % 3 by a_k: the gain of adding k is
// ln(1 + a_k / F_zz), F_zz = 1 + the chosen a of zone z (sigma_p = 1).
TEST(SensorPlacementTest, DiagonalInformationIsChosenByItsClosedForm) {
  const std::vector<double> amounts = {5.0, 1.0, 2.0, 4.0, 3.0, 0.5};
  std::vector<Matrix> information;
  for (std::size_t k = 0; k < amounts.size(); ++k) {
    Matrix one = Matrix::Zero(3, 3);
    one(static_cast<Eigen::Index>(k % 3), static_cast<Eigen::Index>(k % 3)) = amounts[k];
    information.push_back(one);
  }
  SensorPlacementOptions options;
  options.count = 4;
  const SensorPlacementSummary summary = PlaceSensors(options, information);
  ASSERT_EQ(summary.termination, TerminationType::kConvergence) << summary.message;
  // F = diag(1, 1, 1); pick 0 (ln 6 against ln 3, ln 4 and less): diag(6, 1, 1); pick 4
  // (ln 4 against ln 3 for 2, ln(10/6) for 3): diag(6, 4, 1); pick 2 (ln 3):
  // diag(6, 4, 3); pick 3 (ln(10/6) against ln(5/4) for 1 and ln(7/6) for 5).
  EXPECT_EQ(summary.chosen, std::vector<int>({0, 4, 2, 3}));
  EXPECT_NEAR(summary.log_det_gain[0], std::log(6.0), 1e-14);
  EXPECT_NEAR(summary.log_det_gain[1], std::log(4.0), 1e-14);
  EXPECT_NEAR(summary.log_det_gain[2], std::log(3.0), 1e-14);
  EXPECT_NEAR(summary.log_det_gain[3], std::log(10.0 / 6.0), 1e-14);
  EXPECT_NEAR(summary.chosen_std(3, 0), 1.0 / std::sqrt(10.0), 1e-15);
  EXPECT_NEAR(summary.chosen_std(3, 1), 1.0 / std::sqrt(4.0), 1e-15);
  EXPECT_NEAR(summary.no_sensor_std[1], 1.0, 1e-15);
}

// Random information of rank 2 on 5 zones: the first pick is the best single candidate of
// an exhaustive search; every gain is the log det difference computed from determinants;
// with every candidate chosen the std is all_candidates_std.
TEST(SensorPlacementTest, TheGreedyChoiceMatchesDeterminantsAndAnExhaustiveFirstPick) {
  const int candidates = 12, zones = 5;
  const std::vector<Matrix> information = RandomInformation(candidates, zones, 2, 7);
  SensorPlacementOptions options;
  options.count = candidates;
  options.prior_log_modulus_std = 0.5;
  const SensorPlacementSummary summary = PlaceSensors(options, information);
  ASSERT_EQ(summary.termination, TerminationType::kConvergence) << summary.message;
  const Matrix prior = 4.0 * Matrix::Identity(zones, zones);
  int best = -1;
  double best_det = 0.0;
  for (int k = 0; k < candidates; ++k) {
    const double det = (prior + information[static_cast<std::size_t>(k)]).determinant();
    if (det > best_det) {
      best_det = det;
      best = k;
    }
  }
  EXPECT_EQ(summary.chosen[0], best);
  Matrix chosen = prior;
  for (int i = 0; i < candidates; ++i) {
    const double before = std::log(chosen.determinant());
    chosen += information[static_cast<std::size_t>(summary.chosen[static_cast<std::size_t>(i)])];
    // Measured: 1.8e-15 at worst.
    EXPECT_NEAR(summary.log_det_gain[static_cast<std::size_t>(i)],
                std::log(chosen.determinant()) - before, 2e-14)
        << i;
  }
  // Every gain is positive and, the objective being submodular, none above the one before.
  for (int i = 1; i < candidates; ++i) {
    EXPECT_LE(summary.log_det_gain[static_cast<std::size_t>(i)],
              summary.log_det_gain[static_cast<std::size_t>(i - 1)] * (1.0 + 1e-12));
  }
  EXPECT_LT((summary.chosen_std.row(candidates - 1).transpose() - summary.all_candidates_std)
                .cwiseAbs()
                .maxCoeff(),
            1e-14);
}

TEST(SensorPlacementTest, ACountAboveTheCandidatesOrABadMatrixFails) {
  std::vector<Matrix> information = RandomInformation(3, 2, 1, 1);
  SensorPlacementOptions options;
  options.count = 4;
  SensorPlacementSummary summary = PlaceSensors(options, information);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_NE(summary.message.find("count 4 exceeds the 3 candidates"), std::string::npos);
  options.count = 2;
  information[1](0, 0) = std::nan("");
  summary = PlaceSensors(options, information);
  EXPECT_EQ(summary.termination, TerminationType::kFailure);
  EXPECT_NE(summary.message.find("candidate 1 is not a finite 2 x 2 matrix"), std::string::npos)
      << summary.message;
}

// The numbers of column `name` of a CSV file.
std::vector<double> CsvColumn(const std::string& path, const std::string& name) {
  std::istringstream text(ReadText(path));
  std::string line;
  std::getline(text, line);
  int column = -1, index = 0;
  std::istringstream header(line);
  for (std::string cell; std::getline(header, cell, ',');) {
    if (cell == name) column = index;
    ++index;
  }
  std::vector<double> values;
  while (column >= 0 && std::getline(text, line)) {
    std::istringstream row(line);
    std::string cell;
    for (int c = 0; c <= column; ++c) std::getline(row, cell, ',');
    values.push_back(std::stod(cell));
  }
  return values;
}

// identify sensors on the plate's full field (1248 candidates, the 3 x 1 grid of zones):
// 4 sensors, then a run on those 4 alone (data.channels) gives, as its every-candidate
// std, the first run's std of the chosen sensors under their own noise.
TEST(SensorPlacementRunTest, ThePlatesChosenSensorsHaveTheStdOfARunOnThemAlone) {
  const std::string dir = FreshDirectory("sensor_placement_plate");
  const std::string common = " --set model.zone_grid=[3,1] --set data.snr=20 -q ";
  const RunResult first = RunIdentify("sensors " + SourcePath("configs/plate_zones.yaml") + common +
                                      "--count 4 -o " + dir + "/first");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const YAML::Node channels = YAML::LoadFile(dir + "/first/channels.yaml")["data"]["channels"];
  ASSERT_EQ(channels.size(), 4u);
  std::string list;
  for (const YAML::Node& channel : channels) {
    list += (list.empty() ? "" : ",") + channel.as<std::string>();
  }
  const std::vector<double> largest = CsvColumn(dir + "/first/sensors.csv", "largest_std");
  ASSERT_EQ(largest.size(), 4u);
  for (std::size_t i = 1; i < largest.size(); ++i) EXPECT_LE(largest[i], largest[i - 1]);
  const std::vector<double> chosen = CsvColumn(dir + "/first/cramer_rao.csv", "std_chosen");
  const std::vector<double> every = CsvColumn(dir + "/first/cramer_rao.csv", "std_every_candidate");
  ASSERT_EQ(chosen.size(), 3u);

  const RunResult second =
      RunIdentify("sensors " + SourcePath("configs/plate_zones.yaml") + common +
                  "--set 'data.channels=[" + list + "]' --count 4 -o " + dir + "/second");
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const std::vector<double> alone =
      CsvColumn(dir + "/second/cramer_rao.csv", "std_every_candidate");
  ASSERT_EQ(alone.size(), 3u);
  for (std::size_t z = 0; z < 3; ++z) {
    // Measured: the same ten digits in the CSV.
    EXPECT_NEAR(alone[z], chosen[z], 1e-9 * chosen[z]) << z;
    EXPECT_LT(every[z], chosen[z]) << z;  // every candidate tells more than four
  }
}

// configs/plate_zones_gauges.yaml's data.channels is what identify sensors chooses among
// its manifest's 1872 candidates for its 64 zones at its SNR, in that order.
TEST(SensorPlacementRunTest, TheGaugeConfigsChannelsAreTheDesignsChoice) {
  const std::string dir = FreshDirectory("sensor_placement_gauges");
  const std::string config = SourcePath("configs/plate_zones_gauges.yaml");
  const RunResult run =
      RunIdentify("sensors " + config + " --set data.channels=[] --count 20 -q -o " + dir);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const YAML::Node chosen = YAML::LoadFile(dir + "/channels.yaml")["data"]["channels"];
  const YAML::Node committed = YAML::LoadFile(config)["data"]["channels"];
  ASSERT_EQ(chosen.size(), 20u);
  ASSERT_EQ(committed.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(chosen[i].as<std::string>(), committed[i].as<std::string>()) << i;
  }
}

TEST(SensorPlacementRunTest, BadInputsExitWithOneLineAndWriteNothing) {
  const std::string dir = FreshDirectory("sensor_placement_refusals");
  const std::string plate = SourcePath("configs/plate_zones.yaml");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {SourcePath("configs/quick.yaml") + " --set data.snr=20",
       "model.kind: identify sensors chooses among a matrix model's sensors"},
      {plate + " --set data.snr=.inf", "data.snr: identify sensors needs the noise level"},
      {plate + " --set data.snr=20 --count 2000", "--count must lie in [1, 1248]"},
      {plate + " --set data.snr=20 --set 'data.channels=[ux_1_0, nope]'",
       "data.channels: 'nope' is not a sensor of the manifest"},
      {plate + " --set data.snr=20 --set 'data.channels=[ux_1_0, ux_1_0]'",
       "data.channels: 'ux_1_0' is listed twice"},
  };
  for (const auto& [arguments, reason] : cases) {
    const RunResult run = RunIdentify("sensors " + arguments + " -q -o " + dir + "/out");
    EXPECT_EQ(run.exit_code, 2) << arguments << "\n" << run.output;
    EXPECT_EQ(run.output.rfind("error: ", 0), 0u) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
    EXPECT_NE(run.output.find(reason), std::string::npos) << arguments << "\n" << run.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/out")) << arguments;
  }
}

}  // namespace
}  // namespace mcrewave
