// Identify's back ends (identification.h), each the scalar loop's settings of the one
// optimiser layer: the guarded objective (guarded_objective.h) and the NLopt and Ceres
// drivers (nlopt_driver.h, ceres_driver.h).
#pragma once

#include "mcrewave/optim/identification.h"
#include "optim/guarded_objective.h"

namespace mcrewave::internal {

// Each runs its optimiser on the guarded objective of x = E / modulus_scale within
// options' bounds from options.initial, and sets the summary's termination, message,
// optimizer_message and (Ceres) iterations; the caller then fills in the best point.
// curvature: an estimate of d^2 cost / dx^2 at options.initial (0: unknown). NLopt's
// gradient methods see the cost in units of its change over the bounds (curvature x
// width^2); Ceres' parameter is scaled so that its first step is the Newton step.
void MinimizeWithNlopt(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, double curvature, IdentificationSummary* summary);
void MinimizeWithCeres(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, double curvature, IdentificationSummary* summary);
void MinimizeWithBrent(const IdentificationOptions& options, GuardedObjective* objective,
                       double modulus_scale, IdentificationSummary* summary);
void MinimizeWithSecant(const IdentificationOptions& options, GuardedObjective* objective,
                        double modulus_scale, double curvature, IdentificationSummary* summary);

// mcrewave's own 1-D back ends (Brent, secant): the absolute floor of their tolerance on
// x = E / E_scale (x is of order 1), tol = relative_tolerance |x| + kAbsoluteTolerance.
constexpr double kAbsoluteTolerance = 1e-12;

// Ends such a back end at the guard's stop, with its termination and message.
inline void ReportStop(const GuardedObjective& objective, IdentificationSummary* summary) {
  summary->termination = objective.StopTermination();
  summary->message = objective.stop_message();
}

}  // namespace mcrewave::internal
