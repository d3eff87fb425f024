#include "mcrewave/optim/bounded_minimizer.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <new>
#include <nlopt.hpp>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/enum_names.h"
#include "optim/nlopt_results.h"

namespace mcrewave {
namespace {

enum class StopReason { kNone, kEvaluationLimit, kTimeLimit, kFailure };

// The objective as the optimisers must see it: counted, limited, exceptions caught
// (message kept), non-finite costs refused, the best point remembered. Once stopped,
// every later call returns false without evaluating.
class Guard {
 public:
  Guard(const BoundedMinimizerOptions& options, MultiParameterObjective* objective)
      : options_(options), objective_(objective), start_(std::chrono::steady_clock::now()) {}

  bool Evaluate(const double* x, double* cost, double* gradient) {
    if (stop_ != StopReason::kNone) return false;
    if (evaluations_ >= options_.max_evaluations) {
      Stop(StopReason::kEvaluationLimit, "zone_identification.max_evaluations (" +
                                             std::to_string(options_.max_evaluations) +
                                             ") reached before convergence");
      return false;
    }
    if (ElapsedSeconds() > options_.max_time) {
      Stop(StopReason::kTimeLimit, "zone_identification.max_time reached before convergence");
      return false;
    }
    ++evaluations_;
    if (gradient != nullptr) ++gradient_evaluations_;
    const int n = objective_->num_parameters();
    bool ok = false;
    try {
      ok = objective_->Evaluate(x, cost, gradient);
      if (!ok) {
        const std::string why = objective_->error_message();
        Stop(StopReason::kFailure,
             "the objective failed: " + (why.empty() ? std::string("no reason given") : why));
        return false;
      }
    } catch (const std::exception& error) {
      Stop(StopReason::kFailure, std::string("the objective threw: ") + error.what());
      return false;
    } catch (...) {
      Stop(StopReason::kFailure, "the objective threw an unknown exception");
      return false;
    }
    bool finite = std::isfinite(*cost);
    for (int i = 0; gradient != nullptr && i < n; ++i)
      finite = finite && std::isfinite(gradient[i]);
    if (!finite) {
      Stop(StopReason::kFailure, "the objective returned a non-finite cost or gradient");
      return false;
    }
    if (evaluations_ == 1) initial_cost_ = *cost;
    if (best_.empty() || *cost < best_cost_) {
      best_.assign(x, x + n);
      best_cost_ = *cost;
    }
    // What the optimiser sees: cost / cost_scale_ (see set_cost_scale).
    *cost /= cost_scale_;
    for (int i = 0; gradient != nullptr && i < n; ++i) gradient[i] /= cost_scale_;
    return true;
  }

  // From now on the optimiser sees cost / scale and gradient / scale (the summary
  // keeps the objective's own cost). Precondition: scale > 0.
  void set_cost_scale(double scale) { cost_scale_ = scale; }

  double ElapsedSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  StopReason stop() const { return stop_; }
  // A point of lower cost than the first evaluation's was found.
  bool improved() const { return !best_.empty() && best_cost_ < initial_cost_; }

  // The termination the stop calls for: limits kNoConvergence, failures kFailure.
  void ReportStop(BoundedMinimizerSummary* summary) const {
    summary->termination =
        stop_ == StopReason::kFailure ? TerminationType::kFailure : TerminationType::kNoConvergence;
    summary->message = stop_message_;
  }
  void FillSummary(BoundedMinimizerSummary* summary) const {
    summary->x = best_;
    summary->cost = best_.empty() ? std::numeric_limits<double>::quiet_NaN() : best_cost_;
    summary->initial_cost = initial_cost_;
    summary->evaluations = evaluations_;
    summary->gradient_evaluations = gradient_evaluations_;
    summary->wall_time_s = ElapsedSeconds();
    // A converged run without a usable point is not usable.
    if (best_.empty() && summary->termination == TerminationType::kConvergence) {
      summary->termination = TerminationType::kFailure;
      summary->message = "no usable evaluation";
    }
  }

 private:
  void Stop(StopReason reason, std::string message) {
    stop_ = reason;
    stop_message_ = std::move(message);
  }

