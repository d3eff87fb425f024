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
#include <vector>

#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"

namespace mcrewave {
namespace {

// The required columns, in the order they are written: time and the four end channels.
constexpr int kEndColumns = 5;
constexpr std::array<const char*, kEndColumns> kColumnNames = {"t", "u0", "uL", "f0", "fL"};
constexpr char kHeader[] = "t,u0,uL,f0,fL";
// Largest accepted |step - reference step| / reference step, the reference being
// the median of the file's steps.
constexpr double kStepTolerance = 1e-6;
// A progress line every this many rows (large files).
constexpr std::size_t kProgressRows = 250000;

// `line` without trailing spaces, tabs and carriage returns (Windows line ends).
std::string StripLineEnd(const std::string& line) {
  const std::size_t last = line.find_last_not_of(" \t\r");
  return last == std::string::npos ? "" : line.substr(0, last + 1);
}

// Parses a whole field (surrounding spaces allowed) as a number with strtod;
// false when anything else is left over or the field is empty.
bool ParseNumber(const std::string& field, double* value) {
  const char* begin = field.c_str();
  char* end = nullptr;
  *value = std::strtod(begin, &end);
  if (end == begin) return false;
  while (*end == ' ' || *end == '\t') ++end;
  return *end == '\0';
}

// Formats "%g" with the default 6 significant digits, for messages.
std::string Short(double value) { return FormatNumber(value, kSixDigits); }

// The step of t_0 + k h that reproduces every time of the file exactly, searched
// among the doubles within a few ulps of the mean step; the mean step itself when
// none does. This makes a file written by WriteMeasurementCsv read back bit for bit.
double ExactStep(const std::vector<double>& times, double mean_step) {
  double candidate = mean_step;
  for (int ulp = 0; ulp < 4; ++ulp) candidate = std::nextafter(candidate, 0.0);
  for (int trial = 0; trial < 9; ++trial, candidate = std::nextafter(candidate, HUGE_VAL)) {
    bool reproduces_all = true;
    for (std::size_t k = 0; k < times.size() && reproduces_all; ++k) {
      reproduces_all = times[0] + static_cast<double>(k) * candidate == times[k];
    }
    if (reproduces_all) return candidate;
  }
  return mean_step;
}

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

MeasurementSet ReadMeasurementCsv(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read measurement file " + path + ": " + std::strerror(errno));
  }
  return ParseMeasurementCsv(file, path);
}

int ChannelTable::Find(const std::string& name) const {
  const auto found = std::find(names.begin(), names.end(), name);
  return found == names.end() ? -1 : static_cast<int>(found - names.begin());
}

ChannelTable ReadChannelTable(const std::string& path, const HeaderCheck& check_header) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read measurement file " + path + ": " + std::strerror(errno));
  }
  return ParseChannelTable(file, path, check_header);
}

