// The scalar objective of the outer loop, seen by every optimiser of
// identification.h through one interface (shaped like ceres::FirstOrderFunction):
// one scaled parameter x = E / modulus_scale(), a scaled cost, an optional gradient,
// and false (never a made-up number) when the value cannot be had. The MCRE's
// McreObjective (mcre/objective.h) and least squares' OutputErrorModulusObjective
// (least_squares/output_error_modulus_objective.h) implement it.
#pragma once

#include <memory>
#include <string>

#include "mcrewave/optim/first_order_objective.h"

namespace mcrewave {

// A scalar objective of one parameter x = E / modulus_scale() (x of order 1).
class ModulusObjective : public FirstOrderObjective {
 public:
  int num_parameters() const final { return 1; }

  // E [Pa] per unit of the parameter x.
  virtual double modulus_scale() const = 0;

  // An independent objective of the same cost (same scale, same cost scaling),
  // its inner solves run to the relative tolerance inner_tolerance, usable on
  // another thread while this one is not evaluated; null when the objective
  // cannot be copied (the default).
  virtual std::unique_ptr<ModulusObjective> CloneForScan(double inner_tolerance) const {
    (void)inner_tolerance;
    return nullptr;
  }

  // Forgets every earlier solution and solver state a later evaluation would start
  // from, so that the next evaluation is the same bits as the first of a fresh
  // CloneForScan copy's (the scan reuses one copy for several chunks of points); its
  // sweeps() go on counting. Nothing to do for an objective without such state (the
  // default).
  virtual void StartAfresh() {}

  // Inner sweeps (direct + retrograde) of every evaluation so far; 0 when the
  // objective has no inner solver (the default).
  virtual long sweeps() const { return 0; }

  // The predicted mean spacing, in ln E, of the valleys of the cost
  // (PredictedValleySpacing of valley_spacing.h on the model's response to
  // the measured loads); 0 when the objective cannot tell (the default). Runs the
  // model once (counted in sweeps()).
  virtual double ValleySpacing() { return 0.0; }
};

// E = parameter x modulus_scale [Pa], the trial modulus of an optimiser's parameter;
// false, with the reason in *why, when it is not a positive finite number.
bool TrialModulus(double parameter, double modulus_scale, double* modulus, std::string* why);

}  // namespace mcrewave
