// How the MCRE weights w_u, w_f change the conditioning of the coupled problem
// and the identification, on the paper's case (100 elements, 1750 steps, data
// from the 4x finer truth).
//
// Per weight pair: the extreme eigenvalue a_max of A = I - G (Lanczos estimate of
// the adaptive relaxation), the sweeps of CG and of the adaptive relaxation at
// E_ref (SNR 2.5), the bias of the noise-free minimiser, and over `seeds` noise
// realisations at SNR 2.5: the error of the minimiser of e^2 on a grid of E in
// [0.8, 1.2] E_ref (1 % steps, refined by a parabola through the best three points),
// the number of local minima on that grid, and the curvature of e^2 at the minimum
// relative to its value, E^2 e2'' / e2 (how sharply the valley rises above the
// noise floor).
//
// Usage: weights_benchmark OUTPUT_DIR [seeds]   (writes weights.csv, cost_curves.csv)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"

namespace {

constexpr int kGridPoints = 41;
constexpr double kGridLow = 0.8, kGridHigh = 1.2;

struct CurveFacts {
  double minimiser = 0.0;  // E / E_ref
  double curvature = 0.0;  // E^2 e2'' / e2 at the minimum
  int local_minima = 0;
  std::vector<double> costs;
};

double GridFactor(int i) { return kGridLow + (kGridHigh - kGridLow) * i / (kGridPoints - 1); }

CurveFacts CostCurve(const mcrewave::BarModel& model, const mcrewave::ChannelSet& data,
                     const mcrewave::McreWeights& weights, double reference) {
  const mcrewave::MatrixModelData matrices = mcrewave::BarRunModel(model, data, {});
  mcrewave::MatrixMcreProblem problem(matrices, data, weights, reference, 0.5);
  mcrewave::CoupledSolverOptions options;
  options.tolerance = 1e-10;
  CurveFacts facts;
  for (int i = 0; i < kGridPoints; ++i) {
    problem.SetModulus(GridFactor(i) * reference);
    mcrewave::CoupledSolution solution;
    const auto summary = mcrewave::SolveCoupled(options, &problem, nullptr, &solution);
    facts.costs.push_back(summary.IsSolutionUsable() ? solution.cost
                                                     : std::numeric_limits<double>::quiet_NaN());
  }
  const auto& c = facts.costs;
  int best = static_cast<int>(std::min_element(c.begin(), c.end()) - c.begin());
  for (int i = 1; i + 1 < kGridPoints; ++i) {
    if (c[i] < c[i - 1] && c[i] < c[i + 1]) ++facts.local_minima;
  }
  if (c[0] < c[1]) ++facts.local_minima;
  if (c[kGridPoints - 1] < c[kGridPoints - 2]) ++facts.local_minima;
  best = std::clamp(best, 1, kGridPoints - 2);
  // Parabola through the best three points: vertex and second derivative.
  const double step = GridFactor(1) - GridFactor(0);
  const double second = (c[best - 1] - 2.0 * c[best] + c[best + 1]) / (step * step);
  const double first = (c[best + 1] - c[best - 1]) / (2.0 * step);
  facts.minimiser = GridFactor(best) - (second > 0.0 ? first / second : 0.0);
  facts.curvature = second * facts.minimiser * facts.minimiser / c[best];
  return facts;
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR [seeds]\n", argv[0]);
    return 2;
  }
  const std::string output_dir = argv[1];
  const int seeds = argc > 2 ? std::atoi(argv[2]) : 4;
  const mcrewave::BarProperties bar;
  const mcrewave::LoadOptions load;
  const mcrewave::TimeOptions time;
  const mcrewave::BarModel model(bar);
  const double reference = bar.modulus;
  const std::vector<std::pair<double, double>> weight_pairs = {
      {0.001, 1.0}, {0.01, 1.0}, {0.1, 1.0}, {1.0, 1.0}, {0.01, 0.1}, {0.01, 10.0}};

  // Data sets: index 0 noise-free, then seeds 1..n at SNR 2.5.
  std::vector<mcrewave::ChannelSet> data_sets;
  mcrewave::DataOptions data;
  data_sets.push_back(mcrewave::MakeSyntheticMeasurements(bar, load, time, data));
  data.snr = 2.5;
  for (int seed = 1; seed <= seeds; ++seed) {
    data.seed = static_cast<std::uint64_t>(seed);
    data_sets.push_back(mcrewave::MakeSyntheticMeasurements(bar, load, time, data));
  }

