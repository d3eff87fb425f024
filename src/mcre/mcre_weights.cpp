#include "mcrewave/mcre/mcre_weights.h"

#include <cmath>
#include <sstream>

namespace mcrewave {

bool McreWeights::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(std::isfinite(displacement_weight) && displacement_weight > 0.0)) {
    why << "mcre.w_u must be a finite positive number, got " << displacement_weight;
  } else if (!(std::isfinite(force_weight) && force_weight > 0.0)) {
    why << "mcre.w_f must be a finite positive number, got " << force_weight;
  } else if (!(std::isfinite(strain_weight) && strain_weight > 0.0)) {
    why << "mcre.w_e must be a finite positive number, got " << strain_weight;
  } else if (!(std::isfinite(reaction_weight) && reaction_weight > 0.0)) {
    why << "mcre.w_r must be a finite positive number, got " << reaction_weight;
  } else if (!(std::isfinite(clamp_displacement_weight) && clamp_displacement_weight > 0.0)) {
    why << "mcre.w_u0 must be a finite positive number, got " << clamp_displacement_weight;
  } else if (!(std::isfinite(unmeasured_force_weight) && unmeasured_force_weight > 0.0)) {
    why << "mcre.w_fu must be a finite positive number, got " << unmeasured_force_weight;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

}  // namespace mcrewave
