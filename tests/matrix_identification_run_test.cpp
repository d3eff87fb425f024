// identify run and identify simulate on a structure given by matrices (model.kind:
// matrix; app/matrix_identification_run.h), end to end through the binary: the bar
// exported as matrices, its clamp dropped or kept as a support under each treatment,
// identifies the modulus the built-in bar identifies from the same CSV; a simulated CSV read back
// (its columns renamed by model.channel_map) gives the synthetic run's evaluations bit for bit; bad
// inputs exit with one line naming the file or key and leave nothing written; the plate example's
// config runs.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "identify_binary.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/model/matrix_export.h"

namespace mcrewave {
namespace {

using testing::FreshDirectory;
using testing::ReadText;
using testing::RunIdentify;
using testing::RunResult;
using testing::SourcePath;
using testing::ZoneModulus;

// The quick bar (configs/quick.yaml: 25 elements) as matrices, its zone at the
// nominal modulus 160 GPa (the start of the search, 20 % off the data's 200 GPa).
std::string WriteQuickBarMatrices(const std::string& folder) {
  const Config quick = LoadConfig(SourcePath("configs/quick.yaml"));
  std::filesystem::create_directories(folder);
  return WriteMatrixModel(folder, BarMatrixModel(BarModel(quick.model), 160e9));
}

// configs/quick.yaml for the structure of `manifest`: the keys a matrix run reads
// (AppliedConfigToYaml; the bar's geometry, which a matrix model refuses, left out),
// written into `folder`. Returns its path.
std::string WriteQuickMatrixConfig(const std::string& folder, const std::string& manifest) {
  Config config = LoadConfig(SourcePath("configs/quick.yaml"));
  config.structure.kind = ModelKind::kMatrix;
  config.structure.manifest = manifest;
  const std::string path = folder + "/quick_matrix.yaml";
  std::ofstream(path) << AppliedConfigToYaml(config);
  return path;
}

// Simulates the quick bar with `simulate_settings` into dir/data.csv and exports the
// quick bar with its clamp as a support (dof 0, channels f0 and u0) into dir/support:
// the manifest's path, "" when the simulation failed (a failure recorded).
std::string SimulateAndExportQuickBarWithSupport(const std::string& dir,
                                                 const std::string& simulate_settings) {
  const std::string quick = SourcePath("configs/quick.yaml");
  const RunResult simulated =
      RunIdentify("simulate " + quick + simulate_settings + " -q -o " + dir + "/data.csv");
  EXPECT_EQ(simulated.exit_code, 0) << simulated.output;
  if (simulated.exit_code != 0) return "";
  std::filesystem::create_directories(dir + "/support");
  return WriteMatrixModel(dir + "/support", BarMatrixModel(BarModel(LoadConfig(quick).model), 160e9,
                                                           {}, BarClampExport::kSupport));
}

// The rows of a CSV file after its header, each split at its commas.
std::vector<std::vector<std::string>> ElementMapCsvRows(const std::string& path,
                                                        std::string* header) {
  std::istringstream lines(ReadText(path));
  std::getline(lines, *header);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> cells;
    std::istringstream stream(line);
    for (std::string cell; std::getline(stream, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

// The element map of the bar's run (element,x,share,fraction,sensitivity and its noise
// std at its E*) against the matrix run's of the bar exported with its elements
// (element,x,share,fraction,nominal_share,nominal_fraction,zone,sensitivity,
// nominal_sensitivity and the sensitivity's noise std at its identified modulus).
void ExpectTheBarsElementMap(const std::string& bar_csv, const std::string& matrix_csv) {
  std::string bar_header, matrix_header;
  const auto bar = ElementMapCsvRows(bar_csv, &bar_header);
  const auto matrix = ElementMapCsvRows(matrix_csv, &matrix_header);
  EXPECT_EQ(bar_header, "element,x,share,fraction,sensitivity,sensitivity_noise_std");
  EXPECT_EQ(matrix_header,
            "element,x,share,fraction,nominal_share,nominal_fraction,zone,sensitivity,"
            "nominal_sensitivity,sensitivity_noise_std");
  ASSERT_EQ(matrix.size(), bar.size());
  double worst = 0.0, worst_sensitivity = 0.0, largest_sensitivity = 0.0;
  for (std::size_t e = 0; e < bar.size(); ++e) {
    ASSERT_EQ(matrix[e].size(), 10u);
    EXPECT_EQ(matrix[e][0], bar[e][0]);
    EXPECT_EQ(matrix[e][1], bar[e][1]);  // the midpoint, written alike
    EXPECT_EQ(matrix[e][6], "0");
    worst = std::max(worst, std::abs(std::stod(matrix[e][3]) - std::stod(bar[e][3])));
    worst_sensitivity =
        std::max(worst_sensitivity, std::abs(std::stod(matrix[e][7]) - std::stod(bar[e][4])));
    largest_sensitivity = std::max(largest_sensitivity, std::abs(std::stod(bar[e][4])));
    // The noise's spread from the run's own draws (the channels in another order than
    // the bar's: other draws).
    EXPECT_GT(std::stod(matrix[e][9]), 0.0);
  }
  // The fractions at the two runs' moduli (5.5e-8 apart) from their own solves:
  // measured 3.0e-8 apart at most.
  EXPECT_LT(worst, 1e-7);
  // The sensitivities, relative to the largest: measured 2.1e-5 apart at most (each
  // from its own inner solve to inner.tolerance, at its own modulus).
  EXPECT_LT(worst_sensitivity, 1e-4 * largest_sensitivity);
}

TEST(MatrixIdentificationRunTest, TheBarAsMatricesIdentifiesTheBuiltInBarsModulus) {
  const std::string dir = FreshDirectory("matrix_run_bar");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const std::string manifest = WriteQuickBarMatrices(dir + "/bar_matrices");
  // The same CSV, no pre-filter (its cut-off is estimated from fL for the bar and from
  // every load channel, f0 and fL, for matrices).
  const std::string data =
      " --set data.source=csv --set data.path=" + dir + "/data.csv --set prefilter.enabled=false";
  const RunResult bar = RunIdentify("run " + quick + data + " -q -o " + dir + "/bar");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  // The same config but the model: the same search functional (quick.yaml's `same`).
  const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + data +
                                         " -q -o " + dir + "/matrices");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const double bar_modulus =
      YAML::LoadFile(dir + "/bar/summary.yaml")["identified_modulus"].as<double>();
  const double matrix_modulus = ZoneModulus(dir + "/matrices/zones.csv", 0);
  // Both minimise the same e^2(E) on the same data (the general path reproduces the bar
  // to 1e-12, matrix_export_test.cpp), by different optimisers (the bar's scan and the
  // secant, which stops on a step below relative_tolerance 1e-7, NLopt L-BFGS on log E
  // to 1e-8): measured 5.5e-8 apart, relative.
  EXPECT_NEAR(matrix_modulus / bar_modulus - 1.0, 0.0, 1e-7)
      << std::setprecision(17) << "bar " << bar_modulus << " Pa, matrices " << matrix_modulus
      << " Pa";
  for (const char* file :
       {"summary.yaml", "zones.csv", "zone_evaluations.csv", "fit.csv", "error_map_dofs.csv",
        "zones.png", "fit.png", "evaluations.csv", "scan.csv", "valleys.csv", "cost_curve.csv",
        "cost_curve.png", "inner_residual.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/matrices/" + file)) << file;
  }
  // The homogeneous stage is the bar's identification on the same e^2 (the bar's own
  // BarRunModel against its export read back, the K at 160 GPa scaled): the same scan,
  // an E* as near as two refinements to outer.relative_tolerance 1e-7 along paths that
  // differ in round-off (measured 5.1e-9 apart, relative), and the bar's files.
  const YAML::Node bar_summary = YAML::LoadFile(dir + "/bar/summary.yaml");
  const YAML::Node summary = YAML::LoadFile(dir + "/matrices/summary.yaml");
  EXPECT_NEAR(summary["identified_modulus"].as<double>() / bar_modulus - 1.0, 0.0, 5e-8);
  EXPECT_EQ(summary["scan"]["points"].as<int>(), bar_summary["scan"]["points"].as<int>());
  for (const char* file : {"evaluations.csv", "scan.csv", "cost_curve.csv"}) {
    std::istringstream bar_text(ReadText(dir + "/bar/" + file));
    std::istringstream matrix_text(ReadText(dir + "/matrices/" + file));
    std::string bar_header, matrix_header;
    std::getline(bar_text, bar_header);
    std::getline(matrix_text, matrix_header);
    EXPECT_EQ(matrix_header, bar_header) << file;
  }
  // The zones: block holds what zones.csv holds, and J_rest bounds e^2.
  const YAML::Node zones = summary["zones"];
  EXPECT_EQ(zones["moduli"][0]["modulus"].as<double>(), matrix_modulus);
  EXPECT_EQ(zones["homogeneous_modulus"].as<double>(), summary["identified_modulus"].as<double>());
  EXPECT_EQ(summary["model"]["dofs"].as<int>(), 26);
  EXPECT_EQ(summary["inner"]["method"].as<std::string>(), "conjugate_gradient");  // auto's
  EXPECT_GT(zones["cost"].as<double>(), 0.0);
  EXPECT_GT(zones["homogeneous_cost"].as<double>(), 0.0);
  EXPECT_LT(zones["cost"].as<double>(), zones["nominal_cost"].as<double>());
  EXPECT_LT(zones["nominal_cost"].as<double>(), zones["cost_scale"].as<double>());
  ExpectTheBarsElementMap(dir + "/bar/error_map.csv", dir + "/matrices/error_map.csv");
  EXPECT_EQ(summary["error_map"]["peak_element"].as<int>(),
            YAML::LoadFile(dir + "/bar/summary.yaml")["error_map"]["peak_element"].as<int>());
  EXPECT_GT(summary["error_map"]["nominal_peak_fraction"].as<double>(), 0.0);
}

// The quick bar in 4 zones of equal length, exported as matrices: the zones are
// identified by the built-in bar's steps (the penalty on the jumps between consecutive
// zones, its weight from the L-curve, then the merging), and from uniform data both
// roads merge the four zones into one group at the same modulus.
TEST(MatrixIdentificationRunTest, ZonesOfTheBarAsMatricesAreRegularisedAndMergedAsTheBarsAre) {
  const std::string dir = FreshDirectory("matrix_run_zones_merged");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const Config config = LoadConfig(quick, {"model.zone_count=4"});
  std::filesystem::create_directories(dir + "/bar_matrices");
  const std::string manifest = WriteMatrixModel(
      dir + "/bar_matrices",
      BarMatrixModel(BarModel(config.model, config.zones.ElementZones(config.model)), 160e9));
  const std::string data = " --set data.source=csv --set data.path=" + dir +
                           "/data.csv --set prefilter.enabled=false"
                           " --set zone_identification.merge_zones=true";
  const RunResult bar =
      RunIdentify("run " + quick + data + " --set model.zone_count=4 -q -o " + dir + "/bar");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + data +
                                         " -q -o " + dir + "/matrices");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const YAML::Node bar_zones = YAML::LoadFile(dir + "/bar/summary.yaml")["zones"];
  const YAML::Node zones = YAML::LoadFile(dir + "/matrices/summary.yaml")["zones"];
  // Both weights chosen for a discrepancy target (the matrix run's noise levels from its
  // own channels: measured 1.75e-5 against the bar's 1.88e-5).
  EXPECT_GT(zones["target_misfit"].as<double>(), 0.0);
  EXPECT_GT(bar_zones["target_misfit"].as<double>(), 0.0);
  EXPECT_EQ(zones["groups"].as<int>(), 1);
  EXPECT_EQ(bar_zones["groups"].as<int>(), 1);
  // The merged group's refit on p = log(E / E_nom) and on p = log(E / E*), J_rest at 160 GPa
  // and at E*: measured 5e-10 apart, relative (the bar's summary prints 10 digits).
  for (int z = 0; z < 4; ++z) {
    const double bar_modulus = bar_zones["moduli"][z]["modulus"].as<double>();
    EXPECT_NEAR(zones["moduli"][z]["modulus"].as<double>() / bar_modulus - 1.0, 0.0, 5e-9)
        << std::setprecision(17) << "zone " << z << ": bar " << bar_modulus << " Pa, matrices "
        << zones["moduli"][z]["modulus"].as<double>() << " Pa";
  }
}

// Many zones on a trusted support whose displacement the data hold are identified with
// the support measured, as the bar's zones are (zone_identification.measured_clamp,
// docs/boundaries.md section 8): the quick bar in 3 zones with its clamp a support, run
// trusted, gives the zones of the run told the measured clamp and its scan
// (MeasuredSupportConfig: quick.yaml's w_u and w_e are the paper's; the search measured
// at 0.1) to the bit, and trusted ones with the key off.
TEST(MatrixIdentificationRunTest, ZonesOnATrustedSupportAreIdentifiedWithTheSupportMeasured) {
  const std::string dir = FreshDirectory("matrix_run_zones_trusted");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const Config config = LoadConfig(quick);
  std::vector<int> zones(config.model.elements);
  for (int e = 0; e < config.model.elements; ++e) zones[e] = 3 * e / config.model.elements;
  std::filesystem::create_directories(dir + "/support");
  const std::string manifest = WriteMatrixModel(
      dir + "/support",
      BarMatrixModel(BarModel(config.model, zones), 160e9, {}, BarClampExport::kSupport));
  const std::string run = "run " + WriteQuickMatrixConfig(dir, manifest) +
                          " --set data.source=csv --set data.path=" + dir + "/data.csv -q -o " +
                          dir;
  const std::pair<const char*, const char*> runs[] = {
      {"measured",
       " --set mcre.clamp=measured --set search.functional=measured --set search.w_u=1 "
       "--set search.w_e=1"},
      {"trusted", " --set mcre.clamp=trusted"},
      {"trusted_kept", " --set mcre.clamp=trusted --set zone_identification.measured_clamp=false"}};
  for (const auto& [name, settings] : runs) {
    const RunResult result = RunIdentify(run + "/" + name + settings);
    ASSERT_EQ(result.exit_code, 0) << result.output;
  }
  auto clamp_of = [&](const char* name) {
    return YAML::LoadFile(dir + "/" + name + "/summary.yaml")["zones"]["clamp"].as<std::string>();
  };
  EXPECT_EQ(clamp_of("measured"), "measured");
  EXPECT_EQ(clamp_of("trusted"), "measured");
  EXPECT_EQ(clamp_of("trusted_kept"), "trusted");
  for (int z = 0; z < 3; ++z) {
    EXPECT_EQ(ZoneModulus(dir + "/trusted/zones.csv", z),
              ZoneModulus(dir + "/measured/zones.csv", z));
    EXPECT_NE(ZoneModulus(dir + "/trusted_kept/zones.csv", z),
              ZoneModulus(dir + "/measured/zones.csv", z));
  }
}

// The support test's ramp on the one road (docs/boundaries.md section 10): the quick bar
// on a spring of 10 E S / L, exported with its clamp as a support and trusted, the ramp
// widened to [0.5, 1000] so that its t lies inside. The matrix run weighs the trusted and the
// measured E by the bar's run's a, and its E* is the bar's.
TEST(MatrixIdentificationRunTest, TheRampWeighsBothTreatmentsOfTheBarAsMatrices) {
  const std::string dir = FreshDirectory("matrix_run_ramp");
  const std::string quick = SourcePath("configs/quick.yaml");
  const std::string manifest =
      SimulateAndExportQuickBarWithSupport(dir, " --set data.support_stiffness=2e8");
  ASSERT_FALSE(manifest.empty());
  const std::string settings = " --set data.source=csv --set data.path=" + dir +
                               "/data.csv --set prefilter.enabled=false --set mcre.clamp=trusted"
                               " --set mcre.support_check_ramp_start=0.5"
                               " --set mcre.support_check_threshold=1000 -q -o " +
                               dir;
  const RunResult bar = RunIdentify("run " + quick + settings + "/bar");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  const RunResult matrices =
      RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + settings + "/matrices");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const YAML::Node b = YAML::LoadFile(dir + "/bar/summary.yaml")["supports"];
  const YAML::Node m = YAML::LoadFile(dir + "/matrices/summary.yaml");
  const YAML::Node supports = m["supports"];
  const double weight = supports["measured_weight"].as<double>();
  ASSERT_GT(weight, 0.0);
  ASSERT_LT(weight, 1.0);
  // The same test of the same raw data on both roads (measured: the same bits).
  EXPECT_NEAR(weight, b["measured_weight"].as<double>(), 1e-12);
  EXPECT_DOUBLE_EQ(m["identified_modulus"].as<double>(),
                   (1.0 - weight) * supports["trusted_modulus"].as<double>() +
                       weight * supports["measured_modulus"].as<double>());
  // Each treatment's E on both roads: the same e^2 along paths that differ in round-off
  // (measured: 3.1e-9 trusted, 3.0e-9 measured apart, relative; a = 0.047).
  for (const char* key : {"trusted_modulus", "measured_modulus"}) {
    EXPECT_NEAR(supports[key].as<double>() / b[key].as<double>() - 1.0, 0.0, 5e-8) << key;
  }
}

// The quick bar exported with its clamp as a support (dof 0, channels f0 and u0) under
// each treatment of mcre.clamp: the run through the manifest identifies the built-in
// bar's modulus from the same CSV.
TEST(MatrixIdentificationRunTest, TheBarWithItsClampAsASupportIdentifiesTheBuiltInBarsModulus) {
  const std::string dir = FreshDirectory("matrix_run_support");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const Config config = LoadConfig(quick);
  std::filesystem::create_directories(dir + "/support");
  const std::string manifest =
      WriteMatrixModel(dir + "/support",
                       BarMatrixModel(BarModel(config.model), 160e9, {}, BarClampExport::kSupport));
  const std::string data =
      " --set data.source=csv --set data.path=" + dir + "/data.csv --set prefilter.enabled=false";
  for (const char* clamp : {"measured", "trusted", "pinned"}) {
    SCOPED_TRACE(clamp);
    const std::string treatment = std::string(" --set mcre.clamp=") + clamp;
    // Both scan their own e^2 (quick.yaml's search.functional: same).
    const RunResult bar =
        RunIdentify("run " + quick + data + treatment + " -q -o " + dir + "/bar_" + clamp);
    ASSERT_EQ(bar.exit_code, 0) << bar.output;
    const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + data +
                                           treatment + " -q -o " + dir + "/matrices_" + clamp);
    ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
    const double bar_modulus =
        YAML::LoadFile(dir + "/bar_" + clamp + "/summary.yaml")["identified_modulus"].as<double>();
    const double matrix_modulus = ZoneModulus(dir + "/matrices_" + clamp + "/zones.csv", 0);
    // The same e^2(E) (matrix_supports_test.cpp: to 1e-13), different optimisers (the
    // bar's scan and the secant, which stops on a step below relative_tolerance 1e-7,
    // NLopt L-BFGS on log E to 1e-8): measured 5.5e-8 (measured), 2.1e-8 (trusted) and
    // below 1e-8 (pinned) apart, relative.
    EXPECT_NEAR(matrix_modulus / bar_modulus - 1.0, 0.0, 1e-7)
        << std::setprecision(17) << "bar " << bar_modulus << " Pa, matrices " << matrix_modulus
        << " Pa";
    const YAML::Node summary = YAML::LoadFile(dir + "/matrices_" + clamp + "/summary.yaml");
    EXPECT_EQ(summary["model"]["supports"].as<int>(), 1);
    // The homogeneous stage's E*, the bar's identification on the same e^2 along paths
    // that differ in round-off: measured 5.1e-9 (measured), 1.0e-9 (trusted) and 2.1e-9
    // (pinned) apart, relative.
    EXPECT_NEAR(summary["identified_modulus"].as<double>() / bar_modulus - 1.0, 0.0, 5e-8);
  }
  // With the pre-filter on, both roads take its cut-off from fL alone (the clamp's
  // force f0 is the support's channel, no load), the same frequency to the bit.
  const std::string filtered = " --set data.source=csv --set data.path=" + dir + "/data.csv";
  const RunResult bar = RunIdentify("run " + quick + filtered + " -q -o " + dir + "/bar_filtered");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + filtered +
                                         " -q -o " + dir + "/matrices_filtered");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const double bar_cutoff =
      YAML::LoadFile(dir + "/bar_filtered/summary.yaml")["prefilter"]["cutoff_frequency"]
          .as<double>();
  EXPECT_GT(bar_cutoff, 0.0);
  EXPECT_EQ(YAML::LoadFile(dir + "/matrices_filtered/summary.yaml")["prefilter"]["cutoff_frequency"]
                .as<double>(),
            bar_cutoff);
}