  const BoundedMinimizerOptions& options_;
  MultiParameterObjective* objective_;
  std::chrono::steady_clock::time_point start_;
  StopReason stop_ = StopReason::kNone;
  std::string stop_message_;
  int evaluations_ = 0;
  int gradient_evaluations_ = 0;
  std::vector<double> best_;
  double best_cost_ = 0.0;
  double initial_cost_ = std::numeric_limits<double>::quiet_NaN();
  double cost_scale_ = 1.0;
};

// ---------------------------------------------------------------------------- NLopt

struct NloptData {
  Guard* guard;
  nlopt::opt* optimizer;
};

// Never throws (Guard catches): a refused evaluation force-stops NLopt and returns
// +HUGE_VAL, which no algorithm takes for a best point.
double NloptCost(const std::vector<double>& x, std::vector<double>& gradient, void* data) {
  auto* d = static_cast<NloptData*>(data);
  double cost = HUGE_VAL;
  double* g = gradient.empty() ? nullptr : gradient.data();
  if (!d->guard->Evaluate(x.data(), &cost, g)) {
    d->optimizer->force_stop();
    if (g != nullptr) std::fill(gradient.begin(), gradient.end(), 0.0);
    return HUGE_VAL;
  }
  return cost;
}

nlopt::algorithm NloptAlgorithm(BoundedAlgorithm algorithm) {
  switch (algorithm) {
    case BoundedAlgorithm::kNloptMma:
      return nlopt::LD_MMA;
    case BoundedAlgorithm::kNloptSlsqp:
      return nlopt::LD_SLSQP;
    case BoundedAlgorithm::kNloptBobyqa:
      return nlopt::LN_BOBYQA;
    default:
      return nlopt::LD_LBFGS;
  }
}

void RunNlopt(const BoundedMinimizerOptions& options, const std::vector<double>& lower,
              const std::vector<double>& upper, std::vector<double> x, Guard* guard,
              BoundedMinimizerSummary* summary) {
  const unsigned n = static_cast<unsigned>(x.size());
  nlopt::opt optimizer(NloptAlgorithm(options.algorithm), n);
  NloptData data{guard, &optimizer};
  optimizer.set_min_objective(NloptCost, &data);
  optimizer.set_lower_bounds(lower);
  optimizer.set_upper_bounds(upper);
  optimizer.set_xtol_abs(options.step_tolerance);
  if (options.function_tolerance > 0.0) optimizer.set_ftol_rel(options.function_tolerance);
  // One more than the guard's limit, so that the guard (with its message) ends the run.
  optimizer.set_maxeval(options.max_evaluations + 1);
  optimizer.set_maxtime(options.max_time);
  if (options.algorithm == BoundedAlgorithm::kNloptBobyqa) {
    // First trust region: a tenth of each width (NLopt's default can be half of it).
    std::vector<double> step(n);
    for (unsigned i = 0; i < n; ++i) step[i] = 0.1 * (upper[i] - lower[i]);
    optimizer.set_initial_step(step);
  }
  double cost = HUGE_VAL;
  try {
    const nlopt::result result = optimizer.optimize(x, cost);
    summary->optimizer_message = internal::NloptResultName(result);
    if (result == nlopt::MAXEVAL_REACHED || result == nlopt::MAXTIME_REACHED) {
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "NLopt stopped before convergence (" + summary->optimizer_message + ")";
    } else {
      summary->termination = TerminationType::kConvergence;
      summary->message = "converged (NLopt: " + summary->optimizer_message + ")";
    }
  } catch (const nlopt::roundoff_limited&) {
    summary->optimizer_message = "roundoff limited";
    summary->termination = TerminationType::kConvergence;
    summary->message = "converged to round-off (NLopt: roundoff limited)";
  } catch (const nlopt::forced_stop&) {
    summary->optimizer_message = "forced stop";
    summary->termination = TerminationType::kFailure;
    summary->message = "NLopt was force-stopped for no reason the objective knows";
  } catch (const std::bad_alloc&) {
    summary->optimizer_message = "out of memory";
    summary->termination = TerminationType::kFailure;
    summary->message = "NLopt ran out of memory";
  } catch (const std::exception& error) {
    summary->optimizer_message = error.what();
    if (internal::IsLineSearchStallAfterProgress(error, UsesGradient(options.algorithm),
                                                 guard->improved(),
                                                 guard->stop() != StopReason::kNone)) {
      summary->termination = TerminationType::kConvergence;
      summary->message = internal::kLineSearchStallMessage;
    } else {
      summary->termination = TerminationType::kFailure;
      summary->message = std::string("NLopt failed: ") + error.what();
    }
  }
  if (guard->stop() != StopReason::kNone) guard->ReportStop(summary);
}

// ---------------------------------------------------------------------------- Ceres

// x_i = lo_i + (hi_i - lo_i) (1 + sin y_i) / 2, dx_i/dy_i = (hi_i - lo_i) cos(y_i) / 2.
struct SineMap {
  std::vector<double> lower, upper;

