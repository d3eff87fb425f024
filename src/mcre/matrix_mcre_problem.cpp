#include "mcrewave/mcre/matrix_mcre_problem.h"

#include <cassert>
#include <vector>

namespace mcrewave {

ChannelSet MatrixChannelSet(const MatrixModelData& model, double time_step, const Matrix& loads,
                            const Matrix& outputs) {
  assert(loads.rows() == static_cast<Eigen::Index>(model.loads.size()) &&
         outputs.rows() == static_cast<Eigen::Index>(model.sensors.size()) &&
         outputs.cols() == loads.cols());
  ChannelSet set;
  set.time_step = time_step;
  for (std::size_t c = 0; c < model.loads.size(); ++c) {
    set.Add(model.loads[c].channel, ChannelKind::kForce,
            loads.row(static_cast<Eigen::Index>(c)).transpose());
  }
  for (std::size_t k = 0; k < model.sensors.size(); ++k) {
    set.Add(model.sensors[k].channel,
            model.sensors[k].kind == SensorKind::kStrain ? ChannelKind::kStrain
                                                         : ChannelKind::kDisplacement,
            outputs.row(static_cast<Eigen::Index>(k)).transpose());
  }
  return set;
}

MatrixMcreProblem::MatrixMcreProblem(const MatrixModelData& model, const ChannelSet& data,
                                     const McreWeights& weights, double reference_modulus,
                                     double theta, Factorization factorization)
    : model_(model), time_step_(data.time_step), theta_(theta), factorization_(factorization) {
  const int n = model.dofs();
  const int num_loads = static_cast<int>(model.loads.size());
  const int num_sensors = static_cast<int>(model.sensors.size());
  // The data's channels of the model, gathered once into rows (columns t_j for the sweeps).
  const int samples = data.num_samples();
  measured_loads_.resize(num_loads, samples);
  for (int c = 0; c < num_loads; ++c) {
    measured_loads_.row(c) = data.Values(model.loads[c].channel).transpose();
  }
  measured_outputs_.resize(num_sensors, samples);
  for (int k = 0; k < num_sensors; ++k) {
    measured_outputs_.row(k) = data.Values(model.sensors[k].channel).transpose();
  }
  assert(weights.IsValid(nullptr) && reference_modulus > 0.0 && num_steps() >= 1 &&
         model.stiffness_length > 0.0 && model.length > 0.0);
  // k* = E0 a*; alpha_c = w_f / k*, beta_k = w_u k* or w_e k* l*^2
  // (docs/matrix_models.md section 3).
  const double stiffness_scale = reference_modulus * model.stiffness_length;
  alphas_ = Vector::Constant(num_loads, weights.force_weight / stiffness_scale);
  betas_.resize(num_sensors);
  std::vector<Eigen::Triplet<double>> entries;
  for (int c = 0; c < num_loads; ++c) {
    const Vector& g = model.loads[c].vector;
    for (int i = 0; i < n; ++i) {
      if (g[i] != 0.0) entries.emplace_back(i, c, g[i]);
    }
  }
  loads_.resize(n, num_loads);
  loads_.setFromTriplets(entries.begin(), entries.end());
  loads_transposed_ = loads_.transpose();
  entries.clear();
  for (int k = 0; k < num_sensors; ++k) {
    const MatrixModelSensor& sensor = model.sensors[k];
    betas_[k] = sensor.kind == SensorKind::kStrain
                    ? weights.strain_weight * stiffness_scale * model.length * model.length
                    : weights.displacement_weight * stiffness_scale;
    for (int outer = 0; outer < sensor.row.outerSize(); ++outer) {
      for (SparseMatrix::InnerIterator it(sensor.row, outer); it; ++it) {
        entries.emplace_back(k, static_cast<int>(it.col()), it.value());
      }
    }
  }
  observation_.resize(num_sensors, n);
  observation_.setFromTriplets(entries.begin(), entries.end());
  observation_transposed_ = observation_.transpose();
  for (int b = 0; b < 2; ++b) {
    velocity_[b] = Vector::Zero(n);
    state_[b] = Vector::Zero(n);
  }
  shift_ = Vector::Zero(n);
  force_ = Vector::Zero(n);
  product_ = Vector::Zero(n);
  channel_ = Vector::Zero(num_loads);
  other_channel_ = Vector::Zero(num_loads);
  trace_ = Vector::Zero(num_sensors);
  SetModuli(NominalModuli());
}

void MatrixMcreProblem::SetModuli(const Vector& zone_moduli) {
  assert(zone_moduli.size() == static_cast<Eigen::Index>(model_.zones.size()) &&
         zone_moduli.minCoeff() > 0.0);
  if (moduli_.size() == zone_moduli.size() && moduli_ == zone_moduli) return;
  moduli_ = zone_moduli;
  // K = sum_z (E_z / E_z,nom) K_z.
  stiffness_ = model_.Stiffness(moduli_);
  ThetaIntegratorOptions options;
  options.time_step = time_step_;
  options.theta = theta_;
  options.factorization = factorization_;
  integrator_.Init(model_.mass, stiffness_, options);
}

void MatrixMcreProblem::DirectSweep(const Matrix& retrograde, bool include_data,
                                    Matrix* displacement) {
  const int n = num_nodes(), m = num_steps();
  assert(retrograde.rows() == n && retrograde.cols() == m + 1);
  displacement->resize(n, m + 1);
  // From rest: U_0 = V_0 = 0.
  displacement->col(0).setZero();
  velocity_[0].setZero();
  for (int k = 0; k < m; ++k) {
    const int current = k & 1, next = current ^ 1;
    // f_theta = -K W_theta + G (F~_theta - diag(1/alpha) G^T W_theta),
    // W_theta = theta W_{k+1} + (1 - theta) W_k.
    shift_ = theta_ * retrograde.col(k + 1) + (1.0 - theta_) * retrograde.col(k);
    channel_.noalias() = loads_transposed_ * shift_;
    channel_ = -channel_.cwiseQuotient(alphas_);
    if (include_data) {
      channel_ += theta_ * measured_loads_.col(k + 1) + (1.0 - theta_) * measured_loads_.col(k);
    }
    force_.noalias() = loads_ * channel_;
    integrator_.StepShifted(velocity_[current], displacement->col(k), shift_, force_,
                            velocity_[next], displacement->col(k + 1));
  }
  ++sweep_count_;
}

void MatrixMcreProblem::RetrogradeSweep(const Matrix& displacement, bool include_data,
                                        Matrix* retrograde) {
  const int n = num_nodes(), m = num_steps();
  assert(displacement.rows() == n && displacement.cols() == m + 1);
  retrograde->resize(n, m + 1);
  // From rest at T: (v_m, omega_m) = (0, 0), in reversed time.
  velocity_[0].setZero();
  state_[0].setZero();
  for (int j = m, s = 0; j > 0; --j, ++s) {
    const int current = s & 1, next = current ^ 1;
    // Step t_j -> t_{j-1} carries c_j H^T diag(beta) (H U_j - d~_j).
    trace_.noalias() = observation_ * displacement.col(j);
    if (include_data) trace_ -= measured_outputs_.col(j);
    trace_ = (QuadratureWeight(j) * betas_).cwiseProduct(trace_);
    force_.noalias() = observation_transposed_ * trace_;
    integrator_.Step(velocity_[current], state_[current], force_, velocity_[next], state_[next]);
    // W_j = (theta omega_{j-1} + (1 - theta) omega_j) / c_j, omega_m = 0.
    retrograde->col(j) =
        (theta_ * state_[next] + (1.0 - theta_) * state_[current]) * (1.0 / QuadratureWeight(j));
  }
  // W_0 = (1 - theta) omega_0 / c_0 (omega_{-1} = 0).
  retrograde->col(0) = ((1.0 - theta_) / QuadratureWeight(0)) * state_[m & 1];
  ++sweep_count_;
}

double MatrixMcreProblem::InnerProduct(const Matrix& x, const Matrix& y) {
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // x_j^T (K + G diag(1/alpha) G^T) y_j.
    product_.noalias() = stiffness_ * y.col(j);
    channel_.noalias() = loads_transposed_ * x.col(j);
    other_channel_.noalias() = loads_transposed_ * y.col(j);
    const double term =
        x.col(j).dot(product_) + channel_.cwiseQuotient(alphas_).dot(other_channel_);
    sum += QuadratureWeight(j) * h * term;
  }
  return sum;
}