// A spring of 10 E S / L at the quick bar's clamp, SNR 20, the clamp trusted: the bar and
// its export with the clamp as a support test u0 against f0 alike, both find the clamp
// contradicted and identify with it measured, the same modulus.
TEST(MatrixIdentificationRunTest, ASpringAtTheSupportSwitchesTheMatrixRunAsItSwitchesTheBars) {
  const std::string dir = FreshDirectory("matrix_run_support_spring");
  const std::string quick = SourcePath("configs/quick.yaml");
  const std::string manifest = SimulateAndExportQuickBarWithSupport(
      dir, " --set data.support_stiffness=2e8 --set data.snr=20");
  ASSERT_FALSE(manifest.empty());
  const Config config = LoadConfig(quick);
  const std::string settings = " --set data.source=csv --set data.path=" + dir +
                               "/data.csv --set mcre.clamp=trusted --set mcre.w_u=1e-7 "
                               "--set mcre.w_e=1e-7 --set mcre.w_r=1e-6";
  const RunResult bar = RunIdentify("run " + quick + settings + " -q -o " + dir + "/bar");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + settings +
                                         " -q -o " + dir + "/matrices");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const YAML::Node bar_summary = YAML::LoadFile(dir + "/bar/summary.yaml");
  const YAML::Node matrix_summary = YAML::LoadFile(dir + "/matrices/summary.yaml");
  for (const YAML::Node& summary : {bar_summary, matrix_summary}) {
    EXPECT_TRUE(summary["supports"]["switched"].as<bool>());
    EXPECT_EQ(summary["supports"]["tests"][0]["support"].as<std::string>(), "clamp");
    EXPECT_EQ(summary["config"]["mcre"]["clamp"].as<std::string>(), "measured");
  }
  const double bar_statistic = bar_summary["supports"]["tests"][0]["statistic"].as<double>();
  const double matrix_statistic = matrix_summary["supports"]["tests"][0]["statistic"].as<double>();
  // Measured: t = 47.29 on both roads, to the bit (the same f0 pre-filtered alike); the
  // moduli 6.7e-8 apart, relative (both refined to outer.relative_tolerance 1e-7, from
  // windows their searches, on a coarser grid, placed a round-off apart; 4.2e-9 with
  // the search on the data's own grid), and +0.24 % from the bar's 200 GPa.
  EXPECT_GT(bar_statistic, 10.0);
  EXPECT_NEAR(matrix_statistic / bar_statistic - 1.0, 0.0, 1e-12);
  EXPECT_NEAR(
      ZoneModulus(dir + "/matrices/zones.csv", 0) / bar_summary["identified_modulus"].as<double>() -
          1.0,
      0.0, 2e-7);
  EXPECT_NEAR(bar_summary["identified_modulus"].as<double>() / config.model.modulus - 1.0, 0.0,
              1e-2);
}

