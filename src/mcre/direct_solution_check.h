// The acceptance test of the coupled solvers that compute (U, W) without iterating
// (all-at-once, Riccati, single and multiple shooting): the same measure as the iterative
// solvers (coupled_solver.h), so that a direct solve that lost its accuracy to
// round-off amplification is reported as a failure, never returned as numbers.
#pragma once

#include <string>

#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave::internal {

// Computes, from 5 sweeps of the problem (not counted as the method's work),
//   c = T(0),  r = T(W) - W,  relative residual ||r||_P / ||c||_P,
// and the mismatch ||U - Direct(W)|| / ||Direct(W)|| of the returned displacement.
// The solve converges when the relative residual meets options.tolerance (or ||r||_P
// is at the round-off floor 1e-11 ||Retrograde(0)||_P of the iterative solvers) and
// the mismatch is at most max(tolerance, 1e-12); otherwise it fails. Sets
// summary->termination, relative_residual and message (method_description, then the
// figures).
void CheckDirectSolution(const CoupledSolverOptions& options, const std::string& method_description,
                         CoupledProblem* problem, const CoupledSolution& solution,
                         CoupledSolverSummary* summary);

// "1.234e-05": three significant digits, for messages.
std::string ScientificString(double value);

}  // namespace mcrewave::internal
