// Internal entry points of the coupled solvers (one per method), called by
// SolveCoupled once options are checked and the clock is started. Each fills the
// solution's fields (U and W) and the summary's termination, message, iterations,
// residuals and method-specific figures; SolveCoupled adds cost, gradient,
// sweeps and time.
#pragma once

#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave::internal {

void SolveAllAtOnce(const CoupledSolverOptions& options, CoupledProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary);
void SolveByRelaxation(const CoupledSolverOptions& options, CoupledProblem* problem,
                       const Matrix* initial_retrograde, CoupledSolution* solution,
                       CoupledSolverSummary* summary);
void SolveByConjugateGradient(const CoupledSolverOptions& options, CoupledProblem* problem,
                              const Matrix* initial_retrograde, CoupledSolution* solution,
                              CoupledSolverSummary* summary);
void SolveByRiccati(const CoupledSolverOptions& options, CoupledProblem* problem,
                    CoupledSolution* solution, CoupledSolverSummary* summary);
void SolveByShooting(const CoupledSolverOptions& options, CoupledProblem* problem,
                     CoupledSolution* solution, CoupledSolverSummary* summary);
// Also fills the solution's cost, gradients, traces and what the problem's streaming
// totals hold (the bar: end retrograde values, error map and its picture; a matrix
// model: the dof and zone maps); its fields U and W stay empty. initial_traces
// (nullable): a warm start y^(0) of the problem's ZeroTraces() shape.
void SolveByStreamingConjugateGradient(const CoupledSolverOptions& options,
                                       StreamingCoupledProblem* problem,
                                       const Matrix* initial_traces, CoupledSolution* solution,
                                       CoupledSolverSummary* summary);

}  // namespace mcrewave::internal
