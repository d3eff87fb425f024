// Peak memory and time of one coupled solve, stored-field conjugate gradients
// against the streaming solver (docs/streaming.md), on the bar as every run solves it
// (BarRunModel, MatrixMcreProblem), against the number of nodes n
// (paper's bar scaled at its Courant number c h / h_e = 0.57, 1750 steps) and against
// the number of steps m (101 nodes, window m h). Data: the finite-element truth on the
// model's grid with noise at SNR 10; the solve at 0.95 E_ref from W = 0, tolerance
// 1e-8. Peak memory is the growth of the process's resident high-water mark (VmHWM,
// reset through /proc/self/clear_refs) while the MCRE problem is built (its O(n)
// states and factorisation) and solved; the data are made before. The stored-field
// solver is run only where its ten fields fit in --max-stored-bytes (default 4 GB).
// Prints one row per case (time, CG iterations, sweeps, nanoseconds per node and step
// of one sweep, peak memory) and the fitted log-log slopes of time and memory.
//
// --formulation paper (default) solves the paper's free-free MCRE (McreWeights(), the
// clamp measured), in which docs/streaming.md's first tables were measured;
// --formulation defaults the config's (McreOptions: the clamp trusted, w_u = w_e = 1e-7,
// w_r = 1e-6).
//
// Usage: streaming_benchmark [--min-elements N] [--max-elements N] [--min-steps M]
//                            [--max-steps M] [--max-stored-bytes B] [--tolerance T]
//                            [--formulation paper|defaults]
#include <malloc.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/model/simulation.h"

namespace {

using namespace mcrewave;

long PeakResidentBytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return 1024L * std::stol(line.substr(6));
  }
  return -1;
}

long ResidentBytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return 1024L * std::stol(line.substr(6));
  }
  return -1;
}

// Returns freed heap memory to the system, then resets VmHWM to the resident size.
void ResetPeak() {
  malloc_trim(0);
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
}

struct Measured {
  double seconds = NAN;
  double peak_bytes = NAN;
  int iterations = -1;
  long sweeps = -1;
  double cost = NAN;
};

double tolerance = 1e-8;
McreOptions formulation = [] {
  McreOptions paper;
  paper.weights = McreWeights();
  paper.clamp = ClampModel::kMeasured;
  return paper;
}();

// Builds the problem at 0.95 E_ref and solves it once; the time is the solve's, the
// memory that of the problem and the solve.
Measured SolveOnce(const BarModel& model, const ChannelSet& data, CoupledSolverType type) {
  CoupledSolverOptions options;
  options.type = type;
  options.tolerance = tolerance;
  options.max_iterations = 100000;
  // The stored-field solver unrefused; the streaming one keeps omega's whole history
  // up to 64 MB, as docs/streaming.md's tables were measured, and uses checkpoints above.
  options.max_field_bytes = type == CoupledSolverType::kStreamingConjugateGradient
                                ? MatrixMcreProblem::kDefaultHistoryBytes
                                : 1L << 40;
  ResetPeak();
  const long before = ResidentBytes();
  Measured measured;
  {
    const MatrixModelData matrices = BarRunModel(model, data, {});
    MatrixMcreProblem problem(matrices, data, formulation.weights, formulation.reference_modulus,
                              0.5, Factorization::kAutomatic, formulation.clamp);
    problem.SetModulus(0.95 * 200e9);
    const auto start = std::chrono::steady_clock::now();
    CoupledSolution solution;
    const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &solution);
    measured.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    measured.iterations = summary.iterations;
    measured.sweeps = summary.sweeps;
    measured.cost = summary.IsSolutionUsable() ? solution.cost : NAN;
    if (!summary.IsSolutionUsable()) {
      std::fprintf(stderr, "%s: %s\n", CoupledSolverTypeToString(type), summary.message.c_str());
    }
    measured.peak_bytes = static_cast<double>(PeakResidentBytes() - before);
  }
  return measured;
}

struct Row {
  int nodes, steps;
  Measured stored, streamed;
};

Row Case(int elements, int steps, double max_stored_bytes) {
  BarProperties bar;
  bar.elements = elements;
  TimeOptions time;
  time.step = 0.36e-6 * 100.0 / elements;
  time.window = time.step * steps;
  LoadOptions load;
  load.duration = 0.1e-3 * std::min(1.0, time.window / 0.63e-3);
  DataOptions data;
  data.snr = 10.0;
  data.truth_refinement = 1;
  const BarModel model(bar);
  const ChannelSet measured = MakeSyntheticMeasurements(bar, load, time, data);
  Row row{elements + 1, steps, {}, {}};
  const double stored_bytes = kIterativeSolverFields * 8.0 * (elements + 1.0) * (steps + 1.0);
  if (stored_bytes <= max_stored_bytes) {
    row.stored = SolveOnce(model, measured, CoupledSolverType::kConjugateGradient);
  }
  row.streamed = SolveOnce(model, measured, CoupledSolverType::kStreamingConjugateGradient);
  return row;
}

