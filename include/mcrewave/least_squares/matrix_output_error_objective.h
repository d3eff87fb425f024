// Output-error least squares on a structure given by matrices (docs/formulation.md
// section 8, docs/matrix_models.md section 10), the comparator of ZoneMcreObjective:
// the model M U'' + K(E) U = G F~, K(E) = sum_z (E_z / E_z,nom) K_z, driven from rest
// by the measured loads alone, its outputs H U against the measured sensor channels and
// (with supports) the supports' reactions r_s against their measured forces,
//
//   J(E_1..E_Z) = 1/2 sum_j c_j h [sum_k w_k (h_k U_j - d~_kj)^2
//                                  + w_f sum_s (r_s,j - f~_sj)^2]      [s],
//
// c_j the trapezoidal weights (c_0 = c_m = 1/2, else 1). Each sensor is normalised by
// the misfit level of its kind, the bar's convention (docs/comparator.md):
// w_k = 1 / s_u^2 for a displacement row, 1 / s_e^2 for a strain row, and a support's
// force by w_f = 1 / s_f^2 (NoiseLevels; the loads are inputs, taken as exact).
//
// Supports (docs/matrix_models.md section 11) are held, the bar's least squares' rigid
// clamp (the trusted treatment whatever mcre.clamp says): the rows and columns of their
// dofs D decoupled in M and K (diagonals kept), so U = 0 on D; a load's and a sensor
// row's entries on D dropped. A support's displacement channel is no output (U = 0
// there). Its reaction at t_j, with the inertia of the free dofs f as the bar's clamp
// reaction f0 = M_01 a_1 + K_01 u_1, is
//   r_s,j = g_s^T (K U_j + M a_j),   M_ff a_j = (G F~_j)_f - K_ff U_j,  a = 0 on D,
//         = q_s(E)^T U_j + p_s^T F~_j,
//   m_s = M_ff^-1 (M g_s)_f,  q_s(E) = [K(E) (g_s - m_s)]_f = sum_z E_z v_sz,
//   v_sz = [K_z (g_s - m_s)]_f / E_z,nom,  p_s = G_f^T m_s,
// (one solve with M per support, in the constructor), and its derivative
//   dr_s,j/dE_z = q_s^T S_z,j + v_sz^T U_j.
// Without mass coupling between D and the free dofs (m_s = 0) r_s is the trusted MCRE's
// g_s^T K U (MatrixMcreProblem::ModelSupportForces).
//
// Scheme: the theta method of linalg/theta_integrator.h with f_theta = G F~_theta,
// X_theta = theta X_{k+1} + (1 - theta) X_k, one factorisation of
// M + h^2 theta^2 K(E) per set of moduli. Gradient by forward sensitivities
// S_z = dU/dE_z, each the same scheme from rest with the same factorisation and
//   f_theta = -(1/E_z,nom) K_z U_theta        (M S_z'' + K S_z = -(1/E_z,nom) K_z U),
// the exact derivative of the discrete J:
//   dJ/dE_z = sum_j c_j h [sum_k w_k (h_k U_j - d~_kj) h_k S_z,j
//                          + w_f sum_s (r_s,j - f~_sj) dr_s,j/dE_z]      [s / Pa].
// One sweep per evaluation without the gradient, 1 + Z with it; no allocation in the
// time loop (every scratch is sized before it).
//
// Or (LeastSquaresGradient::kAdjoint) by the discrete adjoint (docs/matrix_models.md
// section 18): the forward sweep keeps U_0..U_m; then, backward from a_m = 0,
// e_m = g_m, the transposed steps of the same factorisation
// (ThetaIntegrator::StepTransposed),
//   y_k = S^-1 (a_{k+1} + h theta e_{k+1}),  a_k = R y_k + h (1 - theta) e_{k+1},
//   e_k = e_{k+1} - h K y_k + g_k,
//   g_j = dJ/dU_j = c_j h [H^T W (H U_j - d~_j) + w_f sum_s (r_s,j - f~_sj) q_s],
// and, the force of S_z being f_theta = -(1/E_z,nom) K_z U_theta,
//   dJ/dE_z = -h/E_z,nom sum_k y_k^T K_z U_theta,k
//             + sum_j c_j h w_f sum_s (r_s,j - f~_sj) v_sz^T U_j,
// the same derivative of the same discrete J as the forward sensitivities' up to
// round-off: two sweeps whatever Z, and n (m + 1) doubles for the trajectory.
//
// Seen by the optimisers as ZoneMcreObjective is (optim/log_moduli_objective.h): as a
// function of p_z = log(E_z / E_z,ref), E_z,ref the nominal moduli or one given scale,
// with J_scale = J_rest (J with every prediction 0).
#pragma once