// The same manifest by least squares (outer.functional: least_squares): the support
// held, its force f0 an output weighted by 1 / s_f^2, as the built-in bar's least
// squares holds its clamp and compares f0; both identify the same modulus from the CSV.
TEST(MatrixIdentificationRunTest,
     TheBarWithItsClampAsASupportIdentifiesTheBarsLeastSquaresModulus) {
  const std::string dir = FreshDirectory("matrix_run_support_ls");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const Config config = LoadConfig(quick);
  std::filesystem::create_directories(dir + "/support");
  const std::string manifest =
      WriteMatrixModel(dir + "/support",
                       BarMatrixModel(BarModel(config.model), 160e9, {}, BarClampExport::kSupport));
  const std::string data = " --set data.source=csv --set data.path=" + dir +
                           "/data.csv --set prefilter.enabled=false" +
                           " --set outer.functional=least_squares";
  const RunResult bar = RunIdentify("run " + quick + data + " -q -o " + dir + "/bar");
  ASSERT_EQ(bar.exit_code, 0) << bar.output;
  // quick.yaml's mcre.clamp (measured) is ignored by both: least squares holds the clamp.
  const RunResult matrices = RunIdentify("run " + WriteQuickMatrixConfig(dir, manifest) + data +
                                         " -q -o " + dir + "/matrices");
  ASSERT_EQ(matrices.exit_code, 0) << matrices.output;
  const YAML::Node bar_summary = YAML::LoadFile(dir + "/bar/summary.yaml");
  const double bar_modulus = bar_summary["identified_modulus"].as<double>();
  const double matrix_modulus = ZoneModulus(dir + "/matrices/zones.csv", 0);
  // The same J(E) (matrix_output_error_objective_test.cpp: to 1e-13), different
  // optimisers (the bar's scan and BOBYQA to relative_tolerance 1e-7, NLopt L-BFGS on
  // log E to 1e-8): measured 2.0e-9 apart, relative.
  EXPECT_NEAR(matrix_modulus / bar_modulus - 1.0, 0.0, 1e-8)
      << std::setprecision(17) << "bar " << bar_modulus << " Pa, matrices " << matrix_modulus
      << " Pa";
  const YAML::Node summary = YAML::LoadFile(dir + "/matrices/summary.yaml");
  EXPECT_EQ(summary["functional"].as<std::string>(), "least_squares");
  EXPECT_EQ(summary["model"]["supports"].as<int>(), 1);
  EXPECT_EQ(summary["misfit_levels"]["source"].as<std::string>(), "data_differences");
  // The levels of the bar's DifferenceNoiseLevels: s_u over u0 and uL, s_f over f0 and fL.
  const YAML::Node bar_levels = bar_summary["uncertainty"];
  EXPECT_EQ(summary["misfit_levels"]["displacement"].as<double>(),
            bar_levels["noise_std_displacement"].as<double>());
  EXPECT_EQ(summary["misfit_levels"]["force"].as<double>(),
            bar_levels["noise_std_force"].as<double>());
  EXPECT_LT(summary["zones"]["cost"].as<double>(), summary["zones"]["nominal_cost"].as<double>());
  // The homogeneous stage is the bar's least squares on the same J, the same scan and
  // BOBYQA along paths that differ in round-off: measured 1.6e-9 apart, relative.
  EXPECT_NEAR(summary["identified_modulus"].as<double>() / bar_modulus - 1.0, 0.0, 2e-8);
  EXPECT_EQ(summary["scan"]["points"].as<int>(), bar_summary["scan"]["points"].as<int>());
}

