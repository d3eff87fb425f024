// Conjugate gradients on the sensor traces (docs/streaming.md). With
// Phi(y) = H Direct(Retrograde(y)) (StreamingCoupledProblem::StreamingMap of
// MatrixMcreProblem, or of the tests' band-model bar), b = Phi(0) and
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
// for that residual and one for its norm, against three per iteration saved; that
// pass leaves the totals out, and a start within the tolerance is accepted with no
// iteration, one more application of the map summing them). Given ||r_0||_W of a
// nearby problem (the same modulus on the previous mesh, docs/multilevel.md), the
// data start's residual and norm are computed only when the warm start's residual is
// not below it. Its stopping test is the stored-field solvers' whatever the start: the
// residual r = Phi(y) - y maps to their residual c - A W = R r at W = Retrograde(y)
// (R the retrograde sweep driven by r without data), whose P-norm is
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
// backward sweep (StreamingCoupledProblem::RetrogradeEnergy). (A first version stopped on
// ||r||_beta / ||Phi(0)||_beta, which grows with the window: at the tolerance 1e-8 on
// 101 nodes, e^2 was 2.2e-3 off the stored-field CG's at 1e5 steps.)
//
// Preconditioned (options.preconditioner, docs/streaming.md section 6): with M = I - L
// at moduli near the solve's (StreamingCoupledProblem::PrepareTracePreconditioner),
// z_k = M^-1 r_k, rho_k = <r_k, z_k>, p_k = z_k + (rho_k / rho_{k-1}) p_{k-1}, the same
// step; M is self-adjoint in <.,.>_beta. The recursion above for ||r_k||_W needs
// r_k = p_k - beta_k p_{k-1}, which PCG does not have: ||r_k||_W is estimated by
// ||r_start||_W (rho_k / rho_start)^1/2 and measured by RetrogradeEnergy once that
// estimate is within kMeasuredResidualFactor of the tolerance (not when it is that far
// below it); r_k is tested before p_k is applied, then the final pass as above.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

#include "mcre/coupled_solver_internal.h"
#include "mcre/direct_solution_check.h"
#include "mcrewave/core/interrupt.h"

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

// Preconditioned, the residual's W-norm is estimated from the decrease of its
// M^-1-norm, and measured (one backward sweep) once the estimate is within this factor
// of the tolerance: the two norms weigh the spectrum of -L differently. An estimate
// below the tolerance by this factor goes to the final pass unmeasured: the two norms'
// ratio is at most the square root of the condition of M^-1 (I - L), about 3 within the
// rebuild change (docs/streaming.md section 6), and the final pass measures the true
// residual anyway.
constexpr double kMeasuredResidualFactor = 10.0;

// One solve by conjugate gradients on the traces (the scheme at the top of this
// file): its trace fields, the scalars of the recursion and of the stopping test,
// and the notes of its final message.
class StreamingConjugateGradient {
 public:
  StreamingConjugateGradient(const CoupledSolverOptions& options, StreamingCoupledProblem* problem,
                             CoupledSolution* solution, CoupledSolverSummary* summary)
      : options_(options), problem_(problem), solution_(solution), summary_(summary) {}

  // Solves from the data, or from initial_traces (nullable) when its residual is
  // smaller; fills the solution and the summary. reference_residual_norm > 0 with
  // initial_traces: ||r_0||_W of a nearby problem (SolveCoupled's), the data start then
  // computed only when the warm start's residual is not below it.
  void Solve(const Matrix* initial_traces, double reference_residual_norm);
  // ||r_0||_W, the norm the relative residuals were measured against (0 before Solve).
  double reference_residual_norm() const { return rhs_norm_; }
  // The summary's spectrum_min / spectrum_max: the Ritz extremes of the CG run before
  // the first restart, once it took a step.
  void ReportSpectrum() const { lanczos_.ReportTo(summary_); }

