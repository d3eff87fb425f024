// Tests of the result files of `identify run` (app/results.h): the quick case
// identified in-process, its files written, then every CSV and the summary's
// headline numbers parsed back and compared with the IdentificationRun they were
// written from (values written with 17 significant digits read back to the same
// double), and the error map and model end forces recomputed from the
// retrograde field with the bar's element formulas.
#include "mcrewave/app/results.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::ReadText;
using testing::SourcePath;

struct Csv {
  std::string header;
  std::vector<std::vector<double>> rows;
};

// A CSV of numbers ("nan" included) with one header line.
Csv ReadCsv(const std::string& path) {
  Csv csv;
  std::istringstream lines(ReadText(path));
  std::getline(lines, csv.header);
  for (std::string line; std::getline(lines, line);) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      row.push_back(std::strtod(cell.c_str(), nullptr));
    }
    csv.rows.push_back(row);
  }
  return csv;
}

// The value of a top-level "key: value  # comment" line of a summary.yaml.
double TopLevelNumber(const std::string& yaml, const std::string& key) {
  const std::size_t at = yaml.find("\n" + key + ": ");
  EXPECT_NE(at, std::string::npos) << key;
  if (at == std::string::npos) return std::nan("");
  return std::strtod(yaml.c_str() + at + key.size() + 3, nullptr);
}

class ResultFilesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Config config = LoadConfig(SourcePath("configs/quick.yaml"));
    run_ = new IdentificationRun(RunIdentification(config, LoadMeasurements(config)));
    ASSERT_TRUE(run_->IsUsable()) << run_->outer.FullReport();
    folder_ = new std::string(FreshDirectory("result_files") + "/results");
    WriteIdentificationResults(*run_, *folder_, false);
  }
  static void TearDownTestSuite() {
    delete run_;
    delete folder_;
  }
  static std::string File(const std::string& name) { return *folder_ + "/" + name; }

  static IdentificationRun* run_;
  static std::string* folder_;
};

IdentificationRun* ResultFilesTest::run_ = nullptr;
std::string* ResultFilesTest::folder_ = nullptr;

TEST_F(ResultFilesTest, SummaryHoldsTheIdentifiedModulusCostAndCounts) {
  const std::string yaml = "\n" + ReadText(File("summary.yaml"));
  EXPECT_EQ(TopLevelNumber(yaml, "identified_modulus"), run_->identified_modulus());
  EXPECT_EQ(TopLevelNumber(yaml, "cost"), run_->cost());
  // The scan's and the refinement's.
  EXPECT_EQ(TopLevelNumber(yaml, "evaluations"),
            run_->outer.scan_evaluations + run_->outer.evaluations);
  EXPECT_EQ(TopLevelNumber(yaml, "sweeps"), run_->outer.scan_sweeps + run_->sweeps);
  // relative_error = (E* - E_data) / E_data with the 200 GPa of configs/quick.yaml.
  EXPECT_EQ(TopLevelNumber(yaml, "relative_error"), (run_->identified_modulus() - 200e9) / 200e9);
}

TEST_F(ResultFilesTest, EvaluationsCsvHoldsEveryEvaluationInOrder) {
  const Csv csv = ReadCsv(File("evaluations.csv"));
  ASSERT_EQ(csv.rows.size(), run_->evaluations.size());
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const std::vector<double>& row = csv.rows[i];
    const ObjectiveEvaluation& evaluation = run_->evaluations[i];
    ASSERT_EQ(row.size(), 9u) << "row " << i + 1;
    EXPECT_EQ(row[0], i + 1.0);
    EXPECT_EQ(row[1], evaluation.modulus);
    ASSERT_TRUE(evaluation.usable);
    EXPECT_EQ(row[2], evaluation.cost);
    EXPECT_EQ(row[3], evaluation.cost_gradient);
    EXPECT_EQ(row[4], evaluation.gradient_requested ? 1.0 : 0.0);
    EXPECT_EQ(row[6], evaluation.inner.iterations);
    EXPECT_EQ(row[7], evaluation.inner.sweeps);
    // Written with 6 significant digits.
    EXPECT_NEAR(row[8], evaluation.inner.relative_residual,
                1e-5 * evaluation.inner.relative_residual);
  }
  // The best evaluation is the identified modulus and cost.
  EXPECT_EQ(csv.rows[run_->best_index][1], run_->identified_modulus());
  EXPECT_EQ(csv.rows[run_->best_index][2], run_->cost());
}

