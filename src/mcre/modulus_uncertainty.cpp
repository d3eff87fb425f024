#include "mcrewave/mcre/modulus_uncertainty.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

#include "mcrewave/core/random.h"
#include "mcrewave/mcre/mcre_problem.h"

namespace mcrewave {

bool UncertaintyOptions::IsValid(std::string* error) const {
  if (samples >= 2 && samples <= 1000) return true;
  if (error != nullptr) {
    *error = "uncertainty.samples must be an integer in [2, 1000], got " + std::to_string(samples);
  }
  return false;
}

namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

}  // namespace

double DifferenceNoiseStd(const Vector& channel) {
  std::vector<double> second_differences;
  for (Eigen::Index j = 1; j + 1 < channel.size(); ++j) {
    second_differences.push_back(channel[j + 1] - 2.0 * channel[j] + channel[j - 1]);
  }
  const double median = Median(second_differences);
  for (double& value : second_differences) value = std::abs(value - median);
  return 1.4826 * Median(second_differences) / std::sqrt(6.0);
}

NoiseLevels DifferenceNoiseLevels(const ChannelSet& data) {
  const BarEnds ends = BarEndChannels(data);
  const std::vector<BarSensor> sensors = BarSensors(data);
  NoiseLevels levels;
  // s^2 averaged over the two ends
  levels.displacement_std = std::sqrt(
      0.5 * (std::pow(DifferenceNoiseStd(ends.u0), 2) + std::pow(DifferenceNoiseStd(ends.uL), 2)));
  levels.force_std = std::sqrt(
      0.5 * (std::pow(DifferenceNoiseStd(ends.f0), 2) + std::pow(DifferenceNoiseStd(ends.fL), 2)));
  if (sensors.empty()) return levels;
  // With interior sensors: s^2 averaged over every channel of the kind.
  double displacement_sum =
      std::pow(DifferenceNoiseStd(ends.u0), 2) + std::pow(DifferenceNoiseStd(ends.uL), 2);
  int displacement_count = 2;
  double strain_sum = 0.0;
  int strain_count = 0;
  for (const BarSensor& sensor : sensors) {
    const double variance = std::pow(
        DifferenceNoiseStd(data.channels[static_cast<std::size_t>(sensor.index)].values), 2);
    if (sensor.kind == SensorKind::kStrain) {
      strain_sum += variance;
      ++strain_count;
    } else {
      displacement_sum += variance;
      ++displacement_count;
    }
  }
  levels.displacement_std = std::sqrt(displacement_sum / displacement_count);
  if (strain_count > 0) levels.strain_std = std::sqrt(strain_sum / strain_count);
  return levels;
}

NoiseLevels MisfitLevels(const ChannelSet& data, const CoupledSolution& solution, double alpha,
                         const Vector* clamp_reaction) {
  const BarEnds ends = BarEndChannels(data);
  assert(clamp_reaction == nullptr || clamp_reaction->size() == data.num_samples());
  double displacement_sum = 0.0;
  double force_sum = 0.0;
  for (int j = 0; j < data.num_samples(); ++j) {
    displacement_sum += std::pow(solution.EndDisplacement(0, j) - ends.u0[j], 2) +
                        std::pow(solution.EndDisplacement(1, j) - ends.uL[j], 2);
    // F - F~ = -B W / alpha at the two ends; r(U) - f0~ at a trusted clamp.
    const double f0_misfit = clamp_reaction != nullptr ? (*clamp_reaction)[j] - ends.f0[j]
                                                       : solution.EndRetrograde(0, j) / alpha;
    force_sum += std::pow(f0_misfit, 2) + std::pow(solution.EndRetrograde(1, j) / alpha, 2);
  }
  const double count = 2.0 * data.num_samples();
  NoiseLevels levels;
  levels.displacement_std = std::sqrt(displacement_sum / count);
  levels.force_std = std::sqrt(force_sum / count);
  return levels;
}

double CostGradientSlope(const std::vector<CostCurvePoint>& curve, double center, double window,
                         int* points_used) {
  std::vector<const CostCurvePoint*> chosen;
  for (const CostCurvePoint& point : curve) {
    if (point.usable && std::abs(point.modulus - center) <= window * center) {
      chosen.push_back(&point);
    }
  }
  if (chosen.size() < 3) {
    chosen.clear();
    for (const CostCurvePoint& point : curve) {
      if (point.usable) chosen.push_back(&point);
    }
  }
  *points_used = static_cast<int>(chosen.size());
  if (chosen.size() < 2) return 0.0;
  double mean_modulus = 0.0;
  double mean_gradient = 0.0;
  for (const CostCurvePoint* point : chosen) {
    mean_modulus += point->modulus;
    mean_gradient += point->cost_gradient;
  }
  mean_modulus /= chosen.size();
  mean_gradient /= chosen.size();
  // k = sum (E_i - mean E)(g_i - mean g) / sum (E_i - mean E)^2
  double covariance = 0.0;
  double variance = 0.0;
  for (const CostCurvePoint* point : chosen) {
    covariance += (point->modulus - mean_modulus) * (point->cost_gradient - mean_gradient);
    variance += (point->modulus - mean_modulus) * (point->modulus - mean_modulus);
  }
  return variance > 0.0 ? covariance / variance : 0.0;
}

