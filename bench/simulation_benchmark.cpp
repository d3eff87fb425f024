// Cost of the direct simulation and of one theta-method time step.
//
//   BM_SimulateClampedBar: the paper's case (100 elements, 1750 steps of 0.36 us),
//     assembly and factorisation included.
//   BM_ThetaSweep/N: a forward sweep of the free bar with N elements (end force on
//     node N, the end displacement read at every step); the counter time_per_step [s]
//     is the wall time of one step. The integrator is initialised outside the timing.
//
// After the runs, main prints the least-squares slope of log(time per step) against
// log(N): a banded step is O(N), so the goal is a slope of about 1.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "bench_util.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/simulation.h"

namespace mcrewave {
namespace {

void BM_SimulateClampedBar(benchmark::State& state) {
  const BarProperties bar;  // 100 elements
  const LoadOptions load;
  const TimeOptions time;  // 0.63 ms / 0.36 us = 1750 steps
  for (auto _ : state) {
    ChannelSet measurements = SimulateClampedBar(bar, load, time);
    benchmark::DoNotOptimize(measurements.Values("uL").data());
  }
  state.counters["steps"] = time.NumSteps();
  state.counters["time_per_step"] = benchmark::Counter(
      time.NumSteps(), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SimulateClampedBar)->Unit(benchmark::kMillisecond);

// Fewer steps for the large meshes, so that one sweep takes about the same time.
int StepsFor(int elements) { return elements <= 1000 ? 1750 : 1750 * 1000 / elements + 1; }

void BM_ThetaSweep(benchmark::State& state) {
  const int elements = static_cast<int>(state.range(0));
  BarProperties bar;
  bar.elements = elements;
  const BarModel model(bar);
  const int n = model.num_nodes();
  ThetaIntegratorOptions options;
  // The paper's Courant number c h / h_e = 0.57.
  options.time_step = 0.36e-6 * 100 / elements;
  options.theta = 0.5;
  ThetaIntegrator integrator;
  integrator.Init(model.mass(), model.Stiffness(bar.modulus), options);
  const int num_steps = StepsFor(elements);
  const Vector zero = Vector::Zero(n);
  double end_displacement = 0.0;
  for (auto _ : state) {
    integrator.SweepForward(
        num_steps, zero, zero,
        [&](int k, Eigen::Ref<Vector> force) {
          force.setZero();
          force[n - 1] = std::sin(1e-3 * k);
        },
        [&](int /*k*/, const Vector& /*velocity*/, const Vector& displacement) {
          end_displacement += displacement[n - 1];
        });
  }
  benchmark::DoNotOptimize(end_displacement);
  state.counters["elements"] = elements;
  state.counters["steps"] = num_steps;
  state.counters["time_per_step"] = benchmark::Counter(
      num_steps, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ThetaSweep)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond);

// The console output, plus (elements, time per step) of every BM_ThetaSweep run.
class SweepRecorder : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      if (run.run_type != Run::RT_Iteration || run.error_occurred) continue;
      if (run.run_name.function_name != "BM_ThetaSweep") continue;
      points_.emplace_back(run.counters.at("elements").value,
                           run.counters.at("time_per_step").value);
    }
  }
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_;
};

// Least-squares slope of log(y) against log(x).
double LogLogSlope(const std::vector<std::pair<double, double>>& points) {
  const double n = static_cast<double>(points.size());
  double mean_x = 0.0, mean_y = 0.0;
  for (const auto& [x, y] : points) {
    mean_x += std::log(x) / n;
    mean_y += std::log(y) / n;
  }
  double sxy = 0.0, sxx = 0.0;
  for (const auto& [x, y] : points) {
    sxy += (std::log(x) - mean_x) * (std::log(y) - mean_y);
    sxx += (std::log(x) - mean_x) * (std::log(x) - mean_x);
  }
  return sxy / sxx;
}

}  // namespace
}  // namespace mcrewave

static int BenchmarkMain(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  mcrewave::SweepRecorder recorder;
  benchmark::RunSpecifiedBenchmarks(&recorder);
  benchmark::Shutdown();
  const auto& points = recorder.points();
  if (points.size() >= 2) {
    std::printf("\nTheta sweep, time per step:\n");
    for (const auto& [elements, seconds] : points) {
      std::printf("  %8.0f elements  %10.1f ns/step  %6.2f ns/step/node\n", elements, seconds * 1e9,
                  seconds * 1e9 / (elements + 1));
    }
    std::printf("Fitted log-log slope of time per step vs number of elements: %.3f (goal ~1)\n",
                mcrewave::LogLogSlope(points));
  }
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