// The quick bar's manifest with its loads and sensors as matrices (G.mtx with its channel
// names, H_1.mtx with theirs: MatrixModelLayout::kMatrices) runs as its per-file manifest
// does: zones.csv, fit.csv and evaluations.csv byte for byte.
TEST(MatrixIdentificationRunTest, LoadAndObservationMatricesRunAsThePerFileManifest) {
  const std::string dir = FreshDirectory("matrix_run_channel_matrices");
  const std::string quick = SourcePath("configs/quick.yaml");
  ASSERT_EQ(RunIdentify("simulate " + quick + " -q -o " + dir + "/data.csv").exit_code, 0);
  const Config config = LoadConfig(quick);
  const MatrixModelData bar = BarMatrixModel(BarModel(config.model), 160e9);
  std::filesystem::create_directories(dir + "/files");
  std::filesystem::create_directories(dir + "/matrices");
  const std::string per_file = WriteMatrixModel(dir + "/files", bar);
  const std::string matrices =
      WriteMatrixModel(dir + "/matrices", bar, MatrixModelLayout::kMatrices);
  ASSERT_NE(ReadText(matrices).find("loads_matrix"), std::string::npos);
  ASSERT_EQ(ReadText(matrices).find("load_f0.mtx"), std::string::npos);
  const std::string run = "run " + WriteQuickMatrixConfig(dir, per_file) +
                          " --set data.source=csv --set data.path=" + dir +
                          "/data.csv --set mcre.clamp=trusted -q";
  const RunResult files_run =
      RunIdentify(run + " --set model.manifest=" + per_file + " -o " + dir + "/run_files");
  ASSERT_EQ(files_run.exit_code, 0) << files_run.output;
  const RunResult matrices_run =
      RunIdentify(run + " --set model.manifest=" + matrices + " -o " + dir + "/run_matrices");
  ASSERT_EQ(matrices_run.exit_code, 0) << matrices_run.output;
  for (const char* file : {"zones.csv", "fit.csv", "evaluations.csv"}) {
    const std::string expected = ReadText(dir + "/run_files/" + file);
    EXPECT_FALSE(expected.empty()) << file;
    EXPECT_EQ(ReadText(dir + "/run_matrices/" + file), expected) << file;
  }
}

