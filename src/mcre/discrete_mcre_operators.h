// The banded operators of the discrete MCRE system (docs/discrete_mcre.md) for the
// solvers that do not go through McreProblem's sweeps (Riccati, shooting): they
// apply single theta steps and band products to the columns of dense blocks, and
// count every multiply-accumulate they perform (include/mcrewave/core/operation_counts.h).
//
// Notation (docs/riccati_shooting.md): n nodes, M mass, K = E K1 stiffness,
// B = e_0 e_0^T + e_N e_N^T, Kp = K + B / alpha, and for the theta method with step h
//
//   S  = M + h^2 theta^2 K         (the iteration matrix of a step),
//   S' = M + h^2 (1 - theta)^2 K   (that of the step run backwards: shooting),
//   R  = M - h^2 theta (1 - theta) K,
//
// so that one step (u', v') = Phi (u, v) + Psi f of theta_integrator.h is
//
//   v' = S^-1 (R v - h K u + h f),   u' = u + h (1 - theta) v + h theta v',
//   i.e. Psi f = (h^2 theta S^-1 f, h S^-1 f).
#pragma once

#include "mcrewave/linalg/band_matrix.h"
#include "mcrewave/mcre/mcre_problem.h"

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

class DiscreteMcreOperators {
 public:
  // Builds M, K, R, Kp as band matrices and factorises S and S' at the problem's
  // current modulus. The problem must outlive this object.
  explicit DiscreteMcreOperators(const McreProblem& problem);

  int num_nodes() const { return num_nodes_; }
  int num_steps() const { return num_steps_; }
  int last_node() const { return num_nodes_ - 1; }
  int half_bandwidth() const { return bandwidth_; }  // of M and K
  double time_step() const { return time_step_; }
  double theta() const { return theta_; }
  double beta() const { return problem_.beta(); }
  double QuadratureWeight(int j) const { return problem_.QuadratureWeight(j); }

  // x += scale F~_j, the measured end forces as a nodal vector (f0_j at node 0, fL_j at N).
  void AddForceData(int j, double scale, Eigen::Ref<Vector> x) const;
  // x += scale U~_j, the measured end displacements as a nodal vector.
  void AddDisplacementData(int j, double scale, Eigen::Ref<Vector> x) const;

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
  // uncoupled bar conserves it up to the end springs B / alpha.
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
  const McreProblem& problem_;
  int num_nodes_, num_steps_, bandwidth_;
  double time_step_, theta_, inverse_alpha_;
  SymmetricBandMatrix stiffness_;   // K
  SymmetricBandMatrix free_state_;  // R
  BandLdlt step_factor_;            // S = L D L^T
  BandLdlt reversed_step_factor_;   // S' = L D L^T
  BandCholesky penalty_factor_;     // Kp = Lp Lp^T
  BandCholesky mass_factor_;        // M = Lm Lm^T
  double macs_ = 0.0;
};

}  // namespace mcrewave::internal