TEST_F(ResultFilesTest, ScanCsvHoldsTheScanCostsInJouleSeconds) {
  const Csv csv = ReadCsv(File("scan.csv"));
  EXPECT_EQ(csv.header, "modulus,cost,cost_gradient,usable");
  ASSERT_EQ(csv.rows.size(), run_->outer.scan_moduli.size());
  ASSERT_EQ(csv.rows.size(), 41u);
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    EXPECT_EQ(csv.rows[i][0], run_->outer.scan_moduli[i]);
    // e^2 = scaled cost x J_rest
    EXPECT_EQ(csv.rows[i][1], run_->outer.scan_costs[i] * run_->rest_cost);
    // de^2/dE = (d cost / dx) J_rest / E_scale
    EXPECT_EQ(csv.rows[i][2],
              run_->outer.scan_gradients[i] * (run_->rest_cost / run_->config.outer.initial));
    EXPECT_EQ(csv.rows[i][3], 1.0);
  }
  // Evenly spaced in log E over the bounds [100, 400] GPa.
  EXPECT_EQ(csv.rows.front()[0], 100e9);
  EXPECT_NEAR(csv.rows.back()[0], 400e9, 1e-12 * 400e9);
  EXPECT_NEAR(csv.rows[20][0], 200e9, 1e-12 * 200e9);
}

TEST_F(ResultFilesTest, CostCurveCsvHoldsTheCurveAroundTheIdentifiedModulus) {
  const Csv csv = ReadCsv(File("cost_curve.csv"));
  ASSERT_EQ(csv.rows.size(), run_->cost_curve.size());
  ASSERT_EQ(csv.rows.size(), 21u);
  double lowest = csv.rows[0][1];
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const CostCurvePoint& point = run_->cost_curve[i];
    ASSERT_TRUE(point.usable);
    EXPECT_EQ(csv.rows[i][0], point.modulus);
    EXPECT_EQ(csv.rows[i][1], point.cost);
    EXPECT_EQ(csv.rows[i][2], point.cost_gradient);
    lowest = std::min(lowest, csv.rows[i][1]);
  }
  // E* is the curve's centre and no point of the curve lies below e^2(E*)
  // (the curve's solves are tighter than the optimiser's: 1e-12 relative slack).
  EXPECT_EQ(csv.rows[10][0], run_->identified_modulus());
  EXPECT_GE(lowest, run_->cost() * (1.0 - 1e-12));
}

TEST_F(ResultFilesTest, InnerResidualCsvHoldsTheColdSolveHistoryDownToTheTolerance) {
  const Csv csv = ReadCsv(File("inner_residual.csv"));
  const std::vector<double>& history = run_->cold_solve.residual_history;
  ASSERT_EQ(csv.rows.size(), history.size());
  ASSERT_GE(csv.rows.size(), 2u);
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    EXPECT_EQ(csv.rows[i][0], i + 1.0);
    EXPECT_EQ(csv.rows[i][1], history[i]);
  }
  // From W = 0 the first residual is 1; the last meets inner.tolerance (1e-8).
  EXPECT_EQ(csv.rows.front()[1], 1.0);
  EXPECT_LE(csv.rows.back()[1], 1e-8);
}

