// The sweep-based coupled solvers: waveform relaxation (fixed or adaptive
// coefficient) and conjugate gradients. Notation of docs/discrete_mcre.md:
// T(W) = Retrograde(Direct(W)) with the data, c = T(0), G W = T(W) - T(0),
// A = I - G, residual r = c - A W = T(W) - W, norms in <.,.>_P.

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include "mcre/coupled_solver_internal.h"
#include "mcre/direct_solution_check.h"
#include "mcrewave/core/interrupt.h"

namespace mcrewave::internal {
namespace {

// The state every iterative solver starts from: W^(0), U = Direct(W^(0)),
// r = T(W^(0)) - W^(0), ||c||_P, and the round-off floor of the residual. Costs 3
// sweeps, 5 when W^(0) != 0 (c is then computed separately), run as one batch of
// direct sweeps and one of retrograde sweeps. When c = 0 the solution (W = 0) is
// set and the summary says so.
struct StartingPoint {
  double rhs_norm = 0.0;  // ||c||_P
  // ||r||_P below this is round-off: c = T(0) is the difference of the retrograde
  // responses to the force data and to the displacement data, which cancel when the
  // data are consistent with the model; the floor is kRoundOffFloor times the
  // response to the displacement data alone, W_u = Retrograde(0) with the data.
  double residual_floor = 0.0;
  bool solved = false;  // c = 0: the solution W = 0 is already in place
};

// Measured: on the paper's case with noise-free data at E_ref and w_u = 1
// (a_max = 3.2e3), CG's true residual stalls at 2e-12 ||W_u||_P while its recursive
// residual goes on decreasing; with noisy data ||c||_P is 3 to 6 ||W_u||_P, so this
// floor only acts on data consistent with the model to about 1e-3 or better.
constexpr double kRoundOffFloor = 1e-11;

StartingPoint Start(CoupledProblem* problem, const Matrix* initial_retrograde,
                    CoupledSolution* solution, Matrix* residual, CoupledSolverSummary* summary) {
  StartingPoint start;
  Matrix& retrograde = solution->retrograde;
  CoupledProblem::SolverWorkspace& work = problem->workspace();
  const bool zero_start =
      initial_retrograde == nullptr || initial_retrograde->cwiseAbs().maxCoeff() == 0.0;
  // T(W^(0)) = Retrograde(U), U = Direct(W^(0)); c = T(0); W_u = Retrograde(0): the
  // sweeps of the same direction run batched (DirectSweepsWithData).
  if (zero_start) {
    retrograde.setZero(problem->num_nodes(), problem->num_steps() + 1);
    problem->DirectSweepsWithData({nullptr}, {&solution->displacement});
    problem->RetrogradeSweepsWithData({&solution->displacement, nullptr},
                                      {residual, &work.data_response});
    // T(0) = c.
    start.rhs_norm = problem->Norm(*residual);
  } else {
    retrograde = *initial_retrograde;
    problem->DirectSweepsWithData({&retrograde, nullptr}, {&solution->displacement, &work.scratch});
    problem->RetrogradeSweepsWithData({&solution->displacement, &work.scratch, nullptr},
                                      {residual, &work.rhs, &work.data_response});
    start.rhs_norm = problem->Norm(work.rhs);
  }
  summary->reference_residual_norm = start.rhs_norm;
  start.residual_floor = kRoundOffFloor * problem->Norm(work.data_response);
  *residual -= retrograde;
  summary->iterations = 0;
  if (start.rhs_norm == 0.0) {
    // c = 0: W = 0 is the solution (and U = Direct(0) already when W^(0) = 0).
    if (!zero_start) {
      retrograde.setZero();
      problem->DirectSweep(retrograde, true, &solution->displacement);
    }
    summary->termination = TerminationType::kConvergence;
    summary->relative_residual = 0.0;
    summary->message = "the data are matched exactly: c = T(0) = 0";
    start.solved = true;
  }
  return start;
}

// True when ||r||_P = relative * ||c||_P meets the tolerance or the round-off floor.
bool Converged(const StartingPoint& start, double relative, double tolerance) {
  return relative <= tolerance || relative * start.rhs_norm <= start.residual_floor;
}

// Extreme eigenvalues of A = I - G by `steps` Lanczos steps in <.,.>_P from
// `start`; 2 sweeps per step. Returns {a_min, a_max} of the Ritz values.
std::pair<double, double> EstimateSpectrum(CoupledProblem* problem, const Matrix& start,
                                           int steps) {
  Matrix q = start / problem->Norm(start);
  Matrix q_previous = problem->ZeroField();
  Matrix w, scratch;
  Vector diagonal(steps), off_diagonal(steps);
  double beta_previous = 0.0;
  int done = 0;
  for (int i = 0; i < steps; ++i) {
    // w = A q = q - G q.
    problem->ApplyIterationMap(q, &scratch, &w);
    w = q - w;
    const double alpha = problem->InnerProduct(q, w);
    w -= alpha * q + beta_previous * q_previous;
    const double beta = problem->Norm(w);
    diagonal[i] = alpha;
    off_diagonal[i] = beta;
    done = i + 1;
    if (!(beta > 1e-12 * std::abs(alpha))) break;  // invariant subspace found
    q_previous.swap(q);
    q = w / beta;
    beta_previous = beta;
  }
  return TridiagonalEigenvalueExtremes(diagonal.head(done),
                                       off_diagonal.head(std::max(done - 1, 0)));
}

// The message of a converged solve.
std::string ConvergenceMessage(const StartingPoint& start, double relative, double tolerance) {
  if (relative <= tolerance) {
    return "relative residual " + ScientificString(relative) + " <= tolerance " + ScientificString(tolerance);
  }
  return "residual " + ScientificString(relative * start.rhs_norm) + " at the round-off floor " +
         ScientificString(start.residual_floor) +
         " (c = T(0) nearly cancels: the data are close to consistent with the model)";
}

// The relaxation coefficient to start with: options.relaxation_coefficient, or for
// the adaptive relaxation 2 / (a_min + a_max) from a Lanczos estimate of A's
// spectrum started from `residual` (a_max, inflated by the safety factor, into
// *spectrum_max). The spectrum and omega go into the summary too.
double InitialRelaxationCoefficient(const CoupledSolverOptions& options, CoupledProblem* problem,
                                    const Matrix& residual, double* spectrum_max,
                                    CoupledSolverSummary* summary) {
  double omega = options.relaxation_coefficient;
  if (options.type == CoupledSolverType::kAdaptiveRelaxation) {
    // omega = 2 / (a_min + a_max), a_max inflated by the safety factor; a >= 1 always.
    const auto [a_min, a_max] =
        EstimateSpectrum(problem, residual, options.spectrum_estimation_steps);
    summary->spectrum_min = std::max(1.0, a_min);
    *spectrum_max = options.spectrum_safety_factor * a_max;
    summary->spectrum_max = *spectrum_max;
    omega = 2.0 / (summary->spectrum_min + *spectrum_max);
  }
  summary->relaxation_coefficient = omega;
  return omega;
}

constexpr int kMaxSafeguardRestarts = 10;

// The adaptive relaxation's safeguard: raises *spectrum_max to the a that the
// residual's growth factor reveals and sets *omega (and the summary) from it.
// False, with the summary's divergence, after kMaxSafeguardRestarts re-estimates.
bool ReestimateRelaxationCoefficient(const CoupledSolverOptions& options, double growth,
                                     double* omega, double* spectrum_max,
                                     CoupledSolverSummary* summary) {
  if (summary->safeguard_restarts >= kMaxSafeguardRestarts) {
    summary->termination = TerminationType::kDivergence;
    summary->message = "the adaptive relaxation kept diverging after " +
                       std::to_string(kMaxSafeguardRestarts) + " re-estimates of omega";
    return false;
  }
  ++summary->safeguard_restarts;
  *spectrum_max =
      options.spectrum_safety_factor * std::max(1.2 * *spectrum_max, (1.0 + growth) / *omega);
  summary->spectrum_max = *spectrum_max;
  *omega = 2.0 / (summary->spectrum_min + *spectrum_max);
  summary->relaxation_coefficient = *omega;
  return true;
}

// The message of a relaxation whose residual grew from best to relative.
std::string RelaxationDivergenceMessage(double best, double relative, int iteration, double omega) {
  return "the relaxation diverges: the relative residual grew from " + ScientificString(best) +
         " to " + ScientificString(relative) + " by iteration " + std::to_string(iteration) +
         "; omega = " + ScientificString(omega) +
         " is above the convergence limit 2 / (1 - lambda_min(G)): use a "
         "smaller omega, adaptive_relaxation or conjugate_gradient";
}

}  // namespace

std::pair<double, double> TridiagonalEigenvalueExtremes(const Vector& diagonal,
                                                        const Vector& sub_diagonal) {
  Eigen::SelfAdjointEigenSolver<Matrix> ritz;
  ritz.computeFromTridiagonal(diagonal, sub_diagonal, Eigen::EigenvaluesOnly);
  return {ritz.eigenvalues().minCoeff(), ritz.eigenvalues().maxCoeff()};
}

void ConjugateGradientLanczos::ReportTo(CoupledSolverSummary* summary) const {
  const auto k = static_cast<Eigen::Index>(steps.size());
  if (k == 0) return;
  Vector diagonal(k), sub_diagonal(k - 1);
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto at = static_cast<std::size_t>(i);
    // T_kk = 1 / step_k + ratio_{k-1} / step_{k-1},  T_k,k+1 = sqrt(ratio_k) / step_k
    diagonal[i] = 1.0 / steps[at] + (i > 0 ? ratios[at - 1] / steps[at - 1] : 0.0);
    if (i + 1 < k) sub_diagonal[i] = std::sqrt(ratios[at]) / steps[at];
  }
  std::tie(summary->spectrum_min, summary->spectrum_max) =
      TridiagonalEigenvalueExtremes(diagonal, sub_diagonal);
}

