// Output-error least squares on a structure given by matrices (docs/formulation.md
// section 8, docs/matrix_models.md section 10), the comparator of MatrixZoneObjective:
// the model M U'' + K(E) U = G F~, K(E) = sum_z (E_z / E_z,nom) K_z, driven from rest
// by the measured loads alone, its outputs H U against the measured sensor channels,
//
//   J(E_1..E_Z) = 1/2 sum_j c_j h sum_k w_k (h_k U_j - d~_kj)^2      [s],
//
// c_j the trapezoidal weights (c_0 = c_m = 1/2, else 1). Each sensor is normalised by
// the misfit level of its kind, the bar's convention (ZoneOutputErrorObjective):
// w_k = 1 / s_u^2 for a displacement row, 1 / s_e^2 for a strain row (NoiseLevels; the
// loads are inputs, taken as exact, so s_f does not enter). The bar's clamp reaction
// f0, an output of its clamped model with inertia, has no counterpart here: a matrix
// model's outputs are rows of U.
//
// Scheme: the theta method of linalg/theta_integrator.h with f_theta = G F~_theta,
// X_theta = theta X_{k+1} + (1 - theta) X_k, one factorisation of
// M + h^2 theta^2 K(E) per set of moduli. Gradient by forward sensitivities
// S_z = dU/dE_z, each the same scheme from rest with the same factorisation and
//   f_theta = -(1/E_z,nom) K_z U_theta        (M S_z'' + K S_z = -(1/E_z,nom) K_z U),
// the exact derivative of the discrete J:
//   dJ/dE_z = sum_j c_j h sum_k w_k (h_k U_j - d~_kj) h_k S_z,j      [s / Pa].
// One sweep per evaluation without the gradient, 1 + Z with it; no allocation in the
// time loop (every scratch is sized in the constructor).
//
// Seen by the optimisers as MatrixZoneObjective is (optim/log_moduli_objective.h): as a
// function of p_z = log(E_z / E_z,nom), with J_scale = J_rest (J with every prediction
// 0).
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/log_moduli_objective.h"

namespace mcrewave {

class MatrixOutputErrorObjective : public LogModuliObjective {
 public:
  // Keeps a reference to model, which must outlive the objective; copies the histories
  // of data's channels named as the model's loads and sensors (data may go).
  // misfit_levels: s_u (> 0 when the model has a displacement sensor) and s_e (> 0 when
  // it has a strain sensor). Preconditions: data has a channel of each of the model's
  // loads and sensors (else throws std::logic_error) on t_j = j h and m >= 1 steps,
  // theta in [0, 1].
  MatrixOutputErrorObjective(const MatrixModelData& model, const ChannelSet& data,
                             const NoiseLevels& misfit_levels, double theta,
                             Factorization factorization = Factorization::kAutomatic);

  // J at the zone moduli [s] (num_parameters() entries [Pa], positive), and dJ/dE_z
  // [s / Pa] into *gradient when it is not null (resized to num_parameters()). Leaves
  // the outputs H U_j in outputs(). Re-initialises the integrator (the moduli change K).
  double Cost(const Vector& zone_moduli, Vector* gradient);

  // The outputs H U_j of the last Cost, one row per sensor in the model's order, one
  // column per sample [m] or [-].
  const Matrix& outputs() const { return outputs_; }
  // w_k [1/m^2 or 1], per sensor in the model's order.
  const Vector& sensor_weights() const { return weights_; }
  // J_rest = 1/2 sum_j c_j h sum_k w_k d~_kj^2 [s]; the cost scale (1 when J_rest = 0).
  double rest_cost() const { return rest_cost_; }
  double cost_scale() const override { return rest_cost_ > 0.0 ? rest_cost_ : 1.0; }
  // Simulations run: 1 per Cost, plus one per zone with the gradient.
  long sweeps() const { return sweeps_; }
  const ThetaIntegrator& integrator() const { return integrator_; }

 protected:
  bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient, std::string* why) override;

 private:
  const MatrixModelData& model_;
  double time_step_;  // h [s]
  double theta_;
  Factorization factorization_;
  Matrix measured_loads_;                     // F~ [N], C x (m + 1), rows in the model's order
  Matrix measured_outputs_;                   // d~ [m] or [-], S x (m + 1)
  Vector weights_;                            // w_k
  SparseMatrix loads_;                        // G, n x C
  SparseMatrix observation_;                  // H, S x n
  std::vector<SparseMatrix> zone_stiffness_;  // K_z / E_z,nom [N/(m Pa)]
  ThetaIntegrator integrator_;

  // Scratch of Cost, sized in the constructor: double buffers of the state, the
  // sensitivities (one column per zone, double buffered), the theta-weighted
  // displacement and loads of a step, a force vector, the residuals and the outputs.
  Vector velocity_[2], displacement_[2], weighted_, channel_, force_, residual_, trace_;
  Matrix sensitivity_velocity_[2], sensitivity_[2];
  Matrix outputs_;

  double rest_cost_ = 0.0;
  long sweeps_ = 0;
};

}  // namespace mcrewave
