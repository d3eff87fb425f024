#include "mcrewave/app/study.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "app/run_journal.h"
#include "app/study_internal.h"
#include "mcrewave/app/comparator_study.h"
#include "mcrewave/app/config.h"
#include "mcrewave/app/identification_run.h"
#include "mcrewave/app/matrix_identification_run.h"
#include "mcrewave/core/file_util.h"
#include "mcrewave/core/format.h"
#include "mcrewave/data/noise.h"
#include "mcrewave/data/prefilter.h"
#include "mcrewave/mcre/matrix_mcre_problem.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/model/simulation.h"

namespace mcrewave {
namespace internal {

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

std::string Duration(double seconds) {
  char text[64];
  const long whole = std::lround(seconds);
  if (whole >= 60) {
    std::snprintf(text, sizeof(text), "%ld min %02ld s", whole / 60, whole % 60);
  } else {
    std::snprintf(text, sizeof(text), "%ld s", whole);
  }
  return text;
}

void Progress::Restored(int runs) {
  std::lock_guard<std::mutex> lock(mutex_);
  total_ -= runs;
}

void Progress::RunDone() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++done_;
  const double elapsed = SecondsSince(start_);
  // left = elapsed / done * (total - done)
  const double left = elapsed / done_ * (total_ - done_);
  StudyProgressLogger()->info("{}: {} / {} runs, {} elapsed, about {} left", what_, done_, total_,
                              Duration(elapsed), Duration(left));
}

void ParallelFor(int count, int threads, const std::function<void(int)>& task, Progress* progress) {
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  auto worker = [&]() {
    for (int i = next++; i < count && !failed; i = next++) {
      try {
        task(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
        return;
      }
      progress->RunDone();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min(threads, count); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
  if (first_error) std::rethrow_exception(first_error);
}

void ResumableParallelFor(int count, int threads, const std::function<void(int)>& task,
                          Progress* progress, RunJournal* journal,
                          const std::function<std::string(int)>& encode,
                          const std::function<void(int, const std::string&)>& decode) {
  std::vector<int> todo;
  int restored = 0;
  for (int i = 0; i < count; ++i) {
    if (journal == nullptr) {
      todo.push_back(i);
      continue;
    }
    const auto found = journal->restored().find(i);
    if (found != journal->restored().end()) {
      try {
        decode(i, found->second);
        ++restored;
        continue;
      } catch (const std::exception&) {
        // An unreadable record: the run is run again.
      }
    }
    todo.push_back(i);
  }
  if (restored > 0) {
    StudyProgressLogger()->info("resumed {} of {} runs from {}", restored, count, journal->path());
  }
  if (progress != nullptr) progress->Restored(restored);
  ParallelFor(
      static_cast<int>(todo.size()), threads,
      [&](int k) {
        task(todo[k]);
        if (journal != nullptr) journal->Record(todo[k], encode(todo[k]));
      },
      progress);
}

// The measurements of one (SNR, seed): the noise-free truth plus white noise
// (noise.h); the truth itself at SNR inf.
ChannelSet NoisyMeasurements(const ChannelSet& truth, double snr, std::uint64_t seed) {
  ChannelSet measured = truth;
  AddMeasurementNoise(snr, seed, &measured);
  return measured;
}

MatrixStudyTruth::MatrixStudyTruth(const Config& config, const std::string& study)
    : model(LoadMatrixModel(config)) {
  Config noise_free = config;
  noise_free.data.snr = std::numeric_limits<double>::infinity();
  measurements = LoadMatrixMeasurements(noise_free, model);
  if (measurements.truth_moduli.size() != static_cast<int>(model.zones.size())) {
    throw InputError(config.Name() + ": the " + study +
                     " study needs the truth's modulus of every zone of " +
                     config.structure.manifest + ", and the truth (" +
                     (config.data.truth_manifest.empty() ? config.structure.manifest
                                                         : config.data.truth_manifest) +
                     ") lacks a zone of the same name");
  }
  for (std::size_t z = 0; z < model.zones.size(); ++z) {
    zone_names.push_back(model.zones[z].name);
    reference_moduli.push_back(measurements.truth_moduli[static_cast<int>(z)]);
  }
}

ChannelSet SimulateStudyTruth(const Config& config) {
  return SimulateTruth(config.model, config.load, config.time, config.data);
}

// The identification of one run as `identify run` does it, with the scan on
// the run's own thread; *converged when the outer loop converged inside the bounds.
IdentificationRun IdentifyOnOneThread(const Config& config, const ChannelSet& measured, double snr,
                                      std::uint64_t seed, bool* converged, std::string* message) {
  Config run_config = config;
  run_config.outer.scan_threads = 1;
  run_config.data.snr = snr;
  run_config.data.seed = seed;
  IdentificationRun run = IdentifyModulus(run_config, measured);
  *converged = run.IsUsable();
  *message = run.IsUsable() ? "" : run.outer.message;
  if (run.IsUsable()) {
    *message = ModulusOnBoundMessage(run.identified_modulus(), config.outer);
    *converged = message->empty();
  }
  return run;
}

// Noise seeds of one SNR: 1..seeds, or the single seed 0 (no noise drawn) at SNR inf.
std::vector<std::uint64_t> SeedsOf(double snr, int seeds) {
  if (std::isinf(snr)) return {0};
  std::vector<std::uint64_t> list;
  for (int seed = 1; seed <= seeds; ++seed) list.push_back(static_cast<std::uint64_t>(seed));
  return list;
}

// ---------------------------------------------------------------------------
// Text.

std::string Csv(double value) { return FormatNumber(value, kTenDigits); }

std::string Brief(double value, int digits) {
  return FormatNumber(value, {NumberFormat::Notation::kSignificant, digits, false, false, "-"});
}

std::string NamedModuliInGpa(const std::vector<std::string>& names,
                             const std::vector<double>& moduli) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : ", ") + names[i] + " " + Brief(moduli[i] / 1e9, 6) + " GPa";
  }
  return text;
}

std::string Percent(double ratio) {
  if (std::isnan(ratio)) return "-";
  return FormatNumber(100.0 * ratio, {NumberFormat::Notation::kFixed, 3, true}) + " %";
}

std::string SnrText(double snr) { return std::isinf(snr) ? "inf" : Brief(snr); }

std::vector<std::string> WriteStudyFolder(
    const std::string& folder, const std::vector<std::pair<std::string, std::string>>& files,
    const std::vector<std::pair<std::string, std::string>>& figures, bool draw,
    const std::string& summary) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw std::runtime_error("cannot create folder " + folder + ": " + error.message());
  std::vector<std::string> written;
  for (const auto& [name, content] : files) {
    WriteFileAtomically(folder + "/" + name, content);
    written.push_back(folder + "/" + name);
  }
  if (draw) {
    for (const auto& [name, script] : figures) {
      bool gnuplot_missing = false;
      const std::string why = DrawGnuplotFigure(folder, name, script, &gnuplot_missing);
      if (gnuplot_missing) {
        spdlog::warn("gnuplot not found on the PATH: figures skipped (the CSV files are written)");
        break;
      }
      if (!why.empty()) {
        spdlog::warn("figure {}/{}.png skipped: {}", folder, name, why);
        continue;
      }
      written.push_back(folder + "/" + name + ".png");
    }
  }
  WriteFileAtomically(folder + "/summary.md", summary);
  written.push_back(folder + "/summary.md");
  return written;
}

// Sampled local minima of a curve (interior points lower than both neighbours;
// NaN points break the comparison).
int LocalMinima(const std::vector<double>& values) {
  int minima = 0;
  for (std::size_t i = 1; i + 1 < values.size(); ++i) {
    if (values[i] < values[i - 1] && values[i] < values[i + 1]) ++minima;
  }
  return minima;
}

