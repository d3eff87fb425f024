//                         mcrewave identify
//
// Identifies the Young's modulus of an elastic bar, or the zone moduli of any
// linear structure given by matrices from another finite-element code, from noisy
// transient measurements with the modified constitutive relation error (MCRE), and
// simulates the experiment that produces such measurements.
//
// Sample runs:
//   identify run configs/paper_bar.yaml --output results/main
//   identify run configs/quick.yaml --set outer.optimizer=ceres --output /tmp/quick -v
//   identify run configs/measured_csv.yaml -q
//   identify run configs/paper_bar.yaml --set inner.method=streaming_conjugate_gradient -o /tmp/s
//   identify run configs/paper_bar_pinned.yaml -o /tmp/pinned
//   identify run configs/paper_bar.yaml --set data.support_stiffness=2e8 -o /tmp/spring
//   identify simulate configs/paper_bar.yaml --output measurements.csv
//   identify simulate configs/paper_bar.yaml --set data.snr=.inf --output clean.csv
//   identify simulate configs/paper_bar.yaml --set model.elements=400 --output fine.csv
//   identify study configs/studies.yaml --output results
//   identify study configs/studies.yaml --set study.kind=robustness --set study.robustness.seeds=10
//   identify study configs/paper_bar.yaml --set study.kind=comparator
//   identify run configs/paper_bar.yaml --set outer.functional=least_squares -o /tmp/ls
//   identify run configs/quick.yaml --set outer.functional=least_squares --set model.zone_count=10
//       --set 'data.truth_zones=[{start: 0.6, end: 0.7, modulus: 140e9}]' -o /tmp/ls_zones
//   identify run configs/plate.yaml --output /tmp/plate
//   identify run configs/beam3d.yaml --output /tmp/beam3d
//   identify simulate configs/plate.yaml --output plate.csv
//   identify run configs/plate.yaml --set data.source=csv --set data.path=$PWD/plate.csv -o /tmp/p
//   identify sensors configs/plate_zones.yaml --count 20 --set data.snr=20 -o /tmp/sensors
//   identify --print-default-config > my_config.yaml
//
// Description:
//   `run` reads a YAML config, gets the measurements (synthetic, or the CSV file
//   of data.path, resampled onto the config's time grid when sampled otherwise),
//   identifies E by minimising the MCRE cost e^2(E) with the outer optimiser of `outer:` (NLopt
//   or Ceres) over coupled direct/retrograde solves by the method of `inner:` (auto:
//   the stored-field CG, or the streaming CG when its fields exceed
//   inner.max_field_bytes), then computes the cost curve around the identified E, the
//   error map of the constitutive gap and an uncertainty figure, and writes summary.yaml,
//   CSV files and PNG figures into the output folder (include/mcrewave/app/results.h), each
//   file atomically and only at the end. One progress line per outer evaluation at the
//   default level. SIGINT, SIGTERM or SIGHUP stop a run at once, but not while it writes
//   its results: an interrupted run leaves the earlier results of its folder as they were.
//
//   With model.kind: matrix, `run` reads the matrices of model.manifest and identifies
//   every zone modulus at once (include/mcrewave/app/matrix_identification_run.h),
//   writing summary.yaml, zones.csv, fit.csv, the error maps and their figures; the
//   CSV's columns are the manifest's channels (model.channel_map renames them), and
//   `simulate` writes such a CSV from the truth of data.truth_manifest.
//
//   `simulate` reads a YAML config (see include/mcrewave/app/config.h or
//   --print-default-config), simulates the bar clamped at x = 0 (or held there by
//   the spring data.support_stiffness) and hit by a
//   half-sine load at x = L on the truth discretisation of `data:`, samples the
//   four channels (u0, uL, f0, fL) on the model's time grid, adds white noise at
//   the configured SNR and writes the measurement CSV (t,u0,uL,f0,fL).
//
//   `study` reads a YAML config and runs the studies of its `study:` section
//   (include/mcrewave/app/study.h): robustness over SNR and noise seeds, the
//   relaxation coefficient, cost curves; each into a subfolder of the output
//   folder (CSV files, PNG figures, summary.md), then a README.md gathering the
//   summaries. Runs spread over study.threads threads; one progress line per
//   completed run with the time left (-v: the identifications' own lines too).
//
//   `sensors` reads a YAML config of a matrix model and chooses --count of its sensors
//   (say, of a full field) by greedy D-optimal design on the Fisher information of the
//   zone moduli at their nominal values, under the load: history and the noise of
//   data.snr (include/mcrewave/app/sensor_placement_run.h); it writes sensors.csv,
//   cramer_rao.csv and channels.yaml, the data.channels block that runs `run` on them.
//
// Exit code 0 on success (for `run`: a converged identification); otherwise one
// line on stderr saying why and exit code 2 for bad input (config, CSV, options,
// an output folder that cannot be created) or 1 for a failed computation.

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "mcrewave/app/comparator_study.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/damage_study.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/results.h"
#include "mcrewave/app/run.h"
#include "mcrewave/app/sensor_placement_run.h"
#include "mcrewave/app/study.h"
#include "mcrewave/core/version.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/data/noise.h"
#include "mcrewave/model/simulation.h"

