// The streaming application of the coupled map of a structure given by matrices
// (matrix_mcre_problem.h, docs/streaming.md section 5): the retrograde sweep driven by
// the traces backward keeping its state at checkpoints, then segment by segment from
// t = 0 the retrograde field swept again from its checkpoint and consumed in forward
// order by the direct sweep, the totals summed as the fields pass.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {

double MatrixMcreProblem::TraceInnerProduct(const Matrix& a, const Matrix& b) const {
  assert(a.rows() == num_traces() && b.rows() == num_traces() && a.cols() == b.cols());
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h sum_k beta_k a_kj b_kj.
    sum += QuadratureWeight(j) * time_step() * betas_.dot(a.col(j).cwiseProduct(b.col(j)));
  }
  return sum;
}

void MatrixMcreProblem::RetrogradeTraceStep(int j, const Matrix& traces, bool include_data,
                                            const Vector& velocity, const Vector& state,
                                            Vector& velocity_next, Vector& state_next) {
  trace_ = traces.col(j);
  RetrogradeStep(j, include_data, velocity, state, velocity_next, state_next);
}

void MatrixMcreProblem::RetrogradeStep(int j, bool include_data, const Vector& velocity,
                                       const Vector& state, Vector& velocity_next,
                                       Vector& state_next) {
  // c_j H^T diag(beta) (y_j - d~_j).
  WeightTraces(j, include_data, trace_);
  integrator_.StepWithEndLoads(velocity, state, 0.0, 0.0, velocity_next, state_next,
                               observation_columns_.Scatter(trace_.data()));
}

void MatrixMcreProblem::DirectStep(int k, bool include_data, const double* previous,
                                   const double* next, const Vector& velocity,
                                   const Eigen::Ref<const Vector>& displacement,
                                   Vector& velocity_next, Eigen::Ref<Vector> displacement_next) {
  // f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta).
  DirectChannels(k, include_data, shift_.data(), previous, next, channel_);
  integrator_.StepWithEndLoads(velocity, displacement, shift_, 0.0, 0.0, velocity_next,
                               displacement_next, load_columns_.Scatter(channel_.data()));
}

void MatrixMcreProblem::DirectChannels(int k, bool include_data, const double* shift,
                                       const double* previous, const double* next,
                                       Eigen::Ref<Vector> channel) const {
  // Loops over the few channels rather than Eigen expressions, whose set-up costs more
  // than their work at this size; the same operations, so the same bits.
  const int channels = static_cast<int>(channel.size());
  double* out = channel.data();
  if (shift != nullptr) {
    load_columns_.TransposeMultiply(shift, out);
    // -diag(1/alpha) G^T W_theta.
    for (int c = 0; c < channels; ++c) out[c] = -(out[c] / alphas_[c]);
    if (load_active_.size() > 0) {
      bool edge = false;
      for (int c = 0; c < channels; ++c) {
        const double now = load_active_(c, k), later = load_active_(c, k + 1);
        if (now == 0.0 && later == 0.0) out[c] = 0.0;
        edge = edge || now != later;
      }
      if (edge) {
        // Where a load starts or stops acting:
        // -(theta a_{k+1} (G^T W_{k+1}) + (1 - theta) a_k (G^T W_k)) / alpha.
        load_columns_.TransposeMultiply(previous, edge_channel_[0].data());
        load_columns_.TransposeMultiply(next, edge_channel_[1].data());
        for (int c = 0; c < channels; ++c) {
          const double now = load_active_(c, k), later = load_active_(c, k + 1);
          if (now == later) continue;
          out[c] = -(
              (theta_ * later * edge_channel_[1][c] + (1.0 - theta_) * now * edge_channel_[0][c]) /
              alphas_[c]);
        }
      }
    }
  } else {
    channel.setZero();
  }
  if (include_data) {
    // + F~_theta = theta F~_{k+1} + (1 - theta) F~_k.
    const double* next = measured_loads_.col(k + 1).data();
    const double* now = measured_loads_.col(k).data();
    for (int c = 0; c < channels; ++c) {
      out[c] += theta_ * next[c] + (1.0 - theta_) * now[c];
    }
  }
}

void MatrixMcreProblem::WeightTraces(int j, bool include_data, Eigen::Ref<Vector> trace) const {
  // c_j beta_k (y_k - d~_k), channel by channel (as DirectChannels, a loop).
  const int rows = static_cast<int>(trace.size());
  const double weight = QuadratureWeight(j);
  double* y = trace.data();
  if (include_data) {
    const double* data = measured_outputs_.col(j).data();
    for (int k = 0; k < rows; ++k) y[k] -= data[k];
  }
  for (int k = 0; k < rows; ++k) y[k] = (weight * betas_[k]) * y[k];
}

