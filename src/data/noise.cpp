#include "mcrewave/data/noise.h"

#include <cassert>
#include <cmath>
#include <random>
#include <vector>

namespace mcrewave {
namespace {

// Standard normal deviates by the Box-Muller transform, so that the sequence
// does not depend on the standard library's normal_distribution.
class StandardNormal {
 public:
  explicit StandardNormal(std::uint64_t seed) : engine_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // u1 in (0, 1], u2 in [0, 1): 53-bit uniforms from the raw engine output.
    const double u1 = ((engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = (engine_() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace

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
