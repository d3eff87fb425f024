#include "mcrewave/app/damage_study.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "app/run_journal.h"
#include "app/study_internal.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/zone_identification_run.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/least_squares/matrix_output_error_objective.h"
#include "mcrewave/mcre/element_error_map.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/regularization.h"

namespace mcrewave {
namespace {

using internal::Brief;
using internal::Csv;
using internal::Percent;
using internal::SnrText;

constexpr int kEqualZones = 10;

struct DamageCase {
  int truth;
  bool interior_sensors;
  double snr;
  std::uint64_t seed;
  bool per_element;
};

// The grid (truth, sensors, SNR, zoning), then the seeds 2..study.damage.seeds of the soft
// truth with the interior sensors at SNR 10 and 10 zones (seed 1 is in the grid when
// 10 is one of the SNRs).
std::vector<DamageCase> Cases(const StudyOptions& options) {
  std::vector<DamageCase> cases;
  for (int truth = 0; truth < static_cast<int>(DamageTruths().size()); ++truth) {
    for (bool interior : {false, true}) {
      for (double snr : options.damage.snr) {
        for (bool per_element : {false, true}) {
          cases.push_back({truth, interior, snr, std::isinf(snr) ? 0u : 1u, per_element});
        }
      }
    }
  }
  for (int seed = 2; seed <= options.damage.seeds; ++seed) {
    cases.push_back({0, true, 10.0, static_cast<std::uint64_t>(seed), false});
  }
  return cases;
}

std::vector<ModulusZone> ScaledTruth(const DamageTruth& truth, double reference) {
  std::vector<ModulusZone> zones = truth.zones;
  for (ModulusZone& zone : zones) zone.modulus *= reference;
  return zones;
}

// The config of one run: the user's with the case's truth, sensors, noise and zoning.
Config RunConfig(const Config& config, const DamageCase& damage) {
  Config run_config = config;
  run_config.outer.scan_threads = 1;
  run_config.data.truth_zones = ScaledTruth(DamageTruths()[damage.truth], config.model.modulus);
  run_config.data.sensors =
      damage.interior_sensors ? DamageInteriorSensors() : std::vector<std::string>{};
  run_config.data.channels.clear();
  run_config.data.snr = damage.snr;
  run_config.data.seed = damage.seed;
  run_config.zones = ZoneLayout();
  run_config.zones.zoning = damage.per_element ? Zoning::kPerElement : Zoning::kEqual;
  if (!damage.per_element) run_config.zones.zone_count = kEqualZones;
  // Merging costs up to zones^2 / 2 refits: minutes for 10 zones, hours for one per element.
  run_config.zone_identification.merge_zones =
      config.zone_identification.merge_zones && !damage.per_element;
  return run_config;
}

// The comparator of the run's zones: the same zones, from the same E*, with the same
// options, by output-error least squares on the same (pre-filtered) data, its
// misfit normalised by LeastSquaresMisfitLevels and its discrepancy target from the
// noise levels the MCRE's target uses.
void FitLeastSquaresZones(const Config& config, const ChannelSet& measured,
                          const IdentificationRun& scalar, const BarModel& zoned,
                          const std::vector<double>& truth_moduli, DamageLeastSquaresFit* fit) {
  fit->ran = true;
  std::string source;
  const NoiseLevels misfit_levels =
      LeastSquaresMisfitLevels(config, measured, scalar.data, &source);
  PrefilterOptions prefilter = config.prefilter;
  prefilter.cutoff_frequency = scalar.prefilter_cutoff;
  const MatrixModelData zoned_matrices = BarRunModel(zoned, scalar.data, scalar.ends);
  const ZoneIdentificationSummary summary = IdentifyZoneModuliByLeastSquares(
      config.zone_identification, zoned_matrices, scalar.data, misfit_levels, config.time.theta,
      scalar.identified_modulus(), config.outer.lower_bound, config.outer.upper_bound,
      scalar.estimated_noise, prefilter);
  fit->evaluations = summary.evaluations;
  fit->groups = summary.merge.groups;
  fit->wall_time_s = summary.wall_time_s;
  if (!summary.IsSolutionUsable() || summary.moduli.size() == 0) {
    fit->message = "least-squares zones: " + summary.message;
    return;
  }
  fit->moduli.assign(summary.moduli.data(), summary.moduli.data() + summary.moduli.size());
  MatrixOutputErrorObjective reference(zoned_matrices, scalar.data, misfit_levels,
                                       config.time.theta, Factorization::kAutomatic,
                                       scalar.identified_modulus());
  const Vector truth = Eigen::Map<const Vector>(truth_moduli.data(), truth_moduli.size());
  fit->reference_cost_ratio = reference.Cost(truth, nullptr) / summary.cost;
  fit->weakest_zone = static_cast<int>(std::min_element(fit->moduli.begin(), fit->moduli.end()) -
                                       fit->moduli.begin());
  fit->max_zone_error = 0.0;
  for (std::size_t z = 0; z < fit->moduli.size(); ++z) {
    fit->max_zone_error =
        std::max(fit->max_zone_error, std::abs(fit->moduli[z] / truth_moduli[z] - 1.0));
  }
  fit->converged = true;
}

// The run's case: its truth, sensors, SNR, seed and zoning.
void AssignCase(const DamageCase& damage, DamageRun* run) {
  run->truth = damage.truth;
  run->interior_sensors = damage.interior_sensors;
  run->snr = damage.snr;
  run->seed = damage.seed;
  run->per_element = damage.per_element;
}

void RunOne(const Config& config, const DamageCase& damage, DamageRun* run) {
  const auto start = std::chrono::steady_clock::now();
  AssignCase(damage, run);
  const Config run_config = RunConfig(config, damage);
  assert(ConfigProblem(run_config).empty());  // CheckDamageStudyConfig

  const ChannelSet measured = MakeSyntheticMeasurements(run_config.model, run_config.load,
                                                        run_config.time, run_config.data);
  IdentificationRun scalar = IdentifyModulus(run_config, measured);
  // The scalar identification's coupled solves: its scans' and search's (on copies of
  // the objective and on the search functional) and those the objective recorded.
  run->evaluations = scalar.outer.scan_evaluations + static_cast<int>(scalar.evaluations.size());
  if (!scalar.IsUsable()) {
    run->message = "scalar identification: " + scalar.outer.message;
    return;
  }
  run->homogeneous_modulus = scalar.identified_modulus();
  // The error map at E* (mcre/element_error_map.h), on the exported bar's elements,
  // which are the bar's.
  const BarModel uniform(run_config.model);
  const Vector shares =
      scalar.solution.has_fields()
          ? MatrixElementGapShares(*scalar.model, Vector::Constant(1, run->homogeneous_modulus),
                                   scalar.solution.retrograde, run_config.time.step)
          : scalar.solution.element_error_map;  // a streaming solve's, per element
  Eigen::Index peak = 0;
  shares.maxCoeff(&peak);
  run->error_map_peak = uniform.element_midpoint(static_cast<int>(peak));

  scalar.estimated_noise = DifferenceNoiseLevels(measured);
  const ZoneIdentificationRun zones =
      RunZoneIdentification(run_config, run_config.zones, scalar, run_config.data.truth_zones);
  const ZoneIdentificationSummary& summary = zones.summary;
  run->evaluations += summary.evaluations;
  run->regularization_weight = summary.regularized.weight;
  run->groups = summary.merge.groups;
  if (!summary.IsSolutionUsable() || summary.moduli.size() == 0) {
    run->message = "zone identification: " + summary.message;
    return;
  }
  const BarModel zoned(run_config.model, run_config.zones.ElementZones(run_config.model));
  run->zone_start = summary.zone_start;
  run->zone_end = summary.zone_end;
  run->moduli.assign(summary.moduli.data(), summary.moduli.data() + summary.moduli.size());
  run->truth_moduli =
      ZoneModuliInSeries(zoned, ElementModuli(run_config.model, run_config.data.truth_zones));
  run->weakest_zone = static_cast<int>(std::min_element(run->moduli.begin(), run->moduli.end()) -
                                       run->moduli.begin());
  run->max_zone_error = 0.0;
  for (std::size_t z = 0; z < run->moduli.size(); ++z) {
    run->max_zone_error =
        std::max(run->max_zone_error, std::abs(run->moduli[z] / run->truth_moduli[z] - 1.0));
  }
  run->converged = true;
  run->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!damage.per_element) {
    // e^2 at the truth's zone moduli in series, on the data and zones of the run.
    const MatrixModelData zoned_matrices = BarRunModel(zoned, scalar.data, scalar.ends);
    McreObjective reference =
        MatrixMcreObjective(zoned_matrices, scalar.data, run_config.mcre, run_config.time.theta,
                            run_config.inner, Factorization::kAutomatic, run->homogeneous_modulus);
    const ObjectiveEvaluation& record = reference.EvaluateModuli(
        Eigen::Map<const Vector>(run->truth_moduli.data(), run->truth_moduli.size()), false);
    if (record.usable) run->reference_cost_ratio = record.cost / summary.cost;
    FitLeastSquaresZones(run_config, measured, scalar, zoned, run->truth_moduli,
                         &run->least_squares);
  }
}

std::string SensorsText(bool interior) { return interior ? "interior" : "ends"; }
std::string ZoningText(bool per_element) { return per_element ? "per_element" : "10_equal"; }

std::string RunsCsv(const DamageStudy& study) {
  std::ostringstream csv;
  csv << "run,truth,sensors,snr,seed,zoning,converged,homogeneous_modulus_pa,error_map_peak_m,"
         "weakest_zone_start_m,weakest_zone_end_m,weakest_ratio,max_zone_error,"
         "regularization_weight,groups,evaluations,wall_time_s,message,reference_cost_ratio,"
         "ls_converged,ls_weakest_zone_start_m,ls_weakest_ratio,ls_max_zone_error,ls_groups,"
         "ls_reference_cost_ratio,ls_evaluations,ls_wall_time_s,ls_message\n";
  for (std::size_t i = 0; i < study.runs.size(); ++i) {
    const DamageRun& run = study.runs[i];
    const bool zones = run.converged && run.weakest_zone >= 0;
    csv << i << "," << DamageTruths()[run.truth].name << "," << SensorsText(run.interior_sensors)
        << "," << SnrText(run.snr) << "," << run.seed << "," << ZoningText(run.per_element) << ","
        << (run.converged ? 1 : 0) << "," << Csv(run.homogeneous_modulus) << ","
        << Csv(run.error_map_peak) << "," << (zones ? Csv(run.zone_start[run.weakest_zone]) : "")
        << "," << (zones ? Csv(run.zone_end[run.weakest_zone]) : "") << ","
        << (zones ? Csv(run.moduli[run.weakest_zone] / study.reference_modulus) : "") << ","
        << Csv(run.max_zone_error) << "," << Csv(run.regularization_weight) << "," << run.groups
        << "," << run.evaluations << "," << Csv(run.wall_time_s) << ",\"" << run.message << "\","
        << Csv(run.reference_cost_ratio) << ",";
    // The least-squares columns: empty where it did not run (one zone per element).
    const DamageLeastSquaresFit& fit = run.least_squares;
    const bool fitted = fit.converged && fit.weakest_zone >= 0;
    if (fit.ran) csv << (fit.converged ? 1 : 0);
    csv << "," << (fitted ? Csv(run.zone_start[fit.weakest_zone]) : "") << ","
        << (fitted ? Csv(fit.moduli[fit.weakest_zone] / study.reference_modulus) : "") << ","
        << (fit.ran ? Csv(fit.max_zone_error) : "") << ","
        << (fit.ran ? std::to_string(fit.groups) : "") << ","
        << (fit.ran ? Csv(fit.reference_cost_ratio) : "") << ","
        << (fit.ran ? std::to_string(fit.evaluations) : "") << ","
        << (fit.ran ? Csv(fit.wall_time_s) : "") << ",\"" << fit.message << "\"\n";
  }
  return csv.str();
}

std::string ZonesCsvOf(const DamageStudy& study) {
  std::ostringstream csv;
  csv << "run,zone,start_m,end_m,modulus_pa,truth_pa,ratio_to_reference,truth_ratio,"
         "ls_modulus_pa\n";
  for (std::size_t i = 0; i < study.runs.size(); ++i) {
    const DamageRun& run = study.runs[i];
    for (std::size_t z = 0; z < run.moduli.size(); ++z) {
      csv << i << "," << z << "," << Csv(run.zone_start[z]) << "," << Csv(run.zone_end[z]) << ","
          << Csv(run.moduli[z]) << "," << Csv(run.truth_moduli[z]) << ","
          << Csv(run.moduli[z] / study.reference_modulus) << ","
          << Csv(run.truth_moduli[z] / study.reference_modulus) << ","
          << (z < run.least_squares.moduli.size() ? Csv(run.least_squares.moduli[z]) : "") << "\n";
    }
  }
  return csv.str();
}

// The run of the grid with these settings (seed 1, or 0 at SNR inf), or -1.
int FindRun(const DamageStudy& study, int truth, bool interior, double snr, bool per_element) {
  for (std::size_t i = 0; i < study.runs.size(); ++i) {
    const DamageRun& run = study.runs[i];
    if (run.truth == truth && run.interior_sensors == interior && run.per_element == per_element &&
        (run.snr == snr || (std::isinf(run.snr) && std::isinf(snr))) && run.seed <= 1) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

// A profile's curve: the run (-1: absent) and whether its moduli are least squares'.
struct ProfileCurve {
  int run;
  bool least_squares;
};

// profile_<truth>.csv: x and E(x) / E_ref of the truth and of the curves (NaN when
// absent), sampled at 1000 points.
std::string ProfileCsv(const DamageStudy& study, int truth, const std::vector<ProfileCurve>& runs,
                       double length) {
  std::ostringstream csv;
  csv << "x_m,truth";
  for (std::size_t r = 0; r < runs.size(); ++r) csv << ",run" << r;
  csv << "\n";
  const std::vector<ModulusZone> zones = DamageTruths()[truth].zones;
  for (int i = 0; i <= 1000; ++i) {
    const double x = length * i / 1000.0;
    double truth_value = 1.0;
    for (const ModulusZone& zone : zones) {
      if (x >= zone.start && x <= zone.end) truth_value = zone.modulus;
    }
    csv << Csv(x) << "," << Csv(truth_value);
    for (const ProfileCurve& curve : runs) {
      double value = std::nan("");
      if (curve.run >= 0 && study.runs[curve.run].converged) {
        const DamageRun& run = study.runs[curve.run];
        const std::vector<double>& moduli =
            curve.least_squares ? run.least_squares.moduli : run.moduli;
        for (std::size_t z = 0; z < moduli.size(); ++z) {
          if (x >= run.zone_start[z] && x <= run.zone_end[z]) {
            value = moduli[z] / study.reference_modulus;
          }
        }
      }
      csv << "," << Csv(value);
    }
    csv << "\n";
  }
  return csv.str();
}

std::string ProfilesScript(const std::string& folder, const std::vector<std::string>& labels) {
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size 1100,1200\n"
         << "set multiplot layout 3,1 title 'Identified E(x) / E_{ref} against the truth (interior "
            "sensors)'\nset xlabel 'x [m]'\nset ylabel 'E / E_{ref}'\nset grid\n"
         << "set key outside right\nset datafile separator comma\n";
  for (std::size_t t = 0; t < DamageTruths().size(); ++t) {
    const std::string csv = GnuplotString(folder + "/profile_" + DamageTruths()[t].name + ".csv");
    // noenhanced: the truths' names hold underscores, subscripts in enhanced text.
    script << "set title '" << DamageTruths()[t].name << "' noenhanced\nplot " << csv
           << " skip 1 using 1:2 with lines lw 3 lc rgb '#000000' title 'truth'";
    for (std::size_t r = 0; r < labels.size(); ++r) {
      script << ", " << csv << " skip 1 using 1:" << r + 3 << " with lines lw 2 lc rgb '"
             << internal::Colour(static_cast<int>(r)) << "' title '" << labels[r] << "'";
    }
    script << "\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

// The counts of the SNR-10 seeds of the soft truth (goal 2), for one functional.
struct SeedCounts {
  int weakest = 0, soft_within = 0, others_within = 0, converged = 0;
  double worst_soft = 0.0, worst_other = 0.0;
  void Add(const std::vector<double>& moduli, int weakest_zone,
           const std::vector<double>& truth_moduli) {
    ++converged;
    int soft = -1;  // the zone of the smallest truth
    for (std::size_t z = 0; z < truth_moduli.size(); ++z) {
      if (soft < 0 || truth_moduli[z] < truth_moduli[soft]) soft = static_cast<int>(z);
    }
    if (weakest_zone == soft) ++weakest;
    double other = 0.0;
    for (std::size_t z = 0; z < moduli.size(); ++z) {
      const double error = std::abs(moduli[z] / truth_moduli[z] - 1.0);
      if (static_cast<int>(z) == soft) {
        worst_soft = std::max(worst_soft, error);
        if (error <= 0.05) ++soft_within;
      } else {
        other = std::max(other, error);
      }
    }
    worst_other = std::max(worst_other, other);
    if (other <= 0.05) ++others_within;
  }
};

// The summary's title and the description of the runs.
void SummaryHeader(const DamageStudy& study, std::ostringstream& md) {
  md << "# Damage localisation (zones and sensors)\n\n"
     << study.runs.size() << " runs on " << study.threads << " threads in "
     << internal::Duration(study.wall_time_s)
     << ". Each run: the scalar identification (E*), the error map at E*, then every zone "
        "modulus from E* (docs/zones_and_sensors.md) and, with 10 equal zones, the same zones "
        "by output-error least squares (\"Zones: the MCRE against least squares\"). Truths: `soft` "
        "0.7 E over [0.6, 0.7] m, "
        "`non_aligned` 0.75 E over [0.63, 0.71] m, `two_zones` 0.8 E over [0.15, 0.25] m and "
        "1.15 E over [0.55, 0.65] m. Sensors: `ends` (u0, uL, f0, fL) or `interior` (the ends "
        "with u@0.25, 0.5, 0.75 and e@0.2, 0.45, 0.65, 0.9). Zone errors against the truth's "
        "modulus of each zone (its elements in series). Settings: "
     << study.settings << ".\n\n";
}

// Goal 1: noise-free, 10 zones, every zone within 1 % (the soft truth); the other
// truths beside it.
void NoiseFreeSection(const DamageStudy& study, std::ostringstream& md) {
  const double reference = study.reference_modulus;
  // The soft truth, the one the 10 equal zones represent (the goals are the soft
  // truth's); the other truths are reported beside it, with the costs that say why
  // they cannot be met.
  md << "## Noise-free, 10 zones: every zone within 1 % (soft truth)\n\n"
     << "The goals concern the soft truth, whose zone lies on the identification's zone "
        "boundaries. The other truths are reported, not judged: their boundaries fall inside "
        "the zones, which then have no single true modulus. The cost ratios are each "
        "functional's data cost (the MCRE's e^2, least squares' J) at the truth's zone moduli "
        "in series over its cost at the identified ones: far above 1, the data are better "
        "explained by other moduli than the truth's in series. Least squares: the same zones "
        "by output-error least squares, from the same E*, with the same penalty, weight rule "
        "and merging, attempted when the MCRE's zones converged; each functional's "
        "evaluations and time are its own, the costs at the truth not counted.\n\n"
     << "| truth | sensors | max zone error, MCRE | max zone error, least squares | weakest "
        "zone | E_weakest / E_ref | error map peak [m] | e^2(truth in series) / e^2(identified) "
        "| J(truth in series) / J(identified) | goal "
        "|\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (int t = 0; t < static_cast<int>(DamageTruths().size()); ++t) {
    for (bool interior : {false, true}) {
      const int i = FindRun(study, t, interior, std::numeric_limits<double>::infinity(), false);
      if (i < 0) continue;
      const DamageRun& run = study.runs[i];
      const DamageLeastSquaresFit& fit = run.least_squares;
      md << "| " << DamageTruths()[t].name << " | " << SensorsText(interior) << " | ";
      if (!run.converged) {
        md << "failed: " << run.message << " | | | | | | | " << (t == 0 ? "missed" : "none")
           << " |\n";
        continue;
      }
      md << Percent(run.max_zone_error) << " | "
         << (fit.converged ? Percent(fit.max_zone_error) : "failed") << " | ["
         << Brief(run.zone_start[run.weakest_zone]) << ", " << Brief(run.zone_end[run.weakest_zone])
         << "] | " << Brief(run.moduli[run.weakest_zone] / reference) << " | "
         << Brief(run.error_map_peak) << " | " << Brief(run.reference_cost_ratio) << " | "
         << (fit.converged ? Brief(fit.reference_cost_ratio) : "") << " | "
         << (t != 0                       ? "none: not representable"
             : run.max_zone_error <= 0.01 ? "met"
                                          : "missed")
         << " |\n";
    }
  }
}

// Goal 2: the seeds at SNR 10, for the MCRE's zones and least squares'.
void SeedsSection(const DamageStudy& study, std::ostringstream& md) {
  int seeds = 0;
  SeedCounts mcre, least_squares;
  for (const DamageRun& run : study.runs) {
    if (!(run.truth == 0 && run.interior_sensors && run.snr == 10.0 && !run.per_element)) continue;
    ++seeds;
    if (!run.converged) continue;
    mcre.Add(run.moduli, run.weakest_zone, run.truth_moduli);
    const DamageLeastSquaresFit& fit = run.least_squares;
    if (fit.converged) least_squares.Add(fit.moduli, fit.weakest_zone, run.truth_moduli);
  }
  md << "\n## SNR 10, interior sensors, 10 zones, " << seeds << " seeds (soft truth)\n\n"
     << "| functional | soft zone the weakest | soft zone within 5 % | every other zone within "
        "5 % | worst soft-zone error | worst other-zone error | converged |\n"
        "|---|---|---|---|---|---|---|\n";
  for (const auto& [name, counts] : {std::pair<const char*, const SeedCounts&>{"MCRE", mcre},
                                     {"least squares", least_squares}}) {
    md << "| " << name << " | " << counts.weakest << " / " << seeds << " | " << counts.soft_within
       << " / " << seeds << " | " << counts.others_within << " / " << seeds << " | "
       << Percent(counts.worst_soft) << " | " << Percent(counts.worst_other) << " | "
       << counts.converged << " / " << seeds << " |\n";
  }
  md << "\nGoal (the MCRE's): the soft zone the weakest in at least 19 of 20, its modulus and "
        "every other zone within 5 %.\n";
}

// Goal 3: one zone per element at SNR 20.
void PerElementSection(const DamageStudy& study, std::ostringstream& md) {
  const double reference = study.reference_modulus;
  const int per_element = FindRun(study, 0, true, 20.0, true);
  if (per_element >= 0 && study.runs[per_element].converged) {
    const DamageRun& run = study.runs[per_element];
    double inside = 0.0, outside = 0.0;
    int inside_count = 0, outside_count = 0;
    for (std::size_t z = 0; z < run.moduli.size(); ++z) {
      const double middle = 0.5 * (run.zone_start[z] + run.zone_end[z]);
      if (middle > 0.6 && middle < 0.7) {
        inside += run.moduli[z] / reference;
        ++inside_count;
      } else {
        outside += run.moduli[z] / reference;
        ++outside_count;
      }
    }
    inside /= std::max(inside_count, 1);
    outside /= std::max(outside_count, 1);
    md << "\n## One zone per element, SNR 20, interior sensors (soft truth)\n\n"
       << "Mean identified E / E_ref over [0.6, 0.7] m: " << Brief(inside)
       << " (goal: within 10 % of 0.7: " << (std::abs(inside / 0.7 - 1.0) <= 0.1 ? "met" : "missed")
       << "); elsewhere: " << Brief(outside)
       << " (goal: within 10 % of 1: " << (std::abs(outside - 1.0) <= 0.1 ? "met" : "missed")
       << "); regularisation weight " << Brief(run.regularization_weight) << ", " << run.evaluations
       << " evaluations, " << internal::Duration(run.wall_time_s) << ".\n";
  }
}

// The grid: every run (seed 1), and the figures.
void GridSection(const DamageStudy& study, std::ostringstream& md) {
  const double reference = study.reference_modulus;
  md << "\n## Every run of the grid\n\n| truth | sensors | SNR | zoning | E* / E_ref | error map "
        "peak [m] | weakest zone | E_weakest / E_ref | max zone error | evaluations | time | "
        "least squares: max zone error | evaluations | time |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const DamageRun& run : study.runs) {
    if (run.seed > 1) continue;
    md << "| " << DamageTruths()[run.truth].name << " | " << SensorsText(run.interior_sensors)
       << " | " << SnrText(run.snr) << " | " << ZoningText(run.per_element) << " | ";
    if (!run.converged) {
      md << Brief(run.homogeneous_modulus / reference) << " | " << Brief(run.error_map_peak)
         << " | failed | | | " << run.evaluations << " | | | | |\n";
      continue;
    }
    md << Brief(run.homogeneous_modulus / reference) << " | " << Brief(run.error_map_peak) << " | ["
       << Brief(run.zone_start[run.weakest_zone]) << ", " << Brief(run.zone_end[run.weakest_zone])
       << "] | " << Brief(run.moduli[run.weakest_zone] / reference) << " | "
       << Percent(run.max_zone_error) << " | " << run.evaluations << " | "
       << internal::Duration(run.wall_time_s) << " | ";
    const DamageLeastSquaresFit& fit = run.least_squares;
    if (!fit.ran) {
      md << " | | |\n";
    } else {
      md << (fit.converged ? Percent(fit.max_zone_error) : "failed") << " | " << fit.evaluations
         << " | " << internal::Duration(fit.wall_time_s) << " |\n";
    }
  }
  md << "\nFigures: profiles.png (identified E(x) against the truth with the interior sensors: "
        "10 zones noise-free (MCRE and least squares) and at SNR 10, one zone per element at "
        "SNR 20).\n";
}

std::string Summary(const DamageStudy& study) {
  std::ostringstream md;
  SummaryHeader(study, md);
  NoiseFreeSection(study, md);
  SeedsSection(study, md);
  PerElementSection(study, md);
  GridSection(study, md);
  return md.str();
}

}  // namespace

const std::vector<DamageTruth>& DamageTruths() {
  static const std::vector<DamageTruth> truths = {
      {"soft", {{0.6, 0.7, 0.7}}},
      {"non_aligned", {{0.63, 0.71, 0.75}}},
      {"two_zones", {{0.15, 0.25, 0.8}, {0.55, 0.65, 1.15}}},
  };
  return truths;
}

const std::vector<std::string>& DamageInteriorSensors() {
  static const std::vector<std::string> sensors = {"u@0.25", "u@0.5",  "u@0.75", "e@0.2",
                                                   "e@0.45", "e@0.65", "e@0.9"};
  return sensors;
}

void CheckDamageStudyConfig(const Config& config, const std::string& name) {
  for (const DamageCase& damage : Cases(config.study)) {
    const std::string problem = ConfigProblem(RunConfig(config, damage));
    if (problem.empty()) continue;
    throw InputError(name + ": study.kind damage places its truth zones and sensors in m on " +
                     "the paper's bar; its run of the " + DamageTruths()[damage.truth].name +
                     " truth with " + (damage.interior_sensors ? "interior" : "end") +
                     " sensors and " +
                     (damage.per_element ? "one zone per element" : "10 equal zones") +
                     " would fail on this config's bar: " + problem);
  }
}

namespace {

// A run's outcome as a journal record (app/run_journal.h), and back (its case fields
// are the study's own).
std::string EncodeDamageRun(const DamageRun& run) {
  const DamageLeastSquaresFit& fit = run.least_squares;
  return internal::RecordWriter()
      .Add(run.converged)
      .Add(run.message)
      .Add(run.homogeneous_modulus)
      .Add(run.error_map_peak)
      .Add(run.zone_start)
      .Add(run.zone_end)
      .Add(run.moduli)
      .Add(run.truth_moduli)
      .Add(run.weakest_zone)
      .Add(run.max_zone_error)
      .Add(run.regularization_weight)
      .Add(run.groups)
      .Add(run.reference_cost_ratio)
      .Add(run.evaluations)
      .Add(run.wall_time_s)
      .Add(fit.ran)
      .Add(fit.converged)
      .Add(fit.message)
      .Add(fit.moduli)
      .Add(fit.weakest_zone)
      .Add(fit.max_zone_error)
      .Add(fit.groups)
      .Add(fit.reference_cost_ratio)
      .Add(fit.evaluations)
      .Add(fit.wall_time_s)
      .text();
}

void DecodeDamageRun(const std::string& record, DamageRun* run) {
  internal::RecordReader in(record);
  DamageRun out = *run;
  DamageLeastSquaresFit& fit = out.least_squares;
  out.converged = in.Bool();
  out.message = in.Text();
  out.homogeneous_modulus = in.Double();
  out.error_map_peak = in.Double();
  out.zone_start = in.Doubles();
  out.zone_end = in.Doubles();
  out.moduli = in.Doubles();
  out.truth_moduli = in.Doubles();
  out.weakest_zone = static_cast<int>(in.Integer());
  out.max_zone_error = in.Double();
  out.regularization_weight = in.Double();
  out.groups = static_cast<int>(in.Integer());
  out.reference_cost_ratio = in.Double();
  out.evaluations = static_cast<int>(in.Integer());
  out.wall_time_s = in.Double();
  fit.ran = in.Bool();
  fit.converged = in.Bool();
  fit.message = in.Text();
  fit.moduli = in.Doubles();
  fit.weakest_zone = static_cast<int>(in.Integer());
  fit.max_zone_error = in.Double();
  fit.groups = static_cast<int>(in.Integer());
  fit.reference_cost_ratio = in.Double();
  fit.evaluations = static_cast<int>(in.Integer());
  fit.wall_time_s = in.Double();
  if (!in.AtEnd()) throw std::runtime_error("the record has more fields");
  *run = out;
}

}  // namespace

DamageStudy RunDamageStudy(const Config& config, const std::string& journal_path) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<DamageCase> cases = Cases(config.study);
  DamageStudy study;
  study.reference_modulus = config.model.modulus;
  study.length = config.model.length;
  study.runs.resize(cases.size());
  study.threads = internal::ResolveThreads(config.study.threads);
  std::ostringstream settings;
  settings << "clamp " << ClampModelToString(config.mcre.clamp)
           << ", w_u = " << config.mcre.weights.displacement_weight
           << ", w_f = " << config.mcre.weights.force_weight
           << ", w_e = " << config.mcre.weights.strain_weight << "; zone penalty "
           << RegularizationKindToString(config.zone_identification.regularization.kind)
           << ", its weight by the rule "
           << WeightRuleToString(config.zone_identification.regularization.weight_rule)
           << (config.zone_identification.merge_zones
                   ? "; neighbouring zones merged while a refit meets the target (10 equal zones)"
                   : "");
  study.settings = settings.str();
  internal::Progress progress("damage", static_cast<int>(cases.size()));
  const std::unique_ptr<internal::RunJournal> journal =
      internal::OpenStudyJournal(journal_path, config, "damage");
  for (std::size_t i = 0; i < cases.size(); ++i) AssignCase(cases[i], &study.runs[i]);
  internal::ResumableParallelFor(
      static_cast<int>(cases.size()), study.threads,
      [&](int i) { RunOne(config, cases[i], &study.runs[i]); }, &progress, journal.get(),
      [&](int i) { return EncodeDamageRun(study.runs[i]); },
      [&](int i, const std::string& record) { DecodeDamageRun(record, &study.runs[i]); });
  study.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

std::vector<std::string> WriteDamageResults(const DamageStudy& study, const std::string& folder,
                                            bool figures) {
  std::vector<std::pair<std::string, std::string>> files = {{"runs.csv", RunsCsv(study)},
                                                            {"zones.csv", ZonesCsvOf(study)}};
  for (int t = 0; t < static_cast<int>(DamageTruths().size()); ++t) {
    const int noise_free = FindRun(study, t, true, std::numeric_limits<double>::infinity(), false);
    const std::vector<ProfileCurve> runs = {{noise_free, false},
                                            {noise_free, true},
                                            {FindRun(study, t, true, 10.0, false), false},
                                            {FindRun(study, t, true, 20.0, true), false}};
    files.emplace_back("profile_" + DamageTruths()[t].name + ".csv",
                       ProfileCsv(study, t, runs, study.length));
  }
  const std::vector<std::pair<std::string, std::string>> drawings = {
      {"profiles", ProfilesScript(folder, {"10 zones, SNR inf", "10 zones, SNR inf, least squares",
                                           "10 zones, SNR 10", "per element, SNR 20"})}};
  return internal::WriteStudyFolder(folder, files, drawings, figures, Summary(study));
}

}  // namespace mcrewave
