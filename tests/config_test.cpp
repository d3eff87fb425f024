#include "mcrewave/app/config.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave {
namespace {

// The keys model.*, load.*, time.* and data.* up to data.seed.
void ExpectSameConfigModelToData(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.model.length, actual.model.length);
  EXPECT_EQ(expected.model.section, actual.model.section);
  EXPECT_EQ(expected.model.density, actual.model.density);
  EXPECT_EQ(expected.model.modulus, actual.model.modulus);
  EXPECT_EQ(expected.model.elements, actual.model.elements);
  EXPECT_EQ(expected.model.mass, actual.model.mass);
  EXPECT_EQ(expected.model.reaction_length, actual.model.reaction_length);
  EXPECT_EQ(expected.model.coarse_elements, actual.model.coarse_elements);
  EXPECT_EQ(expected.load.kind, actual.load.kind);
  EXPECT_EQ(expected.load.amplitude, actual.load.amplitude);
  EXPECT_EQ(expected.load.duration, actual.load.duration);
  EXPECT_EQ(expected.time.window, actual.time.window);
  EXPECT_EQ(expected.time.step, actual.time.step);
  EXPECT_EQ(expected.time.theta, actual.time.theta);
  EXPECT_EQ(expected.data.source, actual.data.source);
  EXPECT_EQ(expected.data.path, actual.data.path);
  EXPECT_EQ(expected.data.truth, actual.data.truth);
  EXPECT_EQ(expected.data.truth_refinement, actual.data.truth_refinement);
  EXPECT_EQ(expected.data.snr, actual.data.snr);
  EXPECT_EQ(expected.data.seed, actual.data.seed);
}

// The weights w_u and w_f, mcre.reference_modulus and inner.*.
void ExpectSameConfigMcreAndInner(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.mcre.weights.displacement_weight, actual.mcre.weights.displacement_weight);
  EXPECT_EQ(expected.mcre.weights.force_weight, actual.mcre.weights.force_weight);
  EXPECT_EQ(expected.mcre.reference_modulus, actual.mcre.reference_modulus);
  EXPECT_EQ(expected.inner.type, actual.inner.type);
  EXPECT_EQ(expected.inner.tolerance, actual.inner.tolerance);
  EXPECT_EQ(expected.inner.unchecked_tolerance, actual.inner.unchecked_tolerance);
  EXPECT_EQ(expected.inner.max_iterations, actual.inner.max_iterations);
  EXPECT_EQ(expected.inner.relaxation_coefficient, actual.inner.relaxation_coefficient);
  EXPECT_EQ(expected.inner.spectrum_estimation_steps, actual.inner.spectrum_estimation_steps);
  EXPECT_EQ(expected.inner.spectrum_safety_factor, actual.inner.spectrum_safety_factor);
  EXPECT_EQ(expected.inner.divergence_factor, actual.inner.divergence_factor);
  EXPECT_EQ(expected.inner.max_all_at_once_unknowns, actual.inner.max_all_at_once_unknowns);
  EXPECT_EQ(expected.inner.max_all_at_once_bytes, actual.inner.max_all_at_once_bytes);
  EXPECT_EQ(expected.inner.max_dense_solver_bytes, actual.inner.max_dense_solver_bytes);
  EXPECT_EQ(expected.inner.max_field_bytes, actual.inner.max_field_bytes);
  EXPECT_EQ(expected.inner.shooting_condition_limit, actual.inner.shooting_condition_limit);
  EXPECT_EQ(expected.inner.shooting_segment_growth, actual.inner.shooting_segment_growth);
  EXPECT_EQ(expected.inner.preconditioner, actual.inner.preconditioner);
  EXPECT_EQ(expected.inner.preconditioner_rebuild_change,
            actual.inner.preconditioner_rebuild_change);
  EXPECT_EQ(expected.inner.max_preconditioner_traces, actual.inner.max_preconditioner_traces);
}

// The keys outer.*, prefilter.*, uncertainty.* and output.*.
void ExpectSameConfigOuterToOutput(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.outer.optimizer, actual.outer.optimizer);
  EXPECT_EQ(expected.outer.algorithm, actual.outer.algorithm);
  EXPECT_EQ(expected.outer.lower_bound, actual.outer.lower_bound);
  EXPECT_EQ(expected.outer.upper_bound, actual.outer.upper_bound);
  EXPECT_EQ(expected.outer.initial, actual.outer.initial);
  EXPECT_EQ(expected.outer.relative_tolerance, actual.outer.relative_tolerance);
  EXPECT_EQ(expected.outer.max_evaluations, actual.outer.max_evaluations);
  EXPECT_EQ(expected.outer.max_time, actual.outer.max_time);
  EXPECT_EQ(expected.outer.scan_points, actual.outer.scan_points);
  EXPECT_EQ(expected.outer.functional, actual.outer.functional);
  EXPECT_EQ(expected.outer.scan_tolerance, actual.outer.scan_tolerance);
  EXPECT_EQ(expected.outer.scan_samples_per_valley, actual.outer.scan_samples_per_valley);
  EXPECT_EQ(expected.outer.scan_max_points, actual.outer.scan_max_points);
  EXPECT_EQ(expected.outer.refine_margin, actual.outer.refine_margin);
  EXPECT_EQ(expected.outer.scan_threads, actual.outer.scan_threads);
  EXPECT_EQ(expected.outer.refine_candidates, actual.outer.refine_candidates);
  EXPECT_EQ(expected.prefilter.enabled, actual.prefilter.enabled);
  EXPECT_EQ(expected.prefilter.cutoff_frequency, actual.prefilter.cutoff_frequency);
  EXPECT_EQ(expected.prefilter.order, actual.prefilter.order);
  EXPECT_EQ(expected.prefilter.at_rest_before_start, actual.prefilter.at_rest_before_start);
  EXPECT_EQ(expected.uncertainty.samples, actual.uncertainty.samples);
  EXPECT_EQ(expected.uncertainty.seed, actual.uncertainty.seed);
  EXPECT_EQ(expected.output.folder, actual.output.folder);
  EXPECT_EQ(expected.output.figures, actual.output.figures);
  EXPECT_EQ(expected.output.curve_points, actual.output.curve_points);
}

// The keys study.* up to study.comparator.errors.
void ExpectSameConfigStudy(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.study.kind, actual.study.kind);
  EXPECT_EQ(expected.study.folder, actual.study.folder);
  EXPECT_EQ(expected.study.threads, actual.study.threads);
  EXPECT_EQ(expected.study.figures, actual.study.figures);
  EXPECT_EQ(expected.study.robustness.snr, actual.study.robustness.snr);
  EXPECT_EQ(expected.study.robustness.seeds, actual.study.robustness.seeds);
  EXPECT_EQ(expected.study.relaxation.snr, actual.study.relaxation.snr);
  EXPECT_EQ(expected.study.relaxation.moduli, actual.study.relaxation.moduli);
  EXPECT_EQ(expected.study.relaxation.omega_min, actual.study.relaxation.omega_min);
  EXPECT_EQ(expected.study.relaxation.omega_max, actual.study.relaxation.omega_max);
  EXPECT_EQ(expected.study.relaxation.omega_points, actual.study.relaxation.omega_points);
  EXPECT_EQ(expected.study.relaxation.tolerance, actual.study.relaxation.tolerance);
  EXPECT_EQ(expected.study.cost_curves.snr, actual.study.cost_curves.snr);
  EXPECT_EQ(expected.study.cost_curves.seeds, actual.study.cost_curves.seeds);
  EXPECT_EQ(expected.study.cost_curves.points, actual.study.cost_curves.points);
  EXPECT_EQ(expected.study.cost_curves.low, actual.study.cost_curves.low);
  EXPECT_EQ(expected.study.cost_curves.high, actual.study.cost_curves.high);
  EXPECT_EQ(expected.study.damage.snr, actual.study.damage.snr);
  EXPECT_EQ(expected.study.damage.seeds, actual.study.damage.seeds);
  EXPECT_EQ(expected.study.comparator.snr, actual.study.comparator.snr);
  EXPECT_EQ(expected.study.comparator.seeds, actual.study.comparator.seeds);
  EXPECT_EQ(expected.study.comparator.errors, actual.study.comparator.errors);
}

// The keys zones.*, data.sensors, data.channels and data.truth_zones.
void ExpectSameConfigZonesAndSensors(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.zones.zoning, actual.zones.zoning);
  EXPECT_EQ(expected.zones.zone_count, actual.zones.zone_count);
  EXPECT_EQ(expected.zones.zone_boundaries, actual.zones.zone_boundaries);
  EXPECT_EQ(expected.zones.zone_grid, actual.zones.zone_grid);
  EXPECT_EQ(expected.zones.free_zones, actual.zones.free_zones);
  EXPECT_EQ(expected.data.sensors, actual.data.sensors);
  EXPECT_EQ(expected.data.channels, actual.data.channels);
  ASSERT_EQ(expected.data.truth_zones.size(), actual.data.truth_zones.size());
  for (std::size_t i = 0; i < expected.data.truth_zones.size(); ++i) {
    EXPECT_EQ(expected.data.truth_zones[i].start, actual.data.truth_zones[i].start);
    EXPECT_EQ(expected.data.truth_zones[i].end, actual.data.truth_zones[i].end);
    EXPECT_EQ(expected.data.truth_zones[i].modulus, actual.data.truth_zones[i].modulus);
  }
}