double MatrixMcreProblem::StiffnessForm(const double* x, const double* y) {
  if (integrator_.factorization() == Factorization::kBand) {
    return integrator_.stiffness().BilinearForm(x, y);
  }
  const int n = num_nodes();
  product_.noalias() = stiffness_ * Eigen::Map<const Vector>(y, n);
  return Eigen::Map<const Vector>(x, n).dot(product_);
}

double MatrixMcreProblem::PenaltyForm(int j, const Eigen::Ref<const Vector>& x,
                                      const Eigen::Ref<const Vector>& y) {
  // x^T (K + G diag(a_j / alpha) G^T) y, the integrand of InnerProduct.
  const double stiffness_form = StiffnessForm(x.data(), y.data());
  load_columns_.TransposeMultiply(x.data(), channel_.data());
  MaskInactiveLoads(j, channel_);
  load_columns_.TransposeMultiply(y.data(), other_channel_.data());
  return stiffness_form + channel_.cwiseQuotient(alphas_).dot(other_channel_);
}

double MatrixMcreProblem::RetrogradeEnergy(const Matrix& traces) {
  assert(traces.rows() == num_traces() && traces.cols() == num_steps() + 1);
  const int m = num_steps();
  const double h = time_step();
  double energy = 0.0;
  // The retrograde sweep from rest at T driven by the traces alone, W_j formed as the
  // state passes: W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, omega_m = 0.
  velocity_[0].setZero();
  state_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, false, velocity_[current], state_[current], velocity_[next],
                        state_[next]);
    stream_retrograde_[0] =
        (theta_ * state_[next] + (1.0 - theta_) * state_[current]) * (1.0 / QuadratureWeight(j));
    // + c_j h W_j^T P W_j.
    energy +=
        QuadratureWeight(j) * h * PenaltyForm(j, stream_retrograde_[0], stream_retrograde_[0]);
  }
  // W_0 = (1 - theta) omega_0 / c_0.
  stream_retrograde_[0] = ((1.0 - theta_) / QuadratureWeight(0)) * state_[m & 1];
  energy += QuadratureWeight(0) * h * PenaltyForm(0, stream_retrograde_[0], stream_retrograde_[0]);
  ++sweep_count_;
  return energy;
}

void MatrixMcreProblem::AddStreamingSample(int j, const Vector& displacement,
                                           const Vector& retrograde, int picture_stride,
                                           StreamingTotals* totals) {
  const int zones = static_cast<int>(model_.zones.size());
  const double weight = QuadratureWeight(j) * time_step();
  // e^2: c_j h [1/2 W^T K W + 1/2 (G^T W)^T diag(1/alpha) G^T W
  //             + 1/2 (H U - d~)^T diag(beta) (H U - d~)] (Cost), trace_ = H U_j - d~_j,
  // W^T K W as StiffnessForm takes it (from the band of K on the band path).
  product_.noalias() = stiffness_ * retrograde;
  const double stiffness_form =
      integrator_.factorization() == Factorization::kBand
          ? integrator_.stiffness().BilinearForm(retrograde.data(), retrograde.data())
          : retrograde.dot(product_);
  load_columns_.TransposeMultiply(retrograde.data(), channel_.data());
  totals->load_retrograde.col(j) = channel_;
  MaskInactiveLoads(j, channel_);
  totals->cost +=
      weight * (0.5 * stiffness_form + 0.5 * channel_.cwiseQuotient(alphas_).dot(channel_) +
                0.5 * betas_.dot(trace_.cwiseProduct(trace_)));
  // The dof map c_j h 1/2 W_ij (K W_j)_i (DofErrorMap).
  totals->error_map += (0.5 * weight) * retrograde.cwiseProduct(product_);
  if (element_maps_ && !model_.elements.empty()) {
    // The element map's shares and sensitivities' field part and, on every
    // picture_stride-th sample, its picture's row (mcre/element_error_map.h, as
    // ComputeElementErrorMap and ElementSensitivities take them from the fields).
    AddSampleElementMaps(model_, moduli_, displacement.data(), retrograde.data(), weight,
                         &totals->element_error_map, &totals->element_sensitivity);
    if (j % picture_stride == 0) {
      SampleElementGapDensity(model_, moduli_, retrograde.data(), stream_density_row_.data());
      totals->gap_density.row(j / picture_stride) = stream_density_row_.transpose();
    }
  }
  for (int z = 0; z < zones; ++z) {
    const MatrixModelZone& zone = model_.zones[z];
    // W^T K_z W, W^T K_z U and U^T K_z U.
    double gap = 0.0, cross = 0.0, strain = 0.0;
    zone_forms_[z].Forms(retrograde.data(), displacement.data(), &gap, &cross, &strain);
    // -(1/(2 E_z,nom)) c_j h W_j^T K_z (W_j + 2 U_j) (CostGradients).
    totals->cost_gradients[z] += -0.5 * weight * (gap + 2.0 * cross) / zone.nominal_modulus;
    // (E_z / E_z,nom) c_j h 1/2 X_j^T K_z X_j of W and U (ZoneErrorMap).
    const double scale = moduli_[z] / zone.nominal_modulus;
    totals->zone_error_map[z] += scale * weight * 0.5 * gap;
    totals->zone_strain_energy[z] += scale * weight * 0.5 * strain;
  }
  if (num_reactions_ == 0) return;
  // Trusted: c_j h alpha_r sum_s (r_s(U_j) - f~_sj) g_s^T K_z U_j / E_z,nom.
  FormReactionMisfit(j, displacement);
  for (int z = 0; z < zones; ++z) {
    totals->cost_gradients[z] +=
        weight * reaction_weight_ *
        reaction_zone_forms_[z](reaction_trace_.data(), displacement.data());
  }
  if (element_maps_ && !model_.elements.empty()) {
    AddSampleReactionSensitivities(displacement.data(), weight, &totals->element_sensitivity);
  }
}

