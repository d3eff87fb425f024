// The exact solution of the continuous reference experiment (formulation.md
// section 1): the bar clamped at x = 0, at rest at t = 0, loaded at x = L by the
// half-sine force F(t). Independent of the FE model and of the theta method; it is
// the reference the discretisation is checked against, and a "truth" for
// synthetic data.
#pragma once

#include "mcrewave/data/measurement.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/experiment.h"

namespace mcrewave {

class ExactBarSolution {
 public:
  // bar.elements and bar.mass are ignored (the solution is continuous).
  ExactBarSolution(const BarProperties& bar, const LoadOptions& load);

  // u(x, t) [m].
  double Displacement(double x, double time) const;
  // The force applied on the bar at x = 0 by the clamp, positive along +x:
  // f0(t) = -S sigma(0, t) = -S E u_x(0, t) [N].
  double ClampForce(double time) const;
  // The four channels (u0 = 0, uL, f0, fL = F) at t_k = k h, k = 0..m.
  ChannelSet Sample(const TimeOptions& time) const;

 private:
  BarProperties bar_;
  LoadOptions load_;
};

}  // namespace mcrewave