// The keys added later: the other mcre weights, mcre.clamp, search.*,
// study.comparator.data, structure.*, data.truth_manifest and data.truth_moduli.
void ExpectSameConfigLaterKeys(const Config& expected, const Config& actual) {
  EXPECT_EQ(expected.mcre.weights.strain_weight, actual.mcre.weights.strain_weight);
  EXPECT_EQ(expected.mcre.weights.reaction_weight, actual.mcre.weights.reaction_weight);
  EXPECT_EQ(expected.mcre.weights.clamp_displacement_weight,
            actual.mcre.weights.clamp_displacement_weight);
  EXPECT_EQ(expected.mcre.clamp, actual.mcre.clamp);
  EXPECT_EQ(expected.mcre.support_check, actual.mcre.support_check);
  EXPECT_EQ(expected.mcre.support_check_threshold, actual.mcre.support_check_threshold);
  EXPECT_EQ(expected.mcre.support_check_ramp_start, actual.mcre.support_check_ramp_start);
  EXPECT_EQ(expected.mcre.weights.unmeasured_force_weight,
            actual.mcre.weights.unmeasured_force_weight);
  EXPECT_EQ(expected.mcre.unmeasured_loads, actual.mcre.unmeasured_loads);
  EXPECT_EQ(expected.data.time_column, actual.data.time_column);
  EXPECT_EQ(expected.data.time_origin, actual.data.time_origin);
  EXPECT_EQ(expected.data.at_rest_before_record, actual.data.at_rest_before_record);
  EXPECT_EQ(expected.mcre.unmeasured_load_interval, actual.mcre.unmeasured_load_interval);
  EXPECT_EQ(expected.data.support_stiffness, actual.data.support_stiffness);
  EXPECT_EQ(expected.search.functional, actual.search.functional);
  EXPECT_EQ(expected.search.displacement_weight, actual.search.displacement_weight);
  EXPECT_EQ(expected.search.strain_weight, actual.search.strain_weight);
  EXPECT_EQ(expected.search.clamp_displacement_weight, actual.search.clamp_displacement_weight);
  EXPECT_EQ(expected.search.reaction_weight, actual.search.reaction_weight);
  EXPECT_EQ(expected.search.inner_tolerance, actual.search.inner_tolerance);
  EXPECT_EQ(expected.search.scan_points, actual.search.scan_points);
  EXPECT_EQ(expected.search.samples_per_valley, actual.search.samples_per_valley);
  EXPECT_EQ(expected.search.window_points, actual.search.window_points);
  EXPECT_EQ(expected.search.refine_window, actual.search.refine_window);
  EXPECT_EQ(expected.search.algorithm, actual.search.algorithm);
  EXPECT_EQ(expected.search.relative_tolerance, actual.search.relative_tolerance);
  EXPECT_EQ(expected.search.time_step_factor, actual.search.time_step_factor);
  EXPECT_EQ(expected.study.comparator.data, actual.study.comparator.data);
  EXPECT_EQ(expected.structure.kind, actual.structure.kind);
  EXPECT_EQ(expected.structure.manifest, actual.structure.manifest);
  EXPECT_EQ(expected.structure.channel_map, actual.structure.channel_map);
  EXPECT_EQ(expected.data.truth_manifest, actual.data.truth_manifest);
  EXPECT_EQ(expected.data.truth_moduli, actual.data.truth_moduli);
  EXPECT_EQ(expected.zone_identification.start_moduli, actual.zone_identification.start_moduli);
}

// The keys zone_identification.*.
void ExpectSameConfigZoneIdentification(const Config& expected, const Config& actual) {
  const ZoneIdentificationOptions& zones = expected.zone_identification;
  const ZoneIdentificationOptions& zones_again = actual.zone_identification;
  EXPECT_EQ(zones.minimizer.optimizer, zones_again.minimizer.optimizer);
  EXPECT_EQ(zones.minimizer.algorithm, zones_again.minimizer.algorithm);
  EXPECT_EQ(zones.minimizer.step_tolerance, zones_again.minimizer.step_tolerance);
  EXPECT_EQ(zones.minimizer.function_tolerance, zones_again.minimizer.function_tolerance);
  EXPECT_EQ(zones.minimizer.max_evaluations, zones_again.minimizer.max_evaluations);
  EXPECT_EQ(zones.minimizer.max_time, zones_again.minimizer.max_time);
  EXPECT_EQ(zones.regularization.kind, zones_again.regularization.kind);
  EXPECT_EQ(zones.neighbours, zones_again.neighbours);
  EXPECT_EQ(zones.regularization.weight, zones_again.regularization.weight);
  EXPECT_EQ(zones.regularization.tv_smoothing, zones_again.regularization.tv_smoothing);
  EXPECT_EQ(zones.regularization.max_weight, zones_again.regularization.max_weight);
  EXPECT_EQ(zones.regularization.min_weight, zones_again.regularization.min_weight);
  EXPECT_EQ(zones.regularization.grid_factor, zones_again.regularization.grid_factor);
  EXPECT_EQ(zones.regularization.refinement_steps, zones_again.regularization.refinement_steps);
  EXPECT_EQ(zones.regularization.weight_tolerance,
            zones_again.regularization.weight_tolerance);
  EXPECT_EQ(zones.regularization.discrepancy_factor, zones_again.regularization.discrepancy_factor);
  EXPECT_EQ(zones.regularization.floor_margin, zones_again.regularization.floor_margin);
  EXPECT_EQ(zones.noise_samples, zones_again.noise_samples);
  EXPECT_EQ(zones.noise_seed, zones_again.noise_seed);
  EXPECT_EQ(zones.merge_zones, zones_again.merge_zones);
  EXPECT_EQ(zones.measured_clamp, zones_again.measured_clamp);
}

// Every key of the two configs is equal (NaN never occurs in a valid config).
void ExpectSameConfig(const Config& expected, const Config& actual) {
  ExpectSameConfigModelToData(expected, actual);
  ExpectSameConfigMcreAndInner(expected, actual);
  ExpectSameConfigOuterToOutput(expected, actual);
  ExpectSameConfigStudy(expected, actual);
  ExpectSameConfigZonesAndSensors(expected, actual);
  ExpectSameConfigLaterKeys(expected, actual);
  ExpectSameConfigZoneIdentification(expected, actual);
}

// Runs `action`, which must throw InputError whose message contains every one of
// `fragments`.
void ExpectInputError(const std::function<void()>& action,
                      const std::vector<std::string>& fragments) {
  try {
    action();
  } catch (const InputError& error) {
    const std::string message = error.what();
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message: " << message << "\nlacks: " << fragment;
    }
    return;
  }
  ADD_FAILURE() << "no InputError thrown";
}

