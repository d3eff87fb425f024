// The coupled direct / retrograde MCRE problem as the coupled solvers see it
// (coupled_solver.h), whatever the structure (MatrixMcreProblem, matrix_mcre_problem.h,
// for a structure given by matrices, the built-in bar exported as matrices among them).
// docs/discrete_mcre.md states the problem; for a general
// structure docs/matrix_models.md gives the same equations with the load vectors G
// and the observation rows H:
//
//   DirectSweep:      W -> U, forward with the force G F~ - P W,  P = K + G diag(1/alpha) G^T
//   RetrogradeSweep:  U -> W, backward with the force c_j H^T diag(beta) (H U_j - d~_j)
//
// Fields are n x (m + 1) matrices (n dofs, column j = time t_j = j h). The iterative
// solvers need the sweeps and the inner product <x, y>_P only; the all-at-once
// reference solver assembles the space-time system from the matrices below.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

class CoupledProblem {
 public:
  virtual ~CoupledProblem() = default;

  virtual int num_nodes() const = 0;     // n, the dofs of a field's column
  virtual int num_steps() const = 0;     // m
  virtual double time_step() const = 0;  // h [s]
  virtual double theta() const = 0;
  // The zone moduli E_z [Pa] of the current factorisation.
  virtual const Vector& moduli() const = 0;
  int num_zones() const { return static_cast<int>(moduli().size()); }
  // Sets E_z (num_zones() entries, positive) and refactorises when they changed.
  virtual void SetModuli(const Vector& zone_moduli) = 0;
  // Sets every zone's modulus to E [Pa] (> 0); num_zones() must be known (moduli() not
  // empty).
  void SetModulus(double modulus) { SetModuli(Vector::Constant(num_zones(), modulus)); }

  // A zero field of the problem's shape, n x (m + 1).
  Matrix ZeroField() const { return Matrix::Zero(num_nodes(), num_steps() + 1); }
  // Quadrature weight c_j (1/2 at both ends, 1 inside).
  double QuadratureWeight(int j) const { return (j == 0 || j == num_steps()) ? 0.5 : 1.0; }

  // W -> U. With include_data the measured forces enter; without, the sweep is the
  // linear part only. U is resized if needed (outside the time loop).
  virtual void DirectSweep(const Matrix& retrograde, bool include_data, Matrix* displacement) = 0;
  // U -> W. With include_data the measured outputs d~ enter.
  virtual void RetrogradeSweep(const Matrix& displacement, bool include_data,
                               Matrix* retrograde) = 0;
  // Up to kMaxSweepBatch sweeps with the data at once, sweep b from inputs[b] (null:
  // the zero field) into outputs[b] (resized), outputs distinct from every input; the
  // results of the single sweeps, counted as that many sweeps. This default runs them
  // one after the other; MatrixMcreProblem interleaves them.
  static constexpr int kMaxSweepBatch = 3;
  virtual void DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
                                    const std::vector<Matrix*>& displacement);
  virtual void RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
                                        const std::vector<Matrix*>& retrograde);
  // The affine map T(W) = RetrogradeSweep(DirectSweep(W)) with the data: two sweeps.
  // displacement receives DirectSweep(W).
  void FixedPointMap(const Matrix& retrograde, Matrix* displacement, Matrix* image);
  // The linear part: G W = T(W) - T(0); two sweeps. scratch_displacement is work space.
  void ApplyIterationMap(const Matrix& retrograde, Matrix* scratch_displacement, Matrix* image);

  // <x, y>_P = sum_j c_j h x_j^T P y_j, in which A = I - G is self-adjoint.
  virtual double InnerProduct(const Matrix& x, const Matrix& y) = 0;
  double Norm(const Matrix& x) { return std::sqrt(std::max(0.0, InnerProduct(x, x))); }
  // e^2 = sum_j c_j h [1/2 W^T K W + 1/2 (G^T W)^T diag(1/alpha) G^T W
  //                    + 1/2 (H U - d~)^T diag(beta) (H U - d~)]  [J s].
  virtual double Cost(const Matrix& displacement, const Matrix& retrograde) = 0;
  // de^2/dE_z = -(1/(2 E_z)) sum_j c_j h W_j^T K_z(E_z) (W_j + 2 U_j) [J s / Pa];
  // gradient resized to num_zones().
  virtual void CostGradients(const Matrix& displacement, const Matrix& retrograde,
                             Vector* gradient) = 0;

  // The operators of the space-time system (all-at-once solver), at the current
  // moduli: M [kg], K [N/m], P = K + G diag(1/alpha) G^T [N/m], H^T diag(beta) H.
  virtual SparseMatrix MassMatrix() const = 0;
  virtual SparseMatrix StiffnessMatrix() const = 0;
  virtual SparseMatrix PenaltyMatrix() const = 0;
  // Whether P changes with the sample: a load known to vanish outside an interval
  // (docs/unmeasured_loads.md) has its G diag(1/alpha) G^T term only where it may act.
  // The solvers that take P as one matrix (Riccati, shooting) refuse such a problem;
  // the all-at-once solver takes PenaltyMatrixAt(j).
  virtual bool TimeVaryingPenalty() const { return false; }
  // P at sample j [N/m]; PenaltyMatrix() unless TimeVaryingPenalty().
  virtual SparseMatrix PenaltyMatrixAt(int /*j*/) const { return PenaltyMatrix(); }
  virtual SparseMatrix WeightedObservation() const = 0;
  // H^T diag(beta) d~_j [N] at sample j into load (size n).
  virtual void WeightedData(int j, Eigen::Ref<Vector> load) const = 0;
  // G F~_j [N], the measured forces at sample j, into load (size n).
  virtual void MeasuredForce(int j, Eigen::Ref<Vector> load) const = 0;

  // Number of sweeps (direct + retrograde) run since construction.
  long sweep_count() const { return sweep_count_; }

  // Work fields of the iterative coupled solvers, kept with the problem between
  // solves so that a solve on a problem solved before allocates no field (no page
  // faults of fresh fields; docs/performance.md). Each is resized by its user; `zero`
  // is the zero field, never written.
  struct SolverWorkspace {
    Matrix residual, direction, image, scratch, rhs, data_response;
    Matrix zero;
  };
  SolverWorkspace& workspace();

 protected:
  long sweep_count_ = 0;

 private:
  SolverWorkspace workspace_;
};

}  // namespace mcrewave
