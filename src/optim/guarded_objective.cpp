#include "optim/guarded_objective.h"

#include <cmath>
#include <exception>
#include <sstream>
#include <utility>

#include "mcrewave/core/interrupt.h"

namespace mcrewave::internal {

GuardedObjective::GuardedObjective(FirstOrderObjective* objective, GuardLimits limits)
    : objective_(objective), limits_(std::move(limits)), start_(std::chrono::steady_clock::now()) {}

double GuardedObjective::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string GuardedObjective::LimitMessage(StopReason limit) const {
  std::ostringstream why;
  if (limit == StopReason::kEvaluationLimit) {
    why << limits_.section << ".max_evaluations (" << limits_.max_evaluations
        << ") reached before convergence";
  } else {
    why << limits_.section << ".max_time (" << limits_.max_time << " s) reached before convergence";
  }
  return why.str();
}

TerminationType GuardedObjective::StopTermination() const {
  return stop_ == StopReason::kFailure ? TerminationType::kFailure
                                       : TerminationType::kNoConvergence;
}

void GuardedObjective::Stop(StopReason reason, std::string message) {
  stop_ = reason;
  stop_message_ = std::move(message);
}

bool GuardedObjective::Evaluate(const double* x, double* cost, double* gradient) {
  if (stop_ != StopReason::kNone) return false;
  if (InterruptRequested()) {
    Stop(StopReason::kFailure, kInterruptedMessage);
    return false;
  }
  if (evaluations_ >= limits_.max_evaluations) {
    Stop(StopReason::kEvaluationLimit, LimitMessage(StopReason::kEvaluationLimit));
    return false;
  }
  if (ElapsedSeconds() >= limits_.max_time) {
    Stop(StopReason::kTimeLimit, LimitMessage(StopReason::kTimeLimit));
    return false;
  }
  ++evaluations_;
  if (gradient != nullptr) ++gradient_evaluations_;
  const int n = objective_->num_parameters();
  std::string failure;
  try {
    if (!objective_->Evaluate(x, cost, gradient)) {
      failure = objective_->error_message();
      if (failure.empty()) failure = "the objective failed without giving a reason";
    } else if (!std::isfinite(*cost)) {
      failure = "the objective returned a non-finite cost";
    } else {
      for (int i = 0; gradient != nullptr && i < n && failure.empty(); ++i) {
        if (!std::isfinite(gradient[i])) failure = "the objective returned a non-finite gradient";
      }
    }
  } catch (const std::exception& error) {
    failure = std::string("the objective threw: ") + error.what();
  } catch (...) {
    failure = "the objective threw an exception that is not a std::exception";
  }
  if (!failure.empty()) {
    Stop(StopReason::kFailure, std::move(failure));
    if (observer_) observer_(*this, x, nullptr, nullptr);
    return false;
  }
  if (!has_best()) initial_cost_ = *cost;
  if (!has_best() || *cost < best_cost_) {
    best_x_.assign(x, x + n);
    best_cost_ = *cost;
    if (gradient != nullptr) {
      best_gradient_.assign(gradient, gradient + n);
    } else {
      best_gradient_.clear();
    }
  }
  if (observer_) observer_(*this, x, cost, gradient);
  // What the optimiser sees: cost / cost_scale_ (see set_cost_scale).
  *cost /= cost_scale_;
  for (int i = 0; gradient != nullptr && i < n; ++i) gradient[i] /= cost_scale_;
  return true;
}

}  // namespace mcrewave::internal