 private:
  // The final pass at y: the true residual Phi(y) - y = b - (I - L) y into `image`,
  // its W-norm relative to ||r_0||_W returned, and the sums of the fields in `totals`.
  double FinalPass(const Matrix& y) { return ResidualPass(y, true); }
  // The final pass's residual, with the totals or without them (a warm start's: its
  // totals are wanted only when it is accepted as it is).
  double ResidualPass(const Matrix& y, bool with_totals);
  // Converged with `message`: the solution takes the totals of the last final pass.
  void Accept(const std::string& message);
  // What became of a warm start: refused (its residual not below the data's, relative_),
  // kept as CG's start, or accepted as it is (within the tolerance: the solve is done).
  enum class WarmStartOutcome { kRefused, kKept, kAccepted };
  WarmStartOutcome TryWarmStart(const Matrix& initial_traces);
  // L p into image, then q = (I - L) p; <p, -L p> and <p, q> returned through the
  // pointers. False (the summary says why) when <p, q> is not positive.
  bool ApplyToDirection(int iteration, double* direction_energy, double* curvature);
  // z = M^-1 r (z = r without a preconditioner), p = z and rho = <r, z> of the residual
  // r now in residual_, whose ||r||_W / ||r_0||_W is relative_ (preconditioned: the
  // start of its estimate).
  void StartRecursion();
  // Preconditioned: ||r_k||_W / ||r_0||_W into relative_ and the history, estimated
  // by start_relative_ (rho_k / start_rho_)^1/2 (the M^-1-norm's decrease), measured
  // by one backward sweep once that estimate is within kMeasuredResidualFactor of the
  // tolerance, above or below.
  void UpdatePreconditionedResidual();
  // ||r_k||_W / ||r_0||_W from the recursion into relative_ and the history; false
  // (the summary says why) when it is not finite.
  bool UpdateRecursiveResidual(int iteration, double direction_energy);
  // The CG step y_{k+1}, r_{k+1}, p_{k+1} and the scalars of the next residual norm.
  void Step(double direction_energy, double curvature);
  // r_k met the tolerance: the final pass checks the true residual of y_k. True when
  // the solve is done (converged or not); false when CG restarts from it.
  bool CheckTrueResidual();
  // After the last restart: accepts a true residual at a round-off floor, else says
  // that the tolerance was missed.
  void StopAfterRestarts(double true_relative);

  const CoupledSolverOptions& options_;
  StreamingCoupledProblem* problem_;
  CoupledSolution* solution_;
  CoupledSolverSummary* summary_;
  Matrix traces_, residual_, direction_, image_;
  // With a preconditioner M (options.preconditioner): z = M^-1 r, and rho = <r, z>
  // and ||r||_W / ||r_0||_W where the recursion (re)started.
  bool preconditioned_ = false;
  Matrix preconditioned_residual_;
  double start_rho_ = 0.0, start_relative_ = 1.0;
  double rhs_norm_ = 0.0;
  StreamingCoupledProblem::StreamingTotals totals_;
  // Said in the message when the solve started from the warm start or switched to
  // checkpoints.
  std::string start_note_, switch_note_;
  // ||r_k||_W / ||r_0||_W: 1 at the data, less from a warm start that is kept, the
  // true one after a restart, then from the CG recursion (after q_k is formed).
  double relative_ = 1.0;
  double rho_ = 0.0;
  // beta_k, <p_{k-1}, -L p_{k-1}> and <p_k, p_{k-1}> of the recursion above.
  double direction_coefficient_ = 0.0, previous_direction_energy_ = 0.0;
  double consecutive_directions_ = 0.0;
  int restarts_ = 0, since_restart_ = 0, max_restarts_ = kMaxRestarts;
  // The true residual of the previous final pass (none yet: infinite).
  double previous_true_relative_ = std::numeric_limits<double>::infinity();
  // The Lanczos coefficients (step_k, rho_{k+1} / rho_k) before the first restart.
  ConjugateGradientLanczos lanczos_;
};

