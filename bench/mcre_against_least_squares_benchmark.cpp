// CPU time of the MCRE identification against output-error least squares on the same
// data, measured side by side in one process (A B A B), and where the MCRE's sweeps go.
//
// The bar (configs/paper_bar.yaml, or the config given): its synthetic data at SNR 20,
// 10, 5 and 2.5 and noise seeds 1..S, pre-filtered as identify run does, each data set
// identified
//   (A) by the MCRE as identify run and the comparator study identify it: the supports
//       tested against the raw data (ConfigForTheSupports), then IdentifyWithMcre (the
//       search functional's scan and refinement, e^2's window scan and refinement);
//   (B) by least squares as identify run's outer.functional least_squares does:
//       OutputErrorModulusObjective normalised by LeastSquaresMisfitLevels, then
//       Identify with the same outer: section (its global scan on J, then NLopt).
// Both on one scan thread. Each run's CPU time is the process's (user + system) over
// the call; per data set the minimum over the repeats, A and B alternating; per SNR the
// median over the seeds, and the ratio A / B of the medians; the most valleys the
// MCRE's global scan saw over the seeds, and how far apart the two E are.
//
// The plate (configs/plate.yaml): every zone modulus by RunMatrixIdentification without
// maps or uncertainty (what a study needs of each run), outer.functional mcre against
// least_squares, at the config's SNR over the seeds.
//
// Then the MCRE's sweeps on the bar's first data set by stage: the scans (the search
// functional's and e^2's window), the search's refinement, and e^2's refinement, with that
// refinement's coupled solves, their CG iterations and the sweeps a solve spends
// outside its iterations (its start and its final check).
//
// Goals (issue 41): the ratio at most 1.5 at every SNR, the bar's MCRE at most 0.2 CPU s.
//
// Usage: mcre_against_least_squares_benchmark [--seeds S] [--repeats N] [--no-plate]
//            [--set key=value ...] [BAR_CONFIG.yaml]
//   paths relative to the working directory (default configs/paper_bar.yaml; the plate's
//   configs/plate.yaml from the source tree); --set applies to both configs.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/least_squares/output_error_modulus_objective.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/identification.h"

namespace {

using namespace mcrewave;
using bench::ProcessCpuSeconds;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// One data set of the bar: the raw and the identification's (pre-filtered) data, the
// model on the latter.
struct BarDataSet {
  Config config;
  ChannelSet measured;
  ChannelSet data;
  MatrixModelData model;
};

BarDataSet MakeBarDataSet(const Config& given, double snr, int seed) {
  BarDataSet set;
  set.config = given;
  set.config.data.snr = snr;
  set.config.data.seed = static_cast<std::uint64_t>(seed);
  set.config.outer.scan_threads = 1;
  set.measured = SyntheticMeasurements(set.config);
  set.data = PrefilterMeasurements(set.measured, set.config.prefilter, nullptr);
  set.model = BarRunModel(BarModel(set.config.model), set.data, EndDisplacementChannels());
  return set;
}

struct Timed {
  double cpu_s = std::numeric_limits<double>::infinity();
  double modulus = 0.0;
  long sweeps = 0;
  int valleys = 0;  // of the global scan
  bool usable = false;
};

// (A): the support test, then IdentifyWithMcre; *identification keeps the last one.
Timed RunMcre(const BarDataSet& set, McreIdentification* identification) {
  Timed timed;
  const double start = ProcessCpuSeconds();
  std::vector<SupportCheck> checks;
  bool switched = false;
  double weight = 0.0;
  const Config config = ConfigForTheSupports(set.config, set.model, set.measured, set.data, &checks,
                                             &switched, &weight, /*log=*/false);
  *identification = IdentifyWithMcre(config, set.model, set.data);
  timed.cpu_s = ProcessCpuSeconds() - start;
  timed.modulus = identification->outer.modulus;
  timed.valleys = identification->outer.local_minima;
  timed.usable = identification->outer.IsSolutionUsable();
  timed.sweeps = identification->outer.scan_sweeps + identification->objective->sweeps() +
                 identification->search_sweeps;
  return timed;
}

// (B): least squares with the same outer: section.
Timed RunLeastSquaresOn(const BarDataSet& set) {
  Timed timed;
  const double start = ProcessCpuSeconds();
  std::string source;
  const NoiseLevels levels = LeastSquaresMisfitLevels(set.config, set.measured, set.data, &source);
  OutputErrorModulusObjective objective(set.model, set.data, levels, set.config.time.theta,
                                        set.config.outer.initial);
  const IdentificationSummary summary = Identify(set.config.outer, &objective);
  timed.cpu_s = ProcessCpuSeconds() - start;
  timed.modulus = summary.modulus;
  timed.usable = summary.IsSolutionUsable();
  timed.sweeps = objective.sweeps() + summary.scan_sweeps;
  return timed;
}

void Keep(const Timed& run, Timed* best) {
  if (run.cpu_s < best->cpu_s) *best = run;
}

// The MCRE's sweeps of one identification by stage (the header's last paragraph).
void PrintSweepsByStage(const McreIdentification& identification) {
  const IdentificationSummary& outer = identification.outer;
  const std::vector<ObjectiveEvaluation>& evaluations = identification.objective->evaluations();
  long solves = 0, iterations = 0, sweeps = 0;
  for (const ObjectiveEvaluation& evaluation : evaluations) {
    ++solves;
    iterations += std::max(evaluation.inner.iterations, 0);
    sweeps += std::max(evaluation.inner.sweeps, 0L);
  }
  std::printf(
      "  MCRE sweeps by stage: the scans (the search functional's and e^2's window) %ld, the "
      "search's refinement %ld, e^2's refinement %ld (%ld solves, %ld CG iterations: %ld "
      "sweeps in iterations, %.1f a solve outside them); evaluations: scans and search %d, "
      "e^2's refinement %d\n",
      outer.scan_sweeps, identification.search_sweeps, sweeps, solves, iterations, 2 * iterations,
      solves > 0 ? static_cast<double>(sweeps - 2 * iterations) / solves : 0.0,
      outer.scan_evaluations, outer.evaluations);
}

void RunBar(const Config& config, int seeds, int repeats) {
  std::printf("bar: %d nodes, %d steps; seeds 1..%d, %d repeats (CPU s of one identification)\n",
              config.model.elements + 1, config.time.NumSteps(), seeds, repeats);
  std::printf("  %-6s %-10s %-10s %-7s %-12s %-12s %-13s %s\n", "SNR", "MCRE [s]", "LS [s]",
              "ratio", "MCRE sweeps", "LS sweeps", "MCRE valleys", "max |E_MCRE / E_LS - 1|");
  McreIdentification first;  // of the first data set
  for (const double snr : {20.0, 10.0, 5.0, 2.5}) {
    std::vector<double> mcre_s, ls_s, mcre_sweeps, ls_sweeps;
    double largest_difference = 0.0;
    int most_valleys = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      const BarDataSet set = MakeBarDataSet(config, snr, seed);
      Timed mcre, least_squares;
      McreIdentification identification;
      for (int r = 0; r < repeats; ++r) {
        Keep(RunMcre(set, &identification), &mcre);
        Keep(RunLeastSquaresOn(set), &least_squares);
      }
      if (!mcre.usable || !least_squares.usable) {
        std::printf("  SNR %g seed %d: %s\n", snr, seed,
                    !mcre.usable ? "the MCRE did not converge" : "least squares did not converge");
      }
      mcre_s.push_back(mcre.cpu_s);
      ls_s.push_back(least_squares.cpu_s);
      mcre_sweeps.push_back(static_cast<double>(mcre.sweeps));
      ls_sweeps.push_back(static_cast<double>(least_squares.sweeps));
      largest_difference =
          std::max(largest_difference, std::abs(mcre.modulus / least_squares.modulus - 1.0));
      most_valleys = std::max(most_valleys, mcre.valleys);
      if (first.objective == nullptr) first = std::move(identification);
    }
    const double mcre_median = Median(mcre_s), ls_median = Median(ls_s);
    std::printf("  %-6g %-10.4f %-10.4f %-7.2f %-12.0f %-12.0f %-13d %.2e\n", snr, mcre_median,
                ls_median, mcre_median / ls_median, Median(mcre_sweeps), Median(ls_sweeps),
                most_valleys, largest_difference);
  }
  PrintSweepsByStage(first);
}

