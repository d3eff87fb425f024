// The NLopt back end of Identify (identification.h): the scalar loop's settings of the
// one NLopt driver (nlopt_driver.h).
#include <cmath>
#include <vector>

#include "mcrewave/optim/algorithms.h"
#include "optim/identification_internal.h"
#include "optim/nlopt_driver.h"

namespace mcrewave::internal {

void MinimizeWithNlopt(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, double curvature, IdentificationSummary* summary) {
  nlopt::opt optimizer(NloptAlgorithm(summary->algorithm), 1);
  const bool gradient_based = UsesGradient(options.optimizer, summary->algorithm, 1);
  // The gradient methods (MMA's convexity term, L-BFGS' first step) assume cost
  // changes of order one across the bounds; a flat e^2 stops MMA at its start. Their
  // cost unit is the change the curvature k predicts over the bounds' width w: k w^2.
  const double width = (options.upper_bound - options.lower_bound) / modulus_scale;
  const double predicted_change = curvature * width * width;
  if (gradient_based && predicted_change > 0.0 && std::isfinite(predicted_change)) {
    objective->set_cost_scale(predicted_change);
  }
  optimizer.set_lower_bounds(options.lower_bound / modulus_scale);
  optimizer.set_upper_bounds(options.upper_bound / modulus_scale);
  optimizer.set_xtol_rel(options.relative_tolerance);
  optimizer.set_maxeval(options.max_evaluations);
  optimizer.set_maxtime(options.max_time);
  std::vector<double> x{options.initial / modulus_scale};
  const OptimizerOutcome outcome = RunNlopt(&optimizer, objective, &x, gradient_based);
  summary->termination = outcome.termination;
  summary->message = outcome.message;
  summary->optimizer_message = outcome.optimizer_message;
}

}  // namespace mcrewave::internal
