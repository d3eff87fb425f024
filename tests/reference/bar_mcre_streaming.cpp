// The streaming application of the coupled map on sensor traces (bar_mcre_problem.h,
// docs/streaming.md): the retrograde sweep backward keeping only its state, then one
// forward pass that rebuilds W_j by the reversed trapezoidal recursion and runs the
// direct sweep beside it.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "reference/bar_error_map.h"
#include "reference/bar_mcre_problem.h"

namespace mcrewave {
namespace testing {

double BarMcreProblem::TraceInnerProduct(const Matrix& a, const Matrix& b) const {
  const int m = num_steps();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    // c_j h sum_k beta_k a_kj b_kj.
    double term = beta_u0_ * a(0, j) * b(0, j) + beta_uL_ * a(1, j) * b(1, j);
    for (int k = 0; k < num_interior_sensors(); ++k) {
      term += sensor_weights_[k] * a(2 + k, j) * b(2 + k, j);
    }
    sum += QuadratureWeight(j) * time_step() * term;
  }
  return sum;
}

double BarMcreProblem::RetrogradeEnergy(const Matrix& traces) {
  assert(traces.rows() == num_traces() && traces.cols() == num_steps() + 1);
  const int m = num_steps();
  const double h = time_step();
  double energy = 0.0;
  // The retrograde sweep from rest at T driven by the traces alone, W_j formed as the
  // state passes: W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, omega_m = 0.
  stream_velocity_[0].setZero();
  stream_omega_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, false, stream_velocity_[current], stream_omega_[current],
                        stream_velocity_[next], stream_omega_[next]);
    stream_retrograde_[0] =
        (theta_ * stream_omega_[next] + (1.0 - theta_) * stream_omega_[current]) *
        (1.0 / QuadratureWeight(j));
    // + c_j h W_j^T (K + B/alpha) W_j.
    energy += QuadratureWeight(j) * h *
              PenaltyForm(stream_retrograde_[0].data(), stream_retrograde_[0].data());
  }
  // W_0 = (1 - theta) omega_0 / c_0.
  stream_retrograde_[0] = ((1.0 - theta_) / QuadratureWeight(0)) * stream_omega_[m & 1];
  energy += QuadratureWeight(0) * h *
            PenaltyForm(stream_retrograde_[0].data(), stream_retrograde_[0].data());
  ++sweep_count_;
  return energy;
}

Vector BarMcreProblem::TraceWeights() const {
  Vector weights(num_traces());
  weights[0] = beta_u0_;
  weights[1] = beta_uL_;
  for (int k = 0; k < num_interior_sensors(); ++k) weights[2 + k] = sensor_weights_[k];
  return weights;
}

void BarMcreProblem::UseCheckpoints() {
  if (uses_checkpoints()) return;
  const int n = num_nodes(), m = num_steps();
  // stride = ceil(sqrt(2 m)): memory 2 n m / stride + n stride, about 2 n sqrt(2 m).
  checkpoint_stride_ = std::max(1, static_cast<int>(std::ceil(std::sqrt(2.0 * m))));
  checkpoints_ = Matrix::Zero(2 * n, m / checkpoint_stride_ + 1);
  segment_ = Matrix::Zero(n, checkpoint_stride_ + 1);
}

Matrix BarMcreProblem::DataTraces() const {
  Matrix traces(num_traces(), num_steps() + 1);
  for (int j = 0; j < data_.num_samples(); ++j) traces(0, j) = U0Datum(j);
  traces.row(1) = measured_.uL.transpose();
  for (int k = 0; k < num_interior_sensors(); ++k) traces.row(2 + k) = sensor_data_[k]->transpose();
  return traces;
}

void BarMcreProblem::DataResponseTraces(Matrix* traces) {
  const int m = num_steps();
  traces->resize(num_traces(), m + 1);
  // From rest: U_0 = V_0 = 0; the force of step t_k -> t_{k+1} is F~_theta alone (W = 0).
  stream_velocity_[0].setZero();
  stream_displacement_[0].setZero();
  ObserveTraces(stream_displacement_[0], traces->col(0).data());
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    // f_theta = theta F~_{k+1} + (1 - theta) F~_k at both ends.
    const double f0 =
        force0_gain_ * (theta_ * measured_.f0[k + 1] + (1.0 - theta_) * measured_.f0[k]);
    const double fL = theta_ * measured_.fL[k + 1] + (1.0 - theta_) * measured_.fL[k];
    integrator_.StepWithEndLoads(stream_velocity_[current], stream_displacement_[current], f0, fL,
                                 stream_velocity_[next], stream_displacement_[next]);
    ObserveTraces(stream_displacement_[next], traces->col(k + 1).data());
  }
  ++sweep_count_;
}

void BarMcreProblem::ObserveTraces(const Vector& displacement, double* column) const {
  column[0] = displacement[0];
  column[1] = displacement[num_nodes() - 1];
  for (int k = 0; k < num_interior_sensors(); ++k) {
    column[2 + k] = sensor_rows_[k].Apply(displacement.data());
  }
}