#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"
#include "mcrewave/linalg/sparse_bilinear_form.h"
#include "mcrewave/linalg/theta_integrator.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/log_moduli_objective.h"

namespace mcrewave {

class MatrixOutputErrorObjective : public LogModuliObjective {
 public:
  // Keeps a reference to model, which must outlive the objective; copies the histories
  // of data's channels named as the model's loads, sensors and supports' forces (data
  // may go). misfit_levels: s_u (> 0 when the model has a displacement sensor), s_e
  // (> 0 when it has a strain sensor) and s_f (> 0 when it has a support).
  // Preconditions: data has a channel of each of the model's loads, sensors and
  // supports' forces (else throws std::logic_error) on t_j = j h and m >= 1 steps, theta
  // in [0, 1]. Throws std::runtime_error when the mass matrix of the free dofs cannot be
  // factorised (a model with supports). modulus_scale > 0: every zone's reference
  // E_z,ref of p_z = log(E_z / E_z,ref) [Pa] (the bar's zones: the homogeneous E*); 0:
  // the nominal moduli.
  MatrixOutputErrorObjective(const MatrixModelData& model, const ChannelSet& data,
                             const NoiseLevels& misfit_levels, double theta,
                             Factorization factorization = Factorization::kAutomatic,
                             double modulus_scale = 0.0);

  // J at the zone moduli [s] (num_parameters() entries [Pa], positive), and dJ/dE_z
  // [s / Pa] into *gradient when it is not null (resized to num_parameters()). With
  // fisher_information (then gradient must not be null), the Fisher information of the
  // moduli under white noise of the misfit levels on every output, the loads taken as
  // exact (Gauss-Newton: the expected curvature of chi^2 / 2, free of the residuals'
  // ripple), resized to Z x Z [1/Pa^2]:
  //   I_zz' = sum_j c_j [sum_k w_k (h_k S_z,j)(h_k S_z',j)
  //                      + w_f sum_s (dr_s,j/dE_z)(dr_s,j/dE_z')].
  // With sensor_information (then gradient must not be null), each sensor's own part of
  // it, one Z x Z matrix per sensor in the model's order [1/Pa^2]:
  //   I_k,zz' = sum_j c_j w_k (h_k S_z,j)(h_k S_z',j),
  // whose sum over the sensors is I without the supports' forces (the information of
  // any subset of the sensors: least_squares/sensor_placement.h).
  // Leaves the outputs H U_j in outputs() and the reactions r_s,j in support_forces().
  // Re-initialises the integrator (the moduli change K).
  double Cost(const Vector& zone_moduli, Vector* gradient, Matrix* fisher_information = nullptr,
              std::vector<Matrix>* sensor_information = nullptr);

  // How Cost's gradient is computed (the Fisher information always uses the forward
  // sensitivities). kAdjoint sizes the trajectory's n (m + 1) doubles here.
  void SetGradientMethod(LeastSquaresGradient method);
  LeastSquaresGradient gradient_method() const { return gradient_method_; }

  // The outputs H U_j of the last Cost, one row per sensor in the model's order, one
  // column per sample [m] or [-].
  const Matrix& outputs() const { return outputs_; }
  // The supports' reactions r_s,j of the last Cost, one row per support in the model's
  // order, one column per sample [N] (no row without supports).
  const Matrix& support_forces() const { return support_forces_; }
  // w_k [1/m^2 or 1], per sensor in the model's order.
  const Vector& sensor_weights() const { return weights_; }
  // w_f = 1 / s_f^2 [1/N^2] of the supports' forces (0 without supports).
  double force_weight() const { return force_weight_; }
  // J_rest = 1/2 sum_j c_j h [sum_k w_k d~_kj^2 + w_f sum_s f~_sj^2] [s]; the cost scale
  // (1 when J_rest = 0).
  double rest_cost() const { return rest_cost_; }
  double cost_scale() const override { return rest_cost_ > 0.0 ? rest_cost_ : 1.0; }
  // Simulations run: 1 per Cost, plus one per zone with the forward sensitivities'
  // gradient or one backward sweep with the adjoint's.
  long sweeps() const { return sweeps_; }
  const ThetaIntegrator& integrator() const { return integrator_; }

