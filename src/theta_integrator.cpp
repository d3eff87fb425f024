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
  const double h = options.time_step, theta = options.theta;
  // S = M + h^2 theta^2 K,  R = M - h^2 theta (1 - theta) K.
  const SymmetricBandMatrix schur =
      SymmetricBandMatrix::LinearCombination(1.0, mass_, h * h * theta * theta, stiffness_);
  free_state_matrix_ = SymmetricBandMatrix::LinearCombination(
      1.0, mass_, -h * h * theta * (1.0 - theta), stiffness_);
  ++factorization_count_;
  if (!iteration_matrix_.Compute(schur)) {
    throw std::runtime_error(
        "theta integrator: the iteration matrix M + h^2 theta^2 K is not positive definite");
  }
  const int n = size();
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
  // Free state and input: rhs = R v_k - h K u_k + h f_theta.
  SymmetricBandMatrix::MultiplyPairAdd(free_state_matrix_, v_k, -h, stiffness_, u_k, h, force_theta,
                                       v_next);
  // S v_{k+1} = rhs.
  iteration_matrix_.SolveInPlace(v_next);
  // u_{k+1} = u_k + h (1 - theta) v_k + h theta v_{k+1}.
  u_next = u_k + (h * (1.0 - theta)) * v_k + (h * theta) * v_next;
}

}  // namespace mcrewave
