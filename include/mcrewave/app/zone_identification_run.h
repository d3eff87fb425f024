// The identification of zone moduli within `identify run` (docs/zones_and_sensors.md,
// "Identification of zone moduli"): after the scalar identification, from its
// homogeneous E*, every zone modulus at once (identification/zone_identification.h; by the
// MCRE, with a trusted clamp measured when the data hold u0, or by output-error least
// squares with outer.functional: least_squares), and its
// outputs: the `zones:` block of summary.yaml, zones.csv and the figure moduli.png of
// E(x) (a step plot) against the truth's E(x) when the data are synthetic.
#pragma once

#include <string>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/model/bar_model.h"
#include "mcrewave/identification/zone_identification.h"

namespace mcrewave {

struct IdentificationRun;

struct ZoneIdentificationRun {
  bool ran = false;  // false: one zone, nothing done (the scalar result stands alone)
  ZoneLayout layout;
  ZoneIdentificationSummary summary;
  // The clamp's treatment the zones were identified with: mcre.clamp, or measured
  // (zone_identification.measured_clamp).
  ClampModel clamp = ClampModel::kMeasured;
  // Synthetic data: the truth's modulus per element of the identification's mesh
  // [Pa] (BarProperties.modulus, the truth zones over it, in series where an
  // element is cut); empty for CSV data.
  Vector truth_element_moduli;
};

// The zone layout of the identification: Config::zones (model.zoning, model.zone_count,
// model.zone_boundaries). More than one zone runs the zone identification.
ZoneLayout IdentificationZoneLayout(const Config& config);
// The truth zones of synthetic data over model.modulus (data.truth_zones); empty for
// CSV data.
std::vector<ModulusZone> TruthZones(const Config& config);

// Runs the zone identification when the layout has more than one zone on
// config.model (else returns ran = false), with a trusted clamp measured
// (MeasuredSupportConfig) when zone_identification.measured_clamp and the data hold u0:
// from scalar.identified_modulus() within
// [outer.lower_bound, outer.upper_bound], on scalar.data (pre-filtered as the scalar
// run saw them), noise levels scalar.estimated_noise for the discrepancy target,
// warm-started from scalar.solution when the clamp's treatment is the scalar run's.
// truth_zones: as TruthZones (synthetic data only).
// Precondition: scalar.IsUsable(), layout.Validate(config.model) empty.
ZoneIdentificationRun RunZoneIdentification(const Config& config, const ZoneLayout& layout,
                                            const IdentificationRun& scalar,
                                            const std::vector<ModulusZone>& truth_zones);

// The same with outer.functional: least_squares: the zones by output-error least
// squares (IdentifyZoneModuliByLeastSquares) from scalar.identified_modulus(), on
// scalar.data with its misfit levels scalar.misfit_levels, the discrepancy target from
// scalar.estimated_noise. Precondition: scalar.IsUsable(), the layout valid.
ZoneIdentificationRun RunLeastSquaresZoneIdentification(
    const Config& config, const ZoneLayout& layout, const IdentificationRun& scalar,
    const std::vector<ModulusZone>& truth_zones);

// The lines of summary.yaml's `zones:` block (indented, no trailing newline per line).
std::vector<std::string> ZonesYamlLines(const ZoneIdentificationRun& run);
// zones.csv in the layout of app/zones_csv.h: each zone's extent, its start E* as the
// nominal modulus, and the truth's modulus (its elements in series,
// ZoneModuliInSeries; empty when unknown).
std::string ZonesCsv(const ZoneIdentificationRun& run, const BarProperties& bar);
// Writes zones.csv (and moduli.png with figures) into folder; returns the paths written.
std::vector<std::string> WriteZoneResults(const ZoneIdentificationRun& run,
                                          const BarProperties& bar, const std::string& folder,
                                          bool figures);

}  // namespace mcrewave
