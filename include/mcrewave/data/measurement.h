// The bar's measurements: a channel set (data/channel_set.h) of the bar's channels,
// and its CSV form.
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

#include <istream>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/data/channel_set.h"

namespace mcrewave {

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

// The bar's channel set: u0 and uL (kDisplacement), f0 and fL (kForce), each interior
// sensor u@X (kDisplacement) or e@X (kStrain); a set from ParseMeasurementCsv has
// them in the file's column order, one from BarChannelSet u0, uL, f0, fL first.
ChannelSet BarChannelSet(double start_time, double time_step, Vector u0, Vector uL, Vector f0,
                         Vector fL);

// The four end channels of a bar's set, looked up once (for loops over the samples).
// Refers into the set: valid while its channels are neither added nor removed.
struct BarEnds {
  const Vector& u0;  // [m]
  const Vector& uL;  // [m]
  const Vector& f0;  // [N]
  const Vector& fL;  // [N]
};
// Precondition: the set has the four (else throws std::logic_error).
BarEnds BarEndChannels(const ChannelSet& set);

// An interior sensor of the bar, `u@X` (kDisplacement) or `e@X` (kStrain): of a bar's
// set (BarSensors: the channel's name parsed, index its channel), or one to place
// (BarMatrixModel).
struct BarSensor {
  SensorKind kind = SensorKind::kDisplacement;
  double position = 0.0;  // X [m]
  int index = -1;         // into ChannelSet::channels; -1 when not of a set
};
// The interior sensors of a bar's set, in its order: every channel whose name is u@X
// or e@X.
std::vector<BarSensor> BarSensors(const ChannelSet& set);
// The values of those sensors, in the same order (refer into the set as BarEnds).
std::vector<const Vector*> BarSensorValues(const ChannelSet& set);

// Reads a measurement CSV. Validates the header (every name a channel, the required
// ones present, none twice: the same name, or the same sensor kind and position), the
// column count, every number (finite, no NaN/Inf), at least two rows, and a strictly
// increasing uniform time column (relative spread of the steps at most 1e-6). Throws
// InputError naming the file and the line on any failure. Logs a progress line every
// 250000 rows; memory is the columns of doubles, never the whole text.
ChannelSet ReadMeasurementCsv(const std::string& path);

// The same from a stream; `name` stands for the file name in messages.
ChannelSet ParseMeasurementCsv(std::istream& text, const std::string& name);

// The bar's header check of ReadMeasurementCsv (a HeaderCheck, channel_set.h): "" when
// `names` (t included) are channels of this header's names, the five end columns
// present and no channel twice; else the reason, quoting `line`. No names: what a
// header should be.
std::string BarHeaderProblem(const std::vector<std::string>& names, const std::string& line);

// The kind of the bar's channel `name` (a ChannelKindOf): f0 and fL forces, e@X strains,
// the others displacements.
ChannelKind BarChannelKind(const std::string& name);

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
void CheckMeasurementChannels(const ChannelSet& measurements, const std::string& name);
constexpr double kOutlierNoiseFactor = 50.0;

// The channels an identification uses (config data.channels): the set with only the
// interior sensors named in `channels` (all when `channels` is empty) and, in *use_u0
// and *use_uL, whether the end displacements are among them (f0 and fL always are:
// the model's loads). Throws InputError naming `key`, the channel and `source` when a
// channel is not in the set.
ChannelSet SelectChannels(const ChannelSet& measurements, const std::vector<std::string>& channels,
                          const std::string& key, const std::string& source, bool* use_u0,
                          bool* use_uL);

// Writes the set as CSV (t,u0,uL,f0,fL, then the sensors by name) with 17 significant
// digits, atomically (temporary file then rename). Throws std::runtime_error if the
// file cannot be written.
void WriteMeasurementCsv(const ChannelSet& measurements, const std::string& path);

}  // namespace mcrewave