TEST(MatrixIdentificationRunTest, ASimulatedCsvReadBackGivesTheSyntheticRunsModuli) {
  const std::string dir = FreshDirectory("matrix_run_simulate");
  const std::string manifest = WriteQuickBarMatrices(dir + "/bar_matrices");
  const std::string config = dir + "/matrix.yaml";
  std::ofstream(config) << "model:\n  kind: matrix\n  manifest: bar_matrices/model.yaml\n"
                           "  channel_map: {fL: hammer, uL: tip}\n"
                           "data:\n  truth_moduli: [210e9]\n  snr: 20\n  seed: 3\n"
                           "time:\n  window: 0.432e-3\n  step: 1.44e-6\n"
                           "prefilter:\n  enabled: false\n";
  const RunResult synthetic = RunIdentify("run " + config + " -q -o " + dir + "/synthetic");
  ASSERT_EQ(synthetic.exit_code, 0) << synthetic.output;
  const RunResult simulate = RunIdentify("simulate " + config + " -q -o " + dir + "/data.csv");
  ASSERT_EQ(simulate.exit_code, 0) << simulate.output;
  EXPECT_EQ(ReadText(dir + "/data.csv").substr(0, 20), "t,f0,hammer,u0,tip\n0");
  const RunResult from_csv = RunIdentify("run " + config + " --set data.source=csv" +
                                         " --set data.path=data.csv -q -o " + dir + "/csv");
  ASSERT_EQ(from_csv.exit_code, 0) << from_csv.output;
  // The CSV holds 17 digits: the same data, the same evaluations and modulus, bit for
  // bit (zones.csv differs in the truth, known to the synthetic run only).
  EXPECT_EQ(ReadText(dir + "/synthetic/evaluations.csv"), ReadText(dir + "/csv/evaluations.csv"));
  EXPECT_EQ(ReadText(dir + "/synthetic/error_map_dofs.csv"),
            ReadText(dir + "/csv/error_map_dofs.csv"));
  EXPECT_EQ(ZoneModulus(dir + "/synthetic/zones.csv", 0), ZoneModulus(dir + "/csv/zones.csv", 0));
}

