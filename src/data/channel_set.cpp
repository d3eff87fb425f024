#include "mcrewave/data/channel_set.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
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
using internal::StripLineEnd;

// Largest accepted |step - reference step| / reference step, the reference being
// the median of the file's steps.
constexpr double kStepTolerance = 1e-6;
// A progress line every this many rows (large files).
constexpr std::size_t kProgressRows = 250000;

// The step of t_0 + k h that reproduces every time of the file exactly, searched
// among the doubles within a few ulps of the mean step; the mean step itself when
// none does. This makes a file written by WriteChannelCsv read back bit for bit.
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

int ChannelSet::Find(std::string_view name) const {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].name == name) return static_cast<int>(c);
  }
  return -1;
}

const Vector& ChannelSet::Values(std::string_view name) const {
  const int c = Find(name);
  if (c < 0) throw std::logic_error("the channel set has no channel '" + std::string(name) + "'");
  return channels[static_cast<std::size_t>(c)].values;
}

Vector& ChannelSet::Values(std::string_view name) {
  return const_cast<Vector&>(static_cast<const ChannelSet&>(*this).Values(name));
}

Vector& ChannelSet::Add(std::string name, ChannelKind kind, Vector values) {
  if (Find(name) >= 0) {
    throw std::logic_error("the channel set has a channel '" + name + "' already");
  }
  channels.push_back({std::move(name), kind, std::move(values)});
  return channels.back().values;
}

void KeepFirstSamples(int samples, ChannelSet* set) {
  assert(samples >= 0 && samples <= set->num_samples());
  for (Channel& channel : set->channels) channel.values.conservativeResize(samples);
}

ChannelSet ReadChannelCsv(const std::string& path, const HeaderCheck& check_header,
                          const ChannelKindOf& kind_of, const std::string& time_name) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError("cannot read measurement file " + path + ": " + std::strerror(errno));
  }
  return ParseChannelCsv(file, path, check_header, kind_of, time_name);
}

namespace {

// Throws the InputError "path:line: what".
[[noreturn]] void FailAt(const std::string& path, long line_number, const std::string& what) {
  throw InputError(path + ":" + std::to_string(line_number) + ": " + what);
}

// The comma-separated fields of `text` into *fields.
void SplitFields(const std::string& text, std::vector<std::string>* fields) {
  fields->clear();
  for (std::size_t field_start = 0;;) {
    const std::size_t comma = text.find(',', field_start);
    fields->push_back(text.substr(field_start, comma - field_start));
    if (comma == std::string::npos) break;
    field_start = comma + 1;
  }
}

// The header line (line 1, byte order mark removed): the column names, trimmed, each
// named once, time_name among them (its index in *time_column), then check_header's own
// conditions.
std::vector<std::string> ParseHeader(std::string line, const std::string& path,
                                     const HeaderCheck& check_header, const std::string& time_name,
                                     std::size_t* time_column) {
  if (line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);  // UTF-8 byte order mark
  std::vector<std::string> fields, names;
  SplitFields(line, &fields);
  for (const std::string& field : fields) {
    const std::size_t first = field.find_first_not_of(" \t");
    const std::size_t last = field.find_last_not_of(" \t");
    names.push_back(first == std::string::npos ? "" : field.substr(first, last - first + 1));
  }
  if (check_header) {
    const std::string why = check_header(names, line);
    if (!why.empty()) FailAt(path, 1, why);
  }
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (names[c].empty()) FailAt(path, 1, "column " + std::to_string(c + 1) + " has no name");
    for (std::size_t other = 0; other < c; ++other) {
      if (names[other] == names[c]) {
        FailAt(path, 1,
               "column " + std::to_string(c + 1) + " '" + names[c] + "' repeats column " +
                   std::to_string(other + 1) + " '" + names[other] + "'");
      }
    }
  }
  const auto time = std::find(names.begin(), names.end(), time_name);
  if (time == names.end()) {
    FailAt(path, 1,
           "the header '" + line + "' lacks the time column '" + time_name + "' [s]" +
               (time_name == "t" ? "" : " (data.time_column)"));
  }
  *time_column = static_cast<std::size_t>(time - names.begin());
  return names;
}

