// The weights of the MCRE's data terms, one set per problem (mcre.w_* of the config).
#pragma once

#include <string>

namespace mcrewave {

// Dimensionless weights of the data terms (formulation.md section 2). On a structure
// of stiffness scale k* = E0 a* and length scale l* (matrix_mcre_problem.h; the bar:
// a* = S / L, l* = L),
//   beta = w_u k* [N/m],  alpha = w_f / k* [m/N],
// so that every term of J is an energy [J] and e^2 is in [J s].
//
// Defaults w_u = 0.01, w_f = 1, the weights of the paper's free-free formulation
// (the config's defaults are TrustedClampWeights() of objective.h): the extreme
// eigenvalue of the iteration map, due to the rigid-body mode of the unclamped model,
// scales with w_u / w_f (about -35 at these defaults on the paper's case against
// -3.4e3 at w_u = 1), so relaxation and CG converge in tens to hundreds of sweeps
// instead of thousands; the evidence for the identification itself is in
// docs/weights.md.
//
// Strain gauges (docs/zones_and_sensors.md): beta_e = w_e k* l*^2 [N m]; a uniform
// strain e over the bar moves its end by e L, so w_e = w_u weighs a gauge like an end
// displacement sensor of the same information; the default follows w_u.
struct McreWeights {
  double displacement_weight = 0.01;  // w_u
  double force_weight = 1.0;          // w_f
  double strain_weight = 0.01;        // w_e
  // w_r: the measured clamp reaction f0 under a trusted or pinned clamp,
  // alpha_r = w_r / k* [m/N]. Trusted: the weight of f0 as an output; it counts
  // against uL in the ratio w_r / w_u: with w_u = 1e-5 the default weighs the two about
  // as their noise does on the paper's case (docs/trusted_clamp.md). Pinned: the weight
  // of f0 as a load, in place of alpha (docs/trusted_clamp.md section 9).
  double reaction_weight = 1e-4;
  // w_u0: a pinned clamp's displacement datum u(0) = 0, beta_0 = w_u0 k* [N/m]
  // (docs/trusted_clamp.md section 9).
  double clamp_displacement_weight = 0.1;
  // w_fu: an unmeasured load's force against the datum 0, alpha_u = w_fu / k* [m/N]
  // (docs/unmeasured_loads.md). The force is free in the limit w_fu -> 0; a finite w_fu
  // is a Tikhonov weight on its history. Against a gauge of weight w_e, a force that
  // explains a strain e at a bar's gauge costs about w_fu / w_e of that strain's misfit.
  double unmeasured_force_weight = 1e-6;
  bool IsValid(std::string* error) const;
};

}  // namespace mcrewave