// The quick bar as matrices identified with the streaming CG named, and with auto
// under a field limit it exceeds, against the stored-field CG's run: the same modulus
// (measured 8.3e-9 apart, relative, either way; the homogeneous stage's E* 7.6e-9), e^2
// at the identified and nominal moduli, and the summary naming the solver.
TEST(MatrixIdentificationRunTest, TheStreamingSolverIdentifiesTheStoredFieldRunsModulus) {
  const std::string dir = FreshDirectory("matrix_run_streaming");
  WriteQuickBarMatrices(dir + "/bar_matrices");
  const std::string config = dir + "/matrix.yaml";
  std::ofstream(config) << "model:\n  kind: matrix\n  manifest: bar_matrices/model.yaml\n"
                           "data:\n  truth_moduli: [210e9]\n  snr: 20\n  seed: 3\n"
                           "time:\n  window: 0.432e-3\n  step: 1.44e-6\n"
                           "prefilter:\n  enabled: false\n";
  const RunResult stored = RunIdentify("run " + config + " -q -o " + dir + "/stored");
  ASSERT_EQ(stored.exit_code, 0) << stored.output;
  const RunResult named = RunIdentify(
      "run " + config + " --set inner.method=streaming_conjugate_gradient -q -o " + dir + "/named");
  ASSERT_EQ(named.exit_code, 0) << named.output;
  // 26 dofs, 300 steps: 626080 bytes of fields.
  const RunResult automatic =
      RunIdentify("run " + config + " --set inner.max_field_bytes=626079 -q -o " + dir + "/auto");
  ASSERT_EQ(automatic.exit_code, 0) << automatic.output;
  const double reference = ZoneModulus(dir + "/stored/zones.csv", 0);
  for (const char* run : {"named", "auto"}) {
    SCOPED_TRACE(run);
    const std::string out = dir + "/" + run;
    const double modulus = ZoneModulus(out + "/zones.csv", 0);
    EXPECT_NEAR(modulus / reference - 1.0, 0.0, 1e-7)
        << std::setprecision(17) << "stored " << reference << " Pa, streamed " << modulus << " Pa";
    const YAML::Node summary = YAML::LoadFile(out + "/summary.yaml");
    EXPECT_NEAR(
        summary["identified_modulus"].as<double>() /
                YAML::LoadFile(dir + "/stored/summary.yaml")["identified_modulus"].as<double>() -
            1.0,
        0.0, 1e-7);
    EXPECT_EQ(summary["inner"]["method"].as<std::string>(), "streaming_conjugate_gradient");
    EXPECT_TRUE(std::filesystem::exists(out + "/error_map_dofs.csv"));
    // The element map from the shares and picture rows the streaming sweeps summed: the
    // stored-field run's peak, its fraction as near as the moduli are (measured 8.6e-9
    // apart, relative, either way).
    EXPECT_TRUE(std::filesystem::exists(out + "/error_map.csv"));
    EXPECT_TRUE(std::filesystem::exists(out + "/error_map_spacetime.dat"));
    const YAML::Node stored_map = YAML::LoadFile(dir + "/stored/summary.yaml")["error_map"];
    EXPECT_EQ(summary["error_map"]["peak_element"].as<int>(), stored_map["peak_element"].as<int>());
    EXPECT_NEAR(summary["error_map"]["peak_fraction"].as<double>(),
                stored_map["peak_fraction"].as<double>(),
                1e-7 * stored_map["peak_fraction"].as<double>());
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/stored/error_map.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/stored/error_map_spacetime.dat"));
  const YAML::Node stored_summary = YAML::LoadFile(dir + "/stored/summary.yaml");
  const YAML::Node streamed_summary = YAML::LoadFile(dir + "/named/summary.yaml");
  const YAML::Node streamed_zones = streamed_summary["zones"],
                   stored_zones = stored_summary["zones"];
  EXPECT_NEAR(streamed_zones["cost"].as<double>(), stored_zones["cost"].as<double>(),
              1e-6 * stored_zones["cost"].as<double>());
  EXPECT_NEAR(streamed_zones["nominal_cost"].as<double>(),
              stored_zones["nominal_cost"].as<double>(),
              1e-9 * stored_zones["nominal_cost"].as<double>());
}

TEST(MatrixIdentificationRunTest, BadInputsExitWithOneLineAndWriteNothing) {
  const std::string dir = FreshDirectory("matrix_run_refusals");
  const std::string manifest = WriteQuickBarMatrices(dir + "/bar_matrices");
  const std::string base = dir + "/base.yaml";
  std::ofstream(base) << "model:\n  kind: matrix\n  manifest: bar_matrices/model.yaml\n"
                         "time:\n  window: 0.432e-3\n  step: 1.44e-6\n";
  std::ofstream(dir + "/short.csv") << "t,f0,fL,u0\n0,0,0,0\n1.44e-6,0,1,0\n";
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      // A channel of the map missing from the CSV: the file, the column, the channel.
      {"--set data.source=csv --set data.path=short.csv --set 'model.channel_map={uL: tip}'",
       {dir + "/short.csv:1", "lacks the column 'tip' of the model's channel 'uL'",
        "model.channel_map"}},
      // A channel missing under its own name.
      {"--set data.source=csv --set data.path=short.csv", {"short.csv:1", "lacks the column 'uL'"}},
      {"--set 'model.channel_map={uX: tip}'",
       {"model.channel_map: 'uX' is not a channel of the manifest"}},
      {"--set model.manifest=missing.yaml", {"model.manifest: cannot read manifest"}},
      {"--set 'data.truth_moduli=[1e11, 2e11]'", {"data.truth_moduli has 2 moduli", "1 zones"}},
      {"--set outer.lower_bound=170e9 --set outer.initial=180e9",
       {"outer.lower_bound and outer.upper_bound", "nominal modulus 1.6e+11 Pa of zone 'zone0'"}},
      {"--set model.zone_count=2", {"model.zone_count applies to the bar only"}},
      {"--set 'data.channels=[uL, uX]'",
       {"data.channels: 'uX' is not a sensor of the manifest", "loads and supports"}},
      {"--set 'data.channels=[uL, uL]'", {"data.channels: 'uL' is listed twice"}},
  };
  for (const auto& [overrides, reasons] : cases) {
    const std::string out = dir + "/out";
    const RunResult run = RunIdentify("run " + base + " " + overrides + " -o " + out);
    EXPECT_EQ(run.exit_code, 2) << overrides << "\n" << run.output;
    EXPECT_EQ(run.output.rfind("error: ", 0), 0u) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
    for (const std::string& reason : reasons) {
      EXPECT_NE(run.output.find(reason), std::string::npos) << overrides << "\n" << run.output;
    }
    EXPECT_FALSE(std::filesystem::exists(out)) << overrides;
  }
  // simulate writes nothing either, and study refuses every study but robustness.
  const RunResult simulate = RunIdentify("simulate " + base +
                                         " --set 'model.channel_map={uX: tip}' -o " + dir + "/x.csv");
  EXPECT_EQ(simulate.exit_code, 2) << simulate.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.csv"));
  const RunResult study = RunIdentify("study " + base + " -o " + dir + "/study");
  EXPECT_EQ(study.exit_code, 2) << study.output;
  EXPECT_NE(study.output.find("study.kind 'all' runs on the bar only; with model.kind 'matrix' "
                              "use study.kind: robustness or comparator"),
            std::string::npos)
      << study.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/study"));
}