ModulusUncertainty EstimateModulusUncertainty(const UncertaintyOptions& options,
                                              const BarModel& model, const ChannelSet& data,
                                              const McreOptions& mcre, double theta,
                                              const CoupledSolverOptions& inner, double modulus,
                                              const CoupledSolution& solution,
                                              const NoiseLevels& noise, double curvature,
                                              int curvature_points, EndDisplacementChannels ends) {
  assert(options.IsValid(nullptr));
  ModulusUncertainty result;
  result.noise = noise;
  result.curvature = curvature;
  result.curvature_points = curvature_points;
  if (!solution.has_fields()) {
    result.message =
        "the first-order figure needs the stored fields U and W, which the streaming solver "
        "does not keep (inner.method: conjugate_gradient gives it when its fields fit "
        "inner.max_field_bytes)";
    return result;
  }
  if (!(curvature > 0.0)) {
    result.message = "the cost curve is not convex around the optimum (slope of de^2/dE <= 0)";
    return result;
  }
  if (!(noise.displacement_std > 0.0 || noise.force_std > 0.0)) {
    result.message = "no noise to propagate (both noise levels are 0)";
    return result;
  }
  ChannelSet noise_data = data;
  Vector& noise_u0 = noise_data.Values("u0");
  Vector& noise_uL = noise_data.Values("uL");
  Vector& noise_f0 = noise_data.Values("f0");
  Vector& noise_fL = noise_data.Values("fL");
  const std::vector<BarSensor> noise_sensors = BarSensors(noise_data);
  const Vector& data_f0 = data.Values("f0");
  StandardNormal normal(options.seed);
  Matrix plus_displacement, plus_retrograde, minus_displacement, minus_retrograde;
  double sum_of_squares = 0.0;
  for (int sample = 0; sample < options.samples; ++sample) {
    for (Vector* channel : {&noise_u0, &noise_uL}) {
      for (double& value : *channel) value = noise.displacement_std * normal();
    }
    for (Vector* channel : {&noise_f0, &noise_fL}) {
      for (double& value : *channel) value = noise.force_std * normal();
    }
    for (const BarSensor& sensor : noise_sensors) {
      const double level =
          sensor.kind == SensorKind::kStrain ? noise.strain_std : noise.displacement_std;
      for (double& value : noise_data.channels[static_cast<std::size_t>(sensor.index)].values) {
        value = level * normal();
      }
    }
    McreProblem problem(model, noise_data, mcre.weights, mcre.reference_modulus, theta, ends,
                        mcre.clamp);
    problem.SetModulus(modulus);
    CoupledSolution noise_solution;
    const CoupledSolverSummary summary = SolveCoupled(inner, &problem, nullptr, &noise_solution);
    result.sweeps += summary.sweeps;
    if (!summary.IsSolutionUsable()) {
      result.message = "a noise solve is not usable: " + summary.BriefReport();
      return result;
    }
    plus_displacement = solution.displacement + noise_solution.displacement;
    plus_retrograde = solution.retrograde + noise_solution.retrograde;
    minus_displacement = solution.displacement - noise_solution.displacement;
    minus_retrograde = solution.retrograde - noise_solution.retrograde;
    // dg_1 = (g(s_d + s_n) - g(s_d - s_n)) / 2, g the quadratic de^2/dE at E*
    double gradient_change =
        0.5 * (problem.CostGradient(plus_displacement, plus_retrograde) -
               problem.CostGradient(minus_displacement, minus_retrograde));
    if (mcre.clamp == ClampModel::kTrusted) {
      // The reaction's explicit term alpha_r (r / E) (r - f0~) holds the data f0~
      // itself, which the problem above has as the noise f_n only. With r_d, r_n the
      // reactions of s_d, s_n and f_d the data's f0~, its part linear in the noise is
      //   alpha_r / E [r_n (r_d - f_d) + r_d (r_n - f_n)],
      // while the difference above gave alpha_r / E [2 r_d r_n - f_n r_n]: add
      //   alpha_r / E [r_n (f_n - f_d) - r_d f_n]  at every sample.
      for (int j = 0; j <= problem.num_steps(); ++j) {
        const double r_d = problem.ClampReaction(solution.displacement.col(j).data());
        const double r_n = problem.ClampReaction(noise_solution.displacement.col(j).data());
        const double f_n = noise_f0[j], f_d = data_f0[j];
        gradient_change += problem.QuadratureWeight(j) * problem.time_step() *
                           problem.reaction_weight() / modulus *
                           (r_n * (f_n - f_d) - r_d * f_n);
      }
    }
    // dE = -dg_1 / k
    const double modulus_change = -gradient_change / curvature;
    sum_of_squares += modulus_change * modulus_change;
    spdlog::debug("uncertainty sample {}: dE = {:.4g} Pa", sample + 1, modulus_change);
  }
  result.samples = options.samples;
  // std(E*) = sqrt(mean dE_i^2)
  result.std_dev = std::sqrt(sum_of_squares / options.samples);
  result.relative_std_dev = result.std_dev / modulus;
  result.available = true;
  result.message = "ok";
  return result;
}

}  // namespace mcrewave
