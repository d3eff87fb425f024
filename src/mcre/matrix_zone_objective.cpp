#include "mcrewave/mcre/matrix_zone_objective.h"

#include <spdlog/spdlog.h>

#include <cassert>
#include <cmath>

namespace mcrewave {

MatrixZoneObjective::MatrixZoneObjective(MatrixMcreProblem* problem,
                                         const CoupledSolverOptions& inner)
    : problem_(problem), inner_(inner), nominal_(problem->NominalModuli()) {
  assert(inner.IsValid(nullptr));
  const double rest = problem->RestCost();
  cost_scale_ = rest > 0.0 ? rest : 1.0;
}

Vector MatrixZoneObjective::Moduli(const double* p) const {
  Vector moduli(nominal_.size());
  for (int z = 0; z < nominal_.size(); ++z) moduli[z] = nominal_[z] * std::exp(p[z]);
  return moduli;
}

bool MatrixZoneObjective::Evaluate(const double* p, double* cost, double* gradient) {
  ++evaluations_;
  const Vector moduli = Moduli(p);
  if (!(moduli.allFinite() && moduli.minCoeff() > 0.0)) {
    error_message_ = "a trial zone modulus is not a positive finite number";
    return false;
  }
  problem_->SetModuli(moduli);
  const CoupledSolverSummary summary =
      SolveCoupled(inner_, problem_, warm_start_.size() > 0 ? &warm_start_ : nullptr, &solution_);
  if (!summary.IsSolutionUsable() || !std::isfinite(solution_.cost)) {
    error_message_ = "the coupled solve of evaluation " + std::to_string(evaluations_) +
                     " is not usable: " + summary.BriefReport() + " (" + summary.message + ")";
    return false;
  }
  spdlog::debug("evaluation {}: e^2 = {:.9g} J s; inner {} (from {:.3g})", evaluations_,
                solution_.cost, summary.BriefReport(),
                summary.residual_history.empty() ? -1.0 : summary.residual_history.front());
  // W, or the traces after a streaming solve.
  warm_start_ = solution_.WarmStart();
  // cost = e^2 / J_rest
  *cost = solution_.cost / cost_scale_;
  if (gradient != nullptr) {
    for (int z = 0; z < moduli.size(); ++z) {
      // d cost / d p_z = (de^2/dE_z) E_z / J_rest
      gradient[z] = solution_.cost_gradients[z] * moduli[z] / cost_scale_;
    }
  }
  return true;
}

}  // namespace mcrewave