void BarMcreProblem::TraceLoads(int j, const Matrix& traces, bool include_data, double* f0,
                                double* fL) {
  const double quadrature = QuadratureWeight(j);
  // c_j beta (y_j - d~_j) at the ends; the sensors' c_j beta_k (y_kj - d~_kj) h_k.
  *f0 = quadrature * beta_u0_ * (traces(0, j) - (include_data ? U0Datum(j) : 0.0));
  *fL = quadrature * beta_uL_ * (traces(1, j) - (include_data ? measured_.uL[j] : 0.0));
  double* values = load_values_.col(0).data();
  for (int k = 0; k < num_interior_sensors(); ++k) {
    const double misfit = traces(2 + k, j) - (include_data ? (*sensor_data_[k])[j] : 0.0);
    const double load = quadrature * sensor_weights_[k] * misfit;
    values[2 * k] = load * sensor_rows_[k].coefficients[0];
    values[2 * k + 1] = load * sensor_rows_[k].coefficients[1];
  }
}

void BarMcreProblem::RetrogradeTraceStep(int j, const Matrix& traces, bool include_data,
                                         const Vector& velocity, const Vector& state,
                                         Vector& velocity_next, Vector& state_next) {
  double f0 = 0.0, fL = 0.0;
  TraceLoads(j, traces, include_data, &f0, &fL);
  integrator_.StepWithEndLoads(velocity, state, f0, fL, velocity_next, state_next,
                               num_interior_sensors() > 0 ? &point_loads_[0] : nullptr);
}

void BarMcreProblem::ResetStreamingTotals(int picture_stride, StreamingTotals* totals) {
  const int m = num_steps();
  totals->cost = 0.0;
  totals->cost_gradients.setZero(num_zones());
  totals->error_map.setZero(model_.num_elements());
  totals->gap_density.resize(m / picture_stride + 1, stream_density_row_.size());
  totals->rebuild_error = 0.0;
}

void BarMcreProblem::AddStreamingSample(int j, const Vector& displacement, const Vector& retrograde,
                                        int picture_stride, StreamingTotals* totals) {
  const double weight = QuadratureWeight(j) * time_step();
  totals->cost += weight * SampleCost(j, displacement.data(), retrograde.data());
  AddSampleCostGradients(j, displacement.data(), retrograde.data(), &totals->cost_gradients);
  AddSampleGapShares(model_, moduli_, retrograde.data(), weight, &totals->error_map);
  if (j % picture_stride == 0) {
    SampleGapDensity(model_, moduli_, retrograde.data(), stream_density_row_.data());
    totals->gap_density.row(j / picture_stride) = stream_density_row_.transpose();
  }
}

void BarMcreProblem::StreamingMap(const Matrix& traces, bool include_data, Matrix* image,
                                  StreamingTotals* totals) {
  assert(traces.rows() == num_traces() && traces.cols() == num_steps() + 1 && image != &traces);
  const int m = num_steps(), last = num_nodes() - 1;
  image->resize(num_traces(), m + 1);
  // Every picture_stride-th sample goes into the error map's space-time picture.
  const int picture_stride = SpaceTimeStride(m);
  if (totals != nullptr) ResetStreamingTotals(picture_stride, totals);
  // y_j = H U_j into the image, and the totals of sample j.
  auto observe = [&](int j, const Vector& displacement, const Vector& retrograde) {
    ObserveTraces(displacement, image->col(j).data());
    if (totals != nullptr) AddStreamingSample(j, displacement, retrograde, picture_stride, totals);
  };
  // The direct step t_{j-1} -> t_j from (V, U)[current] into [next], given W_{j-1} and
  // W_j, with f_theta = -K W_theta + (F~_theta - B W_theta / alpha),
  // W_theta = theta W_j + (1 - theta) W_{j-1} (as DirectSweep); then observe(j).
  auto direct_step = [&](int j, const Vector& previous_retrograde, const Vector& retrograde) {
    const int current = (j - 1) & 1, next = current ^ 1;
    stream_shift_ = theta_ * retrograde + (1.0 - theta_) * previous_retrograde;
    double direct_f0 = -stream_shift_[0] / alpha0_;
    double direct_fL = -stream_shift_[last] / alpha_;
    if (include_data) {
      direct_f0 += theta_ * measured_.f0[j] + (1.0 - theta_) * measured_.f0[j - 1];
      direct_fL += theta_ * measured_.fL[j] + (1.0 - theta_) * measured_.fL[j - 1];
    }
    direct_f0 *= force0_gain_;
    integrator_.StepWithEndLoads(stream_direct_velocity_[current], stream_displacement_[current],
                                 stream_shift_, direct_f0, direct_fL, stream_direct_velocity_[next],
                                 stream_displacement_[next]);
    observe(j, stream_displacement_[next], retrograde);
  };
  stream_direct_velocity_[0].setZero();
  stream_displacement_[0].setZero();

  if (uses_checkpoints()) {
    CheckpointedStreamingMap(traces, include_data, observe, direct_step);
    sweep_count_ += 4;
    return;
  }

  // 1. The retrograde sweep from rest at T, its state only: (v_j, omega_j), j = m..0.
  stream_velocity_[0].setZero();
  stream_omega_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, include_data, stream_velocity_[current], stream_omega_[current],
                        stream_velocity_[next], stream_omega_[next]);
  }
  const int final_state = m & 1;

  // 2. Forward: the rebuilt retrograde state and the direct sweep side by side. For
  // theta = 1/2 the step (a_{j-1}, omega_{j-1}) -> (a_j, omega_j) with a = -v and the
  // load of the backward step j -> j-1 inverts that step exactly (docs/streaming.md).
  stream_rebuilt_velocity_[0] = -stream_velocity_[final_state];
  stream_rebuilt_omega_[0] = stream_omega_[final_state];
  // W_0 = (1 - theta) omega_0 / c_0.
  stream_retrograde_[0] = ((1.0 - theta_) / QuadratureWeight(0)) * stream_rebuilt_omega_[0];
  double largest_omega = stream_rebuilt_omega_[0].norm();
  observe(0, stream_displacement_[0], stream_retrograde_[0]);
  for (int j = 1; j <= m; ++j) {
    const int current = (j - 1) & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, include_data, stream_rebuilt_velocity_[current],
                        stream_rebuilt_omega_[current], stream_rebuilt_velocity_[next],
                        stream_rebuilt_omega_[next]);
    // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, with omega_m = 0 exactly
    // (the rebuilt omega_m is its round-off).
    const double omega_weight = j == m ? 0.0 : 1.0 - theta_;
    stream_retrograde_[next] =
        (theta_ * stream_rebuilt_omega_[current] + omega_weight * stream_rebuilt_omega_[next]) *
        (1.0 / QuadratureWeight(j));
    if (j < m) largest_omega = std::max(largest_omega, stream_rebuilt_omega_[next].norm());
    direct_step(j, stream_retrograde_[current], stream_retrograde_[next]);
  }
  if (totals != nullptr) {
    totals->rebuild_error =
        largest_omega > 0.0 ? stream_rebuilt_omega_[m & 1].norm() / largest_omega : 0.0;
  }
  sweep_count_ += 3;
}