void StreamingConjugateGradient::Solve(const Matrix* initial_traces,
                                       double reference_residual_norm) {
  solution_->displacement.resize(0, 0);
  solution_->retrograde.resize(0, 0);
  summary_->iterations = 0;
  // ||r_0||_W given by a nearby problem: the warm start first, the data start only when
  // it is refused. Otherwise the data start first, the warm start measured against it.
  const bool given_reference = initial_traces != nullptr && reference_residual_norm > 0.0;
  WarmStartOutcome warm = WarmStartOutcome::kRefused;
  if (given_reference) {
    rhs_norm_ = reference_residual_norm;
    warm = TryWarmStart(*initial_traces);
  }
  if (warm == WarmStartOutcome::kRefused) {
    // y_0 = d~: r_0 = b - (I - L) d~ = Phi(d~) - d~.
    traces_ = problem_->DataTraces();
    problem_->StreamingMap(traces_, true, &residual_);
    residual_ -= traces_;
    rhs_norm_ = std::sqrt(std::max(problem_->RetrogradeEnergy(residual_), 0.0));
    if (rhs_norm_ == 0.0) {
      FinalPass(traces_);
      Accept("the data are matched exactly: Phi(d~) = d~");
      return;
    }
    if (initial_traces != nullptr && !given_reference) warm = TryWarmStart(*initial_traces);
  }
  if (warm == WarmStartOutcome::kAccepted) return;
  if (warm == WarmStartOutcome::kKept && given_reference) {
    start_note_ += ", measured against the given ||r_0||_W " + ScientificString(rhs_norm_);
  }
  preconditioned_ = options_.preconditioner == TracePreconditioner::kDenseTraces &&
                    problem_->PrepareTracePreconditioner(options_.preconditioner_rebuild_change,
                                                         options_.max_preconditioner_traces);
  if (preconditioned_) {
    start_note_ += "; preconditioned by I - L at moduli within " +
                   ScientificString(options_.preconditioner_rebuild_change);
  }
  StartRecursion();
  summary_->residual_history.push_back(relative_);
  summary_->relative_residual = relative_;
  for (int iteration = 0;; ++iteration, ++since_restart_) {
    summary_->iterations = iteration;
    if (InterruptRequested()) {
      summary_->termination = TerminationType::kFailure;
      summary_->message = kInterruptedMessage;
      return;
    }
    if (iteration == options_.max_iterations) {
      summary_->termination = TerminationType::kNoConvergence;
      summary_->message = "no convergence in " + std::to_string(iteration) +
                          " iterations: relative residual " + ScientificString(relative_);
      return;
    }
    // Preconditioned, ||r_k||_W is known before p_k is applied: y_k is checked first.
    if (preconditioned_ && relative_ <= options_.tolerance) {
      if (CheckTrueResidual()) return;
      continue;
    }
    double direction_energy = 0.0, curvature = 0.0;
    if (!ApplyToDirection(iteration, &direction_energy, &curvature)) return;
    if (!preconditioned_ && since_restart_ > 0 &&
        !UpdateRecursiveResidual(iteration, direction_energy)) {
      return;
    }
    // Progress of solves that take minutes (1e6 dofs): `identify run -v`.
    spdlog::debug("streaming CG: iteration {}, relative residual {:.3e}, {} sweeps so far",
                  iteration + 1, relative_, problem_->sweep_count());
    if (relative_ > options_.tolerance) {
      Step(direction_energy, curvature);
      continue;
    }
    if (CheckTrueResidual()) return;
  }
}

double StreamingConjugateGradient::ResidualPass(const Matrix& y, bool with_totals) {
  problem_->StreamingMap(y, true, &image_, with_totals ? &totals_ : nullptr);
  image_ -= y;
  return rhs_norm_ > 0.0 ? std::sqrt(std::max(problem_->RetrogradeEnergy(image_), 0.0)) / rhs_norm_
                         : 0.0;
}

void StreamingConjugateGradient::Accept(const std::string& message) {
  summary_->termination = TerminationType::kConvergence;
  summary_->message = message + "; rebuild error " + ScientificString(totals_.rebuild_error) +
                      start_note_ + switch_note_;
  solution_->cost = totals_.cost;
  solution_->cost_gradients = totals_.cost_gradients;
  solution_->cost_gradient = totals_.cost_gradients.sum();
  solution_->traces = traces_;
  solution_->load_retrograde = totals_.load_retrograde;
  solution_->error_map = totals_.error_map;
  solution_->element_error_map = totals_.element_error_map;
  solution_->element_sensitivity = totals_.element_sensitivity;
  solution_->zone_error_map = totals_.zone_error_map;
  solution_->zone_strain_energy = totals_.zone_strain_energy;
  solution_->gap_density = totals_.gap_density;
}

StreamingConjugateGradient::WarmStartOutcome StreamingConjugateGradient::TryWarmStart(
    const Matrix& initial_traces) {
  // r^(0) = Phi(y^(0)) - y^(0), into `image` until it is kept, without the totals: a
  // start within the tolerance takes them from one more application of the map.
  const double warm_relative = ResidualPass(initial_traces, false);
  spdlog::debug(
      "streaming CG: warm start's relative residual {:.3e} (the data's {:.3e}), {} sweeps",
      warm_relative, relative_, problem_->sweep_count());
  if (!(warm_relative < relative_)) return WarmStartOutcome::kRefused;
  traces_ = initial_traces;
  residual_.swap(image_);
  relative_ = warm_relative;
  start_note_ = "; from the warm start (relative residual " + ScientificString(warm_relative) + ")";
  if (relative_ > options_.tolerance) return WarmStartOutcome::kKept;
  // The totals of y^(0) and the rebuild's error; image_ is free (the residual is kept).
  problem_->StreamingMap(traces_, true, &image_, &totals_);
  if (totals_.rebuild_error <= options_.max_rebuild_error) {
    summary_->residual_history.push_back(relative_);
    summary_->relative_residual = relative_;
    Accept("relative residual " + ScientificString(relative_) + " <= tolerance " +
           ScientificString(options_.tolerance) + " at the start");
    return WarmStartOutcome::kAccepted;
  }
  return WarmStartOutcome::kKept;
}

