// What the two NLopt back ends (the scalar loop, nlopt_identification.cpp, and the
// zones' bounded minimiser, bounded_minimizer.cpp) make of NLopt's results.
#pragma once

#include <exception>
#include <nlopt.hpp>
#include <string>

namespace mcrewave::internal {

// NLopt's result code in words ("xtol reached", ...).
std::string NloptResultName(nlopt::result result);

// Whether `error`, thrown by nlopt::opt::optimize, is NLopt's generic failure
// (NLOPT_FAILURE, "nlopt failure") of a gradient-based algorithm that made progress
// (improved: a usable cost below the first one) and was not stopped by the objective:
// its line search found no decrease along a descent direction, i.e. the cost is flat
// to the objective's precision there (the inner solves' tolerance). Both back ends
// count it as convergence, with kLineSearchStallMessage. Measured:
// configs/paper_bar_pinned.yaml (inner tolerance 1e-6), NLopt L-BFGS stops 1.4e-6
// from BOBYQA's E.
bool IsLineSearchStallAfterProgress(const std::exception& error, bool gradient_based,
                                    bool improved, bool stopped_by_objective);
inline constexpr const char* kLineSearchStallMessage =
    "converged to the objective's precision (NLopt: line search without decrease)";

}  // namespace mcrewave::internal
