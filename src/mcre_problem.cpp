#include "mcrewave/mcre_problem.h"

#include <cassert>
#include <cmath>
#include <sstream>

namespace mcrewave {

bool McreWeights::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!(std::isfinite(displacement_weight) && displacement_weight > 0.0)) {
    why << "mcre.w_u must be a finite positive number, got " << displacement_weight;
  } else if (!(std::isfinite(force_weight) && force_weight > 0.0)) {
    why << "mcre.w_f must be a finite positive number, got " << force_weight;
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

McreProblem::McreProblem(const BarModel& model, const MeasurementSet& data,
                         const McreWeights& weights, double reference_modulus, double theta)
    : model_(model), data_(data), theta_(theta), unit_stiffness_(model.unit_stiffness()) {
  assert(weights.IsValid(nullptr) && data.num_steps() >= 1 && reference_modulus > 0.0);
  const BarProperties& bar = model.properties();
  // beta = w_u S E0 / L, alpha = w_f L / (S E0)  (formulation.md section 2).
  beta_ = weights.displacement_weight * bar.section * reference_modulus / bar.length;
  alpha_ = weights.force_weight * bar.length / (bar.section * reference_modulus);
  const int n = model.num_nodes();
  force_now_ = Vector::Zero(n);
  force_next_ = Vector::Zero(n);
  omega_previous_ = Vector::Zero(n);
  product_ = Vector::Zero(n);
  rest_state_ = Vector::Zero(n);
  SetModulus(bar.modulus);
}

void McreProblem::SetModulus(double modulus) {
  assert(modulus > 0.0);
  if (modulus == modulus_) return;
  modulus_ = modulus;
  ThetaIntegratorOptions options;
  options.time_step = data_.time_step;
  options.theta = theta_;
  integrator_.Init(model_.mass(), model_.Stiffness(modulus), options);
}

void McreProblem::DirectSweep(const Matrix& retrograde, bool include_data, Matrix* displacement) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  assert(retrograde.rows() == n && retrograde.cols() == m + 1);
  displacement->resize(n, m + 1);
  const SymmetricBandMatrix& stiffness = integrator_.stiffness();
  const double inverse_alpha = 1.0 / alpha_;
  // g_j = F~_j - (K + B/alpha) W_j, written into `force`.
  auto nodal_force = [&](int j, Vector& force) {
    stiffness.Multiply(retrograde.col(j), force);
    force = -force;
    force[0] -= inverse_alpha * retrograde(0, j);
    force[last] -= inverse_alpha * retrograde(last, j);
    if (include_data) {
      force[0] += data_.f0[j];
      force[last] += data_.fL[j];
    }
  };
  nodal_force(0, force_now_);
  integrator_.SweepForward(
      m, rest_state_, rest_state_,
      [&](int k, Eigen::Ref<Vector> force) {
        // f_theta = theta g_{k+1} + (1 - theta) g_k.
        nodal_force(k + 1, force_next_);
        force = theta_ * force_next_ + (1.0 - theta_) * force_now_;
        force_now_.swap(force_next_);
      },
      [&](int k, const Vector&, const Vector& u) { displacement->col(k) = u; });
  ++sweep_count_;
}

void McreProblem::RetrogradeSweep(const Matrix& displacement, bool include_data,
                                  Matrix* retrograde) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  assert(displacement.rows() == n && displacement.cols() == m + 1);
  retrograde->resize(n, m + 1);
  integrator_.SweepBackward(
      m, rest_state_, rest_state_,
      [&](int k, Eigen::Ref<Vector> force) {
        // Step t_{k+1} -> t_k carries the force c_{k+1} beta (B U_{k+1} - U~_{k+1}) (R2).
        const int j = k + 1;
        const double weight = QuadratureWeight(j) * beta_;
        force.setZero();
        force[0] = weight * displacement(0, j);
        force[last] = weight * displacement(last, j);
        if (include_data) {
          force[0] -= weight * data_.u0[j];
          force[last] -= weight * data_.uL[j];
        }
      },
      [&](int j, const Vector&, const Vector& omega) {
        // W_{j+1} = (theta omega_j + (1 - theta) omega_{j+1}) / c_{j+1}  (R3), omega_m = 0.
        if (j < m) {
          retrograde->col(j + 1) =
              (theta_ * omega + (1.0 - theta_) * omega_previous_) / QuadratureWeight(j + 1);
        }
        if (j == 0) {
          // W_0 = (1 - theta) omega_0 / c_0 (omega_{-1} = 0).
          retrograde->col(0) = ((1.0 - theta_) / QuadratureWeight(0)) * omega;
        }
        omega_previous_ = omega;
      });
  ++sweep_count_;
}

void McreProblem::FixedPointMap(const Matrix& retrograde, Matrix* displacement, Matrix* image) {
  DirectSweep(retrograde, true, displacement);
  RetrogradeSweep(*displacement, true, image);
}

void McreProblem::ApplyIterationMap(const Matrix& retrograde, Matrix* scratch_displacement,
                                    Matrix* image) {
  DirectSweep(retrograde, false, scratch_displacement);
  RetrogradeSweep(*scratch_displacement, false, image);
}

double McreProblem::InnerProduct(const Matrix& x, const Matrix& y) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  const double h = time_step();
  const SymmetricBandMatrix& stiffness = integrator_.stiffness();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    // x_j^T (K + B/alpha) y_j.
    stiffness.Multiply(y.col(j), product_);
    double term = x.col(j).dot(product_);
    term += (x(0, j) * y(0, j) + x(last, j) * y(last, j)) / alpha_;
    sum += QuadratureWeight(j) * h * term;
  }
  return sum;
}

double McreProblem::Cost(const Matrix& displacement, const Matrix& retrograde) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  const double h = time_step();
  const SymmetricBandMatrix& stiffness = integrator_.stiffness();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    stiffness.Multiply(retrograde.col(j), product_);
    const double gap = 0.5 * retrograde.col(j).dot(product_);
    const double force_misfit =
        (retrograde(0, j) * retrograde(0, j) + retrograde(last, j) * retrograde(last, j)) /
        (2.0 * alpha_);
    const double u0_misfit = displacement(0, j) - data_.u0[j];
    const double uL_misfit = displacement(last, j) - data_.uL[j];
    const double displacement_misfit =
        0.5 * beta_ * (u0_misfit * u0_misfit + uL_misfit * uL_misfit);
    sum += QuadratureWeight(j) * h * (gap + force_misfit + displacement_misfit);
  }
  return sum;
}

double McreProblem::CostGradient(const Matrix& displacement, const Matrix& retrograde) {
  const int m = num_steps();
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    // W_j^T K1 (W_j + 2 U_j), with K = E K1 so that -(1/(2E)) W^T K (.) = -(1/2) W^T K1 (.).
    unit_stiffness_.Multiply(retrograde.col(j), product_);
    sum += QuadratureWeight(j) * h * product_.dot(retrograde.col(j) + 2.0 * displacement.col(j));
  }
  return -0.5 * sum;
}

}  // namespace mcrewave