bool StreamingConjugateGradient::ApplyToDirection(int iteration, double* direction_energy,
                                                  double* curvature) {
  // L p into image, then q = (I - L) p.
  problem_->StreamingMap(direction_, false, &image_);
  *direction_energy = -problem_->TraceInnerProduct(direction_, image_);
  image_ = direction_ - image_;
  *curvature = problem_->TraceInnerProduct(direction_, image_);
  if (!(*curvature > 0.0)) {
    summary_->termination = TerminationType::kFailure;
    summary_->message = "streaming conjugate gradients broke down: <p, (I - L) p> = " +
                        ScientificString(*curvature) + " at iteration " + std::to_string(iteration);
    return false;
  }
  return true;
}

void StreamingConjugateGradient::StartRecursion() {
  if (preconditioned_) problem_->PreconditionTraces(residual_, &preconditioned_residual_);
  const Matrix& preconditioned = preconditioned_ ? preconditioned_residual_ : residual_;
  direction_ = preconditioned;
  rho_ = problem_->TraceInnerProduct(residual_, preconditioned);
  start_rho_ = rho_;
  start_relative_ = relative_;
}

void StreamingConjugateGradient::UpdatePreconditionedResidual() {
  relative_ =
      start_rho_ > 0.0 ? start_relative_ * std::sqrt(std::max(rho_, 0.0) / start_rho_) : 0.0;
  if (relative_ <= kMeasuredResidualFactor * options_.tolerance &&
      relative_ > options_.tolerance / kMeasuredResidualFactor) {
    // ||r||_W^2 = ||R r||_P^2, R r the retrograde field driven by r.
    relative_ = std::sqrt(std::max(problem_->RetrogradeEnergy(residual_), 0.0)) / rhs_norm_;
  }
  summary_->residual_history.push_back(relative_);
  summary_->relative_residual = relative_;
}

bool StreamingConjugateGradient::UpdateRecursiveResidual(int iteration, double direction_energy) {
  // ||r_k||_W^2 = <p_k, -L p_k> + 2 beta_k <p_k, p_{k-1}> + beta_k^2 <p_{k-1}, -L p_{k-1}>.
  const double energy =
      direction_energy + 2.0 * direction_coefficient_ * consecutive_directions_ +
      direction_coefficient_ * direction_coefficient_ * previous_direction_energy_;
  relative_ = std::sqrt(std::max(energy, 0.0)) / rhs_norm_;
  if (!std::isfinite(relative_)) {
    summary_->termination = TerminationType::kFailure;
    summary_->message =
        "streaming conjugate gradients broke down: non-finite residual at iteration " +
        std::to_string(iteration);
    return false;
  }
  summary_->residual_history.push_back(relative_);
  summary_->relative_residual = relative_;
  return true;
}

void StreamingConjugateGradient::Step(double direction_energy, double curvature) {
  // y_{k+1} = y_k + a p_k, r_{k+1} = r_k - a q_k, a = <r_k, r_k> / <p_k, q_k>.
  const double step = rho_ / curvature;
  traces_ += step * direction_;
  residual_ -= step * image_;
  // z_{k+1} = M^-1 r_{k+1} (r_{k+1} without a preconditioner), rho = <r, z>,
  // p_{k+1} = z_{k+1} + beta p_k.
  if (preconditioned_) problem_->PreconditionTraces(residual_, &preconditioned_residual_);
  const Matrix& preconditioned = preconditioned_ ? preconditioned_residual_ : residual_;
  const double rho_next = problem_->TraceInnerProduct(residual_, preconditioned);
  direction_coefficient_ = rho_next / rho_;
  if (restarts_ == 0) lanczos_.Add(step, direction_coefficient_);
  if (!preconditioned_) {
    // <p_{k+1}, p_k> = <r_{k+1}, p_k> + beta_{k+1} <p_k, p_k>, for ||r||_W's recursion.
    consecutive_directions_ =
        problem_->TraceInnerProduct(residual_, direction_) +
        direction_coefficient_ * problem_->TraceInnerProduct(direction_, direction_);
    previous_direction_energy_ = direction_energy;
  }
  direction_ = preconditioned + direction_coefficient_ * direction_;
  rho_ = rho_next;
  if (preconditioned_) UpdatePreconditionedResidual();
}

