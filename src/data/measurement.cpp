#include "mcrewave/data/measurement.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "data/csv_fields.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"

namespace mcrewave {
namespace {

using internal::ParseNumber;
using internal::ShortNumber;

// The required columns, in the order they are written: time and the four end channels.
constexpr int kEndColumns = 5;
constexpr std::array<const char*, kEndColumns> kColumnNames = {"t", "u0", "uL", "f0", "fL"};
constexpr char kHeader[] = "t,u0,uL,f0,fL";
}  // namespace

bool ParseChannelName(const std::string& text, ChannelName* channel, std::string* why) {
  static const std::array<std::pair<const char*, ChannelName::Kind>, 5> kEnds{{
      {"t", ChannelName::Kind::kTime},
      {"u0", ChannelName::Kind::kU0},
      {"uL", ChannelName::Kind::kUL},
      {"f0", ChannelName::Kind::kF0},
      {"fL", ChannelName::Kind::kFL},
  }};
  for (const auto& [name, kind] : kEnds) {
    if (text == name) {
      *channel = ChannelName();
      channel->kind = kind;
      return true;
    }
  }
  const bool displacement = text.rfind("u@", 0) == 0, strain = text.rfind("e@", 0) == 0;
  if (!displacement && !strain) {
    *why = "not a channel name (t, u0, uL, f0, fL, u@X or e@X with X in m)";
    return false;
  }
  const std::string number = text.substr(2);
  double position = 0.0;
  if (number.empty() || number.find_first_of(" \t") != std::string::npos ||
      !ParseNumber(number, &position) || !std::isfinite(position) || position < 0.0) {
    *why = "the position X of '" + text + "' must be a finite number >= 0 (in m)";
    return false;
  }
  channel->kind = ChannelName::Kind::kSensor;
  channel->sensor_kind = strain ? SensorKind::kStrain : SensorKind::kDisplacement;
  channel->position = position;
  return true;
}

ChannelSet BarChannelSet(double start_time, double time_step, Vector u0, Vector uL, Vector f0,
                         Vector fL) {
  ChannelSet set;
  set.start_time = start_time;
  set.time_step = time_step;
  set.channels = {{"u0", ChannelKind::kDisplacement, std::move(u0)},
                  {"uL", ChannelKind::kDisplacement, std::move(uL)},
                  {"f0", ChannelKind::kForce, std::move(f0)},
                  {"fL", ChannelKind::kForce, std::move(fL)}};
  return set;
}

BarEnds BarEndChannels(const ChannelSet& set) {
  return {set.Values("u0"), set.Values("uL"), set.Values("f0"), set.Values("fL")};
}

std::vector<BarSensor> BarSensors(const ChannelSet& set) {
  std::vector<BarSensor> sensors;
  for (std::size_t c = 0; c < set.channels.size(); ++c) {
    ChannelName channel;
    std::string why;
    if (ParseChannelName(set.channels[c].name, &channel, &why) &&
        channel.kind == ChannelName::Kind::kSensor) {
      sensors.push_back({channel.sensor_kind, channel.position, static_cast<int>(c)});
    }
  }
  return sensors;
}

std::vector<const Vector*> BarSensorValues(const ChannelSet& set) {
  std::vector<const Vector*> values;
  for (const BarSensor& sensor : BarSensors(set)) {
    values.push_back(&set.channels[static_cast<std::size_t>(sensor.index)].values);
  }
  return values;
}

ChannelSet ReadMeasurementCsv(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read measurement file " + path + ": " + std::strerror(errno));
  }
  return ParseMeasurementCsv(file, path);
}

