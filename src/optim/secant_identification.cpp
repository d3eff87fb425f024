// The bounded 1-D back end of Identify (identification.h) for outer.algorithm secant:
// a safeguarded secant iteration on the gradient, mcrewave's own, listed under
// outer.optimizer nlopt as brent is.
//
// Scheme: the minimiser is a zero of g = d cost / dx. From x_0 = options.initial the
// first step is Newton's with the scan's curvature estimate c > 0,
//   x_1 = x_0 - g_0 / c,
// and every later one the secant step through the last two points,
//   x_{k+1} = x_k - g_k (x_k - x_{k-1}) / (g_k - g_{k-1}),
// when that slope is positive (the cost convex between them). The bracket [a, b]
// starts at the bounds and shrinks to each new point on the side its gradient's sign
// says the minimiser lies (g > 0: to its left). A step that leaves the open bracket,
// or has no positive slope to take, is replaced by the midpoint between x_k and the
// bracket's end downhill. Stops, without evaluating it, when a step is shorter than
// tol = relative_tolerance |x_k| + kAbsoluteTolerance (E located to about
// relative_tolerance, as NLopt's xtol_rel), or when the bracket is narrower than 2 tol.
// Near a simple minimum the secant converges with order (1 + sqrt 5) / 2
// (docs/performance.md gives the evaluations it saves).
#include <cmath>

#include "optim/identification_internal.h"

namespace mcrewave::internal {

void MinimizeWithSecant(const IdentificationOptions& options, GuardedObjective* objective,
                        double modulus_scale, double curvature, IdentificationSummary* summary) {
  double a = options.lower_bound / modulus_scale;
  double b = options.upper_bound / modulus_scale;
  double x = options.initial / modulus_scale;
  double cost = 0.0, gradient = 0.0;
  if (!objective->Evaluate(&x, &cost, &gradient)) {
    ReportStop(*objective, summary);
    return;
  }
  bool has_previous = false;
  double previous_x = x, previous_gradient = gradient;
  for (;;) {
    // The minimiser lies where the gradient says: left of x when g > 0.
    if (gradient > 0.0) b = x;
    if (gradient < 0.0) a = x;
    const double tol = options.relative_tolerance * std::abs(x) + kAbsoluteTolerance;
    if (gradient == 0.0 || b - a <= 2.0 * tol) break;
    double step = 0.0;
    bool model_step = false;
    if (has_previous) {
      // The secant slope (g_k - g_{k-1}) / (x_k - x_{k-1}).
      const double slope = (gradient - previous_gradient) / (x - previous_x);
      if (slope > 0.0 && std::isfinite(slope)) {
        step = -gradient / slope;
        model_step = true;
      }
    } else if (curvature > 0.0) {
      step = -gradient / curvature;
      model_step = true;
    }
    if (model_step && std::abs(step) <= tol) break;
    double next = x + step;
    if (!model_step || !(next > a && next < b)) {
      // Halfway to the bracket's end downhill.
      next = 0.5 * (x + (gradient > 0.0 ? a : b));
    }
    previous_x = x;
    previous_gradient = gradient;
    has_previous = true;
    x = next;
    if (!objective->Evaluate(&x, &cost, &gradient)) {
      ReportStop(*objective, summary);
      return;
    }
  }
  summary->termination = TerminationType::kConvergence;
  summary->optimizer_message = "step or bracket within relative_tolerance |x| + 1e-12";
  summary->message = "converged (secant: " + summary->optimizer_message + ")";
}

}  // namespace mcrewave::internal
