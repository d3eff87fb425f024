// Conjugate gradients on the sensor traces (docs/streaming.md). With
// Phi(y) = H Direct(Retrograde(y)) (McreProblem::StreamingMap), b = Phi(0) and
// L y = Phi(y) - Phi(0), the coupled solution's traces solve
//
//   (I - L) y = b,
//
// and I - L is self-adjoint positive definite in <.,.>_beta on the weighted rows
// (L = -H D P D* H^T diag(beta)), with the same nonzero spectrum as A = I - G of the
// stored-field solvers: CG takes as many iterations or more (1.0 to 1.7 times,
// measured: it minimises another norm of the error), at three sweeps each instead of
// two (four from checkpoints: theta != 1/2, or after the rebuild drifted), and holds
// a handful of trace fields (channels x (m + 1)) and O(n) states (O(n sqrt(m)) with
// checkpoints).
//
// CG starts from the data, y_0 = d~, where the retrograde field vanishes: the
// stored-field solvers' start W = 0, or from a warm start y^(0) (the previous
// modulus's traces) when its residual is smaller in the W-norm below (three sweeps
// for that residual and one for its norm, against three per iteration saved; a start
// within the tolerance is accepted from that pass, with no iteration). Its
// stopping test is the stored-field solvers' whatever the start: the residual
// r = Phi(y) - y maps to their residual c - A W = R r at W = Retrograde(y) (R the
// retrograde sweep driven by r without data), whose P-norm is
//
//   ||r||_W^2 = ||R r||_P^2 = <r, -L r>_beta = <r, (I - L) r>_beta - <r, r>_beta,
//
// and ||r_k||_W / ||r_0||_W <= tolerance, tested on y_k once the application of
// that iteration has formed q_k. CG gives ||r_k||_W for free from its
// (I - L)-conjugate directions (r_k = p_k - beta_k p_{k-1}, -L p_k from the map):
//
//   <r_k, -L r_k> = <p_k, -L p_k> + 2 beta_k <p_k, p_{k-1}> + beta_k^2 <p_{k-1}, -L p_{k-1}>,
//
// three terms >= 0, free of the cancellation of <r, (I - L) r> - <r, r> where -L is
// small beside I. The true residual of the final pass is measured by one more
// backward sweep (McreProblem::RetrogradeEnergy). (A first version stopped on
// ||r||_beta / ||Phi(0)||_beta, which grows with the window: at the tolerance 1e-8 on
// 101 nodes, e^2 was 2.2e-3 off the stored-field CG's at 1e5 steps.)
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

#include "mcre/coupled_solver_internal.h"
#include "mcre/direct_solution_check.h"