 protected:
  bool ModuliCost(const Vector& moduli, double* cost, Vector* gradient, std::string* why) override;
  // Logs one line per usable evaluation.
  void OnEvaluated(const Vector& moduli, double cost, double gradient_norm) override;

 private:
  // c_j of the trapezoidal sum over the samples t_0..t_m: 1/2 at both ends, else 1.
  double SampleWeight(int j) const {
    return (j == 0 || j == measured_outputs_.cols() - 1) ? 0.5 : 1.0;
  }
  // The supports' reaction rows v_sz and p_s (the header's formula), with held_ set.
  void BuildReactions(const ChannelSet& data, const NoiseLevels& misfit_levels);
  // The misfit of sample j (c_j h / 2 times the bracket of J) with the reactions into
  // support_forces_ and their residuals into force_residual_; adds its gradient term
  // into *gradient when it is not null.
  // With fisher_information, adds its terms of sample j too.
  double SampleCost(int j, const Vector& displacement, const Matrix& sensitivity, Vector* gradient,
                    Matrix* fisher_information, std::vector<Matrix>* sensor_information);
  // The adjoint's gradient (the header's formula) into *gradient (zeroed), from the
  // trajectory, outputs_ and support_forces_ of the forward sweep just run.
  void AdjointGradient(Vector* gradient);
  // g_j = dJ/dU_j into adjoint_load_ (the header's formula); with supports, adds the
  // explicit part of dJ/dE_z at t_j into *gradient.
  void AdjointLoad(int j, Vector* gradient);

  const MatrixModelData& model_;
  double time_step_;  // h [s]
  double theta_;
  Factorization factorization_;
  Matrix measured_loads_;                     // F~ [N], C x (m + 1), rows in the model's order
  Matrix measured_outputs_;                   // d~ [m] or [-], S x (m + 1)
  Vector weights_;                            // w_k
  SparseMatrix loads_;                        // G, n x C (held rows dropped)
  SparseMatrix observation_;                  // H, S x n (held columns dropped)
  std::vector<SparseMatrix> zone_stiffness_;  // K_z / E_z,nom [N/(m Pa)] (held decoupled)
  ThetaIntegrator integrator_;

  // Supports (none: every member below empty): the held dofs (1 on D), M with them
  // decoupled, the measured forces f~ [N] (R x (m + 1)), w_f [1/N^2], the rows v_sz
  // (R x n per zone [N/(m Pa)]), q_s(E) (R x n [N/m]) and p_s^T (R x C [-]).
  std::vector<char> held_;
  SparseMatrix held_mass_;
  Matrix measured_forces_;
  double force_weight_ = 0.0;
  std::vector<Matrix> reaction_zone_rows_;
  Matrix reaction_rows_, reaction_loads_;

  // Scratch of Cost, sized in the constructor (the Fisher information's below, on its
  // first request, before the time loop): double buffers of the state, the
  // sensitivities (one column per zone, double buffered), the theta-weighted
  // displacement and loads of a step, a force vector, the residuals and the outputs;
  // the reactions' residuals and derivatives.
  Vector velocity_[2], displacement_[2], weighted_, channel_, force_, residual_, trace_;
  Vector force_residual_, force_trace_;
  Matrix sensitivity_velocity_[2], sensitivity_[2];
  Matrix outputs_, support_forces_;
  // The outputs' and reactions' derivatives of a sample, one column per zone (the
  // Fisher information's; sized on its first request).
  Matrix output_sensitivity_, force_sensitivity_;
  Vector sensor_sensitivity_;  // one sensor's row of output_sensitivity_ (Z entries)

  // The adjoint (kAdjoint): U_j by columns, n x (m + 1); the zones' forms
  // x^T (K_z / E_z,nom) y; the adjoint state (a, e) double buffered, y_k, g_j and the
  // weighted residuals.
  LeastSquaresGradient gradient_method_ = LeastSquaresGradient::kForwardSensitivities;
  Matrix trajectory_;
  std::vector<SparseBilinearForm> zone_forms_;
  Vector adjoint_velocity_[2], adjoint_displacement_[2], adjoint_force_, adjoint_load_;
  Vector weighted_residual_;

  double rest_cost_ = 0.0;
  long sweeps_ = 0;
};

}  // namespace mcrewave
