// Minimisation of a function of several parameters within bounds: the outer loop of
// the identification of zone moduli (identification/zone_identification.h; the problem:
// docs/zones_and_sensors.md, "Identification of zone moduli").
//
// The objective is a MultiParameterObjective, shaped like ceres::FirstOrderFunction:
// a cost, an optional gradient, and false (never a made-up number) when the value
// cannot be had. Back ends, all started from the same point within the same bounds:
//
//   nlopt_lbfgs   NLopt's low-storage BFGS (LD_LBFGS), bounded, with the gradient
//   nlopt_mma     NLopt's method of moving asymptotes (LD_MMA), with the gradient
//   nlopt_slsqp   NLopt's sequential quadratic programming (LD_SLSQP), with the gradient
//   nlopt_bobyqa  Powell's BOBYQA (LN_BOBYQA), derivative-free: for a few parameters
//                 only (it needs (n + 1)(n + 2) / 2 evaluations for its first model)
//   ceres_lbfgs   ceres::GradientProblemSolver, L-BFGS with a Wolfe line search, on
//                 free variables y_i with the bound transform of every parameter
//                   x_i = lo_i + (hi_i - lo_i) (1 + sin y_i) / 2
//                 (MINUIT's). Chosen over the logistic map of the scalar loop
//                 (identification.h) because a bound is reached at a finite y
//                 (y = +-pi/2), where the cost is smooth and quadratic in y: an optimum
//                 on a bound (a zone pushed to a bound of the search) converges like
//                 an interior one, while the logistic map only reaches it as y -> inf
//                 with a gradient that vanishes exponentially. The price: dx/dy = 0 on
//                 the bounds makes them stationary points in y, so the start is kept
//                 strictly inside (a start on a bound is moved in by 1e-6 of the width).
//
// Guarded as the scalar loop is (nlopt_identification.cpp): every evaluation is
// counted, the evaluation and time limits are enforced before each one, an exception
// or a false return of the objective is caught in the adapter, its message kept and
// the optimiser stopped (NLopt force-stopped: its C++ wrapper would report a bare
// "nlopt failure"); a non-finite cost is a failure. The best point seen is reported,
// not the optimiser's last. NLopt's generic failure of a gradient-based algorithm
// after progress (its line search found no decrease: the cost is flat to the
// objective's precision, measured on the paper's bar with inner solves at 1e-8) counts
// as convergence, as roundoff_limited does.
//
// Scaling: the cost is evaluated once at the start before the optimiser runs, and the
// optimiser sees cost / |cost(start)| (and the gradient likewise): its internal tests
// (NLopt L-BFGS's gradient test, Ceres' line search) assume a cost of order one, while
// the scaled e^2 / J_rest of nearly consistent data starts at 1e-6 or below (measured:
// NLopt L-BFGS stopped with "success" at 3.6e-4 relative error of the zone moduli on
// the 10-zone inverse crime without this scaling).
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

// A cost of num_parameters() parameters, with an optional gradient.
class MultiParameterObjective {
 public:
  virtual ~MultiParameterObjective() = default;
  virtual int num_parameters() const = 0;
  // Writes the cost at x to *cost and, when gradient is not null, d cost / d x_i to
  // gradient[i]. False when the value could not be computed (error_message() says
  // why). May throw: MinimizeWithinBounds catches.
  virtual bool Evaluate(const double* x, double* cost, double* gradient) = 0;
  // Why the last failed Evaluate failed ("" when none failed).
  virtual std::string error_message() const { return ""; }
};

bool UsesGradient(BoundedAlgorithm algorithm);

// The `zone_identification:` options of the minimiser.
struct BoundedMinimizerOptions {
  // Ceres' L-BFGS: the paper's bar, noise-free, 10 zones in 133 evaluations and 100 in
  // 189, against 264 and 373 for NLopt's (docs/zones_and_sensors.md).
  BoundedAlgorithm algorithm = BoundedAlgorithm::kCeresLbfgs;
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

  // Valid when step_tolerance in (0, 0.1), function_tolerance in [0, 0.1),
  // max_evaluations >= 2, max_time > 0. Messages name the zone_identification.* keys.
  bool IsValid(std::string* error) const;
};

struct BoundedMinimizerSummary {
  BoundedAlgorithm algorithm = BoundedAlgorithm::kNloptLbfgs;
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
                                             MultiParameterObjective* objective,
                                             const std::vector<double>& lower,
                                             const std::vector<double>& upper,
                                             const std::vector<double>& initial);

}  // namespace mcrewave