namespace mcrewave::internal {
namespace {

// When the true residual of the final pass misses the tolerance, CG restarts from
// it at most this many times; after that, a true residual within
// kRoundOffFloorFactor times the rebuild error is accepted (and said so).
constexpr int kMaxRestarts = 2;
constexpr double kRoundOffFloorFactor = 10.0;

// The sweeps' own round-off is a floor too, checkpoints or not: the solves with the
// factorisation of M + h^2 K / 4 lose digits as the Courant number grows (a true
// residual of 5.8e-8 against the tolerance 1e-8 after three restarts, with
// checkpoints, on the paper's bar with 1e6 elements, Courant number 5700). After the
// restarts, a true residual that the last restart did not reduce tenfold is accepted
// at that floor when it is within this factor of the tolerance.
constexpr double kStalledResidualFactor = 100.0;

}  // namespace

void SolveByStreamingConjugateGradient(const CoupledSolverOptions& options, McreProblem* problem,
                                       const Matrix* initial_traces, CoupledSolution* solution,
                                       CoupledSolverSummary* summary) {
  assert(initial_traces == nullptr || (initial_traces->rows() == problem->num_traces() &&
                                       initial_traces->cols() == problem->num_steps() + 1));
  solution->displacement.resize(0, 0);
  solution->retrograde.resize(0, 0);
  // y_0 = d~: r_0 = b - (I - L) d~ = Phi(d~) - d~.
  Matrix traces = problem->DataTraces();
  Matrix residual, direction, image;
  problem->StreamingMap(traces, true, &residual);
  residual -= traces;
  const double rhs_norm = std::sqrt(std::max(problem->RetrogradeEnergy(residual), 0.0));
  summary->iterations = 0;
  McreProblem::StreamingTotals totals;
  // The final pass at y: the true residual Phi(y) - y = b - (I - L) y into `image`,
  // its W-norm relative to ||r_0||_W returned, and the sums of the fields in `totals`.
  auto final_pass = [&](const Matrix& y) {
    problem->StreamingMap(y, true, &image, &totals);
    image -= y;
    return rhs_norm > 0.0 ? std::sqrt(std::max(problem->RetrogradeEnergy(image), 0.0)) / rhs_norm
                          : 0.0;
  };
  // Said in the message when the solve started from the warm start or switched to
  // checkpoints.
  std::string start_note, switch_note;
  auto accept = [&](const std::string& message) {
    summary->termination = TerminationType::kConvergence;
    summary->message = message + "; rebuild error " + ScientificString(totals.rebuild_error) +
                       start_note + switch_note;
    solution->cost = totals.cost;
    solution->cost_gradients = totals.cost_gradients;
    solution->cost_gradient = totals.cost_gradients.sum();
    solution->traces = traces;
    solution->end_retrograde = totals.end_retrograde;
    solution->error_map = totals.error_map;
    solution->gap_density = totals.gap_density;
  };
  if (rhs_norm == 0.0) {
    final_pass(traces);
    accept("the data are matched exactly: Phi(d~) = d~");
    return;
  }
  // ||r_k||_W / ||r_0||_W: 1 at the data, less from a warm start that is kept, the
  // true one after a restart, then from the CG recursion (after q_k is formed).
  double relative = 1.0;
  if (initial_traces != nullptr) {
    // r^(0) = Phi(y^(0)) - y^(0), into `image` until it is kept; a final pass, so
    // that a start already within the tolerance needs no other.
    const double warm_relative = final_pass(*initial_traces);
    if (warm_relative < relative) {
      traces = *initial_traces;
      residual.swap(image);
      relative = warm_relative;
      start_note =
          "; from the warm start (relative residual " + ScientificString(warm_relative) + ")";
      if (relative <= options.tolerance && totals.rebuild_error <= options.max_rebuild_error) {
        summary->residual_history.push_back(relative);
        summary->relative_residual = relative;
        accept("relative residual " + ScientificString(relative) + " <= tolerance " +
               ScientificString(options.tolerance) + " at the start");
        return;
      }
    }
  }
  direction = residual;
  double rho = problem->TraceInnerProduct(residual, residual);
  // beta_k, <p_{k-1}, -L p_{k-1}> and <p_k, p_{k-1}> of the recursion above.
  double direction_coefficient = 0.0, previous_direction_energy = 0.0, consecutive_directions = 0.0;
  int restarts = 0, since_restart = 0, max_restarts = kMaxRestarts;
  // The true residual of the previous final pass (none yet: infinite).
  double previous_true_relative = std::numeric_limits<double>::infinity();
  summary->residual_history.push_back(relative);
  summary->relative_residual = relative;
  for (int iteration = 0;; ++iteration, ++since_restart) {
    summary->iterations = iteration;
    if (iteration == options.max_iterations) {
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "no convergence in " + std::to_string(iteration) +
                         " iterations: relative residual " + ScientificString(relative);
      return;
    }
    // L p into image, then q = (I - L) p.
    problem->StreamingMap(direction, false, &image);
    const double direction_energy = -problem->TraceInnerProduct(direction, image);
    image = direction - image;
    const double curvature = problem->TraceInnerProduct(direction, image);
    if (!(curvature > 0.0)) {
      summary->termination = TerminationType::kFailure;
      summary->message = "streaming conjugate gradients broke down: <p, (I - L) p> = " +
                         ScientificString(curvature) + " at iteration " + std::to_string(iteration);
      return;
    }
    if (since_restart > 0) {
      // ||r_k||_W^2 = <p_k, -L p_k> + 2 beta_k <p_k, p_{k-1}> + beta_k^2 <p_{k-1}, -L p_{k-1}>.
      const double energy =
          direction_energy + 2.0 * direction_coefficient * consecutive_directions +
          direction_coefficient * direction_coefficient * previous_direction_energy;
      relative = std::sqrt(std::max(energy, 0.0)) / rhs_norm;
      if (!std::isfinite(relative)) {
        summary->termination = TerminationType::kFailure;
        summary->message =
            "streaming conjugate gradients broke down: non-finite residual at iteration " +
            std::to_string(iteration);
        return;
      }
      summary->residual_history.push_back(relative);
      summary->relative_residual = relative;
    }
    if (relative > options.tolerance) {
      // y_{k+1} = y_k + a p_k, r_{k+1} = r_k - a q_k, a = <r_k, r_k> / <p_k, q_k>.
      const double step = rho / curvature;
      traces += step * direction;
      residual -= step * image;
      const double rho_next = problem->TraceInnerProduct(residual, residual);
      direction_coefficient = rho_next / rho;
      // <p_{k+1}, p_k> = <r_{k+1}, p_k> + beta_{k+1} <p_k, p_k>.
      consecutive_directions =
          problem->TraceInnerProduct(residual, direction) +
          direction_coefficient * problem->TraceInnerProduct(direction, direction);
      direction = residual + direction_coefficient * direction;
      previous_direction_energy = direction_energy;
      rho = rho_next;
      continue;
    }
    // r_k met the tolerance: the final pass checks the true residual of y_k. (Not
    // y_{k+1}: ||r_k||_W is not monotone, CG minimising another norm, and r_{k+1}
    // measured up to 1e4 times r_k.)
    double true_relative = final_pass(traces);
    if (!(totals.rebuild_error <= options.max_rebuild_error)) {
      // The reversed recursion drifted (the stiff modes' round-off at a high Courant
      // number): W from checkpoints from now on, exact, and y's true residual measured
      // with that map; CG goes on from it with one more restart allowed.
      switch_note = "; W from checkpoints after the rebuilt field drifted by " +
                    ScientificString(totals.rebuild_error) + " (limit " +
                    ScientificString(options.max_rebuild_error) + ")";
      problem->UseCheckpoints();
      true_relative = final_pass(traces);
      ++max_restarts;
    }
    summary->relative_residual = true_relative;
    if (true_relative <= options.tolerance) {
      accept("relative residual " + ScientificString(true_relative) + " <= tolerance " +
             ScientificString(options.tolerance));
      return;
    }
    if (restarts == max_restarts) {
      // The rebuild's round-off is a floor under the true residual: Phi(y) ~ y is
      // known to about rebuild_error ||y|| (1.1e-8 measured on 1e5 elements at
      // Courant number 570, where a tolerance of 1e-8 cannot be met).
      const double floor = kRoundOffFloorFactor * totals.rebuild_error *
                           std::sqrt(std::max(problem->RetrogradeEnergy(traces), 0.0)) / rhs_norm;
      if (true_relative <= floor) {
        accept("relative residual " + ScientificString(true_relative) + " at the round-off floor " +
               ScientificString(floor) + " of the rebuilt field (tolerance " +
               ScientificString(options.tolerance) + ")");
        return;
      }
      if (true_relative > 0.1 * previous_true_relative &&
          true_relative <= kStalledResidualFactor * options.tolerance) {
        accept("relative residual " + ScientificString(true_relative) +
               " at the round-off floor of the sweeps: the last restart left it at " +
               ScientificString(true_relative / previous_true_relative) +
               " times the previous one (tolerance " + ScientificString(options.tolerance) + ")");
        return;
      }
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "the true residual " + ScientificString(true_relative) +
                         " misses the tolerance " + ScientificString(options.tolerance) +
                         " after " + std::to_string(restarts) + " restarts";
      return;
    }
    // Restart from the true residual: the recursive one drifted from it.
    previous_true_relative = true_relative;
    ++restarts;
    since_restart = -1;
    residual = image;
    direction = residual;
    rho = problem->TraceInnerProduct(residual, residual);
    relative = true_relative;
    summary->residual_history.push_back(relative);
  }
}

}  // namespace mcrewave::internal
