// Wall time of the identification of zone moduli (identification/zone_identification.h) on the
// paper's case (configs/paper_bar_free_free.yaml, or the config given), after the
// scalar identification that gives the homogeneous start E*. The data below are those
// of the free-free model (driven by both measured end forces), hence its config: the
// trusted clamp's model does not reproduce them.
//
// Data: the end forces of the paper's experiment drive a per-element truth of the
// model's own mesh with a soft zone of 0.7 E over [0.6, 0.7] L (direct sweep at W = 0);
// its end displacements are the measured ones (noise-free unless --snr is given, then
// seeded white noise at that SNR on both kinds, as noise.h defines it). For Z = 10 equal
// zones and one zone per element it reports the scalar E*, the zone identification's
// time, evaluations, weight, the worst zone error and the mean over [0.6, 0.7] L.
// The zone identification options are the config's (zone_identification.*), the
// optimiser and algorithm those of --optimizer and --algorithm when given.
// Goals (issue 13): 10 zones under 5 s, 100 zones under 20 s on one core.
//
// Usage: zone_identification_benchmark [--snr S] [--optimizer nlopt|ceres] [--algorithm NAME]
//        [--zones Z] [--verbose]
//        [CONFIG.yaml]
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/identification/zone_identification.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace {

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double Rms(const mcrewave::Vector& v) { return std::sqrt(v.squaredNorm() / v.size()); }

// The benchmark's command line (see the usage above).
struct ZoneBenchArguments {
  std::string path = "configs/paper_bar_free_free.yaml";
  double snr = std::numeric_limits<double>::infinity();
  mcrewave::OptimizerType optimizer = mcrewave::OptimizerType::kNlopt;
  mcrewave::OuterAlgorithm algorithm = mcrewave::OuterAlgorithm::kLbfgs;
  bool optimizer_given = false;
  bool algorithm_given = false;
  bool verbose = false;
  int only_zones = 0;  // 0: both
};

// Reads the command line into arguments; 0, or the exit status 2 after an unknown
// optimizer or algorithm.
int ParseZoneBenchArguments(int argc, char** argv, ZoneBenchArguments* arguments) {
  using namespace mcrewave;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--snr") == 0 && i + 1 < argc) {
      arguments->snr = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--verbose") == 0) {
      arguments->verbose = true;
    } else if (std::strcmp(argv[i], "--zones") == 0 && i + 1 < argc) {
      arguments->only_zones = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--optimizer") == 0 && i + 1 < argc) {
      arguments->optimizer_given = true;
      if (!StringToOptimizerType(argv[++i], &arguments->optimizer)) {
        std::fprintf(stderr, "unknown optimizer %s\n", argv[i]);
        return 2;
      }
    } else if (std::strcmp(argv[i], "--algorithm") == 0 && i + 1 < argc) {
      arguments->algorithm_given = true;
      if (!StringToOuterAlgorithm(argv[++i], &arguments->algorithm)) {
        std::fprintf(stderr, "unknown algorithm %s\n", argv[i]);
        return 2;
      }
    } else {
      arguments->path = argv[i];
    }
  }
  return 0;
}

// The truth: a soft zone of 0.7 E over [0.6, 0.7] L, one modulus per element, driven by
// the data's end forces; its end displacements replace the data's. Returns the truth's
// moduli.
mcrewave::Vector ReplaceBySoftZoneTruth(const mcrewave::Config& config,
                                        mcrewave::ChannelSet* data) {
  using namespace mcrewave;
  ZoneLayout per_element;
  per_element.zoning = Zoning::kPerElement;
  const BarModel truth_model(config.model, per_element.ElementZones(config.model));
  Vector truth(config.model.elements);
  for (int e = 0; e < config.model.elements; ++e) {
    const double x = truth_model.element_midpoint(e) / config.model.length;
    truth[e] = (x > 0.6 && x < 0.7 ? 0.7 : 1.0) * config.model.modulus;
  }
  const MatrixModelData truth_matrices = BarRunModel(truth_model, *data, {});
  MatrixMcreProblem truth_problem(truth_matrices, *data, config.mcre.weights,
                                  config.mcre.reference_modulus, config.time.theta);
  truth_problem.SetModuli(truth);
  Matrix displacement;
  truth_problem.DirectSweep(truth_problem.ZeroField(), true, &displacement);
  data->Values("u0") = displacement.row(0).transpose();
  data->Values("uL") = displacement.row(truth_model.num_nodes() - 1).transpose();
  return truth;
}

// Seeded white noise at SNR snr on the end displacements and the end forces.
void AddEndNoise(double snr, mcrewave::ChannelSet* data) {
  using namespace mcrewave;
  std::mt19937_64 engine(1);
  std::normal_distribution<double> normal;
  const double u_std = Rms(data->Values("uL")) / snr;
  const double f_std = Rms(data->Values("fL")) / snr;
  for (Vector* v : {&data->Values("u0"), &data->Values("uL")}) {
    for (double& value : *v) value += u_std * normal(engine);
  }
  for (Vector* v : {&data->Values("f0"), &data->Values("fL")}) {
    for (double& value : *v) value += f_std * normal(engine);
  }
}