// "plot a, b, c\n": one gnuplot plot command of the given plot elements.
std::string PlotCommand(const std::vector<std::string>& plots) {
  std::string command = "plot ";
  for (std::size_t i = 0; i < plots.size(); ++i) command += (i == 0 ? "" : ", ") + plots[i];
  return command + "\n";
}

std::string Colour(int index) {
  static const char* const colours[] = {"#1f4e9c", "#d62728", "#2ca02c", "#ff7f0e",
                                        "#9467bd", "#8c564b", "#17becf", "#7f7f7f"};
  return colours[index % 8];
}

}  // namespace internal

using namespace internal;

bool StudySelected(StudyKind kind, StudyKind part) {
  return (kind == StudyKind::kAll && part != StudyKind::kDamage &&
          part != StudyKind::kComparator) ||
         kind == part;
}

bool StudyOptions::IsValid(std::string* error) const {
  std::ostringstream why;
  auto check_snr = [&](const std::vector<double>& list, const char* key) {
    if (list.empty() || list.size() > 100) {
      why << key << " must hold 1 to 100 SNRs, got " << list.size();
      return false;
    }
    for (const double snr : list) {
      if (!(snr > 0.0)) {
        why << key << " must hold SNRs > 0 (.inf: no noise), got " << snr;
        return false;
      }
    }
    return true;
  };
  if (folder.empty()) {
    why << "study.folder must name a folder";
  } else if (!(threads >= 0 && threads <= 256)) {
    why << "study.threads must lie in [0, 256] (0: every core), got " << threads;
  } else if (!check_snr(robustness.snr, "study.robustness.snr")) {
  } else if (!(robustness.seeds >= 1 && robustness.seeds <= 100000)) {
    why << "study.robustness.seeds must lie in [1, 100000], got " << robustness.seeds;
  } else if (!check_snr(relaxation.snr, "study.relaxation.snr")) {
  } else if (relaxation.moduli.empty() || relaxation.moduli.size() > 100 ||
             std::any_of(relaxation.moduli.begin(), relaxation.moduli.end(),
                         [](double f) { return !(f > 0.0 && f <= 10.0); })) {
    why << "study.relaxation.moduli must hold 1 to 100 factors of model.modulus in (0, 10]";
  } else if (!(relaxation.omega_min > 0.0 && relaxation.omega_min < relaxation.omega_max &&
               relaxation.omega_max < 2.0)) {
    why << "study.relaxation.omega_min and study.relaxation.omega_max must satisfy 0 < omega_min < "
           "omega_max < 2, got "
        << relaxation.omega_min << " and " << relaxation.omega_max;
  } else if (!(relaxation.omega_points >= 2 && relaxation.omega_points <= 1000)) {
    why << "study.relaxation.omega_points must lie in [2, 1000], got " << relaxation.omega_points;
  } else if (!(relaxation.tolerance > 0.0 && relaxation.tolerance < 1.0)) {
    why << "study.relaxation.tolerance must lie in (0, 1), got " << relaxation.tolerance;
  } else if (!check_snr(cost_curves.snr, "study.cost_curves.snr")) {
  } else if (!(cost_curves.seeds >= 1 && cost_curves.seeds <= 100000)) {
    why << "study.cost_curves.seeds must lie in [1, 100000], got " << cost_curves.seeds;
  } else if (!(cost_curves.points >= 3 && cost_curves.points <= 10000)) {
    why << "study.cost_curves.points must lie in [3, 10000], got " << cost_curves.points;
  } else if (!(cost_curves.low > 0.0 && cost_curves.low < cost_curves.high &&
               std::isfinite(cost_curves.high))) {
    why << "study.cost_curves.low and study.cost_curves.high must satisfy 0 < low < high "
           "(finite), got "
        << cost_curves.low << " and " << cost_curves.high;
  } else if (!check_snr(damage.snr, "study.damage.snr")) {
  } else if (!(damage.seeds >= 1 && damage.seeds <= 1000)) {
    why << "study.damage.seeds must lie in [1, 1000], got " << damage.seeds;
  } else if (!check_snr(comparator.snr, "study.comparator.snr")) {
  } else if (!(comparator.seeds >= 1 && comparator.seeds <= 100000)) {
    why << "study.comparator.seeds must lie in [1, 100000], got " << comparator.seeds;
  } else if (comparator.errors.empty() ||
             std::any_of(comparator.errors.begin(), comparator.errors.end(),
                         [](const std::string& name) {
                           const std::vector<std::string>& known = ComparatorModelErrors();
                           return std::find(known.begin(), known.end(), name) == known.end();
                         })) {
    why << "study.comparator.errors must hold model errors among none, density, force_gain, "
           "displacement_gain, soft_zone, support_50, support_10, support_5";
  } else if (comparator.data.empty() || comparator.data.size() > 2 ||
             std::any_of(
                 comparator.data.begin(), comparator.data.end(),
                 [](const std::string& name) { return name != "raw" && name != "prefilter"; }) ||
             (comparator.data.size() == 2 && comparator.data[0] == comparator.data[1])) {
    why << "study.comparator.data must hold raw, prefilter or both, once each";
  } else {
    return true;
  }
  if (error != nullptr) *error = why.str();
  return false;
}

std::string StudyJournalPath(const Config& config, const std::string& study) {
  return (std::filesystem::path(config.study.folder) / ("." + study + ".journal")).string();
}

void RemoveStudyJournal(const std::string& path) {
  std::error_code error;
  std::filesystem::remove(path, error);
}

std::shared_ptr<spdlog::logger> StudyProgressLogger() {
  static const std::shared_ptr<spdlog::logger> logger = [] {
    std::shared_ptr<spdlog::logger> clone = spdlog::default_logger()->clone("study");
    clone->set_level(spdlog::level::info);
    return clone;
  }();
  return logger;
}

double Quantile(std::vector<double> values, double q) {
  std::sort(values.begin(), values.end());
  const double position = q * (values.size() - 1.0);
  const std::size_t below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, values.size() - 1);
  // linear interpolation between the order statistics around q (n - 1)
  return values[below] + (position - below) * (values[above] - values[below]);
}

// ---------------------------------------------------------------------------
// Robustness.