ChannelTable ParseChannelTable(std::istream& file, const std::string& path,
                               const HeaderCheck& check_header) {
  auto fail = [&path](long line_number, const std::string& what) {
    throw InputError(path + ":" + std::to_string(line_number) + ": " + what);
  };

  // The header: column c holds names[c]; time_column is the column of t.
  std::vector<std::string> names;
  std::size_t time_column = 0;
  std::vector<std::vector<double>> columns;
  std::string line;
  std::vector<std::string> fields;  // the fields of the current row
  long line_number = 0;
  long first_blank_line = 0;  // first empty line seen so far, 0 if none
  auto split = [&fields](const std::string& text) {
    fields.clear();
    for (std::size_t field_start = 0;;) {
      const std::size_t comma = text.find(',', field_start);
      fields.push_back(text.substr(field_start, comma - field_start));
      if (comma == std::string::npos) break;
      field_start = comma + 1;
    }
  };
  while (std::getline(file, line)) {
    ++line_number;
    line = StripLineEnd(line);
    if (line_number == 1) {
      if (line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 byte order mark
      split(line);
      for (std::string field : fields) {
        const std::size_t first = field.find_first_not_of(" \t");
        const std::size_t last = field.find_last_not_of(" \t");
        names.push_back(first == std::string::npos ? "" : field.substr(first, last - first + 1));
      }
      if (check_header) {
        const std::string why = check_header(names, line);
        if (!why.empty()) fail(1, why);
      }
      for (std::size_t c = 0; c < names.size(); ++c) {
        if (names[c].empty()) fail(1, "column " + std::to_string(c + 1) + " has no name");
        for (std::size_t other = 0; other < c; ++other) {
          if (names[other] == names[c]) {
            fail(1, "column " + std::to_string(c + 1) + " '" + names[c] + "' repeats column " +
                        std::to_string(other + 1) + " '" + names[other] + "'");
          }
        }
      }
      const auto time = std::find(names.begin(), names.end(), "t");
      if (time == names.end()) {
        fail(1, "the header '" + line + "' lacks the time column 't' [s]");
      }
      time_column = static_cast<std::size_t>(time - names.begin());
      columns.resize(names.size());
      continue;
    }
    if (line.empty()) {
      if (first_blank_line == 0) first_blank_line = line_number;
      continue;
    }
    if (first_blank_line != 0) fail(first_blank_line, "empty line between data rows");

    split(line);
    if (fields.size() != names.size()) {
      fail(line_number, "expected " + std::to_string(names.size()) + " columns, got " +
                            std::to_string(fields.size()));
    }
    for (std::size_t c = 0; c < names.size(); ++c) {
      double value = 0.0;
      if (!ParseNumber(fields[c], &value)) {
        fail(line_number, "column '" + names[c] + "': '" + fields[c] + "' is not a number");
      }
      if (!std::isfinite(value)) {
        fail(line_number, "column '" + names[c] + "': '" + fields[c] + "' is not a finite number");
      }
      if (c == time_column && !columns[c].empty() && !(value > columns[c].back())) {
        fail(line_number, "time is not strictly increasing (t = " + Short(value) + " s after " +
                              Short(columns[c].back()) + " s)");
      }
      columns[c].push_back(value);
    }
    if (columns[time_column].size() % kProgressRows == 0) {
      spdlog::info("{}: read {} rows", path, columns[time_column].size());
    }
  }
  if (file.bad()) {
    throw InputError("cannot read measurement file " + path + ": " + std::strerror(errno));
  }
  if (line_number == 0) {
    const std::string expected = check_header ? check_header({}, "") : "";
    fail(1, "expected " +
                (expected.empty() ? std::string("a header naming the columns, t among them")
                                  : expected) +
                ", got an empty file");
  }

  const std::vector<double>& times = columns[time_column];
  const std::size_t rows = times.size();
  if (rows < 2) {
    fail(line_number, "expected at least 2 data rows, got " + std::to_string(rows));
  }
  const double mean_step = (times.back() - times.front()) / static_cast<double>(rows - 1);
  if (!std::isfinite(mean_step)) {
    fail(line_number, "time span " + Short(times.front()) + " s to " + Short(times.back()) +
                          " s is too wide for a double");
  }
  // Each step against the median step: a sample missing (or one too many) anywhere
  // changes only the steps next to it, and the row where the first bad step ends (the
  // first row whose t is off) is reported. (The mean step is off by about 1/rows for
  // a single missing sample, so every step differed from it and line 3 was blamed.)
  double reference_step = 0.0;
  {
    std::vector<double> steps(rows - 1);
    for (std::size_t k = 1; k < rows; ++k) steps[k - 1] = times[k] - times[k - 1];
    const auto median = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
    std::nth_element(steps.begin(), median, steps.end());
    reference_step = *median;
  }
  for (std::size_t k = 1; k < rows; ++k) {
    const double step = times[k] - times[k - 1];
    if (std::abs(step - reference_step) > kStepTolerance * reference_step) {
      // Data row k is on line k + 2: the header is line 1 and an empty line between
      // data rows is refused above.
      fail(static_cast<long>(k) + 2,
           "time step " + Short(step) + " s (from t = " + Short(times[k - 1]) +
               " s on the previous row), expected the file's step " + Short(reference_step) +
               " s (the median step) within 1e-6 relative");
    }
  }

  ChannelTable table;
  table.start_time = times.front();
  table.time_step = ExactStep(times, mean_step);
  table.samples = static_cast<int>(rows);
  // Each column is freed once copied: at most one column is held twice.
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (c == time_column) continue;
    table.names.push_back(names[c]);
    table.columns.emplace_back(Eigen::Map<const Vector>(
        columns[c].data(), static_cast<Eigen::Index>(columns[c].size())));
    columns[c] = {};
  }
  return table;
}

void WriteChannelTable(const ChannelTable& table, const std::string& path) {
  std::string content = "t";
  for (std::size_t c = 0; c < table.names.size(); ++c) {
    assert(table.columns[c].size() == table.samples);
    content += "," + table.names[c];
  }
  content += "\n";
  content.reserve(content.size() +
                  static_cast<std::size_t>(table.samples) * (1 + table.names.size()) * 25);
  char field[32];
  for (int k = 0; k < table.samples; ++k) {
    int length = std::snprintf(field, sizeof(field), "%.17g", table.Time(k));
    content.append(field, static_cast<std::size_t>(length));
    for (const Vector& column : table.columns) {
      length = std::snprintf(field, sizeof(field), ",%.17g", column[k]);
      content.append(field, static_cast<std::size_t>(length));
    }
    content += '\n';
  }
  WriteFileAtomically(path, content);
}