void MatrixMcreProblem::ResetStreamingTotals(int picture_stride, StreamingTotals* totals) const {
  const int zones = num_zones();
  totals->cost = 0.0;
  totals->cost_gradients.setZero(zones);
  totals->error_map.setZero(num_nodes());
  totals->zone_error_map.setZero(zones);
  totals->zone_strain_energy.setZero(zones);
  const bool elements = element_maps_ && !model_.elements.empty();
  totals->element_error_map.setZero(elements ? static_cast<Eigen::Index>(model_.elements.size())
                                             : 0);
  totals->element_sensitivity.setZero(totals->element_error_map.size());
  totals->gap_density.resize(elements ? num_steps() / picture_stride + 1 : 0,
                             elements ? stream_density_row_.size() : 0);
  totals->load_retrograde.resize(channel_.size(), num_steps() + 1);
  totals->rebuild_error = 0.0;  // W from checkpoints: the stored sweep's
}

void MatrixMcreProblem::StreamingElementMaps(const Matrix& traces, CoupledSolution* solution) {
  assert(traces.rows() == num_traces() && traces.cols() == num_steps() + 1);
  const bool gathered = element_maps_;
  element_maps_ = true;
  Matrix image;
  StreamingTotals totals;
  StreamingMap(traces, true, &image, &totals);
  element_maps_ = gathered;
  solution->element_error_map = std::move(totals.element_error_map);
  solution->gap_density = std::move(totals.gap_density);
  solution->element_sensitivity = std::move(totals.element_sensitivity);
}

void MatrixMcreProblem::CheckpointRetrogradeSweep(const Matrix& traces, bool include_data) {
  const int n = num_nodes(), m = num_steps();
  const int stride = checkpoint_stride_;
  // The retrograde sweep from rest at T keeping its state (v_j, omega_j) at the
  // checkpoints j = m - i s (column i: v over omega).
  velocity_[0].setZero();
  state_[0].setZero();
  checkpoints_.col(0).setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    RetrogradeTraceStep(j, traces, include_data, velocity_[current], state_[current],
                        velocity_[next], state_[next]);
    if ((m - (j - 1)) % stride == 0) {
      const int column = (m - (j - 1)) / stride;
      checkpoints_.col(column).head(n) = velocity_[next];
      checkpoints_.col(column).tail(n) = state_[next];
    }
  }
}

bool MatrixMcreProblem::HistoryFits(long bytes) const {
  return 8.0 * num_nodes() * (num_steps() + 1.0) <= static_cast<double>(bytes);
}

void MatrixMcreProblem::SetHistoryBudget(long bytes) {
  // A layout already made is kept unless the new budget changes it.
  if (checkpoint_stride_ != 0 && HistoryFits(bytes) != HistoryFits(history_budget_bytes_)) {
    checkpoint_stride_ = 0;
  }
  history_budget_bytes_ = bytes;
}