std::string BarHeaderProblem(const std::vector<std::string>& names, const std::string& line) {
  const std::string expected_header =
      std::string("a header naming the columns: ") + kHeader +
      " in any order, then any interior channels u@X (displacement at X m) and e@X (strain "
      "at X m)";
  if (names.empty()) return expected_header;
  std::array<int, kEndColumns> found{};
  std::vector<ChannelName> channels;
  for (std::size_t c = 0; c < names.size(); ++c) {
    ChannelName channel;
    std::string why;
    if (!ParseChannelName(names[c], &channel, &why)) {
      return "column " + std::to_string(c + 1) + " '" + names[c] + "': " + why + "; expected " +
             expected_header;
    }
    for (std::size_t other = 0; other < c; ++other) {
      const bool same_sensor = channel.kind == ChannelName::Kind::kSensor &&
                               channels[other].kind == ChannelName::Kind::kSensor &&
                               channels[other].sensor_kind == channel.sensor_kind &&
                               channels[other].position == channel.position;
      if (names[other] == names[c] || same_sensor) {
        return "column " + std::to_string(c + 1) + " '" + names[c] + "' repeats column " +
               std::to_string(other + 1) + " '" + names[other] + "'";
      }
    }
    if (channel.kind != ChannelName::Kind::kSensor) found[static_cast<int>(channel.kind)] = 1;
    channels.push_back(channel);
  }
  for (int c = 0; c < kEndColumns; ++c) {
    if (found[c] == 0) {
      return std::string("the header '") + line + "' lacks the column '" + kColumnNames[c] +
             "'; expected " + expected_header;
    }
  }
  return "";
}

ChannelKind BarChannelKind(const std::string& name) {
  ChannelName channel;
  std::string why;
  ParseChannelName(name, &channel, &why);
  switch (channel.kind) {
    case ChannelName::Kind::kF0:
    case ChannelName::Kind::kFL:
      return ChannelKind::kForce;
    case ChannelName::Kind::kSensor:
      return channel.sensor_kind == SensorKind::kStrain ? ChannelKind::kStrain
                                                        : ChannelKind::kDisplacement;
    default:
      return ChannelKind::kDisplacement;
  }
}

ChannelSet ParseMeasurementCsv(std::istream& file, const std::string& path) {
  return ParseChannelCsv(file, path, BarHeaderProblem, BarChannelKind);
}

void CheckMeasurementChannels(const ChannelSet& measurements, const std::string& name) {
  const BarEnds ends = BarEndChannels(measurements);
  const Vector* channels[] = {&ends.u0, &ends.uL, &ends.f0, &ends.fL};
  for (int c = 0; c < 4; ++c) {
    const Vector& x = *channels[c];
    const std::string column = std::string("column '") + kColumnNames[c + 1] + "'";
    const double peak = x.size() > 0 ? x.cwiseAbs().maxCoeff() : 0.0;
    if (peak == 0.0 && c > 0) {
      throw InputError(name + ":2: " + column +
                       " is zero on every row: a dead channel (only u0, at the clamped end, "
                       "may be zero)");
    }
    const Eigen::Index samples = x.size();
    if (samples < 3) continue;
    const Vector second_differences =
        x.head(samples - 2) - 2.0 * x.segment(1, samples - 2) + x.tail(samples - 2);
    std::vector<double> magnitudes(second_differences.data(),
                                   second_differences.data() + second_differences.size());
    for (double& magnitude : magnitudes) magnitude = std::abs(magnitude);
    std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                     magnitudes.end());
    const double noise_level = 1.4826 * magnitudes[magnitudes.size() / 2];
    const double threshold = std::max(kOutlierNoiseFactor * noise_level, 0.5 * peak);
    Eigen::Index worst = 0;  // second difference x[k-1] - 2 x[k] + x[k+1] of k = worst + 1
    const double largest = second_differences.cwiseAbs().maxCoeff(&worst);
    if (largest > threshold) {
      // A spike s at an interior sample k gives second differences (s, -2 s, s) centred
      // on k; at the first or last sample only s, at its neighbour's, with nothing
      // beside it (below a quarter of it: a spike on the neighbour leaves half).
      Eigen::Index spike = worst + 1;
      const Eigen::Index last = second_differences.size() - 1;
      if (last > 0 && worst == last && std::abs(second_differences[last - 1]) < 0.25 * largest) {
        spike = samples - 1;
      } else if (last > 0 && worst == 0 && std::abs(second_differences[1]) < 0.25 * largest) {
        spike = 0;
      }
      throw InputError(name + ":" + std::to_string(spike + 2) + ": " + column + ": " +
                       ShortNumber(x[spike]) + " is an outlier: its second difference " +
                       ShortNumber(second_differences[worst]) + " is above " +
                       ShortNumber(kOutlierNoiseFactor) + " times the channel's noise level " +
                       ShortNumber(noise_level) + " and half its peak " + ShortNumber(peak) +
                       "; repair or remove the file's outliers");
    }
  }
}

