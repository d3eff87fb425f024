#include "mcrewave/optim/modulus_objective.h"

#include <cmath>
#include <sstream>

namespace mcrewave {

bool TrialModulus(double parameter, double modulus_scale, double* modulus, std::string* why) {
  *modulus = parameter * modulus_scale;
  if (std::isfinite(*modulus) && *modulus > 0.0) return true;
  std::ostringstream message;
  message << "trial modulus " << *modulus << " Pa is not a positive finite number";
  *why = message.str();
  return false;
}

}  // namespace mcrewave