// identify study with study.kind robustness on a matrix model: its folder and the README.
TEST(MatrixIdentificationRunTest, TheRobustnessStudyRunsOnAMatrixModel) {
  const std::string dir = FreshDirectory("matrix_run_study");
  WriteQuickBarMatrices(dir + "/bar_matrices");
  const std::string config = dir + "/matrix.yaml";
  std::ofstream(config) << "model:\n  kind: matrix\n  manifest: bar_matrices/model.yaml\n"
                           "data:\n  truth_moduli: [200e9]\n"
                           "time:\n  window: 0.432e-3\n  step: 1.44e-6\n"
                           "study:\n  kind: robustness\n  robustness:\n    snr: [.inf, 20]\n"
                           "    seeds: 2\n  threads: 2\n";
  const RunResult study = RunIdentify("study " + config + " -o " + dir + "/study");
  ASSERT_EQ(study.exit_code, 0) << study.output;
  EXPECT_NE(study.output.find("matrix model " + dir + "/bar_matrices/model.yaml"),
            std::string::npos)
      << study.output;
  EXPECT_NE(study.output.find("robustness: 3 / 3 runs"), std::string::npos) << study.output;
  const std::string runs = ReadText(dir + "/study/robustness/runs.csv");
  // One zone: the bar's layout, one row per run.
  EXPECT_EQ(runs.substr(0, runs.find('\n')),
            "snr,snr_index,seed,converged,identified_modulus,relative_error,evaluations,"
            "scan_evaluations,sweeps,local_minima");
  EXPECT_EQ(std::count(runs.begin(), runs.end(), '\n'), 4);
  EXPECT_NE(ReadText(dir + "/study/README.md").find("## Robustness (`robustness/`)"),
            std::string::npos);
}

