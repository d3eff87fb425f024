// The Ceres back end of Identify (identification.h).
#include <ceres/ceres.h>

#include <cmath>
#include <string>

#include "optim/identification_internal.h"

namespace mcrewave::internal {
namespace {

// The bounded map between Ceres' free parameter z and x = E / E_scale:
//   x(z) = x_lo + (x_hi - x_lo) s(sigma z),  s(y) = 1 / (1 + exp(-y)),
//   dx/dz = sigma (x_hi - x_lo) s (1 - s),
// smooth, increasing, and inside [x_lo, x_hi] for every z. The scale sigma sets
// the curvature of the cost in z: Ceres' first line-search step is
// -g min(1, 1 / |g|) in z, the Newton step -g / c'' when c'' = d^2 cost / dz^2 = 1,
// so sigma = 1 / (sqrt(k) dx/dz|_{sigma=1}) with k the curvature in x at the start
// makes the first step follow the curvature of e^2 instead of a unit step in z.
struct BoundedMap {
  double x_lower;
  double x_upper;
  double sigma = 1.0;

  double X(double z) const { return x_lower + (x_upper - x_lower) * Logistic(sigma * z); }
  double DxDz(double z) const {
    const double s = Logistic(sigma * z);
    return sigma * (x_upper - x_lower) * s * (1.0 - s);
  }
  // z(x) = log(s / (1 - s)) / sigma, s = (x - x_lo) / (x_hi - x_lo); x strictly inside.
  double Z(double x) const {
    const double s = (x - x_lower) / (x_upper - x_lower);
    return std::log(s / (1.0 - s)) / sigma;
  }
  // 1 / (1 + exp(-y)), written so that exp never overflows.
  static double Logistic(double y) {
    if (y >= 0.0) return 1.0 / (1.0 + std::exp(-y));
    const double e = std::exp(y);
    return e / (1.0 + e);
  }
};

// The objective in z for Ceres: cost(x(z)) and d cost/dz = (d cost/dx)(dx/dz).
class BoundedFirstOrderFunction : public ceres::FirstOrderFunction {
 public:
  BoundedFirstOrderFunction(GuardedObjective* objective, BoundedMap map)
      : objective_(objective), map_(map) {}

  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    const double z = parameters[0];
    double gradient_x = 0.0;
    if (!objective_->Evaluate(map_.X(z), cost, gradient != nullptr ? &gradient_x : nullptr)) {
      return false;
    }
    // d cost/dz = (d cost/dx)(dx/dz)
    if (gradient != nullptr) gradient[0] = gradient_x * map_.DxDz(z);
    return true;
  }
  int NumParameters() const override { return 1; }

 private:
  GuardedObjective* objective_;
  BoundedMap map_;
};

// Ends the run once an accepted step changes x by at most relative_tolerance |x|
// (the same test as NLopt's xtol_rel, on E rather than on z), and aborts it once
// the guarded objective has stopped (limit or failure).
class StoppingCallback : public ceres::IterationCallback {
 public:
  StoppingCallback(const double* z, BoundedMap map, double relative_tolerance,
                   const GuardedObjective* objective)
      : z_(z),
        map_(map),
        relative_tolerance_(relative_tolerance),
        objective_(objective),
        previous_x_(map.X(*z)) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (objective_->stop() != StopReason::kNone) return ceres::SOLVER_ABORT;
    const double x = map_.X(*z_);
    const bool small_step = summary.iteration > 0 && summary.step_is_valid &&
                            std::abs(x - previous_x_) <= relative_tolerance_ * std::abs(x);
    previous_x_ = x;
    return small_step ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  const double* z_;
  BoundedMap map_;
  double relative_tolerance_;
  const GuardedObjective* objective_;
  double previous_x_;
};

}  // namespace

void MinimizeWithCeres(const IdentificationOptions& options, GuardedObjective* objective,
                       double curvature, IdentificationSummary* summary) {
  const double scale = objective->modulus_scale();
  BoundedMap map{options.lower_bound / scale, options.upper_bound / scale};
  if (curvature > 0.0 && std::isfinite(curvature)) {
    // d^2 cost / dz^2 = k (dx/dz)^2 = 1 at the start (the term g d^2x/dz^2 left out).
    map.sigma = 1.0 / (std::sqrt(curvature) * map.DxDz(map.Z(options.initial / scale)));
  }
  double z = map.Z(options.initial / scale);

  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type =
      summary->algorithm == OuterAlgorithm::kBfgs ? ceres::BFGS : ceres::LBFGS;
  solver_options.line_search_type = ceres::WOLFE;
  solver_options.max_num_iterations = options.max_evaluations;
  solver_options.max_solver_time_in_seconds = options.max_time;
  // The step test on E is StoppingCallback's; Ceres' own tests are set to
  // round-off so that they only end a run that can make no more progress.
  solver_options.parameter_tolerance = 1e-15;
  solver_options.function_tolerance = 1e-15;
  solver_options.gradient_tolerance = 1e-20;
  solver_options.logging_type = ceres::SILENT;
  solver_options.update_state_every_iteration = true;
  StoppingCallback callback(&z, map, options.relative_tolerance, objective);
  solver_options.callbacks.push_back(&callback);

  ceres::GradientProblem problem(new BoundedFirstOrderFunction(objective, map));
  ceres::GradientProblemSolver::Summary ceres_summary;
  ceres::Solve(solver_options, problem, &z, &ceres_summary);

  summary->optimizer_message = ceres_summary.message;
  summary->iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  if (objective->stop() != StopReason::kNone) {
    objective->ReportStop(summary);
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

}  // namespace mcrewave::internal
