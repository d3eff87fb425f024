#include "mcrewave/mcre/mcre_problem.h"

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
  } else if (!(std::isfinite(strain_weight) && strain_weight > 0.0)) {
    why << "mcre.w_e must be a finite positive number, got " << strain_weight;
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
  for (int b = 0; b < 2; ++b) {
    velocity_[b] = Vector::Zero(n);
    omega_[b] = Vector::Zero(n);
  }
  shift_ = Vector::Zero(n);
  batch_velocity_ = Matrix::Zero(n, 2 * ThetaIntegrator::kMaxBatch);
  batch_state_ = Matrix::Zero(n, 2 * ThetaIntegrator::kMaxBatch);
  batch_shift_ = Matrix::Zero(n, ThetaIntegrator::kMaxBatch);
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
  const double inverse_alpha = 1.0 / alpha_;
  // From rest: U_0 = V_0 = 0.
  displacement->col(0).setZero();
  velocity_[0].setZero();
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    // The force of step t_k -> t_{k+1}, f_theta = theta g_{k+1} + (1 - theta) g_k with
    // g_j = F~_j - (K + B/alpha) W_j, is by linearity
    //   f_theta = -K W_theta + (F~_theta - B W_theta / alpha),
    //   W_theta = theta W_{k+1} + (1 - theta) W_k.
    shift_ = theta_ * retrograde.col(k + 1) + (1.0 - theta_) * retrograde.col(k);
    double f0 = -inverse_alpha * shift_[0];
    double fL = -inverse_alpha * shift_[last];
    if (include_data) {
      f0 += theta_ * data_.f0[k + 1] + (1.0 - theta_) * data_.f0[k];
      fL += theta_ * data_.fL[k + 1] + (1.0 - theta_) * data_.fL[k];
    }
    integrator_.StepWithEndLoads(velocity_[current], displacement->col(k), shift_, f0, fL,
                                 velocity_[next], displacement->col(k + 1));
  }
  ++sweep_count_;
}

void McreProblem::RetrogradeSweep(const Matrix& displacement, bool include_data,
                                  Matrix* retrograde) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  assert(displacement.rows() == n && displacement.cols() == m + 1);
  retrograde->resize(n, m + 1);
  // From rest at T: (v_m, omega_m) = (0, 0), in reversed time.
  velocity_[0].setZero();
  omega_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    // Step t_j -> t_{j-1} carries the force c_j beta (B U_j - U~_j) (R2).
    const double weight = QuadratureWeight(j) * beta_;
    double f0 = weight * displacement(0, j);
    double fL = weight * displacement(last, j);
    if (include_data) {
      f0 -= weight * data_.u0[j];
      fL -= weight * data_.uL[j];
    }
    integrator_.StepWithEndLoads(velocity_[current], omega_[current], f0, fL, velocity_[next],
                                 omega_[next]);
    // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j  (R3), omega_m = 0; times
    // 1/c_j in {1, 2}, exact, instead of a division per entry.
    retrograde->col(j) =
        (theta_ * omega_[next] + (1.0 - theta_) * omega_[current]) * (1.0 / QuadratureWeight(j));
  }
  // W_0 = (1 - theta) omega_0 / c_0 (omega_{-1} = 0).
  retrograde->col(0) = ((1.0 - theta_) / QuadratureWeight(0)) * omega_[m & 1];
  ++sweep_count_;
}

McreProblem::SolverWorkspace& McreProblem::workspace() {
  if (workspace_.zero.rows() != num_nodes() || workspace_.zero.cols() != num_steps() + 1) {
    workspace_.zero = ZeroField();
  }
  return workspace_;
}

template <int B>
void McreProblem::DirectSweeps(const Matrix* const (&retrograde)[B],
                               Matrix* const (&displacement)[B]) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  const double inverse_alpha = 1.0 / alpha_;
  for (int b = 0; b < B; ++b) {
    assert(retrograde[b] == nullptr ||
           (retrograde[b]->rows() == n && retrograde[b]->cols() == m + 1));
    displacement[b]->resize(n, m + 1);
    displacement[b]->col(0).setZero();
    batch_velocity_.col(2 * b).setZero();
  }
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    const double* v_k[B];
    const double* u_k[B];
    const double* z[B];
    double f0[B], fL[B];
    double* v_next[B];
    double* u_next[B];
    for (int b = 0; b < B; ++b) {
      // As DirectSweep: f_theta = -K W_theta + (F~_theta - B W_theta / alpha).
      f0[b] = theta_ * data_.f0[k + 1] + (1.0 - theta_) * data_.f0[k];
      fL[b] = theta_ * data_.fL[k + 1] + (1.0 - theta_) * data_.fL[k];
      z[b] = nullptr;
      if (retrograde[b] != nullptr) {
        batch_shift_.col(b) =
            theta_ * retrograde[b]->col(k + 1) + (1.0 - theta_) * retrograde[b]->col(k);
        f0[b] = -inverse_alpha * batch_shift_(0, b) + f0[b];
        fL[b] = -inverse_alpha * batch_shift_(last, b) + fL[b];
        z[b] = batch_shift_.col(b).data();
      }
      v_k[b] = batch_velocity_.col(2 * b + current).data();
      v_next[b] = batch_velocity_.col(2 * b + next).data();
      u_k[b] = displacement[b]->col(k).data();
      u_next[b] = displacement[b]->col(k + 1).data();
    }
    integrator_.StepsWithEndLoads<B>(v_k, u_k, z, f0, fL, v_next, u_next);
  }
  sweep_count_ += B;
}