namespace {

struct SimulateArguments {
  std::string config_path;
  std::vector<std::string> overrides;
  std::string output_path;
};

struct StudyArguments {
  std::string config_path;
  std::vector<std::string> overrides;
  std::string output_folder;  // "" = study.folder of the config
};

struct RunArguments {
  std::string config_path;
  std::vector<std::string> overrides;
  std::string output_folder;  // "" = output.folder of the config
};

struct SensorsArguments {
  std::string config_path;
  std::vector<std::string> overrides;
  std::string output_folder;
  int count = 20;
};

// Log levels of -v and -q; info (one line per outer evaluation) otherwise.
struct Verbosity {
  bool verbose = false;
  bool quiet = false;
  void Apply() const {
    spdlog::set_level(verbose ? spdlog::level::debug
                              : (quiet ? spdlog::level::warn : spdlog::level::info));
  }
  // For `study`: the progress lines at info (warn with -q); the many
  // identifications' own lines only with -v.
  void ApplyToStudy() const {
    spdlog::set_level(verbose ? spdlog::level::info : spdlog::level::warn);
    mcrewave::StudyProgressLogger()->set_level(quiet ? spdlog::level::warn : spdlog::level::info);
  }
};

// SIGINT, SIGTERM and SIGHUP end the process at once, except while results are
// being written: then the signal is held until every file is in place, so an
// interrupted run leaves either the earlier results or the complete new ones, and
// no temporary file. The handler may run on any thread (Ceres' pool).
volatile std::sig_atomic_t writing_results = 0;
volatile std::sig_atomic_t held_signal = 0;

extern "C" void HoldSignalWhileWriting(int signal_number) {
  if (writing_results != 0) {
    held_signal = signal_number;
    return;
  }
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void InstallSignalHandlers() {
  struct sigaction action = {};
  action.sa_handler = HoldSignalWhileWriting;
  sigemptyset(&action.sa_mask);
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal_number, &action, nullptr);
}

// While it lives, the signals above are held; a held one is raised at its end.
class ResultsBeingWritten {
 public:
  ResultsBeingWritten() { writing_results = 1; }
  ~ResultsBeingWritten() {
    writing_results = 0;
    if (held_signal != 0) {
      std::signal(held_signal, SIG_DFL);
      std::raise(held_signal);
    }
  }
  ResultsBeingWritten(const ResultsBeingWritten&) = delete;
  ResultsBeingWritten& operator=(const ResultsBeingWritten&) = delete;
};

// Throws InputError "<what>: <folder> is not a folder" or "<what>: cannot write in
// <folder>" unless `folder` is a folder this process can write in.
void RequireWritableFolder(const std::filesystem::path& folder, const std::string& what) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) {
    throw mcrewave::InputError(what + ": " + folder.string() + " is not a folder");
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw mcrewave::InputError(what + ": cannot write in " + folder.string());
  }
}

