#include "mcrewave/optim/bounded_minimizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

#include "mcrewave/core/format.h"
#include "mcrewave/optim/algorithms.h"
#include "optim/ceres_driver.h"
#include "optim/guarded_objective.h"
#include "optim/nlopt_driver.h"

namespace mcrewave {
namespace {

using internal::GuardedObjective;
using internal::OptimizerOutcome;

// Any number of parameters above one: every algorithm but brent, Identify's alone.
constexpr int kManyParameters = 2;

OptimizerOutcome RunNlopt(const BoundedMinimizerOptions& options, OuterAlgorithm algorithm,
                          const std::vector<double>& lower, const std::vector<double>& upper,
                          std::vector<double> x, GuardedObjective* guard) {
  const unsigned n = static_cast<unsigned>(x.size());
  nlopt::opt optimizer(internal::NloptAlgorithm(algorithm), n);
  optimizer.set_lower_bounds(lower);
  optimizer.set_upper_bounds(upper);
  optimizer.set_xtol_abs(options.step_tolerance);
  if (options.function_tolerance > 0.0) optimizer.set_ftol_rel(options.function_tolerance);
  // One more than the guard's limit, so that the guard (with its message) ends the run.
  optimizer.set_maxeval(options.max_evaluations + 1);
  optimizer.set_maxtime(options.max_time);
  if (algorithm == OuterAlgorithm::kBobyqa) {
    // First trust region: a tenth of each width (NLopt's default can be half of it).
    std::vector<double> step(n);
    for (unsigned i = 0; i < n; ++i) step[i] = 0.1 * (upper[i] - lower[i]);
    optimizer.set_initial_step(step);
  }
  return internal::RunNlopt(&optimizer, guard, &x,
                            UsesGradient(options.optimizer, algorithm, kManyParameters));
}

// x_i = lo_i + (hi_i - lo_i) (1 + sin y_i) / 2, dx_i/dy_i = (hi_i - lo_i) cos(y_i) / 2.
class SineMap : public internal::BoundMap {
 public:
  SineMap(const std::vector<double>& lower, const std::vector<double>& upper)
      : lower_(lower), upper_(upper) {}

  double X(int i, double y) const override {
    const double x = lower_[i] + (upper_[i] - lower_[i]) * 0.5 * (1.0 + std::sin(y));
    return std::clamp(x, lower_[i], upper_[i]);
  }
  double DxDz(int i, double y) const override {
    return 0.5 * (upper_[i] - lower_[i]) * std::cos(y);
  }
  // y in [-pi/2, pi/2] for x strictly inside.
  double Y(int i, double x) const {
    const double s = 2.0 * (x - lower_[i]) / (upper_[i] - lower_[i]) - 1.0;
    return std::asin(std::clamp(s, -1.0, 1.0));
  }

