// Internal entry points of the coupled solvers (one per method), called by
// SolveCoupled once options are checked and the clock is started. Each fills the
// solution's fields (U and W) and the summary's termination, message, iterations,
// residuals and method-specific figures; SolveCoupled adds cost, gradient,
// sweeps and time.
#pragma once

#include <utility>
#include <vector>

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
// (nullable): a warm start y^(0) of the problem's ZeroTraces() shape;
// reference_residual_norm: SolveCoupled's.
void SolveByStreamingConjugateGradient(const CoupledSolverOptions& options,
                                       StreamingCoupledProblem* problem,
                                       const Matrix* initial_traces, double reference_residual_norm,
                                       CoupledSolution* solution, CoupledSolverSummary* summary);

// {min, max} of the eigenvalues of the symmetric tridiagonal matrix with this diagonal
// and sub-diagonal (one entry fewer): the Ritz extremes of a Lanczos process.
std::pair<double, double> TridiagonalEigenvalueExtremes(const Vector& diagonal,
                                                        const Vector& sub_diagonal);

// The Lanczos coefficients of a conjugate-gradient run on A = I - G in <.,.>_P (or on
// I - L over the traces, whose spectrum is A's but for eigenvalues 1): step_k =
// rho_k / <p_k, A p_k> and ratio_k = rho_{k+1} / rho_k give the tridiagonal (Saad,
// Iterative Methods for Sparse Linear Systems, 2nd ed., section 6.7.3)
//   T_kk = 1 / step_k + ratio_{k-1} / step_{k-1},   T_k,k+1 = sqrt(ratio_k) / step_k.
struct ConjugateGradientLanczos {
  std::vector<double> steps, ratios;
  void Add(double step, double ratio) {
    steps.push_back(step);
    ratios.push_back(ratio);
  }
  // The extreme Ritz values of T into summary->spectrum_min / spectrum_max; nothing
  // before the first step.
  void ReportTo(CoupledSolverSummary* summary) const;
};

}  // namespace mcrewave::internal
