// The theta-method time integrator of M u'' + K u = f(t) (docs/formulation.md section 5),
// in first-order form with v = u':
//
//     rhs = R v_k - h K u_k,          R = M - h^2 theta (1 - theta) K   (free state)
//     S v_{k+1} = rhs + h f_theta,    S = M + h^2 theta^2 K             (input)
//     u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1},
//
// f_theta the step's theta-weighted force, formed by the caller. S (the Schur complement
// of the first-order iteration matrix; SPD) is factorised once in Init. theta = 1/2 is
// the trapezoidal rule (second order, energy conserving), theta = 1 backward Euler.
//
// Paths, chosen by ThetaIntegratorOptions::factorization (kAutomatic: ChooseFactorization):
// tridiagonal M and K (the bar) one branch-free pass for the right-hand side and the
// twisted factorisation of band_matrix.h; other bands SymmetricBandMatrix and BandLdlt;
// general sparse M and K the sparse LDL^T of sparse_theta_step.h. They solve the same
// system and differ by round-off.
//
// StepWithEndLoads forms, in the same pass, the force of the MCRE sweeps
// f_theta = -K z + f0 e_0 + fL e_{n-1} (+ point loads: the interior sensors' loads of
// the retrograde sweep). SweepBackward runs the retrograde problem in reversed time
// tau = T - t from a final state, from index m down to 0; the "velocity" it carries is
// then du/dtau = -du/dt. The integrator knows nothing of MCRE.
#pragma once

#include <utility>

#include "mcrewave/core/types.h"
#include "mcrewave/linalg/band_matrix.h"
#include "mcrewave/linalg/sparse_theta_step.h"

namespace mcrewave {

// Point loads p_i [N] at nodes node_i, a few per step (sensor loads); the arrays
// belong to the caller and must hold `count` entries each.
struct PointLoads {
  int count = 0;
  const int* nodes = nullptr;
  const double* values = nullptr;  // [N]
};

// kAutomatic's choice for M and K: kBand when the half bandwidth p of their union
// is at most kMaxAutomaticBandwidth (the bar: p = 1), else kSparse
// (docs/matrix_models.md section 5). Other values are returned as they are.
constexpr int kMaxAutomaticBandwidth = 32;
Factorization ChooseFactorization(Factorization requested, const SparseMatrix& mass,
                                  const SparseMatrix& stiffness);
// The largest |i - j| of a stored entry.
int HalfBandwidth(const SparseMatrix& matrix);

struct ThetaIntegratorOptions {
  double time_step = 0.36e-6;  // h [s]
  double theta = 0.5;          // implicitness, in [0, 1]; 1/2 = trapezoidal
  Factorization factorization = Factorization::kAutomatic;

  bool IsValid(std::string* error) const;
};

class ThetaIntegrator {
 public:
  // Builds and factorises S = M + h^2 theta^2 K and allocates every scratch vector.
  // M must be SPD and K symmetric positive semi-definite. Call again
  // (re-initialise) whenever K (the modulus), h or theta changes. Throws
  // std::runtime_error if S is not positive definite.
  void Init(const SparseMatrix& mass, const SparseMatrix& stiffness,
            const ThetaIntegratorOptions& options);

  // One step from (v_k, u_k) with the theta-weighted force f_theta of the step.
  // Writes (v_next, u_next); they must not alias the inputs. No allocation.
  void Step(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
            const Eigen::Ref<const Vector>& force_theta, Eigen::Ref<Vector> v_next,
            Eigen::Ref<Vector> u_next);

  // One step with the force f_theta = -K z + f0 e_0 + fL e_{n-1} [N] (z [m], same
  // size as u_k) or, without z, f_theta = f0 e_0 + fL e_{n-1}. Same contract as
  // Step otherwise.
  // point_loads (nullable) adds its loads to f_theta.
  void StepWithEndLoads(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
                        const Eigen::Ref<const Vector>& z, double f0, double fL,
                        Eigen::Ref<Vector> v_next, Eigen::Ref<Vector> u_next,
                        const PointLoads* point_loads = nullptr);
  void StepWithEndLoads(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
                        double f0, double fL, Eigen::Ref<Vector> v_next, Eigen::Ref<Vector> u_next,
                        const PointLoads* point_loads = nullptr);