void MatrixMcreProblem::StreamingMap(const Matrix& traces, bool include_data, Matrix* image,
                                     StreamingTotals* totals) {
  assert(traces.rows() == num_traces() && traces.cols() == num_steps() + 1 && image != &traces);
  const int n = num_nodes(), m = num_steps();
  if (checkpoint_stride_ == 0) {
    // s = ceil(sqrt(2 m)): memory 2 n m / s + n s, about 2 n sqrt(2 m) doubles; or s = m
    // when omega's whole history fits.
    const bool whole = HistoryFits(history_budget_bytes_);
    checkpoint_stride_ = whole ? m : std::max(1, static_cast<int>(std::ceil(std::sqrt(2.0 * m))));
    checkpoints_ = Matrix::Zero(2 * n, m / checkpoint_stride_ + 1);
    segment_ = Matrix::Zero(n, checkpoint_stride_ + 1);
  }
  const int stride = checkpoint_stride_;
  image->resize(num_traces(), m + 1);
  // The element map's picture takes every picture_stride-th sample.
  const int picture_stride = SpaceTimeStride(m);
  if (totals != nullptr) ResetStreamingTotals(picture_stride, totals);
  // y_j = H U_j into the image, and sample j into the totals.
  auto observe = [&](int j, const Vector& displacement, const Vector& retrograde) {
    observation_columns_.TransposeMultiply(displacement.data(), trace_.data());
    image->col(j) = trace_;
    if (totals == nullptr) return;
    trace_ -= measured_outputs_.col(j);
    AddStreamingSample(j, displacement, retrograde, picture_stride, totals);
  };
  // The direct step t_{j-1} -> t_j of DirectSweep from (V, U)[current] into [next],
  // f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta),
  // W_theta = theta W_j + (1 - theta) W_{j-1}; then observe(j).
  auto direct_step = [&](int j, const Vector& previous_retrograde, const Vector& retrograde) {
    const int current = (j - 1) & 1, next = current ^ 1;
    shift_ = theta_ * retrograde + (1.0 - theta_) * previous_retrograde;
    DirectStep(j - 1, include_data, previous_retrograde.data(), retrograde.data(),
               stream_velocity_[current], stream_displacement_[current], stream_velocity_[next],
               stream_displacement_[next]);
    observe(j, stream_displacement_[next], retrograde);
  };

  // At the data itself (y = d~, include_data: the start of every solve) the retrograde
  // loads c_j H^T diag(beta) (y_j - d~_j) are zero, so omega stays at rest: no
  // backward sweep, W = 0 (as the sweep would give it), the direct sweep alone.
  const bool at_rest = include_data && traces == measured_outputs_;
  // 1. The retrograde sweep from rest at T keeping its state at the checkpoints; with
  //    one segment (s = m) its only checkpoint is that rest state, and step 2 is the
  //    one backward sweep.
  if (stride < m && !at_rest) {
    CheckpointRetrogradeSweep(traces, include_data);
  } else {
    checkpoints_.col(0).setZero();
  }

  // 2. Forward over the segments [a, b] between checkpoints, earliest first: from the
  // checkpoint at b the retrograde steps b -> a again (the same steps, so the same bits
  // as the first pass and as RetrogradeSweep), omega_j kept in column j - a of
  // segment_, then W_j in forward order and the direct steps beside them.
  stream_velocity_[0].setZero();
  stream_displacement_[0].setZero();
  const int lowest_checkpoint = m % stride;
  int a = 0;
  int b = lowest_checkpoint > 0 ? lowest_checkpoint : std::min(stride, m);
  while (a < m) {
    const int column = (m - b) / stride;
    velocity_[0] = checkpoints_.col(column).head(n);
    state_[0] = checkpoints_.col(column).tail(n);
    segment_.col(b - a) = state_[0];
    if (at_rest) segment_.leftCols(b - a + 1).setZero();
    for (int j = b, s = 0; j > a && !at_rest; --j, ++s) {
      const int current = s & 1, next = current ^ 1;
      RetrogradeTraceStep(j, traces, include_data, velocity_[current], state_[current],
                          velocity_[next], state_[next]);
      segment_.col(j - 1 - a) = state_[next];
    }
    if (a == 0) {
      // W_0 = (1 - theta) omega_0 / c_0; U_0 = 0.
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
  sweep_count_ += at_rest ? 1 : stride < m ? 3 : 2;
}

}  // namespace mcrewave
