#include "reference/bar_least_squares.h"

#include <cassert>
#include <cmath>
#include <stdexcept>

#include "mcrewave/optim/valley_spacing.h"

namespace mcrewave {
namespace testing {

void OutputErrorSensorRows(const BarModel& model, const ChannelSet& data, const NoiseLevels& noise,
                           std::vector<ObservationRow>* rows, std::vector<double>* weights) {
  rows->clear();
  weights->clear();
  for (const BarSensor& sensor : BarSensors(data)) {
    const bool strain = sensor.kind == SensorKind::kStrain;
    assert(!strain || noise.strain_std > 0.0);
    rows->push_back(strain ? model.StrainRow(sensor.position)
                           : model.DisplacementRow(sensor.position));
    const double level = strain ? noise.strain_std : noise.displacement_std;
    weights->push_back(1.0 / (level * level));
  }
}

double ClampReaction(const SymmetricBandMatrix& stiffness, const BandLdlt& mass_factor,
                     double mass_01, double stiffness_01, const Vector& displacement, double fL,
                     Vector* acceleration) {
  // M_r a = fL e_N - K_r u
  stiffness.Multiply(displacement, *acceleration);
  *acceleration = -*acceleration;
  (*acceleration)[acceleration->size() - 1] += fL;
  mass_factor.SolveInPlace(*acceleration);
  // f0 = M_01 a_1 + K_01 u_1
  return mass_01 * (*acceleration)[0] + stiffness_01 * displacement[0];
}

double OutputErrorRestCost(const ChannelSet& data, const NoiseLevels& noise,
                           const std::vector<double>& sensor_weights,
                           EndDisplacementChannels ends) {
  const int samples = data.num_samples();
  const double h = data.time_step;
  const BarEnds ends_data = BarEndChannels(data);
  const std::vector<const Vector*> sensors = BarSensorValues(data);
  const double weight_u = 1.0 / (noise.displacement_std * noise.displacement_std);
  const double weight_f = 1.0 / (noise.force_std * noise.force_std);
  double rest_cost = 0.0;
  for (int k = 0; k < samples; ++k) {
    // c_k h / 2 [uL~^2 / s_u^2 + f0~^2 / s_f^2 + sum sensors]
    const double c = (k == 0 || k == samples - 1) ? 0.5 : 1.0;
    double sum = weight_f * ends_data.f0[k] * ends_data.f0[k];
    if (ends.uL) sum += weight_u * ends_data.uL[k] * ends_data.uL[k];
    for (std::size_t i = 0; i < sensors.size(); ++i) {
      sum += sensor_weights[i] * (*sensors[i])[k] * (*sensors[i])[k];
    }
    rest_cost += 0.5 * c * h * sum;
  }
  return rest_cost;
}

ClampedBarData::ClampedBarData(const BarModel& model, const ChannelSet& data,
                               const NoiseLevels& noise, EndDisplacementChannels ends)
    : measured(BarEndChannels(data)),
      sensor_data(BarSensorValues(data)),
      free_mass(BarModel::ClampedBlock(model.mass())),
      mass_01(model.mass().coeff(0, 1)) {
  assert(data.num_steps() >= 1 && noise.displacement_std > 0.0 && noise.force_std > 0.0);
  if (!mass_factor.Compute(SymmetricBandMatrix(free_mass))) {
    throw std::runtime_error("output-error model: the mass matrix is not positive definite");
  }
  OutputErrorSensorRows(model, data, noise, &sensor_rows, &sensor_weights);
  rest_cost = OutputErrorRestCost(data, noise, sensor_weights, ends);
}

BarLeastSquares::BarLeastSquares(const BarModel& model, const ChannelSet& data,
                                 const NoiseLevels& noise, double theta, double modulus_scale,
                                 EndDisplacementChannels ends)
    : model_(model),
      data_(data),
      bar_(model, data, noise, ends),
      noise_(noise),
      theta_(theta),
      modulus_scale_(modulus_scale),
      ends_(ends),
      free_stiffness_one_(BarModel::ClampedBlock(model.unit_stiffness())),
      stiffness_one_01_(model.unit_stiffness().coeff(0, 1)) {
  assert(model.num_zones() == 1 && theta >= 0.0 && theta <= 1.0 && modulus_scale > 0.0);
  const int free = model.num_nodes() - 1;
  for (Vector* scratch :
       {&velocity_, &displacement_, &next_velocity_, &next_displacement_, &sensitivity_velocity_,
        &sensitivity_, &next_sensitivity_velocity_, &next_sensitivity_, &shift_, &acceleration_,
        &acceleration_sensitivity_}) {
    scratch->setZero(free);
  }
  nodal_.setZero(model.num_nodes());
  const int samples = data.num_samples();
  prediction_.uL.setZero(samples);
  prediction_.f0.setZero(samples);
  prediction_.sensors.assign(bar_.sensor_data.size(), Vector::Zero(samples));
}

double BarLeastSquares::ValleySpacing() {
  const OutputErrorPrediction& prediction = Predict(modulus_scale_, false);
  const int channels = 2 + static_cast<int>(prediction.sensors.size());
  Matrix traces(channels, prediction.f0.size());
  Vector weights(channels);
  traces.row(0) = prediction.uL.transpose();
  weights[0] = ends_.uL ? 1.0 / (noise_.displacement_std * noise_.displacement_std) : 0.0;
  traces.row(1) = prediction.f0.transpose();
  weights[1] = 1.0 / (noise_.force_std * noise_.force_std);
  for (int i = 0; i + 2 < channels; ++i) {
    traces.row(2 + i) = prediction.sensors[i].transpose();
    weights[2 + i] = bar_.sensor_weights[i];
  }
  return PredictedValleySpacing(traces, weights, data_.time_step);
}

const OutputErrorPrediction& BarLeastSquares::Predict(double modulus, bool gradient_requested) {
  assert(modulus > 0.0 && std::isfinite(modulus));
  ThetaIntegratorOptions options;
  options.time_step = data_.time_step;
  options.theta = theta_;
  const SparseMatrix free_stiffness = modulus * free_stiffness_one_;
  integrator_.Init(bar_.free_mass, free_stiffness, options);

  const int samples = data_.num_samples();
  const int loaded = static_cast<int>(velocity_.size()) - 1;  // node N, free numbering
  const double h = data_.time_step;
  const double stiffness_01 = modulus * stiffness_one_01_;
  const double weight_u = 1.0 / (noise_.displacement_std * noise_.displacement_std);
  const double weight_f = 1.0 / (noise_.force_std * noise_.force_std);
  velocity_.setZero();
  displacement_.setZero();
  sensitivity_velocity_.setZero();
  sensitivity_.setZero();
  double cost = 0.0, gradient = 0.0, information = 0.0;
  for (int k = 0; k < samples; ++k) {
    if (k > 0) {
      // f_theta = (theta fL~_k + (1 - theta) fL~_{k-1}) e_N on the step t_{k-1} -> t_k.
      const double load = theta_ * bar_.measured.fL[k] + (1.0 - theta_) * bar_.measured.fL[k - 1];
      integrator_.StepWithEndLoads(velocity_, displacement_, 0.0, load, next_velocity_,
                                   next_displacement_);
      if (gradient_requested) {
        // ds: the same scheme with f_theta = -K z, z = (theta u_k + (1 - theta) u_{k-1}) / E.
        shift_ = (theta_ * next_displacement_ + (1.0 - theta_) * displacement_) / modulus;
        integrator_.StepWithEndLoads(sensitivity_velocity_, sensitivity_, shift_, 0.0, 0.0,
                                     next_sensitivity_velocity_, next_sensitivity_);
        sensitivity_velocity_.swap(next_sensitivity_velocity_);
        sensitivity_.swap(next_sensitivity_);
      }
      velocity_.swap(next_velocity_);
      displacement_.swap(next_displacement_);
    }
    const double f0 =
        ClampReaction(integrator_.stiffness(), bar_.mass_factor, bar_.mass_01, stiffness_01,
                      displacement_, bar_.measured.fL[k], &acceleration_);
    prediction_.uL[k] = displacement_[loaded];
    prediction_.f0[k] = f0;
    const double c = (k == 0 || k == samples - 1) ? 0.5 : 1.0;
    const double residual_f = f0 - bar_.measured.f0[k];
    const double residual_u = displacement_[loaded] - bar_.measured.uL[k];
    // c_k h / 2 [(uL - uL~)^2 / s_u^2 + (f0 - f0~)^2 / s_f^2 + sensors]
    double sum = weight_f * residual_f * residual_f;
    if (ends_.uL) sum += weight_u * residual_u * residual_u;
    if (!bar_.sensor_rows.empty()) nodal_.tail(nodal_.size() - 1) = displacement_;
    for (std::size_t i = 0; i < bar_.sensor_rows.size(); ++i) {
      const double predicted = bar_.sensor_rows[i].Apply(nodal_.data());
      prediction_.sensors[i][k] = predicted;
      const double residual = predicted - (*bar_.sensor_data[i])[k];
      sum += bar_.sensor_weights[i] * residual * residual;
    }
    cost += 0.5 * c * h * sum;
    if (gradient_requested) {
      // M_r da_k = -K_r (s_k + u_k / E);  df0_k = M_01 da_1 + K_01 s_1 + K_01 u_1 / E.
      shift_ = sensitivity_ + displacement_ / modulus;
      integrator_.stiffness().Multiply(shift_, acceleration_sensitivity_);
      acceleration_sensitivity_ = -acceleration_sensitivity_;
      bar_.mass_factor.SolveInPlace(acceleration_sensitivity_);
      const double df0 = bar_.mass_01 * acceleration_sensitivity_[0] + stiffness_01 * shift_[0];
      // d/dE of the bracket above, times c_k h / 2.
      double dsum = 2.0 * weight_f * residual_f * df0;
      // c_k sum (dy/dE)^2 / s^2, the Fisher information's terms.
      double isum = weight_f * df0 * df0;
      if (ends_.uL) {
        dsum += 2.0 * weight_u * residual_u * sensitivity_[loaded];
        isum += weight_u * sensitivity_[loaded] * sensitivity_[loaded];
      }
      if (!bar_.sensor_rows.empty()) nodal_.tail(nodal_.size() - 1) = sensitivity_;
      for (std::size_t i = 0; i < bar_.sensor_rows.size(); ++i) {
        const double residual = prediction_.sensors[i][k] - (*bar_.sensor_data[i])[k];
        const double derivative = bar_.sensor_rows[i].Apply(nodal_.data());
        dsum += 2.0 * bar_.sensor_weights[i] * residual * derivative;
        isum += bar_.sensor_weights[i] * derivative * derivative;
      }
      gradient += 0.5 * c * h * dsum;
      information += c * isum;
    }
  }
  sweeps_ += gradient_requested ? 2 : 1;
  prediction_.modulus = modulus;
  prediction_.cost = cost;
  prediction_.cost_gradient = gradient_requested ? gradient : 0.0;
  prediction_.fisher_information = gradient_requested ? information : 0.0;
  return prediction_;
}

}  // namespace testing
}  // namespace mcrewave
