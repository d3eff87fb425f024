// Tests of the error map (mcre/error_map.h): the shares against a direct sum over the
// field, the space-time picture's sampling, and the files `identify run` writes.
#include "mcrewave/mcre/error_map.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "identify_binary.h"
#include "reference/bar_error_map.h"

namespace mcrewave {
namespace {

TEST(ErrorMapTest, SharesAreTheElementEnergiesOfTheGapSummedOverTheWindow) {
  BarProperties bar;
  bar.elements = 6;
  ZoneLayout layout;
  layout.zone_count = 2;
  const BarModel model(bar, layout.ElementZones(bar));
  Vector moduli(2);
  moduli << 150e9, 250e9;
  const int steps = 9;
  const double h = 1e-6;
  std::mt19937 engine(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix retrograde(model.num_nodes(), steps + 1);
  for (Eigen::Index i = 0; i < retrograde.size(); ++i)
    retrograde.data()[i] = 1e-6 * uniform(engine);

  const ErrorMap map = testing::ComputeErrorMap(model, moduli, retrograde, h, 4);
  // Independently: W^T K_el W with the element's assembled stiffness matrix.
  const SparseMatrix stiffness = model.Stiffness(moduli);
  Vector total_by_time = Vector::Zero(steps + 1);
  for (int e = 0; e < 6; ++e) {
    Vector element_moduli = Vector::Zero(6);
    element_moduli[e] = moduli[model.element_zone(e)];
    const SparseMatrix element = model.StiffnessOfElements(element_moduli);
    double share = 0.0;
    for (int j = 0; j <= steps; ++j) {
      const Vector w = retrograde.col(j);
      const double weight = (j == 0 || j == steps) ? 0.5 : 1.0;
      share += weight * h * 0.5 * w.dot(element * w);
    }
    // Measured at most 2.2e-16 relative.
    EXPECT_NEAR(map.share[e], share, 1e-15 * share) << "element " << e;
    EXPECT_DOUBLE_EQ(map.position[e], (e + 0.5) / 6.0);
  }
  EXPECT_NEAR(map.Fractions().sum(), 1.0, 1e-15);
  // 9 steps on at most 4 samples: stride 3, samples 0, 3, 6, 9.
  ASSERT_EQ(map.times.size(), 4);
  EXPECT_DOUBLE_EQ(map.times[3], 9 * h);
  const Vector w = retrograde.col(6);
  const double jump = w[3] - w[2];
  EXPECT_NEAR(map.density(2, 2), 0.5 * 150e9 * bar.section / (1.0 / 6) * jump * jump / (1.0 / 6),
              1e-14 * map.density(2, 2));
}

TEST(ErrorMapTest, FineMeshesAverageTheirElementsIntoAtMost2000Columns) {
  // 4001 elements: groups of ceil(4001 / 2000) = 3, so 1334 columns, the last one of
  // 2 elements; each column the mean of its elements' densities from a 4001-column
  // picture computed element by element here.
  BarProperties bar;
  bar.elements = 4001;
  const BarModel model(bar);
  ASSERT_EQ(SpaceTimeGroupSize(4001), 3);
  ASSERT_EQ(SpaceTimeGroupSize(2000), 1);
  const Vector positions = SpaceTimeColumnPositions(model);
  ASSERT_EQ(positions.size(), 1334);
  const double length = 1.0 / 4001;
  // Column 0 holds elements 0..2 (centre: element 1's midpoint); the last, 3999..4000.
  EXPECT_NEAR(positions[0], 1.5 * length, 1e-15);
  EXPECT_NEAR(positions[1333], 4000.0 * length, 1e-15);
  std::mt19937 engine(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Matrix retrograde(model.num_nodes(), 3);
  for (Eigen::Index i = 0; i < retrograde.size(); ++i)
    retrograde.data()[i] = 1e-6 * uniform(engine);
  const Vector moduli = Vector::Constant(1, 200e9);
  const ErrorMap map = testing::ComputeErrorMap(model, moduli, retrograde, 1e-6, 3);
  ASSERT_EQ(map.density.rows(), 3);
  ASSERT_EQ(map.density.cols(), 1334);
  double worst = 0.0;
  for (int c = 0; c < 1334; ++c) {
    const int first = 3 * c, end = std::min(4001, first + 3);
    double sum = 0.0;
    for (int e = first; e < end; ++e) {
      const double jump = retrograde(e + 1, 1) - retrograde(e, 1);
      // 1/2 E (S / l) jump^2 / l.
      sum += 0.5 * 200e9 * bar.section / length * jump * jump / length;
    }
    const double expected = sum / (end - first);
    worst = std::max(worst, std::abs(map.density(1, c) - expected) / expected);
  }
  // Measured 0: the same products in the same order.
  EXPECT_LT(worst, 1e-15);
}

TEST(ErrorMapFilesTest, IdentifyRunWritesTheMapItsPeakAndTheFigure) {
  namespace fs = std::filesystem;
  const std::string folder = testing::FreshDirectory("error_map_files") + "/results";
  const testing::RunResult result = testing::RunIdentify(
      "run " + testing::SourcePath("configs/quick.yaml") + " --output " + folder + " -q");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // error_map.csv: element,x,share,fraction,sensitivity,sensitivity_noise_std; one row
  // per element (25).
  std::istringstream csv(testing::ReadText(folder + "/error_map.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "element,x,share,fraction,sensitivity,sensitivity_noise_std");
  std::vector<double> fractions;
  double largest = -1.0, largest_x = -1.0;
  double softening = -std::numeric_limits<double>::infinity(), softening_x = -1.0;
  double softening_ratio = 0.0;
  while (std::getline(csv, line)) {
    std::istringstream row(line);
    std::string element, x, share, fraction, sensitivity, noise_std;
    std::getline(row, element, ',');
    std::getline(row, x, ',');
    std::getline(row, share, ',');
    std::getline(row, fraction, ',');
    std::getline(row, sensitivity, ',');
    std::getline(row, noise_std, ',');
    EXPECT_GT(std::stod(noise_std), 0.0);
    if (std::stod(sensitivity) > softening) {
      softening = std::stod(sensitivity);
      softening_x = std::stod(x);
      softening_ratio = softening / std::stod(noise_std);
    }
    EXPECT_EQ(std::stoi(element), static_cast<int>(fractions.size()));
    EXPECT_NEAR(std::stod(x), (fractions.size() + 0.5) / 25.0, 1e-12);
    EXPECT_GT(std::stod(share), 0.0);
    fractions.push_back(std::stod(fraction));
    if (fractions.back() > largest) {
      largest = fractions.back();
      largest_x = std::stod(x);
    }
  }
  ASSERT_EQ(fractions.size(), 25u);
  double sum = 0.0;
  for (double f : fractions) sum += f;
  // Printed with 17 digits: measured 1.1e-16 from 1.
  EXPECT_NEAR(sum, 1.0, 1e-15);
  const std::string summary = testing::ReadText(folder + "/summary.yaml");
  EXPECT_NE(summary.find("  peak_position: "), std::string::npos) << summary;
  const double summary_x = std::stod(summary.substr(summary.find("  peak_position: ") + 17, 30));
  EXPECT_DOUBLE_EQ(summary_x, largest_x);
  // The sensitivity's largest element, as summary.yaml names it.
  const YAML::Node map = YAML::LoadFile(folder + "/summary.yaml")["error_map"];
  EXPECT_DOUBLE_EQ(map["softening_peak_position"].as<double>(), softening_x);
  // The ratio from the 17 printed digits of both: measured 0 apart.
  EXPECT_NEAR(map["softening_peak_noise_ratio"].as<double>(), softening_ratio,
              1e-14 * std::abs(softening_ratio));
  EXPECT_GE(map["stiffening_peak_position"].as<double>(), 0.0);
  EXPECT_TRUE(fs::exists(folder + "/error_map_spacetime.dat"));
  EXPECT_TRUE(fs::exists(folder + "/error_map.png")) << result.output;
}

}  // namespace
}  // namespace mcrewave