TEST_F(ResultFilesTest, EndsCsvHoldsTheMeasuredChannelsAndTheModelAtTheIdentifiedModulus) {
  const Csv csv = ReadCsv(File("ends.csv"));
  const ChannelSet& data = run_->data;
  const Matrix& displacement = run_->solution.displacement;
  const Matrix& retrograde = run_->solution.retrograde;
  const int last = static_cast<int>(displacement.rows()) - 1;
  ASSERT_EQ(last, 25);
  ASSERT_EQ(static_cast<int>(csv.rows.size()), data.num_samples());
  for (int j = 0; j < data.num_samples(); ++j) {
    const std::vector<double>& row = csv.rows[j];
    EXPECT_EQ(row[0], j * data.time_step);
    EXPECT_EQ(row[1], data.Values("u0")[j]);
    EXPECT_EQ(row[2], displacement(0, j));
    EXPECT_EQ(row[3], data.Values("uL")[j]);
    EXPECT_EQ(row[4], displacement(last, j));
    EXPECT_EQ(row[5], data.Values("f0")[j]);
    // Model force at an end: F = F~ - w_end / alpha (docs/discrete_mcre.md section 2).
    EXPECT_EQ(row[6], data.Values("f0")[j] - retrograde(0, j) / run_->alpha);
    EXPECT_EQ(row[7], data.Values("fL")[j]);
    EXPECT_EQ(row[8], data.Values("fL")[j] - retrograde(last, j) / run_->alpha);
  }
}

// ends.csv's f0_model is the model's force at x = 0 of the clamp model: under a
// pinned clamp the load f0~ - W_0 / alpha_0 with alpha_0 = w_r L / (S E0), under a
// trusted one the reaction r(U_j) = K_01(E*) U_1 = -(E* S / l) U_1 (docs/
// trusted_clamp.md sections 1 and 9), each recomputed here from the weights and the
// bar; w_u0 and w_r differ so that a swap of the two shows.
TEST(EndsCsvTest, TheModelForceAtTheClampIsTheClampModels) {
  for (const char* clamp : {"pinned", "trusted"}) {
    SCOPED_TRACE(clamp);
    const Config config =
        LoadConfig(SourcePath("configs/quick.yaml"),
                   {std::string("mcre.clamp=") + clamp, "mcre.w_u=0.01", "mcre.w_u0=0.3",
                    "mcre.w_r=0.05", "uncertainty.samples=2"});
    const IdentificationRun run = RunIdentification(config, LoadMeasurements(config));
    ASSERT_TRUE(run.IsUsable()) << run.outer.FullReport();
    const std::string folder = FreshDirectory(std::string("ends_csv_") + clamp) + "/results";
    WriteIdentificationResults(run, folder, false);
    const Csv csv = ReadCsv(folder + "/ends.csv");
    ASSERT_EQ(static_cast<int>(csv.rows.size()), run.data.num_samples());
    const double length = 1.0, section = 1e-4, reference_modulus = 200e9;
    const double alpha0 = 0.05 * length / (section * reference_modulus);
    const double element_stiffness = run.identified_modulus() * section / (length / 25);
    double largest = 0.0, difference = 0.0;
    for (int j = 0; j < run.data.num_samples(); ++j) {
      const double expected =
          std::string(clamp) == "pinned"
              ? run.data.Values("f0")[j] - run.solution.retrograde(0, j) / alpha0
              : -element_stiffness * run.solution.displacement(1, j);
      // alpha_0 and K_01 rounded otherwise than the library's: a few ulps (measured
      // up to 3.7e-16 of max(1 N, |F_0|)).
      EXPECT_NEAR(csv.rows[j][6], expected, 4e-15 * std::max(1.0, std::abs(expected)))
          << "row " << j;
      largest = std::max(largest, std::abs(expected));
      difference = std::max(difference, std::abs(csv.rows[j][6] - run.data.Values("f0")[j]));
    }
    // The clamp force is not the measured f0 itself (the model's differs from the data).
    EXPECT_GT(difference, 1e-3 * largest);
  }
}

