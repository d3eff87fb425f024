// Benchmark of the coupled direct / retrograde solvers on the paper's case
// (100 elements, 1750 steps, the paper's weights and free-free formulation, tolerance
// 1e-8), on the bar as every run solves it (BarRunModel, MatrixMcreProblem), at E_ref and
// 0.8 E_ref, SNR inf and 2.5 (truth 4x finer, seed 1):
//   (a) fixed-omega relaxation at the best omega of a scan,
//   (b) adaptive omega,
//   (c) conjugate gradients (Krylov),
//   (d) the all-at-once sparse LU (once: it needs minutes and gigabytes),
// each in sweeps, seconds and multiples of one direct sweep's time; then a
// warm-started solve after a 1 % change of E against a cold start.
//
// Goals: adaptive within 1.25x the sweeps of the scan's best omega; Krylov at least
// 5x fewer sweeps than the best omega; Krylov faster than all-at-once.
//
// Usage: coupled_solver_benchmark [--skip-all-at-once]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "bench_util.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"

namespace {

using mcrewave::CoupledProblem;
using mcrewave::CoupledSolution;
using mcrewave::CoupledSolverOptions;
using mcrewave::CoupledSolverSummary;
using mcrewave::CoupledSolverType;
using mcrewave::MatrixMcreProblem;

CoupledSolverSummary Run(CoupledSolverType type, CoupledProblem* problem, double omega = 0.5,
                         int max_iterations = 20000, const mcrewave::Matrix* initial = nullptr) {
  CoupledSolverOptions options;
  options.type = type;
  options.relaxation_coefficient = omega;
  options.max_iterations = max_iterations;
  options.max_all_at_once_unknowns = 2'000'000;
  options.max_all_at_once_bytes = 16L << 30;  // the paper's case needs about 14 GB
  CoupledSolution solution;
  return mcrewave::SolveCoupled(options, problem, initial, &solution);
}

struct ScanResult {
  double omega = 0.0;
  CoupledSolverSummary summary;
};

// Sweeps to tolerance of the fixed-omega relaxation over a log grid of omega, then
// a finer grid around the best; runs longer than twice the best so far are cut.
ScanResult ScanOmega(CoupledProblem* problem) {
  ScanResult best;
  long best_sweeps = std::numeric_limits<long>::max();
  auto try_omega = [&](double omega) {
    const int cap = best_sweeps == std::numeric_limits<long>::max()
                        ? 20000
                        : static_cast<int>(best_sweeps);  // iterations = sweeps / 2
    const CoupledSolverSummary summary = Run(CoupledSolverType::kRelaxation, problem, omega, cap);
    if (summary.IsSolutionUsable() && summary.sweeps < best_sweeps) {
      best_sweeps = summary.sweeps;
      best = {omega, summary};
    }
  };
  for (double omega = 1.0; omega > 4e-3; omega /= 1.4) try_omega(omega);
  const double center = best.omega;
  for (int i = -6; i <= 6; ++i) try_omega(center * std::pow(1.4, i / 7.0));
  return best;
}

double SecondsOfOneDirectSweep(CoupledProblem* problem) {
  mcrewave::Matrix field = problem->ZeroField(), displacement;
  const int repeats = 20;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) problem->DirectSweep(field, true, &displacement);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / repeats;
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  const bool skip_all_at_once = argc > 1 && std::strcmp(argv[1], "--skip-all-at-once") == 0;
  mcrewave::BarProperties bar;  // the paper's bar, 100 elements
  mcrewave::LoadOptions load;
  mcrewave::TimeOptions time;  // 0.63 ms, 0.36 us, 1750 steps
  const mcrewave::BarModel model(bar);
  const double reference = bar.modulus;

