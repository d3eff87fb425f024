// The sparse path of the theta integrator (theta_integrator.h): one step of
//
//     rhs = R v_k - h K (u_k + z) + h f,     R = M - h^2 theta (1 - theta) K,
//     S v_{k+1} = rhs,                        S = M + h^2 theta^2 K,
//     u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1},
//
// for general sparse symmetric M and K (a plate, a frame, a 3-D part: bandwidths that
// the band path of band_matrix.h would fill in). S is factorised by Eigen's
// SimplicialLDLT with the approximate minimum degree ordering (AMD); the symbolic
// analysis is kept while the pattern of S stays the same, so a new modulus costs one
// numeric factorisation. A step is
//   - one pass over the union pattern of M and K, R and -h K stored side by side on
//     it (the right-hand side, z and the force fused in);
//   - P, the forward solve with L, D^-1, the backward solve with L^T, P^T on the
//     factor's own arrays into preallocated scratch;
//   - the displacement update,
// and allocates nothing. Its cost: docs/matrix_models.md section 5.
#pragma once

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include "mcrewave/core/types.h"

namespace mcrewave {

struct PointLoads;

class SparseThetaStepper {
 public:
  // Builds R, -h K and S, and factorises S (reusing the symbolic analysis when the
  // pattern of S is that of the previous call). M and K: square, same size, symmetric
  // (both triangles stored). Returns false when S is not positive definite.
  bool Compute(const SparseMatrix& mass, const SparseMatrix& stiffness, double time_step,
               double theta);

  // One step (see the file comment); z and force may be null (zero). Adds f0 e_0 +
  // fL e_{n-1} and the point loads (nullable) to f. Outputs must not alias inputs.
  // No allocation.
  void Step(const double* v_k, const double* u_k, const double* z, const double* force, double f0,
            double fL, const PointLoads* point_loads, double* v_next, double* u_next);

  // The transposed step (ThetaIntegrator::StepTransposed): y = S^-1 (a + h theta e),
  // a_k = R y + h (1 - theta) e, e_k = e - h K y. Outputs must not alias inputs. No
  // allocation.
  void StepTransposed(const double* a_next, const double* e_next, double* y, double* a_k,
                      double* e_k);

  // x <- S^-1 x. No allocation.
  void SolveInPlace(double* x);
  // y = A x for A = M or K over the stored pattern (no allocation).
  void MultiplyMass(const double* x, double* y) const;
  void MultiplyStiffness(const double* x, double* y) const;

  int size() const { return static_cast<int>(mass_.rows()); }
  // Entries of L (strictly lower) plus the diagonal D: the factor's nonzeros.
  long factor_nonzeros() const;
  // Entries of the union pattern of M and K (both triangles).
  long pattern_nonzeros() const { return static_cast<long>(pattern_rows_.size()); }
  const SparseMatrix& mass() const { return mass_; }
  const SparseMatrix& stiffness() const { return stiffness_; }
  int analysis_count() const { return analysis_count_; }

 private:
  using Factor = Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>;

  SparseMatrix mass_, stiffness_;  // as given (compressed)
  double time_step_ = 0.0, theta_ = 0.5;
  // The union pattern of M and K in compressed columns (= rows: symmetric), with R
  // and -h K on it.
  std::vector<int> pattern_start_, pattern_rows_;
  std::vector<double> free_values_, stiffness_values_;
  SparseMatrix schur_;  // S, the pattern of the last analysis
  Factor factor_;
  bool analysed_ = false;
  int analysis_count_ = 0;
  std::vector<int> permutation_;  // P: scratch[i] = x[permutation_[i]]
  Vector inverse_pivot_;          // D^-1
  Vector scratch_;                // permuted right-hand side
};

}  // namespace mcrewave
