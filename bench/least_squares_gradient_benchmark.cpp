// CPU time of output-error least squares' gradient over many zone moduli: forward
// sensitivities (1 + Z sweeps) against the discrete adjoint (2 sweeps), measured side by
// side in one process (A B A B), on the many-zone plate (configs/plate_zones.yaml, or
// the config given): its model and synthetic data as identify run builds them, at the
// config's time window and at 500 steps, in its 16 x 4 grid of zones (64) and one zone
// per element (576).
//
// For each case, at moduli 5 % off E_ref in a checkerboard (so that every zone's
// derivative is non-zero), the CPU time of one evaluation of J
//   (J)  without the gradient (one sweep),
//   (A)  with the gradient by forward sensitivities,
//   (B)  with the gradient by the adjoint,
// the ratio A / B, B / J, and max_z |dJ/dE_z (A) - dJ/dE_z (B)| / max_z |dJ/dE_z (A)|.
// Thread CPU times, the minimum over --repeats (default 3).
//
// Goals (issue 42: least squares on the per-element layout): the adjoint's evaluation at
// most 3 J, whatever Z; A / B then grows like Z / 2.
//
// Usage: least_squares_gradient_benchmark [--repeats N] [CONFIG.yaml]
//   (default configs/plate_zones.yaml, relative to the working directory).

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"

namespace {

using namespace mcrewave;
using bench::ThreadCpuSeconds;

struct Case {
  std::string name;
  std::vector<std::string> overrides;
};

// The thread CPU time of one call of `run` [s].
template <typename Run>
double Seconds(Run&& run) {
  const double start = ThreadCpuSeconds();
  run();
  return ThreadCpuSeconds() - start;
}

int Main(int argc, char** argv) {
  int repeats = 3;
  std::string path = "configs/plate_zones.yaml";
  bench::ParseRepeatsAndConfig(argc, argv, &repeats, &path);
  spdlog::set_level(spdlog::level::warn);
  const std::vector<Case> cases = {
      {"grid 16 x 4, config's window", {"model.zoning=grid"}},
      {"grid 16 x 4, 500 steps", {"model.zoning=grid", "time.window=5e-4"}},
      {"per element, config's window", {"model.zoning=per_element", "model.zone_grid=[]"}},
      {"per element, 500 steps",
       {"model.zoning=per_element", "model.zone_grid=[]", "time.window=5e-4"}},
  };
  std::printf("%-32s %5s %6s %10s %10s %10s %8s %6s %10s\n", "case", "zones", "steps", "J [s]",
              "forward [s]", "adjoint [s]", "fwd/adj", "adj/J", "mismatch");
  for (const Case& item : cases) {
    const Config config = LoadConfig(path, item.overrides);
    const MatrixModelData model = LoadMatrixModel(config);
    const MatrixMeasurements measurements = LoadMatrixMeasurements(config, model);
    std::string source;
    const NoiseLevels levels = MatrixLeastSquaresMisfitLevels(config, model, measurements,
                                                              measurements.histories, &source);
    MatrixOutputErrorObjective forward(model, measurements.histories, levels, config.time.theta);
    MatrixOutputErrorObjective adjoint(model, measurements.histories, levels, config.time.theta);
    adjoint.SetGradientMethod(LeastSquaresGradient::kAdjoint);
    const int zones = forward.num_parameters();
    Vector moduli = model.NominalModuli();
    for (int z = 0; z < zones; ++z) moduli[z] *= (z % 2 == 0) ? 1.05 : 0.95;
    Vector forward_gradient, adjoint_gradient;
    double cost_s = std::numeric_limits<double>::infinity();
    double forward_s = cost_s, adjoint_s = cost_s;
    // J, A, B, J, A, B, ...: the minimum of each over the repeats.
    for (int r = 0; r < repeats; ++r) {
      cost_s = std::min(cost_s, Seconds([&] { forward.Cost(moduli, nullptr); }));
      forward_s = std::min(forward_s, Seconds([&] { forward.Cost(moduli, &forward_gradient); }));
      adjoint_s = std::min(adjoint_s, Seconds([&] { adjoint.Cost(moduli, &adjoint_gradient); }));
    }
    const double mismatch = (adjoint_gradient - forward_gradient).lpNorm<Eigen::Infinity>() /
                            forward_gradient.lpNorm<Eigen::Infinity>();
    std::printf("%-32s %5d %6ld %10.4f %10.4f %10.4f %8.1f %6.2f %10.2e\n", item.name.c_str(),
                zones, static_cast<long>(measurements.histories.num_samples() - 1), cost_s,
                forward_s, adjoint_s, forward_s / adjoint_s, adjoint_s / cost_s, mismatch);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(Main, argc, argv); }