// Writes config files into a fresh directory of its own.
class ConfigFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ =
        std::filesystem::path(::testing::TempDir()) /
        ("mcrewave_config_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(directory_);
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  // Writes `content` to `name` in the test directory; returns its path.
  std::string WriteFile(const std::string& name, const std::string& content) const {
    const std::string path = (directory_ / name).string();
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

  // Writes `content` as config.yaml and expects LoadConfig to throw an InputError
  // whose message names the file, `line` and every one of `fragments`.
  void ExpectLoadError(const std::string& content, int line,
                       std::vector<std::string> fragments) const {
    const std::string path = WriteFile("config.yaml", content);
    fragments.push_back(path + ":" + std::to_string(line) + ": ");
    ExpectInputError([&path] { LoadConfig(path); }, fragments);
  }

  std::filesystem::path directory_;
};

TEST(ConfigTest, DefaultOptionsAreValid) {
  const Config config;
  std::string error;
  EXPECT_TRUE(config.model.IsValid(&error)) << error;
  EXPECT_TRUE(config.load.IsValid(&error)) << error;
  EXPECT_TRUE(config.time.IsValid(&error)) << error;
  EXPECT_TRUE(config.data.IsValid(&error)) << error;
  EXPECT_EQ(config.time.NumSteps(), 1750);
}

TEST(ConfigTest, DefaultInnerMethodIsAutoAndValid) {
  const Config config;
  EXPECT_EQ(config.inner.type, CoupledSolverType::kAuto);
  std::string error;
  EXPECT_TRUE(config.inner.IsValid(&error)) << error;
  EXPECT_EQ(ConfigProblem(config), "");
  const std::string yaml = DefaultConfigYaml();
  EXPECT_NE(yaml.find("\n  method: auto "), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("| streaming_conjugate_gradient | auto)"), std::string::npos) << yaml;
  EXPECT_EQ(ParseConfig("inner:\n  method: auto\n", "a.yaml").inner.type, CoupledSolverType::kAuto);
}

// The bar's fields are checked at load as SolveCoupled checks them: auto never refused
// (it streams), a stored-field method refused naming the ways out.
TEST(ConfigTest, FieldsAboveTheLimitStreamWithAutoAndAreRefusedWithStoredFieldMethods) {
  // 1e5 elements, 1750 steps: 14008140080 bytes of fields, above the default 2^31.
  const Config streamed = ParseConfig("", "a.yaml", {"model.elements=100000"});
  EXPECT_EQ(streamed.inner.type, CoupledSolverType::kAuto);
  EXPECT_EQ(ResolveCoupledSolverType(streamed.inner, 100001, 1750, true),
            CoupledSolverType::kStreamingConjugateGradient);
  for (const char* method : {"conjugate_gradient", "relaxation", "adaptive_relaxation"}) {
    ExpectInputError(
        [method] {
          ParseConfig("", "a.yaml",
                      {"model.elements=100000", std::string("inner.method=") + method});
        },
        {"--set model.elements=100000: model.elements (100000) and 1750 steps (time.window / "
         "time.step) need 14008140080 bytes for inner.method '" +
             std::string(method) + "'",
         "above inner.max_field_bytes = 2147483648; use inner.method: "
         "streaming_conjugate_gradient (or auto), which stores no space-time field, raise "
         "inner.max_field_bytes, or use fewer elements, a shorter window or a larger step"});
  }
  // Raised above the fields, the stored-field CG loads; lowered below the paper's bar
  // (14148080 bytes), auto streams there too.
  EXPECT_NO_THROW(ParseConfig("", "a.yaml",
                              {"model.elements=100000", "inner.method=conjugate_gradient",
                               "inner.max_field_bytes=14008140080"}));
  const Config small = ParseConfig("", "a.yaml", {"inner.max_field_bytes=14148079"});
  EXPECT_EQ(ResolveCoupledSolverType(small.inner, 101, 1750, true),
            CoupledSolverType::kStreamingConjugateGradient);
  EXPECT_EQ(ResolveCoupledSolverType(Config().inner, 101, 1750, true),
            CoupledSolverType::kConjugateGradient);
}

TEST(ConfigTest, AMatrixModelTakesAutoAndEveryOtherInnerMethod) {
  const std::string matrix = "model:\n  kind: matrix\n  manifest: m.yaml\n";
  EXPECT_EQ(ParseConfig(matrix, "a.yaml").inner.type, CoupledSolverType::kAuto);
  EXPECT_EQ(ParseConfig(matrix + "inner:\n  method: conjugate_gradient\n", "a.yaml").inner.type,
            CoupledSolverType::kConjugateGradient);
  EXPECT_EQ(
      ParseConfig(matrix + "inner:\n  method: streaming_conjugate_gradient\n", "a.yaml").inner.type,
      CoupledSolverType::kStreamingConjugateGradient);
  // Riccati and shooting take the matrix model's operators (docs/riccati_shooting.md).
  for (const char* method : {"riccati", "single_shooting", "multiple_shooting"}) {
    EXPECT_EQ(CoupledSolverTypeToString(
                  ParseConfig(matrix + "inner:\n  method: " + method + "\n", "a.yaml").inner.type),
              std::string(method));
  }
}

TEST(ConfigTest, DefaultConfigYamlParsesToTheDefaultConfig) {
  const std::string yaml = DefaultConfigYaml();
  ExpectSameConfig(Config{}, ParseConfig(yaml, "default.yaml"));
  for (const char* line :
       {"model:", "load:", "time:", "data:", "mcre:", "inner:", "outer:", "uncertainty:", "output:",
        "  length: 1", "# [m] ", "  snr: .inf", "  density: 800", "(consistent | lumped)",
        "  max_all_at_once_bytes: 2147483648"}) {
    EXPECT_NE(yaml.find(line), std::string::npos) << yaml << "\nlacks " << line;
  }
}

// The keys of each study lie in a block named after its study.kind, in a file and
// on the command line alike; the default config shows the blocks with their headings.
TEST(ConfigTest, StudyKeysAreNestedPerStudy) {
  const double inf = std::numeric_limits<double>::infinity();
  const Config config = ParseConfig(
      "study:\n  kind: robustness\n  robustness:\n    snr: [.inf, 7]\n    seeds: 3\n"
      "  relaxation:\n  cost_curves:\n    low: 0.5\n",
      "a.yaml");
  const Config defaults;
  EXPECT_EQ(config.study.kind, StudyKind::kRobustness);
  EXPECT_EQ(config.study.robustness.snr, (std::vector<double>{inf, 7.0}));
  EXPECT_EQ(config.study.robustness.seeds, 3);
  EXPECT_EQ(config.study.cost_curves.low, 0.5);
  EXPECT_EQ(config.study.cost_curves.high, defaults.study.cost_curves.high);
  EXPECT_EQ(config.study.relaxation.omega_points, defaults.study.relaxation.omega_points);

  const Config set = ParseConfig(
      "", "a.yaml",
      {"study.robustness.snr=[10]", "study.relaxation.omega_min=0.01", "study.cost_curves.points=5",
       "study.damage.seeds=2", "study.comparator.data=[raw]"});
  EXPECT_EQ(set.study.robustness.snr, (std::vector<double>{10.0}));
  EXPECT_EQ(set.study.relaxation.omega_min, 0.01);
  EXPECT_EQ(set.study.cost_curves.points, 5);
  EXPECT_EQ(set.study.damage.seeds, 2);
  EXPECT_EQ(set.study.comparator.data, (std::vector<std::string>{"raw"}));

  const std::string yaml = DefaultConfigYaml();
  for (const char* block : {"robustness", "relaxation", "cost_curves", "damage", "comparator"}) {
    const std::size_t at = yaml.find(std::string("\n  ") + block + ":  ");
    ASSERT_NE(at, std::string::npos) << yaml << "\nlacks the block " << block;
    const std::string line = yaml.substr(at + 1, yaml.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find(std::string("# study.kind ") + block + ": "), std::string::npos) << line;
    EXPECT_EQ(yaml.compare(yaml.find('\n', at + 1) + 1, 4, "    "), 0) << yaml;
  }
  EXPECT_NE(yaml.find("\n    snr: [.inf, 20, 10, 5, 2.5]  "), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\n    omega_min: 0.005  "), std::string::npos) << yaml;
  EXPECT_EQ(yaml.find("robustness_snr"), std::string::npos) << yaml;
  // A run's summary.yaml echoes the blocks too, and reads back.
  const std::string applied = AppliedConfigToYaml(Config());
  EXPECT_NE(applied.find("\n  robustness:\n    snr: [.inf, 20, 10, 5, 2.5]\n    seeds: 100\n"),
            std::string::npos)
      << applied;
  ExpectSameConfig(Config{}, ParseConfig(applied, "summary.yaml"));
}

TEST(ConfigTest, UnknownStudyKeysAreRefusedByName) {
  ExpectInputError([] { ParseConfig("study:\n  robustness:\n    snrr: [10]\n", "a.yaml"); },
                   {"a.yaml:3: unknown key 'study.robustness.snrr'; did you mean "
                    "'study.robustness.snr'?"});
  ExpectInputError([] { ParseConfig("", "a.yaml", {"study.robustness.snrr=[10]"}); },
                   {"--set study.robustness.snrr=[10]: unknown key 'study.robustness.snrr'; did "
                    "you mean 'study.robustness.snr'?"});
  ExpectInputError([] { ParseConfig("study:\n  robust:\n    snr: [10]\n", "a.yaml"); },
                   {"a.yaml:2: unknown key 'study.robust'; did you mean 'study.robustness'?"});
  // A key of another study's block is unknown in this one.
  ExpectInputError([] { ParseConfig("study:\n  robustness:\n    omega_min: 0.01\n", "a.yaml"); },
                   {"a.yaml:3: unknown key 'study.robustness.omega_min'"});
}

// The flat study keys of before the blocks are unknown keys, each refused with its
// name now.
TEST(ConfigTest, FlatStudyKeysAreRefusedNamingTheirNestedKey) {
  const std::vector<std::pair<std::string, std::string>> renames = {
      {"robustness_snr", "robustness.snr"},
      {"robustness_seeds", "robustness.seeds"},
      {"relaxation_snr", "relaxation.snr"},
      {"relaxation_moduli", "relaxation.moduli"},
      {"omega_min", "relaxation.omega_min"},
      {"omega_max", "relaxation.omega_max"},
      {"omega_points", "relaxation.omega_points"},
      {"relaxation_tolerance", "relaxation.tolerance"},
      {"cost_curve_snr", "cost_curves.snr"},
      {"cost_curve_seeds", "cost_curves.seeds"},
      {"cost_curve_points", "cost_curves.points"},
      {"cost_curve_low", "cost_curves.low"},
      {"cost_curve_high", "cost_curves.high"},
      {"damage_snr", "damage.snr"},
      {"damage_seeds", "damage.seeds"},
      {"comparator_snr", "comparator.snr"},
      {"comparator_seeds", "comparator.seeds"},
      {"comparator_errors", "comparator.errors"},
      {"comparator_data", "comparator.data"}};
  for (const auto& rename : renames) {
    // A plain variable: a lambda may not capture a structured binding in C++17.
    const std::string& old_name = rename.first;
    const std::string message = "unknown key 'study." + old_name +
                                "'; the study keys are nested per study: it is now 'study." +
                                rename.second + "'";
    ExpectInputError([&old_name] { ParseConfig("study:\n  " + old_name + ": 1\n", "a.yaml"); },
                     {"a.yaml:2: " + message});
    ExpectInputError([&old_name] { ParseConfig("", "a.yaml", {"study." + old_name + "=1"}); },
                     {"--set study." + old_name + "=1: " + message});
  }
}

// A block is a map of keys, a key of a block is written nested in a file, and
// --set sets keys, not blocks.
TEST(ConfigTest, StudyBlocksAreMapsOfTheirKeys) {
  ExpectInputError([] { ParseConfig("study:\n  robustness: 5\n", "a.yaml"); },
                   {"a.yaml:2: study.robustness: expected a map of keys (snr, seeds), got '5'"});
  ExpectInputError([] { ParseConfig("study:\n  robustness:\n    snr:\n      x: 1\n", "a.yaml"); },
                   {"a.yaml:3: study.robustness.snr: expected a list of numbers", "got a map"});
  ExpectInputError([] { ParseConfig("study:\n  robustness.snr: [10]\n", "a.yaml"); },
                   {"a.yaml:2: study.robustness.snr: expected it nested, 'robustness:' with "
                    "'snr:' under it"});
  ExpectInputError([] { ParseConfig("", "a.yaml", {"study.robustness=[10]"}); },
                   {"--set study.robustness=[10]: study.robustness is a block of keys (snr, "
                    "seeds): set one of them, e.g. study.robustness.snr=..."});
  ExpectInputError(
      [] {
        ParseConfig("study:\n  robustness:\n    seeds: 2\n  robustness:\n    snr: [10]\n",
                    "a.yaml");
      },
      {"a.yaml:4: duplicate key 'study.robustness' (first given on line 2)"});
  ExpectInputError(
      [] { ParseConfig("study:\n  robustness:\n    seeds: 2\n    seeds: 3\n", "a.yaml"); },
      {"a.yaml:4: duplicate key 'study.robustness.seeds' (first given on line 3)"});
  ExpectInputError([] { ParseConfig("study: 5\n", "a.yaml"); },
                   {"a.yaml:1: study: expected a map of keys (kind, folder, threads, figures, "
                    "robustness, relaxation, cost_curves, damage, comparator), got '5'"});
}

TEST(ConfigTest, ScanAndPrefilterKeysAreReadAndChecked) {
  const Config config = ParseConfig(
      "outer:\n  scan_points: 0\n  refine_candidates: 3\n"
      "prefilter:\n  enabled: true\n  cutoff_frequency: 50e3\n"
      "  order: 6\n",
      "scan.yaml");
  EXPECT_EQ(config.outer.scan_points, 0);
  EXPECT_EQ(config.outer.refine_candidates, 3);
  EXPECT_TRUE(config.prefilter.enabled);
  EXPECT_EQ(config.prefilter.cutoff_frequency, 50e3);
  EXPECT_EQ(config.prefilter.order, 6);
  for (const auto& [override_text, key] : std::vector<std::pair<std::string, std::string>>{
           {"outer.scan_points=2", "outer.scan_points"},
           {"outer.scan_points=-1", "outer.scan_points"},
           {"outer.scan_tolerance=1.5", "outer.scan_tolerance"},
           {"outer.scan_samples_per_valley=0.5", "outer.scan_samples_per_valley"},
           {"outer.scan_samples_per_valley=-1", "outer.scan_samples_per_valley"},
           {"outer.scan_max_points=20", "outer.scan_max_points"},
           {"outer.refine_margin=-0.1", "outer.refine_margin"},
           {"outer.refine_margin=.nan", "outer.refine_margin"},
           {"prefilter.order=3", "prefilter.order"},
           {"prefilter.cutoff_frequency=-1", "prefilter.cutoff_frequency"}}) {
    try {
      ParseConfig("", "scan.yaml", {override_text});
      ADD_FAILURE() << override_text << " was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(key), std::string::npos) << error.what();
    }
  }
}

TEST(ConfigTest, AllAtOnceByteLimitIsReadAndChecked) {
  EXPECT_EQ(Config{}.inner.max_all_at_once_bytes, 1L << 31);
  EXPECT_EQ(
      ParseConfig("inner:\n  max_all_at_once_bytes: 1000\n", "a.yaml").inner.max_all_at_once_bytes,
      1000);
  ExpectInputError([] { ParseConfig("inner:\n  max_all_at_once_bytes: 0\n", "a.yaml"); },
                   {"a.yaml:2: inner.max_all_at_once_bytes: expected a positive integer (in "
                    "bytes), got '0'"});
  CoupledSolverOptions options;
  options.max_all_at_once_bytes = 0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_NE(why.find("inner.max_all_at_once_bytes must be positive"), std::string::npos) << why;
}

TEST(ConfigTest, DefaultConfigYamlCommentsEveryKey) {
  const std::string yaml = DefaultConfigYaml();
  int keys = 0;
  std::size_t begin = 0;
  while (begin < yaml.size()) {
    const std::size_t end = yaml.find('\n', begin);
    const std::string line = yaml.substr(begin, end - begin);
    begin = end + 1;
    if (line.rfind("  ", 0) != 0) continue;  // comments and section lines
    ++keys;
    EXPECT_NE(line.find(" # "), std::string::npos) << line;
  }
  EXPECT_GE(keys, 40);
}

// PrefilterMeasurements filters every channel (the end channels and the interior
// sensors), the matrix run every load and output; the description said "the four
// measured channels".
TEST(ConfigTest, ThePrefilterIsDescribedAsFilteringEveryChannel) {
  const std::string yaml = DefaultConfigYaml();
  const std::size_t key = yaml.find("\n  enabled: true", yaml.find("\nprefilter:"));
  ASSERT_NE(key, std::string::npos) << yaml;
  const std::string line = yaml.substr(key + 1, yaml.find('\n', key + 1) - key - 1);
  EXPECT_NE(line.find("the same on every channel the identification uses"), std::string::npos)
      << line;
  EXPECT_EQ(line.find("four"), std::string::npos) << line;
}

TEST(ConfigTest, ConfigToYamlRoundTripsExactly) {
  Config config;
  config.model.length = 0.1 + 0.2;
  config.model.section = 1.0 / 3.0 * 1e-4;
  config.model.density = 7850.000000000001;
  config.model.modulus = 2.1e11;
  config.model.elements = 437;
  config.model.mass = MassType::kLumped;
  config.model.reaction_length = 0.07;
  config.model.coarse_elements = 111;
  config.load.amplitude = -12.5;
  config.load.duration = 2.0 / 3.0 * 1e-4;
  config.time.window = 1e-3;
  config.time.step = 1e-6;
  config.time.theta = 0.6;
  config.data.source = DataSource::kCsv;
  config.data.path = "dir with spaces/quote\"s and \\ back: # x.csv";
  config.data.truth = TruthModel::kExact;
  config.data.truth_refinement = 64;
  config.data.snr = 2.5;
  config.data.seed = std::numeric_limits<std::uint64_t>::max();
  config.mcre.weights.displacement_weight = 0.3;
  config.mcre.weights.force_weight = 1.0 / 7.0;
  config.mcre.reference_modulus = 70e9;
  config.inner.type = CoupledSolverType::kAdaptiveRelaxation;
  config.inner.tolerance = 1e-11;
  config.inner.unchecked_tolerance = 1e-5;
  config.inner.max_iterations = 123;
  config.inner.relaxation_coefficient = 0.7;
  config.inner.spectrum_estimation_steps = 9;
  config.inner.spectrum_safety_factor = 1.2;
  config.inner.divergence_factor = 50.0;
  config.inner.max_all_at_once_unknowns = 3'000'000'000L;
  config.inner.max_all_at_once_bytes = (1L << 35) + 1;
  config.inner.max_dense_solver_bytes = 1L << 33;
  config.inner.max_field_bytes = 1L << 34;
  config.inner.shooting_condition_limit = 1e12;
  config.inner.shooting_segment_growth = 1e3;
  config.outer.optimizer = OptimizerType::kCeres;
  config.outer.algorithm = OuterAlgorithm::kBfgs;
  config.outer.lower_bound = 1e9;
  config.outer.upper_bound = 1e12;
  config.outer.initial = 1.0 / 3.0 * 1e11;
  config.outer.relative_tolerance = 1e-9;
  config.outer.max_evaluations = 67;
  config.outer.max_time = 0.5;
  config.uncertainty.samples = 3;
  config.uncertainty.seed = 99;
  config.output.folder = "out dir/run #1";
  config.output.figures = false;
  config.output.curve_points = 7;
  config.study.kind = StudyKind::kCostCurves;
  config.study.threads = 3;
  config.study.robustness.snr = {std::numeric_limits<double>::infinity(), 1.0 / 3.0, 2.5};
  config.study.relaxation.moduli = {0.1 + 0.2};
  config.study.cost_curves.high = 1.0 / 7.0 + 1.0;
  const std::string yaml = ConfigToYaml(config);
  ExpectSameConfig(config, ParseConfig(yaml, "resolved.yaml"));
  EXPECT_NE(yaml.find("mass: lumped"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("truth: exact"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("method: adaptive_relaxation"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("optimizer: ceres"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("figures: false"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("kind: cost_curves"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\n  robustness:\n    snr: [.inf, "), std::string::npos) << yaml;

  config.data.snr = std::numeric_limits<double>::infinity();
  const std::string infinite_snr = ConfigToYaml(config);
  EXPECT_NE(infinite_snr.find("snr: .inf"), std::string::npos) << infinite_snr;
  ExpectSameConfig(config, ParseConfig(infinite_snr, "resolved.yaml"));
}

// Every key of a config YAML text as "section.key" (a key of a block:
// "section.block.key") -> its value as written (comments and comment lines dropped;
// a '#' inside a quoted value kept).
std::map<std::string, std::string> FlatKeys(const std::string& yaml) {
  std::map<std::string, std::string> keys;
  std::istringstream lines(yaml);
  std::vector<std::pair<std::size_t, std::string>> maps;  // indent and name of the open maps
  for (std::string line; std::getline(lines, line);) {
    const std::size_t first = line.find_first_not_of(' ');
    if (first == std::string::npos || line[first] == '#') continue;
    bool quoted = false;
    std::size_t end = line.size();
    for (std::size_t i = first; i < line.size(); ++i) {
      if (line[i] == '"' && (i == 0 || line[i - 1] != '\\')) quoted = !quoted;
      if (line[i] == '#' && !quoted) {
        end = i;
        break;
      }
    }
    std::string text = line.substr(0, end);
    text.erase(text.find_last_not_of(' ') + 1);
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos) continue;
    while (!maps.empty() && maps.back().first >= first) maps.pop_back();
    const std::string name = text.substr(first, colon - first);
    std::string value = text.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    if (value.empty()) {  // a section or a block: its keys follow, further indented
      maps.emplace_back(first, name);
      continue;
    }
    std::string path;
    for (const auto& [indent, map] : maps) path += map + ".";
    keys[path + name] = value;
  }
  return keys;
}

// Every key of the table set to a value other than its default (valid
// together: csv data with a path, explicit zone boundaries, ceres with bfgs, ...).
constexpr const char* kEveryKeyNotAtItsDefault = R"(model:
  length: 0.30000000000000004
  section: 3.3333333333333335e-05
  density: 7850.000000000001
  modulus: 2.1e11
  elements: 437
  coarse_elements: 111
  mass: lumped
  reaction_length: 0.07
  zoning: boundaries
  zone_boundaries: [0.1, 0.2]
load:
  kind: half_sine
  amplitude: -12.5
  duration: 6.666666666666667e-05
time:
  window: 1e-3
  step: 1e-6
  theta: 0.6
data:
  source: csv
  path: "dir with spaces/quote\"s and \\ back: # x.csv"
  truth: exact
  truth_refinement: 64
  snr: 2.5
  seed: 18446744073709551615
  sensors: [u@0.1, e@0.25]
  channels: [fL, f0, uL, u@0.1, e@0.25]
  truth_zones: [{start: 0.1, end: 0.15, modulus: 1.4e11}]
  support_stiffness: 2e8
mcre:
  w_u: 0.3
  w_f: 0.14285714285714285
  w_e: 0.7
  w_r: 0.03
  w_u0: 0.25
  reference_modulus: 70e9
  clamp: pinned
  support_check: warn
  support_check_threshold: 3.5
  support_check_ramp_start: 1.5
inner:
  method: adaptive_relaxation
  tolerance: 1e-11
  unchecked_tolerance: 1e-5
  max_iterations: 123
  omega: 0.7
  spectrum_steps: 9
  spectrum_safety_factor: 1.2
  divergence_factor: 50
  max_all_at_once_unknowns: 3000000000
  max_all_at_once_bytes: 34359738369
  max_field_bytes: 17179869184
  max_dense_solver_bytes: 8589934592
  shooting_condition_limit: 1e12
  shooting_segment_growth: 1e3
outer:
  functional: least_squares
  optimizer: ceres
  algorithm: bfgs
  lower_bound: 1e9
  upper_bound: 1e12
  initial: 33333333333.333332
  relative_tolerance: 1e-9
  max_evaluations: 167
  max_time: 0.5
  scan_points: 17
  scan_samples_per_valley: 2.5
  scan_max_points: 333
  scan_tolerance: 3e-3
  scan_threads: 3
  refine_margin: 0.25
  refine_candidates: 4
search:
  w_u: 0.02
  w_e: 0.03
  w_u0: 0.2
  w_r: 0.3
  inner_tolerance: 1e-5
  scan_points: 9
  samples_per_valley: 2.5
  window_points: 4
  refine_window: 0.05
  algorithm: bobyqa
  relative_tolerance: 1e-4
  time_step_factor: 3
prefilter:
  enabled: false
  cutoff_frequency: 12345.5
  order: 6
  at_rest_before_start: false
uncertainty:
  samples: 3
  seed: 99
output:
  folder: "out dir/run #1"
  figures: false
  curve_points: 7
study:
  kind: cost_curves
  folder: "studies/x"
  threads: 3
  figures: false
  robustness:
    snr: [.inf, 0.3333333333333333, 2.5]
    seeds: 7
  relaxation:
    snr: [5]
    moduli: [0.30000000000000004]
    omega_min: 0.01
    omega_max: 0.2
    omega_points: 5
    tolerance: 1e-6
  cost_curves:
    snr: [20]
    seeds: 2
    points: 9
    low: 0.7
    high: 1.1428571428571428
  damage:
    snr: [.inf, 15]
    seeds: 3
  comparator:
    snr: [.inf, 7]
    seeds: 4
    errors: [density, soft_zone]
    data: [prefilter]
zone_identification:
  optimizer: nlopt
  algorithm: slsqp
  step_tolerance: 1e-9
  function_tolerance: 1e-11
  max_evaluations: 321
  max_time: 12.5
  regularization: total_variation
  neighbours: shared_nodes
  regularization_weight: 0.25
  weight_rule: discrepancy
  tv_smoothing: 0.002
  max_weight: 2
  min_weight: 1e-7
  grid_factor: 10
  refinement_steps: 5
  weight_tolerance: 0.5
  discrepancy_factor: 1.5
  floor_margin: noise_fit
  noise_samples: 6
  noise_seed: 7
  merge_zones: true
  measured_clamp: false
)";

// The keys of a structure given by matrices at non-default values (they are refused
// with the bar, as the bar's zones and sensors are with matrices).
constexpr const char* kEveryMatrixKeyNotAtItsDefault = R"(model:
  kind: matrix
  manifest: "plate dir/model #2.yaml"
  channel_map: {F: "F [N]", uy_tip: "tip #1"}
  zoning: grid
  zone_grid: [16, 4]
  free_zones: [grid_10_2, "grid 9 #2", "a, b"]
data:
  truth_manifest: fine/model.yaml
  truth_moduli: [2e11, 1.4000000000000001e11]
  time_column: time_s
  time_origin: -2.6e-4
  at_rest_before_record: true
mcre:
  w_fu: 3.0000000000000001e-5
  unmeasured_loads: [F, "hammer #2"]
  unmeasured_load_interval: [0, 1.2e-4, 1e-5, 2.5e-4]
zone_identification:
  start_modulus: 1.25e11
  least_squares_gradient: adjoint
)";

// The key of equal zones, refused with the zoning of kEveryKeyNotAtItsDefault; the
// streaming CG's preconditioner, which kEveryKeyNotAtItsDefault's adaptive_relaxation
// does not take.
constexpr const char* kEqualZonesKeyNotAtItsDefault = R"(model:
  zone_count: 3
search:
  functional: same
inner:
  method: streaming_conjugate_gradient
  preconditioner: dense_traces
  preconditioner_rebuild_change: 0.035
  max_preconditioner_traces: 777
)";

// The zones' starts one per zone, refused with kEveryMatrixKeyNotAtItsDefault's
// start_modulus.
constexpr const char* kStartModuliKeyNotAtItsDefault = R"(model:
  kind: matrix
  manifest: m.yaml
zone_identification:
  start_moduli: [1.5e11, 2.5e11]
)";

TEST(ConfigTest, EveryKeyAtANonDefaultValueRoundTripsExactly) {
  const std::map<std::string, std::string> defaults = FlatKeys(ConfigToYaml(Config()));
  const std::map<std::string, std::string> documented = FlatKeys(DefaultConfigYaml());
  ASSERT_EQ(documented.size(), defaults.size());
  // Every key of the commented default config differs from its default in one of the
  // four configs: a key added to the table but left out of all fails this test.
  std::map<std::string, int> set_somewhere;
  for (const char* text : {kEveryKeyNotAtItsDefault, kEveryMatrixKeyNotAtItsDefault,
                           kEqualZonesKeyNotAtItsDefault, kStartModuliKeyNotAtItsDefault}) {
    const Config config = ParseConfig(text, "every_key.yaml");
    const std::string yaml = ConfigToYaml(config);
    const std::map<std::string, std::string> keys = FlatKeys(yaml);
    EXPECT_EQ(keys.size(), documented.size());
    for (const auto& [key, value] : documented) {
      ASSERT_EQ(keys.count(key), 1u) << key << " is not written by ConfigToYaml";
      set_somewhere[key] += keys.at(key) != defaults.at(key) ? 1 : 0;
    }
    // Read back: the same config, field by field and as text.
    const Config again = ParseConfig(yaml, "resolved.yaml");
    ExpectSameConfig(config, again);
    EXPECT_EQ(ConfigToYaml(again), yaml);
  }
  for (const auto& [key, count] : set_somewhere) {
    // load.kind has one value only (half_sine).
    if (key == "load.kind") continue;
    EXPECT_GE(count, 1) << key << " is at its default";
  }
}

// A summary's config block lists the keys its model kind reads: a matrix run's no
// bar geometry or study (its clamp keys treat the manifest's supports, its outer: and
// search: keys the homogeneous stage); the bar's no manifest.
// Every key named by KeyApplies' lists is a key of the table (the counts below fail on a
// misspelling).
TEST(ConfigTest, AppliedConfigListsTheKeysOfItsModelKindOnly) {
  const std::map<std::string, std::string> every = FlatKeys(ConfigToYaml(Config()));
  const Config matrix = ParseConfig(kEveryMatrixKeyNotAtItsDefault, "matrix.yaml");
  const std::map<std::string, std::string> matrix_keys = FlatKeys(AppliedConfigToYaml(matrix));
  const std::map<std::string, std::string> bar_keys = FlatKeys(AppliedConfigToYaml(Config()));
  for (const char* key : {"model.manifest",
                          "model.channel_map",
                          "data.truth_manifest",
                          "data.truth_moduli",
                          "mcre.w_u",
                          "mcre.reference_modulus",
                          "mcre.clamp",
                          "mcre.w_r",
                          "mcre.w_u0",
                          "inner.method",
                          "outer.lower_bound",
                          "prefilter.cutoff_frequency",
                          "zone_identification.algorithm",
                          "time.step",
                          "load.amplitude",
                          "uncertainty.samples",
                          "inner.max_dense_solver_bytes",
                          "inner.shooting_condition_limit",
                          "search.functional",
                          "outer.scan_points",
                          "outer.initial",
                          "output.curve_points",
                          "zone_identification.merge_zones",
                          "zone_identification.regularization",
                          "data.channels"}) {
    EXPECT_EQ(matrix_keys.count(key), 1u) << key;
    EXPECT_TRUE(KeyApplies(key, ModelKind::kMatrix)) << key;
  }
  for (const char* key :
       {"model.length", "model.zone_count", "data.truth_zones", "study.kind", "data.sensors"}) {
    EXPECT_EQ(matrix_keys.count(key), 0u) << key;
    EXPECT_EQ(bar_keys.count(key), 1u) << key;
  }
  // The bar reads all but the 10 matrix keys (the record's time column, origin and rest
  // before it, and the zones' start modulus and moduli among them); a matrix run none of the
  // section study:
  // and 15 single keys fewer (it reads the dense solvers' limits, Riccati and shooting
  // running on any model, the zones' regularisation and merging, and data.channels, the
  // manifest's sensors it uses).
  EXPECT_EQ(bar_keys.size(), every.size() - 10);
  std::size_t sections = 0;
  for (const auto& [key, value] : every) {
    const std::string section = key.substr(0, key.find('.'));
    sections += section == "study" ? 1 : 0;
  }
  EXPECT_EQ(matrix_keys.size(), every.size() - sections - 15);
  // Values as resolved: the matrix run's own.
  EXPECT_EQ(matrix_keys.at("model.manifest"), FlatKeys(ConfigToYaml(matrix)).at("model.manifest"));
}

// The clamp's treatment and weights apply to a matrix model's supports
// (docs/matrix_models.md section 11).
TEST(ConfigTest, MatrixModelsReadTheClampKeysForTheirSupports) {
  const Config config = ParseConfig(
      "model:\n  kind: matrix\n  manifest: m.yaml\nmcre:\n  clamp: pinned\n  w_r: 0.01\n"
      "  w_u0: 0.2\n",
      "a.yaml");
  EXPECT_EQ(config.mcre.clamp, ClampModel::kPinned);
  EXPECT_EQ(config.mcre.weights.reaction_weight, 0.01);
  EXPECT_EQ(config.mcre.weights.clamp_displacement_weight, 0.2);
  for (const char* key : {"mcre.clamp", "mcre.w_r", "mcre.w_u0"}) {
    EXPECT_TRUE(KeyApplies(key, ModelKind::kMatrix)) << key;
  }
}

TEST(ConfigTest, KeysOfTheOtherKindOfStructureAreRefusedNamingTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"model:\n  manifest: m.yaml\n", "model.manifest applies to model.kind 'matrix' only"},
      {"data:\n  truth_moduli: [1e11]\n", "data.truth_moduli applies to model.kind 'matrix'"},
      {"zone_identification:\n  start_modulus: 1e11\n",
       "zone_identification.start_modulus applies to model.kind 'matrix'"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\nzone_identification:\n  start_modulus: "
       "5e11\n",
       "kinds.yaml:5: zone_identification.start_modulus (5e+11 Pa) must lie strictly inside "
       "[outer.lower_bound, outer.upper_bound] = [1e+11, 4e+11] Pa"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\nzone_identification:\n  start_modulus: "
       "-1\n",
       "zone_identification.start_modulus must be 0 (the homogeneous stage's E*) or a modulus"},
      {"zone_identification:\n  start_moduli: [1e11]\n",
       "zone_identification.start_moduli applies to model.kind 'matrix'"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\nzone_identification:\n  start_moduli: "
       "[2e11, 5e11]\n",
       "kinds.yaml:5: zone_identification.start_moduli (5e+11 Pa) must lie strictly inside "
       "[outer.lower_bound, outer.upper_bound] = [1e+11, 4e+11] Pa"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\nzone_identification:\n  start_moduli: "
       "[-1]\n",
       "zone_identification.start_moduli must hold positive moduli [Pa], got -1"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\nzone_identification:\n  start_moduli: "
       "[2e11]\n  start_modulus: 2e11\n",
       "zone_identification.start_moduli and start_modulus are both given: keep one"},
      {"zone_identification:\n  floor_margin: noise_fit\n  noise_samples: 1\n",
       "zone_identification.floor_margin noise_fit takes the noise's spread from its draws: set "
       "zone_identification.noise_samples to 2 or more"},
      {"model:\n  kind: matrix\n", "model.manifest must name the manifest"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zone_count: 3\n",
       "model.zone_count applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\ndata:\n  sensors: [u@0.5]\n",
       "data.sensors applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  coarse_elements: 50\n",
       "model.coarse_elements applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zoning: boundaries\n",
       "model.zoning 'boundaries' applies to the bar only; on a matrix model use per_element "
       "or grid"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zoning: grid\n",
       "model.zoning 'grid' needs model.zone_grid"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zone_grid: [4, 2]\n",
       "model.zone_grid applies to model.zoning 'grid' only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  free_zones: [grid_0_0]\n",
       "model.free_zones applies to a matrix model with model.zoning per_element or grid"},
      {"model:\n  zoning: grid\n  zone_grid: [4, 2]\n",
       "model.zone_grid must hold one count of zones along the bar"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zoning: grid\n  zone_grid: [4, 0]\n",
       "model.zone_grid: expected 1 to 3 positive integers"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  zoning: grid\n  zone_grid: [1, 2, 3, 4]\n",
       "model.zone_grid: expected 1 to 3 positive integers"},
      // Every key of the bar's structure away from its default, where it was set.
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  elements: 50\n",
       "kinds.yaml:4: model.elements applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\ndata:\n  truth: exact\n",
       "kinds.yaml:5: data.truth applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\ndata:\n  truth_refinement: 3\n",
       "kinds.yaml:5: data.truth_refinement applies to the bar only"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  channel_map: {F: t}\n",
       "cannot map to the time column"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  channel_map: {F: a, G: a}\n",
       "column 'a' is mapped to both 'F' and 'G'"},
      {"model:\n  kind: matrix\n  manifest: m.yaml\n  channel_map: [F, a]\n",
       "expected a map of channel names to CSV columns"},
  };
  for (const auto& [text, reason] : cases) {
    try {
      ParseConfig(text, "kinds.yaml");
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find(reason), std::string::npos)
          << error.what() << "\nexpected: " << reason;
      EXPECT_EQ(std::string(error.what()).rfind("kinds.yaml:", 0), 0u) << error.what();
    }
  }
  // An override names itself; at its default a key of the bar says nothing and passes.
  try {
    ParseConfig("model:\n  kind: matrix\n  manifest: m.yaml\n", "kinds.yaml", {"model.length=2"});
    ADD_FAILURE() << "model.length=2 accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("--set model.length=2: model.length applies", 0), 0u)
        << error.what();
  }
  EXPECT_NO_THROW(
      ParseConfig("model:\n  kind: matrix\n  manifest: m.yaml\n  length: 1\n", "kinds.yaml"));
}

// Least squares is the MCRE's comparator on matrix models too
// (app/matrix_identification_run.h).
TEST(ConfigTest, LeastSquaresIsAcceptedOnAMatrixModel) {
  const Config config = ParseConfig(
      "model:\n  kind: matrix\n  manifest: m.yaml\nouter:\n  functional: least_squares\n",
      "matrix_least_squares.yaml");
  EXPECT_EQ(config.outer.functional, OuterFunctional::kLeastSquares);
  EXPECT_EQ(config.structure.kind, ModelKind::kMatrix);
}

TEST(ConfigTest, PaperBarConfigLoads) {
  const std::string path = std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar.yaml";
  const Config config = LoadConfig(path);
  Config expected;
  expected.data.snr = 2.5;
  expected.output.folder = "results/paper_bar";
  ExpectSameConfig(expected, config);
  EXPECT_EQ(config.source_path, path);
  EXPECT_EQ(config.time.NumSteps(), 1750);
}

TEST(ConfigTest, PaperBarFreeFreeDiffersInItsMcreSectionAndSearchFunctionalOnly) {
  Config expected = LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar.yaml");
  expected.mcre.clamp = ClampModel::kMeasured;
  expected.mcre.weights.displacement_weight = 0.01;
  expected.mcre.weights.strain_weight = 0.01;
  expected.search.functional = SearchFunctional::kSame;
  expected.output.folder = "results/paper_bar_free_free";
  ExpectSameConfig(
      expected, LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar_free_free.yaml"));
}

TEST(ConfigTest, PaperBarPinnedDiffersInItsMcreSectionScanInnerToleranceAndSearchOnly) {
  Config expected = LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar.yaml");
  expected.mcre.clamp = ClampModel::kPinned;
  expected.mcre.weights.displacement_weight = 0.01;
  expected.mcre.weights.strain_weight = 0.01;
  expected.mcre.weights.clamp_displacement_weight = 0.1;
  expected.mcre.weights.reaction_weight = 0.1;
  expected.outer.scan_points = 12;
  expected.inner.tolerance = 1e-6;
  expected.search.functional = SearchFunctional::kSame;
  expected.output.folder = "results/paper_bar_pinned";
  ExpectSameConfig(
      expected, LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar_pinned.yaml"));
}

// configs/bar_zones.yaml: the paper's bar with the damage study's settings that
// localise (scripts/studies.sh), each one named here.
TEST(ConfigTest, BarZonesDiffersFromPaperBarInTheSettingsThatLocalise) {
  Config expected = LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/paper_bar.yaml");
  expected.zones.zoning = Zoning::kEqual;
  expected.zones.zone_count = 10;
  expected.data.truth_zones = {ModulusZone{0.6, 0.7, 140e9}};
  expected.data.sensors = {"u@0.25", "u@0.5", "u@0.75", "e@0.2", "e@0.45", "e@0.65", "e@0.9"};
  expected.data.snr = 10.0;
  expected.mcre.clamp = ClampModel::kMeasured;
  expected.mcre.weights.displacement_weight = 0.01;
  expected.mcre.weights.strain_weight = 1e-4;
  expected.search.functional = SearchFunctional::kSame;
  expected.zone_identification.regularization.kind = RegularizationKind::kTotalVariation;
  expected.zone_identification.merge_zones = true;
  expected.output.folder = "results/bar_zones";
  ExpectSameConfig(expected,
                   LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/bar_zones.yaml"));
}

TEST(ConfigTest, QuickAndMeasuredCsvConfigsLoad) {
  const Config quick = LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/quick.yaml");
  EXPECT_EQ(quick.model.elements, 25);
  EXPECT_EQ(quick.time.NumSteps(), 300);
  EXPECT_EQ(quick.data.snr, 20.0);
  const Config measured =
      LoadConfig(std::string(MCREWAVE_SOURCE_DIR) + "/configs/measured_csv.yaml");
  EXPECT_EQ(measured.data.source, DataSource::kCsv);
  EXPECT_EQ(measured.outer.optimizer, OptimizerType::kCeres);
}

// One YAML document, which may open with '---'; a second is refused at its marker.
// The third text (found by the config fuzzer) made yaml-cpp's LoadAll loop forever.
TEST(ConfigTest, AConfigIsOneYamlDocument) {
  EXPECT_EQ(ParseConfig("# comment\n---\nmodel:\n  elements: 7\n", "a.yaml").model.elements, 7);
  ExpectInputError([] { ParseConfig("model:\n  elements: 7\n--- \noutput: {}\n", "a.yaml"); },
                   {"a.yaml:3: a config is one YAML document; a second one ('---') starts here"});
  try {
    ParseConfig(",\v: d\n-nul-\n", "fuzz.yaml");
  } catch (const InputError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("fuzz.yaml", 0), 0u) << error.what();
  }
}

TEST(ConfigTest, BooleanAcceptsTheYamlSpellings) {
  EXPECT_FALSE(ParseConfig("output:\n  figures: no\n", "a.yaml").output.figures);
  EXPECT_TRUE(ParseConfig("output:\n  figures: yes\n", "a.yaml").output.figures);
  EXPECT_FALSE(ParseConfig("", "a.yaml", {"output.figures=false"}).output.figures);
}

TEST(ConfigTest, EveryCoupledSolverIsAnInnerMethod) {
  for (const char* name : {"all_at_once", "relaxation", "adaptive_relaxation", "conjugate_gradient",
                           "riccati", "single_shooting", "multiple_shooting"}) {
    CoupledSolverType type;
    ASSERT_TRUE(StringToCoupledSolverType(name, &type));
    // mcre.clamp measured and its own scan: the paper's data term.
    EXPECT_EQ(ParseConfig("", "a.yaml",
                          {std::string("inner.method=") + name, "mcre.clamp=measured",
                           "search.functional=same"})
                  .inner.type,
              type);
  }
}

TEST(ConfigTest, RiccatiAndShootingAreAcceptedWithEveryDataTerm) {
  // They solve any clamp and sensors (the general data term W_obs = H^T diag(beta) H,
  // docs/riccati_shooting.md), so no data term is refused at load any more.
  for (const char* name : {"riccati", "single_shooting", "multiple_shooting"}) {
    const std::string method = std::string("inner.method=") + name;
    EXPECT_NO_THROW(ParseConfig("", "a.yaml", {method}));
    EXPECT_NO_THROW(ParseConfig("", "a.yaml", {method, "mcre.clamp=pinned"}));
    EXPECT_NO_THROW(
        ParseConfig("", "a.yaml", {method, "mcre.clamp=measured", "data.sensors=[e@0.5]"}));
    EXPECT_NO_THROW(
        ParseConfig("", "a.yaml", {method, "mcre.clamp=measured", "data.channels=[uL, f0, fL]"}));
    EXPECT_NO_THROW(ParseConfig("", "a.yaml", {method, "mcre.clamp=measured"}));
  }
}

TEST(ConfigTest, EmptyTextAndEmptySectionsGiveDefaults) {
  ExpectSameConfig(Config{}, ParseConfig("", "empty.yaml"));
  ExpectSameConfig(Config{}, ParseConfig("model:\ndata:\n", "sections.yaml"));
}

TEST(ConfigTest, InfiniteSnrIsAccepted) {
  EXPECT_EQ(ParseConfig("data:\n  snr: .inf\n", "a.yaml").data.snr,
            std::numeric_limits<double>::infinity());
}

TEST(ConfigTest, ASupportSpringIsPositiveAndTheExactTruthHasNone) {
  EXPECT_EQ(ParseConfig("data:\n  support_stiffness: 2e8\n", "a.yaml").data.support_stiffness, 2e8);
  ExpectInputError([] { ParseConfig("data:\n  support_stiffness: -1\n", "a.yaml"); },
                   {"a.yaml", "data.support_stiffness must be positive in N/m"});
  ExpectInputError([] { ParseConfig("model:\n  reaction_length: 2\n", "a.yaml"); },
                   {"a.yaml", "model.reaction_length must lie in [0, L = 1] m, got 2"});
  EXPECT_EQ(ParseConfig("model:\n  coarse_elements: 0\n", "a.yaml").model.coarse_elements, 0);
  ExpectInputError([] { ParseConfig("model:\n  coarse_elements: 5\n", "a.yaml"); },
                   {"a.yaml",
                    "model.coarse_elements must be 0 (one mesh) or an integer in [10, "
                    "1e8], got 5"});
  ExpectInputError([] { ParseConfig("model:\n  coarse_elements: -1\n", "a.yaml"); },
                   {"a.yaml", "model.coarse_elements", "an integer >= 0"});
  ExpectInputError(
      [] { ParseConfig("data:\n  truth: exact\n  support_stiffness: 2e8\n", "a.yaml"); },
      {"a.yaml", "data.support_stiffness: the exact truth"});
}

TEST(ConfigTest, TheSupportCheckIsReadAndChecked) {
  const Config defaults;
  EXPECT_EQ(defaults.mcre.support_check, SupportCheckAction::kSwitch);
  const Config config =
      ParseConfig("mcre:\n  support_check: warn\n  support_check_threshold: 3.5\n", "a.yaml");
  EXPECT_EQ(config.mcre.support_check, SupportCheckAction::kWarn);
  EXPECT_EQ(config.mcre.support_check_threshold, 3.5);
  EXPECT_EQ(defaults.mcre.support_check_threshold, 2.5);
  ExpectInputError([] { ParseConfig("mcre:\n  support_check: maybe\n", "a.yaml"); },
                   {"a.yaml", "mcre.support_check", "'switch', 'warn', 'off'"});
  ExpectInputError([] { ParseConfig("mcre:\n  support_check_threshold: 0\n", "a.yaml"); },
                   {"a.yaml", "mcre.support_check_threshold must be a finite positive number"});
  // The ramp: from 1.28 by default; its start at most the threshold (equal: a hard switch).
  EXPECT_EQ(defaults.mcre.support_check_ramp_start, 1.28);
  EXPECT_EQ(ParseConfig("mcre:\n  support_check_ramp_start: 2.5\n", "a.yaml")
                .mcre.support_check_ramp_start,
            2.5);
  ExpectInputError([] { ParseConfig("mcre:\n  support_check_ramp_start: 2.6\n", "a.yaml"); },
                   {"a.yaml",
                    "mcre.support_check_ramp_start must be a finite positive number no larger than "
                    "mcre.support_check_threshold (2.5), got 2.6"});
  ExpectInputError([] { ParseConfig("mcre:\n  support_check_ramp_start: 0\n", "a.yaml"); },
                   {"a.yaml", "mcre.support_check_ramp_start must be"});
}

TEST(ConfigTest, OverridesApplyAfterTheFile) {
  const Config config = ParseConfig("model:\n  elements: 50\n", "a.yaml",
                                    {"model.elements=200", "model.mass=lumped", "data.snr=.inf",
                                     "data.seed=42", "time.theta=1", "data.path=run/m.csv"});
  EXPECT_EQ(config.model.elements, 200);
  EXPECT_EQ(config.model.mass, MassType::kLumped);
  EXPECT_EQ(config.data.snr, std::numeric_limits<double>::infinity());
  EXPECT_EQ(config.data.seed, 42u);
  EXPECT_EQ(config.time.theta, 1.0);
  EXPECT_EQ(config.data.path, "run/m.csv");
}

TEST(ConfigTest, OverrideWithWrongTypeNamesTheOverride) {
  ExpectInputError([] { ParseConfig("", "a.yaml", {"model.elements=abc"}); },
                   {"--set model.elements=abc: expected a positive integer, got 'abc'"});
  ExpectInputError([] { ParseConfig("", "a.yaml", {"model.length=abc"}); },
                   {"--set model.length=abc: expected a number (in m), got 'abc'"});
  ExpectInputError([] { ParseConfig("", "a.yaml", {"model.length="}); },
                   {"--set model.length=: expected a number (in m), got nothing"});
}

TEST(ConfigTest, OverrideOutOfRangeNamesTheOverride) {
  ExpectInputError([] { ParseConfig("time:\n  theta: 0.5\n", "a.yaml", {"time.theta=2"}); },
                   {"--set time.theta=2: ", "time.theta"});
}

TEST(ConfigTest, OverrideWithoutEqualsSignIsRejected) {
  ExpectInputError([] { ParseConfig("", "a.yaml", {"model.elements"}); },
                   {"--set model.elements: ", "key.path=value"});
}

TEST(ConfigTest, OverrideOfUnknownKeySuggestsTheNearestKey) {
  ExpectInputError([] { ParseConfig("", "a.yaml", {"model.lenght=2"}); },
                   {"--set model.lenght=2: unknown key 'model.lenght'; did you mean "
                    "'model.length'?"});
}

TEST(ConfigTest, ParseConfigNamesTheGivenName) {
  ExpectInputError([] { ParseConfig("model:\n  length: abc\n", "my.yaml"); },
                   {"my.yaml:2: model.length: expected a number (in m), got 'abc'"});
}

TEST_F(ConfigFileTest, RelativeDataPathIsResolvedAgainstTheConfigFolder) {
  WriteFile("measured.csv", "t,u0,uL,f0,fL\n");
  const std::string text = "data:\n  source: csv\n  path: measured.csv\n";
  const Config config = LoadConfig(WriteFile("config.yaml", text));
  EXPECT_EQ(config.data.path, (directory_ / "measured.csv").string());
  EXPECT_EQ(ParseConfig(text, "config.yaml").data.path, "measured.csv");
}

TEST_F(ConfigFileTest, AbsoluteDataPathIsKept) {
  const std::string csv = WriteFile("measured.csv", "t,u0,uL,f0,fL\n");
  const Config config =
      LoadConfig(WriteFile("config.yaml", "data:\n  source: csv\n  path: " + csv + "\n"));
  EXPECT_EQ(config.data.path, csv);
}

TEST_F(ConfigFileTest, MissingConfigFile) {
  const std::string path = (directory_ / "absent.yaml").string();
  ExpectInputError([&path] { LoadConfig(path); },
                   {"cannot read config file " + path + ": No such file or directory"});
}

TEST_F(ConfigFileTest, UnknownKeySuggestsTheNearestKey) {
  ExpectLoadError("model:\n  lenght: 2\n", 2,
                  {"unknown key 'model.lenght'; did you mean 'model.length'?"});
}

TEST_F(ConfigFileTest, UnknownSectionSuggestsTheNearestSection) {
  ExpectLoadError("model:\n  length: 2\nmodle:\n  length: 1\n", 3,
                  {"unknown section 'modle'; did you mean 'model'?"});
}

TEST_F(ConfigFileTest, StringGivenForNumber) {
  ExpectLoadError("model:\n  length: abc\n", 2,
                  {"model.length: expected a number (in m), got 'abc'"});
}

TEST_F(ConfigFileTest, ListGivenForNumber) {
  ExpectLoadError("load:\n  amplitude: [1, 2]\n", 2,
                  {"load.amplitude: expected a number (in N), got a list"});
}

TEST_F(ConfigFileTest, FractionGivenForInteger) {
  ExpectLoadError("model:\n  elements: 1.5\n", 2,
                  {"model.elements: expected a positive integer, got '1.5'"});
}

TEST_F(ConfigFileTest, NegativeLength) {
  ExpectLoadError("model:\n  section: 1e-4\n  length: -1\n", 3,
                  {"model.length must be a finite positive number, got -1"});
}

TEST_F(ConfigFileTest, ZeroElements) {
  ExpectLoadError("model:\n  elements: 0\n", 2,
                  {"model.elements: expected a positive integer, got '0'"});
}

TEST_F(ConfigFileTest, ThetaOutOfRange) {
  ExpectLoadError("time:\n  theta: 1.5\n", 2,
                  {"time.theta must lie in [0.5, 1] (unconditionally stable), got 1.5"});
}

TEST_F(ConfigFileTest, StepNotDividingWindow) {
  ExpectLoadError("time:\n  window: 1e-3\n  step: 0.3e-3\n", 2,
                  {"time.window", "time.step", "whole number"});
}

TEST_F(ConfigFileTest, ZeroSnr) {
  ExpectLoadError("data:\n  snr: 0\n", 2, {"data.snr must be positive"});
}

TEST_F(ConfigFileTest, NanSnr) {
  ExpectLoadError("data:\n  snr: .nan\n", 2, {"data.snr: expected a number, got '.nan'"});
}

TEST_F(ConfigFileTest, NanLength) {
  ExpectLoadError("model:\n  length: .NaN\n", 2, {"model.length: expected a number (in m)"});
}

TEST_F(ConfigFileTest, UnknownEnumNameListsTheNames) {
  ExpectLoadError("model:\n  mass: diagonal\n", 2,
                  {"model.mass: expected one of 'consistent', 'lumped', got 'diagonal'"});
}

TEST_F(ConfigFileTest, UnknownClampModelAndComparatorDataAreRefused) {
  ExpectLoadError("mcre:\n  clamp: rigid\n", 2,
                  {"mcre.clamp: expected one of 'measured', 'trusted', 'pinned', got 'rigid'"});
  ExpectLoadError("mcre:\n  w_r: 0\n", 2, {"mcre.w_r must be a finite positive number"});
  ExpectLoadError("mcre:\n  w_u0: -1\n", 2, {"mcre.w_u0 must be a finite positive number"});
  ExpectLoadError("study:\n  comparator:\n    data: [raw, raw]\n", 3,
                  {"study.comparator.data must hold raw, prefilter or both, once each"});
}

TEST_F(ConfigFileTest, SearchKeysAreCheckedAndBelongToThePinnedSearchFunctional) {
  ExpectLoadError("search:\n  functional: other\n", 2,
                  {"search.functional: expected one of 'pinned', 'same', 'measured', got 'other'"});
  ExpectLoadError("search:\n  w_u: 0\n", 2, {"search.w_u must be a finite positive number, got 0"});
  ExpectLoadError("search:\n  w_r: -1\n", 2,
                  {"search.w_r must be a finite positive number, got -1"});
  ExpectLoadError("search:\n  inner_tolerance: 1\n", 2,
                  {"search.inner_tolerance must lie in (0, 1), got 1"});
  ExpectLoadError("search:\n  scan_points: 2\n", 2,
                  {"search.scan_points must lie in [3, 100000], got 2"});
  ExpectLoadError("search:\n  samples_per_valley: 0.5\n", 2,
                  {"search.samples_per_valley must be 0 (outer.scan_samples_per_valley) or lie in "
                   "[1, 100], got 0.5"});
  ExpectLoadError("search:\n  window_points: 2\n", 2,
                  {"search.window_points must lie in [3, 100], got 2"});
  ExpectLoadError("search:\n  refine_window: 0.6\n", 2,
                  {"search.refine_window must lie in (0, 0.5], got 0.6"});
  ExpectLoadError("search:\n  algorithm: lbfgs\n", 2,
                  {"search.algorithm must be bobyqa or secant, got lbfgs"});
  ExpectLoadError("search:\n  relative_tolerance: 0.5\n", 2,
                  {"search.relative_tolerance must be 0 (outer.relative_tolerance) or lie in "
                   "(0, 0.1], got 0.5"});
  ExpectLoadError("search:\n  time_step_factor: 65\n", 2,
                  {"search.time_step_factor must lie in [1, 64], got 65"});
  ExpectLoadError("search:\n  time_step_factor: 0\n", 2, {"search.time_step_factor"});
  // The two stages' scans within outer's limits.
  ExpectLoadError("outer:\n  scan_points: 3\n  scan_max_points: 5\n", 3,
                  {"search.scan_points (6) must not exceed outer.scan_max_points (5)"});
  ExpectLoadError("outer:\n  scan_points: 3\n  max_evaluations: 12\n", 3,
                  {"outer.max_evaluations (12) must be at least search.scan_points + "
                   "search.window_points + 4 = 13 with search.functional 'pinned'"});
  EXPECT_NO_THROW(ParseConfig("outer:\n  scan_points: 3\n  max_evaluations: 13\n", "a.yaml"));
  // A key of the pinned search functional with the functional `same`: ignored, refused.
  ExpectLoadError("search:\n  functional: same\n  w_u0: 0.2\n", 3,
                  {"search.w_u0 applies to search.functional 'pinned' only (search.functional "
                   "is 'same', the scan runs on mcre:'s e^2); leave it out with this functional"});
  // The measured search functional reads w_u and w_e, not the pinned clamp's w_u0 and w_r.
  EXPECT_NO_THROW(ParseConfig("search:\n  functional: measured\n  w_u: 0.1\n", "a.yaml"));
  ExpectLoadError("search:\n  functional: measured\n  w_r: 0.2\n", 3,
                  {"search.w_r applies to search.functional 'pinned' only (search.functional "
                   "is 'measured'"});
  ExpectLoadError(
      "search:\n  functional: measured\nouter:\n  scan_points: 3\n  "
      "max_evaluations: 12\n",
      5, {"with search.functional 'measured'"});
}

TEST_F(ConfigFileTest, NegativeSeed) {
  ExpectLoadError("data:\n  seed: -1\n", 2, {"data.seed: expected an integer", "got '-1'"});
}

TEST_F(ConfigFileTest, TruthRefinementOutOfRange) {
  ExpectLoadError("data:\n  truth_refinement: 65\n", 2,
                  {"data.truth_refinement must be an integer in [1, 64], got 65"});
}

TEST_F(ConfigFileTest, PrefilterCutoffAtOrAboveNyquistIsRefused) {
  // time.step 2 us: Nyquist 250 kHz.
  const std::string time = "time:\n  window: 1e-3\n  step: 2e-6\n";
  ExpectLoadError(time + "prefilter:\n  cutoff_frequency: 250e3\n", 5,
                  {"prefilter.cutoff_frequency (250000 Hz) must be below the Nyquist frequency "
                   "0.5 / time.step = 250000 Hz (time.step = 2e-06 s)"});
  ExpectLoadError(time + "prefilter:\n  enabled: false\n  cutoff_frequency: 1e9\n", 6,
                  {"prefilter.cutoff_frequency (1e+09 Hz) must be below the Nyquist "
                   "frequency"});
  EXPECT_EQ(LoadConfig(WriteFile("below.yaml", time + "prefilter:\n  cutoff_frequency: 249999\n"))
                .prefilter.cutoff_frequency,
            249999.0);
  // 0 (derived from the data) is not compared.
  EXPECT_EQ(LoadConfig(WriteFile("zero.yaml", time + "prefilter:\n  cutoff_frequency: 0\n"))
                .prefilter.cutoff_frequency,
            0.0);
}

TEST_F(ConfigFileTest, PrefilterCutoffAboveNyquistIsPlacedWhereEitherKeyWasSet) {
  // The default time.step 0.36 us: Nyquist 1388888.9 Hz; the override names itself.
  const std::string defaults = WriteFile("defaults.yaml", "");
  ExpectInputError([&defaults] { LoadConfig(defaults, {"prefilter.cutoff_frequency=1.5e6"}); },
                   {"--set prefilter.cutoff_frequency=1.5e6: prefilter.cutoff_frequency "
                    "(1.5e+06 Hz) must be below the Nyquist frequency 0.5 / time.step = "
                    "1388888.888888889 Hz"});
  // A cut-off valid at the file's step, made invalid by a coarser step override:
  // placed on the cut-off's line (the key the message names first).
  const std::string path = WriteFile("config.yaml", "prefilter:\n  cutoff_frequency: 300e3\n");
  EXPECT_EQ(LoadConfig(path).prefilter.cutoff_frequency, 300e3);
  ExpectInputError([&path] { LoadConfig(path, {"time.step=2e-6"}); },
                   {path + ":2: prefilter.cutoff_frequency (300000 Hz) must be below the Nyquist "
                           "frequency 0.5 / time.step = 250000 Hz (time.step = 2e-06 s)"});
}

TEST_F(ConfigFileTest, CsvSourceWithoutPath) {
  ExpectLoadError("data:\n  source: csv\n", 2, {"data.path must name a measurement CSV file"});
}

TEST_F(ConfigFileTest, CsvPathToMissingFile) {
  ExpectLoadError(
      "data:\n  source: csv\n  path: missing.csv\n", 3,
      {"data.path: cannot read measurement file '" + (directory_ / "missing.csv").string() + "'",
       "No such file or directory"});
}

TEST_F(ConfigFileTest, CsvPathOverrideToMissingFileNamesTheOverride) {
  const std::string path = WriteFile("config.yaml", "data:\n  source: csv\n  path: a.csv\n");
  ExpectInputError([&path] { LoadConfig(path, {"data.path=/nonexistent/b.csv"}); },
                   {"--set data.path=/nonexistent/b.csv: data.path: cannot read measurement "
                    "file '/nonexistent/b.csv'"});
}

TEST_F(ConfigFileTest, MalformedYaml) {
  ExpectLoadError("model:\n  length: 1\n  section: [1, 2\nload:\n", 4, {"malformed YAML"});
}

TEST_F(ConfigFileTest, SectionThatIsNotAMap) {
  ExpectLoadError(
      "data:\n  seed: 3\nmodel: 3\n", 3,
      {"model: expected a map of keys (kind, manifest, channel_map, length, section", "got '3'"});
}

TEST_F(ConfigFileTest, TopLevelThatIsNotAMap) {
  ExpectLoadError("- model\n- load\n", 1,
                  {"expected a map of sections (model, load, time, data, mcre, inner, outer, "
                   "search, prefilter, uncertainty, output, study, zone_identification)",
                   "got a list"});
}

TEST_F(ConfigFileTest, DuplicateKey) {
  ExpectLoadError("model:\n  length: 1\n  length: 2\n", 3,
                  {"duplicate key 'model.length' (first given on line 2)"});
}

TEST_F(ConfigFileTest, DuplicateSection) {
  ExpectLoadError("model:\n  length: 1\nmodel:\n  elements: 2\n", 3,
                  {"duplicate section 'model' (first given on line 1)"});
}

}  // namespace
}  // namespace mcrewave