TEST_F(ResultFilesTest, ErrorMapCsvHoldsTheElementSharesOfTheConstitutiveGap) {
  const Csv csv = ReadCsv(File("error_map.csv"));
  ASSERT_EQ(csv.rows.size(), 25u);
  // e_el^2 = sum_j c_j h 1/2 W_j^T K_el W_j with K_el = E* S / l_e [[1, -1], [-1, 1]]
  // and the trapezoidal weights c_0 = c_m = 1/2, else 1: recomputed here from the
  // retrograde field.
  const Matrix& w = run_->solution.retrograde;
  const double h = run_->data.time_step;
  const double element_length = 1.0 / 25, section = 1e-4;
  const int m = static_cast<int>(w.cols()) - 1;
  double total = 0.0;
  for (int e = 0; e < 25; ++e) {
    double share = 0.0;
    for (int j = 0; j <= m; ++j) {
      const double c = (j == 0 || j == m) ? 0.5 : 1.0;
      const double stretch = w(e + 1, j) - w(e, j);
      share +=
          c * h * 0.5 * run_->identified_modulus() * section / element_length * stretch * stretch;
    }
    EXPECT_EQ(csv.rows[e][0], e);
    EXPECT_NEAR(csv.rows[e][1], (e + 0.5) * element_length, 1e-15);
    // Measured: the same bits (the library sums in this order); 1e-14 relative
    // leaves room for another summation order.
    EXPECT_NEAR(csv.rows[e][2], share, 1e-14 * share) << "element " << e;
    EXPECT_EQ(csv.rows[e][2], run_->error_map.share[e]);
    total += csv.rows[e][2];
  }
  for (int e = 0; e < 25; ++e) EXPECT_NEAR(csv.rows[e][3], csv.rows[e][2] / total, 1e-14);
}

TEST(TwoStageResultsTest, TheScanFilesHoldTheSearchFunctionalsCostsInItsOwnScale) {
  // The quick case with the default global search: the scan of the pinned search
  // functional, then the paper's e^2 refined near its minimum.
  Config config = LoadConfig(SourcePath("configs/quick.yaml"));
  config.search.functional = SearchFunctional::kPinned;
  const IdentificationRun run = RunIdentification(config, LoadMeasurements(config));
  ASSERT_TRUE(run.IsUsable()) << run.outer.FullReport();
  ASSERT_TRUE(run.outer.scan_of_search);
  EXPECT_EQ(run.outer.local_minima, 1);
  // Its scale is the search functional's J_rest, not the paper's e^2's.
  EXPECT_GT(std::abs(run.scan_cost_scale / run.rest_cost - 1.0), 1e-3);
  // Every evaluation of e^2 within search.refine_window of the search's minimiser.
  for (const ObjectiveEvaluation& evaluation : run.evaluations) {
    EXPECT_LE(std::abs(evaluation.modulus / run.outer.search_modulus - 1.0),
              config.search.refine_window * (1.0 + 1e-12));
  }
  const std::string folder = FreshDirectory("result_files_two_stages") + "/results";
  WriteIdentificationResults(run, folder, false);
  const Csv scan = ReadCsv(folder + "/scan.csv");
  ASSERT_EQ(scan.rows.size(), run.outer.scan_moduli.size());
  for (std::size_t i = 0; i < scan.rows.size(); ++i) {
    EXPECT_EQ(scan.rows[i][1], run.outer.scan_costs[i] * run.scan_cost_scale);
  }
  const YAML::Node summary = YAML::LoadFile(folder + "/summary.yaml");
  EXPECT_EQ(summary["scan"]["functional"].as<std::string>(), "search_pinned");
  EXPECT_EQ(summary["scan"]["search_modulus"].as<double>(), run.outer.search_modulus);
  EXPECT_EQ(summary["scan"]["local_minima"].as<int>(), 1);
  EXPECT_EQ(summary["evaluations"].as<int>(), run.outer.scan_evaluations + run.outer.evaluations);
  EXPECT_EQ(summary["optimizer"]["evaluations"].as<int>(),
            static_cast<int>(run.evaluations.size()));
}

}  // namespace
}  // namespace mcrewave
