// The paper's bar (100 elements, 1750 steps, SNR 2.5, seed 1) on the two roads, side
// by side in one run: the built-in bar (mcre/mcre_problem.h) and the same bar exported
// as matrices with its clamp as a support (model/matrix_export.h, BarClampExport::kSupport;
// mcre/matrix_mcre_problem.h). Both at the paper's weights and a clamp treatment
// (trusted, measured or pinned), theta = 1/2. Per road, medians over repeats:
//   - one direct and one retrograde sweep with the data;
//   - one stored-field CG solve to 1e-8 (the default inner solver), and its sweeps;
//   - e^2 and the zone gradient of the solved fields;
// then the ratios matrices / bar. The gate: the bar as matrices within 1.2
// times the built-in bar's time.
//
// Usage: bar_as_matrices_benchmark [--clamp trusted|measured|pinned] [--repeats N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"

namespace mcrewave {
namespace {

using Clock = std::chrono::steady_clock;

template <typename Work>
double MedianSeconds(int repeats, Work&& work) {
  std::vector<double> seconds;
  for (int i = 0; i < repeats; ++i) {
    const auto start = Clock::now();
    work();
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::nth_element(seconds.begin(), seconds.begin() + repeats / 2, seconds.end());
  return seconds[repeats / 2];
}

struct RoadTimes {
  double direct_s = 0.0, retrograde_s = 0.0, solve_s = 0.0, gradient_s = 0.0;
  long solve_sweeps = 0;
  double cost = 0.0;
};

RoadTimes TimeRoad(CoupledProblem* problem, int repeats) {
  RoadTimes times;
  Matrix u, w;
  const Matrix zero = problem->ZeroField();
  times.direct_s = MedianSeconds(repeats, [&] { problem->DirectSweep(zero, true, &u); });
  times.retrograde_s = MedianSeconds(repeats, [&] { problem->RetrogradeSweep(u, true, &w); });
  CoupledSolution solution;
  CoupledSolverSummary summary;
  times.solve_s = MedianSeconds(repeats, [&] {
    summary = SolveCoupled(CoupledSolverOptions(), problem, nullptr, &solution);
  });
  times.solve_sweeps = summary.sweeps;
  Vector gradient;
  times.gradient_s = MedianSeconds(repeats, [&] {
    times.cost = problem->Cost(solution.displacement, solution.retrograde);
    problem->CostGradients(solution.displacement, solution.retrograde, &gradient);
  });
  return times;
}

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

  McreProblem built_in(model, measurements, weights, bar.modulus, time.theta, {}, clamp);
  MatrixMcreProblem general(matrices, measurements, weights, bar.modulus, time.theta,
                            Factorization::kAutomatic, clamp);
  const Vector moduli = Vector::Constant(1, 0.9 * bar.modulus);
  built_in.SetModuli(moduli);
  general.SetModuli(moduli);

  std::printf("paper's bar, %d dofs, %d steps, clamp %s, %d repeats (medians)\n",
              built_in.num_nodes(), built_in.num_steps(), ClampModelToString(clamp), repeats);
  const RoadTimes bar_times = TimeRoad(&built_in, repeats);
  const RoadTimes matrix_times = TimeRoad(&general, repeats);
  std::printf("%-28s %12s %12s %8s\n", "", "built-in bar", "as matrices", "ratio");
  auto row = [](const char* name, double a, double b) {
    std::printf("%-28s %10.3f ms %10.3f ms %8.2f\n", name, 1e3 * a, 1e3 * b, b / a);
  };
  row("direct sweep", bar_times.direct_s, matrix_times.direct_s);
  row("retrograde sweep", bar_times.retrograde_s, matrix_times.retrograde_s);
  row("CG solve to 1e-8", bar_times.solve_s, matrix_times.solve_s);
  row("e^2 and its gradient", bar_times.gradient_s, matrix_times.gradient_s);
  std::printf("CG sweeps: %ld (bar), %ld (matrices); e^2: %.17g (bar), %.17g (matrices)\n",
              bar_times.solve_sweeps, matrix_times.solve_sweeps, bar_times.cost,
              matrix_times.cost);
  return 0;
}

}  // namespace
}  // namespace mcrewave

int main(int argc, char** argv) { return mcrewave::Main(argc, argv); }
