// The paper's bar (100 elements, 1750 steps, SNR 2.5, seed 1) on the two roads, side
// by side in one run: the built-in bar's own band-model road (tests/reference/
// bar_mcre_problem.h, the tests' reference) and the same bar exported
// as matrices with its clamp as a support (model/matrix_export.h, BarClampExport::kSupport;
// mcre/matrix_mcre_problem.h). Both at the paper's weights and a clamp treatment
// (trusted, measured or pinned), theta = 1/2. The roads run alternately (A B A B);
// each figure is the median of its road's repeats:
//   - one direct and one retrograde sweep with the data;
//   - one stored-field CG solve to 1e-8 (the default inner solver), and its sweeps;
//   - e^2 and the zone gradient of the solved fields;
// then the ratios matrices / bar. The gate: the bar as matrices within 1.2
// times the built-in bar's time.
//
// Usage: bar_as_matrices_benchmark [--clamp trusted|measured|pinned] [--repeats N]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"
#include "reference/bar_mcre_problem.h"

namespace mcrewave {
namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> seconds) {
  std::nth_element(seconds.begin(), seconds.begin() + seconds.size() / 2, seconds.end());
  return seconds[seconds.size() / 2];
}

// Runs work(0) (the built-in bar) and work(1) (the bar as matrices) alternately, A B A B,
// `repeats` times each, and returns the two medians [s].
template <typename Work>
std::array<double, 2> SideBySideSeconds(int repeats, Work&& work) {
  std::array<std::vector<double>, 2> seconds;
  for (int i = 0; i < repeats; ++i) {
    for (int road = 0; road < 2; ++road) {
      const auto start = Clock::now();
      work(road);
      seconds[road].push_back(std::chrono::duration<double>(Clock::now() - start).count());
    }
  }
  return {Median(seconds[0]), Median(seconds[1])};
}

// One road's problem and the fields its timed work writes.
struct RoadState {
  CoupledProblem* problem = nullptr;
  Matrix zero, u, w;
  CoupledSolution solution;
  CoupledSolverSummary summary;
  Vector gradient;
  double cost = 0.0;
};

int Main(int argc, char** argv) {
  ClampModel clamp = ClampModel::kTrusted;
  int repeats = 7;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--clamp") == 0) {
      if (!StringToClampModel(argv[i + 1], &clamp)) {
        std::fprintf(stderr, "--clamp: expected trusted, measured or pinned, got %s\n",
                     argv[i + 1]);
        return 2;
      }
    } else if (std::strcmp(argv[i], "--repeats") == 0) {
      repeats = std::max(1, std::atoi(argv[i + 1]));
    }
  }
  const BarProperties bar;  // the paper's bar, 100 elements
  const LoadOptions load;
  const TimeOptions time;  // 1750 steps
  DataOptions data;
  data.snr = 2.5;
  const BarModel model(bar);
  const ChannelSet measurements = MakeSyntheticMeasurements(bar, load, time, data);
  McreWeights weights;  // the paper's weights
  const MatrixModelData matrices =
      BarMatrixModel(model, bar.modulus, {}, BarClampExport::kSupport);

  testing::BarMcreProblem built_in(model, measurements, weights, bar.modulus, time.theta, {},
                                   clamp);
  MatrixMcreProblem general(matrices, measurements, weights, bar.modulus, time.theta,
                            Factorization::kAutomatic, clamp);
  const Vector moduli = Vector::Constant(1, 0.9 * bar.modulus);
  built_in.SetModuli(moduli);
  general.SetModuli(moduli);

  std::printf("paper's bar, %d dofs, %d steps, clamp %s, %d repeats each, A B A B (medians)\n",
              built_in.num_nodes(), built_in.num_steps(), ClampModelToString(clamp), repeats);
  std::array<RoadState, 2> roads;
  roads[0].problem = &built_in;
  roads[1].problem = &general;
  for (RoadState& road : roads) road.zero = road.problem->ZeroField();
  const auto direct = SideBySideSeconds(
      repeats, [&](int r) { roads[r].problem->DirectSweep(roads[r].zero, true, &roads[r].u); });
  const auto retrograde = SideBySideSeconds(
      repeats, [&](int r) { roads[r].problem->RetrogradeSweep(roads[r].u, true, &roads[r].w); });
  const auto solve = SideBySideSeconds(repeats, [&](int r) {
    roads[r].summary =
        SolveCoupled(CoupledSolverOptions(), roads[r].problem, nullptr, &roads[r].solution);
  });
  const auto gradient = SideBySideSeconds(repeats, [&](int r) {
    RoadState& road = roads[r];
    road.cost = road.problem->Cost(road.solution.displacement, road.solution.retrograde);
    road.problem->CostGradients(road.solution.displacement, road.solution.retrograde,
                                &road.gradient);
  });
  std::printf("%-28s %12s %12s %8s\n", "", "built-in bar", "as matrices", "ratio");
  auto row = [](const char* name, const std::array<double, 2>& seconds) {
    std::printf("%-28s %10.3f ms %10.3f ms %8.2f\n", name, 1e3 * seconds[0], 1e3 * seconds[1],
                seconds[1] / seconds[0]);
  };
  row("direct sweep", direct);
  row("retrograde sweep", retrograde);
  row("CG solve to 1e-8", solve);
  row("e^2 and its gradient", gradient);
  std::printf("CG sweeps: %ld (bar), %ld (matrices); e^2: %.17g (bar), %.17g (matrices)\n",
              roads[0].summary.sweeps, roads[1].summary.sweeps, roads[0].cost, roads[1].cost);
  return 0;
}

}  // namespace
}  // namespace mcrewave

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(mcrewave::Main, argc, argv); }
