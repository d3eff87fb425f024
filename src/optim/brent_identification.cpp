// The bounded 1-D back end of Identify (identification.h): Brent's minimiser,
// for outer.algorithm brent (NLopt has no 1-D method; listed with NLopt's
// derivative-free algorithms under outer.optimizer nlopt).
//
// Scheme (R. P. Brent, Algorithms for Minimization without Derivatives, 1973,
// ch. 5; the fmin of Forsythe, Malcolm and Moler): on a bracket [a, b] that
// always holds the best point x, each step tries the minimum of the parabola
// through the three best points x, w, v and falls back on a golden-section step
// into the larger part of the bracket when that parabola step is not well
// inside or does not shrink fast enough. Stops when the bracket around x is
// within 2 tol, tol = relative_tolerance |x| + kAbsoluteTolerance: E is
// located to about relative_tolerance, as NLopt's xtol_rel.
#include <cmath>

#include "optim/identification_internal.h"

namespace mcrewave::internal {

void MinimizeWithBrent(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, IdentificationSummary* summary) {
  const double scale = modulus_scale;
  // (3 - sqrt(5)) / 2: the golden-section fraction.
  const double golden = 0.5 * (3.0 - std::sqrt(5.0));
  double a = options.lower_bound / scale;
  double b = options.upper_bound / scale;
  // x: best point so far; w: second best; v: the previous w.
  double x = options.initial / scale;
  double fx = 0.0;
  if (!objective->Evaluate(&x, &fx, nullptr)) {
    ReportStop(*objective, summary);
    return;
  }
  double w = x, v = x, fw = fx, fv = fx;
  double step = 0.0;         // the last step d
  double step_before = 0.0;  // the step before it, e
  for (;;) {
    const double middle = 0.5 * (a + b);
    const double tol = options.relative_tolerance * std::abs(x) + kAbsoluteTolerance;
    if (std::abs(x - middle) <= 2.0 * tol - 0.5 * (b - a)) break;
    bool parabolic = false;
    if (std::abs(step_before) > tol) {
      // Minimum of the parabola through (x, fx), (w, fw), (v, fv): x + p / q.
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0.0) p = -p;
      q = std::abs(q);
      const double previous = step_before;
      step_before = step;
      // Accepted when inside (a, b) and shorter than half the step before last.
      if (std::abs(p) < std::abs(0.5 * q * previous) && p > q * (a - x) && p < q * (b - x)) {
        step = p / q;
        const double u = x + step;
        if (u - a < 2.0 * tol || b - u < 2.0 * tol) step = x < middle ? tol : -tol;
        parabolic = true;
      }
    }
    if (!parabolic) {
      step_before = x < middle ? b - x : a - x;
      step = golden * step_before;
    }
    // Never closer than tol to x.
    const double u = std::abs(step) >= tol ? x + step : (step > 0.0 ? x + tol : x - tol);
    double fu = 0.0;
    if (!objective->Evaluate(&u, &fu, nullptr)) {
      ReportStop(*objective, summary);
      return;
    }
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w;
      fv = fw;
      w = x;
      fw = fx;
      x = u;
      fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w;
        fv = fw;
        w = u;
        fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u;
        fv = fu;
      }
    }
  }
  summary->termination = TerminationType::kConvergence;
  summary->optimizer_message = "bracket within 2 (relative_tolerance |x| + 1e-12)";
  summary->message = "converged (Brent: " + summary->optimizer_message + ")";
}

}  // namespace mcrewave::internal