MeasurementSet ParseMeasurementCsv(std::istream& file, const std::string& path) {
  const std::string expected_header =
      std::string("a header naming the columns: ") + kHeader +
      " in any order, then any interior channels u@X (displacement at X m) and e@X (strain "
      "at X m)";
  // The bar's header: every name a channel of data/measurement.h, no sensor twice, the
  // five end columns present ("" when so; an empty header asks what is expected).
  auto check_header = [&expected_header](const std::vector<std::string>& names,
                                         const std::string& line) -> std::string {
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
  };
  ChannelTable table = ParseChannelTable(file, path, check_header);

  MeasurementSet measurements;
  measurements.start_time = table.start_time;
  measurements.time_step = table.time_step;
  Vector* ends[] = {nullptr, &measurements.u0, &measurements.uL, &measurements.f0,
                    &measurements.fL};
  for (std::size_t c = 0; c < table.names.size(); ++c) {
    ChannelName channel;
    std::string why;
    ParseChannelName(table.names[c], &channel, &why);  // checked with the header
    if (channel.kind == ChannelName::Kind::kSensor) {
      measurements.sensors.push_back(
          {table.names[c], channel.sensor_kind, channel.position, std::move(table.columns[c])});
    } else {
      *ends[static_cast<int>(channel.kind)] = std::move(table.columns[c]);
    }
  }
  return measurements;
}

void CheckMeasurementChannels(const MeasurementSet& measurements, const std::string& name) {
  const Vector* channels[] = {&measurements.u0, &measurements.uL, &measurements.f0,
                              &measurements.fL};
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
                       Short(x[spike]) + " is an outlier: its second difference " +
                       Short(second_differences[worst]) + " is above " +
                       Short(kOutlierNoiseFactor) + " times the channel's noise level " +
                       Short(noise_level) + " and half its peak " + Short(peak) +
                       "; repair or remove the file's outliers");
    }
  }
}

void KeepFirstSamples(int samples, MeasurementSet* measurements) {
  assert(samples >= 0 && samples <= measurements->num_samples());
  for (Vector* channel :
       {&measurements->u0, &measurements->uL, &measurements->f0, &measurements->fL}) {
    channel->conservativeResize(samples);
  }
  for (SensorChannel& sensor : measurements->sensors) sensor.values.conservativeResize(samples);
}

MeasurementSet SelectChannels(const MeasurementSet& measurements,
                              const std::vector<std::string>& channels, const std::string& key,
                              const std::string& source, bool* use_u0, bool* use_uL) {
  *use_u0 = true;
  *use_uL = true;
  if (channels.empty()) return measurements;
  MeasurementSet selected = measurements;
  selected.sensors.clear();
  *use_u0 = std::find(channels.begin(), channels.end(), "u0") != channels.end();
  *use_uL = std::find(channels.begin(), channels.end(), "uL") != channels.end();
  for (std::size_t i = 0; i < channels.size(); ++i) {
    ChannelName wanted;
    std::string why;
    if (!ParseChannelName(channels[i], &wanted, &why)) {
      throw InputError(key + "[" + std::to_string(i) + "] = '" + channels[i] + "': " + why);
    }
    if (wanted.kind != ChannelName::Kind::kSensor) continue;
    auto found = std::find_if(measurements.sensors.begin(), measurements.sensors.end(),
                              [&wanted](const SensorChannel& sensor) {
                                return sensor.kind == wanted.sensor_kind &&
                                       sensor.position == wanted.position;
                              });
    if (found == measurements.sensors.end()) {
      std::string available;
      for (const SensorChannel& sensor : measurements.sensors) available += " " + sensor.name;
      throw InputError(
          key + "[" + std::to_string(i) + "] = '" + channels[i] + "': no such channel in " +
          source + " (its interior channels:" + (available.empty() ? " none" : available) + ")");
    }
    selected.sensors.push_back(*found);
  }
  return selected;
}

void WriteMeasurementCsv(const MeasurementSet& measurements, const std::string& path) {
  const int samples = measurements.num_samples();
  assert(measurements.uL.size() == samples && measurements.f0.size() == samples &&
         measurements.fL.size() == samples);
  std::string content = kHeader;
  for (const SensorChannel& sensor : measurements.sensors) {
    assert(sensor.values.size() == samples);
    content += "," + sensor.name;
  }
  content += "\n";
  content.reserve(content.size() +
                  static_cast<std::size_t>(samples) * (5 + measurements.sensors.size()) * 25);
  char row[5 * 32];
  for (int k = 0; k < samples; ++k) {
    int length = std::snprintf(row, sizeof(row), "%.17g,%.17g,%.17g,%.17g,%.17g",
                               measurements.Time(k), measurements.u0[k], measurements.uL[k],
                               measurements.f0[k], measurements.fL[k]);
    content.append(row, static_cast<std::size_t>(length));
    for (const SensorChannel& sensor : measurements.sensors) {
      length = std::snprintf(row, sizeof(row), ",%.17g", sensor.values[k]);
      content.append(row, static_cast<std::size_t>(length));
    }
    content += '\n';
  }
  WriteFileAtomically(path, content);
}

}  // namespace mcrewave
