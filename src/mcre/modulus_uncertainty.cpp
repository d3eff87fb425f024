#include "mcrewave/mcre/modulus_uncertainty.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "mcrewave/mcre/zone_uncertainty.h"

namespace mcrewave {

bool UncertaintyOptions::IsValid(std::string* error) const {
  if (samples == 0 || (samples >= 2 && samples <= 1000)) return true;
  if (error != nullptr) {
    *error = "uncertainty.samples must be an integer in [2, 1000], or 0 for no estimate, got " +
             std::to_string(samples);
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

double NoiseLevel(const NoiseLevels& noise, ChannelKind kind) {
  switch (kind) {
    case ChannelKind::kStrain:
      return noise.strain_std;
    case ChannelKind::kForce:
      return noise.force_std;
    case ChannelKind::kDisplacement:
      break;
  }
  return noise.displacement_std;
}

void DrawWhiteNoise(const NoiseLevels& noise, StandardNormal* normal, ChannelSet* set) {
  for (Channel& channel : set->channels) {
    const double level = NoiseLevel(noise, channel.kind);
    for (double& value : channel.values) value = level * (*normal)();
  }
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

NoiseLevels EndMisfitLevels(const ChannelSet& data, const ChannelSet& model) {
  // Sums over the samples of (model - measured)^2 of the ends' channels model holds.
  auto mean_square = [&](const char* end_0, const char* end_1) {
    const int first = model.Find(end_0), second = model.Find(end_1);
    const Vector* model_channels[] = {
        first >= 0 ? &model.channels[static_cast<std::size_t>(first)].values : nullptr,
        second >= 0 ? &model.channels[static_cast<std::size_t>(second)].values : nullptr};
    const Vector* measured[] = {&data.Values(end_0), &data.Values(end_1)};
    double sum = 0.0;
    int count = 0;
    for (int j = 0; j < data.num_samples(); ++j) {
      for (int end = 0; end < 2; ++end) {
        if (model_channels[end] == nullptr) continue;
        sum += std::pow((*model_channels[end])[j] - (*measured[end])[j], 2);
        ++count;
      }
    }
    return count > 0 ? sum / count : 0.0;
  };
  NoiseLevels levels;
  levels.displacement_std = std::sqrt(mean_square("u0", "uL"));
  levels.force_std = std::sqrt(mean_square("f0", "fL"));
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
                                              const MatrixModelData& model, const ChannelSet& data,
                                              const McreOptions& mcre, double theta,
                                              const CoupledSolverOptions& inner, double modulus,
                                              const CoupledSolution& solution,
                                              const NoiseLevels& noise, double curvature,
                                              int curvature_points) {
  assert(options.IsValid(nullptr) && model.zones.size() == 1);
  ModulusUncertainty result;
  if (options.samples == 0) {
    result.message = kUncertaintyOffMessage;
    return result;
  }
  result.noise = noise;
  result.curvature = curvature;
  result.curvature_points = curvature_points;
  if (!(curvature > 0.0)) {
    result.message = "the cost curve is not convex around the optimum (slope of de^2/dE <= 0)";
    return result;
  }
  // dE = -dg_1 / k: the zone figure with H = k.
  const Matrix hessian = Matrix::Constant(1, 1, curvature);
  const ZoneUncertainty zone =
      EstimateZoneUncertainty(options, model, data, mcre, theta, inner,
                              Vector::Constant(1, modulus), solution, noise, &hessian);
  result.sweeps = zone.sweeps;
  if (!zone.available) {
    result.message = zone.message;
    return result;
  }
  result.samples = zone.samples;
  result.std_dev = zone.std_dev[0];
  result.sensitivity_std = zone.sensitivity_std;
  result.relative_std_dev = result.std_dev / modulus;
  result.available = true;
  result.message = "ok";
  return result;
}

}  // namespace mcrewave
