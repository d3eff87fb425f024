// zones.csv: the identified zone moduli in one layout for every model kind (the bar's
// zone identification, a structure given by matrices), one row per zone:
//
//   zone                     index from 0
//   name                     the manifest's zone name; the bar's "zone<index>"
//   start_m, end_m           the zone's extent along the bar [m]; empty off the bar
//   nominal_modulus_pa       the zone's start: the manifest's nominal modulus, or the
//                            bar's homogeneous E* [Pa]
//   modulus_pa               the identified modulus [Pa]
//   relative_to_nominal      modulus / nominal
//   truth_modulus_pa         synthetic data: the truth's modulus of the zone (the bar:
//                            its elements in series) [Pa]; empty otherwise
//   relative_error           modulus / truth - 1; empty without a truth
//   error_share_nominal,     the zone's share of the constitutive gap at the nominal
//   error_share_identified   and at the identified moduli; empty where not computed
//   relative_gap_nominal,    the gap relative to the zone's strain energy, at the
//   relative_gap_identified  nominal and identified moduli; empty where not computed
//
// Numbers in 17 significant digits (they read back to the same double).
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace mcrewave {

// One row of zones.csv; NaN for a value that does not apply (an empty cell).
struct ZoneRow {
  std::string name;
  double start_m = NAN, end_m = NAN;
  double nominal_modulus = NAN;  // [Pa]
  double modulus = NAN;          // [Pa]
  double truth_modulus = NAN;    // [Pa]
  double error_share_nominal = NAN, error_share_identified = NAN;
  double relative_gap_nominal = NAN, relative_gap_identified = NAN;
};

// The text of zones.csv: its header, then one line per row.
std::string ZonesCsv(const std::vector<ZoneRow>& rows);

}  // namespace mcrewave
