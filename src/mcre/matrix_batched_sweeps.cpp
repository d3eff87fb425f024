// Batched sweeps of a structure given by matrices (matrix_mcre_problem.h): up to
// kMaxSweepBatch direct (retrograde) sweeps with the data at once, each step of the
// batch one ThetaIntegrator::StepsWithEndLoads call, so that the tridiagonal solves of
// the bar exported as matrices run interleaved. Each sweep forms its force as DirectSweep
// (RetrogradeSweep) does, so the results are the single sweeps' bits.
#include <cassert>
#include <stdexcept>

#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {

template <int B>
void MatrixMcreProblem::DirectSweeps(const Matrix* const (&retrograde)[B],
                                     Matrix* const (&displacement)[B]) {
  const int n = num_nodes(), m = num_steps();
  // Sized by the constructor; resized here only if a pattern grew since.
  if (batch_load_values_.rows() < load_columns_.num_point_loads()) {
    batch_load_values_.resize(load_columns_.num_point_loads(), kMaxSweepBatch);
  }
  for (int b = 0; b < B; ++b) {
    assert(retrograde[b] == nullptr ||
           (retrograde[b]->rows() == n && retrograde[b]->cols() == m + 1));
    displacement[b]->resize(n, m + 1);
    displacement[b]->col(0).setZero();
    batch_velocity_.col(2 * b).setZero();
  }
  const PointLoads* loads[B];
  for (int b = 0; b < B; ++b) loads[b] = &batch_loads_[b];
  const double no_end_loads[B] = {};
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    const double* v_k[B];
    const double* u_k[B];
    const double* z[B];
    double* v_next[B];
    double* u_next[B];
    for (int b = 0; b < B; ++b) {
      // As DirectStep: f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta),
      // W_theta = theta W_{k+1} + (1 - theta) W_k (none for the zero field).
      z[b] = nullptr;
      if (retrograde[b] != nullptr) {
        batch_shift_.col(b) =
            theta_ * retrograde[b]->col(k + 1) + (1.0 - theta_) * retrograde[b]->col(k);
        z[b] = batch_shift_.col(b).data();
      }
      auto channel = batch_channel_.col(b);
      DirectChannels(
          k, true, z[b], retrograde[b] != nullptr ? retrograde[b]->col(k).data() : nullptr,
          retrograde[b] != nullptr ? retrograde[b]->col(k + 1).data() : nullptr, channel);
      load_columns_.Scatter(channel.data(), batch_load_values_.col(b).data(), &batch_loads_[b]);
      v_k[b] = batch_velocity_.col(2 * b + current).data();
      v_next[b] = batch_velocity_.col(2 * b + next).data();
      u_k[b] = displacement[b]->col(k).data();
      u_next[b] = displacement[b]->col(k + 1).data();
    }
    integrator_.StepsWithEndLoads<B>(v_k, u_k, z, no_end_loads, no_end_loads, v_next, u_next,
                                     loads);
  }
  sweep_count_ += B;
}

template <int B>
void MatrixMcreProblem::RetrogradeSweeps(const Matrix* const (&displacement)[B],
                                         Matrix* const (&retrograde)[B]) {
  const int n = num_nodes(), m = num_steps();
  // Sized by the constructor; resized here only if a pattern grew since.
  if (batch_load_values_.rows() < observation_columns_.num_point_loads()) {
    batch_load_values_.resize(observation_columns_.num_point_loads(), kMaxSweepBatch);
  }
  for (int b = 0; b < B; ++b) {
    assert(displacement[b] == nullptr ||
           (displacement[b]->rows() == n && displacement[b]->cols() == m + 1));
    retrograde[b]->resize(n, m + 1);
    batch_velocity_.col(2 * b).setZero();
    batch_state_.col(2 * b).setZero();
  }
  const PointLoads* loads[B];
  for (int b = 0; b < B; ++b) loads[b] = &batch_loads_[b];
  const double* no_shift[B] = {};
  const double no_end_loads[B] = {};
  for (int j = m, step = 0; j > 0; --j, ++step) {
    const int current = step & 1, next = current ^ 1;
    const double* v_k[B];
    const double* omega_k[B];
    double* v_next[B];
    double* omega_next[B];
    for (int b = 0; b < B; ++b) {
      // As RetrogradeStep: c_j H^T diag(beta) (H U_j - d~_j) on step t_j -> t_{j-1}.
      auto trace = batch_trace_.col(b);
      if (displacement[b] != nullptr) {
        observation_columns_.TransposeMultiply(displacement[b]->col(j).data(), trace.data());
      } else {
        trace.setZero();
      }
      WeightTraces(j, true, trace);
      observation_columns_.Scatter(trace.data(), batch_load_values_.col(b).data(),
                                   &batch_loads_[b]);
      v_k[b] = batch_velocity_.col(2 * b + current).data();
      v_next[b] = batch_velocity_.col(2 * b + next).data();
      omega_k[b] = batch_state_.col(2 * b + current).data();
      omega_next[b] = batch_state_.col(2 * b + next).data();
    }
    integrator_.StepsWithEndLoads<B>(v_k, omega_k, no_shift, no_end_loads, no_end_loads, v_next,
                                     omega_next, loads);
    for (int b = 0; b < B; ++b) {
      // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, as RetrogradeSweep.
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

void MatrixMcreProblem::DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
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
      throw std::logic_error("1 to kMaxSweepBatch sweeps at once");
  }
}

void MatrixMcreProblem::RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
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
      throw std::logic_error("1 to kMaxSweepBatch sweeps at once");
  }
}

}  // namespace mcrewave
