// The damage-localisation study (docs/zones_and_sensors.md, "Damage localisation"),
// run by `identify study` with study.kind: damage (not part of all):
//
// On the config's bar (the paper's: 100 elements, 1750 steps, truth 4x finer) with
// three truths:
//   soft          0.7 E_ref over [0.6, 0.7] m (on the identification's zone boundaries),
//   non_aligned   0.75 E_ref over [0.63, 0.71] m (no model zone matches it),
//   two_zones     0.8 E_ref over [0.15, 0.25] m and 1.15 E_ref over [0.55, 0.65] m;
// two sensor sets: the ends only (u0, uL, f0, fL), and the ends with u@0.25, 0.5,
// 0.75 and e@0.2, 0.45, 0.65, 0.9; every SNR of study.damage.snr (noise seed 1, none at
// SNR inf); two zonings of the identification: 10 equal zones and one zone per
// element. Then study.damage.seeds seeds of the soft truth with the interior sensors at
// SNR 10 and 10 zones. Each run: the scalar identification (E*), the error map at E*
// (its peak), the zone identification from E* (every zone's modulus), against the
// truth's modulus of each zone (its elements in series). With 10 equal zones also the
// same zones by output-error least squares (DamageLeastSquaresFit; attempted when the
// MCRE's zones converged), and for both functionals the data cost at the truth's zone
// moduli in series over the cost at the identified ones.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "mcrewave/model/bar_model.h"

namespace mcrewave {

struct Config;

struct DamageTruth {
  std::string name;
  std::vector<ModulusZone> zones;  // moduli as factors of E_ref
};
// The three truths of the study, moduli as factors of E_ref.
const std::vector<DamageTruth>& DamageTruths();
// The interior sensors of the study.
const std::vector<std::string>& DamageInteriorSensors();

// The zones of one run identified by output-error least squares (10 equal zones only):
// the MCRE's comparator on the same data, zones, start E*, penalty, weight rule and
// merging (IdentifyZoneModuliByLeastSquares).
struct DamageLeastSquaresFit {
  bool ran = false;
  bool converged = false;
  std::string message;                                               // why not, when not
  std::vector<double> moduli;                                        // E_z [Pa]
  int weakest_zone = -1;                                             // smallest E_z
  double max_zone_error = std::numeric_limits<double>::quiet_NaN();  // max |E_z / truth_z - 1|
  int groups = -1;                                                   // after merging
  // J at the truth's zone moduli in series over J at the identified ones.
  double reference_cost_ratio = std::numeric_limits<double>::quiet_NaN();
  int evaluations = 0;  // simulations' evaluations
  double wall_time_s = std::numeric_limits<double>::quiet_NaN();
};

struct DamageRun {
  int truth = 0;  // index in DamageTruths()
  bool interior_sensors = false;
  double snr = 0.0;
  std::uint64_t seed = 0;    // 0 at SNR inf
  bool per_element = false;  // one zone per element; else 10 equal zones
  bool converged = false;    // the scalar and the zone identification both converged
  std::string message;       // why not, when not converged
  double homogeneous_modulus = std::numeric_limits<double>::quiet_NaN();  // E* [Pa]
  double error_map_peak = std::numeric_limits<double>::quiet_NaN();  // x of its largest element [m]
  std::vector<double> zone_start, zone_end;                          // [m]
  std::vector<double> moduli;                                        // identified E_z [Pa]
  std::vector<double> truth_moduli;  // the truth's E over each zone, in series [Pa]
  int weakest_zone = -1;             // index of the smallest identified E_z
  double max_zone_error = std::numeric_limits<double>::quiet_NaN();  // max |E_z / truth_z - 1|
  double regularization_weight = std::numeric_limits<double>::quiet_NaN();
  int groups = -1;      // zones left distinct by merging (-1: not merged)
  // e^2 at the truth's zone moduli in series over e^2 at the identified ones (10 equal
  // zones; NaN otherwise). Noise-free, far above 1 says the data are better explained
  // by other moduli than the truth's zone values (a truth the zones cannot represent);
  // with noise the identified moduli also fit the noise, which alone raises it above 1.
  double reference_cost_ratio = std::numeric_limits<double>::quiet_NaN();
  int evaluations = 0;  // coupled solves, scalar and zones
  double wall_time_s = std::numeric_limits<double>::quiet_NaN();
  DamageLeastSquaresFit least_squares;  // the same zones by least squares (10 equal zones)
};

struct DamageStudy {
  double reference_modulus = 0.0;  // E_ref [Pa]
  double length = 0.0;             // L [m]
  std::vector<DamageRun> runs;     // the grid (truth, sensors, SNR, zoning), then the seeds
  int threads = 0;
  double wall_time_s = 0.0;
  // The settings every run shares (clamp, weights, zone penalty and its weight's rule),
  // as summary.md states them.
  std::string settings;
};

// Throws InputError, prefixed by `name` (the config file), when a run of the study
// would not be a valid config: its truths and sensors sit at fixed positions in m
// (the paper's bar, L = 1 m) and its 10 zones need 10 elements, so a shorter or
// coarser bar is refused here, before any study runs.
void CheckDamageStudyConfig(const Config& config, const std::string& name);

// Precondition: config valid (as LoadConfig returns it), synthetic finite-element
// truth, and CheckDamageStudyConfig passed.
// journal_path: as RunRobustnessStudy (study.h), the runs journaled and resumed there.
DamageStudy RunDamageStudy(const Config& config, const std::string& journal_path = "");

// damage/: runs.csv (one row per run), zones.csv (one row per run and zone),
// profiles.png (identified E(x) against the truth, per truth), error_map_peaks.png
// and summary.md (the goals of the study against the measured figures).
std::vector<std::string> WriteDamageResults(const DamageStudy& study, const std::string& folder,
                                            bool figures);

}  // namespace mcrewave