  // One step with the force f_theta = -K z + force [N] (z [m]): the direct sweep of
  // a general model, whose loads are vectors rather than end forces. Same contract as
  // Step. No allocation.
  void StepShifted(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
                   const Eigen::Ref<const Vector>& z, const Eigen::Ref<const Vector>& force,
                   Eigen::Ref<Vector> v_next, Eigen::Ref<Vector> u_next);

  // The transpose of Step, the step of the discrete adjoint: given the adjoints
  // (a_{k+1}, e_{k+1}) of (v_{k+1}, u_{k+1}), those of (v_k, u_k) and of the step's
  // force (J a scalar function of the states, a = dJ/dv, e = dJ/du; docs/
  // matrix_models.md section 18):
  //   y = S^-1 (a_{k+1} + h theta e_{k+1}),      dJ/df_theta = h y,
  //   a_k = R y + h (1 - theta) e_{k+1},
  //   e_k = e_{k+1} - h K y,
  // M and K symmetric. Writes y, a_k and e_k; they must not alias the inputs. No
  // allocation.
  void StepTransposed(const Eigen::Ref<const Vector>& a_next,
                      const Eigen::Ref<const Vector>& e_next, Eigen::Ref<Vector> y,
                      Eigen::Ref<Vector> a_k, Eigen::Ref<Vector> e_k);

  // B independent steps at once (B = 2 or 3), step b as StepWithEndLoads from
  // (v_k[b], u_k[b]) with z[b] (null: none), f0[b], fL[b]; all arrays of size()
  // contiguous doubles, outputs distinct from every input; point_loads[b] (nullable,
  // or the whole array null) as in StepWithEndLoads. The tridiagonal solves
  // run interleaved (about the latency of one); the results are those of B single
  // steps, bit for bit.
  static constexpr int kMaxBatch = 3;
  template <int B>
  void StepsWithEndLoads(const double* const (&v_k)[B], const double* const (&u_k)[B],
                         const double* const (&z)[B], const double (&f0)[B], const double (&fL)[B],
                         double* const (&v_next)[B], double* const (&u_next)[B],
                         const PointLoads* const* point_loads = nullptr);

  // Runs num_steps steps forward in time from (v0, u0).
  //   forcing(k, f): writes into f (an Eigen::Ref<Vector> of size n) the force
  //                  f_theta of the step t_k -> t_{k+1};
  //   observer(k, v, u): called for k = 0, ..., num_steps with the state at t_k.
  template <typename Forcing, typename Observer>
  void SweepForward(int num_steps, const Eigen::Ref<const Vector>& v0,
                    const Eigen::Ref<const Vector>& u0, Forcing&& forcing, Observer&& observer);

  // Runs num_steps steps backward in time from the final state (v_T, u_T) at
  // t_m = T, with v = du/dtau = -du/dt.
  //   forcing(k, f): the force f_theta of the step t_{k+1} -> t_k (k = m-1 .. 0);
  //   observer(k, v, u): called for k = num_steps, ..., 0.
  template <typename Forcing, typename Observer>
  void SweepBackward(int num_steps, const Eigen::Ref<const Vector>& v_final,
                     const Eigen::Ref<const Vector>& u_final, Forcing&& forcing,
                     Observer&& observer);

  int size() const { return sparse_path_ ? sparse_.size() : static_cast<int>(mass_.size()); }
  const ThetaIntegratorOptions& options() const { return options_; }
  // The path Init took: kBand or kSparse.
  Factorization factorization() const {
    return sparse_path_ ? Factorization::kSparse : Factorization::kBand;
  }
  // M and K as band matrices: the band path only (empty on the sparse path).
  const SymmetricBandMatrix& mass() const { return mass_; }
  const SymmetricBandMatrix& stiffness() const { return stiffness_; }
  // The sparse path's M, K, factor and products (sparse path only).
  const SparseThetaStepper& sparse() const { return sparse_; }
  // Number of factorisations of the iteration matrix since construction.
  int factorization_count() const { return factorization_count_; }

 private:
  template <typename Forcing, typename Observer>
  void Sweep(int num_steps, int first, int direction, const Eigen::Ref<const Vector>& v_start,
             const Eigen::Ref<const Vector>& u_start, Forcing&& forcing, Observer&& observer);

