// The results of `identify run` in its output folder (README, "Results"). Every file is
// written atomically (file_util.h; gnuplot draws to a temporary name), summary.yaml
// last, and only once everything is computed: a reader never sees a half-written file
// and a failed run leaves none behind.
//
//   summary.yaml        identified_modulus [Pa], reference_modulus and relative_error
//                       (null for CSV data), cost e^2 [J s], evaluations, sweeps,
//                       wall_time_s, the uncertainty figure, optimiser and inner-solver
//                       totals (inner.method: the solver that ran, auto resolved), the
//                       weights, the cost curve's extent, the resolved config and the
//                       version
//   evaluations.csv     the optimiser's evaluations: E, e^2, de^2/dE, inner solve
//   cost_curve.csv      e^2(E) and de^2/dE around the identified E
//   scan.csv            the global scan's cost and gradient (outer.scan_points > 0), of
//                       e^2 or the search functional (summary.yaml scan.functional)
//   valleys.csv         every valley the scan saw (docs/global_search.md)
//   ends.csv            measured and model end displacements and forces at the
//                       identified E (the run's model_channels: F_L = fL~ - W_L / alpha;
//                       at x = 0 the clamp's load or reaction)
//   inner_residual.csv  relative residual per inner iteration of a solve from W = 0 at
//                       the identified E (direct solvers: their final residual)
//   error_map.csv       each element's share of the constitutive gap at the identified
//                       E, and error_map_spacetime.dat its space-time density
//                       (mcre/error_map.h)
//   zones.csv, ...      with zones, WriteZoneResults' files (zone_identification_run.h),
//                       and summary.yaml's zones: block with the zones' first-order
//                       uncertainty (BarZoneUncertainty)
//   cost_curve.png, ends.png, error_map.png, inner_residual.png (when there is a
//                       residual to draw): with figures (gnuplot, pngcairo)
#pragma once

#include <string>
#include <vector>

#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/matrix_identification_run.h"

namespace mcrewave {

// The text of summary.yaml. Precondition: run.IsUsable().
std::string SummaryYaml(const IdentificationRun& run);

// Writes the files above into `folder` (created if needed) and returns their
// paths. Without gnuplot on the PATH, or when gnuplot fails, the figures are
// skipped with a warning; the CSV files and the summary are still written.
// Throws std::runtime_error naming the file that cannot be written.
// Precondition: run.IsUsable().
std::vector<std::string> WriteIdentificationResults(const IdentificationRun& run,
                                                    const std::string& folder, bool figures);

// With outer.functional: least_squares (run.least_squares), SummaryYaml and
// WriteIdentificationResults write instead:
//   summary.yaml     identified_modulus, reference and relative error, J [s], the
//                    uncertainty 1 / sqrt(d^2J/dE^2) and the noise levels, the
//                    optimizer, scan and prefilter blocks as above, the config
//   scan.csv, valleys.csv   as above, of J
//   cost_curve.csv   J(E) and dJ/dE over E* +- 5 %
//   fit.csv          measured and predicted uL, f0 and interior sensors at E*
//   cost_curve.png, fit.png
//   zones.csv, moduli.csv, moduli.png and summary.yaml's `zones:` block (functional
//                    least_squares, costs J [s]) when the identification has zones
//                    (zone_identification_run.h)
// written in the same way (atomically, summary last).

// With model.kind: matrix (app/matrix_identification_run.h), SummaryYaml and
// WriteIdentificationResults write instead:
//   summary.yaml        the model (manifest, dofs, zones, channels), the data; with the
//                       homogeneous stage (zones of one nominal modulus) the bar's
//                       headline keys of E* (identified_modulus, cost, evaluations,
//                       sweeps) and its optimizer:, scan:, inner: and (one zone)
//                       cost_curve: blocks; the element map's peak at both moduli
//                       (error_map:), the zones' uncertainty, the pre-filter, and the
//                       zones: block in the bar's layout (the zones' minimiser, the
//                       penalty's weight and its choice, the merging, e^2 at the
//                       zone, homogeneous and nominal moduli, J_rest, and per zone its
//                       nominal, identified and (synthetic data) truth modulus and its
//                       share of the constitutive gap at the nominal and the identified
//                       moduli), the resolved config
//   zones.csv           the same per zone
//   zone_evaluations.csv  every evaluation of the zones' minimisations (each weight of the
//                       penalty's and the merges' refits): the zone moduli [Pa],
//                       e^2 / J_rest, usable, |gradient|
//   evaluations.csv, scan.csv, valleys.csv, inner_residual.csv, cost_curve.png (and,
//                       with one zone, cost_curve.csv): the homogeneous stage's, in the
//                       bar's layout
//   fit.csv             t, the loads and the sensors as used (pre-filtered), and each
//                       sensor as the identified model driven by the loads gives it
//   error_map_dofs.csv  the constitutive gap per dof [J s] at the nominal and the
//                       identified moduli (MatrixMcreProblem::DofErrorMap)
//   error_map.csv       with element blocks: the gap per element (mcre/element_error_map.h):
//                       element, its position's coordinates x[, y[, z]] [m] when it has
//                       them, share [J s] and fraction at the identified moduli,
//                       nominal_share and nominal_fraction, zone (index); and
//                       error_map_spacetime.dat its space-time picture at the identified
//                       moduli (gnuplot's nonuniform matrix over the first coordinate,
//                       densities in J per element)
//   zones.png, fit.png  moduli and error shares per zone; the first six sensors
// written in the same way (atomically, summary last). By least squares
// (run.least_squares): summary.yaml says `functional: least_squares`, with J,
// J_rest [s] and the misfit levels in place of e^2 and the inner solver; zones.csv
// has its error-map columns empty; no error_map_dofs.csv; zones.png the moduli alone.

}  // namespace mcrewave
