// CPU cost of one identification, as `identify run` does it, and of one sweep step.
//
// For each config (default: configs/paper_bar.yaml and configs/quick.yaml, paths
// relative to the working directory) it loads the data exactly as `identify run`
// does (synthetic data, pre-filter) and reports:
//   (a) IdentifyWithMcre alone (the scans and refinements of the config's outer and
//       search sections, two stages by default): the identified E, the evaluations
//       of the scans (the search functional's included) and of e^2's refinements,
//       their sweeps, and the CPU time (user + system of the whole process, so the
//       scan's threads count);
//   (b) RunIdentification (Identify, then the cost curve and the uncertainty of
//       `identify run`, without writing files): CPU time and sweeps;
//   (c) one direct and one retrograde sweep of the config's problem at E_ref: CPU
//       time per time step.
// CPU times, not wall times: the machine is shared. Repeats take the minimum.
//
// Goal (paper_bar.yaml): Identify <= 0.5 CPU s, so that a robustness study of 400
// identifications fits in 2 minutes on 2 cores.
//
// Usage: identification_benchmark [--repeats N] [--identify-only] [--set key=value ...]
//                                 [CONFIG.yaml ...]
//   --identify-only: (a) only, e.g. under valgrind --tool=callgrind;
//   --set: config overrides as in `identify run --set`, e.g. --set data.seed=3.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/identification.h"

