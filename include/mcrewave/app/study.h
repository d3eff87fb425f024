// Studies of the identification, run by `identify study CONFIG` from the `study:`
// section of a config (README, "Studies"), each into a folder of its own:
//
//   robustness   for every SNR of robustness.snr and noise seeds 1..robustness.seeds
//                (one run at SNR inf), the identification of `identify run` on data
//                from the truth of `data:` (the bar: identification_run.h, E against
//                E_ref = model.modulus; a matrix model: matrix_identification_run.h
//                without its error maps and uncertainty, every zone modulus against the
//                truth's); per SNR and parameter the statistics of the relative error,
//                the converged share, mean outer evaluations and inner sweeps.
//   relaxation   for every SNR of relaxation.snr (noise seed data.seed) and E = f E_ref,
//                f in relaxation.moduli: the sweeps of the fixed-omega relaxation to
//                relaxation.tolerance on a grid of omega (the paper's Fig. 3) beside what
//                the Lanczos estimate of the spectrum of A = I - G predicts (limit
//                2 / a_max, optimum 2 / (a_min + a_max), the adaptive omega, iterations
//                ln(tol) / ln(rho(omega)), rho = max |1 - omega a|), and the residual
//                histories of the fixed, adaptive and CG solves (Fig. 4 extended).
//   cost_curves  for every SNR of cost_curves.snr and seeds 1..cost_curves.seeds (one at
//                SNR inf): e^2(E) on cost_curves.points moduli evenly spaced over
//                [cost_curves.low, cost_curves.high] E_ref, and the identified E on the
//                same data (the paper's Fig. 6).
//
// E_ref is model.modulus. Every study uses the config's model, load, time grid, data
// truth, weights, inner solver, pre-filter and outer loop; the measurements of one
// (SNR, seed) are the truth plus AddMeasurementNoise(snr, seed) (a matrix model:
// AddMatrixModelNoise), then the pre-filter: the data of `identify run` with data.snr
// and data.seed set to them. The robustness study runs on both model kinds, the others
// on the bar.
// Runs are spread over `threads` threads (0: every core), each run on one thread, and
// stored by index: the numbers do not depend on the number of threads. Progress lines
// go to StudyProgressLogger().
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/mcre/coupled_solver.h"

namespace mcrewave {

struct Config;

// The `study:` section of the config.
struct StudyOptions {
  StudyKind kind = StudyKind::kAll;
  // Results folder of `identify study` (one subfolder per study and a
  // README.md); relative to the working directory; --output replaces it.
  std::string folder = "results";
  // Threads running the studies' runs; 0: std::thread::hardware_concurrency().
  int threads = 0;
  // Figures (gnuplot) beside the CSV files.
  bool figures = true;

  // Robustness (study.robustness.*): signal-to-noise ratios (.inf: no noise) and
  // seeds per finite SNR.
  struct Robustness {
    std::vector<double> snr = {std::numeric_limits<double>::infinity(), 20.0, 10.0, 5.0, 2.5};
    int seeds = 100;
  };
  Robustness robustness;

  // Relaxation (study.relaxation.*): SNRs, moduli as factors of E_ref, the omega
  // grid (evenly spaced, ends included) and the relative residual the grid's
  // solves reach (the paper used 1e-4).
  struct Relaxation {
    std::vector<double> snr = {std::numeric_limits<double>::infinity(), 10.0, 2.5};
    std::vector<double> moduli = {0.8, 1.0, 1.2};
    double omega_min = 0.005;
    double omega_max = 0.1;
    int omega_points = 20;
    double tolerance = 1e-4;
  };
  Relaxation relaxation;

  // Cost curves (study.cost_curves.*): SNRs, seeds per finite SNR, and the grid of
  // E as factors of E_ref.
  struct CostCurves {
    std::vector<double> snr = {std::numeric_limits<double>::infinity(), 10.0, 2.5};
    int seeds = 3;
    int points = 41;
    double low = 0.8;
    double high = 1.2;
  };
  CostCurves cost_curves;

  // Damage localisation (study.damage.*, damage_study.h): SNRs of the grid and
  // seeds of the SNR-10 runs.
  struct Damage {
    std::vector<double> snr = {std::numeric_limits<double>::infinity(), 20.0, 10.0, 5.0};
    int seeds = 20;
  };
  Damage damage;

  // MCRE against least squares (study.comparator.*, comparator_study.h): SNRs,
  // seeds per finite SNR, the model errors (ComparatorModelErrors()) and the data
  // each functional identifies from: raw and/or prefilter (pre-filtered).
  struct Comparator {
    std::vector<double> snr = {20.0, 10.0, 5.0, 2.5};
    int seeds = 100;
    std::vector<std::string> errors = {"none",      "density",    "force_gain", "displacement_gain",
                                       "soft_zone", "support_50", "support_10", "support_5"};
    std::vector<std::string> data = {"raw", "prefilter"};
  };
  Comparator comparator;

