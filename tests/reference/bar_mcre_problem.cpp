#include "reference/bar_mcre_problem.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "reference/bar_error_map.h"

namespace mcrewave {
namespace testing {

static_assert(CoupledProblem::kMaxSweepBatch == ThetaIntegrator::kMaxBatch,
              "the batched sweeps interleave the integrator's batch");

BarMcreProblem::BarMcreProblem(const BarModel& model, const ChannelSet& data,
                               const McreWeights& weights, double reference_modulus, double theta,
                               EndDisplacementChannels ends, ClampModel clamp)
    : model_(model),
      data_(data),
      measured_(BarEndChannels(data)),
      theta_(theta),
      ends_(ends),
      clamp_(clamp) {
  assert(weights.IsValid(nullptr) && data.num_steps() >= 1 && reference_modulus > 0.0);
  const BarProperties& bar = model.properties();
  // The weights from the scales of a structure given by matrices (docs/matrix_models.md
  // section 3) with a* = S / L and l* = L, computed as MatrixMcreProblem does:
  // k* = E0 a*, beta = w_u k* = w_u S E0 / L, alpha = w_f / k* = w_f L / (S E0)
  // (docs/discrete_mcre.md) and beta_e = w_e k* l*^2 = w_e S E0 L
  // (docs/zones_and_sensors.md).
  const double stiffness_scale = reference_modulus * (bar.section / bar.length);
  beta_ = weights.displacement_weight * stiffness_scale;
  alpha_ = weights.force_weight / stiffness_scale;
  strain_beta_ = weights.strain_weight * stiffness_scale * bar.length * bar.length;
  const bool trusted = clamp == ClampModel::kTrusted;
  const bool pinned = clamp == ClampModel::kPinned;
  if (trusted) ends_.u0 = false;
  // A pinned clamp always has its u0 row: the datum is the known u(0) = 0, not a
  // channel of the data.
  if (pinned) ends_.u0 = true;
  beta_u0_ = ends_.u0 ? beta_ : 0.0;
  beta_uL_ = ends_.uL ? beta_ : 0.0;
  alpha0_ = alpha_;
  force0_gain_ = trusted ? 0.0 : 1.0;
  if (pinned) {
    // beta_0 = w_u0 k* = w_u0 S E0 / L on the datum u0~ = 0; alpha_0 = w_r / k* on f0.
    beta_u0_ = weights.clamp_displacement_weight * stiffness_scale;
    alpha0_ = weights.reaction_weight / stiffness_scale;
  }
  std::vector<double> weights_of_rows;
  for (const BarSensor& sensor : BarSensors(data)) {
    const Vector& values = data.channels[static_cast<std::size_t>(sensor.index)].values;
    assert(sensor.position >= 0.0 && sensor.position <= bar.length &&
           values.size() == data.num_samples());
    const bool strain = sensor.kind == SensorKind::kStrain;
    sensor_rows_.push_back(strain ? model.StrainRow(sensor.position)
                                  : model.DisplacementRow(sensor.position));
    // U_0 = 0 under a trusted clamp: the row's node-0 part observes nothing and
    // would load the held node.
    if (trusted && sensor_rows_.back().nodes[0] == 0) sensor_rows_.back().coefficients[0] = 0.0;
    weights_of_rows.push_back(strain ? strain_beta_ : beta_);
    sensor_data_.push_back(&values);
  }
  if (trusted) {
    // The clamp reaction r(U) = K_01(E) U_1, weight alpha_r, data f0~; its coefficient
    // is set with the moduli (SetModuli).
    reaction_row_ = static_cast<int>(sensor_rows_.size());
    ObservationRow reaction;
    reaction.nodes[0] = 0;
    reaction.nodes[1] = 1;
    sensor_rows_.push_back(reaction);
    // alpha_r = w_r / k* = w_r L / (S E0).
    weights_of_rows.push_back(weights.reaction_weight / stiffness_scale);
    sensor_data_.push_back(&measured_.f0);
  }
  // The zone stiffnesses K_z = E_nom K1_z at the model's modulus, and a trusted clamp's
  // reaction rows e_0^T K_z / E_nom without the held column 0, of CostGradients.
  nominal_modulus_ = bar.modulus;
  const int n = model.num_nodes();
  for (int z = 0; z < model.num_zones(); ++z) {
    zone_stiffness_.push_back(
        model.Stiffness(Vector::Unit(model.num_zones(), z) * nominal_modulus_));
    if (!trusted) continue;
    const Vector row =
        (zone_stiffness_.back().transpose() * Vector::Unit(n, 0)) * (1.0 / nominal_modulus_);
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 1; i < n; ++i) {
      if (row[i] != 0.0) entries.emplace_back(0, i, row[i]);
    }
    reaction_zone_rows_.emplace_back(1, n);
    reaction_zone_rows_.back().setFromTriplets(entries.begin(), entries.end());
  }
  for (const SparseMatrix& stiffness : zone_stiffness_) zone_forms_.emplace_back(stiffness);
  for (const SparseMatrix& rows : reaction_zone_rows_) reaction_zone_forms_.emplace_back(rows);
  gradient_shift_.resize(n);
  reaction_trace_.resize(1);
  const int num_sensors = static_cast<int>(sensor_rows_.size());
  sensor_weights_ = Eigen::Map<const Vector>(weights_of_rows.data(), num_sensors);
  // The weights of Misfits' rows: uL, the interior sensors, then u0 or the reaction.
  cost_weights_.resize(num_sensors + (trusted ? 1 : 2));
  cost_weights_[0] = beta_uL_;
  for (int k = 0; k < num_sensors - trusted; ++k) cost_weights_[1 + k] = sensor_weights_[k];
  cost_weights_[cost_weights_.size() - 1] = trusted ? sensor_weights_[reaction_row_] : beta_u0_;
  cost_misfits_.resize(cost_weights_.size());
  for (const ObservationRow& row : sensor_rows_) {
    load_nodes_.push_back(row.nodes[0]);
    load_nodes_.push_back(row.nodes[1]);
  }
  load_values_ = Matrix::Zero(2 * num_sensors, ThetaIntegrator::kMaxBatch);
  for (int b = 0; b < ThetaIntegrator::kMaxBatch; ++b) {
    point_loads_[b].count = 2 * num_sensors;
    point_loads_[b].nodes = load_nodes_.data();
    point_loads_[b].values = load_values_.col(b).data();
  }
  for (int b = 0; b < 2; ++b) {
    velocity_[b] = Vector::Zero(n);
    omega_[b] = Vector::Zero(n);
  }
  shift_ = Vector::Zero(n);
  for (int b = 0; b < 2; ++b) {
    for (Vector* v : {&stream_velocity_[b], &stream_omega_[b], &stream_rebuilt_velocity_[b],
                      &stream_rebuilt_omega_[b], &stream_direct_velocity_[b],
                      &stream_displacement_[b], &stream_retrograde_[b]}) {
      *v = Vector::Zero(n);
    }
  }
  stream_shift_ = Vector::Zero(n);
  stream_density_row_ = Vector::Zero(SpaceTimeColumnPositions(model).size());
  if (theta != 0.5) UseCheckpoints();
  batch_velocity_ = Matrix::Zero(n, 2 * ThetaIntegrator::kMaxBatch);
  batch_state_ = Matrix::Zero(n, 2 * ThetaIntegrator::kMaxBatch);
  batch_shift_ = Matrix::Zero(n, ThetaIntegrator::kMaxBatch);
  SetModulus(bar.modulus);
}

void BarMcreProblem::SetModulus(double modulus) {
  assert(modulus > 0.0);
  SetModuli(Vector::Constant(model_.num_zones(), modulus));
}

void BarMcreProblem::SetModuli(const Vector& zone_moduli) {
  assert(zone_moduli.size() == model_.num_zones() && zone_moduli.minCoeff() > 0.0);
  if (moduli_.size() == zone_moduli.size() && moduli_ == zone_moduli) return;
  moduli_ = zone_moduli;
  ThetaIntegratorOptions options;
  options.time_step = data_.time_step;
  options.theta = theta_;
  if (reaction_row_ >= 0) {
    // r(U) = K_01 U_1 = -(E_1 S / l_1) U_1, its row sum_z E_z (e_0^T K_z / E_nom) formed as
    // MatrixMcreProblem forms a support's reaction row.
    reactions_ = moduli_[0] * reaction_zone_rows_[0];
    for (int z = 1; z < num_zones(); ++z) reactions_ += moduli_[z] * reaction_zone_rows_[z];
    sensor_rows_[reaction_row_].coefficients[1] = reactions_.coeff(0, 1);
  }
  // K = sum_z (E_z / E_nom) K_z (StiffnessMatrix); node 0 decoupled under a trusted clamp.
  integrator_.Init(MassMatrix(), StiffnessMatrix(), options);
}

namespace {

// The matrix with row and column 0 decoupled from the others (diagonal kept): the
// node held at rest when its load is zero.
SparseMatrix WithFirstNodeHeld(SparseMatrix matrix) {
  for (int column = 0; column < matrix.outerSize(); ++column) {
    for (SparseMatrix::InnerIterator entry(matrix, column); entry; ++entry) {
      if ((entry.row() == 0) != (entry.col() == 0)) entry.valueRef() = 0.0;
    }
  }
  matrix.prune(0.0);
  return matrix;
}

}  // namespace

SparseMatrix BarMcreProblem::MassMatrix() const {
  return clamp_ == ClampModel::kTrusted ? WithFirstNodeHeld(model_.mass()) : model_.mass();
}

SparseMatrix BarMcreProblem::StiffnessMatrix() const {
  // K = sum_z (E_z / E_nom) K_z, as MatrixModelData::Stiffness sums the zones of the bar
  // exported as matrices (so that the two factorise the same K to the bit).
  SparseMatrix stiffness(num_nodes(), num_nodes());
  for (int z = 0; z < num_zones(); ++z) {
    stiffness += (moduli_[z] / nominal_modulus_) * zone_stiffness_[z];
  }
  return clamp_ == ClampModel::kTrusted ? WithFirstNodeHeld(std::move(stiffness)) : stiffness;
}

void BarMcreProblem::SensorLoads(int j, const double* displacement_j, bool include_data,
                                 double* values) const {
  const double quadrature = QuadratureWeight(j);
  for (int k = 0; k < num_interior_sensors(); ++k) {
    // r_k = c_j beta_k (h_k . U_j - d~_kj), applied as r_k h_k.
    double misfit = displacement_j != nullptr ? sensor_rows_[k].Apply(displacement_j) : 0.0;
    if (include_data) misfit -= (*sensor_data_[k])[j];
    const double load = quadrature * sensor_weights_[k] * misfit;
    values[2 * k] = load * sensor_rows_[k].coefficients[0];
    values[2 * k + 1] = load * sensor_rows_[k].coefficients[1];
  }
}

void BarMcreProblem::DirectSweep(const Matrix& retrograde, bool include_data,
                                 Matrix* displacement) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  assert(retrograde.rows() == n && retrograde.cols() == m + 1);
  displacement->resize(n, m + 1);
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
    // The end forces as MatrixMcreProblem::DirectChannels forms its channels:
    // -W_theta / alpha, then + F~_theta (a trusted clamp's f0: 0).
    double f0 = force0_gain_ * (-shift_[0] / alpha0_);
    double fL = -shift_[last] / alpha_;
    if (include_data) {
      f0 = force0_gain_ * (-shift_[0] / alpha0_ +
                           (theta_ * measured_.f0[k + 1] + (1.0 - theta_) * measured_.f0[k]));
      fL += theta_ * measured_.fL[k + 1] + (1.0 - theta_) * measured_.fL[k];
    }
    integrator_.StepWithEndLoads(velocity_[current], displacement->col(k), shift_, f0, fL,
                                 velocity_[next], displacement->col(k + 1));
  }
  ++sweep_count_;
}

