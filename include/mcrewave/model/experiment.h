// The reference experiment (formulation.md section 1): the shock load, the time
// grid and where the measurements come from.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/core/types.h"
#include "mcrewave/model/bar_model.h"

namespace mcrewave {

// The load applied on the bar at x = L, positive along +x.
struct LoadOptions {
  LoadKind kind = LoadKind::kHalfSine;
  double amplitude = 1000.0;  // F0 [N], finite and nonzero
  double duration = 1e-4;     // t_load [s]

  bool IsValid(std::string* error) const;
  // F(t) [N] at time t [s].
  double Value(double time) const;
};

// The observation window and the time discretisation of the model.
struct TimeOptions {
  double window = 0.63e-3;  // T [s]
  double step = 0.36e-6;    // h [s]
  double theta = 0.5;       // theta-method parameter, in [0.5, 1]

  // Valid when window and step are positive, theta is in [0.5, 1] and the window
  // holds a whole number of steps (to 1e-9 relative).
  bool IsValid(std::string* error) const;
  // m = T / h, the number of steps; samples are t_k = k h, k = 0..m.
  int NumSteps() const;
};

// Where the measurements come from. Synthetic data are computed on a "truth"
// (a finer FE discretisation, or the exact solution: never the identifying
// model's own grid unless truth_refinement = 1), sampled at t_k = k h, then
// Gaussian white noise is added at the given SNR (see noise.h for the definition).
struct DataOptions {
  DataSource source = DataSource::kSynthetic;
  std::string path;                                      // CSV file when source = csv
  TruthModel truth = TruthModel::kFiniteElement;         // synthetic only
  int truth_refinement = 4;                              // mesh and step refined by this factor
  double snr = std::numeric_limits<double>::infinity();  // inf = no noise
  std::uint64_t seed = 1;                                // noise seed
  // Interior sensor channels of synthetic data (`u@X`, `e@X`; data/measurement.h),
  // beside u0, uL, f0, fL.
  std::vector<std::string> sensors;
  // The channels the identification uses (names as in the CSV header); empty: every
  // channel of the data. f0 and fL, the model's loads, must be among them.
  std::vector<std::string> channels;
  // The truth's stretches of another modulus (synthetic only; `model.modulus`
  // elsewhere), each [start, end] m at `modulus` Pa, not overlapping.
  std::vector<ModulusZone> truth_zones;
  // The truth's support at x = 0 (finite_element truth only): a spring of this
  // stiffness [N/m] between node 0 and the wall, a load cell or a compliant clamp;
  // +inf is the rigid clamp u(0) = 0. The measured u0 is then the spring's
  // displacement and f0 = -k_s u0 the force it applies on the bar.
  double support_stiffness = std::numeric_limits<double>::infinity();
  // Synthetic data of a structure given by matrices (model.kind: matrix): the truth's
  // manifest ("" = the model's own; relative to the config file) and its zone moduli
  // [Pa] (one per zone of the truth's manifest; [] = their nominal moduli).
  std::string truth_manifest;
  std::vector<double> truth_moduli;
  // A CSV record (model.kind matrix): the name of its time column [s], the time of its
  // clock that is the model's t = 0 [s] (the record's t - time_origin is the model's),
  // and whether it may begin after the model's t = 0, every channel 0 before its first
  // sample (a shot recorded from a trigger after the impact, before the waves reach the
  // gauges; resample.h).
  std::string time_column = "t";
  double time_origin = 0.0;
  bool at_rest_before_record = false;

  // Checks what needs no other section: channel names well formed and not repeated
  // (data.sensors, data.channels), f0 and fL among data.channels. Positions against
  // the bar and the truth zones are checked with the model (ValidateDataAgainstBar).
  bool IsValid(std::string* error) const;
};

// Empty when data's sensors lie on the bar [0, L], its truth zones are valid for it
// (ValidateModulusZones, not overlapping) and the exact truth is not asked for zones
// or sensors it cannot give; otherwise the reason, naming the key.
std::string ValidateDataAgainstBar(const DataOptions& data, const BarProperties& bar);

}  // namespace mcrewave
