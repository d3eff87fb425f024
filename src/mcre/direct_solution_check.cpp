#include "mcre/direct_solution_check.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mcrewave/core/format.h"

namespace mcrewave::internal {

std::string ScientificString(double value) { return FormatNumber(value, kScientificThreeDecimals); }

void CheckDirectSolution(const CoupledSolverOptions& options, const std::string& method_description,
                         CoupledProblem* problem, const CoupledSolution& solution,
                         CoupledSolverSummary* summary) {
  const Matrix& displacement = solution.displacement;
  const Matrix& retrograde = solution.retrograde;
  if (!displacement.allFinite() || !retrograde.allFinite()) {
    summary->termination = TerminationType::kFailure;
    summary->message = method_description + "; the solution has non-finite values";
    return;
  }
  // c = T(0) and T(W), with Direct(W) as a by-product.
  Matrix scratch, rhs, direct_of_retrograde, image;
  problem->FixedPointMap(problem->ZeroField(), &scratch, &rhs);
  problem->FixedPointMap(retrograde, &direct_of_retrograde, &image);
  // The round-off floor of the iterative solvers: 1e-11 ||W_u||_P, W_u = Retrograde(0).
  Matrix displacement_data_response;
  problem->RetrogradeSweep(problem->ZeroField(), true, &displacement_data_response);
  constexpr double kRoundOffFloor = 1e-11;
  const double floor = kRoundOffFloor * problem->Norm(displacement_data_response);
  const double rhs_norm = problem->Norm(rhs);
  const double residual_norm = problem->Norm(image - retrograde);
  const double relative = rhs_norm > 0.0 ? residual_norm / rhs_norm : residual_norm;
  summary->relative_residual = relative;
  summary->residual_history.assign(1, relative);
  const double direct_norm = direct_of_retrograde.norm();
  const double mismatch = direct_norm > 0.0
                              ? (displacement - direct_of_retrograde).norm() / direct_norm
                              : displacement.norm();
  const bool residual_met = relative <= options.tolerance || residual_norm <= floor;
  const bool displacement_met = mismatch <= std::max(options.tolerance, 1e-12);
  std::string figures = "relative residual " + ScientificString(relative) +
                        ", displacement mismatch " + ScientificString(mismatch);
  if (!std::isfinite(relative) || !std::isfinite(mismatch)) {
    summary->termination = TerminationType::kFailure;
    summary->message = method_description + "; non-finite check: " + figures;
  } else if (residual_met && displacement_met) {
    summary->termination = TerminationType::kConvergence;
    summary->message = method_description + "; " + figures;
  } else {
    summary->termination = TerminationType::kFailure;
    summary->message = method_description + "; but the solution fails its check (" + figures +
                       ", tolerance " + ScientificString(options.tolerance) +
                       "): accuracy lost to round-off amplification";
  }
}

}  // namespace mcrewave::internal
