#include "reference/bar_zone_least_squares.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "reference/bar_least_squares.h"

namespace mcrewave {
namespace testing {

BarZoneLeastSquares::BarZoneLeastSquares(const BarModel& model, const ChannelSet& data,
                                         const NoiseLevels& noise, double theta,
                                         EndDisplacementChannels ends)
    : model_(model),
      data_(data),
      bar_(model, data, noise, ends),
      theta_(theta),
      ends_(ends),
      num_zones_(model.num_zones()),
      weight_u_(1.0 / (noise.displacement_std * noise.displacement_std)),
      weight_f_(1.0 / (noise.force_std * noise.force_std)) {
  assert(theta >= 0.0 && theta <= 1.0);
  for (int z = 0; z < num_zones_; ++z) {
    // K1_z = K(E = 1 Pa in zone z, 0 elsewhere).
    const SparseMatrix unit_zone = model.Stiffness(Vector::Unit(num_zones_, z));
    zone_stiffness_.emplace_back(BarModel::ClampedBlock(unit_zone));
    zone_stiffness_01_.push_back(unit_zone.coeff(0, 1));
  }
  const int free = model.num_nodes() - 1;
  for (Vector* scratch : {&velocity_, &displacement_, &next_velocity_, &next_displacement_,
                          &weighted_, &force_, &acceleration_, &acceleration_sensitivity_}) {
    scratch->setZero(free);
  }
  for (Matrix* scratch :
       {&sensitivity_velocity_, &sensitivity_, &next_sensitivity_velocity_, &next_sensitivity_}) {
    scratch->setZero(free, num_zones_);
  }
  nodal_.setZero(model.num_nodes());
  residuals_.setZero(static_cast<Eigen::Index>(bar_.sensor_rows.size()));
}

double BarZoneLeastSquares::Cost(const Vector& zone_moduli, Vector* gradient) {
  assert(zone_moduli.size() == num_zones_ && zone_moduli.allFinite() &&
         zone_moduli.minCoeff() > 0.0);
  ThetaIntegratorOptions options;
  options.time_step = data_.time_step;
  options.theta = theta_;
  integrator_.Init(bar_.free_mass, BarModel::ClampedBlock(model_.Stiffness(zone_moduli)), options);
  assert(integrator_.factorization() == Factorization::kBand);
  // K_01 = sum_z E_z K1_z(0, 1).
  double stiffness_01 = 0.0;
  for (int z = 0; z < num_zones_; ++z) stiffness_01 += zone_moduli[z] * zone_stiffness_01_[z];

  const bool gradient_requested = gradient != nullptr;
  if (gradient_requested) gradient->setZero(num_zones_);
  const int samples = data_.num_samples();
  const int loaded = static_cast<int>(velocity_.size()) - 1;  // node N, free numbering
  const double h = data_.time_step;
  velocity_.setZero();
  displacement_.setZero();
  sensitivity_velocity_.setZero();
  sensitivity_.setZero();
  double cost = 0.0;
  for (int k = 0; k < samples; ++k) {
    if (k > 0) {
      // f_theta = (theta fL~_k + (1 - theta) fL~_{k-1}) e_N on the step t_{k-1} -> t_k.
      const double load = theta_ * bar_.measured.fL[k] + (1.0 - theta_) * bar_.measured.fL[k - 1];
      integrator_.StepWithEndLoads(velocity_, displacement_, 0.0, load, next_velocity_,
                                   next_displacement_);
      if (gradient_requested) {
        // theta u_k + (1 - theta) u_{k-1}
        weighted_ = theta_ * next_displacement_ + (1.0 - theta_) * displacement_;
        for (int z = 0; z < num_zones_; ++z) {
          // ds_z: the same scheme with f_theta = -K1_z,r (theta u_k + (1 - theta) u_{k-1}).
          zone_stiffness_[z].Multiply(weighted_, force_);
          force_ = -force_;
          integrator_.Step(sensitivity_velocity_.col(z), sensitivity_.col(z), force_,
                           next_sensitivity_velocity_.col(z), next_sensitivity_.col(z));
        }
        sensitivity_velocity_.swap(next_sensitivity_velocity_);
        sensitivity_.swap(next_sensitivity_);
      }
      velocity_.swap(next_velocity_);
      displacement_.swap(next_displacement_);
    }
    const double residual_f =
        ClampReaction(integrator_.stiffness(), bar_.mass_factor, bar_.mass_01, stiffness_01,
                      displacement_, bar_.measured.fL[k], &acceleration_) -
        bar_.measured.f0[k];
    const double residual_u = displacement_[loaded] - bar_.measured.uL[k];
    // c_k h / 2 [(uL - uL~)^2 / s_u^2 + (f0 - f0~)^2 / s_f^2 + sensors]
    double sum = weight_f_ * residual_f * residual_f;
    if (ends_.uL) sum += weight_u_ * residual_u * residual_u;
    if (!bar_.sensor_rows.empty()) nodal_.tail(nodal_.size() - 1) = displacement_;
    for (std::size_t i = 0; i < bar_.sensor_rows.size(); ++i) {
      residuals_[i] = bar_.sensor_rows[i].Apply(nodal_.data()) - (*bar_.sensor_data[i])[k];
      sum += bar_.sensor_weights[i] * residuals_[i] * residuals_[i];
    }
    const double c = (k == 0 || k == samples - 1) ? 0.5 : 1.0;
    cost += 0.5 * c * h * sum;
    if (!gradient_requested) continue;
    for (int z = 0; z < num_zones_; ++z) {
      const auto s = sensitivity_.col(z);
      // M_r da = -K_r s_z - K1_z,r u;  df0 = M_01 da_1 + K_01 s_z,1 + K1_z(0, 1) u_1.
      integrator_.stiffness().Multiply(s, acceleration_sensitivity_);
      zone_stiffness_[z].MultiplyAdd(1.0, displacement_, acceleration_sensitivity_);
      acceleration_sensitivity_ = -acceleration_sensitivity_;
      bar_.mass_factor.SolveInPlace(acceleration_sensitivity_);
      const double df0 = bar_.mass_01 * acceleration_sensitivity_[0] + stiffness_01 * s[0] +
                         zone_stiffness_01_[z] * displacement_[0];
      // d/dE_z of the bracket above, times c_k h / 2.
      double dsum = 2.0 * weight_f_ * residual_f * df0;
      if (ends_.uL) dsum += 2.0 * weight_u_ * residual_u * s[loaded];
      if (!bar_.sensor_rows.empty()) nodal_.tail(nodal_.size() - 1) = s;
      for (std::size_t i = 0; i < bar_.sensor_rows.size(); ++i) {
        dsum +=
            2.0 * bar_.sensor_weights[i] * residuals_[i] * bar_.sensor_rows[i].Apply(nodal_.data());
      }
      (*gradient)[z] += 0.5 * c * h * dsum;
    }
  }
  sweeps_ += gradient_requested ? 1 + num_zones_ : 1;
  return cost;
}

}  // namespace testing
}  // namespace mcrewave