namespace {

// Fills one run (its seed and SNR set) from the identification on its data.
using RobustnessIdentification = std::function<void(RobustnessRun* run)>;

// The runs of every (SNR, seed) of the study's lists, each identified on one thread,
// then the statistics of each SNR and parameter.
// A run's outcome as a journal record (run_journal.h), and back.
std::string EncodeRobustnessRun(const RobustnessRun& run) {
  return RecordWriter()
      .Add(run.converged)
      .Add(run.message)
      .Add(run.identified_moduli)
      .Add(run.relative_errors)
      .Add(run.evaluations)
      .Add(run.scan_evaluations)
      .Add(static_cast<std::int64_t>(run.sweeps))
      .Add(run.local_minima)
      .text();
}

void DecodeRobustnessRun(const std::string& record, RobustnessRun* run) {
  RecordReader reader(record);
  RobustnessRun decoded = *run;
  decoded.converged = reader.Bool();
  decoded.message = reader.Text();
  decoded.identified_moduli = reader.Doubles();
  decoded.relative_errors = reader.Doubles();
  decoded.evaluations = static_cast<int>(reader.Integer());
  decoded.scan_evaluations = static_cast<int>(reader.Integer());
  decoded.sweeps = reader.Integer();
  decoded.local_minima = static_cast<int>(reader.Integer());
  if (!reader.AtEnd()) throw std::runtime_error("the record has more fields");
  *run = decoded;
}

void RunRobustness(const StudyOptions& options, const RobustnessIdentification& identify,
                   RunJournal* journal, RobustnessStudy* study) {
  for (int k = 0; k < static_cast<int>(options.robustness.snr.size()); ++k) {
    const double snr = options.robustness.snr[k];
    for (const std::uint64_t seed : SeedsOf(snr, options.robustness.seeds)) {
      RobustnessRun run;
      run.snr = snr;
      run.snr_index = k;
      run.seed = seed;
      study->runs.push_back(run);
    }
  }
  StudyProgressLogger()->info(
      "robustness: {} identifications ({} SNRs, {} seeds per finite SNR) on {} threads",
      study->runs.size(), options.robustness.snr.size(), options.robustness.seeds, study->threads);
  Progress progress("robustness", static_cast<int>(study->runs.size()));
  const auto parameters = study->parameters.size();
  ResumableParallelFor(
      static_cast<int>(study->runs.size()), study->threads,
      [&](int i) {
        RobustnessRun& run = study->runs[i];
        identify(&run);
        run.identified_moduli.resize(parameters, std::numeric_limits<double>::quiet_NaN());
        run.relative_errors.assign(parameters, std::numeric_limits<double>::quiet_NaN());
        for (std::size_t p = 0; run.converged && p < parameters; ++p) {
          // relative error = (E* - E_ref) / E_ref
          run.relative_errors[p] =
              (run.identified_moduli[p] - study->reference_moduli[p]) / study->reference_moduli[p];
        }
      },
      &progress, journal, [&](int i) { return EncodeRobustnessRun(study->runs[i]); },
      [&](int i, const std::string& record) { DecodeRobustnessRun(record, &study->runs[i]); });

  for (int k = 0; k < static_cast<int>(options.robustness.snr.size()); ++k) {
    for (std::size_t p = 0; p < parameters; ++p) {
      RobustnessStatistics statistics;
      statistics.snr = options.robustness.snr[k];
      statistics.snr_index = k;
      statistics.parameter = static_cast<int>(p);
      std::vector<double> errors;
      for (const RobustnessRun& run : study->runs) {
        if (run.snr_index != k) continue;
        ++statistics.runs;
        statistics.mean_evaluations += run.evaluations;
        statistics.mean_sweeps += static_cast<double>(run.sweeps);
        if (run.converged) errors.push_back(run.relative_errors[p]);
      }
      statistics.converged = static_cast<int>(errors.size());
      statistics.converged_share = static_cast<double>(errors.size()) / statistics.runs;
      statistics.mean_evaluations /= statistics.runs;
      statistics.mean_sweeps /= statistics.runs;
      if (!errors.empty()) {
        double sum = 0.0;
        for (const double e : errors) sum += e;
        statistics.mean_error = sum / errors.size();
        // sample standard deviation: sqrt(sum (e - mean)^2 / (n - 1)); 0 for one run
        double squares = 0.0;
        for (const double e : errors)
          squares += (e - statistics.mean_error) * (e - statistics.mean_error);
        statistics.std_error = errors.size() > 1 ? std::sqrt(squares / (errors.size() - 1.0)) : 0.0;
        statistics.quantile_025 = Quantile(errors, 0.025);
        statistics.quantile_975 = Quantile(errors, 0.975);
      }
      study->statistics.push_back(statistics);
    }
  }
}

// The bar: E from the measurements of the finer truth plus each run's noise.
void RunBarRobustness(const Config& config, RunJournal* journal, RobustnessStudy* study) {
  study->parameters = {"E"};
  study->reference_moduli = {config.model.modulus};
  // The noise-free truth once; each run adds its own noise.
  const ChannelSet truth = SimulateStudyTruth(config);
  RunRobustness(
      config.study,
      [&](RobustnessRun* run) {
        const ChannelSet measured = NoisyMeasurements(truth, run->snr, run->seed);
        const IdentificationRun identification = IdentifyOnOneThread(
            config, measured, run->snr, run->seed, &run->converged, &run->message);
        const IdentificationSummary& outer = identification.outer;
        run->evaluations = outer.evaluations + outer.scan_evaluations;
        run->scan_evaluations = outer.scan_evaluations;
        run->sweeps = identification.sweeps + outer.scan_sweeps;
        run->local_minima = outer.local_minima;
        if (run->converged) run->identified_moduli = {identification.identified_modulus()};
      },
      journal, study);
}

// A matrix model: every zone modulus, without the error maps and the uncertainty, from
// the truth's outputs (data.truth_manifest at data.truth_moduli) plus each run's noise.
void RunMatrixRobustness(const Config& config, RunJournal* journal, RobustnessStudy* study) {
  const MatrixStudyTruth truth(config, "robustness");
  const MatrixModelData& model = truth.model;
  study->matrix_model = true;
  study->parameters = truth.zone_names;
  study->reference_moduli = truth.reference_moduli;
  RunRobustness(
      config.study,
      [&](RobustnessRun* run) {
        Config run_config = config;
        run_config.data.snr = run->snr;
        run_config.data.seed = run->seed;
        MatrixMeasurements measured = truth.measurements;
        AddMatrixModelNoise(model, run->snr, run->seed, &measured.histories, &measured.noise);
        const IdentificationRun identification =
            RunMatrixIdentification(run_config, model, measured, /*maps_and_uncertainty=*/false);
        run->converged = identification.IsUsable();
        run->message = identification.failure;
        run->evaluations = identification.TotalEvaluations();
        run->sweeps = identification.TotalSweeps();
        if (run->converged) {
          const Vector& moduli = identification.identified_moduli;
          run->identified_moduli.assign(moduli.data(), moduli.data() + moduli.size());
        }
      },
      journal, study);
}

}  // namespace

RobustnessStudy RunRobustnessStudy(const Config& config, const std::string& journal_path) {
  const auto start = Clock::now();
  RobustnessStudy study;
  study.threads = ResolveThreads(config.study.threads);
  const std::unique_ptr<RunJournal> journal = OpenStudyJournal(journal_path, config, "robustness");
  if (config.structure.kind == ModelKind::kMatrix) {
    RunMatrixRobustness(config, journal.get(), &study);
  } else {
    RunBarRobustness(config, journal.get(), &study);
  }
  study.wall_time_s = SecondsSince(start);
  return study;
}