  // Valid when folder is not empty, threads in [0, 256], every SNR > 0 (.inf
  // allowed), lists not empty (at most 100 values), seeds in [1, 100000] (damage:
  // [1, 1000]), relaxation.moduli in (0, 10], 0 < relaxation.omega_min <
  // relaxation.omega_max < 2, relaxation.omega_points in [2, 1000],
  // relaxation.tolerance in (0, 1), cost_curves.points in [3, 10000],
  // 0 < cost_curves.low < cost_curves.high (finite), comparator.errors among
  // ComparatorModelErrors(), comparator.data raw and/or prefilter once each.
  // Messages name the study.* keys (study.robustness.snr, ...).
  bool IsValid(std::string* error) const;
};

// Whether `kind` runs the study `part`: kAll runs robustness, relaxation and cost
// curves, not damage or comparator, which run only when asked for by name.
bool StudySelected(StudyKind kind, StudyKind part);

// ---------------------------------------------------------------------------
// Robustness.

struct RobustnessRun {
  double snr = 0.0;
  int snr_index = 0;       // position of snr in robustness.snr
  std::uint64_t seed = 0;  // noise seed (0 at SNR inf: no noise drawn)
  // The outer loop converged and every modulus lies strictly inside the bounds.
  bool converged = false;
  std::string message;  // why not, when not converged
  // One per parameter of the study (RobustnessStudy::parameters), NaN when not converged:
  // the identified modulus E* [Pa] and its relative error (E* - E_ref) / E_ref.
  std::vector<double> identified_moduli;
  std::vector<double> relative_errors;
  int evaluations = 0;       // outer evaluations, scan included
  int scan_evaluations = 0;  // of which in the global scan
  long sweeps = 0;           // inner sweeps of the scan and the local refinements
  int local_minima = 0;      // sampled local minima of the scan
};

struct RobustnessStatistics {
  double snr = 0.0;
  int snr_index = 0;  // position of snr in robustness.snr
  int parameter = 0;  // its index in RobustnessStudy::parameters
  int runs = 0;
  int converged = 0;
  double converged_share = 0.0;
  // Over the converged runs (NaN when none): relative error of the parameter.
  double mean_error = std::numeric_limits<double>::quiet_NaN();
  double std_error = std::numeric_limits<double>::quiet_NaN();  // sample std (0 for one run)
  double quantile_025 = std::numeric_limits<double>::quiet_NaN();
  double quantile_975 = std::numeric_limits<double>::quiet_NaN();
  double mean_evaluations = 0.0;  // over all runs
  double mean_sweeps = 0.0;       // over all runs
};

struct RobustnessStudy {
  // The moduli identified, by name (the bar: "E"; a matrix model: its zones), and the
  // reference of each, E_ref [Pa] (the bar: model.modulus; a matrix model: the truth's
  // modulus of the zone).
  std::vector<std::string> parameters;
  std::vector<double> reference_moduli;
  bool matrix_model = false;        // a matrix model's zones: no global scan
  std::vector<RobustnessRun> runs;  // SNR by SNR, seeds ascending
  // One per SNR and parameter: SNR by SNR in robustness.snr order, the parameters in
  // order within each.
  std::vector<RobustnessStatistics> statistics;
  int threads = 0;
  double wall_time_s = 0.0;
};

// With a journal_path, every finished run is journaled there, and the runs of a journal
// left by a study of the same config killed part way are taken from it instead of being
// run again (the same bits; docs/robustness.md, "Resuming a study"); the caller removes
// it (RemoveStudyJournal) once the results are written. Throws InputError when a matrix
// model's truth lacks one of its zones (no reference), std::runtime_error when the
// journal cannot be written. Precondition: config valid (as LoadConfig returns it),
// synthetic data.
RobustnessStudy RunRobustnessStudy(const Config& config, const std::string& journal_path = "");

// ---------------------------------------------------------------------------
// Relaxation coefficient.

// One (SNR, E) case: the spectrum estimate and the reference solves.
struct RelaxationCase {
  double snr = 0.0;
  double modulus_factor = 0.0;  // E / E_ref
  double modulus = 0.0;         // [Pa]
  // Lanczos estimate of the extreme eigenvalues of A = I - G (inner.spectrum_steps
  // steps from c, no safety factor).
  double spectrum_min = 0.0;
  double spectrum_max = 0.0;
  double omega_limit = 0.0;    // 2 / a_max: the fixed relaxation diverges above
  double omega_optimal = 0.0;  // 2 / (a_min + a_max): least contraction factor
  // The adaptive relaxation's final omega (with inner.spectrum_safety_factor)
  // and the sweeps of each reference solve to inner.tolerance.
  double omega_adaptive = 0.0;
  long adaptive_sweeps = 0;
  long conjugate_gradient_sweeps = 0;
  double omega_fastest = 0.0;  // the grid's omega of fewest sweeps (NaN: none converged)
  long fixed_sweeps = 0;       // its solve to inner.tolerance
};

// One solve of the omega grid.
struct RelaxationPoint {
  int case_index = 0;
  double omega = 0.0;
  TerminationType termination = TerminationType::kFailure;
  int iterations = 0;
  long sweeps = 0;
  double relative_residual = 0.0;
  // ln(tol) / ln(rho), rho = max(|1 - omega a_min|, |1 - omega a_max|), rounded
  // up; -1 when rho >= 1 (divergence predicted).
  int predicted_iterations = -1;
};

// Relative residual per iteration of one reference solve.
struct ResidualHistory {
  int case_index = 0;
  CoupledSolverType method = CoupledSolverType::kConjugateGradient;
  double omega = std::numeric_limits<double>::quiet_NaN();  // NaN for CG
  std::vector<double> residuals;
};

struct RelaxationStudy {
  double tolerance = 0.0;                  // of the grid's solves
  std::vector<RelaxationCase> cases;       // SNR by SNR, moduli in the config's order
  std::vector<RelaxationPoint> points;     // case by case, omega ascending
  std::vector<ResidualHistory> histories;  // case by case: fixed, adaptive, CG
  int threads = 0;
  double wall_time_s = 0.0;
};

// Precondition: config valid, synthetic data.
RelaxationStudy RunRelaxationStudy(const Config& config);

// ---------------------------------------------------------------------------
// Cost curves.

struct CostCurveRun {
  double snr = 0.0;
  std::uint64_t seed = 0;      // 0 at SNR inf
  std::vector<double> moduli;  // [Pa], ascending
  std::vector<double> costs;   // e^2 [J s] (NaN where the coupled solve is not usable)
  bool converged = false;      // of the identification on the same data
  double identified_modulus = std::numeric_limits<double>::quiet_NaN();  // [Pa]
  double identified_cost = std::numeric_limits<double>::quiet_NaN();     // e^2 there [J s]
  double relative_error = std::numeric_limits<double>::quiet_NaN();
};

struct CostCurveStudy {
  double reference_modulus = 0.0;
  std::vector<CostCurveRun> curves;  // SNR by SNR, seeds ascending
  int threads = 0;
  double wall_time_s = 0.0;
};

// Precondition: config valid, synthetic data.
CostCurveStudy RunCostCurveStudy(const Config& config);

// ---------------------------------------------------------------------------
// Results. Each Write* creates `folder` if needed and writes, each file
// atomically (file_util.h), the CSV files, the PNG figures when `figures` (and
// gnuplot is there; otherwise a warning) and summary.md (what each figure shows
// and the headline numbers); returns the paths written. Throws
// std::runtime_error naming a file that cannot be written.
//
//   robustness/   runs.csv (one row per identification), statistics.csv (one
//                 per SNR), robustness.png (mean and 95 % band of the error per
//                 SNR, every run as a point); with more than one parameter, a row per
//                 parameter of each, named in a zone_index and a zone column
//   relaxation/   cases.csv (spectrum, omegas, reference sweeps per case),
//                 sweeps.csv (the omega grid), residuals.csv (the histories),
//                 sweeps_vs_omega.png, residuals.png
//   cost_curves/  curves.csv (e^2 on the grid), minima.csv (identified E per
//                 curve), cost_curves.png
std::vector<std::string> WriteRobustnessResults(const RobustnessStudy& study,
                                                const std::string& folder, bool figures);
std::vector<std::string> WriteRelaxationResults(const RelaxationStudy& study,
                                                const std::string& folder, bool figures);
std::vector<std::string> WriteCostCurveResults(const CostCurveStudy& study,
                                               const std::string& folder, bool figures);

// Where `identify study` journals the runs of `study` (robustness, comparator, damage):
// study.folder/.<study>.journal.
std::string StudyJournalPath(const Config& config, const std::string& study);
// Deletes that journal (nothing when there is none): the study's results are written.
void RemoveStudyJournal(const std::string& path);

// Writes folder/README.md: the summary.md of each study subfolder present
// (robustness, relaxation, cost_curves, damage, comparator, robustness_settings,
// complexity, weights, plate), in that order, under a short header. Each summary's
// headings are shifted so that its first is a level-2 heading naming the folder,
// "## Title (`study/`)". Returns its path.
std::string WriteStudiesReadme(const std::string& folder);

// The logger of the studies' progress lines: the default logger's sinks under
// the name "study", not registered, so that its level is set apart from the
// default logger's (which the identifications inside a study log to).
std::shared_ptr<spdlog::logger> StudyProgressLogger();

// The q-quantile of values (linear interpolation between order statistics).
// Precondition: values not empty, q in [0, 1].
double Quantile(std::vector<double> values, double q);

}  // namespace mcrewave