// Fields above inner.max_field_bytes are refused before the data are simulated when a
// stored-field method is named, exit 2, naming what fits instead; auto streams.
TEST(MatrixIdentificationRunTest, FieldsAboveTheLimitAreRefusedAtLoadNamingWhatFits) {
  const std::string dir = FreshDirectory("matrix_run_field_bytes");
  WriteQuickBarMatrices(dir + "/bar_matrices");
  const std::string base = dir + "/base.yaml";
  std::ofstream(base) << "model:\n  kind: matrix\n  manifest: bar_matrices/model.yaml\n"
                         "time:\n  window: 0.432e-3\n  step: 1.44e-6\n";
  // 26 dofs, 300 steps: 10 fields of 26 x 301 doubles, 626080 bytes.
  const std::string out = dir + "/out";
  const RunResult run = RunIdentify(
      "run " + base + " --set inner.max_field_bytes=626079 --set inner.method=conjugate_gradient" +
      " -o " + out);
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  EXPECT_NE(run.output.find("error: " + base + ": model.manifest " + dir +
                            "/bar_matrices/model.yaml (26 dofs) and 300 steps (time.window / "
                            "time.step) need 626080 bytes for inner.method 'conjugate_gradient'"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("above inner.max_field_bytes = 626079; use inner.method: "
                            "streaming_conjugate_gradient (or auto), which stores no space-time "
                            "field, raise inner.max_field_bytes, or use a coarser mesh (fewer "
                            "dofs), a shorter window or a larger time step"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // At the fields' bytes the check passes, and auto is never refused: it streams.
  const Config config = LoadConfig(base, {"inner.max_field_bytes=626080"});
  EXPECT_NO_THROW(CheckMatrixModelFieldBytes(config, LoadMatrixModel(config)));
  const Config streams = LoadConfig(base, {"inner.max_field_bytes=626079"});
  EXPECT_NO_THROW(CheckMatrixModelFieldBytes(streams, LoadMatrixModel(streams)));
}

// The plate example's config (configs/plate.yaml) on half its window: both zones from
// the finer mesh's data at SNR 20 (seed 1). Measured on the full window: -2.40 %
// (matrix) and -1.16 % (inclusion), mostly the coarse mesh's discretisation error; on
// the half window -2.16 % and -7.69 %, checked to half a percentage point (the run is
// seeded: a change of these figures is a change of the code).
TEST(MatrixIdentificationRunTest, ThePlateConfigIdentifiesBothZones) {
  const std::string dir = FreshDirectory("matrix_run_plate");
  const RunResult run = RunIdentify("run " + SourcePath("configs/plate.yaml") +
                                    " --set time.window=1e-4 -q -o " + dir);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NEAR(ZoneModulus(dir + "/zones.csv", 0) / 200e9 - 1.0, -0.0216, 0.005);
  EXPECT_NEAR(ZoneModulus(dir + "/zones.csv", 1) / 140e9 - 1.0, -0.0769, 0.005);
  EXPECT_TRUE(std::filesystem::exists(dir + "/zones.png"));
  // Without supports and at the search's weights, the search functional is e^2 itself:
  // one stage, its scan on e^2.
  const YAML::Node summary = YAML::LoadFile(dir + "/summary.yaml");
  EXPECT_EQ(summary["scan"]["functional"].as<std::string>(), "same");
  EXPECT_EQ(summary["inner"]["search_sweeps"].as<int>(), 0);
  // The uncertainty of both moduli from the config's 8 noise draws at the data's SNR
  // (zone_uncertainty_test.cpp checks the figure against re-identification).
  const YAML::Node uncertainty = summary["uncertainty"];
  EXPECT_EQ(uncertainty["message"].as<std::string>(), "ok");
  EXPECT_EQ(uncertainty["samples"].as<int>(), 8);
  EXPECT_EQ(uncertainty["noise_source"].as<std::string>(), "synthetic_snr");
  for (int z = 0; z < 2; ++z) {
    const double relative = uncertainty["zones"][z]["relative_std_dev"].as<double>();
    EXPECT_GT(relative, 0.0) << z;
    EXPECT_LT(relative, 0.05) << z;
  }
}

// The plate example's config with its element blocks regrouped into a 3 x 1 grid
// (model.zoning: grid): noise-free data of the coarse mesh itself at a homogeneous
// 200 GPa, whose two manifest zones stay the truth's, without the pre-filter. Every grid
// zone at 200 GPa: measured exactly (the scan's sample at the nominal modulus; the
// coupled solves accepted at the sweeps' round-off, the zones' start a minimum).
TEST(MatrixIdentificationRunTest, APlateGridOfZonesIsIdentifiedFromItsElementBlocks) {
  const std::string dir = FreshDirectory("matrix_run_plate_grid");
  const RunResult run = RunIdentify(
      "run " + SourcePath("configs/plate.yaml") +
      " --set model.zoning=grid --set model.zone_grid=[3,1] --set data.truth_manifest=" +
      SourcePath("configs/plate/coarse/model_axial.yaml") +
      " --set data.truth_moduli=[200e9,200e9] --set data.snr=.inf --set time.window=1e-4"
      " --set prefilter.enabled=false --set uncertainty.samples=2 -q -o " +
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string zones = ReadText(dir + "/zones.csv");
  EXPECT_NE(zones.find("grid_2_0"), std::string::npos) << zones;
  for (int z = 0; z < 3; ++z) {
    EXPECT_NEAR(ZoneModulus(dir + "/zones.csv", z) / 200e9 - 1.0, 0.0, 1e-12) << "zone " << z;
  }
  // A grid over the positions' two coordinates needs two counts.
  const RunResult refused = RunIdentify("run " + SourcePath("configs/plate.yaml") +
                                        " --set model.zoning=grid --set model.zone_grid=[3]"
                                        " -q -o " +
                                        dir + "_refused");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("model.zone_grid must hold one positive count per coordinate"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "_refused"));
}

// model.free_zones on the plate's 3 x 1 grid: grid_1_0 free, the other two tied into
// 'rest'; noise-free data of the model itself give both 200 GPa. A name that is not a
// zone of the layout, one listed twice, or every zone listed is refused naming the key.
TEST(MatrixIdentificationRunTest, FreeZonesKeepTheirModulusAndTieTheOthers) {
  const std::string dir = FreshDirectory("matrix_run_free_zones");
  const std::string base =
      "run " + SourcePath("configs/plate.yaml") +
      " --set model.zoning=grid --set model.zone_grid=[3,1] --set data.truth_manifest=" +
      SourcePath("configs/plate/coarse/model_axial.yaml") +
      " --set data.truth_moduli=[200e9,200e9] --set data.snr=.inf --set time.window=1e-4"
      " --set prefilter.enabled=false --set uncertainty.samples=2 -q ";
  const RunResult run = RunIdentify(base + "--set model.free_zones=[grid_1_0] -o " + dir);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string zones = ReadText(dir + "/zones.csv");
  EXPECT_NE(zones.find(",rest,"), std::string::npos) << zones;
  EXPECT_NE(zones.find(",grid_1_0,"), std::string::npos) << zones;
  EXPECT_EQ(zones.find("grid_0_0"), std::string::npos) << zones;
  for (int z = 0; z < 2; ++z) {
    // Measured: 200 GPa to the printed digits, as the three free zones.
    EXPECT_NEAR(ZoneModulus(dir + "/zones.csv", z) / 200e9 - 1.0, 0.0, 1e-12) << "zone " << z;
  }
  const std::pair<std::string, std::string> refusals[] = {
      {"[grid_7_0]", "model.free_zones: 'grid_7_0' is not a zone of model.zoning grid"},
      {"[grid_1_0,grid_1_0]", "model.free_zones: 'grid_1_0' is listed twice"},
      {"[grid_0_0,grid_1_0,grid_2_0]", "model.free_zones lists every zone"},
  };
  for (const auto& [list, reason] : refusals) {
    const RunResult refused =
        RunIdentify(base + "--set 'model.free_zones=" + list + "' -o " + dir + "_refused");
    EXPECT_EQ(refused.exit_code, 2) << refused.output;
    EXPECT_NE(refused.output.find(reason), std::string::npos) << refused.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "_refused"));
  }
}

// The plate example's config by output-error least squares (outer.functional:
// least_squares, the same minimiser from the same start) against its MCRE run: both
// zones within 3 % of the MCRE's (measured: see docs/matrix_models.md section 10), the
// results in the matrix run's layout with the error map left out.
TEST(MatrixIdentificationRunTest, ThePlateConfigByLeastSquaresAgreesWithTheMcre) {
  const std::string mcre = FreshDirectory("matrix_run_plate_mcre");
  const std::string ls = FreshDirectory("matrix_run_plate_ls");
  const std::string config = SourcePath("configs/plate.yaml");
  const RunResult by_mcre = RunIdentify("run " + config + " -q -o " + mcre);
  ASSERT_EQ(by_mcre.exit_code, 0) << by_mcre.output;
  const RunResult by_ls =
      RunIdentify("run " + config + " --set outer.functional=least_squares -q -o " + ls);
  ASSERT_EQ(by_ls.exit_code, 0) << by_ls.output;
  for (int z = 0; z < 2; ++z) {
    const double reference = ZoneModulus(mcre + "/zones.csv", z);
    EXPECT_NEAR(ZoneModulus(ls + "/zones.csv", z) / reference - 1.0, 0.0, 0.03) << "zone " << z;
  }
  const YAML::Node summary = YAML::LoadFile(ls + "/summary.yaml");
  EXPECT_EQ(summary["functional"].as<std::string>(), "least_squares");
  EXPECT_EQ(summary["config"]["outer"]["functional"].as<std::string>(), "least_squares");
  EXPECT_GT(summary["zones"]["cost"].as<double>(), 0.0);
  EXPECT_LT(summary["zones"]["cost"].as<double>(), summary["zones"]["nominal_cost"].as<double>());
  EXPECT_EQ(summary["misfit_levels"]["source"].as<std::string>(), "synthetic_snr");
  // zones.csv: the one layout, the error-map columns (the last four) empty.
  std::istringstream lines(ReadText(ls + "/zones.csv"));
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header, ReadText(mcre + "/zones.csv").substr(0, header.size()));
  std::getline(lines, row);
  EXPECT_EQ(row.substr(row.size() - 4), ",,,,") << row;
  EXPECT_TRUE(std::filesystem::exists(ls + "/zone_evaluations.csv"));
  EXPECT_TRUE(std::filesystem::exists(ls + "/fit.csv"));
  EXPECT_FALSE(std::filesystem::exists(ls + "/error_map_dofs.csv"));
}

}  // namespace
}  // namespace mcrewave