  double X(int i, double y) const {
    const double x = lower[i] + (upper[i] - lower[i]) * 0.5 * (1.0 + std::sin(y));
    return std::clamp(x, lower[i], upper[i]);
  }
  double DxDy(int i, double y) const { return 0.5 * (upper[i] - lower[i]) * std::cos(y); }
  // y in [-pi/2, pi/2] for x strictly inside.
  double Y(int i, double x) const {
    const double s = 2.0 * (x - lower[i]) / (upper[i] - lower[i]) - 1.0;
    return std::asin(std::clamp(s, -1.0, 1.0));
  }
};

class SineFunction : public ceres::FirstOrderFunction {
 public:
  SineFunction(Guard* guard, const SineMap* map, int n)
      : guard_(guard), map_(map), n_(n), x_(n), gradient_x_(n) {}

  bool Evaluate(const double* y, double* cost, double* gradient) const override {
    for (int i = 0; i < n_; ++i) x_[i] = map_->X(i, y[i]);
    if (!guard_->Evaluate(x_.data(), cost, gradient != nullptr ? gradient_x_.data() : nullptr)) {
      return false;
    }
    // d cost / dy_i = (d cost / dx_i)(dx_i / dy_i)
    for (int i = 0; gradient != nullptr && i < n_; ++i) {
      gradient[i] = gradient_x_[i] * map_->DxDy(i, y[i]);
    }
    return true;
  }
  int NumParameters() const override { return n_; }