// Throws InputError when `folder` cannot be created or written to: checked
// before any computation, so that a bad --output costs nothing.
void CheckOutputFolder(const std::string& folder) {
  namespace fs = std::filesystem;
  fs::path existing = fs::absolute(folder);
  std::error_code error;
  while (!fs::exists(existing, error) && existing.has_parent_path() &&
         existing.parent_path() != existing) {
    existing = existing.parent_path();
  }
  RequireWritableFolder(existing, "output folder " + folder);
}

// Step 5 of RunIdentify: the identified moduli, against the truth's when it is known.
void ReportModuli(const mcrewave::IdentificationRun& run) {
  const mcrewave::Config& config = run.config;
  if (config.structure.kind == mcrewave::ModelKind::kMatrix) {
    for (std::size_t z = 0; z < run.model->zones.size(); ++z) {
      const auto index = static_cast<Eigen::Index>(z);
      const std::string& name = run.model->zones[z].name;
      if (run.truth_moduli.size() > 0) {
        spdlog::info("zone {}: E = {:.9g} Pa (truth {:.9g} Pa, relative error {:.3e})", name,
                     run.identified_moduli[index], run.truth_moduli[index],
                     run.identified_moduli[index] / run.truth_moduli[index] - 1.0);
      } else {
        spdlog::info("zone {}: E = {:.9g} Pa", name, run.identified_moduli[index]);
      }
    }
    spdlog::info("identified {} zone moduli in {} evaluations, {:.2f} s", run.model->zones.size(),
                 run.TotalEvaluations(), run.wall_time_s);
    return;
  }
  if (run.support_blend.Blends()) {
    spdlog::warn(
        "E weighs the clamp measured by {:.3g} and trusted by {:.3g}: the data may contradict a "
        "rigid clamp (summary.yaml, supports:)",
        run.support_blend.weight, 1.0 - run.support_blend.weight);
  } else if (run.support_switched) {
    spdlog::warn(
        "the clamp was treated as measured: the data contradict a rigid clamp (summary.yaml, "
        "supports:)");
  }
  const char* functional = run.least_squares ? " by least squares" : "";
  if (run.reference_known) {
    spdlog::info(
        "identified E = {:.9g} Pa{} (reference {:.9g} Pa, relative error {:.3e}) in {} "
        "evaluations, {:.2f} s",
        run.identified_modulus(), functional, config.model.modulus,
        (run.identified_modulus() - config.model.modulus) / config.model.modulus,
        run.outer.scan_evaluations + run.outer.evaluations, run.wall_time_s);
  } else {
    spdlog::info("identified E = {:.9g} Pa{} in {} evaluations, {:.2f} s", run.identified_modulus(),
                 functional, run.outer.scan_evaluations + run.outer.evaluations, run.wall_time_s);
  }
}

int RunIdentify(const RunArguments& arguments) {
  // 1. Read and validate the config and the output folder (nothing is computed
  //    or written if either is invalid).
  mcrewave::Config config = mcrewave::LoadConfig(arguments.config_path, arguments.overrides);
  if (!arguments.output_folder.empty()) config.output.folder = arguments.output_folder;
  CheckOutputFolder(config.output.folder);

  // 2. The measurements, and 3. the identification: E (or on a structure given by
  //    matrices its zones' common E*), then every zone modulus, the error maps and the
  //    uncertainty (app/run.h).
  const mcrewave::IdentificationRun run = mcrewave::IdentifyFromConfig(config);
  const std::string unreportable = mcrewave::UnreportableMessage(run);
  if (!unreportable.empty()) {
    std::fprintf(stderr, "error: identification failed: %s\n", unreportable.c_str());
    return 1;
  }

  // 4. Write the results, each file atomically.
  std::vector<std::string> files;
  {
    const ResultsBeingWritten held;
    files = mcrewave::WriteIdentificationResults(run, config.output.folder, config.output.figures);
  }

  // 5. Brief report.
  ReportModuli(run);
  spdlog::info("wrote {} files to {}", files.size(), config.output.folder);
  return 0;
}

