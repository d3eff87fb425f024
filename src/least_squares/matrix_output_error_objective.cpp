#include "mcrewave/least_squares/matrix_output_error_objective.h"

#include <spdlog/spdlog.h>

#include <Eigen/SparseCholesky>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "mcrewave/mcre/matrix_mcre_problem.h"

namespace mcrewave {

MatrixOutputErrorObjective::MatrixOutputErrorObjective(const MatrixModelData& model,
                                                       const ChannelSet& data,
                                                       const NoiseLevels& misfit_levels,
                                                       double theta, Factorization factorization,
                                                       double modulus_scale)
    : LogModuliObjective(
          modulus_scale > 0.0
              ? Vector::Constant(static_cast<Eigen::Index>(model.zones.size()), modulus_scale)
              : model.NominalModuli()),
      model_(model),
      time_step_(data.time_step),
      theta_(theta),
      factorization_(factorization) {
  const int n = model.dofs();
  const int zones = static_cast<int>(model.zones.size());
  const int num_loads = static_cast<int>(model.loads.size());
  const int num_sensors = static_cast<int>(model.sensors.size());
  const int samples = data.num_samples();
  // The supports' held dofs (docs/matrix_models.md section 11): none without supports.
  if (!model.supports.empty()) {
    held_.assign(static_cast<std::size_t>(n), 0);
    for (const MatrixModelSupport& support : model.supports) {
      for (const int dof : support.dofs) held_[static_cast<std::size_t>(dof)] = 1;
    }
  }
  auto kept = [&](Eigen::Index i) {
    return held_.empty() || held_[static_cast<std::size_t>(i)] == 0;
  };
  // The data's channels of the model, gathered once into rows (columns t_j).
  measured_loads_.resize(num_loads, samples);
  for (int c = 0; c < num_loads; ++c) {
    measured_loads_.row(c) = data.Values(model.loads[c].channel).transpose();
  }
  measured_outputs_.resize(num_sensors, samples);
  for (int k = 0; k < num_sensors; ++k) {
    measured_outputs_.row(k) = data.Values(model.sensors[k].channel).transpose();
  }
  assert(samples >= 2 && theta >= 0.0 && theta <= 1.0);
  for (int z = 0; z < zones; ++z) {
    // dK/dE_z = K_z / E_z,nom (docs/formulation.md section 6), the held dofs decoupled.
    zone_stiffness_.push_back(model.zones[z].stiffness / model.zones[z].nominal_modulus);
    if (!held_.empty()) zone_stiffness_.back() = WithHeldDofs(zone_stiffness_.back(), held_);
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (int c = 0; c < num_loads; ++c) {
    const Vector& g = model.loads[c].vector;
    for (int i = 0; i < n; ++i) {
      // A load on a held dof goes into the support (as the trusted MCRE's).
      if (g[i] != 0.0 && kept(i)) entries.emplace_back(i, c, g[i]);
    }
  }
  loads_.resize(n, num_loads);
  loads_.setFromTriplets(entries.begin(), entries.end());
  entries.clear();
  weights_.resize(num_sensors);
  for (int k = 0; k < num_sensors; ++k) {
    const MatrixModelSensor& sensor = model.sensors[k];
    // w_k = 1 / s^2 of the sensor's kind (docs/formulation.md section 8).
    const bool strain = sensor.kind == SensorKind::kStrain;
    const double level = strain ? misfit_levels.strain_std : misfit_levels.displacement_std;
    assert(level > 0.0);
    weights_[k] = 1.0 / (level * level);
    for (int outer = 0; outer < sensor.row.outerSize(); ++outer) {
      for (SparseRow::InnerIterator it(sensor.row, outer); it; ++it) {
        // U = 0 on a held dof: the row's entry there observes nothing.
        if (kept(it.col())) entries.emplace_back(k, static_cast<int>(it.col()), it.value());
      }
    }
  }
  observation_.resize(num_sensors, n);
  observation_.setFromTriplets(entries.begin(), entries.end());
  BuildReactions(data, misfit_levels);
  for (int b = 0; b < 2; ++b) {
    velocity_[b] = Vector::Zero(n);
    displacement_[b] = Vector::Zero(n);
    sensitivity_velocity_[b] = Matrix::Zero(n, zones);
    sensitivity_[b] = Matrix::Zero(n, zones);
  }
  weighted_ = Vector::Zero(n);
  force_ = Vector::Zero(n);
  channel_ = Vector::Zero(num_loads);
  residual_ = Vector::Zero(num_sensors);
  trace_ = Vector::Zero(num_sensors);
  outputs_ = Matrix::Zero(num_sensors, samples);
  // J_rest = 1/2 sum_j c_j h [sum_k w_k d~_kj^2 + w_f sum_s f~_sj^2]
  for (int j = 0; j < samples; ++j) {
    const double c = SampleWeight(j);
    rest_cost_ += 0.5 * c * time_step_ * measured_outputs_.col(j).cwiseAbs2().dot(weights_);
    if (!held_.empty()) {
      rest_cost_ += 0.5 * c * time_step_ * force_weight_ * measured_forces_.col(j).squaredNorm();
    }
  }
}

void MatrixOutputErrorObjective::BuildReactions(const ChannelSet& data,
                                                const NoiseLevels& misfit_levels) {
  const int n = model_.dofs();
  const auto supports = static_cast<int>(model_.supports.size());
  const auto samples = data.num_samples();
  measured_forces_.resize(supports, samples);
  support_forces_ = Matrix::Zero(supports, samples);
  force_residual_ = Vector::Zero(supports);
  force_trace_ = Vector::Zero(supports);
  reaction_rows_ = Matrix::Zero(supports, n);
  reaction_loads_ = Matrix::Zero(supports, loads_.cols());
  if (supports == 0) return;
  // w_f = 1 / s_f^2, the bar's clamp reaction's weight.
  assert(misfit_levels.force_std > 0.0);
  force_weight_ = 1.0 / (misfit_levels.force_std * misfit_levels.force_std);
  held_mass_ = WithHeldDofs(model_.mass, held_);
  Eigen::SimplicialLDLT<SparseMatrix> mass_factor(held_mass_);
  if (mass_factor.info() != Eigen::Success) {
    throw std::runtime_error(
        "output-error model with supports: the mass matrix of the free dofs is not positive "
        "definite");
  }
  Matrix rows(supports, n);  // (g_s - m_s)^T
  for (int s = 0; s < supports; ++s) {
    const MatrixModelSupport& support = model_.supports[s];
    measured_forces_.row(s) = data.Values(support.force_channel).transpose();
    // m_s = M_ff^-1 (M g_s)_f, 0 on D (the held rows of M decoupled; docs/matrix_models.md
    // section 10).
    Vector coupling = model_.mass * support.reaction;
    for (int i = 0; i < n; ++i) {
      if (held_[static_cast<std::size_t>(i)] != 0) coupling[i] = 0.0;
    }
    const Vector inertia = mass_factor.solve(coupling);
    // p_s = G_f^T m_s (G's held rows dropped)
    reaction_loads_.row(s) = (loads_.transpose() * inertia).transpose();
    rows.row(s) = (support.reaction - inertia).transpose();
  }
  for (const MatrixModelZone& zone : model_.zones) {
    // v_sz = [K_z (g_s - m_s)]_f / E_z,nom (K_z symmetric)
    Matrix zone_rows = (rows * zone.stiffness) * (1.0 / zone.nominal_modulus);
    for (int i = 0; i < n; ++i) {
      if (held_[static_cast<std::size_t>(i)] != 0) zone_rows.col(i).setZero();
    }
    reaction_zone_rows_.push_back(std::move(zone_rows));
  }
}

double MatrixOutputErrorObjective::SampleCost(int j, const Vector& displacement,
                                              const Matrix& sensitivity, Vector* gradient,
                                              Matrix* fisher_information,
                                              std::vector<Matrix>* sensor_information) {
  const int zones = num_parameters();
  const double h = time_step_;
  // r_j = H U_j - d~_j
  trace_.noalias() = observation_ * displacement;
  outputs_.col(j) = trace_;
  residual_ = trace_ - measured_outputs_.col(j);
  const double c = SampleWeight(j);
  // c_j h / 2 sum_k w_k r_kj^2
  double cost = 0.5 * c * h * residual_.cwiseAbs2().dot(weights_);
  const bool supports = !held_.empty();
  if (supports) {
    // r_s,j = q_s^T U_j + p_s^T F~_j against f~_sj: c_j h / 2 w_f sum_s (r_s,j - f~_sj)^2
    force_trace_.noalias() = reaction_rows_ * displacement;
    force_trace_.noalias() += reaction_loads_ * measured_loads_.col(j);
    support_forces_.col(j) = force_trace_;
    force_residual_ = force_trace_ - measured_forces_.col(j);
    cost += 0.5 * c * h * force_weight_ * force_residual_.squaredNorm();
  }
  if (gradient == nullptr) return cost;
  const bool information = fisher_information != nullptr || sensor_information != nullptr;
  for (int z = 0; z < zones; ++z) {
    // c_j h sum_k w_k r_kj (H S_z,j)_k
    trace_.noalias() = observation_ * sensitivity.col(z);
    (*gradient)[z] += c * h * residual_.cwiseProduct(weights_).dot(trace_);
    if (information) output_sensitivity_.col(z) = trace_;
    if (!supports) continue;
    // dr_s,j/dE_z = q_s^T S_z,j + v_sz^T U_j;  c_j h w_f sum_s (r_s,j - f~_sj) dr_s,j/dE_z
    force_trace_.noalias() = reaction_rows_ * sensitivity.col(z);
    force_trace_.noalias() += reaction_zone_rows_[static_cast<std::size_t>(z)] * displacement;
    (*gradient)[z] += c * h * force_weight_ * force_residual_.dot(force_trace_);
    if (information) force_sensitivity_.col(z) = force_trace_;
  }
  if (sensor_information != nullptr) {
    // I_k += c_j w_k (h_k S_j)(h_k S_j)^T, its lower triangle (Cost fills the upper).
    for (Eigen::Index k = 0; k < output_sensitivity_.rows(); ++k) {
      sensor_sensitivity_ = output_sensitivity_.row(k).transpose();
      (*sensor_information)[static_cast<std::size_t>(k)].selfadjointView<Eigen::Lower>().rankUpdate(
          sensor_sensitivity_, c * weights_[k]);
    }
  }
  if (fisher_information != nullptr) {
    // c_j [(H S_z,j)^T W (H S_z',j) + w_f (dr_j/dE_z)^T (dr_j/dE_z')], column by column
    // (no temporary in the time loop).
    for (int z = 0; z < zones; ++z) {
      trace_ = output_sensitivity_.col(z).cwiseProduct(weights_);
      for (int y = 0; y <= z; ++y) {
        double term = trace_.dot(output_sensitivity_.col(y));
        if (supports)
          term += force_weight_ * force_sensitivity_.col(z).dot(force_sensitivity_.col(y));
        (*fisher_information)(z, y) += c * term;
        if (y != z) (*fisher_information)(y, z) = (*fisher_information)(z, y);
      }
    }
  }
  return cost;
}

void MatrixOutputErrorObjective::SetGradientMethod(LeastSquaresGradient method) {
  gradient_method_ = method;
  if (method != LeastSquaresGradient::kAdjoint || !zone_forms_.empty()) return;
  const auto n = static_cast<Eigen::Index>(model_.dofs());
  trajectory_ = Matrix::Zero(n, measured_outputs_.cols());
  for (const SparseMatrix& stiffness : zone_stiffness_) zone_forms_.emplace_back(stiffness);
  for (int b = 0; b < 2; ++b) {
    adjoint_velocity_[b] = Vector::Zero(n);
    adjoint_displacement_[b] = Vector::Zero(n);
  }
  adjoint_force_ = Vector::Zero(n);
  adjoint_load_ = Vector::Zero(n);
  weighted_residual_ = Vector::Zero(observation_.rows());
}

void MatrixOutputErrorObjective::AdjointLoad(int j, Vector* gradient) {
  const double c = SampleWeight(j);
  const double h = time_step_;
  // c_j h H^T W (H U_j - d~_j)
  weighted_residual_ = outputs_.col(j) - measured_outputs_.col(j);
  weighted_residual_ = (c * h) * weighted_residual_.cwiseProduct(weights_);
  adjoint_load_.noalias() = observation_.transpose() * weighted_residual_;
  if (held_.empty()) return;
  // + c_j h w_f sum_s (r_s,j - f~_sj) q_s, and the explicit part of dJ/dE_z,
  // c_j h w_f sum_s (r_s,j - f~_sj) v_sz^T U_j.
  force_residual_ = support_forces_.col(j) - measured_forces_.col(j);
  force_residual_ *= c * h * force_weight_;
  adjoint_load_.noalias() += reaction_rows_.transpose() * force_residual_;
  for (int z = 0; z < num_parameters(); ++z) {
    force_trace_.noalias() = reaction_zone_rows_[static_cast<std::size_t>(z)] * trajectory_.col(j);
    (*gradient)[z] += force_residual_.dot(force_trace_);
  }
}

void MatrixOutputErrorObjective::AdjointGradient(Vector* gradient) {
  const int zones = num_parameters();
  const int last = static_cast<int>(measured_outputs_.cols()) - 1;
  const double h = time_step_;
  gradient->setZero(zones);
  // From t_m: a_m = 0, e_m = g_m.
  int current = 0;
  adjoint_velocity_[0].setZero();
  AdjointLoad(last, gradient);
  adjoint_displacement_[0] = adjoint_load_;
  for (int k = last - 1; k >= 0; --k) {
    const int next = current ^ 1;
    // y_k, a_k and e_k - g_k: the transposed step t_{k+1} -> t_k.
    integrator_.StepTransposed(adjoint_velocity_[current], adjoint_displacement_[current],
                               adjoint_force_, adjoint_velocity_[next],
                               adjoint_displacement_[next]);
    // U_theta,k = theta U_{k+1} + (1 - theta) U_k
    weighted_ = theta_ * trajectory_.col(k + 1) + (1.0 - theta_) * trajectory_.col(k);
    for (int z = 0; z < zones; ++z) {
      // -h/E_z,nom y_k^T K_z U_theta,k
      (*gradient)[z] -=
          h * zone_forms_[static_cast<std::size_t>(z)](adjoint_force_.data(), weighted_.data());
    }
    AdjointLoad(k, gradient);
    adjoint_displacement_[next] += adjoint_load_;
    current = next;
  }
}

double MatrixOutputErrorObjective::Cost(const Vector& zone_moduli, Vector* gradient,
                                        Matrix* fisher_information,
                                        std::vector<Matrix>* sensor_information) {
  const int zones = num_parameters();
  assert((fisher_information == nullptr && sensor_information == nullptr) || gradient != nullptr);
  assert(zone_moduli.size() == zones && zone_moduli.allFinite() && zone_moduli.minCoeff() > 0.0);
  ThetaIntegratorOptions options;
  options.time_step = time_step_;
  options.theta = theta_;
  options.factorization = factorization_;
  // K = sum_z (E_z / E_z,nom) K_z, factorised once for the state and every sensitivity;
  // with supports, the held dofs decoupled in M and K.
  if (held_.empty()) {
    integrator_.Init(model_.mass, model_.Stiffness(zone_moduli), options);
  } else {
    integrator_.Init(held_mass_, WithHeldDofs(model_.Stiffness(zone_moduli), held_), options);
    // q_s(E) = sum_z E_z v_sz
    reaction_rows_.setZero();
    for (int z = 0; z < zones; ++z) {
      reaction_rows_ += zone_moduli[z] * reaction_zone_rows_[static_cast<std::size_t>(z)];
    }
  }

  const bool gradient_requested = gradient != nullptr;
  // The adjoint's gradient when chosen; the Fisher information needs the sensitivities.
  const bool adjoint = gradient_requested && gradient_method_ == LeastSquaresGradient::kAdjoint &&
                       fisher_information == nullptr && sensor_information == nullptr;
  const bool sensitivities = gradient_requested && !adjoint;
  if (gradient_requested) gradient->setZero(zones);
  if (fisher_information != nullptr) fisher_information->setZero(zones, zones);
  if (sensor_information != nullptr) {
    sensor_information->assign(static_cast<std::size_t>(observation_.rows()),
                               Matrix::Zero(zones, zones));
    sensor_sensitivity_.resize(zones);
  }
  if (fisher_information != nullptr || sensor_information != nullptr) {
    output_sensitivity_.resize(observation_.rows(), zones);
    force_sensitivity_.resize(static_cast<Eigen::Index>(model_.supports.size()), zones);
  }
  const int samples = static_cast<int>(measured_outputs_.cols());
  int current = 0;
  // From rest: U_0 = V_0 = 0, S_z,0 = S_z,0' = 0.
  velocity_[0].setZero();
  displacement_[0].setZero();
  sensitivity_velocity_[0].setZero();
  sensitivity_[0].setZero();
  double cost = 0.0;
  for (int j = 0; j < samples; ++j) {
    if (j > 0) {
      const int next = current ^ 1;
      // f_theta = G (theta F~_j + (1 - theta) F~_{j-1}) on the step t_{j-1} -> t_j.
      channel_ = theta_ * measured_loads_.col(j) + (1.0 - theta_) * measured_loads_.col(j - 1);
      force_.noalias() = loads_ * channel_;
      integrator_.Step(velocity_[current], displacement_[current], force_, velocity_[next],
                       displacement_[next]);
      if (sensitivities) {
        // U_theta = theta U_j + (1 - theta) U_{j-1}
        weighted_ = theta_ * displacement_[next] + (1.0 - theta_) * displacement_[current];
        for (int z = 0; z < zones; ++z) {
          // dS_z: the same scheme with f_theta = -(1/E_z,nom) K_z U_theta.
          force_.noalias() = zone_stiffness_[z] * weighted_;
          force_ = -force_;
          integrator_.Step(sensitivity_velocity_[current].col(z), sensitivity_[current].col(z),
                           force_, sensitivity_velocity_[next].col(z), sensitivity_[next].col(z));
        }
      }
      current = next;
    }
    if (adjoint) trajectory_.col(j) = displacement_[current];
    cost += SampleCost(j, displacement_[current], sensitivity_[current],
                       sensitivities ? gradient : nullptr, fisher_information, sensor_information);
  }
  if (adjoint) AdjointGradient(gradient);
  if (sensor_information != nullptr) {
    for (Matrix& information : *sensor_information) {
      for (int z = 0; z < zones; ++z) {
        for (int y = 0; y < z; ++y) information(y, z) = information(z, y);
      }
    }
  }
  sweeps_ += sensitivities ? 1 + zones : (adjoint ? 2 : 1);
  return cost;
}

bool MatrixOutputErrorObjective::ModuliCost(const Vector& moduli, double* cost, Vector* gradient,
                                            std::string* why) {
  (void)why;  // the misfit is always had; Evaluate tests that it is finite
  *cost = Cost(moduli, gradient);
  return true;
}

void MatrixOutputErrorObjective::OnEvaluated(const Vector& moduli, double cost,
                                             double gradient_norm) {
  spdlog::info(
      "least-squares evaluation {}: J / J_rest = {:.10g}, |grad|_inf = {:.3g}, E in "
      "[{:.6g}, {:.6g}] GPa",
      evaluations(), cost, gradient_norm, moduli.minCoeff() * 1e-9, moduli.maxCoeff() * 1e-9);
}

}  // namespace mcrewave
