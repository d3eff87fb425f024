// Cost of one step of the theta integrator's sparse path (linalg/sparse_theta_step.h)
// against the nonzeros of the factor of S = M + h^2 theta^2 K, on 2-D grid meshes
// of 1e3 to 2.5e5 dofs (and more with --max-dofs).
//
// Mesh: an N x N grid of nodes, one scalar dof per node, coupled to its 8 neighbours
// (the 9-point pattern of bilinear quadrilaterals: 9 entries per row), the first
// column grounded, consistent-like mass with the same pattern. Per case: the time of
// Init (AMD analysis + numeric factorisation), the time per step (the one-pass
// right-hand side, the permuted triangular solves, the update), the time of the solve
// alone (P, L, D^-1, L^T, P^T: the two triangular solves that bound any implicit
// step from below), their ratio, and nnz(L + D). Prints the rows and the fitted
// log-log slope of the step time against nnz(L + D).
//
// Then the MCRE sweeps of the same grid as a structure given by matrices
// (mcre/matrix_mcre_problem.h: one zone, a load on the last dof, three displacement
// sensors, kSweepSteps steps): the time per step of a direct and of a retrograde sweep
// (each forms its force from G, H and the other field, then steps) against the
// integrator's step; the bytes of the space-time fields an iterative coupled solve of
// kFieldSteps steps would hold, and whether SolveCoupled refuses them under the
// default inner.max_field_bytes (its message, with the bytes, for the largest grid).
//
//   build/bench/sparse_step_benchmark [--max-dofs 250000]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_util.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/coupled_solver.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The 9-point grid's K (springs to the 8 neighbours) and M.
void MakeGrid(int side, SparseMatrix* mass, SparseMatrix* stiffness) {
  const int n = side * side;
  std::vector<Eigen::Triplet<double>> k, m;
  k.reserve(static_cast<std::size_t>(n) * 18);
  m.reserve(static_cast<std::size_t>(n) * 18);
  auto couple = [&](int a, int b, double spring, double mass_coupling) {
    k.emplace_back(a, a, spring);
    k.emplace_back(b, b, spring);
    k.emplace_back(a, b, -spring);
    k.emplace_back(b, a, -spring);
    m.emplace_back(a, b, mass_coupling);
    m.emplace_back(b, a, mass_coupling);
  };
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const int a = j * side + i;
      m.emplace_back(a, a, 1.0);
      if (i == 0) k.emplace_back(a, a, 1.0);
      if (i + 1 < side) couple(a, a + 1, 1.0, 0.05);
      if (j + 1 < side) couple(a, a + side, 1.0, 0.05);
      if (i + 1 < side && j + 1 < side) couple(a, a + side + 1, 0.5, 0.02);
      if (i > 0 && j + 1 < side) couple(a, a + side - 1, 0.5, 0.02);
    }
  }
  mass->resize(n, n);
  mass->setFromTriplets(m.begin(), m.end());
  stiffness->resize(n, n);
  stiffness->setFromTriplets(k.begin(), k.end());
}

constexpr int kSweepSteps = 20;    // steps of the measured sweeps
constexpr int kFieldSteps = 1000;  // steps of the field-memory figure (m ~ 1000 in the MCRE)

// The grid as a one-zone matrix model: K at the nominal modulus 1, a unit load on the
// last dof (channel F), displacement sensors at the first, middle and last dofs.
MatrixModelData GridModel(const SparseMatrix& mass, const SparseMatrix& stiffness) {
  const auto n = static_cast<int>(mass.rows());
  MatrixModelData model;
  model.mass = mass;
  model.stiffness_length = 1.0;
  model.length = 1.0;
  model.zones.push_back({"grid", stiffness, 1.0});
  Vector load = Vector::Zero(n);
  load[n - 1] = 1.0;
  model.loads.push_back({"F", load});
  for (const int dof : {0, n / 2, n - 1}) {
    SparseMatrix row(1, n);
    row.insert(0, dof) = 1.0;
    model.sensors.push_back({"u" + std::to_string(dof), row, SensorKind::kDisplacement});
  }
  return model;
}

// Seconds per step of a direct and of a retrograde sweep of the grid's MCRE problem,
// and the refusal (or "") of a CG solve over kFieldSteps steps under the default
// inner.max_field_bytes.
void MeasureSweeps(const SparseMatrix& mass, const SparseMatrix& stiffness, double* direct,
                   double* retrograde, std::string* refusal) {
  const MatrixModelData model = GridModel(mass, stiffness);
  const auto n = static_cast<int>(mass.rows());
  Matrix loads = Matrix::Zero(1, kSweepSteps + 1);
  for (int j = 0; j <= kSweepSteps; ++j) loads(0, j) = std::sin(0.3 * j);
  const ChannelSet data = MatrixChannelSet(model, 0.5, loads, Matrix::Zero(3, kSweepSteps + 1));
  MatrixMcreProblem problem(model, data, McreWeights(), 1.0, 0.5, Factorization::kSparse);
  problem.SetModuli(Vector::Ones(1));
  Matrix displacement(n, kSweepSteps + 1), field(n, kSweepSteps + 1);
  Matrix zero = Matrix::Zero(n, kSweepSteps + 1);
  Clock::time_point start = Clock::now();
  problem.DirectSweep(zero, true, &displacement);
  *direct = Seconds(start) / kSweepSteps;
  start = Clock::now();
  problem.RetrogradeSweep(displacement, true, &field);
  *retrograde = Seconds(start) / kSweepSteps;

  const ChannelSet long_data = MatrixChannelSet(model, 0.5, Matrix::Zero(1, kFieldSteps + 1),
                                                Matrix::Zero(3, kFieldSteps + 1));
  MatrixMcreProblem long_problem(model, long_data, McreWeights(), 1.0, 0.5,
                                 Factorization::kSparse);
  CoupledSolverOptions options;  // auto: stored-field CG on matrices; the default max_field_bytes
  CoupledSolution solution;
  const double field_bytes = static_cast<double>(kIterativeSolverFields) * sizeof(double) * n *
                             (kFieldSteps + 1.0);
  *refusal = field_bytes > static_cast<double>(options.max_field_bytes)
                 ? SolveCoupled(options, &long_problem, nullptr, &solution).message
                 : "";
}

