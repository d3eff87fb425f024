// Output-error least squares with zone moduli on the built-in bar's own band model: the
// tests' independent reference for MatrixOutputErrorObjective on the bar exported as
// matrices, which the zone identification uses (docs/zones_and_sensors.md, "Zones: the
// MCRE against least squares"). The library held it as its bar road until issue 39.
// BarLeastSquares' misfit (bar_least_squares.h) with K = sum_z E_z K1_z,
//
//   J(E_1..E_Z) = 1/2 sum_k c_k h sum_channels (y_k - y~_k)^2 / s^2      [s].
//
// Gradient by forward sensitivities s_z,k = du_k/dE_z, each obeying the theta scheme
// with the input -K1_z,r (theta u_{k+1} + (1 - theta) u_k), and
//   df0_k/dE_z = M_01 da_1 + K_01 s_z,1 + K1_z,01 u_1,   M_r da = -K_r s_z - K1_z,r u:
// one sweep per evaluation without the gradient, 1 + Z with it (for the few zones of a
// localisation, not one zone per element). J_rest: OutputErrorRestCost.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/linalg/band_matrix.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/model/matrix_export.h"
#include "reference/bar_least_squares.h"

namespace mcrewave {
namespace testing {

class BarZoneLeastSquares {
 public:
  // Keeps references to model and data: both must outlive the reference. model: the
  // identification's zones (one or more). noise: the levels s_u, s_f, s_e of the
  // misfit's normalisation (> 0 for every kind the data hold). ends: whether uL
  // enters (u0 never does: it is zero in the clamped model). theta in [0, 1].
  BarZoneLeastSquares(const BarModel& model, const ChannelSet& data, const NoiseLevels& noise,
                      double theta, EndDisplacementChannels ends = {});

  // J at the zone moduli [s] (one per zone [Pa], positive), and dJ/dE_z
  // [s / Pa] into *gradient when it is not null (resized to the zone count). Re-initialises the
  // integrator (the moduli change K). No allocation in the time loop.
  double Cost(const Vector& zone_moduli, Vector* gradient);

  // J_rest [s]; the cost scale (1 when J_rest = 0).
  double rest_cost() const { return bar_.rest_cost; }
  double cost_scale() const { return bar_.rest_cost > 0.0 ? bar_.rest_cost : 1.0; }
  long sweeps() const { return sweeps_; }

 private:
  const BarModel& model_;
  const ChannelSet& data_;
  ClampedBarData bar_;
  double theta_;
  EndDisplacementChannels ends_;
  int num_zones_;
  double weight_u_;  // 1 / s_u^2
  double weight_f_;  // 1 / s_f^2

  std::vector<SymmetricBandMatrix> zone_stiffness_;  // K1_z,r on the free nodes [m]
  std::vector<double> zone_stiffness_01_;            // K1_z(0, 1) [m]
  ThetaIntegrator integrator_;

  // Scratch of Cost, sized in the constructor: the state, the theta-weighted
  // displacement of a step and a sensitivity's input, the sensitivities (one column
  // per zone), the accelerations, the displacement over every node (the sensors' rows)
  // and the sensors' residuals of a step.
  Vector velocity_, displacement_, next_velocity_, next_displacement_, weighted_, force_;
  Matrix sensitivity_velocity_, sensitivity_, next_sensitivity_velocity_, next_sensitivity_;
  Vector acceleration_, acceleration_sensitivity_, nodal_, residuals_;

  long sweeps_ = 0;
};

}  // namespace testing
}  // namespace mcrewave
