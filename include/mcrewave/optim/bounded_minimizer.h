// Minimisation of a function of several parameters within bounds: the outer loop of
// the identification of zone moduli (identification/zone_identification.h;
// docs/zones_and_sensors.md, "Optimisers"), on the one optimiser layer that Identify
// (identification.h) uses for one parameter.
//
// The objective is a FirstOrderObjective (first_order_objective.h). Every algorithm of
// algorithms.h but brent (Identify's alone), all started from the same point within the
// same bounds:
//
//   nlopt  bobyqa, cobyla, sbplx without the gradient (BOBYQA's first model takes
//          (n + 1)(n + 2) / 2 evaluations: a few parameters only; its first trust region
//          a tenth of each width); mma, lbfgs, slsqp with it. Stops on xtol_abs (the
//          step tolerance) and ftol_rel.
//   ceres  ceres::GradientProblemSolver, lbfgs (rank 100) or bfgs with a Wolfe line
//          search, on free variables y_i with MINUIT's bound transform
//            x_i = lo_i + (hi_i - lo_i) (1 + sin y_i) / 2,
//          which reaches a bound at a finite y; a start on a bound (a stationary point in
//          y) is moved inside by 1e-6 of the width.
//
// Guards (one for every optimiser, optim's guarded objective): every evaluation is
// counted, the evaluation and time limits are enforced before each one, an exception or
// a false return of the objective stops the optimiser with its message, a non-finite
// cost is a failure, and the best point seen is reported, not the optimiser's last.
// NLopt's generic failure of a gradient-based algorithm after progress (its line search
// found no decrease: the cost is flat to the objective's precision) counts as
// convergence, as roundoff_limited does.
//
// Scaling: the optimiser sees cost / |cost(start)| (the gradient likewise), the cost
// being evaluated once at the start, since its internal tests assume a cost of order one.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/optim/first_order_objective.h"

namespace mcrewave {

// The `zone_identification:` options of the minimiser.
struct BoundedMinimizerOptions {
  // Ceres' L-BFGS by default (docs/zones_and_sensors.md, "Measured on the paper's bar").
  OptimizerType optimizer = OptimizerType::kCeres;
  OuterAlgorithm algorithm = OuterAlgorithm::kDefault;
  // Stop when a step changes every parameter by at most this much (absolute: on
  // p = log(E / E_scale) it is a relative change of E). NLopt xtol_abs; Ceres: the
  // same test on x in an iteration callback.
  double step_tolerance = 1e-8;
  // Stop when a step changes the cost by at most this fraction (NLopt ftol_rel;
  // Ceres function_tolerance); 0: no such test.
  double function_tolerance = 1e-10;
  // Evaluations allowed; reaching the limit is not convergence.
  int max_evaluations = 2000;
  // Wall time allowed [s]; reaching it is not convergence.
  double max_time = 600.0;
  // A start whose cost is at most this is a minimum already (data the model matches to
  // round-off): the optimiser does not run, the start is the answer, converged. Not a
  // config key: set by the caller that knows the cost's scale (0: off).
  double matched_cost = 0.0;

  // Valid when step_tolerance in (0, 0.1), function_tolerance in [0, 0.1),
  // max_evaluations >= 2, max_time > 0, the algorithm offered by the optimiser for
  // many parameters. Messages name the zone_identification.* keys.
  bool IsValid(std::string* error) const;
};

struct BoundedMinimizerSummary {
  OptimizerType optimizer = OptimizerType::kCeres;
  OuterAlgorithm algorithm = OuterAlgorithm::kLbfgs;  // as resolved
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  std::string optimizer_message;  // the optimiser's own word on why it stopped
  std::vector<double> initial;    // the start
  std::vector<double> x;          // best point seen (empty: no usable evaluation)
  double initial_cost = std::numeric_limits<double>::quiet_NaN();
  double cost = std::numeric_limits<double>::quiet_NaN();  // at x
  int evaluations = 0;           // objective evaluations (failed ones included)
  int gradient_evaluations = 0;  // of which with the gradient
  int iterations = -1;           // Ceres iterations; -1 for NLopt (it does not say)
  double wall_time_s = -1.0;

  // A tolerance was met (NLopt xtol / ftol / success or roundoff-limited; Ceres
  // convergence). Limits reached and failures are not usable.
  bool IsSolutionUsable() const { return termination == TerminationType::kConvergence; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Minimises the objective over lower <= x <= upper from `initial` (clamped into
// the bounds). Never throws for what the objective does. Preconditions:
// options.IsValid(); lower, upper, initial have num_parameters() entries, finite,
// lower < upper.
BoundedMinimizerSummary MinimizeWithinBounds(const BoundedMinimizerOptions& options,
                                             FirstOrderObjective* objective,
                                             const std::vector<double>& lower,
                                             const std::vector<double>& upper,
                                             const std::vector<double>& initial);

}  // namespace mcrewave
