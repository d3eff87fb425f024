#include "mcrewave/app/comparator_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "app/run_journal.h"
#include "app/study_internal.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/app/study.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/data/noise.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/least_squares/output_error_modulus_objective.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/simulation.h"
#include "mcrewave/optim/identification.h"

namespace mcrewave {
namespace {

using internal::Brief;
using internal::Csv;
using internal::Percent;
using internal::SnrText;

constexpr double kDensityError = 1.03;      // the model's density / the bar's
constexpr double kForceGain = 1.05;         // measured fL / true fL
constexpr double kDisplacementGain = 1.03;  // measured uL / true uL
constexpr double kSoftZoneFactor = 0.9;     // E over the soft zone / E
constexpr double kSoftZoneLength = 0.1;     // its length / L, from the clamp

// The clamp's spring k_s / (E S / L) of a support_* model error; 0 for another error.
double SupportStiffnessFactor(const std::string& model_error) {
  if (model_error == "support_50") return 50.0;
  if (model_error == "support_10") return 10.0;
  if (model_error == "support_5") return 5.0;
  return 0.0;
}

struct DataSet {
  std::string model_error;
  double snr;
  std::uint64_t seed;
};

std::vector<DataSet> DataSets(const StudyOptions& options) {
  std::vector<DataSet> sets;
  for (const std::string& error : options.comparator.errors) {
    for (const double snr : options.comparator.snr) {
      const int seeds = std::isinf(snr) ? 1 : options.comparator.seeds;
      for (int seed = 1; seed <= seeds; ++seed) {
        sets.push_back({error, snr, std::isinf(snr) ? 0u : static_cast<std::uint64_t>(seed)});
      }
    }
  }
  return sets;
}

// One identification of `functional` on `data` with the model `model`.
void Identify(const Config& config, const BarModel& model, const ChannelSet& data,
              bool least_squares, ComparatorRun* run) {
  const auto start = std::chrono::steady_clock::now();
  Config one_thread = config;
  one_thread.outer.scan_threads = 1;
  IdentificationSummary summary;
  if (least_squares) {
    // s = RMS(measured) / SNR; at SNR inf the RMS alone (the weights' ratio).
    const double snr = std::isinf(run->snr) ? 1.0 : run->snr;
    NoiseLevels noise;
    noise.displacement_std = RootMeanSquare(data.Values("uL")) / snr;
    noise.force_std = RootMeanSquare(data.Values("f0")) / snr;
    const MatrixModelData matrices = BarRunModel(model, data, EndDisplacementChannels());
    OutputErrorModulusObjective objective(matrices, data, noise, config.time.theta,
                                          config.outer.initial);
    summary = mcrewave::Identify(one_thread.outer, &objective);
  } else {
    // As identify run: the search functional's scan, then mcre:'s e^2 (search:).
    const MatrixModelData matrices = BarRunModel(model, data, EndDisplacementChannels());
    summary = IdentifyWithMcre(one_thread, matrices, data).outer;
  }
  run->converged = summary.IsSolutionUsable();
  if (!run->converged) run->message = summary.message;
  run->modulus = summary.modulus;
  run->error = summary.modulus / config.model.modulus - 1.0;
  run->local_minima = summary.local_minima;
  if (summary.search_modulus > 0.0) run->search_modulus = summary.search_modulus;
  run->evaluations = summary.scan_evaluations + summary.evaluations;
  run->wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The runs of one data set, {MCRE, least squares} x `prefilters` in that order (all
// four: MCRE raw, MCRE pre-filtered, least squares raw, least squares pre-filtered).
void RunDataSet(const Config& config, const DataSet& set, const std::vector<bool>& prefilters,
                ComparatorRun* runs) {
  Config truth = config;
  truth.data.snr = set.snr;
  truth.data.seed = set.seed;
  if (set.model_error == "soft_zone") {
    truth.data.truth_zones = {
        {0.0, kSoftZoneLength * config.model.length, kSoftZoneFactor * config.model.modulus}};
  }
  // k_s = factor E S / L
  const double support_factor = SupportStiffnessFactor(set.model_error);
  if (support_factor > 0.0) {
    truth.data.support_stiffness =
        support_factor * config.model.modulus * config.model.section / config.model.length;
  }
  ChannelSet measured = MakeSyntheticMeasurements(truth.model, truth.load, truth.time, truth.data);
  if (set.model_error == "force_gain") measured.Values("fL") *= kForceGain;
  if (set.model_error == "displacement_gain") measured.Values("uL") *= kDisplacementGain;
  BarProperties identified = config.model;
  if (set.model_error == "density") identified.density *= kDensityError;
  const BarModel model(identified);
  const MatrixModelData matrices = BarRunModel(model, measured, EndDisplacementChannels());
  const int filters = static_cast<int>(prefilters.size());
  for (int k = 0; k < 2 * filters; ++k) {
    // Its case fields (functional, data, ...) are RunDataSets'.
    ComparatorRun& run = runs[k];
    PrefilterOptions prefilter = config.prefilter;
    prefilter.enabled = run.prefilter;
    const ChannelSet data = PrefilterMeasurements(measured, prefilter, nullptr);
    // The MCRE's config: the clamp tested on the raw data, as identify run tests it.
    std::vector<SupportCheck> checks;
    const Config mcre_config =
        run.least_squares
            ? config
            : ConfigForTheSupports(config, matrices, measured, data, &checks, &run.support_switched,
                                   &run.support_weight, /*log=*/false);
    if (!checks.empty()) run.support_statistic = checks.front().statistic;
    Identify(mcre_config, model, data, run.least_squares, &run);
    const double a = run.support_weight;
    if (run.least_squares || !(a > 0.0 && a < 1.0) || !run.converged) continue;
    // Both treatments weigh in E (as IdentifyHomogeneousModulusOfSupports weighs them):
    // the other one's identification, then SupportBlend::Modulus.
    ComparatorRun other = run;
    Identify(run.support_switched ? config : MeasuredSupportConfig(config), model, data,
             /*least_squares=*/false, &other);
    run.evaluations += other.evaluations;
    run.wall_time_s += other.wall_time_s;
    run.local_minima = std::max(run.local_minima, other.local_minima);
    if (!other.converged) continue;
    SupportBlend blend;
    blend.weight = a;
    blend.trusted_modulus = run.support_switched ? other.modulus : run.modulus;
    blend.measured_modulus = run.support_switched ? run.modulus : other.modulus;
    run.modulus = blend.Modulus();
    run.error = run.modulus / config.model.modulus - 1.0;
  }
}

// A matrix model's measurements of one data set: the noise-free truth plus the noise of
// (snr, seed) (AddMatrixModelNoise, as identify run adds it), then the sensor gains.
MatrixMeasurements MatrixDataSet(const MatrixModelData& model, const MatrixMeasurements& truth,
                                 const DataSet& set) {
  MatrixMeasurements measured = truth;
  AddMatrixModelNoise(model, set.snr, set.seed, &measured.histories, &measured.noise);
  for (const MatrixModelLoad& load : model.loads) {
    if (set.model_error == "force_gain") measured.histories.Values(load.channel) *= kForceGain;
  }
  for (const MatrixModelSensor& sensor : model.sensors) {
    if (set.model_error == "displacement_gain" && sensor.kind == SensorKind::kDisplacement) {
      measured.histories.Values(sensor.channel) *= kDisplacementGain;
    }
  }
  return measured;
}

// The runs of one data set on a matrix model, {MCRE, least squares} x `prefilters` x
// zones in that order (their case fields RunDataSets'): each functional as identify run identifies
// the zones (without maps or uncertainty), the model `density` times denser under that error.
void RunMatrixDataSet(const Config& config, const MatrixModelData& model,
                      const MatrixMeasurements& truth, const std::vector<double>& reference,
                      const DataSet& set, const std::vector<bool>& prefilters,
                      ComparatorRun* runs) {
  const MatrixMeasurements measured = MatrixDataSet(model, truth, set);
  MatrixModelData identified = model;
  if (set.model_error == "density") identified.mass *= kDensityError;
  const int filters = static_cast<int>(prefilters.size());
  const int zones = static_cast<int>(reference.size());
  for (int k = 0; k < 2 * filters; ++k) {
    const auto start = std::chrono::steady_clock::now();
    Config run_config = config;
    run_config.data.snr = set.snr;
    run_config.data.seed = set.seed;
    run_config.outer.functional =
        k >= filters ? OuterFunctional::kLeastSquares : OuterFunctional::kMcre;
    run_config.prefilter.enabled = prefilters[k % filters];
    const IdentificationRun run =
        RunMatrixIdentification(run_config, identified, measured, /*maps_and_uncertainty=*/false);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (int z = 0; z < zones; ++z) {
      ComparatorRun& out = runs[k * zones + z];
      out.converged = run.IsUsable();
      out.message = run.failure;
      out.evaluations = run.TotalEvaluations();
      // The valleys of the homogeneous stage's scan (-1 without the stage: no scan).
      out.local_minima = run.homogeneous_ran ? run.outer.local_minima : -1;
      if (run.homogeneous_ran && run.outer.search_modulus > 0.0) {
        out.search_modulus = run.outer.search_modulus;
      }
      out.wall_time_s = seconds;
      out.support_switched = run.support_switched;
      out.support_weight = run.support_blend.weight;
      if (!run.support_checks.empty()) out.support_statistic = run.support_checks.front().statistic;
      if (run.identified_moduli.size() == zones) {
        out.modulus = run.identified_moduli[z];
        // E_z / E_z,ref - 1
        out.error = out.modulus / reference[z] - 1.0;
      }
    }
  }
}

std::vector<ComparatorStatistics> Statistics(const ComparatorStudy& study) {
  std::vector<ComparatorStatistics> table;
  for (const std::string& error : study.model_errors) {
    for (const bool least_squares : {false, true}) {
      for (const bool prefilter : study.prefilters) {
        for (const double snr : study.snrs) {
          for (int zone = 0; zone < static_cast<int>(study.zones.size()); ++zone) {
            ComparatorStatistics row;
            row.model_error = error;
            row.zone = zone;
            row.least_squares = least_squares;
            row.prefilter = prefilter;
            row.snr = snr;
            std::vector<double> errors;
            double minima = 0.0, one_valley = 0.0, evaluations = 0.0, time = 0.0, within = 0.0,
                   switched = 0.0;
            int scanned = 0;  // runs with a global scan (a matrix model without the
                              // homogeneous stage has none)
            for (const ComparatorRun& run : study.runs) {
              if (run.model_error != error || run.zone != zone ||
                  run.least_squares != least_squares || run.prefilter != prefilter ||
                  !(run.snr == snr || (std::isinf(run.snr) && std::isinf(snr)))) {
                continue;
              }
              ++row.runs;
              if (!run.converged) continue;
              errors.push_back(run.error);
              if (run.local_minima >= 0) {
                ++scanned;
                minima += run.local_minima;
                one_valley += run.local_minima == 1 ? 1.0 : 0.0;
              }
              evaluations += run.evaluations;
              time += run.wall_time_s;
              switched += run.support_switched ? 1.0 : 0.0;
              within += std::abs(run.error) <= 0.02 ? 1.0 : 0.0;
            }
            const double n = static_cast<double>(errors.size());
            row.converged_share = row.runs > 0 ? n / row.runs : 0.0;
            if (n > 0) {
              double mean = 0.0, squares = 0.0;
              for (const double e : errors) mean += e / n;
              for (const double e : errors) squares += e * e / n;
              double variance = 0.0;
              for (const double e : errors) variance += (e - mean) * (e - mean);
              row.mean_error = mean;
              row.std_error = n > 1 ? std::sqrt(variance / (n - 1.0)) : 0.0;
              row.rms_error = std::sqrt(squares);
              row.quantile_025 = Quantile(errors, 0.025);
              row.quantile_975 = Quantile(errors, 0.975);
              // Shares over every run: a run that did not converge is not within 2 %.
              row.within_2_percent = within / row.runs;
              if (scanned > 0) {
                row.one_valley = one_valley / scanned;
                row.mean_local_minima = minima / scanned;
              }
              row.mean_evaluations = evaluations / n;
              row.mean_wall_time_s = time / n;
              row.switched_share = switched / n;
            }
            table.push_back(row);
          }
        }
      }
    }
  }
  return table;
}

std::string FunctionalText(bool least_squares) { return least_squares ? "least_squares" : "mcre"; }
std::string FilterText(bool prefilter) { return prefilter ? "prefilter" : "raw"; }

// With more than one zone the CSV files and tables name each row's zone.
bool ManyZones(const ComparatorStudy& study) { return study.zones.size() > 1; }

std::string RunsCsv(const ComparatorStudy& study) {
  const bool many = ManyZones(study);
  std::ostringstream csv;
  csv << "model_error,snr,seed,functional,data," << (many ? "zone," : "")
      << "converged,modulus_pa,relative_error,local_minima,evaluations,wall_time_s,"
         "search_modulus_pa,support_switched,support_statistic,support_weight,message\n";
  for (const ComparatorRun& run : study.runs) {
    csv << run.model_error << "," << SnrText(run.snr) << "," << run.seed << ","
        << FunctionalText(run.least_squares) << "," << FilterText(run.prefilter) << ",";
    if (many) csv << study.zones[run.zone] << ",";
    csv << (run.converged ? 1 : 0) << "," << Csv(run.modulus) << "," << Csv(run.error) << ","
        << run.local_minima << "," << run.evaluations << "," << Csv(run.wall_time_s) << ","
        << Csv(run.search_modulus) << "," << (run.support_switched ? 1 : 0) << ","
        << Csv(run.support_statistic) << "," << Csv(run.support_weight) << ",\"" << run.message
        << "\"\n";
  }
  return csv.str();
}

std::string StatisticsCsv(const ComparatorStudy& study) {
  const bool many = ManyZones(study);
  std::ostringstream csv;
  csv << "model_error,functional,data," << (many ? "zone," : "")
      << "snr,runs,converged_share,mean_error,std_error,rms_error,q2.5_error,q97.5_error,"
         "within_2_percent,one_valley,mean_local_minima,mean_evaluations,mean_wall_time_s,"
         "switched_share\n";
  for (const ComparatorStatistics& row : study.statistics) {
    csv << row.model_error << "," << FunctionalText(row.least_squares) << ","
        << FilterText(row.prefilter) << ",";
    if (many) csv << study.zones[row.zone] << ",";
    csv << SnrText(row.snr) << "," << row.runs << "," << Csv(row.converged_share) << ","
        << Csv(row.mean_error) << "," << Csv(row.std_error) << "," << Csv(row.rms_error) << ","
        << Csv(row.quantile_025) << "," << Csv(row.quantile_975) << "," << Csv(row.within_2_percent)
        << "," << Csv(row.one_valley) << "," << Csv(row.mean_local_minima) << ","
        << Csv(row.mean_evaluations) << "," << Csv(row.mean_wall_time_s) << ","
        << Csv(row.switched_share) << "\n";
  }
  return csv.str();
}

// curves.csv: one row per (model error, SNR) with the rms error of each (functional,
// data) combination, for the figure (finite SNRs only: log axis).
std::string CurvesCsv(const ComparatorStudy& study) {
  std::ostringstream csv;
  const bool many = ManyZones(study);
  const int zones = static_cast<int>(study.zones.size());
  csv << "model_error_index,snr";
  for (const bool least_squares : {false, true}) {
    for (const bool prefilter : study.prefilters) {
      for (int zone = 0; zone < zones; ++zone) {
        csv << "," << FunctionalText(least_squares) << "_" << FilterText(prefilter)
            << (many ? "_" + study.zones[zone] : std::string());
      }
    }
  }
  csv << "\n";
  for (std::size_t e = 0; e < study.model_errors.size(); ++e) {
    for (const double snr : study.snrs) {
      if (std::isinf(snr)) continue;
      csv << e << "," << Csv(snr);
      for (const bool least_squares : {false, true}) {
        for (const bool prefilter : study.prefilters) {
          for (int zone = 0; zone < zones; ++zone) {
            for (const ComparatorStatistics& row : study.statistics) {
              if (row.model_error == study.model_errors[e] && row.zone == zone &&
                  row.least_squares == least_squares && row.prefilter == prefilter &&
                  row.snr == snr) {
                csv << "," << Csv(100.0 * row.rms_error);
              }
            }
          }
        }
      }
      csv << "\n";
    }
  }
  return csv.str();
}

std::string CurvesScript(const std::string& folder, const ComparatorStudy& study) {
  const int panels = static_cast<int>(study.model_errors.size());
  const int columns = std::min(panels, 3);
  const int rows = (panels + columns - 1) / columns;
  const std::string csv = GnuplotString(folder + "/curves.csv");
  const bool many = ManyZones(study);
  const int zones = static_cast<int>(study.zones.size());
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size " << 520 * columns << ","
         << 420 * rows << "\nset datafile separator comma\nset logscale xy\nset grid\n"
         << "set xlabel 'SNR'\nset ylabel 'rms error of " << (many ? "E_z" : "E")
         << " [%]'\nset key top right\n"
         << "set multiplot layout " << rows << "," << columns
         << " title 'MCRE against output-error least squares'\n";
  std::vector<std::string> titles;  // the columns of curves.csv after model_error_index, snr
  for (const bool least_squares : {false, true}) {
    for (const bool prefilter : study.prefilters) {
      for (int zone = 0; zone < zones; ++zone) {
        titles.push_back(std::string(least_squares ? "least squares" : "MCRE") +
                         (prefilter ? ", pre-filtered" : ", raw") +
                         (many ? ", " + study.zones[zone] : std::string()));
      }
    }
  }
  for (int e = 0; e < panels; ++e) {
    std::string title = study.model_errors[e];
    std::replace(title.begin(), title.end(), '_', ' ');
    script << "set title '" << title << "'\nplot ";
    for (int c = 0; c < static_cast<int>(titles.size()); ++c) {
      // The colours of the four combinations stay the same whichever are drawn; with
      // zones, each combination and zone its own.
      const int combination = c / zones;
      const int colour =
          many ? c
               : 2 * (combination / static_cast<int>(study.prefilters.size())) +
                     (study.prefilters[combination % study.prefilters.size()] ? 1 : 0);
      script << (c > 0 ? ", " : "") << csv << " skip 1 using ($1 == " << e
             << " ? $2 : NaN):" << c + 3 << " with linespoints lw 2 pt 7 lc rgb '"
             << internal::Colour(colour) << "' title '" << titles[c] << "'";
    }
    script << "\n";
  }
  script << "unset multiplot\n";
  return script.str();
}

// What was compared, how: the bar's text, or a matrix model's.
std::string SummaryIntroduction(const ComparatorStudy& study) {
  std::ostringstream md;
  md << study.runs.size() / study.zones.size() << " identifications on " << study.threads
     << " threads in " << internal::Duration(study.wall_time_s)
     << ". The same data for both functionals, the same optimiser and bounds; ";
  if (study.matrix_model) {
    md << "on the matrix model, as identify run does it: when the zones share one nominal "
          "modulus, one E in every zone first by the global scan and refinements (for the MCRE "
          "on the search functional of search:, then e^2; on e^2 alone where the search "
          "functional is e^2 itself: no supports, search:'s w_u and w_e), its `one valley` "
          "and `valleys` of that scan; then every zone at once from E* (else from the nominal "
          "moduli, without "
          "a scan); least squares' misfit normalised by the noise of each sensor kind. Model "
          "errors: `density` the model's M 3 % larger, `force_gain` every "
          "load measured 5 % high, `displacement_gain` every displacement sensor measured 3 % "
          "high. Errors of each zone modulus relative to the truth's (E_ref: "
       << internal::NamedModuliInGpa(study.zones, study.reference_moduli)
       << "); `within 2 %` as a share of the runs.\n\n";
    return md.str();
  }
  md << "least squares: the clamped model driven by the measured fL, misfit of uL and f0 "
        "normalised by RMS(channel) / SNR, its global scan on J. "
     << (study.mcre_scans_search
             ? "The MCRE's global scan runs on the search functional (search:, the pinned "
               "clamp's e^2), then e^2 is scanned and refined within search.refine_window of "
               "its minimiser, as identify run does; its `one valley` and `valleys` are the "
               "search functional's. "
             : "The MCRE's global scan runs on e^2 itself. ")
     << "Model errors: `density` the model 3 % denser, "
        "`force_gain` fL measured 5 % high, `displacement_gain` uL measured 3 % high, "
        "`soft_zone` the bar 10 % softer over the 10 % of its length by the clamp, "
        "`support_K` the clamp a spring of K E S / L (the model's rigid). The MCRE tests the "
        "clamp on the raw data (mcre.support_check); `clamp switched` is the share of its "
        "runs that treated it as measured. Errors "
        "of E relative to the bar's modulus; `within 2 %` and `one valley` as shares of "
        "the runs.\n\n";
  return md.str();
}

std::string Summary(const ComparatorStudy& study) {
  const bool many = ManyZones(study);
  std::ostringstream md;
  md << "# MCRE against output-error least squares\n\n"
     << SummaryIntroduction(study) << "| model error | functional | data | "
     << (many ? "zone | " : "")
     << "SNR | runs | mean | std | rms | 95 % band | "
        "within 2 % | one valley | valleys | evaluations | time [s] | clamp switched |\n"
     << "|---|---|---|" << (many ? "---|" : "")
     << "---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const ComparatorStatistics& row : study.statistics) {
    md << "| " << row.model_error << " | " << FunctionalText(row.least_squares) << " | "
       << FilterText(row.prefilter) << " | ";
    if (many) md << study.zones[row.zone] << " | ";
    md << SnrText(row.snr) << " | " << row.runs << " | " << Percent(row.mean_error) << " | "
       << Percent(row.std_error) << " | " << Percent(row.rms_error) << " | ["
       << Percent(row.quantile_025) << ", " << Percent(row.quantile_975) << "] | "
       << Brief(100.0 * row.within_2_percent, 3) << " % | "
       << (std::isnan(row.one_valley) ? std::string("-") : Brief(100.0 * row.one_valley, 3) + " %")
       << " | " << Brief(row.mean_local_minima, 3) << " | " << Brief(row.mean_evaluations, 3)
       << " | " << Brief(row.mean_wall_time_s, 3) << " | "
       << (row.least_squares || many ? std::string("-")
                                     : Brief(100.0 * row.switched_share, 3) + " %")
       << " |\n";
  }
  md << "\nRatio of the rms errors, MCRE / least squares (1 or less: MCRE as accurate):\n\n"
     << "| model error | data |" << (many ? " zone |" : "");
  for (const double snr : study.snrs) md << " SNR " << SnrText(snr) << " |";
  md << "\n|---|---|" << (many ? "---|" : "");
  for (std::size_t i = 0; i < study.snrs.size(); ++i) md << "---|";
  md << "\n";
  auto rms = [&](const std::string& error, bool least_squares, bool prefilter, double snr,
                 int zone) {
    for (const ComparatorStatistics& row : study.statistics) {
      if (row.model_error == error && row.zone == zone && row.least_squares == least_squares &&
          row.prefilter == prefilter &&
          (row.snr == snr || (std::isinf(row.snr) && std::isinf(snr)))) {
        return row.rms_error;
      }
    }
    return std::nan("");
  };
  for (const std::string& error : study.model_errors) {
    for (const bool prefilter : study.prefilters) {
      for (int zone = 0; zone < static_cast<int>(study.zones.size()); ++zone) {
        md << "| " << error << " | " << FilterText(prefilter) << " |";
        if (many) md << " " << study.zones[zone] << " |";
        for (const double snr : study.snrs) {
          md << " "
             << Brief(rms(error, false, prefilter, snr, zone) /
                          rms(error, true, prefilter, snr, zone),
                      3)
             << " |";
        }
        md << "\n";
      }
    }
  }
  md << "\nFigure: comparator.png (rms error of " << (many ? "each zone modulus" : "E")
     << " against the SNR, one panel per model error).\n";
  return md.str();
}

}  // namespace

const std::vector<std::string>& ComparatorModelErrors() {
  static const std::vector<std::string> errors = {
      "none",      "density",    "force_gain", "displacement_gain",
      "soft_zone", "support_50", "support_10", "support_5"};
  return errors;
}

namespace {

// The runs of one data set (runs_per_set of them from `first`) as a journal record
// (app/run_journal.h), and back; their case fields are the study's own.
std::string EncodeDataSet(const ComparatorRun* first, int runs_per_set) {
  internal::RecordWriter record;
  for (int k = 0; k < runs_per_set; ++k) {
    const ComparatorRun& run = first[k];
    record.Add(run.converged)
        .Add(run.message)
        .Add(run.modulus)
        .Add(run.error)
        .Add(run.local_minima)
        .Add(run.search_modulus)
        .Add(run.evaluations)
        .Add(run.wall_time_s)
        .Add(run.support_switched)
        .Add(run.support_statistic)
        .Add(run.support_weight);
  }
  return record.text();
}

void DecodeDataSet(const std::string& text, int runs_per_set, ComparatorRun* first) {
  internal::RecordReader record(text);
  std::vector<ComparatorRun> runs(first, first + runs_per_set);
  for (ComparatorRun& run : runs) {
    run.converged = record.Bool();
    run.message = record.Text();
    run.modulus = record.Double();
    run.error = record.Double();
    run.local_minima = static_cast<int>(record.Integer());
    run.search_modulus = record.Double();
    run.evaluations = static_cast<int>(record.Integer());
    run.wall_time_s = record.Double();
    run.support_switched = record.Bool();
    run.support_statistic = record.Double();
    run.support_weight = record.Double();
  }
  if (!record.AtEnd()) throw std::runtime_error("the record has more fields");
  std::copy(runs.begin(), runs.end(), first);
}

// Every data set's runs, runs_per_set of them from study->runs[runs_per_set i] in the
// order {MCRE, least squares} x data x zones: run_set(i) for the sets the journal does
// not hold.
void RunDataSets(const DataSet* sets, int count, int runs_per_set,
                 const std::function<void(int)>& run_set, internal::RunJournal* journal,
                 ComparatorStudy* study, internal::Progress* progress) {
  study->runs.resize(static_cast<std::size_t>(runs_per_set) * count);
  const int filters = static_cast<int>(study->prefilters.size());
  const int zones = static_cast<int>(study->zones.size());
  for (int i = 0; i < count; ++i) {
    // The case fields, for every run (the journal restores the outcomes only).
    for (int k = 0; k < runs_per_set; ++k) {
      ComparatorRun& run = study->runs[static_cast<std::size_t>(runs_per_set) * i + k];
      run.model_error = sets[i].model_error;
      run.snr = sets[i].snr;
      run.seed = sets[i].seed;
      run.zone = k % zones;
      run.least_squares = k / zones >= filters;
      run.prefilter = study->prefilters[(k / zones) % filters];
    }
  }
  internal::ResumableParallelFor(
      count, study->threads, run_set, progress, journal,
      [&](int i) { return EncodeDataSet(&study->runs[runs_per_set * i], runs_per_set); },
      [&](int i, const std::string& record) {
        DecodeDataSet(record, runs_per_set, &study->runs[runs_per_set * i]);
      });
}

// The bar's runs of every data set, four per set (RunDataSet's order).
void RunBarComparator(const Config& config, const std::vector<DataSet>& sets,
                      internal::RunJournal* journal, ComparatorStudy* study,
                      internal::Progress* progress) {
  study->zones = {"E"};
  study->reference_moduli = {config.model.modulus};
  const int runs_per_set = 2 * static_cast<int>(study->prefilters.size());
  RunDataSets(
      sets.data(), static_cast<int>(sets.size()), runs_per_set,
      [&](int i) {
        RunDataSet(config, sets[i], study->prefilters, &study->runs[runs_per_set * i]);
      },
      journal, study, progress);
}

// A matrix model's runs: its zones, their truth (simulated once, noise-free), and the
// runs of every data set.
void RunMatrixComparator(const Config& config, const std::vector<DataSet>& sets,
                         internal::RunJournal* journal, ComparatorStudy* study,
                         internal::Progress* progress) {
  const std::string name = config.Name();
  for (const DataSet& set : sets) {
    if (set.model_error == "soft_zone" || SupportStiffnessFactor(set.model_error) > 0.0) {
      throw InputError(name + ": study.comparator.errors: " + set.model_error +
                       " (the bar softer by its clamp, or its clamp a spring) applies to the "
                       "bar only; with model.kind 'matrix' choose among none, density, "
                       "force_gain and displacement_gain");
    }
  }
  const internal::MatrixStudyTruth truth(config, "comparator");
  const MatrixModelData& model = truth.model;
  study->matrix_model = true;
  study->zones = truth.zone_names;
  study->reference_moduli = truth.reference_moduli;
  const int runs_per_set =
      2 * static_cast<int>(study->prefilters.size()) * static_cast<int>(study->zones.size());
  RunDataSets(
      sets.data(), static_cast<int>(sets.size()), runs_per_set,
      [&](int i) {
        RunMatrixDataSet(config, model, truth.measurements, study->reference_moduli, sets[i],
                         study->prefilters, &study->runs[runs_per_set * i]);
      },
      journal, study, progress);
}

}  // namespace

ComparatorStudy RunComparatorStudy(const Config& config, const std::string& journal_path) {
  if (!config.mcre.unmeasured_loads.empty()) {
    throw InputError(config.Name() +
                     ": mcre.unmeasured_loads: the comparator study runs least squares, which "
                     "needs every load measured; remove mcre.unmeasured_loads for this study");
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<DataSet> sets = DataSets(config.study);
  ComparatorStudy study;
  study.model_errors = config.study.comparator.errors;
  study.snrs = config.study.comparator.snr;
  study.mcre_scans_search = ScansTheSearchFunctional(config);
  for (const std::string& data : config.study.comparator.data) {
    study.prefilters.push_back(data == "prefilter");
  }
  study.threads = internal::ResolveThreads(config.study.threads);
  internal::Progress progress("comparator", static_cast<int>(sets.size()));
  const std::unique_ptr<internal::RunJournal> journal =
      internal::OpenStudyJournal(journal_path, config, "comparator");
  if (config.structure.kind == ModelKind::kMatrix) {
    RunMatrixComparator(config, sets, journal.get(), &study, &progress);
  } else {
    RunBarComparator(config, sets, journal.get(), &study, &progress);
  }
  study.statistics = Statistics(study);
  study.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return study;
}

std::vector<std::string> WriteComparatorResults(const ComparatorStudy& study,
                                                const std::string& folder, bool figures) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"runs.csv", RunsCsv(study)},
      {"statistics.csv", StatisticsCsv(study)},
      {"curves.csv", CurvesCsv(study)}};
  const std::vector<std::pair<std::string, std::string>> drawings = {
      {"comparator", CurvesScript(folder, study)}};
  return internal::WriteStudyFolder(folder, files, drawings, figures, Summary(study));
}

}  // namespace mcrewave
