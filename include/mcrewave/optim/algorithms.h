// Which optimiser offers which algorithm (core/types.h: OptimizerType, OuterAlgorithm),
// for every caller of the one optimiser layer: Identify (identification.h, one
// parameter, the `outer:` keys) and MinimizeWithinBounds (bounded_minimizer.h, any
// number, the `zone_identification:` keys).
//
//   nlopt  bobyqa, cobyla and sbplx without the gradient; mma, lbfgs and slsqp with it;
//          for one parameter only, mcrewave's own brent (Brent's minimiser, without the
//          gradient) and secant (with it). The default: secant for one parameter,
//          bobyqa for more
//   ceres  lbfgs (the default) and bfgs, with the gradient
#pragma once

#include <string>

#include "mcrewave/core/types.h"

namespace mcrewave {

// True when the optimiser offers the algorithm for that many parameters (kDefault:
// always; kBrent: NLopt's list, one parameter only).
bool IsAlgorithmAvailable(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters = 1);
// kDefault resolved for the optimiser and that many parameters (NLopt: secant for one,
// bobyqa for more; Ceres: lbfgs); other values unchanged.
OuterAlgorithm ResolveAlgorithm(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters);
// Whether the algorithm uses the gradient (kDefault resolved first).
bool UsesGradient(OptimizerType optimizer, OuterAlgorithm algorithm, int parameters);
// "a, b or c": the algorithms the optimiser offers for that many parameters, for messages.
std::string AvailableAlgorithms(OptimizerType optimizer, int parameters = 1);

}  // namespace mcrewave
