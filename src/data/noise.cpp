#include "mcrewave/data/noise.h"

#include <cassert>
#include <cmath>
#include <vector>

#include "mcrewave/core/random.h"

namespace mcrewave {

double RootMeanSquare(const Vector& channel) {
  if (channel.size() == 0) return 0.0;
  return std::sqrt(channel.squaredNorm() / static_cast<double>(channel.size()));
}

void AddMeasurementNoise(double snr, std::uint64_t seed, ChannelSet* measurements) {
  assert(snr > 0.0);
  if (std::isinf(snr)) return;
  Vector& u0 = measurements->Values("u0");
  Vector& uL = measurements->Values("uL");
  Vector& f0 = measurements->Values("f0");
  Vector& fL = measurements->Values("fL");
  const double std_u = RootMeanSquare(uL) / snr;
  const double std_f = RootMeanSquare(fL) / snr;
  StandardNormal normal(seed);
  for (Vector* channel : {&u0, &uL}) {
    for (double& value : *channel) value += std_u * normal();
  }
  for (Vector* channel : {&f0, &fL}) {
    for (double& value : *channel) value += std_f * normal();
  }
  // Interior sensors after the end channels (the end channels keep their draws):
  // displacements at std_u, strains at RMS(every strain channel) / SNR.
  const std::vector<BarSensor> sensors = BarSensors(*measurements);
  double strain_squares = 0.0;
  Eigen::Index strain_samples = 0;
  for (const BarSensor& sensor : sensors) {
    if (sensor.kind != SensorKind::kStrain) continue;
    const Vector& values = measurements->channels[static_cast<std::size_t>(sensor.index)].values;
    strain_squares += values.squaredNorm();
    strain_samples += values.size();
  }
  const double std_e =
      strain_samples > 0 ? std::sqrt(strain_squares / static_cast<double>(strain_samples)) / snr
                         : 0.0;
  for (const BarSensor& sensor : sensors) {
    const double level = sensor.kind == SensorKind::kStrain ? std_e : std_u;
    for (double& value : measurements->channels[static_cast<std::size_t>(sensor.index)].values) {
      value += level * normal();
    }
  }
}

}  // namespace mcrewave