int RunSimulate(const SimulateArguments& arguments) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();

  // 1. Read and validate the config and the output file's folder (nothing is
  //    computed if either is invalid).
  const mcrewave::Config config = mcrewave::LoadConfig(arguments.config_path, arguments.overrides);
  // The CSV is written into an existing folder (WriteMeasurementCsv creates none).
  RequireWritableFolder(std::filesystem::absolute(arguments.output_path).parent_path(),
                        "output file " + arguments.output_path);
  if (config.structure.kind == mcrewave::ModelKind::kMatrix) {
    // A structure given by matrices: its truth's outputs and loads, under the columns
    // identify run reads (model.channel_map).
    const mcrewave::ChannelSet table = mcrewave::SimulatedMeasurements(config);
    {
      const ResultsBeingWritten held;
      mcrewave::WriteChannelCsv(table, arguments.output_path);
    }
    spdlog::info("wrote {} samples of {} channels to {} in {:.3f} s", table.num_samples(),
                 table.channels.size(), arguments.output_path,
                 std::chrono::duration<double>(Clock::now() - start).count());
    return 0;
  }
  spdlog::info("config {}: {} elements, {} steps of {:.4g} s, truth {} (refinement {}), SNR {}",
               arguments.config_path, config.model.elements, config.time.NumSteps(),
               config.time.step, mcrewave::TruthModelToString(config.data.truth),
               config.data.truth_refinement, config.data.snr);

  // 2. Simulate the truth and add measurement noise.
  const mcrewave::ChannelSet measurements = mcrewave::SimulatedMeasurements(config);

  // 3. Write the measurement set atomically.
  {
    const ResultsBeingWritten held;
    mcrewave::WriteMeasurementCsv(measurements, arguments.output_path);
  }

  // 4. Brief report.
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  spdlog::info("wrote {} samples to {} in {:.3f} s (RMS uL {:.4g} m, RMS fL {:.4g} N)",
               measurements.num_samples(), arguments.output_path, seconds,
               mcrewave::RootMeanSquare(measurements.Values("uL")),
               mcrewave::RootMeanSquare(measurements.Values("fL")));
  return 0;
}