namespace {

using mcrewave::bench::ProcessCpuSeconds;

struct IdentifyFigures {
  double cpu_s = std::numeric_limits<double>::infinity();
  double modulus = -1.0;
  int scan_evaluations = 0;
  int evaluations = 0;
  long scan_sweeps = 0;
  long refinement_sweeps = 0;
  bool usable = false;
};

IdentifyFigures IdentifyOnce(const mcrewave::Config& config, const mcrewave::ChannelSet& data) {
  IdentifyFigures figures;
  const mcrewave::MatrixModelData model = mcrewave::BarRunModel(
      mcrewave::BarModel(config.model), data, mcrewave::EndDisplacementChannels());
  const double start = ProcessCpuSeconds();
  const mcrewave::McreIdentification identification =
      mcrewave::IdentifyWithMcre(config, model, data);
  figures.cpu_s = ProcessCpuSeconds() - start;
  const mcrewave::IdentificationSummary& summary = identification.outer;
  figures.modulus = summary.modulus;
  figures.scan_evaluations = summary.scan_evaluations;
  figures.evaluations = summary.evaluations;
  figures.scan_sweeps = summary.scan_sweeps;
  figures.refinement_sweeps = identification.objective->sweeps() + identification.search_sweeps;
  figures.usable = summary.IsSolutionUsable();
  return figures;
}

// CPU seconds per time step of a direct and of a retrograde sweep at E_ref, and of
// one direct sweep of a batch of 3 (DirectSweepsWithData).
struct SweepStepTimes {
  double direct = 0.0, retrograde = 0.0, batched_direct = 0.0;
};

SweepStepTimes SweepStepSeconds(const mcrewave::Config& config, const mcrewave::ChannelSet& data) {
  const mcrewave::BarModel model(config.model);
  const mcrewave::MatrixModelData matrices = mcrewave::BarRunModel(model, data, {});
  mcrewave::MatrixMcreProblem problem(matrices, data, config.mcre.weights,
                                      config.mcre.reference_modulus, config.time.theta,
                                      mcrewave::Factorization::kAutomatic, config.mcre.clamp);
  problem.SetModulus(config.model.modulus);
  mcrewave::Matrix retrograde = problem.ZeroField(), displacement;
  problem.DirectSweep(retrograde, true, &displacement);
  problem.RetrogradeSweep(displacement, true, &retrograde);
  const int repeats = std::max(5, 200000 / problem.num_steps());
  double direct = std::numeric_limits<double>::infinity();
  double backward = std::numeric_limits<double>::infinity();
  double batched = std::numeric_limits<double>::infinity();
  mcrewave::Matrix u1, u2;
  for (int round = 0; round < 3; ++round) {
    double start = mcrewave::bench::ThreadCpuSeconds();
    for (int i = 0; i < repeats; ++i) problem.DirectSweep(retrograde, true, &displacement);
    direct = std::min(direct, (mcrewave::bench::ThreadCpuSeconds() - start) / repeats);
    start = mcrewave::bench::ThreadCpuSeconds();
    for (int i = 0; i < repeats; ++i) problem.RetrogradeSweep(displacement, true, &retrograde);
    backward = std::min(backward, (mcrewave::bench::ThreadCpuSeconds() - start) / repeats);
    start = mcrewave::bench::ThreadCpuSeconds();
    for (int i = 0; i < repeats; i += 3) {
      problem.DirectSweepsWithData({&retrograde, nullptr, &retrograde}, {&displacement, &u1, &u2});
    }
    batched = std::min(batched,
                       (mcrewave::bench::ThreadCpuSeconds() - start) / (3 * ((repeats + 2) / 3)));
  }
  const double steps = problem.num_steps();
  return {direct / steps, backward / steps, batched / steps};
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);
  int repeats = 3;
  bool identify_only = false;
  std::vector<std::string> paths, overrides;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--identify-only") == 0) {
      identify_only = true;
    } else if (std::strcmp(argv[i], "--set") == 0 && i + 1 < argc) {
      overrides.emplace_back(argv[++i]);
    } else {
      paths.emplace_back(argv[i]);
    }
  }
  if (paths.empty()) paths = {"configs/paper_bar.yaml", "configs/quick.yaml"};
  for (const std::string& path : paths) {
    const mcrewave::Config config = mcrewave::LoadConfig(path, overrides);
    const mcrewave::ChannelSet measured = mcrewave::LoadMeasurements(config);
    double cutoff = 0.0;
    const mcrewave::ChannelSet data =
        mcrewave::PrefilterMeasurements(measured, config.prefilter, &cutoff);
    std::printf("%s: %d nodes, %d steps, scan %d points on %d threads\n", path.c_str(),
                config.model.elements + 1, config.time.NumSteps(), config.outer.scan_points,
                config.outer.scan_threads);

    IdentifyFigures best;
    for (int r = 0; r < repeats; ++r) {
      const IdentifyFigures figures = IdentifyOnce(config, data);
      if (figures.cpu_s < best.cpu_s) best = figures;
    }
    std::printf(
        "  Identify:          %.3f CPU s, E = %.10e Pa (%s), scan %d evaluations / %ld sweeps, "
        "refinements %d evaluations / %ld sweeps\n",
        best.cpu_s, best.modulus, best.usable ? "converged" : "NOT USABLE", best.scan_evaluations,
        best.scan_sweeps, best.evaluations, best.refinement_sweeps);
    if (identify_only) continue;
    const SweepStepTimes step = SweepStepSeconds(config, data);
    std::printf(
        "  sweep step:        direct %.3f us, retrograde %.3f us, direct in a batch of 3 %.3f us "
        "(CPU per time step and sweep)\n",
        1e6 * step.direct, 1e6 * step.retrograde, 1e6 * step.batched_direct);

    double run_cpu = std::numeric_limits<double>::infinity();
    mcrewave::IdentificationRun run;
    for (int r = 0; r < repeats; ++r) {
      const double start = ProcessCpuSeconds();
      run = mcrewave::RunIdentification(config, measured);
      run_cpu = std::min(run_cpu, ProcessCpuSeconds() - start);
    }
    std::printf(
        "  RunIdentification: %.3f CPU s, E = %.10e Pa, sweeps: refinements %ld, cost curve %ld, "
        "uncertainty %ld\n",
        run_cpu, run.identified_modulus(), run.sweeps, run.cost_curve_sweeps,
        run.uncertainty.sweeps);
  }
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