 private:
  const std::vector<double>& lower_;
  const std::vector<double>& upper_;
};

OptimizerOutcome RunCeres(const BoundedMinimizerOptions& options, OuterAlgorithm algorithm,
                          const std::vector<double>& lower, const std::vector<double>& upper,
                          const std::vector<double>& x0, GuardedObjective* guard) {
  const int n = static_cast<int>(x0.size());
  const SineMap map(lower, upper);
  std::vector<double> y(n);
  for (int i = 0; i < n; ++i) {
    // Strictly inside: a bound is a stationary point in y.
    const double margin = 1e-6 * (upper[i] - lower[i]);
    y[i] = map.Y(i, std::clamp(x0[i], lower[i] + margin, upper[i] - margin));
  }
  internal::CeresSettings settings;
  settings.direction = algorithm == OuterAlgorithm::kBfgs ? ceres::BFGS : ceres::LBFGS;
  // Ceres' default rank 20 starves the many weakly determined parameters of one zone
  // per element (docs/zones_and_sensors.md, "Optimisers").
  settings.max_lbfgs_rank = 100;
  settings.max_iterations = options.max_evaluations;
  settings.max_time = options.max_time;
  if (options.function_tolerance > 0.0) settings.function_tolerance = options.function_tolerance;
  settings.step_absolute = options.step_tolerance;
  return internal::RunCeres(map, settings, guard, &y);
}

}  // namespace

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
  } else if (!IsAlgorithmAvailable(optimizer, algorithm, kManyParameters)) {
    why << "zone_identification.algorithm '" << OuterAlgorithmToString(algorithm)
        << "' is not available with zone_identification.optimizer '"
        << OptimizerTypeToString(optimizer) << "'; choose "
        << AvailableAlgorithms(optimizer, kManyParameters);
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

std::string BoundedMinimizerSummary::BriefReport() const {
  std::ostringstream out;
  out << OptimizerTypeToString(optimizer) << " " << OuterAlgorithmToString(algorithm) << ": "
      << TerminationTypeToString(termination) << ", cost " << cost << " (from " << initial_cost
      << "), " << evaluations << " evaluations, " << wall_time_s << " s";
  return out.str();
}

std::string BoundedMinimizerSummary::FullReport() const {
  std::ostringstream out;
  out << "Bounded minimisation (" << OptimizerTypeToString(optimizer) << " "
      << OuterAlgorithmToString(algorithm) << ")\n"
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
                                             FirstOrderObjective* objective,
                                             const std::vector<double>& lower,
                                             const std::vector<double>& upper,
                                             const std::vector<double>& initial) {
  BoundedMinimizerSummary summary;
  summary.optimizer = options.optimizer;
  summary.algorithm = ResolveAlgorithm(options.optimizer, options.algorithm, kManyParameters);
  const std::size_t n = initial.size();
  summary.initial.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    summary.initial[i] = std::clamp(initial[i], lower[i], upper[i]);
  }
  GuardedObjective guard(objective,
                         {options.max_evaluations, options.max_time, "zone_identification"});
  // The optimisers see the cost relative to its value at the start: their internal
  // tests (NLopt L-BFGS's gradient test, Ceres' line search) assume a cost of order
  // one, while e^2 / J_rest of nearly consistent data starts at 1e-6 or less.
  double start_cost = 0.0;
  std::vector<double> start_gradient(n);
  const bool gradient_based = UsesGradient(options.optimizer, summary.algorithm, kManyParameters);
  OptimizerOutcome outcome;
  if (!guard.Evaluate(summary.initial.data(), &start_cost,
                      gradient_based ? start_gradient.data() : nullptr)) {
    outcome.termination = guard.StopTermination();
    outcome.message = guard.stop_message();
  } else if (options.matched_cost > 0.0 && start_cost <= options.matched_cost) {
    // Scaled by a cost at the round-off the optimisers' steps would be noise.
    outcome.termination = TerminationType::kConvergence;
    outcome.message = "the start is a minimum: its cost " +
                      FormatNumber(start_cost, kScientificThreeDecimals) + " is at most " +
                      FormatNumber(options.matched_cost, kScientificThreeDecimals) +
                      " (the data matched to round-off)";
  } else {
    if (std::abs(start_cost) > 0.0) guard.set_cost_scale(std::abs(start_cost));
    outcome = options.optimizer == OptimizerType::kCeres
                  ? RunCeres(options, summary.algorithm, lower, upper, summary.initial, &guard)
                  : RunNlopt(options, summary.algorithm, lower, upper, summary.initial, &guard);
  }
  summary.termination = outcome.termination;
  summary.message = outcome.message;
  summary.optimizer_message = outcome.optimizer_message;
  summary.iterations = outcome.iterations;
  summary.x = guard.best_x();
  summary.cost = guard.has_best() ? guard.best_cost() : std::numeric_limits<double>::quiet_NaN();
  summary.initial_cost = guard.initial_cost();
  summary.evaluations = guard.evaluations();
  summary.gradient_evaluations = guard.gradient_evaluations();
  summary.wall_time_s = guard.ElapsedSeconds();
  // A converged run without a usable point is not usable.
  if (!guard.has_best() && summary.termination == TerminationType::kConvergence) {
    summary.termination = TerminationType::kFailure;
    summary.message = "no usable evaluation";
  }
  return summary;
}

}  // namespace mcrewave