int RunStudy(const StudyArguments& arguments) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  // 1. Read and validate the config and the output folder.
  mcrewave::Config config = mcrewave::LoadConfig(arguments.config_path, arguments.overrides);
  if (!arguments.output_folder.empty()) config.study.folder = arguments.output_folder;
  if (config.data.source != mcrewave::DataSource::kSynthetic) {
    throw mcrewave::InputError(arguments.config_path +
                               ": data.source: the studies need synthetic data, got 'csv'");
  }
  const mcrewave::StudyKind kind = config.study.kind;
  if (config.structure.kind != mcrewave::ModelKind::kBar &&
      kind != mcrewave::StudyKind::kRobustness && kind != mcrewave::StudyKind::kComparator &&
      kind != mcrewave::StudyKind::kReadme) {
    throw mcrewave::InputError(
        arguments.config_path + ": study.kind '" + mcrewave::StudyKindToString(kind) +
        "' runs on the bar only; with model.kind 'matrix' use study.kind: robustness or "
        "comparator (the plate's own study: scripts/plate_study.sh)");
  }
  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kDamage)) {
    mcrewave::CheckDamageStudyConfig(config, arguments.config_path);
  }
  CheckOutputFolder(config.study.folder);
  const std::string& folder = config.study.folder;
  const bool figures = config.study.figures;
  const std::string structure = config.structure.kind == mcrewave::ModelKind::kBar
                                    ? std::to_string(config.model.elements) + " elements"
                                    : "matrix model " + config.structure.manifest;
  mcrewave::StudyProgressLogger()->info(
      "config {}: {}, {} steps of {:.4g} s; study {} into {}", arguments.config_path, structure,
      config.time.NumSteps(), config.time.step, mcrewave::StudyKindToString(kind), folder);

  // 2. Each selected study: compute, then write its folder.
  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kRobustness)) {
    const std::string journal = mcrewave::StudyJournalPath(config, "robustness");
    const mcrewave::RobustnessStudy study = mcrewave::RunRobustnessStudy(config, journal);
    const ResultsBeingWritten held;
    mcrewave::WriteRobustnessResults(study, folder + "/robustness", figures);
    mcrewave::RemoveStudyJournal(journal);
  }
  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kRelaxation)) {
    const mcrewave::RelaxationStudy study = mcrewave::RunRelaxationStudy(config);
    const ResultsBeingWritten held;
    mcrewave::WriteRelaxationResults(study, folder + "/relaxation", figures);
  }
  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kCostCurves)) {
    const mcrewave::CostCurveStudy study = mcrewave::RunCostCurveStudy(config);
    const ResultsBeingWritten held;
    mcrewave::WriteCostCurveResults(study, folder + "/cost_curves", figures);
  }

  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kDamage)) {
    const std::string journal = mcrewave::StudyJournalPath(config, "damage");
    const mcrewave::DamageStudy study = mcrewave::RunDamageStudy(config, journal);
    const ResultsBeingWritten held;
    mcrewave::WriteDamageResults(study, folder + "/damage", figures);
    mcrewave::RemoveStudyJournal(journal);
  }
  if (mcrewave::StudySelected(kind, mcrewave::StudyKind::kComparator)) {
    const std::string journal = mcrewave::StudyJournalPath(config, "comparator");
    const mcrewave::ComparatorStudy study = mcrewave::RunComparatorStudy(config, journal);
    const ResultsBeingWritten held;
    mcrewave::WriteComparatorResults(study, folder + "/comparator", figures);
    mcrewave::RemoveStudyJournal(journal);
  }

  // 3. The README gathering the studies' summaries.
  std::string readme;
  {
    const ResultsBeingWritten held;
    readme = mcrewave::WriteStudiesReadme(folder);
  }

  // 4. Brief report.
  mcrewave::StudyProgressLogger()->info(
      "study {} done in {:.1f} s; summaries in {}", mcrewave::StudyKindToString(kind),
      std::chrono::duration<double>(Clock::now() - start).count(), readme);
  return 0;
}

