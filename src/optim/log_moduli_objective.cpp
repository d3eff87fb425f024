#include "mcrewave/optim/log_moduli_objective.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace mcrewave {

LogModuliObjective::LogModuliObjective(Vector reference_moduli)
    : reference_moduli_(std::move(reference_moduli)) {
  assert(reference_moduli_.size() > 0 && reference_moduli_.allFinite() &&
         reference_moduli_.minCoeff() > 0.0);
}

Vector LogModuliObjective::Moduli(const double* p) const {
  Vector moduli(reference_moduli_.size());
  for (int z = 0; z < moduli.size(); ++z) moduli[z] = reference_moduli_[z] * std::exp(p[z]);
  return moduli;
}

bool LogModuliObjective::Evaluate(const double* p, double* cost, double* gradient) {
  ++evaluations_;
  const Vector moduli = Moduli(p);
  if (!(moduli.allFinite() && moduli.minCoeff() > 0.0)) {
    error_message_ = "a trial zone modulus is not a positive finite number";
    return false;
  }
  double value = 0.0;
  Vector moduli_gradient;
  if (!ModuliCost(moduli, &value, gradient != nullptr ? &moduli_gradient : nullptr,
                  &error_message_)) {
    return false;
  }
  if (!std::isfinite(value) || (gradient != nullptr && !moduli_gradient.allFinite())) {
    error_message_ = "the cost at the zone moduli of evaluation " + std::to_string(evaluations_) +
                     " is not finite";
    return false;
  }
  const double scale = cost_scale();
  // cost = J / J_scale
  *cost = value / scale;
  double gradient_norm = 0.0;
  if (gradient != nullptr) {
    for (int z = 0; z < moduli.size(); ++z) {
      // d cost / d p_z = (dJ/dE_z) (dE_z/dp_z) / J_scale,  dE_z/dp_z = E_z
      gradient[z] = moduli_gradient[z] * moduli[z] / scale;
      gradient_norm = std::max(gradient_norm, std::abs(gradient[z]));
    }
  }
  error_message_.clear();
  OnEvaluated(moduli, *cost, gradient_norm);
  return true;
}

}  // namespace mcrewave
