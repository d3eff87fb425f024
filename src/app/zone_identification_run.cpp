#include "mcrewave/app/zone_identification_run.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/zones_csv.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"

namespace mcrewave {
namespace {

std::string Number(double value) { return FormatNumber(value, kTenDigitsYaml); }

// Per element: x_start, x_end, identified E, truth E (empty when unknown).
std::string ElementModuliCsv(const ZoneIdentificationRun& run, const BarModel& model) {
  std::ostringstream csv;
  csv << "element,x_start_m,x_end_m,identified_pa,truth_pa\n";
  for (int e = 0; e < model.num_elements(); ++e) {
    csv << e << "," << Number(model.node_position(e)) << "," << Number(model.node_position(e + 1))
        << "," << Number(run.summary.moduli[model.element_zone(e)]) << ","
        << (run.truth_element_moduli.size() > 0 ? Number(run.truth_element_moduli[e]) : "") << "\n";
  }
  return csv.str();
}

std::string ModuliScript(const ZoneIdentificationRun& run, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/moduli.csv");
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set title 'Identified E(x), " << run.summary.moduli.size()
         << " zones'\nset xlabel 'x [m]'\nset ylabel 'E [GPa]'\nset offsets 0, 0, graph 0.05, "
            "graph 0.05\n"
         << "plot " << csv
         << " using 2:($4*1e-9):($3-$2):(0) with vectors nohead lw 3 lc rgb '#d62728' "
            "title 'identified'";
  if (run.truth_element_moduli.size() > 0) {
    script << ", \\\n     " << csv
           << " using 2:($5*1e-9):($3-$2):(0) with vectors nohead lw 1.5 dt 2 lc rgb '#000000' "
              "title 'truth'";
  }
  script << ", \\\n     " << Number(run.summary.homogeneous_modulus * 1e-9)
         << " with lines dt 3 lc rgb '#1f77b4' title 'homogeneous E*'\n";
  return script.str();
}

}  // namespace

ZoneLayout IdentificationZoneLayout(const Config& config) { return config.zones; }

std::vector<ModulusZone> TruthZones(const Config& config) {
  if (config.data.source != DataSource::kSynthetic) return {};
  return config.data.truth_zones;
}

namespace {

// The run's layout, truth and pre-filter, and `identify` (the zones' identification on
// the zoned model with that pre-filter) when the layout has more than one zone.
template <typename Scalar, typename Identify>
ZoneIdentificationRun RunZones(const Config& config, const ZoneLayout& layout, const Scalar& scalar,
                               const std::vector<ModulusZone>& truth_zones, const char* functional,
                               Identify&& identify) {
  ZoneIdentificationRun run;
  run.layout = layout;
  const BarModel model(config.model, layout.ElementZones(config.model));
  if (model.num_zones() <= 1) return run;
  run.ran = true;
  if (scalar.reference_known) run.truth_element_moduli = ElementModuli(config.model, truth_zones);
  PrefilterOptions prefilter = config.prefilter;
  prefilter.cutoff_frequency = scalar.prefilter_cutoff;
  spdlog::info("zones: identifying {} zone moduli by {} from E* = {:.9g} Pa", model.num_zones(),
               functional, scalar.identified_modulus());
  run.summary = identify(model, prefilter);
  spdlog::info("zones: {}", run.summary.BriefReport());
  return run;
}

}  // namespace

ZoneIdentificationRun RunZoneIdentification(const Config& config, const ZoneLayout& layout,
                                            const IdentificationRun& scalar,
                                            const std::vector<ModulusZone>& truth_zones) {
  // A trusted clamp's e^2 tends to least squares, which on many zones fits the model's
  // own error with zones that oscillate; the paper's formulation keeps that error in the
  // constitutive gap and meets the noise's level (docs/boundaries.md section 8). Its
  // fields differ from the scalar run's: no warm start then.
  const Config zone_config = ConfigForTheZones(config, scalar.ends.u0);
  const bool measured = zone_config.mcre.clamp != config.mcre.clamp;
  ZoneIdentificationRun run = RunZones(
      config, layout, scalar, truth_zones,
      measured ? "the MCRE with the clamp measured" : "the MCRE",
      [&](const BarModel& model, const PrefilterOptions& prefilter) {
        ZoneIdentificationSummary summary = IdentifyZoneModuli(
            config.zone_identification, BarRunModel(model, scalar.data, scalar.ends), scalar.data,
            zone_config.mcre, config.time.theta, config.inner, scalar.identified_modulus(),
            config.outer.lower_bound, config.outer.upper_bound, scalar.estimated_noise, prefilter,
            measured ? nullptr : &scalar.solution.WarmStart());
        SetBarZoneExtents(model, &summary);
        return summary;
      });
  run.clamp = zone_config.mcre.clamp;
  return run;
}

ZoneIdentificationRun RunLeastSquaresZoneIdentification(
    const Config& config, const ZoneLayout& layout, const IdentificationRun& scalar,
    const std::vector<ModulusZone>& truth_zones) {
  return RunZones(config, layout, scalar, truth_zones, "output-error least squares",
                  [&](const BarModel& model, const PrefilterOptions& prefilter) {
                    ZoneIdentificationSummary summary = IdentifyZoneModuliByLeastSquares(
                        config.zone_identification, BarRunModel(model, scalar.data, scalar.ends),
                        scalar.data, scalar.misfit_levels, config.time.theta,
                        scalar.identified_modulus(), config.outer.lower_bound,
                        config.outer.upper_bound, scalar.estimated_noise, prefilter);
                    SetBarZoneExtents(model, &summary);
                    return summary;
                  });
}

std::vector<std::string> ZonesYamlLines(const ZoneIdentificationRun& run) {
  const ZoneIdentificationSummary& s = run.summary;
  std::vector<std::string> lines;
  auto line = [&](int indent, const std::string& key, const std::string& value,
                  const std::string& comment = "") {
    lines.push_back(std::string(2 * indent, ' ') + key + ":" + (value.empty() ? "" : " " + value) +
                    (comment.empty() ? "" : "  # " + comment));
  };
  // The cost: the MCRE's e^2 [J s], or least squares' J [s] (outer.functional).
  const std::string cost = s.least_squares ? "J" : "e^2";
  const std::string unit = s.least_squares ? "[s] " : "[J s] ";
  line(0, "zones", "", "identification of every zone modulus from the homogeneous E*");
  line(1, "functional", s.least_squares ? "least_squares" : "mcre", "outer.functional");
  if (!s.least_squares) {
    line(1, "clamp", ClampModelToString(run.clamp),
         "the clamp's treatment of the zones (zone_identification.measured_clamp)");
  }
  line(1, "count", std::to_string(s.moduli.size()));
  line(1, "termination", TerminationTypeToString(s.termination));
  line(1, "message", "\"" + s.message + "\"");
  line(1, "homogeneous_modulus", Number(s.homogeneous_modulus), "[Pa] E*, the start");
  line(1, "cost", Number(s.cost), unit + cost + " at the zone moduli");
  line(1, "homogeneous_cost", Number(s.homogeneous_cost), unit + cost + " at E* in every zone");
  line(1, "optimizer", OptimizerTypeToString(s.regularized.minimizer.optimizer));
  line(1, "algorithm", OuterAlgorithmToString(s.regularized.minimizer.algorithm));
  line(1, "regularization_weight", Number(s.regularized.weight),
       "lambda of the jump penalty on log E");
  line(1, "weight_choice", s.regularized.weight_choice);
  line(1, "target_misfit", Number(s.regularized.target_misfit),
       cost + " / J_rest the noise explains (discrepancy principle; -1: not used)");
  // The moduli reported are the merges' last refit when a merge was kept.
  const double misfit = s.merge.x.empty() ? s.regularized.misfit : s.merge.misfit;
  line(1, "misfit", Number(misfit), cost + " / J_rest at the zone moduli (merged, if any merge)");
  line(1, "misfit_floor", Number(s.regularized.misfit_floor),
       cost + " / J_rest at the grid's lightest weight when the target was missed (-1: met)");
  line(1, "floor_target", Number(s.regularized.floor_target),
       cost + " / J_rest, the floor + zone_identification.floor_margin (-1: met)");
  line(1, "weights_tried", std::to_string(s.regularized.path.size()));
  line(1, "groups", std::to_string(s.merge.groups),
       "zones left distinct by merging (-1: zone_identification.merge_zones off)");
  line(1, "merges", std::to_string(s.merge.merges), "merges kept, of " +
       std::to_string(s.merge.refits) + " refits; with any, moduli and cost are the last refit's");
  line(1, "evaluations", std::to_string(s.evaluations));
  line(1, "sweeps", std::to_string(s.sweeps));
  line(1, "wall_time_s", Number(s.wall_time_s));
  std::string on_bounds = "[";
  for (std::size_t i = 0; i < s.zones_on_bounds.size(); ++i) {
    on_bounds += (i == 0 ? "" : ", ") + std::to_string(s.zones_on_bounds[i]);
  }
  line(1, "zones_on_bounds", on_bounds + "]");
  line(1, "moduli", "", "per zone: index, start and end [m], modulus [Pa], modulus / E*");
  for (Eigen::Index z = 0; z < s.moduli.size(); ++z) {
    lines.push_back("    - {index: " + std::to_string(z) + ", start: " + Number(s.zone_start[z]) +
                    ", end: " + Number(s.zone_end[z]) + ", modulus: " + Number(s.moduli[z]) +
                    ", relative: " + Number(s.moduli[z] / s.homogeneous_modulus) + "}");
  }
  return lines;
}

std::string ZonesCsv(const ZoneIdentificationRun& run, const BarProperties& bar) {
  const BarModel model(bar, run.layout.ElementZones(bar));
  const ZoneIdentificationSummary& s = run.summary;
  // The truth's modulus of a zone: its elements in series.
  const std::vector<double> truth = run.truth_element_moduli.size() > 0
                                        ? ZoneModuliInSeries(model, run.truth_element_moduli)
                                        : std::vector<double>{};
  std::vector<ZoneRow> rows(static_cast<std::size_t>(s.moduli.size()));
  for (std::size_t z = 0; z < rows.size(); ++z) {
    ZoneRow& row = rows[z];
    row.name = "zone" + std::to_string(z);
    row.start_m = s.zone_start[z];
    row.end_m = s.zone_end[z];
    row.nominal_modulus = s.homogeneous_modulus;
    row.modulus = s.moduli[static_cast<Eigen::Index>(z)];
    if (!truth.empty()) row.truth_modulus = truth[z];
  }
  return ZonesCsv(rows);
}

std::vector<std::string> WriteZoneResults(const ZoneIdentificationRun& run,
                                          const BarProperties& bar, const std::string& folder,
                                          bool figures) {
  std::vector<std::string> written;
  if (!run.ran || run.summary.moduli.size() == 0) return written;
  const BarModel model(bar, run.layout.ElementZones(bar));
  WriteFileAtomically(folder + "/zones.csv", ZonesCsv(run, bar));
  written.push_back(folder + "/zones.csv");
  WriteFileAtomically(folder + "/moduli.csv", ElementModuliCsv(run, model));
  written.push_back(folder + "/moduli.csv");
  if (figures) {
    bool gnuplot_missing = false;
    const std::string why =
        DrawGnuplotFigure(folder, "moduli", ModuliScript(run, folder), &gnuplot_missing);
    if (why.empty()) {
      written.push_back(folder + "/moduli.png");
    } else if (!gnuplot_missing) {
      spdlog::warn("figure moduli.png skipped: {}", why);
    }
  }
  return written;
}

}  // namespace mcrewave