void SolveByRelaxation(const CoupledSolverOptions& options, CoupledProblem* problem,
                       const Matrix* initial_retrograde, CoupledSolution* solution,
                       CoupledSolverSummary* summary) {
  const bool adaptive = options.type == CoupledSolverType::kAdaptiveRelaxation;
  Matrix& retrograde = solution->retrograde;
  Matrix& displacement = solution->displacement;
  Matrix& residual = problem->workspace().residual;
  const StartingPoint start = Start(problem, initial_retrograde, solution, &residual, summary);
  if (start.solved) return;

  double spectrum_max = 0.0;
  double omega = InitialRelaxationCoefficient(options, problem, residual, &spectrum_max, summary);

  Matrix best_retrograde = retrograde;
  double best_residual = std::numeric_limits<double>::infinity();
  double previous_residual = std::numeric_limits<double>::infinity();
  int growth_streak = 0;
  // Growth over this many consecutive iterations, to this factor above the best
  // residual, triggers the safeguard (smaller wiggles are round-off).
  constexpr int kGrowthStreak = 3;
  constexpr double kGrowthMargin = 1.5;
  for (int iteration = 0;; ++iteration) {
    const double relative = problem->Norm(residual) / start.rhs_norm;
    summary->relative_residual = relative;
    summary->residual_history.push_back(relative);
    summary->iterations = iteration;
    if (!std::isfinite(relative)) {
      summary->termination = TerminationType::kDivergence;
      summary->message = "the relaxation diverged: the residual is not finite at iteration " +
                         std::to_string(iteration) + " (omega = " + ScientificString(omega) + ")";
      return;
    }
    if (Converged(start, relative, options.tolerance)) {
      summary->termination = TerminationType::kConvergence;
      summary->message = ConvergenceMessage(start, relative, options.tolerance);
      return;
    }
    if (relative < best_residual) {
      best_residual = relative;
      if (adaptive) best_retrograde = retrograde;
    }
    growth_streak = relative > previous_residual ? growth_streak + 1 : 0;
    const double growth = relative / previous_residual;
    previous_residual = relative;
    if (adaptive && growth_streak >= kGrowthStreak && relative > kGrowthMargin * best_residual) {
      // In <.,.>_P the residual contracts monotonically when omega a_max < 2; a
      // sustained growth well above round-off means a_max was underestimated. The
      // growing component has |1 - omega a| = growth, so a = (1 + growth) / omega;
      // restart from the best iterate.
      if (!ReestimateRelaxationCoefficient(options, growth, &omega, &spectrum_max, summary)) return;
      retrograde = best_retrograde;
      problem->FixedPointMap(retrograde, &displacement, &residual);
      residual -= retrograde;
      previous_residual = std::numeric_limits<double>::infinity();
      growth_streak = 0;
      continue;
    }
    if (relative > options.divergence_factor * best_residual) {
      summary->termination = TerminationType::kDivergence;
      summary->message = RelaxationDivergenceMessage(best_residual, relative, iteration, omega);
      return;
    }
    if (InterruptRequested()) {
      summary->termination = TerminationType::kFailure;
      summary->message = kInterruptedMessage;
      return;
    }
    if (iteration == options.max_iterations) {
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "no convergence in " + std::to_string(iteration) +
                         " iterations: relative residual " + ScientificString(relative) +
                         " > tolerance " + ScientificString(options.tolerance);
      return;
    }
    // W <- omega T(W) + (1 - omega) W = W + omega r; then U = Direct(W), r = T(W) - W.
    retrograde += omega * residual;
    problem->FixedPointMap(retrograde, &displacement, &residual);
    residual -= retrograde;
  }
}

