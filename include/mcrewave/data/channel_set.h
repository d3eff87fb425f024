// A channel set: named channels sampled on one uniform time grid, the measurements
// of any structure (docs/zones_and_sensors.md for the bar's channels,
// docs/matrix_models.md for a structure given by matrices), and its CSV form.
//
// CSV form: a header line naming the columns, a column `t` [s] among them, then one
// row per sample t_k = t_0 + k h with h uniform, SI units; every other column is a
// channel named by its header. The kinds of the channels come from the structure
// (the bar's names, data/measurement.h; a matrix model's loads and sensors).
#pragma once

#include <functional>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include "mcrewave/core/types.h"

namespace mcrewave {

// One measured channel: its name (the CSV header), its kind and one value per sample
// ([m], [-] or [N] by kind).
struct Channel {
  std::string name;
  ChannelKind kind = ChannelKind::kDisplacement;
  Vector values;
};

struct ChannelSet {
  double start_time = 0.0;        // t_0 [s]
  double time_step = 0.0;         // h [s]
  std::vector<Channel> channels;  // in the file's column order (t excluded); every
                                  // channel has num_samples() values, no name twice

  // Samples of the first channel (all have as many), 0 when there is none.
  int num_samples() const {
    return channels.empty() ? 0 : static_cast<int>(channels.front().values.size());
  }
  int num_steps() const { return num_samples() - 1; }
  double Time(int k) const { return start_time + k * time_step; }
  // The index of the channel named `name`, or -1.
  int Find(std::string_view name) const;
  // The values of the channel named `name`. Precondition: it is present (else throws
  // std::logic_error naming it).
  const Vector& Values(std::string_view name) const;
  Vector& Values(std::string_view name);
  // Appends a channel and returns its values. Precondition: no channel has that name
  // (else throws std::logic_error).
  Vector& Add(std::string name, ChannelKind kind, Vector values);
};

// Keeps the first `samples` samples of every channel of *set (at most its
// num_samples()); the time grid is unchanged.
void KeepFirstSamples(int samples, ChannelSet* set);

// A check of a header before any row is read: the column names (t included, trimmed)
// and the header line as read; returns "" when they are acceptable, else the reason
// (reported on line 1). Called with no names to ask what a header should be, for the
// message of an empty file.
using HeaderCheck =
    std::function<std::string(const std::vector<std::string>& names, const std::string& line)>;
// The kind of the channel of a column, by its name (called once the header passed).
using ChannelKindOf = std::function<ChannelKind(const std::string& name)>;

// Reads a channel CSV: a header (every column named, no name twice, a time column
// named time_name [s], then check_header's own conditions), at least two rows of finite
// numbers, one per column, and a strictly increasing uniform time column (every step
// within 1e-6 of their median, relative, or within the single-precision rounding of the
// time stamps, 2^-23 of the largest |t|). The channels are in the file's column order,
// of the kinds kind_of gives (kDisplacement without it). Throws InputError naming
// the file and the line on any failure. Logs a progress line every 250000 rows.
// Memory: the columns of doubles (one column held twice at the end).
ChannelSet ReadChannelCsv(const std::string& path, const HeaderCheck& check_header = {},
                          const ChannelKindOf& kind_of = {}, const std::string& time_name = "t");
// The same from a stream; `name` stands for the file name in messages.
ChannelSet ParseChannelCsv(std::istream& text, const std::string& name,
                           const HeaderCheck& check_header = {}, const ChannelKindOf& kind_of = {},
                           const std::string& time_name = "t");

// Writes the set as CSV (t, then the channels in order by name), 17 significant
// digits, atomically (temporary file then rename). Throws std::runtime_error if the
// file cannot be written.
void WriteChannelCsv(const ChannelSet& set, const std::string& path);

}  // namespace mcrewave
