#include "mcrewave/model/experiment.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "mcrewave/data/measurement.h"

namespace mcrewave {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error != nullptr) *error = message;
  return false;
}

bool FinitePositive(double value) { return std::isfinite(value) && value > 0.0; }

}  // namespace

bool LoadOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!std::isfinite(amplitude) || amplitude == 0.0) {
    why << "load.amplitude must be a finite nonzero number of newtons, got " << amplitude;
    return Fail(error, why.str());
  }
  if (!FinitePositive(duration)) {
    why << "load.duration must be a finite positive number of seconds, got " << duration;
    return Fail(error, why.str());
  }
  return true;
}

double LoadOptions::Value(double time) const {
  // Half sine: F(t) = F0 sin(pi t / t_load) on [0, t_load], 0 elsewhere.
  if (time < 0.0 || time > duration) return 0.0;
  return amplitude * std::sin(M_PI * time / duration);
}

bool TimeOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (!FinitePositive(window)) {
    why << "time.window must be a finite positive number of seconds, got " << window;
    return Fail(error, why.str());
  }
  if (!FinitePositive(step)) {
    why << "time.step must be a finite positive number of seconds, got " << step;
    return Fail(error, why.str());
  }
  // The theta method is unconditionally stable for theta >= 1/2 only.
  if (!(theta >= 0.5 && theta <= 1.0)) {
    why << "time.theta must lie in [0.5, 1] (unconditionally stable), got " << theta;
    return Fail(error, why.str());
  }
  const double ratio = window / step;
  if (ratio > 1e8) {
    why << "time.window / time.step = " << ratio << " steps, more than the limit of 1e8";
    return Fail(error, why.str());
  }
  if (ratio < 1.0 - 1e-9 || std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    why << "time.window (" << window << " s) must hold a whole number of time.step (" << step
        << " s); the ratio is " << ratio;
    return Fail(error, why.str());
  }
  return true;
}

int TimeOptions::NumSteps() const { return static_cast<int>(std::lround(window / step)); }

bool DataOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  if (source == DataSource::kCsv && path.empty()) {
    return Fail(error, "data.path must name a measurement CSV file when data.source is csv");
  }
  if (truth_refinement < 1 || truth_refinement > 64) {
    why << "data.truth_refinement must be an integer in [1, 64], got " << truth_refinement;
    return Fail(error, why.str());
  }
  if (!(snr > 0.0)) {
    why << "data.snr must be positive (.inf for no noise), got " << snr;
    return Fail(error, why.str());
  }
  if (!(support_stiffness > 0.0)) {
    why << "data.support_stiffness must be positive in N/m (.inf for a rigid clamp), got "
        << support_stiffness;
    return Fail(error, why.str());
  }
  for (std::size_t z = 0; z < truth_moduli.size(); ++z) {
    if (!(truth_moduli[z] > 0.0) || !std::isfinite(truth_moduli[z])) {
      why << "data.truth_moduli must hold finite positive moduli (Pa), got " << truth_moduli[z]
          << " at index " << z;
      return Fail(error, why.str());
    }
  }
  if (time_column.empty()) return Fail(error, "data.time_column must name a column, got ''");
  if (!std::isfinite(time_origin)) {
    why << "data.time_origin must be a finite time (s), got " << time_origin;
    return Fail(error, why.str());
  }
  // Channel names: well formed, interior sensors only in data.sensors, none twice.
  const std::pair<const char*, const std::vector<std::string>*> lists[] = {
      {"data.sensors", &sensors}, {"data.channels", &channels}};
  for (const auto& [key, list] : lists) {
    for (std::size_t i = 0; i < list->size(); ++i) {
      ChannelName channel;
      std::string reason;
      const std::string& name = (*list)[i];
      if (!ParseChannelName(name, &channel, &reason) || channel.kind == ChannelName::Kind::kTime) {
        why << key << "[" << i << "] = '" << name
            << "': " << (reason.empty() ? "not a measured channel" : reason);
        return Fail(error, why.str());
      }
      if (list == &sensors && channel.kind != ChannelName::Kind::kSensor) {
        why << key << "[" << i << "] = '" << name
            << "': the end channels u0, uL, f0, fL are always simulated; list only interior "
               "sensors u@X or e@X here";
        return Fail(error, why.str());
      }
      for (std::size_t k = 0; k < i; ++k) {
        ChannelName other;
        std::string ignored;
        ParseChannelName((*list)[k], &other, &ignored);
        const bool same =
            (*list)[k] == name ||
            (channel.kind == ChannelName::Kind::kSensor && other.kind == channel.kind &&
             other.sensor_kind == channel.sensor_kind && other.position == channel.position);
        if (same) {
          why << key << "[" << i << "] = '" << name << "' repeats " << key << "[" << k << "] = '"
              << (*list)[k] << "'";
          return Fail(error, why.str());
        }
      }
    }
  }
  if (!channels.empty()) {
    for (const char* load : {"f0", "fL"}) {
      if (std::find(channels.begin(), channels.end(), load) == channels.end()) {
        why << "data.channels must include " << load
            << ": the measured end forces are the model's loads (leave data.channels empty "
               "to use every channel)";
        return Fail(error, why.str());
      }
    }
  }
  return true;
}

std::string ValidateDataAgainstBar(const DataOptions& data, const BarProperties& bar) {
  std::ostringstream why;
  const std::pair<const char*, const std::vector<std::string>*> lists[] = {
      {"data.sensors", &data.sensors}, {"data.channels", &data.channels}};
  for (const auto& [key, list] : lists) {
    for (std::size_t i = 0; i < list->size(); ++i) {
      ChannelName channel;
      std::string ignored;
      if (ParseChannelName((*list)[i], &channel, &ignored) &&
          channel.kind == ChannelName::Kind::kSensor && channel.position > bar.length) {
        why << key << "[" << i << "] = '" << (*list)[i] << "': the sensor lies outside the bar [0, "
            << bar.length << "] m (model.length)";
        return why.str();
      }
    }
  }
  std::string reason = ValidateModulusZones(bar, data.truth_zones, "data.truth_zones");
  if (!reason.empty()) return reason;
  if (data.source == DataSource::kSynthetic && data.truth == TruthModel::kExact &&
      (!data.truth_zones.empty() || !data.sensors.empty() ||
       std::isfinite(data.support_stiffness))) {
    return std::string("data.") +
           (!data.truth_zones.empty() ? "truth_zones"
            : !data.sensors.empty()   ? "sensors"
                                      : "support_stiffness") +
           ": the exact truth (data.truth: exact) is the uniform clamped bar observed at its "
           "ends; use data.truth: finite_element for zones, interior sensors and a compliant "
           "support";
  }
  return "";
}

}  // namespace mcrewave