 private:
  Guard* guard_;
  const SineMap* map_;
  int n_;
  mutable std::vector<double> x_, gradient_x_;
};

// Ends the run once an accepted step changes every x_i by at most step_tolerance;
// aborts once the guard has stopped.
class StepCallback : public ceres::IterationCallback {
 public:
  StepCallback(const std::vector<double>* y, const SineMap* map, double tolerance,
               const Guard* guard)
      : y_(y), map_(map), tolerance_(tolerance), guard_(guard), previous_(y->size()) {
    for (std::size_t i = 0; i < y->size(); ++i) previous_[i] = map->X(static_cast<int>(i), (*y)[i]);
  }

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (guard_->stop() != StopReason::kNone) return ceres::SOLVER_ABORT;
    double largest = 0.0;
    for (std::size_t i = 0; i < y_->size(); ++i) {
      const double x = map_->X(static_cast<int>(i), (*y_)[i]);
      largest = std::max(largest, std::abs(x - previous_[i]));
      previous_[i] = x;
    }
    const bool small = summary.iteration > 0 && summary.step_is_valid && largest <= tolerance_;
    return small ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const std::vector<double>* y_;
  const SineMap* map_;
  double tolerance_;
  const Guard* guard_;
  std::vector<double> previous_;
};

void RunCeres(const BoundedMinimizerOptions& options, const std::vector<double>& lower,
              const std::vector<double>& upper, const std::vector<double>& x0, Guard* guard,
              BoundedMinimizerSummary* summary) {
  const int n = static_cast<int>(x0.size());
  const SineMap map{lower, upper};
  std::vector<double> y(n);
  for (int i = 0; i < n; ++i) {
    // Strictly inside: a bound is a stationary point in y.
    const double margin = 1e-6 * (upper[i] - lower[i]);
    y[i] = map.Y(i, std::clamp(x0[i], lower[i] + margin, upper[i] - margin));
  }
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  solver_options.line_search_type = ceres::WOLFE;
  // Ceres' default rank 20 starves the many weakly determined parameters of one zone
  // per element: 677 evaluations for the last weight of the 100-zone paper bar
  // (noise-free) against 66 with a rank of 100; the rank does not matter for 10 zones.
  solver_options.max_lbfgs_rank = 100;
  solver_options.max_num_iterations = options.max_evaluations;
  solver_options.max_solver_time_in_seconds = options.max_time;
  solver_options.parameter_tolerance = 1e-15;
  solver_options.function_tolerance =
      options.function_tolerance > 0.0 ? options.function_tolerance : 1e-15;
  solver_options.gradient_tolerance = 1e-20;
  solver_options.logging_type = ceres::SILENT;
  solver_options.update_state_every_iteration = true;
  StepCallback callback(&y, &map, options.step_tolerance, guard);
  solver_options.callbacks.push_back(&callback);

  ceres::GradientProblem problem(new SineFunction(guard, &map, n));
  ceres::GradientProblemSolver::Summary ceres_summary;
  ceres::Solve(solver_options, problem, y.data(), &ceres_summary);

  summary->optimizer_message = ceres_summary.message;
  summary->iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  if (guard->stop() != StopReason::kNone) {
    guard->ReportStop(summary);
    return;
  }
  switch (ceres_summary.termination_type) {
    case ceres::CONVERGENCE:
    case ceres::USER_SUCCESS:
      summary->termination = TerminationType::kConvergence;
      summary->message = "converged (Ceres: " + ceres_summary.message + ")";
      break;
    case ceres::NO_CONVERGENCE:
      summary->termination = TerminationType::kNoConvergence;
      summary->message = "Ceres stopped before convergence: " + ceres_summary.message;
      break;
    default:
      summary->termination = TerminationType::kFailure;
      summary->message = "Ceres failed: " + ceres_summary.message;
      break;
  }
}

}  // namespace

bool UsesGradient(BoundedAlgorithm algorithm) {
  return algorithm != BoundedAlgorithm::kNloptBobyqa;
}

bool BoundedMinimizerOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(step_tolerance > 0.0 && step_tolerance < 0.1)) {
    why << "zone_identification.step_tolerance must lie in (0, 0.1), got " << step_tolerance;
  } else if (!(function_tolerance >= 0.0 && function_tolerance < 0.1)) {
    why << "zone_identification.function_tolerance must lie in [0, 0.1), got "
        << function_tolerance;
  } else if (max_evaluations < 2) {
    why << "zone_identification.max_evaluations must be at least 2, got " << max_evaluations;
  } else if (!(max_time > 0.0 && std::isfinite(max_time))) {
    why << "zone_identification.max_time must be a positive number of seconds, got " << max_time;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

std::string BoundedMinimizerSummary::BriefReport() const {
  std::ostringstream out;
  out << BoundedAlgorithmToString(algorithm) << ": " << TerminationTypeToString(termination)
      << ", cost " << cost << " (from " << initial_cost << "), " << evaluations << " evaluations, "
      << wall_time_s << " s";
  return out.str();
}

std::string BoundedMinimizerSummary::FullReport() const {
  std::ostringstream out;
  out << "Bounded minimisation (" << BoundedAlgorithmToString(algorithm) << ")\n"
      << "  termination:          " << TerminationTypeToString(termination) << "\n"
      << "  message:              " << message << "\n"
      << "  optimizer message:    " << optimizer_message << "\n"
      << "  parameters:           " << x.size() << "\n"
      << "  initial cost:         " << initial_cost << "\n"
      << "  final cost:           " << cost << "\n"
      << "  evaluations:          " << evaluations << " (" << gradient_evaluations
      << " with gradient)\n"
      << "  iterations:           " << iterations << "\n"
      << "  wall time:            " << wall_time_s << " s\n";
  return out.str();
}

BoundedMinimizerSummary MinimizeWithinBounds(const BoundedMinimizerOptions& options,
                                             MultiParameterObjective* objective,
                                             const std::vector<double>& lower,
                                             const std::vector<double>& upper,
                                             const std::vector<double>& initial) {
  BoundedMinimizerSummary summary;
  summary.algorithm = options.algorithm;
  const std::size_t n = initial.size();
  summary.initial.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    summary.initial[i] = std::clamp(initial[i], lower[i], upper[i]);
  }
  Guard guard(options, objective);
  // The optimisers see the cost relative to its value at the start: their internal
  // tests (NLopt L-BFGS's gradient test, Ceres' line search) assume a cost of order
  // one, while e^2 / J_rest of nearly consistent data starts at 1e-6 or less.
  double start_cost = 0.0;
  std::vector<double> start_gradient(n);
  if (guard.Evaluate(summary.initial.data(), &start_cost,
                     UsesGradient(options.algorithm) ? start_gradient.data() : nullptr)) {
    if (std::isfinite(start_cost) && std::abs(start_cost) > 0.0) {
      guard.set_cost_scale(std::abs(start_cost));
    }
  } else {
    guard.ReportStop(&summary);
    guard.FillSummary(&summary);
    return summary;
  }
  if (options.algorithm == BoundedAlgorithm::kCeresLbfgs) {
    RunCeres(options, lower, upper, summary.initial, &guard, &summary);
  } else {
    RunNlopt(options, lower, upper, summary.initial, &guard, &summary);
  }
  guard.FillSummary(&summary);
  return summary;
}

}  // namespace mcrewave