// Nanoseconds per node and step of one sweep.
double SweepNanoseconds(const Measured& measured, const Row& row) {
  return 1e9 * measured.seconds / (static_cast<double>(measured.sweeps) * row.nodes * row.steps);
}

void Print(const Row& row) {
  std::printf("%9d %7d | %9.3g %5d %6ld %6.2f %10.4g | %9.3g %5d %6ld %6.2f %10.4g | %10.2e\n",
              row.nodes, row.steps, row.stored.seconds, row.stored.iterations, row.stored.sweeps,
              SweepNanoseconds(row.stored, row), row.stored.peak_bytes / 1e6, row.streamed.seconds,
              row.streamed.iterations, row.streamed.sweeps, SweepNanoseconds(row.streamed, row),
              row.streamed.peak_bytes / 1e6,
              std::isnan(row.stored.cost)
                  ? NAN
                  : std::abs(row.streamed.cost - row.stored.cost) / row.stored.cost);
  std::fflush(stdout);
}

// Least-squares slope of log y against log x over the rows with finite, positive y.
double Slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!(y[i] > 0.0) || !std::isfinite(y[i])) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++count;
  }
  return count >= 2 ? (count * sxy - sx * sy) / (count * sxx - sx * sx) : NAN;
}

void Table(const std::vector<Row>& rows, bool against_nodes) {
  std::vector<double> x, stored_time, streamed_time, streamed_memory, stored_memory;
  for (const Row& row : rows) {
    x.push_back(against_nodes ? row.nodes : row.steps);
    stored_time.push_back(row.stored.seconds);
    streamed_time.push_back(row.streamed.seconds);
    stored_memory.push_back(row.stored.peak_bytes);
    streamed_memory.push_back(row.streamed.peak_bytes);
  }
  std::printf(
      "slopes against %s: time stored %.2f, streamed %.2f; peak memory stored %.2f, "
      "streamed %.2f\n\n",
      against_nodes ? "n" : "m", Slope(x, stored_time), Slope(x, streamed_time),
      Slope(x, stored_memory), Slope(x, streamed_memory));
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  int max_elements = 100000;
  int max_steps = 100000;
  double max_stored_bytes = 4e9;
  int min_elements = 100, min_steps = 1000;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--max-elements") == 0) max_elements = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--max-steps") == 0) max_steps = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--max-stored-bytes") == 0) max_stored_bytes = std::atof(argv[i + 1]);
    if (std::strcmp(argv[i], "--min-elements") == 0) min_elements = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--min-steps") == 0) min_steps = std::atoi(argv[i + 1]);
    if (std::strcmp(argv[i], "--tolerance") == 0) tolerance = std::atof(argv[i + 1]);
    if (std::strcmp(argv[i], "--formulation") == 0) {
      if (std::strcmp(argv[i + 1], "defaults") == 0) {
        formulation = McreOptions();
      } else if (std::strcmp(argv[i + 1], "paper") != 0) {
        std::fprintf(stderr, "--formulation: expected 'paper' or 'defaults', got '%s'\n",
                     argv[i + 1]);
        return 2;
      }
    }
  }
  spdlog::set_level(spdlog::level::warn);
  // Every block above 128 kB mapped on its own and unmapped when freed (no dynamic
  // threshold), so that a case's fields are not resident in the next case's heap.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  std::printf("%9s %7s | %-44s | %-44s | %10s\n", "", "", "stored-field CG", "streaming CG", "");
  std::printf("%9s %7s | %9s %5s %6s %6s %10s | %9s %5s %6s %6s %10s | %10s\n", "nodes", "steps",
              "time [s]", "iter", "sweeps", "ns/nm", "peak [MB]", "time [s]", "iter", "sweeps",
              "ns/nm", "peak [MB]", "d e^2 / e^2");
  std::vector<Row> by_nodes;
  for (int elements = min_elements; elements <= max_elements; elements *= 10) {
    by_nodes.push_back(Case(elements, 1750, max_stored_bytes));
    Print(by_nodes.back());
  }
  Table(by_nodes, true);
  std::vector<Row> by_steps;
  for (int steps = min_steps; steps <= max_steps; steps *= 10) {
    by_steps.push_back(Case(100, steps, max_stored_bytes));
    Print(by_steps.back());
  }
  Table(by_steps, false);
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