void RunPlate(const std::string& path, const std::vector<std::string>& overrides, int seeds,
              int repeats) {
  Config config = LoadConfig(path, overrides);
  const MatrixModelData model = LoadMatrixModel(config);
  std::printf("plate: %d dofs, %d zones, %d steps, SNR %g; seeds 1..%d, %d repeats\n", model.dofs(),
              static_cast<int>(model.zones.size()), config.time.NumSteps(), config.data.snr, seeds,
              repeats);
  std::vector<double> mcre_s, ls_s;
  double largest_difference = 0.0;
  for (int seed = 1; seed <= seeds; ++seed) {
    config.data.seed = static_cast<std::uint64_t>(seed);
    const MatrixMeasurements measurements = LoadMatrixMeasurements(config, model);
    Config least_squares_config = config;
    least_squares_config.outer.functional = OuterFunctional::kLeastSquares;
    double mcre = std::numeric_limits<double>::infinity();
    double least_squares = mcre;
    Vector mcre_moduli, ls_moduli;
    for (int r = 0; r < repeats; ++r) {
      double start = ProcessCpuSeconds();
      const IdentificationRun a = RunMatrixIdentification(config, model, measurements, false);
      mcre = std::min(mcre, ProcessCpuSeconds() - start);
      start = ProcessCpuSeconds();
      const IdentificationRun b =
          RunMatrixIdentification(least_squares_config, model, measurements, false);
      least_squares = std::min(least_squares, ProcessCpuSeconds() - start);
      mcre_moduli = a.zones.summary.moduli;
      ls_moduli = b.zones.summary.moduli;
    }
    mcre_s.push_back(mcre);
    ls_s.push_back(least_squares);
    if (mcre_moduli.size() == ls_moduli.size() && mcre_moduli.size() > 0) {
      largest_difference = std::max(
          largest_difference, (mcre_moduli.array() / ls_moduli.array() - 1.0).abs().maxCoeff());
    }
  }
  const double mcre_median = Median(mcre_s), ls_median = Median(ls_s);
  std::printf("  MCRE %.4f s, LS %.4f s, ratio %.2f; max |E_z,MCRE / E_z,LS - 1| %.2e\n",
              mcre_median, ls_median, mcre_median / ls_median, largest_difference);
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  int seeds = 5;
  int repeats = 3;
  bool plate = true;
  std::string path = "configs/paper_bar.yaml";
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seeds") == 0 && i + 1 < argc) {
      seeds = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--no-plate") == 0) {
      plate = false;
    } else if (std::strcmp(argv[i], "--set") == 0 && i + 1 < argc) {
      overrides.emplace_back(argv[++i]);
    } else {
      path = argv[i];
    }
  }
  RunBar(LoadConfig(path, overrides), seeds, repeats);
  if (plate) {
    RunPlate(std::string(MCREWAVE_SOURCE_DIR) + "/configs/plate.yaml", overrides, seeds, repeats);
  }
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