namespace {

// With more than one parameter, every row of the runs and statistics names its
// parameter in a zone_index and a zone column (after snr_index and seed).
bool ManyParameters(const RobustnessStudy& study) { return study.parameters.size() > 1; }

// "a, b, c": the parameters' names.
std::string ZoneList(const RobustnessStudy& study) {
  std::string list;
  for (const std::string& name : study.parameters) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::string RobustnessRunsCsv(const RobustnessStudy& study) {
  const bool many = ManyParameters(study);
  std::ostringstream csv;
  csv << "snr,snr_index,seed,converged," << (many ? "zone_index,zone," : "")
      << "identified_modulus,relative_error,evaluations,scan_evaluations,sweeps,local_minima\n";
  for (const RobustnessRun& run : study.runs) {
    for (std::size_t p = 0; p < study.parameters.size(); ++p) {
      csv << Csv(run.snr) << "," << run.snr_index << "," << run.seed << ","
          << (run.converged ? 1 : 0) << ",";
      if (many) csv << p << "," << study.parameters[p] << ",";
      csv << Csv(run.identified_moduli[p]) << "," << Csv(run.relative_errors[p]) << ","
          << run.evaluations << "," << run.scan_evaluations << "," << run.sweeps << ","
          << run.local_minima << "\n";
    }
  }
  return csv.str();
}

std::string RobustnessStatisticsCsv(const RobustnessStudy& study) {
  const bool many = ManyParameters(study);
  std::ostringstream csv;
  csv << "snr,snr_index," << (many ? "zone_index,zone," : "")
      << "runs,converged_share,mean_error,std_error,q2.5_error,q97.5_error,"
         "mean_evaluations,mean_sweeps\n";
  for (const RobustnessStatistics& s : study.statistics) {
    csv << Csv(s.snr) << "," << s.snr_index << ",";
    if (many) csv << s.parameter << "," << study.parameters[s.parameter] << ",";
    csv << s.runs << "," << Csv(s.converged_share) << "," << Csv(s.mean_error) << ","
        << Csv(s.std_error) << "," << Csv(s.quantile_025) << "," << Csv(s.quantile_975) << ","
        << Csv(s.mean_evaluations) << "," << Csv(s.mean_sweeps) << "\n";
  }
  return csv.str();
}

std::string RobustnessScript(const RobustnessStudy& study, const std::string& folder) {
  const std::string runs = GnuplotString(folder + "/runs.csv");
  const std::string statistics = GnuplotString(folder + "/statistics.csv");
  const int zones = static_cast<int>(study.parameters.size());
  const int snrs = static_cast<int>(study.statistics.size()) / zones;
  std::ostringstream script;
  script << GnuplotPngTerminal();
  if (!ManyParameters(study)) {
    script << "set title 'Relative error of the identified E against SNR (data from the finer "
              "truth)'\n";
  } else {
    script << "set title 'Relative error of each zone modulus against SNR (each run a dot)'\n";
  }
  script << "set xlabel 'SNR'\nset ylabel '(E^* - E_{ref}) / E_{ref} [%]'\n"
         << "set xrange [-0.5:" << snrs - 0.5 << "]\n"
         << "set key top left\n"
         // every run, spread sideways by its seed (golden-ratio jitter in [-0.2, 0.2])
         << "jitter(s) = 0.4 * (s * 0.6180339887 - floor(s * 0.6180339887) - 0.5)\n";
  if (!ManyParameters(study)) {
    script << "plot " << runs
           << " skip 1 using ($2 + jitter($3)):($4 > 0 ? 100 * $6 : 1/0) with points pt 7 ps 0.6 "
              "lc rgb '#7f9fcf' title 'each run', "
           << statistics
           << " skip 1 using 2:(100 * $5):(100 * $7):(100 * $8):xtic(1) with yerrorbars pt 5 ps "
              "1.2 lw 2 lc rgb '#d62728' title 'mean and 2.5-97.5 % quantiles'\n";
    return script.str();
  }
  // Zone z of Z shifted sideways by 0.6 (z - (Z - 1) / 2) / Z, in a colour of its own;
  // runs.csv and statistics.csv carry zone_index and zone after seed / snr_index.
  script << "set key below\noffset(z) = 0.6 * (z - " << zones - 1 << " / 2.0) / " << zones << "\n"
         << "set xtics (";
  for (int k = 0; k < snrs; ++k) {
    script << (k == 0 ? "" : ", ") << "'" << SnrText(study.statistics[k * zones].snr) << "' " << k;
  }
  script << ")\nplot ";
  for (int z = 0; z < zones; ++z) {
    script << (z == 0 ? "" : ", ") << runs << " skip 1 using ($5 == " << z << " ? $2 + offset(" << z
           << ") + jitter($3) / " << zones << " : 1/0):($4 > 0 ? 100 * $8 : 1/0) with points "
           << "pt 7 ps 0.5 lc rgb '" << Colour(z) << "' notitle, " << statistics
           << " skip 1 using ($3 == " << z << " ? $2 + offset(" << z
           << ") : 1/0):(100 * $7):(100 * $9):(100 * $10) with yerrorbars pt 5 ps 1.2 lw 2 lc rgb '"
           << Colour(z) << "' title " << GnuplotString(study.parameters[z] + ": mean, 2.5-97.5 %");
  }
  script << "\n";
  return script.str();
}

// The summary's table: one row per SNR (and zone, with zones).
std::string RobustnessTable(const RobustnessStudy& study) {
  const bool many = ManyParameters(study);
  std::ostringstream md;
  md << "| SNR | " << (many ? "zone | " : "")
     << "runs | converged | mean error | std | 2.5 % | 97.5 % | evaluations | sweeps |\n"
     << "|---|" << (many ? "---|" : "") << "---|---|---|---|---|---|---|---|\n";
  for (const RobustnessStatistics& s : study.statistics) {
    md << "| " << SnrText(s.snr) << " | ";
    if (many) md << study.parameters[s.parameter] << " | ";
    md << s.runs << " | " << Brief(100.0 * s.converged_share, 4) << " % | " << Percent(s.mean_error)
       << " | " << Brief(100.0 * s.std_error, 3) << " % | " << Percent(s.quantile_025) << " | "
       << Percent(s.quantile_975) << " | " << Brief(s.mean_evaluations, 4) << " | "
       << Brief(s.mean_sweeps, 5) << " |\n";
  }
  return md.str();
}

std::string RobustnessSummary(const RobustnessStudy& study) {
  const bool many = ManyParameters(study);
  std::ostringstream md;
  md << "## Robustness (`robustness/`)\n\n";
  if (!study.matrix_model) {
    md << "`robustness.png`: the relative error (E* - E_ref) / E_ref of the identified modulus "
          "against the SNR, every run as a point and, per SNR, the mean with the 2.5-97.5 % "
          "quantile band of the converged runs. Each run is the identification of `identify "
          "run` (pre-filter, global scan, local refinement) on data from the finer truth plus "
          "white noise of one seed; at SNR inf there is one run (no noise), whose error is the "
          "discretisation bias only (model against the finer truth). `runs.csv`: one row per "
          "identification; `statistics.csv`: one row per SNR. E_ref = "
       << Brief(study.reference_moduli[0] / 1e9, 6) << " GPa.\n\n";
  } else {
    md << "`robustness.png`: the relative error (E* - E_ref) / E_ref of each zone modulus "
          "against the SNR, every run as a point and, per SNR and zone, the mean with the "
          "2.5-97.5 % quantile band of the converged runs (zones: "
       << ZoneList(study)
       << "). Each run is the identification of `identify run` on the matrix model (pre-filter, "
          "the homogeneous stage when the zones' nominal moduli agree, then every zone at once "
          "from its E*, else from the nominal moduli; no error map or uncertainty) on data of "
          "the truth plus white noise of one seed; at SNR inf there is one run (no noise), "
          "whose error is the model's bias against the truth. `runs.csv`: one row per "
          "identification and zone; `statistics.csv`: one row per SNR and zone. E_ref: "
       << NamedModuliInGpa(study.parameters, study.reference_moduli) << ".\n\n";
  }
  md << RobustnessTable(study);
  md << (study.matrix_model
             ? "\nEvaluations: evaluations of e^2 (least squares: J) by the optimiser of "
               "zone_identification:, means over all runs; sweeps: inner sweeps of those "
               "evaluations.\n\n"
             : "\nEvaluations: outer evaluations of the functionals scanned and refined (the "
               "search functional's and e^2's, the scans' included), means over all runs; "
               "sweeps: inner sweeps of those evaluations.\n\n");
  for (const RobustnessStatistics& s : study.statistics) {
    if (std::isinf(s.snr)) {
      md << "- SNR inf" << (many ? ", " + study.parameters[s.parameter] : std::string())
         << ": error " << Percent(s.mean_error) << ", the "
         << (study.matrix_model ? "model's bias against the truth" : "discretisation bias")
         << " (no noise).\n";
    }
  }
  // The lowest finite SNR: the paper's claim.
  double lowest = std::numeric_limits<double>::infinity();
  for (const RobustnessStatistics& s : study.statistics) lowest = std::min(lowest, s.snr);
  for (const RobustnessStatistics& s : study.statistics) {
    if (std::isinf(s.snr) || s.snr != lowest) continue;
    md << "- SNR " << SnrText(s.snr)
       << (many ? ", " + study.parameters[s.parameter] : std::string()) << ": " << s.converged
       << " of " << s.runs << " runs converged; mean error " << Percent(s.mean_error)
       << ", 95 % of the runs within [" << Percent(s.quantile_025) << ", "
       << Percent(s.quantile_975) << "].\n";
  }
  md << "- " << study.runs.size() << " identifications in " << Duration(study.wall_time_s) << " on "
     << study.threads << " threads.\n\n";
  return md.str();
}

}  // namespace

std::vector<std::string> WriteRobustnessResults(const RobustnessStudy& study,
                                                const std::string& folder, bool figures) {
  return WriteStudyFolder(
      folder,
      {{"runs.csv", RobustnessRunsCsv(study)}, {"statistics.csv", RobustnessStatisticsCsv(study)}},
      {{"robustness", RobustnessScript(study, folder)}}, figures, RobustnessSummary(study));
}

// ---------------------------------------------------------------------------
// Relaxation coefficient.

namespace {

// The extreme eigenvalues of A = I - G at the problem's modulus: the Lanczos
// estimate of the adaptive relaxation (coupled_solver.h) without its safety
// factor, read from the summary of an adaptive solve stopped after its first
// iteration (the estimate precedes the iteration).
std::pair<double, double> EstimateSpectrum(const CoupledSolverOptions& inner,
                                           StreamingCoupledProblem* problem) {
  CoupledSolverOptions options = inner;
  options.type = CoupledSolverType::kAdaptiveRelaxation;
  options.preconditioner = TracePreconditioner::kNone;  // the streaming CG's only
  options.spectrum_safety_factor = 1.0;
  options.max_iterations = 1;
  CoupledSolution solution;
  const CoupledSolverSummary summary = SolveCoupled(options, problem, nullptr, &solution);
  return {summary.spectrum_min, summary.spectrum_max};
}

// Iterations of the fixed relaxation to reduce the residual by `tolerance`:
// ln(tol) / ln(rho), rho = max(|1 - omega a_min|, |1 - omega a_max|) the
// contraction factor in <.,.>_P (iterations_ = ceil); -1 when rho >= 1.
int PredictedIterations(double omega, double a_min, double a_max, double tolerance) {
  const double rho = std::max(std::abs(1.0 - omega * a_min), std::abs(1.0 - omega * a_max));
  if (!(rho < 1.0)) return -1;
  if (rho == 0.0) return 1;
  return static_cast<int>(std::ceil(std::log(tolerance) / std::log(rho)));
}

// One case of the relaxation study: its spectrum estimate and omegas, the grid's
// fixed-omega solves to study.relaxation.tolerance (into *points), and the reference
// solves to inner.tolerance with their residual histories (into *histories).
void RunRelaxationCase(const Config& config, const BarModel& model, const ChannelSet& truth,
                       const std::vector<double>& omegas, int c, RelaxationCase* case_out,
                       std::vector<RelaxationPoint>* points,
                       std::vector<ResidualHistory>* histories) {
  const StudyOptions& options = config.study;
  RelaxationCase& relaxation_case = *case_out;
  const ChannelSet data = PrefilterMeasurements(
      NoisyMeasurements(truth, relaxation_case.snr, config.data.seed), config.prefilter);
  const MatrixModelData matrices = BarRunModel(model, data, EndDisplacementChannels());
  MatrixMcreProblem problem(matrices, data, config.mcre.weights, config.mcre.reference_modulus,
                            config.time.theta, Factorization::kAutomatic, config.mcre.clamp);
  problem.SetModuli(Vector::Constant(1, relaxation_case.modulus));
  const auto [a_min, a_max] = EstimateSpectrum(config.inner, &problem);
  relaxation_case.spectrum_min = a_min;
  relaxation_case.spectrum_max = a_max;
  // the fixed relaxation contracts every component iff |1 - omega a| < 1: omega < 2 / a_max
  relaxation_case.omega_limit = 2.0 / a_max;
  // least max |1 - omega a| over [a_min, a_max]
  relaxation_case.omega_optimal = 2.0 / (a_min + a_max);

  auto solve = [&](CoupledSolverType type, double omega, double tolerance) {
    CoupledSolverOptions solver = config.inner;
    solver.type = type;
    solver.preconditioner = TracePreconditioner::kNone;  // the streaming CG's only
    if (type == CoupledSolverType::kRelaxation) solver.relaxation_coefficient = omega;
    solver.tolerance = tolerance;
    CoupledSolution solution;
    return SolveCoupled(solver, &problem, nullptr, &solution);
  };
  long fewest_sweeps = -1;
  relaxation_case.omega_fastest = std::numeric_limits<double>::quiet_NaN();
  for (const double omega : omegas) {
    const CoupledSolverSummary summary =
        solve(CoupledSolverType::kRelaxation, omega, options.relaxation.tolerance);
    RelaxationPoint point;
    point.case_index = c;
    point.omega = omega;
    point.termination = summary.termination;
    point.iterations = summary.iterations;
    point.sweeps = summary.sweeps;
    point.relative_residual = summary.relative_residual;
    point.predicted_iterations =
        PredictedIterations(omega, a_min, a_max, options.relaxation.tolerance);
    points->push_back(point);
    if (summary.IsSolutionUsable() && (fewest_sweeps < 0 || summary.sweeps < fewest_sweeps)) {
      fewest_sweeps = summary.sweeps;
      relaxation_case.omega_fastest = omega;
    }
  }

  // The reference solves to inner.tolerance, with their residual histories.
  auto record = [&](CoupledSolverType type, double omega, const CoupledSolverSummary& summary) {
    ResidualHistory history;
    history.case_index = c;
    history.method = type;
    history.omega = omega;
    history.residuals = summary.residual_history;
    histories->push_back(history);
  };
  if (!std::isnan(relaxation_case.omega_fastest)) {
    const CoupledSolverSummary fixed = solve(CoupledSolverType::kRelaxation,
                                             relaxation_case.omega_fastest, config.inner.tolerance);
    relaxation_case.fixed_sweeps = fixed.sweeps;
    record(CoupledSolverType::kRelaxation, relaxation_case.omega_fastest, fixed);
  }
  const double unused_omega = std::numeric_limits<double>::quiet_NaN();
  const CoupledSolverSummary adaptive =
      solve(CoupledSolverType::kAdaptiveRelaxation, unused_omega, config.inner.tolerance);
  relaxation_case.omega_adaptive = adaptive.relaxation_coefficient;
  relaxation_case.adaptive_sweeps = adaptive.sweeps;
  record(CoupledSolverType::kAdaptiveRelaxation, adaptive.relaxation_coefficient, adaptive);
  const CoupledSolverSummary krylov =
      solve(CoupledSolverType::kConjugateGradient, unused_omega, config.inner.tolerance);
  relaxation_case.conjugate_gradient_sweeps = krylov.sweeps;
  record(CoupledSolverType::kConjugateGradient, std::numeric_limits<double>::quiet_NaN(), krylov);
}

}  // namespace

RelaxationStudy RunRelaxationStudy(const Config& config) {
  const auto start = Clock::now();
  const StudyOptions& options = config.study;
  RelaxationStudy study;
  study.tolerance = options.relaxation.tolerance;
  study.threads = ResolveThreads(options.threads);
  for (const double snr : options.relaxation.snr) {
    for (const double factor : options.relaxation.moduli) {
      RelaxationCase relaxation_case;
      relaxation_case.snr = snr;
      relaxation_case.modulus_factor = factor;
      relaxation_case.modulus = factor * config.model.modulus;
      study.cases.push_back(relaxation_case);
    }
  }
  std::vector<double> omegas;
  for (int i = 0; i < options.relaxation.omega_points; ++i) {
    omegas.push_back(options.relaxation.omega_min +
                     (options.relaxation.omega_max - options.relaxation.omega_min) * i /
                         (options.relaxation.omega_points - 1.0));
  }
  const int cases = static_cast<int>(study.cases.size());
  std::vector<std::vector<RelaxationPoint>> points(cases);
  std::vector<std::vector<ResidualHistory>> histories(cases);

  const ChannelSet truth = SimulateStudyTruth(config);
  const BarModel model(config.model);
  StudyProgressLogger()->info(
      "relaxation: {} cases ({} SNRs x {} moduli), {} omegas each, on {} threads", cases,
      options.relaxation.snr.size(), options.relaxation.moduli.size(), omegas.size(),
      study.threads);
  Progress progress("relaxation", cases);
  ParallelFor(
      cases, study.threads,
      [&](int c) {
        RunRelaxationCase(config, model, truth, omegas, c, &study.cases[c], &points[c],
                          &histories[c]);
      },
      &progress);
  for (int c = 0; c < cases; ++c) {
    study.points.insert(study.points.end(), points[c].begin(), points[c].end());
    study.histories.insert(study.histories.end(), histories[c].begin(), histories[c].end());
  }
  study.wall_time_s = SecondsSince(start);
  return study;
}

namespace {

std::string RelaxationCasesCsv(const RelaxationStudy& study) {
  std::ostringstream csv;
  csv << "case,snr,modulus_factor,modulus,spectrum_min,spectrum_max,omega_limit,omega_optimal,"
         "omega_adaptive,omega_fastest,fixed_sweeps,adaptive_sweeps,conjugate_gradient_sweeps\n";
  for (std::size_t c = 0; c < study.cases.size(); ++c) {
    const RelaxationCase& r = study.cases[c];
    csv << c << "," << Csv(r.snr) << "," << Csv(r.modulus_factor) << "," << Csv(r.modulus) << ","
        << Csv(r.spectrum_min) << "," << Csv(r.spectrum_max) << "," << Csv(r.omega_limit) << ","
        << Csv(r.omega_optimal) << "," << Csv(r.omega_adaptive) << "," << Csv(r.omega_fastest)
        << "," << r.fixed_sweeps << "," << r.adaptive_sweeps << "," << r.conjugate_gradient_sweeps
        << "\n";
  }
  return csv.str();
}

std::string RelaxationSweepsCsv(const RelaxationStudy& study) {
  std::ostringstream csv;
  csv << "case,snr,modulus_factor,omega,termination,converged,iterations,sweeps,"
         "relative_residual,predicted_iterations\n";
  for (const RelaxationPoint& p : study.points) {
    const RelaxationCase& r = study.cases[p.case_index];
    csv << p.case_index << "," << Csv(r.snr) << "," << Csv(r.modulus_factor) << "," << Csv(p.omega)
        << "," << TerminationTypeToString(p.termination) << ","
        << (p.termination == TerminationType::kConvergence ? 1 : 0) << "," << p.iterations << ","
        << p.sweeps << "," << Csv(p.relative_residual) << "," << p.predicted_iterations << "\n";
  }
  return csv.str();
}

std::string ResidualsCsv(const RelaxationStudy& study) {
  std::ostringstream csv;
  csv << "history,case,snr,modulus_factor,method,omega,iteration,relative_residual\n";
  for (std::size_t h = 0; h < study.histories.size(); ++h) {
    const ResidualHistory& history = study.histories[h];
    const RelaxationCase& r = study.cases[history.case_index];
    for (std::size_t i = 0; i < history.residuals.size(); ++i) {
      csv << h << "," << history.case_index << "," << Csv(r.snr) << "," << Csv(r.modulus_factor)
          << "," << CoupledSolverTypeToString(history.method) << "," << Csv(history.omega) << ","
          << i << "," << Csv(history.residuals[i]) << "\n";
    }
  }
  return csv.str();
}

// The distinct values of `field` over the cases, in first-seen order.
std::vector<double> Distinct(const RelaxationStudy& study, double RelaxationCase::*field) {
  std::vector<double> values;
  for (const RelaxationCase& r : study.cases) {
    if (std::find(values.begin(), values.end(), r.*field) == values.end())
      values.push_back(r.*field);
  }
  return values;
}

std::string SweepsScript(const RelaxationStudy& study, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/sweeps.csv");
  const std::vector<double> factors = Distinct(study, &RelaxationCase::modulus_factor);
  const std::vector<double> snrs = Distinct(study, &RelaxationCase::snr);
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size " << 560 * factors.size()
         << ",620 enhanced font 'sans,10'\n"
         << "set multiplot layout 1," << factors.size()
         << " title 'Sweeps of the fixed-omega relaxation to a relative residual of "
         << Brief(study.tolerance)
         << " (lines: measured, dashed: predicted from the spectrum; "
            "arrows: 2/a_{max} solid, adaptive omega dotted)'\n"
         << "set xlabel '{/Symbol w}'\nset ylabel 'sweeps'\nset logscale y\nset key top right\n";
  // The omega axis holds the grid and every marked omega.
  double omega_high = 0.0;
  for (const RelaxationPoint& p : study.points) omega_high = std::max(omega_high, p.omega);
  for (const RelaxationCase& r : study.cases) {
    omega_high = std::max({omega_high, r.omega_limit, r.omega_adaptive});
  }
  script << "set xrange [0:" << 1.05 * omega_high << "]\n";
  for (const double factor : factors) {
    script << "unset arrow\nset title 'E = " << Brief(factor) << " E_{ref}'\n";
    std::vector<std::string> plots;
    for (std::size_t c = 0; c < study.cases.size(); ++c) {
      const RelaxationCase& r = study.cases[c];
      if (r.modulus_factor != factor) continue;
      const int colour_index =
          static_cast<int>(std::find(snrs.begin(), snrs.end(), r.snr) - snrs.begin());
      const std::string colour = Colour(colour_index);
      script << "set arrow from " << r.omega_limit << ", graph 0 to " << r.omega_limit
             << ", graph 1 nohead lw 1.5 lc rgb '" << colour << "'\n"
             << "set arrow from " << r.omega_adaptive << ", graph 0 to " << r.omega_adaptive
             << ", graph 1 nohead dashtype 3 lw 1.5 lc rgb '" << colour << "'\n";
      std::ostringstream measured, predicted;
      measured << csv << " skip 1 using ($1 == " << c << " && $6 == 1 ? $4 : 1/0):8 "
               << "with linespoints pt 7 ps 0.7 lw 2 lc rgb '" << colour << "' title 'SNR "
               << SnrText(r.snr) << "'";
      // predicted sweeps: 3 to start, 2 per iteration (coupled_solver.h)
      predicted << csv << " skip 1 using ($1 == " << c << " && $10 > 0 ? $4 : 1/0):(3 + 2 * $10) "
                << "with lines dashtype 2 lc rgb '" << colour << "' notitle";
      plots.push_back(measured.str());
      plots.push_back(predicted.str());
    }
    script << PlotCommand(plots);
  }
  script << "unset multiplot\n";
  return script.str();
}

// The case of each SNR whose modulus factor is nearest 1.
std::vector<int> CasesNearestReference(const RelaxationStudy& study) {
  std::vector<int> chosen;
  for (const double snr : Distinct(study, &RelaxationCase::snr)) {
    int best = -1;
    for (std::size_t c = 0; c < study.cases.size(); ++c) {
      if (study.cases[c].snr != snr) continue;
      if (best < 0 || std::abs(study.cases[c].modulus_factor - 1.0) <
                          std::abs(study.cases[best].modulus_factor - 1.0)) {
        best = static_cast<int>(c);
      }
    }
    chosen.push_back(best);
  }
  return chosen;
}

std::string ResidualsScript(const RelaxationStudy& study, const std::string& folder) {
  const std::string csv = GnuplotString(folder + "/residuals.csv");
  const std::vector<int> chosen = CasesNearestReference(study);
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size " << 560 * chosen.size()
         << ",620 enhanced font 'sans,10'\n"
         << "set multiplot layout 1," << chosen.size()
         << " title 'Relative residual ||c - A W||_P / ||c||_P against iteration'\n"
         << "set xlabel 'iteration (sweep pair)'\nset ylabel 'relative residual'\n"
         << "set logscale y\nset format y '10^{%T}'\nset key top right\n";
  for (const int c : chosen) {
    const RelaxationCase& r = study.cases[c];
    script << "set title 'SNR " << SnrText(r.snr) << ", E = " << Brief(r.modulus_factor)
           << " E_{ref}'\n";
    std::vector<std::string> plots;
    int colour_index = 0;
    for (std::size_t h = 0; h < study.histories.size(); ++h) {
      const ResidualHistory& history = study.histories[h];
      if (history.case_index != c) continue;
      std::string title;
      if (history.method == CoupledSolverType::kRelaxation) {
        title = "fixed {/Symbol w} = " + Brief(history.omega, 3) + " (fastest of the grid)";
      } else if (history.method == CoupledSolverType::kAdaptiveRelaxation) {
        title = "adaptive {/Symbol w} = " + Brief(history.omega, 3);
      } else {
        title = "conjugate gradients (Krylov)";
      }
      std::ostringstream plot;
      plot << csv << " skip 1 using ($1 == " << h << " ? $7 : 1/0):8 with lines lw 2 lc rgb '"
           << Colour(colour_index++) << "' title '" << title << "'";
      plots.push_back(plot.str());
    }
    script << PlotCommand(plots);
  }
  script << "unset multiplot\n";
  return script.str();
}

std::string RelaxationSummary(const RelaxationStudy& study) {
  std::ostringstream md;
  md << "## Relaxation coefficient (`relaxation/`)\n\n"
     << "`sweeps_vs_omega.png` (the paper's Fig. 3): sweeps of the fixed-omega waveform "
        "relaxation from W = 0 to a relative residual of "
     << Brief(study.tolerance)
     << " against omega, one panel per trial E and one line per SNR, beside the sweeps the "
        "Lanczos estimate [a_min, a_max] of the spectrum of A = I - G predicts (dashed: 3 + 2 "
        "ln(tol) / ln(max |1 - omega a|)), the predicted convergence limit omega = 2 / a_max "
        "(solid vertical) and the adaptive relaxation's omega (dotted vertical). "
        "`residuals.png` (Fig. 4 extended): relative residual against iteration at the E "
        "nearest E_ref, per SNR, for the grid's fastest fixed omega, the adaptive relaxation "
        "and conjugate gradients, each to inner.tolerance. `cases.csv`: spectrum, omegas and "
        "reference sweeps per case; `sweeps.csv`: the grid; `residuals.csv`: the histories.\n\n"
     << "| SNR | E / E_ref | a_min | a_max | 2 / a_max | largest converged omega | 2 / (a_min + "
        "a_max) | fastest omega | adaptive omega | sweeps: fixed / adaptive / CG |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < study.cases.size(); ++c) {
    const RelaxationCase& r = study.cases[c];
    double largest_converged = std::numeric_limits<double>::quiet_NaN();
    for (const RelaxationPoint& p : study.points) {
      if (p.case_index == static_cast<int>(c) && p.termination == TerminationType::kConvergence) {
        largest_converged =
            std::isnan(largest_converged) ? p.omega : std::max(largest_converged, p.omega);
      }
    }
    md << "| " << SnrText(r.snr) << " | " << Brief(r.modulus_factor) << " | "
       << Brief(r.spectrum_min) << " | " << Brief(r.spectrum_max) << " | " << Brief(r.omega_limit)
       << " | " << Brief(largest_converged) << " | " << Brief(r.omega_optimal) << " | "
       << Brief(r.omega_fastest) << " | " << Brief(r.omega_adaptive) << " | " << r.fixed_sweeps
       << " / " << r.adaptive_sweeps << " / " << r.conjugate_gradient_sweeps << " |\n";
  }
  md << "\nSweeps of the last column to inner.tolerance, each from W = 0 (the adaptive "
        "relaxation's include its spectrum estimate). "
     << study.cases.size() << " cases in " << Duration(study.wall_time_s) << " on " << study.threads
     << " threads.\n\n";
  return md.str();
}

}  // namespace

