#include "mcrewave/mcre/matrix_zone_objective.h"

#include <spdlog/spdlog.h>

#include <cassert>
#include <cmath>

namespace mcrewave {

MatrixZoneObjective::MatrixZoneObjective(MatrixMcreProblem* problem,
                                         const CoupledSolverOptions& inner)
    : LogModuliObjective(problem->NominalModuli()), problem_(problem), inner_(inner) {
  assert(inner.IsValid(nullptr));
  const double rest = problem->RestCost();
  cost_scale_ = rest > 0.0 ? rest : 1.0;
}

bool MatrixZoneObjective::ModuliCost(const Vector& moduli, double* cost, Vector* gradient,
                                     std::string* why) {
  problem_->SetModuli(moduli);
  const CoupledSolverSummary summary =
      SolveCoupled(inner_, problem_, warm_start_.size() > 0 ? &warm_start_ : nullptr, &solution_);
  if (!summary.IsSolutionUsable() || !std::isfinite(solution_.cost)) {
    *why = "the coupled solve of evaluation " + std::to_string(evaluations()) +
           " is not usable: " + summary.BriefReport() + " (" + summary.message + ")";
    return false;
  }
  spdlog::debug("evaluation {}: e^2 = {:.9g} J s; inner {} (from {:.3g})", evaluations(),
                solution_.cost, summary.BriefReport(),
                summary.residual_history.empty() ? -1.0 : summary.residual_history.front());
  // W, or the traces after a streaming solve.
  warm_start_ = solution_.WarmStart();
  *cost = solution_.cost;
  if (gradient != nullptr) *gradient = solution_.cost_gradients;
  return true;
}

}  // namespace mcrewave