// Least-squares slope of log y against log x.
double Slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double count = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

void Run(long max_dofs) {
  std::printf("%9s %12s %10s %12s %12s %8s %10s\n", "dofs", "nnz(L+D)", "init_s", "step_us",
              "solve_us", "ratio", "ns/nnz");
  std::vector<double> nonzeros, step_times;
  std::vector<int> sides;
  for (const int side : {32, 71, 100, 224, 316, 500, 708, 1000}) {
    const long n = static_cast<long>(side) * side;
    if (n > max_dofs) break;
    sides.push_back(side);
    SparseMatrix mass, stiffness;
    MakeGrid(side, &mass, &stiffness);
    ThetaIntegratorOptions options;
    options.time_step = 0.5;
    options.factorization = Factorization::kSparse;
    ThetaIntegrator integrator;
    const Clock::time_point init_start = Clock::now();
    integrator.Init(mass, stiffness, options);
    const double init_time = Seconds(init_start);
    const long factor = integrator.sparse().factor_nonzeros();
    Vector v = Vector::Zero(n), u = Vector::Zero(n), v_next(n), u_next(n), force = Vector::Zero(n);
    force[n - 1] = 1.0;
    // Enough repetitions for about 0.5 s per measurement (at least 5).
    const int repetitions = std::max(5, static_cast<int>(2e8 / static_cast<double>(factor)));
    Clock::time_point start = Clock::now();
    for (int r = 0; r < repetitions; ++r) {
      integrator.Step(v, u, force, v_next, u_next);
      v.swap(v_next);
      u.swap(u_next);
    }
    const double step = Seconds(start) / repetitions;
    SparseThetaStepper& stepper = const_cast<SparseThetaStepper&>(integrator.sparse());
    Vector x = Vector::Ones(n);
    start = Clock::now();
    for (int r = 0; r < repetitions; ++r) stepper.SolveInPlace(x.data());
    const double solve = Seconds(start) / repetitions;
    std::printf("%9ld %12ld %10.3f %12.1f %12.1f %8.2f %10.2f\n", n, factor, init_time, 1e6 * step,
                1e6 * solve, step / solve, 1e9 * step / static_cast<double>(factor));
    std::fflush(stdout);
    nonzeros.push_back(static_cast<double>(factor));
    step_times.push_back(step);
    if (u.hasNaN()) std::printf("(NaN)\n");
  }
  std::printf("fitted slope of the step time against nnz(L+D): %.3f\n",
              Slope(nonzeros, step_times));

  std::printf("\nMCRE sweeps of the grid as a matrix model (%d steps; fields of %d steps)\n",
              kSweepSteps, kFieldSteps);
  std::printf("%9s %12s %12s %12s %12s %14s %9s\n", "dofs", "step_us", "direct_us",
              "retro_us", "direct/step", "field_bytes", "refused");
  std::string last_refusal;
  for (std::size_t c = 0; c < sides.size(); ++c) {
    SparseMatrix mass, stiffness;
    MakeGrid(sides[c], &mass, &stiffness);
    double direct = 0.0, retrograde = 0.0;
    std::string refusal;
    MeasureSweeps(mass, stiffness, &direct, &retrograde, &refusal);
    const long n = static_cast<long>(sides[c]) * sides[c];
    const double field_bytes =
        static_cast<double>(kIterativeSolverFields) * sizeof(double) * n * (kFieldSteps + 1.0);
    std::printf("%9ld %12.1f %12.1f %12.1f %12.2f %14.4g %9s\n", n, 1e6 * step_times[c],
                1e6 * direct, 1e6 * retrograde, direct / step_times[c], field_bytes,
                refusal.empty() ? "no" : "yes");
    std::fflush(stdout);
    if (!refusal.empty()) last_refusal = refusal;
  }
  if (!last_refusal.empty()) std::printf("refusal of the largest: %s\n", last_refusal.c_str());
}

}  // namespace
}  // namespace mcrewave

static int BenchmarkMain(int argc, char** argv) {
  long max_dofs = 250000;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--max-dofs") == 0) max_dofs = std::atol(argv[i + 1]);
  }
  mcrewave::Run(max_dofs);
  return 0;
}

int main(int argc, char** argv) { return mcrewave::bench::GuardedMain(BenchmarkMain, argc, argv); }