// The step of a time column read to its last line (line_number): at least 2 rows, a
// finite span, every step the median step within kStepTolerance.
double UniformTimeStep(const std::vector<double>& times, const std::string& path,
                       long line_number) {
  const std::size_t rows = times.size();
  if (rows < 2) {
    FailAt(path, line_number, "expected at least 2 data rows, got " + std::to_string(rows));
  }
  const double mean_step = (times.back() - times.front()) / static_cast<double>(rows - 1);
  if (!std::isfinite(mean_step)) {
    FailAt(path, line_number,
           "time span " + ShortNumber(times.front()) + " s to " + ShortNumber(times.back()) +
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
  // Time stamps written in single precision (a scope's export: about 7 digits) are
  // off by up to 2^-24 of |t|, so a step by twice that: accepted, a missing sample is
  // still a whole step off.
  const double stamp_rounding =
      2.0 * std::ldexp(std::max(std::abs(times.front()), std::abs(times.back())), -24);
  const double tolerance = std::max(kStepTolerance * reference_step, stamp_rounding);
  for (std::size_t k = 1; k < rows; ++k) {
    const double step = times[k] - times[k - 1];
    if (std::abs(step - reference_step) > tolerance) {
      // Data row k is on line k + 2: the header is line 1 and an empty line between
      // data rows is refused.
      FailAt(path, static_cast<long>(k) + 2,
             "time step " + ShortNumber(step) + " s (from t = " + ShortNumber(times[k - 1]) +
                 " s on the previous row), expected the file's step " +
                 ShortNumber(reference_step) +
                 " s (the median step) within 1e-6 relative or the single-precision rounding "
                 "of the time stamps");
    }
  }
  return ExactStep(times, mean_step);
}

}  // namespace

ChannelSet ParseChannelCsv(std::istream& file, const std::string& path,
                           const HeaderCheck& check_header, const ChannelKindOf& kind_of,
                           const std::string& time_name) {
  // The header: column c holds names[c]; time_column is the column of t.
  std::vector<std::string> names;
  std::size_t time_column = 0;
  std::vector<std::vector<double>> columns;
  std::string line;
  std::vector<std::string> fields;  // the fields of the current row
  long line_number = 0;
  long first_blank_line = 0;  // first empty line seen so far, 0 if none
  while (std::getline(file, line)) {
    ++line_number;
    line = StripLineEnd(line);
    if (line_number == 1) {
      names = ParseHeader(line, path, check_header, time_name, &time_column);
      columns.resize(names.size());
      continue;
    }
    if (line.empty()) {
      if (first_blank_line == 0) first_blank_line = line_number;
      continue;
    }
    if (first_blank_line != 0) FailAt(path, first_blank_line, "empty line between data rows");

    SplitFields(line, &fields);
    if (fields.size() != names.size()) {
      FailAt(path, line_number,
             "expected " + std::to_string(names.size()) + " columns, got " +
                 std::to_string(fields.size()));
    }
    for (std::size_t c = 0; c < names.size(); ++c) {
      double value = 0.0;
      if (!ParseNumber(fields[c], &value)) {
        FailAt(path, line_number, "column '" + names[c] + "': '" + fields[c] + "' is not a number");
      }
      if (!std::isfinite(value)) {
        FailAt(path, line_number,
               "column '" + names[c] + "': '" + fields[c] + "' is not a finite number");
      }
      if (c == time_column && !columns[c].empty() && !(value > columns[c].back())) {
        FailAt(path, line_number,
               "time is not strictly increasing (t = " + ShortNumber(value) + " s after " +
                   ShortNumber(columns[c].back()) + " s)");
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
    FailAt(path, 1,
           "expected " +
               (expected.empty() ? std::string("a header naming the columns, t among them")
                                 : expected) +
               ", got an empty file");
  }

  const std::vector<double>& times = columns[time_column];
  ChannelSet set;
  set.time_step = UniformTimeStep(times, path, line_number);
  set.start_time = times.front();
  set.channels.reserve(names.size() - 1);
  // Each column is freed once copied: at most one column is held twice.
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (c == time_column) continue;
    set.channels.push_back({names[c], kind_of ? kind_of(names[c]) : ChannelKind::kDisplacement,
                            Eigen::Map<const Vector>(
                                columns[c].data(), static_cast<Eigen::Index>(columns[c].size()))});
    columns[c] = {};
  }
  return set;
}

void WriteChannelCsv(const ChannelSet& set, const std::string& path) {
  const int samples = set.num_samples();
  std::string content = "t";
  for (const Channel& channel : set.channels) {
    assert(channel.values.size() == samples);
    content += "," + channel.name;
  }
  content += "\n";
  content.reserve(content.size() +
                  static_cast<std::size_t>(samples) * (1 + set.channels.size()) * 25);
  for (int k = 0; k < samples; ++k) {
    content += FormatNumber(set.Time(k), kSeventeenDigits);
    for (const Channel& channel : set.channels) {
      content += ',';
      content += FormatNumber(channel.values[k], kSeventeenDigits);
    }
    content += '\n';
  }
  WriteFileAtomically(path, content);
}

}  // namespace mcrewave