  {
    const auto start = std::chrono::steady_clock::now();
    mcrewave::SimulateClampedBar(bar, load, time);
    std::printf(
        "one clamped direct simulation of the paper's case: %.2f ms\n",
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::printf("\n%-5s %-6s | %-22s | %-16s | %-16s | %-7s %-7s\n", "SNR", "E/Eref",
              "best fixed omega", "adaptive", "Krylov (CG)", "adapt/", "best/");
  std::printf("%-5s %-6s | %7s %6s %7s | %6s %9s | %6s %9s | %-7s %-7s\n", "", "", "omega",
              "sweeps", "s", "sweeps", "s", "sweeps", "s", "best", "Krylov");
  double sweep_seconds = 0.0;
  for (double snr : {std::numeric_limits<double>::infinity(), 2.5}) {
    mcrewave::DataOptions data;
    data.snr = snr;
    const mcrewave::ChannelSet measurements =
        mcrewave::MakeSyntheticMeasurements(bar, load, time, data);
    // The clamp measured: the paper's free-free formulation.
    const mcrewave::MatrixModelData matrices = mcrewave::BarRunModel(model, measurements, {});
    MatrixMcreProblem problem(matrices, measurements, mcrewave::McreWeights(), reference,
                              time.theta, mcrewave::Factorization::kAutomatic,
                              mcrewave::ClampModel::kMeasured);
    if (sweep_seconds == 0.0) sweep_seconds = SecondsOfOneDirectSweep(&problem);
    for (double factor : {1.0, 0.8}) {
      problem.SetModulus(factor * reference);
      const ScanResult scan = ScanOmega(&problem);
      const CoupledSolverSummary adaptive = Run(CoupledSolverType::kAdaptiveRelaxation, &problem);
      const CoupledSolverSummary krylov = Run(CoupledSolverType::kConjugateGradient, &problem);
      std::printf("%-5g %-6.2f | %7.4f %6ld %7.3f | %6ld %9.3f | %6ld %9.4f | %-7.2f %-7.1f\n", snr,
                  factor, scan.omega, scan.summary.sweeps, scan.summary.wall_time_s,
                  adaptive.sweeps, adaptive.wall_time_s, krylov.sweeps, krylov.wall_time_s,
                  static_cast<double>(adaptive.sweeps) / scan.summary.sweeps,
                  static_cast<double>(scan.summary.sweeps) / krylov.sweeps);
      std::printf(
          "%-14s   in direct sweeps: best omega %.0f, adaptive %.0f, Krylov %.1f; "
          "adaptive omega %.4f from a_max %.2f\n",
          "", scan.summary.wall_time_s / sweep_seconds, adaptive.wall_time_s / sweep_seconds,
          krylov.wall_time_s / sweep_seconds, adaptive.relaxation_coefficient,
          adaptive.spectrum_max);
    }
    if (std::isinf(snr)) continue;
    // Warm start after a change of E by 1 %, 0.1 % and 0.01 % (SNR 2.5).
    std::printf("\n");
    for (double change : {1e-2, 1e-3, 1e-4}) {
      problem.SetModulus(reference);
      CoupledSolution previous;
      mcrewave::SolveCoupled(CoupledSolverOptions(), &problem, nullptr, &previous);
      problem.SetModulus((1.0 + change) * reference);
      for (CoupledSolverType type :
           {CoupledSolverType::kConjugateGradient, CoupledSolverType::kAdaptiveRelaxation}) {
        const CoupledSolverSummary cold = Run(type, &problem);
        const CoupledSolverSummary warm = Run(type, &problem, 0.5, 20000, &previous.retrograde);
        std::printf(
            "warm start after a %g %% change of E, %-19s: %4ld sweeps (cold %4ld), "
            "initial relative residual %.2e\n",
            100.0 * change, mcrewave::CoupledSolverTypeToString(type), warm.sweeps, cold.sweeps,
            warm.residual_history.front());
      }
    }
    if (!skip_all_at_once) {
      problem.SetModulus(0.8 * reference);
      const CoupledSolverSummary krylov = Run(CoupledSolverType::kConjugateGradient, &problem);
      const CoupledSolverSummary all_at_once = Run(CoupledSolverType::kAllAtOnce, &problem);
      std::printf(
          "\nall-at-once at SNR 2.5, 0.8 E_ref: %s\n  = %.0f direct sweeps; "
          "Krylov is %.0fx faster\n",
          all_at_once.BriefReport().c_str(), all_at_once.wall_time_s / sweep_seconds,
          all_at_once.wall_time_s / krylov.wall_time_s);
    }
  }
  std::printf("\none direct sweep of the MCRE problem: %.3f ms\n", 1e3 * sweep_seconds);
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
