// A measurement set: the four channels of the experiment sampled on a uniform
// time grid, and its CSV form.
//
// CSV format: a header line exactly `t,u0,uL,f0,fL`, then one row per sample
// t_k = t_0 + k h with h uniform, SI units (s, m, m, N, N):
//   t   time [s]
//   u0  displacement at x = 0 [m]
//   uL  displacement at x = L [m]
//   f0  force applied ON the bar at x = 0, positive along +x [N] (the clamp reaction)
//   fL  force applied ON the bar at x = L, positive along +x [N] (the shock load)
#pragma once

#include <string>

#include "mcrewave/types.h"

namespace mcrewave {

struct MeasurementSet {
  double start_time = 0.0;  // t_0 [s]
  double time_step = 0.0;   // h [s]
  Vector u0, uL;            // [m], one entry per sample
  Vector f0, fL;            // [N], one entry per sample

  int num_samples() const { return static_cast<int>(u0.size()); }
  int num_steps() const { return num_samples() - 1; }
  double Time(int k) const { return start_time + k * time_step; }
};

// Reads a measurement CSV. Validates the header, the column count, every number
// (finite, no NaN/Inf), at least two rows, and a strictly increasing uniform time
// column (relative spread of the steps at most 1e-6). Throws InputError naming the
// file and the line on any failure.
MeasurementSet ReadMeasurementCsv(const std::string& path);

// Writes the set as CSV with full precision (17 significant digits), atomically
// (temporary file then rename). Throws std::runtime_error if the file cannot be
// written.
void WriteMeasurementCsv(const MeasurementSet& measurements, const std::string& path);

}  // namespace mcrewave