void BarMcreProblem::RetrogradeSweep(const Matrix& displacement, bool include_data,
                                     Matrix* retrograde) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
  assert(displacement.rows() == n && displacement.cols() == m + 1);
  retrograde->resize(n, m + 1);
  // From rest at T: (v_m, omega_m) = (0, 0), in reversed time.
  velocity_[0].setZero();
  omega_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    // Step t_j -> t_{j-1} carries the force c_j H^T diag(beta_k) (H U_j - d~_j) (R2):
    // the end displacement rows as end loads, the interior sensors as point loads.
    const double weight0 = QuadratureWeight(j) * beta_u0_;
    const double weightL = QuadratureWeight(j) * beta_uL_;
    // c_j beta (U_j - d~_j), as MatrixMcreProblem::WeightTraces forms it.
    double f0 = weight0 * (displacement(0, j) - (include_data ? U0Datum(j) : 0.0));
    double fL = weightL * (displacement(last, j) - (include_data ? measured_.uL[j] : 0.0));
    const PointLoads* loads = nullptr;
    if (num_interior_sensors() > 0) {
      SensorLoads(j, displacement.col(j).data(), include_data, load_values_.col(0).data());
      loads = &point_loads_[0];
    }
    integrator_.StepWithEndLoads(velocity_[current], omega_[current], f0, fL, velocity_[next],
                                 omega_[next], loads);
    // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j  (R3), omega_m = 0; times
    // 1/c_j in {1, 2}, exact, instead of a division per entry.
    retrograde->col(j) =
        (theta_ * omega_[next] + (1.0 - theta_) * omega_[current]) * (1.0 / QuadratureWeight(j));
  }
  // W_0 = (1 - theta) omega_0 / c_0 (omega_{-1} = 0).
  retrograde->col(0) = ((1.0 - theta_) / QuadratureWeight(0)) * omega_[m & 1];
  ++sweep_count_;
}

