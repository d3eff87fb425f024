// NLopt behind the one optimiser layer: one algorithm table, one objective callback on
// the guarded objective, and one reading of NLopt's results and exceptions, for every
// caller (Identify's one parameter, MinimizeWithinBounds' many).
#pragma once

#include <nlopt.hpp>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "optim/guarded_objective.h"

namespace mcrewave::internal {

// How a minimisation ended, in the words of the layer.
struct OptimizerOutcome {
  TerminationType termination = TerminationType::kFailure;
  std::string message = "not run";
  std::string optimizer_message;  // the optimiser's own word on why it stopped
  int iterations = -1;            // Ceres iterations; -1 for NLopt (it does not say)
};

// NLopt's algorithm for one of OuterAlgorithm's NLopt entries (kDefault: BOBYQA).
// Precondition: IsAlgorithmAvailable(kNlopt, algorithm) and algorithm != kBrent.
nlopt::algorithm NloptAlgorithm(OuterAlgorithm algorithm);

// NLopt's result code in words ("xtol reached", ...).
std::string NloptResultName(nlopt::result result);

// Runs optimizer->optimize from *x (the best point NLopt saw is left there, though the
// guard's best is the one to report) on the guarded objective, which it installs as the
// objective: a refused evaluation force-stops NLopt and returns +HUGE_VAL, which no
// algorithm takes for a best point. The caller sets the bounds, tolerances and limits.
// Never throws. Reading of the end:
//   - a stop of the guard (a limit or a failure of the objective) is the real reason,
//     whatever NLopt says;
//   - NLopt's evaluation or time limit: kNoConvergence;
//   - success, ftol, xtol or roundoff_limited: kConvergence;
//   - NLopt's generic failure of a gradient-based algorithm after progress (its line
//     search found no decrease: the cost is flat to the objective's precision) counts
//     as convergence, as roundoff_limited does (docs/zones_and_sensors.md, "Optimisers");
//   - anything else: kFailure.
OptimizerOutcome RunNlopt(nlopt::opt* optimizer, GuardedObjective* guard, std::vector<double>* x,
                          bool gradient_based);

}  // namespace mcrewave::internal
