// The banded operators of the discrete MCRE system (docs/discrete_mcre.md) for the
// solvers that do not go through the problem's sweeps (Riccati, shooting): they
// apply single theta steps and band products to the columns of dense blocks, and
// count every multiply-accumulate they perform (include/mcrewave/core/operation_counts.h).
// They are built from the sparse operators of any CoupledProblem (coupled_problem.h):
// the built-in bar and a structure given by matrices alike.
//
// Notation (docs/riccati_shooting.md): n dofs, M mass, K stiffness, P = Kp = K + G
// diag(1/alpha) G^T (the penalty matrix), the data term W_obs = H^T diag(beta) H
// (symmetric positive semi-definite, possibly rank deficient) with the weighted data
// b_j = H^T diag(beta) d~_j and the measured loads G F~_j, and for the theta method
// with step h
//
//   S  = M + h^2 theta^2 K         (the iteration matrix of a step),
//   S' = M + h^2 (1 - theta)^2 K   (that of the step run backwards: shooting),
//   R  = M - h^2 theta (1 - theta) K,
//
// so that one step (u', v') = Phi (u, v) + Psi f of theta_integrator.h is
//
//   v' = S^-1 (R v - h K u + h f),   u' = u + h (1 - theta) v + h theta v',
//   i.e. Psi f = (h^2 theta S^-1 f, h S^-1 f).
//
// The observed dofs o_1..o_s are those where W_obs has a nonzero diagonal entry (a
// zero diagonal entry of a positive semi-definite matrix has a zero row and column),
// so W_obs = E_o W_s E_o^T with E_o the s columns of the identity at the observed
// dofs: the paper's end sensors give s = 2 and W_obs = beta (e_0 e_0^T + e_N e_N^T).
#pragma once

#include <vector>

#include "mcrewave/linalg/band_matrix.h"
#include "mcrewave/mcre/coupled_problem.h"

namespace mcrewave::internal {

// Cholesky factor L (A = L L^T) of a symmetric positive definite band matrix, in band
// storage: L^T x are the coordinates in which x^T A x is the squared 2-norm.
class BandCholesky {
 public:
  // Returns false when a pivot is not positive (A is not SPD).
  bool Compute(const SymmetricBandMatrix& matrix);
  // y = L^T x; y must not alias x.
  void MultiplyTransposed(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y) const;
  // x <- L^-T x.
  void SolveTransposed(Eigen::Ref<Vector> x) const;
  // Entries of L: the MACs of either operation.
  double entries() const;

 private:
  Matrix lower_;  // (p + 1) x n, lower_(d, i) = L(i, i - d)
};

// The observed dofs of a data term W_obs = H^T diag(beta) H: its nonzero diagonal
// entries, ascending.
std::vector<int> ObservedDofs(const SparseMatrix& weighted_observation);

class DiscreteMcreOperators {
 public:
  // Builds M, K, R, P and W_obs as band matrices from the problem's sparse operators
  // and factorises S, S', P and M at the problem's current moduli. The problem must
  // outlive this object. Throws std::runtime_error naming the matrix when S, S', P or
  // M is not positive definite.
  explicit DiscreteMcreOperators(const CoupledProblem& problem);

  int num_nodes() const { return num_nodes_; }
  int num_steps() const { return num_steps_; }
  // The half bandwidth of the union of the patterns of M, K and P.
  int half_bandwidth() const { return bandwidth_; }
  double time_step() const { return time_step_; }
  double theta() const { return theta_; }
  double QuadratureWeight(int j) const { return problem_.QuadratureWeight(j); }

  // The observed dofs o_1..o_s and W_obs e_{o_i}, the column of observed dof i.
  const std::vector<int>& observed_dofs() const { return observed_; }
  int num_observed() const { return static_cast<int>(observed_.size()); }
  Vector ObservationColumn(int i) const;

  // x += scale G F~_j, the measured loads at sample j [N].
  void AddMeasuredForce(int j, double scale, Eigen::Ref<Vector> x);
  // x += scale b_j, b_j = H^T diag(beta) d~_j the weighted data at sample j [N].
  void AddWeightedData(int j, double scale, Eigen::Ref<Vector> x);
  // y = W_obs x. y must not alias x.
  void ObservationProduct(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);

  // y = K x, y += scale K x, y = Kp x, y = R x. y must not alias x.
  void StiffnessProduct(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);
  void StiffnessProductAdd(double scale, const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);
  void PenaltyProduct(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);
  void FreeStateProduct(const Eigen::Ref<const Vector>& x, Eigen::Ref<Vector> y);
  // x <- S^-1 x and x <- S'^-1 x.
  void SolveStep(Eigen::Ref<Vector> x);
  void SolveReversedStep(Eigen::Ref<Vector> x);

  // Energy coordinates of a state pair (displacement-like a, velocity-like b):
  // (Lp^T a, Lm^T b) with Kp = Lp Lp^T, M = Lm Lm^T, so that the squared 2-norm of the
  // coordinates is a^T Kp a + b^T M b, an energy [J]. The trapezoidal step of the
  // uncoupled structure conserves it up to the springs G diag(1/alpha) G^T.
  void ToEnergyCoordinates(const Eigen::Ref<const Vector>& displacement_like,
                           const Eigen::Ref<const Vector>& velocity_like,
                           Eigen::Ref<Vector> displacement_coordinates,
                           Eigen::Ref<Vector> velocity_coordinates);
  // The inverse map, in place.
  void FromEnergyCoordinates(Eigen::Ref<Vector> displacement_like,
                             Eigen::Ref<Vector> velocity_like);

  // One theta step (u', v') = Phi (u, v) + Psi f; force may be null (f = 0). The
  // outputs must not alias the inputs.
  void ThetaStep(const Eigen::Ref<const Vector>& u, const Eigen::Ref<const Vector>& v,
                 const Vector* force, Eigen::Ref<Vector> u_next, Eigen::Ref<Vector> v_next);

  // Multiply-accumulates counted since construction, and a way for the solvers to
  // add those of their own dense and vector operations.
  double macs() const { return macs_; }
  void CountMacs(double macs) { macs_ += macs; }

 private:
  const CoupledProblem& problem_;
  int num_nodes_, num_steps_, bandwidth_;
  double time_step_, theta_;
  SymmetricBandMatrix stiffness_;   // K
  SymmetricBandMatrix penalty_;     // P
  SymmetricBandMatrix free_state_;  // R
  SparseMatrix observation_;        // W_obs
  std::vector<int> observed_;       // o_1..o_s
  BandLdlt step_factor_;            // S = L D L^T
  BandLdlt reversed_step_factor_;   // S' = L D L^T
  BandCholesky penalty_factor_;     // Kp = Lp Lp^T
  BandCholesky mass_factor_;        // M = Lm Lm^T
  Vector load_;                     // scratch of the data loads
  double macs_ = 0.0;
};

}  // namespace mcrewave::internal