  // Every (weights, data set) curve, computed by two threads.
  const int num_jobs = static_cast<int>(weight_pairs.size() * data_sets.size());
  std::vector<CurveFacts> curves(num_jobs);
  std::mutex progress_mutex;
  int done = 0;
  auto worker = [&](int first) {
    for (int job = first; job < num_jobs; job += 2) {
      const auto& [w_u, w_f] = weight_pairs[job / data_sets.size()];
      mcrewave::McreWeights weights;
      weights.displacement_weight = w_u;
      weights.force_weight = w_f;
      curves[job] = CostCurve(model, data_sets[job % data_sets.size()], weights, reference);
      std::lock_guard<std::mutex> lock(progress_mutex);
      std::fprintf(stderr, "\rcost curves: %d / %d", ++done, num_jobs);
    }
  };
  std::thread second(worker, 1);
  worker(0);
  second.join();
  std::fprintf(stderr, "\n");

  std::ostringstream table, curves_csv;
  table << "w_u,w_f,a_max,cg_sweeps,adaptive_sweeps,noise_free_error,snr2.5_mean_abs_error,"
           "snr2.5_max_abs_error,snr2.5_mean_local_minima,snr2.5_mean_relative_curvature\n";
  curves_csv << "w_u,w_f,seed,E_over_Eref,cost\n";
  std::printf("%-6s %-5s | %8s %6s %8s | %10s | %10s %10s %7s %10s\n", "w_u", "w_f", "a_max", "CG",
              "adaptive", "bias", "mean|err|", "max|err|", "minima", "curvature");
  table.precision(6);
  for (std::size_t p = 0; p < weight_pairs.size(); ++p) {
    const auto& [w_u, w_f] = weight_pairs[p];
    mcrewave::McreWeights weights;
    weights.displacement_weight = w_u;
    weights.force_weight = w_f;
    const mcrewave::MatrixModelData matrices = mcrewave::BarRunModel(model, data_sets[1], {});
    mcrewave::MatrixMcreProblem problem(matrices, data_sets[1], weights, reference, 0.5);
    mcrewave::CoupledSolverOptions options;
    mcrewave::CoupledSolution solution;
    const auto cg = mcrewave::SolveCoupled(options, &problem, nullptr, &solution);
    options.type = mcrewave::CoupledSolverType::kAdaptiveRelaxation;
    options.max_iterations = 50000;
    const auto adaptive = mcrewave::SolveCoupled(options, &problem, nullptr, &solution);
    const double a_max = adaptive.spectrum_max / options.spectrum_safety_factor;
    const CurveFacts& noise_free = curves[p * data_sets.size()];
    double sum_error = 0.0, max_error = 0.0, sum_minima = 0.0, sum_curvature = 0.0;
    for (int s = 1; s <= seeds; ++s) {
      const CurveFacts& facts = curves[p * data_sets.size() + s];
      const double error = std::abs(facts.minimiser - 1.0);
      sum_error += error;
      max_error = std::max(max_error, error);
      sum_minima += facts.local_minima;
      sum_curvature += facts.curvature;
    }
    std::printf("%-6g %-5g | %8.2f %6ld %8ld | %+9.4f%% | %9.3f%% %9.3f%% %7.2f %10.1f\n", w_u, w_f,
                a_max, cg.sweeps, adaptive.sweeps, 100.0 * (noise_free.minimiser - 1.0),
                100.0 * sum_error / seeds, 100.0 * max_error, sum_minima / seeds,
                sum_curvature / seeds);
    table << w_u << ',' << w_f << ',' << a_max << ',' << cg.sweeps << ',' << adaptive.sweeps << ','
          << noise_free.minimiser - 1.0 << ',' << sum_error / seeds << ',' << max_error << ','
          << sum_minima / seeds << ',' << sum_curvature / seeds << '\n';
    for (std::size_t d = 0; d < data_sets.size(); ++d) {
      const CurveFacts& facts = curves[p * data_sets.size() + d];
      for (int i = 0; i < kGridPoints; ++i) {
        curves_csv << w_u << ',' << w_f << ',' << d << ',' << GridFactor(i) << ',' << facts.costs[i]
                   << '\n';
      }
    }
  }
  mcrewave::WriteFileAtomically(output_dir + "/weights.csv", table.str());
  mcrewave::WriteFileAtomically(output_dir + "/cost_curves.csv", curves_csv.str());
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