// One row of the table: the zone moduli of `zones` zones identified from the scalar
// run's E* and data, their time, worst error against the truth and mean over the soft
// zone.
void IdentifyAndReportZones(int zones, const mcrewave::Config& config,
                            const ZoneBenchArguments& arguments,
                            const mcrewave::IdentificationRun& scalar,
                            const mcrewave::NoiseLevels& noise,
                            const mcrewave::PrefilterOptions& prefilter,
                            const mcrewave::Vector& truth) {
  using namespace mcrewave;
  ZoneLayout layout;
  layout.zone_count = zones;
  if (zones == config.model.elements) layout.zoning = Zoning::kPerElement;
  const BarModel model(config.model, layout.ElementZones(config.model));
  ZoneIdentificationOptions options = config.zone_identification;
  options.minimizer.optimizer = arguments.optimizer;
  options.minimizer.algorithm = arguments.algorithm;
  const auto start = std::chrono::steady_clock::now();
  const ZoneIdentificationSummary summary = IdentifyZoneModuli(
      options, BarRunModel(model, scalar.data, scalar.ends), scalar.data, config.mcre,
      config.time.theta, config.inner, scalar.identified_modulus(), config.outer.lower_bound,
      config.outer.upper_bound, noise, prefilter, &scalar.solution.WarmStart());
  const double seconds = Seconds(start);
  if (summary.moduli.size() == 0) {
    std::fprintf(stderr, "%d zones: %s\n", zones, summary.message.c_str());
    return;
  }
  double worst = 0.0, soft_sum = 0.0;
  int soft_count = 0;
  for (int e = 0; e < config.model.elements; ++e) {
    const double identified = summary.moduli[model.element_zone(e)];
    worst = std::max(worst, std::abs(identified / truth[e] - 1.0));
    const double x = model.element_midpoint(e) / config.model.length;
    if (x > 0.6 && x < 0.7) {
      soft_sum += identified;
      ++soft_count;
    }
  }
  std::printf("%6d %8.2f %12d %10ld %12.3g %13.3g%% %14.4f %s (%s)\n", zones, seconds,
              summary.evaluations, summary.sweeps, summary.regularized.weight, 100.0 * worst,
              soft_sum / soft_count / (0.7 * config.model.modulus),
              summary.regularized.weight_choice.c_str(),
              TerminationTypeToString(summary.termination));
  if (!summary.IsSolutionUsable()) std::printf("  %s\n", summary.message.c_str());
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  using namespace mcrewave;
  ZoneBenchArguments arguments;
  const int status = ParseZoneBenchArguments(argc, argv, &arguments);
  if (status != 0) return status;
  const std::string& path = arguments.path;
  const double snr = arguments.snr;
  spdlog::set_level(arguments.verbose ? spdlog::level::info : spdlog::level::warn);
  try {
    Config config = LoadConfig(path, {"data.snr=.inf"});
    if (!arguments.optimizer_given) {
      arguments.optimizer = config.zone_identification.minimizer.optimizer;
    }
    if (!arguments.algorithm_given) {
      arguments.algorithm = config.zone_identification.minimizer.algorithm;
    }
    ChannelSet data = LoadMeasurements(config);
    const Vector truth = ReplaceBySoftZoneTruth(config, &data);
    if (std::isfinite(snr)) AddEndNoise(snr, &data);
    const NoiseLevels noise = DifferenceNoiseLevels(data);
    const auto scalar_start = std::chrono::steady_clock::now();
    const IdentificationRun scalar = IdentifyModulus(config, data);
    const double scalar_s = Seconds(scalar_start);
    if (!scalar.IsUsable()) {
      std::fprintf(stderr, "scalar identification failed: %s\n", scalar.outer.message.c_str());
      return 1;
    }
    std::printf(
        "%s: %d elements, %d steps, SNR %g, %s %s; scalar E* = %.6g GPa in %.2f s\n", path.c_str(),
        config.model.elements, data.num_steps(), snr, OptimizerTypeToString(arguments.optimizer),
        OuterAlgorithmToString(arguments.algorithm), scalar.identified_modulus() * 1e-9, scalar_s);
    std::printf("%6s %8s %12s %10s %12s %14s %14s %s\n", "zones", "time [s]", "evaluations",
                "sweeps", "weight", "worst error", "soft mean/0.7E", "choice");
    PrefilterOptions prefilter = config.prefilter;
    prefilter.cutoff_frequency = scalar.prefilter_cutoff;
    for (int zones : {10, config.model.elements}) {
      if (arguments.only_zones > 0 && zones != arguments.only_zones) continue;
      IdentifyAndReportZones(zones, config, arguments, scalar, noise, prefilter, truth);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
