// One coupled solve of a structure given by matrices with the streaming CG
// (inner.method streaming_conjugate_gradient, docs/streaming.md section 5): its CPU time
// per dof and time step and the resident memory it needs, so that structures of
// different size and dimension (the 3-D beam of configs/beam3d.yaml at several meshes,
// the plates) compare on one scale. scripts/beam3d_study.sh runs it, one process per
// config, and tabulates the lines in results/beam3d.
//
// The config's model and data (synthetic data at its truth moduli), one solve at the
// nominal moduli from a zero start, at the config's inner options with the method set
// to streaming_conjugate_gradient (its preconditioner and limits as the config says).
// Memory: the process's resident set after the model and data are read and the heap's
// free memory is returned to the system (malloc_trim), and its peak during the solve
// alone (the high-water mark is reset before it, /proc/self/clear_refs; where that is
// refused the whole process's peak is reported and marked so). Prints one line of
// key=value pairs:
//   dofs, steps, traces, iterations, sweeps, cpu_s (thread CPU of the solve),
//   ns_per_dof_step (cpu_s / (sweeps dofs steps)), resident_mb (after reading),
//   solve_peak_mb (peak during the solve), solve_added_mb (the two's difference),
//   history_budget_bytes, e2 (e^2 [J s]), factor_per_dof (the nonzeros of the theta
//   step's factor L of M + (theta h)^2 K by rows, sparse LDL^T in AMD order as
//   linalg/sparse_theta_step.h factorises it), matrix_per_dof (those of M and K).
//
// Usage: streaming_memory_benchmark CONFIG.yaml [--history-bytes B]
//   --history-bytes: the solve's inner.max_field_bytes (the retrograde history is kept
//   whole when n (m + 1) doubles fit, else checkpoints: O(n sqrt(m)) memory).
#include <malloc.h>
#include <spdlog/spdlog.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "bench_util.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace {

using namespace mcrewave;

// A line "Key:   1234 kB" of /proc/self/status, in MB (-1 when absent).
double StatusMegabytes(const char* key) {
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::size_t length = std::strlen(key);
  while (std::getline(status, line)) {
    if (line.compare(0, length, key) == 0 && line.size() > length && line[length] == ':') {
      return std::atof(line.c_str() + length + 1) / 1024.0;
    }
  }
  return -1.0;
}

// Resets the peak resident set to the current one (Linux >= 4.0); false if refused.
bool ResetPeakResident() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear);
}

}  // namespace

static int BenchmarkMain(int argc, char** argv) {
  std::string path;
  long history_bytes = -1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--history-bytes") == 0 && i + 1 < argc) {
      char* end = nullptr;
      history_bytes = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || history_bytes <= 0) {
        std::fprintf(stderr, "error: --history-bytes: '%s' is not a positive integer\n", argv[i]);
        return 2;
      }
    } else {
      path = argv[i];
    }
  }
  if (path.empty()) {
    std::fprintf(stderr, "usage: streaming_memory_benchmark CONFIG.yaml [--history-bytes B]\n");
    return 2;
  }
  spdlog::set_level(spdlog::level::warn);
  const Config config = LoadConfig(path);
  if (config.structure.kind != ModelKind::kMatrix) {
    std::fprintf(stderr, "error: %s: model.kind must be matrix\n", path.c_str());
    return 2;
  }
  const MatrixModelData model = LoadMatrixModel(config);
  const ChannelSet data = LoadMatrixMeasurements(config, model).histories;
  MatrixMcreProblem problem(model, data, config.mcre.weights, config.mcre.reference_modulus,
                            config.time.theta, Factorization::kAutomatic, config.mcre.clamp);
  CoupledSolverOptions options = config.inner;
  options.type = CoupledSolverType::kStreamingConjugateGradient;
  if (history_bytes > 0) options.max_field_bytes = history_bytes;
  problem.SetModuli(model.NominalModuli());

  const long sweeps_before = problem.sweep_count();
  const SparseMatrix stiffness = model.Stiffness(model.NominalModuli());
  const double theta_step = config.time.theta * config.time.step;  // [s]
  const SparseMatrix iteration_matrix = model.mass + theta_step * theta_step * stiffness;
  long factor_nonzeros = 0;
  {
    const Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> factor(
        iteration_matrix);
    factor_nonzeros = factor.matrixL().nestedExpression().nonZeros();
  }
  const long matrix_nonzeros = model.mass.nonZeros() + stiffness.nonZeros();
  malloc_trim(0);
  const double resident = StatusMegabytes("VmRSS");
  const bool reset = ResetPeakResident();
  const double start = bench::ThreadCpuSeconds();
  CoupledSolution solution;
  const CoupledSolverSummary summary = SolveCoupled(options, &problem, nullptr, &solution);
  const double seconds = bench::ThreadCpuSeconds() - start;
  const double peak = StatusMegabytes("VmHWM");
  if (!summary.IsSolutionUsable()) {
    std::fprintf(stderr, "error: %s: the solve failed: %s\n", path.c_str(),
                 summary.message.c_str());
    return 1;
  }
  const long sweeps = problem.sweep_count() - sweeps_before;
  const int steps = data.num_steps();
  std::printf(
      "config=%s dofs=%d steps=%d traces=%d iterations=%d sweeps=%ld cpu_s=%.4g "
      "ns_per_dof_step=%.4g resident_mb=%.1f solve_peak_mb=%.1f%s solve_added_mb=%.1f "
      "history_budget_bytes=%ld e2=%.6g factor_per_dof=%.1f matrix_per_dof=%.1f\n",
      path.c_str(), model.dofs(), steps, problem.num_traces(), summary.iterations, sweeps, seconds,
      1e9 * seconds / (static_cast<double>(sweeps) * model.dofs() * steps), resident, peak,
      reset ? "" : "(process)", peak - resident, options.max_field_bytes, solution.cost,
      static_cast<double>(factor_nonzeros) / model.dofs(),
      static_cast<double>(matrix_nonzeros) / model.dofs());
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
