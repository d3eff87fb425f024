#include "mcrewave/theta_integrator.h"

#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace mcrewave {

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
  mass_ = SymmetricBandMatrix(mass);
  stiffness_ = SymmetricBandMatrix(stiffness);
  const double h_theta = options.time_step * options.theta;
  // S = M + h^2 theta^2 K.
  const SymmetricBandMatrix schur =
      SymmetricBandMatrix::LinearCombination(1.0, mass_, h_theta * h_theta, stiffness_);
  ++factorization_count_;
  if (!iteration_matrix_.Compute(schur)) {
    throw std::runtime_error(
        "theta integrator: the iteration matrix M + h^2 theta^2 K is not positive definite");
  }
  const int n = size();
  shifted_displacement_ = Vector::Zero(n);
  force_ = Vector::Zero(n);
  for (int b = 0; b < 2; ++b) {
    v_[b] = Vector::Zero(n);
    u_[b] = Vector::Zero(n);
  }
}

void ThetaIntegrator::Step(const Eigen::Ref<const Vector>& v_k, const Eigen::Ref<const Vector>& u_k,
                           const Eigen::Ref<const Vector>& force_theta, Eigen::Ref<Vector> v_next,
                           Eigen::Ref<Vector> u_next) {
  const double h = options_.time_step;
  const double theta = options_.theta;
  // Free state: rhs = M v_k - h K (u_k + h theta (1 - theta) v_k).
  shifted_displacement_ = u_k + (h * theta * (1.0 - theta)) * v_k;
  mass_.Multiply(v_k, v_next);
  stiffness_.MultiplyAdd(-h, shifted_displacement_, v_next);
  // Input: rhs += h f_theta; then S v_{k+1} = rhs.
  v_next += h * force_theta;
  iteration_matrix_.SolveInPlace(v_next);
  // u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1}.
  u_next = u_k + (h * (1.0 - theta)) * v_k + (h * theta) * v_next;
}

}  // namespace mcrewave