bool StreamingConjugateGradient::CheckTrueResidual() {
  // Of y_k, not y_{k+1}: ||r_k||_W is not monotone, CG minimising another norm, and
  // r_{k+1} measured up to 1e4 times r_k.
  double true_relative = FinalPass(traces_);
  if (!(totals_.rebuild_error <= options_.max_rebuild_error)) {
    // The reversed recursion drifted (the stiff modes' round-off at a high Courant
    // number): W from checkpoints from now on, exact, and y's true residual measured
    // with that map; CG goes on from it with one more restart allowed.
    switch_note_ = "; W from checkpoints after the rebuilt field drifted by " +
                   ScientificString(totals_.rebuild_error) + " (limit " +
                   ScientificString(options_.max_rebuild_error) + ")";
    problem_->UseCheckpoints();
    true_relative = FinalPass(traces_);
    ++max_restarts_;
  }
  summary_->relative_residual = true_relative;
  if (true_relative <= options_.tolerance) {
    Accept("relative residual " + ScientificString(true_relative) + " <= tolerance " +
           ScientificString(options_.tolerance));
    return true;
  }
  if (restarts_ == max_restarts_) {
    StopAfterRestarts(true_relative);
    return true;
  }
  // Restart from the true residual: the recursive one drifted from it.
  previous_true_relative_ = true_relative;
  ++restarts_;
  since_restart_ = -1;
  residual_ = image_;
  relative_ = true_relative;
  StartRecursion();
  summary_->residual_history.push_back(relative_);
  return false;
}

void StreamingConjugateGradient::StopAfterRestarts(double true_relative) {
  // The rebuild's round-off is a floor under the true residual: Phi(y) ~ y is
  // known to about rebuild_error ||y|| (1.1e-8 measured on 1e5 elements at
  // Courant number 570, where a tolerance of 1e-8 cannot be met).
  const double traces_norm = std::sqrt(std::max(problem_->RetrogradeEnergy(traces_), 0.0));
  const double floor = kRoundOffFloorFactor * totals_.rebuild_error * traces_norm / rhs_norm_;
  if (true_relative <= floor) {
    summary_->at_round_off_floor = true;
    Accept("relative residual " + ScientificString(true_relative) + " at the round-off floor " +
           ScientificString(floor) + " of the rebuilt field (tolerance " +
           ScientificString(options_.tolerance) + ")");
    return;
  }
  // Data the model matches to within the tolerance of their own norm (noise-free data of
  // the model itself, at or near its moduli): the start's residual r_0 = Phi(d~) - d~ is
  // then at the sweeps' round-off, and no decrease relative to it can be measured.
  // Accepted when ||r_0||_W and ||r||_W are both within the tolerance of ||y||_W, y the
  // traces (about d~).
  if (std::max(rhs_norm_, true_relative * rhs_norm_) <= options_.tolerance * traces_norm) {
    Accept("the data are matched within the tolerance: the residual " +
           ScientificString(true_relative * rhs_norm_ / traces_norm) +
           " of the traces' norm (the start's was " + ScientificString(rhs_norm_ / traces_norm) +
           ", at the sweeps' round-off)");
    return;
  }
  if (true_relative > 0.1 * previous_true_relative_ &&
      true_relative <= kStalledResidualFactor * options_.tolerance) {
    summary_->at_round_off_floor = true;
    Accept("relative residual " + ScientificString(true_relative) +
           " at the round-off floor of the sweeps: the last restart left it at " +
           ScientificString(true_relative / previous_true_relative_) +
           " times the previous one (tolerance " + ScientificString(options_.tolerance) + ")");
    return;
  }
  summary_->termination = TerminationType::kNoConvergence;
  summary_->message = "the true residual " + ScientificString(true_relative) +
                      " misses the tolerance " + ScientificString(options_.tolerance) + " after " +
                      std::to_string(restarts_) + " restarts";
}

}  // namespace

void SolveByStreamingConjugateGradient(const CoupledSolverOptions& options,
                                       StreamingCoupledProblem* problem,
                                       const Matrix* initial_traces, double reference_residual_norm,
                                       CoupledSolution* solution, CoupledSolverSummary* summary) {
  assert(initial_traces == nullptr || (initial_traces->rows() == problem->num_traces() &&
                                       initial_traces->cols() == problem->num_steps() + 1));
  StreamingConjugateGradient solver(options, problem, solution, summary);
  solver.Solve(initial_traces, reference_residual_norm);
  summary->reference_residual_norm = solver.reference_residual_norm();
  solver.ReportSpectrum();
}

}  // namespace mcrewave::internal