template <int B>
void McreProblem::RetrogradeSweeps(const Matrix* const (&displacement)[B],
                                   Matrix* const (&retrograde)[B]) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  for (int b = 0; b < B; ++b) {
    assert(displacement[b] == nullptr ||
           (displacement[b]->rows() == n && displacement[b]->cols() == m + 1));
    retrograde[b]->resize(n, m + 1);
    batch_velocity_.col(2 * b).setZero();
    batch_state_.col(2 * b).setZero();
  }
  const double* no_shift[B] = {};
  for (int j = m, step = 0; j > 0; --j, ++step) {
    const int current = step & 1, next = current ^ 1;
    const double* v_k[B];
    const double* omega_k[B];
    double f0[B], fL[B];
    double* v_next[B];
    double* omega_next[B];
    // As RetrogradeSweep: the force c_j beta (B U_j - U~_j) on step t_j -> t_{j-1}.
    const double weight = QuadratureWeight(j) * beta_;
    for (int b = 0; b < B; ++b) {
      f0[b] = displacement[b] != nullptr ? weight * (*displacement[b])(0, j) : 0.0;
      fL[b] = displacement[b] != nullptr ? weight * (*displacement[b])(last, j) : 0.0;
      f0[b] -= weight * data_.u0[j];
      fL[b] -= weight * data_.uL[j];
      v_k[b] = batch_velocity_.col(2 * b + current).data();
      v_next[b] = batch_velocity_.col(2 * b + next).data();
      omega_k[b] = batch_state_.col(2 * b + current).data();
      omega_next[b] = batch_state_.col(2 * b + next).data();
    }
    integrator_.StepsWithEndLoads<B>(v_k, omega_k, no_shift, f0, fL, v_next, omega_next);
    for (int b = 0; b < B; ++b) {
      retrograde[b]->col(j) = (theta_ * batch_state_.col(2 * b + next) +
                               (1.0 - theta_) * batch_state_.col(2 * b + current)) *
                              (1.0 / QuadratureWeight(j));
    }
  }
  for (int b = 0; b < B; ++b) {
    retrograde[b]->col(0) =
        ((1.0 - theta_) / QuadratureWeight(0)) * batch_state_.col(2 * b + (m & 1));
  }
  sweep_count_ += B;
}

void McreProblem::DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
                                       const std::vector<Matrix*>& displacement) {
  assert(retrograde.size() == displacement.size());
  switch (retrograde.size()) {
    case 1:
      DirectSweep(retrograde[0] != nullptr ? *retrograde[0] : workspace().zero, true,
                  displacement[0]);
      return;
    case 2:
      DirectSweeps<2>({retrograde[0], retrograde[1]}, {displacement[0], displacement[1]});
      return;
    case 3:
      DirectSweeps<3>({retrograde[0], retrograde[1], retrograde[2]},
                      {displacement[0], displacement[1], displacement[2]});
      return;
    default:
      assert(false && "1 to kMaxBatch sweeps at once");
  }
}

void McreProblem::RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
                                           const std::vector<Matrix*>& retrograde) {
  assert(retrograde.size() == displacement.size());
  switch (displacement.size()) {
    case 1:
      RetrogradeSweep(displacement[0] != nullptr ? *displacement[0] : workspace().zero, true,
                      retrograde[0]);
      return;
    case 2:
      RetrogradeSweeps<2>({displacement[0], displacement[1]}, {retrograde[0], retrograde[1]});
      return;
    case 3:
      RetrogradeSweeps<3>({displacement[0], displacement[1], displacement[2]},
                          {retrograde[0], retrograde[1], retrograde[2]});
      return;
    default:
      assert(false && "1 to kMaxBatch sweeps at once");
  }
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
    double term = stiffness.BilinearForm(x.col(j).data(), y.col(j).data());
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
    const double* w = retrograde.col(j).data();
    const double gap = 0.5 * stiffness.BilinearForm(w, w);
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
    const double* w = retrograde.col(j).data();
    const double* u = displacement.col(j).data();
    sum += QuadratureWeight(j) * h *
           (unit_stiffness_.BilinearForm(w, w) + 2.0 * unit_stiffness_.BilinearForm(w, u));
  }
  return -0.5 * sum;
}

}  // namespace mcrewave
