// CPU cost of the gradient of every zone against the scalar gradient, on the
// paper's case (configs/paper_bar.yaml, or the config given).
//
// For Z = 1, 10, 100 zones of equal length it reports, at zone moduli a little off
// E_ref (unequal, so that the zone path runs), the CPU time of
//   (a) one coupled solve from W = 0 with its cost and gradient (SolveCoupled: the
//       inner solver of the config, then e^2 and every de^2/dE_z), and
//   (b) the gradient pass alone (MatrixMcreProblem::CostGradients on the solution),
// and the ratios to Z = 1. Goal (issue: zones): (a) at Z zones <= 1.1 x (a) at one
// zone. Thread CPU times, the minimum over --repeats (default 5).
//
// Usage: zone_gradient_benchmark [--repeats N] [CONFIG.yaml]
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <limits>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"

namespace {

struct Figures {
  double solve_s = std::numeric_limits<double>::infinity();
  double gradient_s = std::numeric_limits<double>::infinity();
  long sweeps = 0;
};

Figures Measure(const mcrewave::Config& config, const mcrewave::ChannelSet& data, int zones,
                int repeats) {
  using namespace mcrewave;
  ZoneLayout layout;
  layout.zone_count = zones;
  const BarModel model(config.model, layout.ElementZones(config.model));
  const MatrixModelData matrices = BarRunModel(model, data, {});
  MatrixMcreProblem problem(matrices, data, config.mcre.weights, config.mcre.reference_modulus,
                            config.time.theta, Factorization::kAutomatic, config.mcre.clamp);
  Vector moduli(zones);
  for (int z = 0; z < zones; ++z) moduli[z] = config.model.modulus * (1.0 + 1e-3 * (z % 3));
  problem.SetModuli(moduli);
  Figures figures;
  for (int r = 0; r < repeats; ++r) {
    CoupledSolution solution;
    const long sweeps_before = problem.sweep_count();
    const double start = bench::ThreadCpuSeconds();
    const CoupledSolverSummary summary = SolveCoupled(config.inner, &problem, nullptr, &solution);
    figures.solve_s = std::min(figures.solve_s, bench::ThreadCpuSeconds() - start);
    figures.sweeps = problem.sweep_count() - sweeps_before;
    if (!summary.IsSolutionUsable()) {
      std::fprintf(stderr, "solve failed at %d zones: %s\n", zones, summary.message.c_str());
      std::exit(1);
    }
    Vector gradient;
    const double gradient_start = bench::ThreadCpuSeconds();
    problem.CostGradients(solution.displacement, solution.retrograde, &gradient);
    figures.gradient_s = std::min(figures.gradient_s, bench::ThreadCpuSeconds() - gradient_start);
  }
  return figures;
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  int repeats = 5;
  std::string path = "configs/paper_bar.yaml";
  mcrewave::bench::ParseRepeatsAndConfig(argc, argv, &repeats, &path);
  spdlog::set_level(spdlog::level::warn);
  try {
    const mcrewave::Config config = mcrewave::LoadConfig(path);
    const mcrewave::ChannelSet measured = mcrewave::LoadMeasurements(config);
    double cutoff = 0.0;
    const mcrewave::ChannelSet data =
        config.prefilter.enabled
            ? mcrewave::PrefilterMeasurements(measured, config.prefilter, &cutoff)
            : measured;
    std::printf("%s: %d elements, %d steps, inner solver %s, %d repeats (minimum CPU time)\n",
                path.c_str(), config.model.elements, data.num_steps(),
                mcrewave::CoupledSolverTypeToString(config.inner.type), repeats);
    std::printf("%6s %8s %14s %14s %16s %16s\n", "zones", "sweeps", "solve+grad [s]",
                "gradient [s]", "solve ratio", "gradient ratio");
    Figures one;
    for (int zones : {1, 10, 100}) {
      const Figures figures = Measure(config, data, zones, repeats);
      if (zones == 1) one = figures;
      std::printf("%6d %8ld %14.4g %14.4g %16.3f %16.3f\n", zones, figures.sweeps, figures.solve_s,
                  figures.gradient_s, figures.solve_s / one.solve_s,
                  figures.gradient_s / one.gradient_s);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "error: %s\n", error.what());
    return 1;
  }
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