template <typename Observe, typename DirectStep>
void BarMcreProblem::CheckpointedStreamingMap(const Matrix& traces, bool include_data,
                                              Observe& observe, DirectStep& direct_step) {
  const int m = num_steps(), stride = checkpoint_stride_;
  const int n = num_nodes();
  // 1. The retrograde sweep from rest at T keeping its state (v_j, omega_j) at the
  // checkpoints j = m - i stride (column i of checkpoints_: v over omega).
  stream_velocity_[0].setZero();
  stream_omega_[0].setZero();
  checkpoints_.col(0).setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, include_data, stream_velocity_[current], stream_omega_[current],
                        stream_velocity_[next], stream_omega_[next]);
    if ((m - (j - 1)) % stride == 0) {
      const int column = (m - (j - 1)) / stride;
      checkpoints_.col(column).head(n) = stream_velocity_[next];
      checkpoints_.col(column).tail(n) = stream_omega_[next];
    }
  }
  // 2. Forward over the segments [a, b] between checkpoints, earliest first: from the
  // checkpoint at b the retrograde steps b -> a again (the same steps, so the same
  // bits as the first pass) with omega_j kept for j in [a, b] (column j - a of
  // segment_), then W_j in forward order and the direct steps.
  const int lowest_checkpoint = m % stride;  // j of the last checkpoint
  int a = 0;
  int b = lowest_checkpoint > 0 ? lowest_checkpoint : std::min(stride, m);
  while (a < m) {
    const int column = (m - b) / stride;
    stream_velocity_[0] = checkpoints_.col(column).head(n);
    stream_omega_[0] = checkpoints_.col(column).tail(n);
    segment_.col(b - a) = stream_omega_[0];
    for (int j = b, s = 0; j > a; --j, ++s) {
      const int current = s & 1, next = current ^ 1;
      RetrogradeTraceStep(j, traces, include_data, stream_velocity_[current],
                          stream_omega_[current], stream_velocity_[next], stream_omega_[next]);
      segment_.col(j - 1 - a) = stream_omega_[next];
    }
    if (a == 0) {
      // W_0 = (1 - theta) omega_0 / c_0.
      stream_retrograde_[0] = ((1.0 - theta_) / QuadratureWeight(0)) * segment_.col(0);
      observe(0, stream_displacement_[0], stream_retrograde_[0]);
    }
    for (int j = a + 1; j <= b; ++j) {
      const int current = (j - 1) & 1, next = current ^ 1;
      // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j (omega_m = 0: the
      // checkpoint at m is the rest state).
      stream_retrograde_[next] =
          (theta_ * segment_.col(j - 1 - a) + (1.0 - theta_) * segment_.col(j - a)) *
          (1.0 / QuadratureWeight(j));
      direct_step(j, stream_retrograde_[current], stream_retrograde_[next]);
    }
    a = b;
    b = std::min(b + stride, m);
  }
}

}  // namespace testing
}  // namespace mcrewave