double MatrixMcreProblem::Cost(const Matrix& displacement, const Matrix& retrograde) {
  const double h = time_step();
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h [1/2 W^T K W + 1/2 (G^T W)^T diag(1/alpha) G^T W
    //        + 1/2 (H U - d~)^T diag(beta) (H U - d~)].
    product_.noalias() = stiffness_ * retrograde.col(j);
    channel_.noalias() = loads_transposed_ * retrograde.col(j);
    trace_.noalias() = observation_ * displacement.col(j);
    trace_ -= measured_outputs_.col(j);
    const double integrand = 0.5 * retrograde.col(j).dot(product_) +
                             0.5 * channel_.cwiseQuotient(alphas_).dot(channel_) +
                             0.5 * betas_.dot(trace_.cwiseProduct(trace_));
    sum += QuadratureWeight(j) * h * integrand;
  }
  return sum;
}

void MatrixMcreProblem::CostGradients(const Matrix& displacement, const Matrix& retrograde,
                                      Vector* gradient) {
  const int zones = static_cast<int>(model_.zones.size());
  const double h = time_step();
  gradient->setZero(zones);
  for (int j = 0; j <= num_steps(); ++j) {
    shift_ = retrograde.col(j) + 2.0 * displacement.col(j);
    for (int z = 0; z < zones; ++z) {
      // -(1/(2 E_z,nom)) c_j h W_j^T K_z (W_j + 2 U_j).
      product_.noalias() = model_.zones[z].stiffness * shift_;
      (*gradient)[z] += -0.5 * QuadratureWeight(j) * h * retrograde.col(j).dot(product_) /
                        model_.zones[z].nominal_modulus;
    }
  }
}

