// A measurement set: named channels sampled on a uniform time grid, and its CSV form.
//
// CSV format: a header line naming the columns, then one row per sample
// t_k = t_0 + k h with h uniform, SI units. The columns, in any order:
//   t    time [s]                                                     (required)
//   u0   displacement at x = 0 [m]                                    (required)
//   uL   displacement at x = L [m]                                    (required)
//   f0   force applied ON the bar at x = 0, positive along +x [N]     (required;
//        the clamp reaction)
//   fL   force applied ON the bar at x = L, positive along +x [N]     (required;
//        the shock load)
//   u@X  displacement [m] at X m from the clamped end                 (any number)
//   e@X  axial strain [-] at X (BarModel::StrainRow), compression negative (any number)
// e.g. `t,u0,uL,f0,fL,u@0.25,u@0.5,e@0.2,e@0.65`. The paper's file `t,u0,uL,f0,fL`
// keeps its meaning.
#pragma once

#include <functional>
#include <istream>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

// An interior sensor channel: CSV column `u@X` (displacement [m] at X m from the
// clamped end) or `e@X` (axial strain [-] at X: of the element holding X, at a node
// the mean of its two elements; compression negative).
struct SensorChannel {
  std::string name;  // the CSV header, e.g. "u@0.25"
  SensorKind kind = SensorKind::kDisplacement;
  double position = 0.0;  // X [m]
  Vector values;          // one entry per sample [m] or [-]
};

// A column name of the CSV header, parsed.
struct ChannelName {
  enum class Kind { kTime, kU0, kUL, kF0, kFL, kSensor };  // t, u0, uL, f0, fL, u@X / e@X
  Kind kind = Kind::kTime;
  SensorKind sensor_kind = SensorKind::kDisplacement;  // kSensor only
  double position = 0.0;                               // X [m], kSensor only
};
// Parses a channel name; false with the reason in *why for anything else (e.g. `x@1`,
// `u@`, `u@abc`, a negative or non-finite X).
bool ParseChannelName(const std::string& text, ChannelName* channel, std::string* why);

struct MeasurementSet {
  double start_time = 0.0;             // t_0 [s]
  double time_step = 0.0;              // h [s]
  Vector u0, uL;                       // [m], one entry per sample
  Vector f0, fL;                       // [N], one entry per sample
  std::vector<SensorChannel> sensors;  // interior channels, in the file's column order

  int num_samples() const { return static_cast<int>(u0.size()); }
  int num_steps() const { return num_samples() - 1; }
  double Time(int k) const { return start_time + k * time_step; }
};

// Reads a measurement CSV. Validates the header (every name a channel, the required
// ones present, none twice: the same name, or the same sensor kind and position), the
// column count, every number (finite, no NaN/Inf), at least two rows, and a strictly
// increasing uniform time column (relative spread of the steps at most 1e-6). Throws
// InputError naming the file and the line on any failure. Logs a progress line every
// 250000 rows; memory is the columns of doubles, never the whole text.
MeasurementSet ReadMeasurementCsv(const std::string& path);

// The same from a stream; `name` stands for the file name in messages.
MeasurementSet ParseMeasurementCsv(std::istream& text, const std::string& name);

// A table of named channels on a uniform time grid: the CSV form of the measurements
// of any structure (a column `t` [s], then any columns, each a channel named by its
// header; a structure given by matrices maps them to its loads and sensors).
struct ChannelTable {
  double start_time = 0.0;         // t_0 [s]
  double time_step = 0.0;          // h [s]
  int samples = 0;                 // rows
  std::vector<std::string> names;  // every column but t, in the file's order
  std::vector<Vector> columns;     // one per name, `samples` entries each

  double Time(int k) const { return start_time + k * time_step; }
  // The index of the column named `name`, or -1.
  int Find(const std::string& name) const;
};

// A check of a header before any row is read: the column names (t included, trimmed)
// and the header line as read; returns "" when they are acceptable, else the reason
// (reported on line 1). Called with no names to ask what a header should be, for the
// message of an empty file.
using HeaderCheck =
    std::function<std::string(const std::vector<std::string>& names, const std::string& line)>;

// Reads a channel CSV: a header (every column named, no name twice, a column `t`,
// then check_header's own conditions), at least two rows of finite numbers, one per
// column, and a strictly increasing uniform time column (relative spread of the steps
// at most 1e-6, against their median). Throws InputError naming the file and the line
// on any failure. Memory: the columns of doubles (one column held twice at the end).
ChannelTable ReadChannelTable(const std::string& path, const HeaderCheck& check_header = {});
ChannelTable ParseChannelTable(std::istream& text, const std::string& name,
                               const HeaderCheck& check_header = {});

// Writes the table as CSV (t, then the columns by name), 17 significant digits,
// atomically. Throws std::runtime_error if the file cannot be written.
void WriteChannelTable(const ChannelTable& table, const std::string& path);

// Refuses measurements that read well but cannot be identified from, with an
// InputError naming `name`, the line of the sample (as in the CSV file: sample k
// on line k + 2) and the column:
//   - a dead channel: uL, f0 or fL zero on every sample (u0 may be: the clamped end);
//   - an outlier: the sample of largest second difference x[k-1] - 2 x[k] + x[k+1],
//     when that is above both kOutlierNoiseFactor times the channel's robust noise level
//     (1.4826 median |second difference|) and half the channel's peak |x|; the line
//     named is the spike's, the first or last sample's when it is there.
// A channel in wrong units (scaled by 1e6) passes here; the identification then
// ends on a bound of outer:, which `identify run` refuses.
void CheckMeasurementChannels(const MeasurementSet& measurements, const std::string& name);
constexpr double kOutlierNoiseFactor = 50.0;

// Keeps the first `samples` samples of every channel of *measurements (at most its
// num_samples()); the time grid is unchanged.
void KeepFirstSamples(int samples, MeasurementSet* measurements);

// The channels an identification uses (config data.channels): the set with only the
// interior sensors named in `channels` (all when `channels` is empty) and, in *use_u0
// and *use_uL, whether the end displacements are among them (f0 and fL always are:
// the model's loads). Throws InputError naming `key`, the channel and `source` when a
// channel is not in the set.
MeasurementSet SelectChannels(const MeasurementSet& measurements,
                              const std::vector<std::string>& channels, const std::string& key,
                              const std::string& source, bool* use_u0, bool* use_uL);

// Writes the set as CSV (t,u0,uL,f0,fL, then the sensors by name) with 17 significant
// digits, atomically (temporary file then rename). Throws std::runtime_error if the
// file cannot be written.
void WriteMeasurementCsv(const MeasurementSet& measurements, const std::string& path);

}  // namespace mcrewave