std::vector<std::string> WriteRelaxationResults(const RelaxationStudy& study,
                                                const std::string& folder, bool figures) {
  return WriteStudyFolder(folder,
                          {{"cases.csv", RelaxationCasesCsv(study)},
                           {"sweeps.csv", RelaxationSweepsCsv(study)},
                           {"residuals.csv", ResidualsCsv(study)}},
                          {{"sweeps_vs_omega", SweepsScript(study, folder)},
                           {"residuals", ResidualsScript(study, folder)}},
                          figures, RelaxationSummary(study));
}

// ---------------------------------------------------------------------------
// Cost curves.

CostCurveStudy RunCostCurveStudy(const Config& config) {
  const auto start = Clock::now();
  const StudyOptions& options = config.study;
  CostCurveStudy study;
  study.reference_modulus = config.model.modulus;
  study.threads = ResolveThreads(options.threads);
  for (const double snr : options.cost_curves.snr) {
    for (const std::uint64_t seed : SeedsOf(snr, options.cost_curves.seeds)) {
      CostCurveRun curve;
      curve.snr = snr;
      curve.seed = seed;
      study.curves.push_back(curve);
    }
  }
  const ChannelSet truth = SimulateStudyTruth(config);
  const BarModel model(config.model);
  StudyProgressLogger()->info(
      "cost curves: {} curves of {} points, each with an identification, "
      "on {} threads",
      study.curves.size(), options.cost_curves.points, study.threads);
  Progress progress("cost curves", static_cast<int>(study.curves.size()));
  ParallelFor(
      static_cast<int>(study.curves.size()), study.threads,
      [&](int i) {
        CostCurveRun& curve = study.curves[i];
        const ChannelSet measured = NoisyMeasurements(truth, curve.snr, curve.seed);
        std::string message;
        const IdentificationRun identification = IdentifyOnOneThread(
            config, measured, curve.snr, curve.seed, &curve.converged, &message);
        if (curve.converged) {
          curve.identified_modulus = identification.identified_modulus();
          curve.identified_cost = identification.cost();
          curve.relative_error =
              (curve.identified_modulus - study.reference_modulus) / study.reference_modulus;
        }
        // e^2 on the grid, on the pre-filtered data the identification saw,
        // warm-started point to point.
        const MatrixModelData matrices =
            BarRunModel(model, identification.data, identification.ends);
        McreObjective objective =
            MatrixMcreObjective(matrices, identification.data, config.mcre, config.time.theta,
                                config.inner, Factorization::kAutomatic, study.reference_modulus);
        for (int k = 0; k < options.cost_curves.points; ++k) {
          const double factor =
              options.cost_curves.low + (options.cost_curves.high - options.cost_curves.low) * k /
                                            (options.cost_curves.points - 1.0);
          const ObjectiveEvaluation& evaluation =
              objective.EvaluateModulus(factor * study.reference_modulus, false);
          curve.moduli.push_back(factor * study.reference_modulus);
          curve.costs.push_back(evaluation.usable ? evaluation.cost
                                                  : std::numeric_limits<double>::quiet_NaN());
        }
      },
      &progress);
  study.wall_time_s = SecondsSince(start);
  return study;
}