Vector MatrixMcreProblem::ZoneErrorMap(const Matrix& retrograde) {
  const int zones = static_cast<int>(model_.zones.size());
  const double h = time_step();
  Vector map = Vector::Zero(zones);
  for (int j = 0; j <= num_steps(); ++j) {
    for (int z = 0; z < zones; ++z) {
      // (E_z / E_z,nom) c_j h 1/2 W_j^T K_z W_j.
      product_.noalias() = model_.zones[z].stiffness * retrograde.col(j);
      map[z] += (moduli_[z] / model_.zones[z].nominal_modulus) * QuadratureWeight(j) * h * 0.5 *
                retrograde.col(j).dot(product_);
    }
  }
  return map;
}

Vector MatrixMcreProblem::DofErrorMap(const Matrix& retrograde) {
  const double h = time_step();
  Vector map = Vector::Zero(num_nodes());
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h 1/2 W_ij (K W_j)_i.
    product_.noalias() = stiffness_ * retrograde.col(j);
    map += (0.5 * QuadratureWeight(j) * h) * retrograde.col(j).cwiseProduct(product_);
  }
  return map;
}

SparseMatrix MatrixMcreProblem::PenaltyMatrix() const {
  // P = K + G diag(1/alpha) G^T.
  const SparseMatrix scaled = loads_ * alphas_.cwiseInverse().asDiagonal();
  return stiffness_ + SparseMatrix(scaled * loads_transposed_);
}

SparseMatrix MatrixMcreProblem::WeightedObservation() const {
  // H^T diag(beta) H.
  const SparseMatrix weighted = observation_transposed_ * betas_.asDiagonal();
  return SparseMatrix(weighted * observation_);
}

void MatrixMcreProblem::WeightedData(int j, Eigen::Ref<Vector> load) const {
  // H^T diag(beta) d~_j.
  load.noalias() = observation_transposed_ * betas_.cwiseProduct(measured_outputs_.col(j));
}

void MatrixMcreProblem::MeasuredForce(int j, Eigen::Ref<Vector> load) const {
  // G F~_j.
  load.noalias() = loads_ * measured_loads_.col(j);
}

double MatrixMcreProblem::RestCost() const {
  double sum = 0.0;
  for (int j = 0; j <= num_steps(); ++j) {
    // c_j h [1/2 F~^T diag(alpha) F~ + 1/2 d~^T diag(beta) d~].
    sum += QuadratureWeight(j) * time_step() * 0.5 *
           (alphas_.dot(measured_loads_.col(j).cwiseAbs2()) +
            betas_.dot(measured_outputs_.col(j).cwiseAbs2()));
  }
  return sum;
}

Vector MatrixMcreProblem::NominalModuli() const {
  Vector nominal(model_.zones.size());
  for (std::size_t z = 0; z < model_.zones.size(); ++z) {
    nominal[static_cast<Eigen::Index>(z)] = model_.zones[z].nominal_modulus;
  }
  return nominal;
}

Matrix MatrixMcreProblem::ModelOutputs() {
  Matrix displacement;
  DirectSweep(ZeroField(), true, &displacement);
  return observation_ * displacement;
}

}  // namespace mcrewave