void SolveByConjugateGradient(const CoupledSolverOptions& options, CoupledProblem* problem,
                              const Matrix* initial_retrograde, CoupledSolution* solution,
                              CoupledSolverSummary* summary) {
  Matrix& retrograde = solution->retrograde;
  Matrix& displacement = solution->displacement;
  CoupledProblem::SolverWorkspace& work = problem->workspace();
  Matrix& residual = work.residual;
  const StartingPoint start = Start(problem, initial_retrograde, solution, &residual, summary);
  if (start.solved) return;
  Matrix& direction = work.direction;
  Matrix& image = work.image;
  Matrix& scratch = work.scratch;
  direction = residual;
  double rho = problem->InnerProduct(residual, residual);
  constexpr int kMaxVerifiedRestarts = 5;
  int restarts = 0;
  // Whether `residual` is the true residual T(W) - W with U = Direct(W): after the
  // start and after a verification, not after a CG step (recursive residual).
  bool residual_is_true = true;
  // A loose solve keeps U = Direct(W) along W and ends on the recursive residual
  // (CoupledSolverOptions::unchecked_tolerance).
  const bool unchecked = options.tolerance >= options.unchecked_tolerance;
  // The Lanczos coefficients of the first CG run (a verified restart starts another
  // Krylov space), for the summary's Ritz extremes of A.
  ConjugateGradientLanczos lanczos;
  for (int iteration = 0;; ++iteration) {
    double relative = std::sqrt(std::max(rho, 0.0)) / start.rhs_norm;
    if (!std::isfinite(relative)) {
      summary->termination = TerminationType::kFailure;
      summary->message = "conjugate gradients broke down: non-finite residual at iteration " +
                         std::to_string(iteration);
      return;
    }
    if (Converged(start, relative, options.tolerance)) {
      if (!residual_is_true && !unchecked) {
        // Verify with the true residual T(W) - W (2 sweeps); this also leaves
        // U = Direct(W) consistent with W.
        problem->FixedPointMap(retrograde, &displacement, &residual);
        residual -= retrograde;
        rho = problem->InnerProduct(residual, residual);
        relative = std::sqrt(std::max(rho, 0.0)) / start.rhs_norm;
        residual_is_true = true;
      }
      summary->relative_residual = relative;
      if (unchecked || Converged(start, relative, options.tolerance)) {
        summary->residual_history.push_back(relative);
        summary->iterations = iteration;  // CG steps taken
        summary->termination = TerminationType::kConvergence;
        summary->message = ConvergenceMessage(start, relative, options.tolerance);
        lanczos.ReportTo(summary);
        return;
      }
      if (++restarts > kMaxVerifiedRestarts) {
        summary->termination = TerminationType::kNoConvergence;
        summary->message = "the true residual " + ScientificString(relative) +
                           " stays above the tolerance (round-off limit reached)";
        lanczos.ReportTo(summary);
        return;
      }
      direction = residual;
    }
    summary->residual_history.push_back(relative);
    summary->relative_residual = relative;
    summary->iterations = iteration;
    if (InterruptRequested()) {
      summary->termination = TerminationType::kFailure;
      summary->message = kInterruptedMessage;
      return;
    }
    if (iteration == options.max_iterations) {
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "no convergence in " + std::to_string(iteration) +
                         " iterations: relative residual " + ScientificString(relative) +
                         " > tolerance " + ScientificString(options.tolerance);
      lanczos.ReportTo(summary);
      return;
    }
    // q = A p = p - G p; scratch = D p, the direct sweep of p without the data.
    problem->ApplyIterationMap(direction, &scratch, &image);
    image = direction - image;
    const double curvature = problem->InnerProduct(direction, image);
    if (!(curvature > 0.0)) {
      summary->termination = TerminationType::kFailure;
      summary->message = "conjugate gradients broke down: <p, A p>_P = " + ScientificString(curvature) +
                         " is not positive at iteration " + std::to_string(iteration);
      return;
    }
    const double step = rho / curvature;
    retrograde += step * direction;
    // U = Direct(W) is affine in W: Direct(W + step p) = U + step D p.
    if (unchecked) displacement += step * scratch;
    residual -= step * image;
    residual_is_true = false;
    const double rho_next = problem->InnerProduct(residual, residual);
    if (restarts == 0) lanczos.Add(step, rho_next / rho);
    direction = residual + (rho_next / rho) * direction;
    rho = rho_next;
  }
}

}  // namespace mcrewave::internal