ChannelSet SelectChannels(const ChannelSet& measurements, const std::vector<std::string>& channels,
                          const std::string& key, const std::string& source, bool* use_u0,
                          bool* use_uL) {
  *use_u0 = true;
  *use_uL = true;
  if (channels.empty()) return measurements;
  // The end channels, then the interior ones in the order of `channels`.
  const std::vector<BarSensor> sensors = BarSensors(measurements);
  ChannelSet selected;
  selected.start_time = measurements.start_time;
  selected.time_step = measurements.time_step;
  for (std::size_t c = 0; c < measurements.channels.size(); ++c) {
    const bool interior = std::any_of(sensors.begin(), sensors.end(), [c](const BarSensor& s) {
      return s.index == static_cast<int>(c);
    });
    if (!interior) selected.channels.push_back(measurements.channels[c]);
  }
  *use_u0 = std::find(channels.begin(), channels.end(), "u0") != channels.end();
  *use_uL = std::find(channels.begin(), channels.end(), "uL") != channels.end();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    ChannelName wanted;
    std::string why;
    if (!ParseChannelName(channels[i], &wanted, &why)) {
      throw InputError(key + "[" + std::to_string(i) + "] = '" + channels[i] + "': " + why);
    }
    if (wanted.kind != ChannelName::Kind::kSensor) continue;
    auto found = std::find_if(sensors.begin(), sensors.end(), [&wanted](const BarSensor& sensor) {
      return sensor.kind == wanted.sensor_kind && sensor.position == wanted.position;
    });
    if (found == sensors.end()) {
      std::string available;
      for (const BarSensor& sensor : sensors) {
        available += " " + measurements.channels[static_cast<std::size_t>(sensor.index)].name;
      }
      throw InputError(
          key + "[" + std::to_string(i) + "] = '" + channels[i] + "': no such channel in " +
          source + " (its interior channels:" + (available.empty() ? " none" : available) + ")");
    }
    selected.channels.push_back(measurements.channels[static_cast<std::size_t>(found->index)]);
  }
  return selected;
}

void WriteMeasurementCsv(const ChannelSet& measurements, const std::string& path) {
  const int samples = measurements.num_samples();
  const BarEnds ends = BarEndChannels(measurements);
  const std::vector<BarSensor> sensors = BarSensors(measurements);
  assert(ends.u0.size() == samples && ends.uL.size() == samples && ends.f0.size() == samples &&
         ends.fL.size() == samples);
  std::string content = kHeader;
  for (const BarSensor& sensor : sensors) {
    const Channel& channel = measurements.channels[static_cast<std::size_t>(sensor.index)];
    assert(channel.values.size() == samples);
    content += "," + channel.name;
  }
  content += "\n";
  content.reserve(content.size() + static_cast<std::size_t>(samples) * (5 + sensors.size()) * 25);
  for (int k = 0; k < samples; ++k) {
    content += FormatNumber(measurements.Time(k), kSeventeenDigits);
    for (const double value : {ends.u0[k], ends.uL[k], ends.f0[k], ends.fL[k]}) {
      content += ',';
      content += FormatNumber(value, kSeventeenDigits);
    }
    for (const BarSensor& sensor : sensors) {
      content += ',';
      content +=
          FormatNumber(measurements.channels[static_cast<std::size_t>(sensor.index)].values[k],
                       kSeventeenDigits);
    }
    content += '\n';
  }
  WriteFileAtomically(path, content);
}

}  // namespace mcrewave