namespace {

std::string CurvesCsv(const CostCurveStudy& study) {
  std::ostringstream csv;
  csv << "curve,snr,seed,modulus,modulus_factor,cost\n";
  for (std::size_t i = 0; i < study.curves.size(); ++i) {
    const CostCurveRun& curve = study.curves[i];
    for (std::size_t k = 0; k < curve.moduli.size(); ++k) {
      csv << i << "," << Csv(curve.snr) << "," << curve.seed << "," << Csv(curve.moduli[k]) << ","
          << Csv(curve.moduli[k] / study.reference_modulus) << "," << Csv(curve.costs[k]) << "\n";
    }
  }
  return csv.str();
}

std::string MinimaCsv(const CostCurveStudy& study) {
  std::ostringstream csv;
  csv << "curve,snr,seed,converged,identified_modulus,modulus_factor,relative_error,cost,"
         "grid_local_minima\n";
  for (std::size_t i = 0; i < study.curves.size(); ++i) {
    const CostCurveRun& curve = study.curves[i];
    csv << i << "," << Csv(curve.snr) << "," << curve.seed << "," << (curve.converged ? 1 : 0)
        << "," << Csv(curve.identified_modulus) << ","
        << Csv(curve.identified_modulus / study.reference_modulus) << ","
        << Csv(curve.relative_error) << "," << Csv(curve.identified_cost) << ","
        << LocalMinima(curve.costs) << "\n";
  }
  return csv.str();
}

std::string CostCurvesScript(const CostCurveStudy& study, const std::string& folder) {
  const std::string curves = GnuplotString(folder + "/curves.csv");
  const std::string minima = GnuplotString(folder + "/minima.csv");
  std::vector<double> snrs;
  for (const CostCurveRun& curve : study.curves) {
    if (std::find(snrs.begin(), snrs.end(), curve.snr) == snrs.end()) snrs.push_back(curve.snr);
  }
  std::ostringstream script;
  script << GnuplotPngTerminal() << "set terminal pngcairo size " << 560 * snrs.size()
         << ",620 enhanced font 'sans,10'\n"
         << "set multiplot layout 1," << snrs.size()
         << " title 'MCRE cost e^2(E), one curve per noise seed; circles: the identified E'\n"
         << "set xlabel 'E / E_{ref}'\nset ylabel 'e^2 [J s]'\nset format y '%.3g'\n"
         << "set key top center\n"
         << "set arrow 1 from 1, graph 0 to 1, graph 1 nohead dashtype 2 lc rgb '#555555'\n";
  for (const double snr : snrs) {
    script << "set title 'SNR " << SnrText(snr) << "'\n";
    std::vector<std::string> plots;
    int colour_index = 0;
    for (std::size_t i = 0; i < study.curves.size(); ++i) {
      const CostCurveRun& curve = study.curves[i];
      if (curve.snr != snr) continue;
      const std::string colour = Colour(colour_index++);
      std::ostringstream line, point;
      line << curves << " skip 1 using ($1 == " << i << " ? $5 : 1/0):6 with lines lw 2 lc rgb '"
           << colour << "' title '"
           << (std::isinf(snr) ? std::string("no noise") : "seed " + std::to_string(curve.seed))
           << "'";
      point << minima << " skip 1 using ($1 == " << i << " && $4 == 1 ? $6 : 1/0):8 with points "
            << "pt 6 ps 2 lw 2 lc rgb '" << colour << "' notitle";
      plots.push_back(line.str());
      plots.push_back(point.str());
    }
    script << PlotCommand(plots);
  }
  script << "unset multiplot\n";
  return script.str();
}

std::string CostCurvesSummary(const CostCurveStudy& study) {
  std::ostringstream md;
  md << "## Cost curves (`cost_curves/`)\n\n"
     << "`cost_curves.png` (the paper's Fig. 6): the MCRE cost e^2(E) on a grid of E, one panel "
        "per SNR and one curve per noise seed, on the pre-filtered data the identification sees; "
        "circles mark the modulus the identification (global scan and local refinement) finds "
        "on the same data. `curves.csv`: the grids; `minima.csv`: the identified E and the "
        "sampled local minima of each curve.\n\n"
     << "| SNR | seed | identified E / E_ref | relative error | local minima on the grid |\n"
     << "|---|---|---|---|---|\n";
  for (const CostCurveRun& curve : study.curves) {
    md << "| " << SnrText(curve.snr) << " | " << curve.seed << " | "
       << (curve.converged ? Brief(curve.identified_modulus / study.reference_modulus, 6)
                           : std::string("not converged"))
       << " | " << Percent(curve.relative_error) << " | " << LocalMinima(curve.costs) << " |\n";
  }
  md << "\n"
     << study.curves.size() << " curves in " << Duration(study.wall_time_s) << " on "
     << study.threads << " threads.\n\n";
  return md.str();
}

}  // namespace

