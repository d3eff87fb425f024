#include "mcrewave/linalg/theta_integrator.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <utility>


namespace mcrewave {

int HalfBandwidth(const SparseMatrix& matrix) {
  int bandwidth = 0;
  for (int j = 0; j < matrix.outerSize(); ++j) {
    for (SparseMatrix::InnerIterator it(matrix, j); it; ++it) {
      bandwidth = std::max(bandwidth, static_cast<int>(std::abs(it.row() - it.col())));
    }
  }
  return bandwidth;
}

Factorization ChooseFactorization(Factorization requested, const SparseMatrix& mass,
                                  const SparseMatrix& stiffness) {
  if (requested != Factorization::kAutomatic) return requested;
  const int bandwidth = std::max(HalfBandwidth(mass), HalfBandwidth(stiffness));
  return bandwidth <= kMaxAutomaticBandwidth ? Factorization::kBand : Factorization::kSparse;
}

bool ThetaIntegratorOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(std::isfinite(time_step) && time_step > 0.0)) {
    why << "time step must be a finite positive number, got " << time_step;
  } else if (!(theta >= 0.0 && theta <= 1.0)) {
    why << "theta must lie in [0, 1], got " << theta;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

void ThetaIntegrator::Init(const SparseMatrix& mass, const SparseMatrix& stiffness,
                           const ThetaIntegratorOptions& options) {
  assert(options.IsValid(nullptr));
  assert(mass.rows() == stiffness.rows());
  options_ = options;
  sparse_path_ =
      ChooseFactorization(options.factorization, mass, stiffness) == Factorization::kSparse;
  if (sparse_path_) {
    // The sparse path (sparse_theta_step.h); the band members are released.
    mass_ = SymmetricBandMatrix();
    stiffness_ = SymmetricBandMatrix();
    free_state_matrix_ = SymmetricBandMatrix();
    iteration_matrix_ = BandLdlt();
    tridiagonal_ = false;
    ++factorization_count_;
    if (!sparse_.Compute(mass, stiffness, options.time_step, options.theta)) {
      throw std::runtime_error(
          "theta integrator: the iteration matrix M + h^2 theta^2 K is not positive definite");
    }
    const int n = size();
    force_ = Vector::Zero(n);
    for (int b = 0; b < 2; ++b) {
      v_[b] = Vector::Zero(n);
      u_[b] = Vector::Zero(n);
    }
    return;
  }
  mass_ = SymmetricBandMatrix(mass);
  stiffness_ = SymmetricBandMatrix(stiffness);
  const double h = options.time_step, theta = options.theta;
  // S = M + h^2 theta^2 K,  R = M - h^2 theta (1 - theta) K.
  const SymmetricBandMatrix schur =
      SymmetricBandMatrix::LinearCombination(1.0, mass_, h * h * theta * theta, stiffness_);
  free_state_matrix_ = SymmetricBandMatrix::LinearCombination(
      1.0, mass_, -h * h * theta * (1.0 - theta), stiffness_);
  ++factorization_count_;
  tridiagonal_ = schur.half_bandwidth() <= 1 && free_state_matrix_.half_bandwidth() <= 1;
  const bool factorised =
      tridiagonal_ ? tridiagonal_factor_.Compute(schur) : iteration_matrix_.Compute(schur);
  if (!factorised) {
    throw std::runtime_error(
        "theta integrator: the iteration matrix M + h^2 theta^2 K is not positive definite");
  }
  const int n = size();
  if (tridiagonal_) {
    free_diagonal_.resize(n);
    free_sub_ = Vector::Zero(n);
    stiffness_diagonal_.resize(n);
    stiffness_sub_ = Vector::Zero(n);
    for (int i = 0; i < n; ++i) {
      free_diagonal_[i] = free_state_matrix_.lower(0, i);
      stiffness_diagonal_[i] = -h * stiffness_.lower(0, i);
      if (i > 0 && free_state_matrix_.half_bandwidth() == 1) {
        free_sub_[i] = free_state_matrix_.lower(1, i);
      }
      if (i > 0 && stiffness_.half_bandwidth() == 1)
        stiffness_sub_[i] = -h * stiffness_.lower(1, i);
    }
    shifted_ = Vector::Zero(n);
    shifted_batch_ = Matrix::Zero(n, kMaxBatch);
  }
  force_ = Vector::Zero(n);
  for (int b = 0; b < 2; ++b) {
    v_[b] = Vector::Zero(n);
    u_[b] = Vector::Zero(n);
  }
}

template <bool kForceVector>
void ThetaIntegrator::TridiagonalRightHandSide(const double* v_k, const double* u_k,
                                               const double* z, const double* force, double f0,
                                               double fL, double* shifted, double* v_next,
                                               const PointLoads* point_loads) const {
  const int n = size();
  const double h = options_.time_step;
  const double* s = u_k;
  if (z != nullptr) {
    for (int i = 0; i < n; ++i) shifted[i] = u_k[i] + z[i];
    s = shifted;
  }
  const double* rd = free_diagonal_.data();
  const double* rs = free_sub_.data();
  const double* kd = stiffness_diagonal_.data();
  const double* ks = stiffness_sub_.data();
  // rhs_i = (R v_k)_i + (-h K s)_i + h f_i, rows 1..n-2 without tests, then the ends.
  for (int i = 1; i < n - 1; ++i) {
    double rhs = rd[i] * v_k[i] + rs[i] * v_k[i - 1] + rs[i + 1] * v_k[i + 1] + kd[i] * s[i] +
                 ks[i] * s[i - 1] + ks[i + 1] * s[i + 1];
    if constexpr (kForceVector) rhs += h * force[i];
    v_next[i] = rhs;
  }
  const int last = n - 1;
  double first_row = rd[0] * v_k[0] + kd[0] * s[0];
  if (n > 1) {
    first_row += rs[1] * v_k[1] + ks[1] * s[1];
    double last_row = rd[last] * v_k[last] + rs[last] * v_k[last - 1] + kd[last] * s[last] +
                      ks[last] * s[last - 1];
    if constexpr (kForceVector) last_row += h * force[last];
    v_next[last] = last_row + h * fL;
  }
  if constexpr (kForceVector) first_row += h * force[0];
  v_next[0] = first_row + h * f0;
  if (n == 1) v_next[0] += h * fL;
  // + h p_i e_{node_i}.
  if (point_loads != nullptr) {
    for (int i = 0; i < point_loads->count; ++i) {
      v_next[point_loads->nodes[i]] += h * point_loads->values[i];
    }
  }
}

TwistedTridiagonalLdlt::Update ThetaIntegrator::DisplacementUpdate(const double* u_k,
                                                                   const double* v_k,
                                                                   double* u_next) const {
  // u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1}.
  return {u_k, v_k, options_.time_step * (1.0 - options_.theta),
          options_.time_step * options_.theta, u_next};
}

template <bool kForceVector>
void ThetaIntegrator::TridiagonalStep(const double* v_k, const double* u_k, const double* z,
                                      const double* force, double f0, double fL, double* v_next,
                                      double* u_next, const PointLoads* point_loads) {
  TridiagonalRightHandSide<kForceVector>(v_k, u_k, z, force, f0, fL, shifted_.data(), v_next,
                                         point_loads);
  // S v_{k+1} = rhs, and u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1} row by row
  // as the solve finishes each v_{k+1, i}.
  tridiagonal_factor_.SolveInPlace(v_next, DisplacementUpdate(u_k, v_k, u_next));
}

template <int B>
void ThetaIntegrator::StepsWithEndLoads(const double* const (&v_k)[B],
                                        const double* const (&u_k)[B], const double* const (&z)[B],
                                        const double (&f0)[B], const double (&fL)[B],
                                        double* const (&v_next)[B], double* const (&u_next)[B],
                                        const PointLoads* const* point_loads) {
  static_assert(B >= 2 && B <= kMaxBatch, "2 or 3 steps at once");
  const int n = size();
  if (!tridiagonal_) {
    for (int b = 0; b < B; ++b) {
      using ConstMap = Eigen::Map<const Vector>;
      Eigen::Map<Vector> v_out(v_next[b], n), u_out(u_next[b], n);
      const PointLoads* loads = point_loads != nullptr ? point_loads[b] : nullptr;
      if (z[b] != nullptr) {
        StepWithEndLoads(ConstMap(v_k[b], n), ConstMap(u_k[b], n), ConstMap(z[b], n), f0[b], fL[b],
                         v_out, u_out, loads);
      } else {
        StepWithEndLoads(ConstMap(v_k[b], n), ConstMap(u_k[b], n), f0[b], fL[b], v_out, u_out,
                         loads);
      }
    }
    return;
  }
  for (int b = 0; b < B; ++b) {
    TridiagonalRightHandSide<false>(v_k[b], u_k[b], z[b], nullptr, f0[b], fL[b],
                                    shifted_batch_.col(b).data(), v_next[b],
                                    point_loads != nullptr ? point_loads[b] : nullptr);
  }
  TwistedTridiagonalLdlt::Update updates[B];
  for (int b = 0; b < B; ++b) updates[b] = DisplacementUpdate(u_k[b], v_k[b], u_next[b]);
  tridiagonal_factor_.SolveInPlace<B>(v_next, updates);
}

template void ThetaIntegrator::StepsWithEndLoads<2>(const double* const (&)[2],
                                                    const double* const (&)[2],
                                                    const double* const (&)[2], const double (&)[2],
                                                    const double (&)[2], double* const (&)[2],
                                                    double* const (&)[2], const PointLoads* const*);
template void ThetaIntegrator::StepsWithEndLoads<3>(const double* const (&)[3],
                                                    const double* const (&)[3],
                                                    const double* const (&)[3], const double (&)[3],
                                                    const double (&)[3], double* const (&)[3],
                                                    double* const (&)[3], const PointLoads* const*);

void ThetaIntegrator::Step(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
                           const Eigen::Ref<const Vector>& force_theta, Eigen::Ref<Vector> v_next,
                           Eigen::Ref<Vector> u_next) {
  if (tridiagonal_) {
    TridiagonalStep<true>(v_k.data(), u_k.data(), nullptr, force_theta.data(), 0.0, 0.0,
                          v_next.data(), u_next.data());
    return;
  }
  if (sparse_path_) {
    sparse_.Step(v_k.data(), u_k.data(), nullptr, force_theta.data(), 0.0, 0.0, nullptr,
                 v_next.data(), u_next.data());
    return;
  }
  const double h = options_.time_step;
  const double theta = options_.theta;
  // Free state and input: rhs = R v_k - h K u_k + h f_theta.
  SymmetricBandMatrix::MultiplyPairAdd(free_state_matrix_, v_k, -h, stiffness_, u_k, h, force_theta,
                                       v_next);
  // S v_{k+1} = rhs.
  iteration_matrix_.SolveInPlace(v_next);
  // u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1}.
  u_next = u_k + (h * (1.0 - theta)) * v_k + (h * theta) * v_next;
}

void ThetaIntegrator::StepTransposed(const Eigen::Ref<const Vector>& a_next,
                                     const Eigen::Ref<const Vector>& e_next, Eigen::Ref<Vector> y,
                                     Eigen::Ref<Vector> a_k, Eigen::Ref<Vector> e_k) {
  assert(a_next.size() == size() && e_next.size() == size());
  if (sparse_path_) {
    sparse_.StepTransposed(a_next.data(), e_next.data(), y.data(), a_k.data(), e_k.data());
    return;
  }
  const double h = options_.time_step;
  const double theta = options_.theta;
  // y = S^-1 (a_{k+1} + h theta e_{k+1})
  y = a_next + (h * theta) * e_next;
  if (tridiagonal_) {
    tridiagonal_factor_.SolveInPlace(y);
  } else {
    iteration_matrix_.SolveInPlace(y);
  }
  // a_k = R y + h (1 - theta) e_{k+1}
  free_state_matrix_.Multiply(y, a_k);
  a_k += (h * (1.0 - theta)) * e_next;
  // e_k = e_{k+1} - h K y
  e_k = e_next;
  stiffness_.MultiplyAdd(-h, y, e_k);
}

void ThetaIntegrator::StepWithEndLoads(const Eigen::Ref<const Vector>& v_k,
                                       const Eigen::Ref<const Vector>& u_k,
                                       const Eigen::Ref<const Vector>& z, double f0, double fL,
                                       Eigen::Ref<Vector> v_next, Eigen::Ref<Vector> u_next,
                                       const PointLoads* point_loads) {
  assert(z.size() == u_k.size());
  if (tridiagonal_) {
    TridiagonalStep<false>(v_k.data(), u_k.data(), z.data(), nullptr, f0, fL, v_next.data(),
                           u_next.data(), point_loads);
    return;
  }
  if (sparse_path_) {
    sparse_.Step(v_k.data(), u_k.data(), z.data(), nullptr, f0, fL, point_loads, v_next.data(),
                 u_next.data());
    return;
  }
  // f_theta = -K z + f0 e_0 + fL e_{n-1} + sum_i p_i e_{node_i}, formed in force_.
  stiffness_.Multiply(z, force_);
  force_ = -force_;
  AddEndAndPointLoads(f0, fL, point_loads);
  Step(v_k, u_k, force_, v_next, u_next);
}

void ThetaIntegrator::StepWithEndLoads(const Eigen::Ref<const Vector>& v_k,
                                       const Eigen::Ref<const Vector>& u_k, double f0, double fL,
                                       Eigen::Ref<Vector> v_next, Eigen::Ref<Vector> u_next,
                                       const PointLoads* point_loads) {
  if (tridiagonal_) {
    TridiagonalStep<false>(v_k.data(), u_k.data(), nullptr, nullptr, f0, fL, v_next.data(),
                           u_next.data(), point_loads);
    return;
  }
  if (sparse_path_) {
    sparse_.Step(v_k.data(), u_k.data(), nullptr, nullptr, f0, fL, point_loads, v_next.data(),
                 u_next.data());
    return;
  }
  force_.setZero();
  AddEndAndPointLoads(f0, fL, point_loads);
  Step(v_k, u_k, force_, v_next, u_next);
}

void ThetaIntegrator::StepShifted(const Eigen::Ref<const Vector>& v_k,
                                  const Eigen::Ref<const Vector>& u_k,
                                  const Eigen::Ref<const Vector>& z,
                                  const Eigen::Ref<const Vector>& force, Eigen::Ref<Vector> v_next,
                                  Eigen::Ref<Vector> u_next) {
  assert(z.size() == u_k.size() && force.size() == u_k.size());
  if (sparse_path_) {
    sparse_.Step(v_k.data(), u_k.data(), z.data(), force.data(), 0.0, 0.0, nullptr, v_next.data(),
                 u_next.data());
    return;
  }
  // Band paths: f_theta = force - K z formed in force_.
  stiffness_.Multiply(z, force_);
  force_ = force - force_;
  Step(v_k, u_k, force_, v_next, u_next);
}

void ThetaIntegrator::AddEndAndPointLoads(double f0, double fL, const PointLoads* point_loads) {
  force_[0] += f0;
  force_[size() - 1] += fL;
  if (point_loads == nullptr) return;
  for (int i = 0; i < point_loads->count; ++i) {
    force_[point_loads->nodes[i]] += point_loads->values[i];
  }
}

}  // namespace mcrewave
