// Output-error least squares (finite-element model updating, FEMU) on the built-in bar's
// own band model: the tests' independent reference for OutputErrorModulusObjective and
// MatrixOutputErrorObjective on the bar exported as matrices, which identify run and the
// studies use (docs/formulation.md section 8, docs/comparator.md). The library held it
// as its bar road until issue 39; it lives here as the other code path the objectives
// on the one road are checked against. The bar clamped at
// x = 0 (u_0 = 0), driven at x = L by the measured fL~ in the theta scheme of
// linalg/theta_integrator.h, its predicted outputs against the other measured channels,
// each kind normalised by its noise level:
//
//   J(E) = 1/2 sum_k c_k h [ sum_{u channels} (u_k - u~_k)^2 / s_u^2
//                           + (f0_k - f0~_k)^2 / s_f^2
//                           + sum_{e channels} (e_k - e~_k)^2 / s_e^2 ]      [s],
//
// c_k the trapezoidal weights. The u channels are uL and the interior u@X in use (u0 is
// zero in the model and never enters), f0 the clamp reaction
// f0_k = row_0(M a_k + K u_k), M_r a_k = fL~_k e_N - K_r u_k (as model/simulation.h
// makes the synthetic f0). dJ/dE comes from the forward sensitivity du_k/dE, which obeys
// the same scheme with the input -K1 (theta u_{k+1} + (1 - theta) u_k): two sweeps per
// evaluation with the gradient, one without, no inner iteration. J_rest: J with every
// prediction 0.
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

namespace mcrewave {
namespace testing {

// The outputs of the clamped model at one modulus, on the data's samples.
struct OutputErrorPrediction {
  double modulus = -1.0;       // E [Pa]
  double cost = -1.0;          // J(E) [s] (misfits normalised by the noise levels)
  double cost_gradient = 0.0;  // dJ/dE [s / Pa] (0 when not asked for)
  // The Fisher information of E under white noise of the normalisation's levels,
  //   I = sum_k c_k sum_channels (dy_k/dE)^2 / s^2  [1/Pa^2]
  // (Gauss-Newton: the expected curvature of chi^2 / 2, free of the residuals'
  // ripple), with the gradient (0 when not asked for); std(E) >= 1 / sqrt(I).
  double fisher_information = 0.0;
  Vector uL;                    // [m], one per sample
  Vector f0;                    // [N], the clamp reaction
  std::vector<Vector> sensors;  // per interior sensor of the data [m] or [-]
};

// The observation rows of the data's interior sensors on `model`'s mesh, in the
// data's order, and the weight 1 / s^2 of each one's kind (noise: > 0 for every kind
// the data hold). Overwrites rows and weights.
void OutputErrorSensorRows(const BarModel& model, const ChannelSet& data, const NoiseLevels& noise,
                           std::vector<ObservationRow>* rows, std::vector<double>* weights);
// J_rest [s]: J with every prediction 0,
//   1/2 sum_k c_k h [uL~_k^2 / s_u^2 (when ends.uL) + f0~_k^2 / s_f^2
//                    + sum_sensors sensor_weight y~_k^2].
double OutputErrorRestCost(const ChannelSet& data, const NoiseLevels& noise,
                           const std::vector<double>& sensor_weights, EndDisplacementChannels ends);

// The clamp reaction of the clamped model at one sample: the accelerations of the free
// nodes from M_r a = fL e_N - K_r u into *acceleration (size of u), then
//   f0 = M_01 a_1 + K_01 u_1  [N]   (free node 1 is index 0).
// stiffness: K_r of the integrator's band path; mass_factor: of M_r.
double ClampReaction(const SymmetricBandMatrix& stiffness, const BandLdlt& mass_factor,
                     double mass_01, double stiffness_01, const Vector& displacement, double fL,
                     Vector* acceleration);

// What both band-model references take from the bar and the data: the data's end
// channels and interior sensors, M's free block M_r, M(0, 1) and the factor of M_r, the
// interior sensors' rows on the bar's mesh with the weight 1 / s^2 of each one's kind,
// and J_rest. Keeps pointers into data, which must outlive it.
struct ClampedBarData {
  ClampedBarData(const BarModel& model, const ChannelSet& data, const NoiseLevels& noise,
                 EndDisplacementChannels ends);
  BarEnds measured;                        // data's end channels
  std::vector<const Vector*> sensor_data;  // data's interior sensors (BarSensorValues)
  SparseMatrix free_mass;                  // M_r
  double mass_01 = 0.0;                    // M(0, 1)
  BandLdlt mass_factor;                    // of M_r
  std::vector<ObservationRow> sensor_rows;
  std::vector<double> sensor_weights;
  double rest_cost = 0.0;  // J_rest [s] (OutputErrorRestCost)
};

class BarLeastSquares {
 public:
  // Keeps references to model and data: both must outlive the reference. The
  // model must have one zone. noise: the levels s_u, s_f, s_e of the misfit's
  // normalisation (> 0 for every kind the data hold). ends: whether uL enters
  // (ends.uL; u0 never does). theta in [0, 1], modulus_scale > 0 [Pa].
  BarLeastSquares(const BarModel& model, const ChannelSet& data, const NoiseLevels& noise,
                  double theta, double modulus_scale, EndDisplacementChannels ends = {});

  long sweeps() const { return sweeps_; }
  // PredictedValleySpacing (optim/valley_spacing.h) of the predicted outputs (uL, f0,
  // the sensors) at E = modulus_scale, weighted by 1 / s^2 of their kind: one sweep.
  double ValleySpacing();

  // Simulates the clamped model at E [Pa] (> 0): predictions and J, and dJ/dE when
  // gradient_requested. Re-initialises the integrator (E changes K).
  const OutputErrorPrediction& Predict(double modulus, bool gradient_requested);

  // J_rest [s]: J with every prediction 0; the cost scale (1 when J_rest = 0).
  double rest_cost() const { return bar_.rest_cost; }
  double cost_scale() const { return bar_.rest_cost > 0.0 ? bar_.rest_cost : 1.0; }

 private:
  const BarModel& model_;
  const ChannelSet& data_;
  ClampedBarData bar_;
  NoiseLevels noise_;
  double theta_;
  double modulus_scale_;
  EndDisplacementChannels ends_;

  SparseMatrix free_stiffness_one_;  // K1 on the free nodes (K_r = E K1_r)
  double stiffness_one_01_ = 0.0;    // K1(0, 1)
  ThetaIntegrator integrator_;

  // Scratch of Predict, sized in the constructor.
  Vector velocity_, displacement_, next_velocity_, next_displacement_;
  Vector sensitivity_velocity_, sensitivity_, next_sensitivity_velocity_, next_sensitivity_;
  Vector shift_, acceleration_, acceleration_sensitivity_, nodal_;

  OutputErrorPrediction prediction_;
  long sweeps_ = 0;
};

}  // namespace testing
}  // namespace mcrewave