  // The tridiagonal fast path: rhs = R v_k - h K s + h f (f: the full force when
  // kForceVector, else only f0 e_0 + fL e_{n-1}), solve, u update. s = u_k + z when
  // z is not null, else u_k.
  template <bool kForceVector>
  void TridiagonalStep(const double* v_k, const double* u_k, const double* z, const double* force,
                       double f0, double fL, double* v_next, double* u_next,
                       const PointLoads* point_loads = nullptr);
  // The parts of TridiagonalStep: rhs into v_next (shifted: scratch for u_k + z),
  // and u_next = u_k + h (1 - theta) v_k + h theta v_next.
  template <bool kForceVector>
  void TridiagonalRightHandSide(const double* v_k, const double* u_k, const double* z,
                                const double* force, double f0, double fL, double* shifted,
                                double* v_next, const PointLoads* point_loads) const;
  // f_theta's end and point loads added into force_ (the banded path).
  void AddEndAndPointLoads(double f0, double fL, const PointLoads* point_loads);
  // The tridiagonal solve's fused update u_{k+1} = u_k + h (1 - theta) v_k
  // + h theta v_{k+1} into u_next.
  TwistedTridiagonalLdlt::Update DisplacementUpdate(const double* u_k, const double* v_k,
                                                    double* u_next) const;

  ThetaIntegratorOptions options_;
  bool sparse_path_ = false;
  SparseThetaStepper sparse_;              // the sparse path
  SymmetricBandMatrix mass_;               // M
  SymmetricBandMatrix stiffness_;          // K
  SymmetricBandMatrix free_state_matrix_;  // R = M - h^2 theta (1 - theta) K
  BandLdlt iteration_matrix_;              // LDL^T of S = M + h^2 theta^2 K (bandwidth > 1)
  // The tridiagonal fast path (half bandwidth <= 1).
  bool tridiagonal_ = false;
  TwistedTridiagonalLdlt tridiagonal_factor_;  // S
  // The bands of R and -h K: diagonal [i] = row i, sub-diagonal [i] = (i, i-1)
  // ([0] unused).
  Vector free_diagonal_, free_sub_;            // R
  Vector stiffness_diagonal_, stiffness_sub_;  // -h K
  Vector shifted_;                             // scratch: s = u_k + z
  Matrix shifted_batch_;                       // the same for StepsWithEndLoads, n x kMaxBatch
  int factorization_count_ = 0;
  // Scratch, allocated in Init.
  Vector force_;        // f_theta handed to forcing()
  Vector v_[2], u_[2];  // double buffer of the state
};

template <typename Forcing, typename Observer>
void ThetaIntegrator::Sweep(int num_steps, int first, int direction,
                            const Eigen::Ref<const Vector>& v_start,
                            const Eigen::Ref<const Vector>& u_start, Forcing&& forcing,
                            Observer&& observer) {
  v_[0] = v_start;
  u_[0] = u_start;
  int k = first;
  observer(k, static_cast<const Vector&>(v_[0]), static_cast<const Vector&>(u_[0]));
  for (int s = 0; s < num_steps; ++s) {
    const int cur = s & 1, nxt = cur ^ 1;
    // Forward: step k -> k+1 has index k. Backward: step k -> k-1 has index k-1.
    forcing(direction > 0 ? k : k - 1, Eigen::Ref<Vector>(force_));
    Step(v_[cur], u_[cur], force_, v_[nxt], u_[nxt]);
    k += direction;
    observer(k, static_cast<const Vector&>(v_[nxt]), static_cast<const Vector&>(u_[nxt]));
  }
}

template <typename Forcing, typename Observer>
void ThetaIntegrator::SweepForward(int num_steps, const Eigen::Ref<const Vector>& v0,
                                   const Eigen::Ref<const Vector>& u0, Forcing&& forcing,
                                   Observer&& observer) {
  Sweep(num_steps, 0, +1, v0, u0, std::forward<Forcing>(forcing), std::forward<Observer>(observer));
}

template <typename Forcing, typename Observer>
void ThetaIntegrator::SweepBackward(int num_steps, const Eigen::Ref<const Vector>& v_final,
                                    const Eigen::Ref<const Vector>& u_final, Forcing&& forcing,
                                    Observer&& observer) {
  Sweep(num_steps, num_steps, -1, v_final, u_final, std::forward<Forcing>(forcing),
        std::forward<Observer>(observer));
}

}  // namespace mcrewave