std::vector<std::string> WriteCostCurveResults(const CostCurveStudy& study,
                                               const std::string& folder, bool figures) {
  return WriteStudyFolder(
      folder, {{"curves.csv", CurvesCsv(study)}, {"minima.csv", MinimaCsv(study)}},
      {{"cost_curves", CostCurvesScript(study, folder)}}, figures, CostCurvesSummary(study));
}

namespace {

// A study's summary.md as a section of results/README.md: its headings shifted so
// that the first is a level-2 heading (some summaries open at level 1), and that
// heading naming the folder, as "## Title (`study/`)", when it does not already.
std::string AsReadmeSection(const std::string& summary, const std::string& study) {
  std::istringstream lines(summary);
  std::ostringstream section;
  std::string line;
  int shift = 0;
  bool first_heading = true, in_code = false;
  while (std::getline(lines, line)) {
    if (line.rfind("```", 0) == 0) in_code = !in_code;
    if (!in_code && !line.empty() && line[0] == '#') {
      const int level = static_cast<int>(line.find_first_not_of('#'));
      if (first_heading) {
        shift = 2 - level;
        if (line.find("(`" + study + "/`)") == std::string::npos) {
          line += " (`" + study + "/`)";
        }
        first_heading = false;
      }
      const int shifted = std::max(1, level + shift);
      line = std::string(static_cast<std::size_t>(shifted), '#') +
             line.substr(static_cast<std::size_t>(level));
    }
    section << line << "\n";
  }
  return section.str();
}

}  // namespace

