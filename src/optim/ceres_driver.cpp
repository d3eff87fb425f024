#include "optim/ceres_driver.h"

#include <algorithm>
#include <cmath>

namespace mcrewave::internal {
namespace {

// The objective in z: cost(x(z)) and d cost / dz_i = (d cost / dx_i)(dx_i / dz_i).
class MappedFunction : public ceres::FirstOrderFunction {
 public:
  MappedFunction(GuardedObjective* guard, const BoundMap* map)
      : guard_(guard), map_(map), x_(guard->num_parameters()), gradient_x_(x_.size()) {}

  bool Evaluate(const double* z, double* cost, double* gradient) const override {
    const int n = NumParameters();
    for (int i = 0; i < n; ++i) x_[i] = map_->X(i, z[i]);
    if (!guard_->Evaluate(x_.data(), cost, gradient != nullptr ? gradient_x_.data() : nullptr)) {
      return false;
    }
    // d cost / dz_i = (d cost / dx_i)(dx_i / dz_i)
    for (int i = 0; gradient != nullptr && i < n; ++i) {
      gradient[i] = gradient_x_[i] * map_->DxDz(i, z[i]);
    }
    return true;
  }
  int NumParameters() const override { return static_cast<int>(x_.size()); }

 private:
  GuardedObjective* guard_;
  const BoundMap* map_;
  mutable std::vector<double> x_, gradient_x_;
};

// Ends the run once an accepted step changes every x_i by at most
// step_absolute + step_relative |x_i|; aborts it once the guard has stopped.
class StepCallback : public ceres::IterationCallback {
 public:
  StepCallback(const std::vector<double>* z, const BoundMap* map, const CeresSettings* settings,
               const GuardedObjective* guard)
      : z_(z), map_(map), settings_(settings), guard_(guard), previous_(z->size()) {
    for (std::size_t i = 0; i < z->size(); ++i) previous_[i] = X(i);
  }

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (guard_->stop() != StopReason::kNone) return ceres::SOLVER_ABORT;
    bool small = true;
    for (std::size_t i = 0; i < z_->size(); ++i) {
      const double x = X(i);
      small = small && std::abs(x - previous_[i]) <=
                           settings_->step_absolute + settings_->step_relative * std::abs(x);
      previous_[i] = x;
    }
    return summary.iteration > 0 && summary.step_is_valid && small
               ? ceres::SOLVER_TERMINATE_SUCCESSFULLY
               : ceres::SOLVER_CONTINUE;
  }

 private:
  double X(std::size_t i) const { return map_->X(static_cast<int>(i), (*z_)[i]); }

  const std::vector<double>* z_;
  const BoundMap* map_;
  const CeresSettings* settings_;
  const GuardedObjective* guard_;
  std::vector<double> previous_;
};

}  // namespace

OptimizerOutcome RunCeres(const BoundMap& map, const CeresSettings& settings,
                          GuardedObjective* guard, std::vector<double>* z) {
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = settings.direction;
  options.line_search_type = ceres::WOLFE;
  options.max_lbfgs_rank = settings.max_lbfgs_rank;
  options.max_num_iterations = settings.max_iterations;
  options.max_solver_time_in_seconds = settings.max_time;
  // The step test is StepCallback's; Ceres' own are set to round-off.
  options.parameter_tolerance = 1e-15;
  options.function_tolerance = settings.function_tolerance;
  options.gradient_tolerance = 1e-20;
  options.logging_type = ceres::SILENT;
  options.update_state_every_iteration = true;
  StepCallback callback(z, &map, &settings, guard);
  options.callbacks.push_back(&callback);

  ceres::GradientProblem problem(new MappedFunction(guard, &map));
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(options, problem, z->data(), &summary);

  OptimizerOutcome outcome;
  outcome.optimizer_message = summary.message;
  outcome.iterations = static_cast<int>(summary.iterations.size()) - 1;
  if (guard->stop() != StopReason::kNone) {
    outcome.termination = guard->StopTermination();
    outcome.message = guard->stop_message();
    return outcome;
  }
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
    case ceres::USER_SUCCESS:
      outcome.termination = TerminationType::kConvergence;
      outcome.message = "converged (Ceres: " + summary.message + ")";
      break;
    case ceres::NO_CONVERGENCE:
      outcome.termination = TerminationType::kNoConvergence;
      outcome.message = "Ceres stopped before convergence: " + summary.message;
      break;
    default:
      outcome.termination = TerminationType::kFailure;
      outcome.message = "Ceres failed: " + summary.message;
      break;
  }
  return outcome;
}

}  // namespace mcrewave::internal