template <int B>
void BarMcreProblem::DirectSweeps(const Matrix* const (&retrograde)[B],
                                  Matrix* const (&displacement)[B]) {
  const int n = num_nodes(), m = num_steps(), last = n - 1;
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
      f0[b] = force0_gain_ * (theta_ * measured_.f0[k + 1] + (1.0 - theta_) * measured_.f0[k]);
      fL[b] = theta_ * measured_.fL[k + 1] + (1.0 - theta_) * measured_.fL[k];
      z[b] = nullptr;
      if (retrograde[b] != nullptr) {
        batch_shift_.col(b) =
            theta_ * retrograde[b]->col(k + 1) + (1.0 - theta_) * retrograde[b]->col(k);
        f0[b] = force0_gain_ * (-batch_shift_(0, b) / alpha0_ +
                                (theta_ * measured_.f0[k + 1] + (1.0 - theta_) * measured_.f0[k]));
        fL[b] = -batch_shift_(last, b) / alpha_ + fL[b];
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
void BarMcreProblem::RetrogradeSweeps(const Matrix* const (&displacement)[B],
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
  const PointLoads* loads[B] = {};
  for (int j = m, step = 0; j > 0; --j, ++step) {
    const int current = step & 1, next = current ^ 1;
    const double* v_k[B];
    const double* omega_k[B];
    double f0[B], fL[B];
    double* v_next[B];
    double* omega_next[B];
    // As RetrogradeSweep: the force c_j H^T diag(beta_k) (H U_j - d~_j) on step
    // t_j -> t_{j-1}.
    const double weight0 = QuadratureWeight(j) * beta_u0_;
    const double weightL = QuadratureWeight(j) * beta_uL_;
    for (int b = 0; b < B; ++b) {
      f0[b] =
          weight0 * ((displacement[b] != nullptr ? (*displacement[b])(0, j) : 0.0) - U0Datum(j));
      fL[b] = weightL *
              ((displacement[b] != nullptr ? (*displacement[b])(last, j) : 0.0) - measured_.uL[j]);
      if (num_interior_sensors() > 0) {
        SensorLoads(j, displacement[b] != nullptr ? displacement[b]->col(j).data() : nullptr, true,
                    load_values_.col(b).data());
        loads[b] = &point_loads_[b];
      }
      v_k[b] = batch_velocity_.col(2 * b + current).data();
      v_next[b] = batch_velocity_.col(2 * b + next).data();
      omega_k[b] = batch_state_.col(2 * b + current).data();
      omega_next[b] = batch_state_.col(2 * b + next).data();
    }
    integrator_.StepsWithEndLoads<B>(v_k, omega_k, no_shift, f0, fL, v_next, omega_next,
                                     num_interior_sensors() > 0 ? loads : nullptr);
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

void BarMcreProblem::DirectSweepsWithData(const std::vector<const Matrix*>& retrograde,
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

void BarMcreProblem::RetrogradeSweepsWithData(const std::vector<const Matrix*>& displacement,
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

double BarMcreProblem::EndForceForm(const double* x, const double* y) const {
  const int last = num_nodes() - 1;
  // (x_N / alpha) y_N + (x_0 / alpha_0) y_0 (a trusted clamp: no f0 term), summed as
  // MatrixMcreProblem sums its load channels fL, f0 (the bar exported with its clamp as
  // a support, docs/matrix_models.md section 6).
  return (x[last] / alpha_) * y[last] + force0_gain_ * ((x[0] / alpha0_) * y[0]);
}

double BarMcreProblem::PenaltyForm(const double* x, const double* y) const {
  // x^T K y + x_N y_N / alpha + x_0 y_0 / alpha_0.
  return integrator_.stiffness().BilinearForm(x, y) + EndForceForm(x, y);
}

double BarMcreProblem::RestCost() {
  // The output part 1/2 (H U - d~)^T diag(beta_k) (H U - d~) of J at U = W = 0 is
  // Cost(0, 0), summed here sample by sample from one zero column (Cost's sum, without
  // an n x (m + 1) field); the load part is alpha/2 |F - F~|^2 with F = 0 (a trusted
  // clamp's f0 is an output, in Cost(0, 0); a pinned clamp's has alpha_0 = w_r L / (S E0)).
  const Vector zero = Vector::Zero(num_nodes());
  const Vector& f0 = data_.Values("f0");
  const Vector& fL = data_.Values("fL");
  double sum = 0.0;
  for (int j = 0; j <= data_.num_steps(); ++j) {
    // c_j h [alpha/2 f~L_j^2 + alpha_0/2 f~0_j^2 + 1/2 d~^T diag(beta_k) d~], in
    // MatrixMcreProblem::RestCost's order (a trusted clamp's f0 is an output).
    const double force_part = (fL[j] * fL[j]) * alpha_ + force0_gain_ * ((f0[j] * f0[j]) * alpha0_);
    Misfits(j, zero.data());
    cost_misfits_ = cost_misfits_.cwiseAbs2();
    sum +=
        QuadratureWeight(j) * time_step() * 0.5 * (force_part + cost_weights_.dot(cost_misfits_));
  }
  return sum;
}

double BarMcreProblem::InnerProduct(const Matrix& x, const Matrix& y) {
  const int m = num_steps();
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    // c_j h x_j^T (K + B/alpha) y_j.
    sum += QuadratureWeight(j) * h * PenaltyForm(x.col(j).data(), y.col(j).data());
  }
  return sum;
}

void BarMcreProblem::Misfits(int j, const double* displacement) {
  const int last = num_nodes() - 1, sensors = num_interior_sensors() - (reaction_row_ >= 0);
  // The rows uL, the interior sensors, then u0 (its datum 0 when pinned) or the trusted
  // clamp's reaction: H's rows of the bar exported with its clamp as a support.
  cost_misfits_[0] = displacement[last] - measured_.uL[j];
  for (int k = 0; k < sensors; ++k) {
    cost_misfits_[1 + k] = sensor_rows_[k].Apply(displacement) - (*sensor_data_[k])[j];
  }
  cost_misfits_[1 + sensors] =
      reaction_row_ >= 0
          ? sensor_rows_[reaction_row_].Apply(displacement) - (*sensor_data_[reaction_row_])[j]
          : displacement[0] - U0Datum(j);
}

double BarMcreProblem::SampleCost(int j, const double* displacement, const double* retrograde) {
  // 1/2 W^T K W + 1/2 W^T B W / alpha + 1/2 (H U - d~)^T diag(beta_k) (H U - d~), each
  // part summed as MatrixMcreProblem::Cost sums it.
  const double gap = integrator_.stiffness().BilinearForm(retrograde, retrograde);
  Misfits(j, displacement);
  cost_misfits_ = cost_misfits_.cwiseAbs2();
  return 0.5 * gap + 0.5 * EndForceForm(retrograde, retrograde) +
         0.5 * cost_weights_.dot(cost_misfits_);
}

double BarMcreProblem::Cost(const Matrix& displacement, const Matrix& retrograde) {
  const int m = num_steps();
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= m; ++j) {
    // c_j h [1/2 W^T K W + W^T B W / (2 alpha) + 1/2 (H U - d~)^T diag(beta) (H U - d~)].
    sum += QuadratureWeight(j) * h *
           SampleCost(j, displacement.col(j).data(), retrograde.col(j).data());
  }
  return sum;
}

void BarMcreProblem::AddSampleCostGradients(int j, const double* displacement,
                                            const double* retrograde, Vector* gradient) {
  const int n = num_nodes();
  const double h = time_step();
  const Eigen::Map<const Vector> u(displacement, n), w(retrograde, n);
  // MatrixMcreProblem::CostGradients' sums on the bar exported as matrices
  // (BarMatrixModel with K_z = E_nom K1_z, E_nom = the model's modulus, and the clamp a
  // support), so that the bar's and the exported bar's gradients are the same bits.
  gradient_shift_ = w + 2.0 * u;
  for (int z = 0; z < num_zones(); ++z) {
    // -(1/(2 E_nom)) c_j h W_j^T K_z (W_j + 2 U_j).
    (*gradient)[z] += -0.5 * QuadratureWeight(j) * h *
                      zone_forms_[z](retrograde, gradient_shift_.data()) / nominal_modulus_;
  }
  if (reaction_row_ < 0) return;
  // Trusted: c_j h alpha_r (r(U_j) - f0~_j) e_0^T K_z U_j / E_nom, the explicit term
  // alpha_r (r(U_j) / E_1) (r(U_j) - f0~_j) of the zone of element 1.
  reaction_trace_.noalias() = reactions_ * u;
  reaction_trace_[0] -= measured_.f0[j];
  for (int z = 0; z < num_zones(); ++z) {
    (*gradient)[z] += QuadratureWeight(j) * h * sensor_weights_[reaction_row_] *
                      reaction_zone_forms_[z](reaction_trace_.data(), displacement);
  }
}

double BarMcreProblem::CostGradient(const Matrix& displacement, const Matrix& retrograde) {
  Vector gradient;
  CostGradients(displacement, retrograde, &gradient);
  return gradient.sum();
}

void BarMcreProblem::CostGradients(const Matrix& displacement, const Matrix& retrograde,
                                   Vector* gradient) {
  gradient->setZero(num_zones());
  for (int j = 0; j <= num_steps(); ++j) {
    AddSampleCostGradients(j, displacement.col(j).data(), retrograde.col(j).data(), gradient);
  }
}

SparseMatrix BarMcreProblem::PenaltyMatrix() const {
  // P = K + e_0 e_0^T / alpha_0 + e_N e_N^T / alpha with 1 / alpha_0 = inverse_alpha0():
  // the paper's K + B / alpha (measured clamp), K + e_N e_N^T / alpha (trusted: 0, on the
  // held node's kept diagonal) or the pinned clamp's alpha_0.
  SparseMatrix penalty = StiffnessMatrix();
  penalty.coeffRef(0, 0) += inverse_alpha0();
  penalty.coeffRef(num_nodes() - 1, num_nodes() - 1) += 1.0 / alpha_;
  return penalty;
}

void BarMcreProblem::MeasuredForce(int j, Eigen::Ref<Vector> load) const {
  load.setZero();
  load[0] = force0_gain_ * measured_.f0[j];
  load[num_nodes() - 1] = measured_.fL[j];
}

SparseMatrix BarMcreProblem::WeightedObservation() const {
  const int n = num_nodes();
  std::vector<Eigen::Triplet<double>> entries{{0, 0, beta_u0_}, {n - 1, n - 1, beta_uL_}};
  for (int k = 0; k < num_interior_sensors(); ++k) {
    // beta_k h_k h_k^T.
    const ObservationRow& row = sensor_rows_[k];
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        entries.emplace_back(row.nodes[a], row.nodes[b],
                             sensor_weights_[k] * row.coefficients[a] * row.coefficients[b]);
      }
    }
  }
  SparseMatrix weighted(n, n);
  weighted.setFromTriplets(entries.begin(), entries.end());
  weighted.prune(0.0);
  return weighted;
}

void BarMcreProblem::WeightedData(int j, Eigen::Ref<Vector> load) const {
  load.setZero();
  load[0] += beta_u0_ * U0Datum(j);
  load[num_nodes() - 1] += beta_uL_ * measured_.uL[j];
  for (int k = 0; k < num_interior_sensors(); ++k) {
    // beta_k h_k d~_kj.
    const ObservationRow& row = sensor_rows_[k];
    const double weighted = sensor_weights_[k] * (*sensor_data_[k])[j];
    load[row.nodes[0]] += weighted * row.coefficients[0];
    load[row.nodes[1]] += weighted * row.coefficients[1];
  }
}

Vector BarMcreProblem::ErrorMap(const Matrix& retrograde) const {
  return ElementGapShares(model_, moduli_, retrograde, time_step());
}

McreObjective BarMcreObjective(const BarModel& model, const ChannelSet& data,
                               const McreOptions& mcre, double theta,
                               const CoupledSolverOptions& inner, double modulus_scale,
                               EndDisplacementChannels ends) {
  assert(mcre.IsValid(nullptr));
  return McreObjective(
      [&model, &data, mcre, theta, ends]() -> std::unique_ptr<StreamingCoupledProblem> {
        return std::make_unique<BarMcreProblem>(model, data, mcre.weights, mcre.reference_modulus,
                                                theta, ends, mcre.clamp);
      },
      inner, modulus_scale);
}

}  // namespace testing
}  // namespace mcrewave