std::string WriteStudiesReadme(const std::string& folder) {
  std::ostringstream md;
  md << "# Results of the studies\n\n"
     << "Written by `identify study` (`bash scripts/studies.sh` regenerates every study, figure "
        "and this file: the studies of configs/studies.yaml, then the robustness settings, the "
        "complexity and the weights studies of bench/; `bash scripts/plate_study.sh` the plate's, "
        "`bash scripts/plate_zones_study.sh` the many-zone plate's, "
        "`bash scripts/plate_sensors_study.sh` its sensor layouts', "
        "`bash scripts/beam3d_study.sh` the 3-D beam's, `bash scripts/shpb_study.sh` the real "
        "Hopkinson-bar shots', `bash scripts/plate_basin_study.sh` the basin of attraction on "
        "the SfePy plate's 8 zones, `bash scripts/plate_zones_basin_study.sh` on the many-zone "
        "plate's 64); do not edit by hand. Each "
        "section below is the `summary.md` of its folder.\n\n";
  for (const char* study :
       {"robustness", "relaxation", "cost_curves", "damage", "comparator", "robustness_settings",
        "complexity", "weights", "plate", "plate_zones", "plate_sensors", "beam3d", "beam3d/fine",
        "real", "plate_basin", "plate_zones_basin/full_field", "plate_zones_basin/gauges"}) {
    const std::string summary = folder + "/" + study + "/summary.md";
    std::ifstream file(summary);
    if (!file) continue;
    std::ostringstream text;
    text << file.rdbuf();
    md << AsReadmeSection(text.str(), study);
  }
  const std::string path = folder + "/README.md";
  WriteFileAtomically(path, md.str());
  return path;
}

}  // namespace mcrewave