int RunSensors(const SensorsArguments& arguments) {
  // 1. Read and validate the config and the output folder.
  const mcrewave::Config config = mcrewave::LoadConfig(arguments.config_path, arguments.overrides);
  CheckOutputFolder(arguments.output_folder);

  // 2. The candidates' information and the greedy choice.
  const mcrewave::SensorPlacementRun run = mcrewave::RunSensorPlacement(config, arguments.count);

  // 3. Write the results, each file atomically.
  std::vector<std::string> files;
  {
    const ResultsBeingWritten held;
    files = mcrewave::WriteSensorPlacementResults(run, arguments.output_folder);
  }

  // 4. Brief report.
  spdlog::info("{} in {:.2f} s; wrote {} files to {}", run.placement.BriefReport(), run.wall_time_s,
               files.size(), arguments.output_folder);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mcrewave identify: MCRE identification of the moduli of an elastic structure (a bar, or any "
      "structure given by matrices)"};
  app.set_version_flag("--version", std::string("mcrewave ") + mcrewave::kVersion);
  app.require_subcommand(0, 1);
  bool print_default_config = false;
  app.add_flag("--print-default-config", print_default_config,
               "Print a fully commented default config and exit");

  RunArguments run;
  Verbosity run_verbosity;
  CLI::App* run_command =
      app.add_subcommand("run", "Identify E from the measurements of a config; write the results");
  run_command->add_option("config", run.config_path, "YAML config file")->required();
  run_command
      ->add_option("--set", run.overrides,
                   "Override a config key: --set key.path=value (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  run_command->add_option("-o,--output", run.output_folder,
                          "Results folder (replaces output.folder of the config)");
  CLI::Option* run_verbose =
      run_command->add_flag("-v,--verbose", run_verbosity.verbose, "Log every inner solve too");
  run_command->add_flag("-q,--quiet", run_verbosity.quiet, "Log warnings and errors only")
      ->excludes(run_verbose);

  SimulateArguments simulate;
  Verbosity simulate_verbosity;
  CLI::App* simulate_command =
      app.add_subcommand("simulate", "Simulate the experiment and write a measurement CSV");
  simulate_command->add_option("config", simulate.config_path, "YAML config file")->required();
  simulate_command
      ->add_option("--set", simulate.overrides,
                   "Override a config key: --set key.path=value (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  simulate_command->add_option("-o,--output", simulate.output_path, "Measurement CSV to write")
      ->required();
  CLI::Option* simulate_verbose =
      simulate_command->add_flag("-v,--verbose", simulate_verbosity.verbose, "Log more");
  simulate_command->add_flag("-q,--quiet", simulate_verbosity.quiet, "Log warnings and errors only")
      ->excludes(simulate_verbose);

  StudyArguments study;
  Verbosity study_verbosity;
  CLI::App* study_command = app.add_subcommand(
      "study", "Run the studies of the config's study: section; write CSV files and figures");
  study_command->add_option("config", study.config_path, "YAML config file")->required();
  study_command
      ->add_option("--set", study.overrides,
                   "Override a config key: --set key.path=value (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  study_command->add_option("-o,--output", study.output_folder,
                            "Results folder (replaces study.folder of the config)");
  CLI::Option* study_verbose = study_command->add_flag("-v,--verbose", study_verbosity.verbose,
                                                       "Log the identifications' own lines too");
  study_command->add_flag("-q,--quiet", study_verbosity.quiet, "Log warnings and errors only")
      ->excludes(study_verbose);

  SensorsArguments sensors;
  Verbosity sensors_verbosity;
  CLI::App* sensors_command = app.add_subcommand(
      "sensors", "Choose a few of a matrix model's sensors by D-optimal design; write them");
  sensors_command->add_option("config", sensors.config_path, "YAML config file")->required();
  sensors_command
      ->add_option("--set", sensors.overrides,
                   "Override a config key: --set key.path=value (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sensors_command->add_option("-n,--count", sensors.count, "Sensors to choose (default 20)");
  sensors_command->add_option("-o,--output", sensors.output_folder, "Results folder")->required();
  CLI::Option* sensors_verbose =
      sensors_command->add_flag("-v,--verbose", sensors_verbosity.verbose, "Log more");
  sensors_command->add_flag("-q,--quiet", sensors_verbosity.quiet, "Log warnings and errors only")
      ->excludes(sensors_verbose);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& help_or_version) {
    return app.exit(help_or_version);
  } catch (const CLI::ParseError& error) {
    // Bad command-line options are bad input: one line, exit code 2.
    std::fprintf(stderr, "error: %s (see identify --help)\n", error.what());
    return 2;
  }

  InstallSignalHandlers();
  try {
    if (print_default_config) {
      std::cout << mcrewave::DefaultConfigYaml();
      return 0;
    }
    if (run_command->parsed()) {
      run_verbosity.Apply();
      return RunIdentify(run);
    }
    if (study_command->parsed()) {
      study_verbosity.ApplyToStudy();
      return RunStudy(study);
    }
    if (sensors_command->parsed()) {
      sensors_verbosity.Apply();
      return RunSensors(sensors);
    }
    if (simulate_command->parsed()) {
      simulate_verbosity.Apply();
      return RunSimulate(simulate);
    }
    std::cerr << app.help();
    return 1;
  } catch (const mcrewave::InputError& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
}
