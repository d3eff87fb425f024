// The comparator study (`identify study --set study.kind=comparator`): the MCRE and
// output-error least squares (least_squares/output_error_modulus_objective.h) identify E from
// the same data, with the same optimiser and bounds (outer:), each as identify run does
// (the MCRE's global scan on the search functional of search:, least squares' on J), with
// and without the pre-filter, over noise seeds, on the config's case as it is ("none")
// and with the model errors real tests have:
//
//   density            the identification's model 3 % denser than the bar measured
//   force_gain         the measured load fL 5 % too high (a force sensor's gain)
//   displacement_gain  the measured uL 3 % too high (a displacement sensor's gain)
//   soft_zone          the bar 10 % softer over [0, 0.1 L] (by the clamp), the model
//                      uniform
//   support_50, support_10, support_5
//                      the clamp a spring of 50, 10 or 5 E S / L (data.support_stiffness),
//                      the model's clamp rigid
//
// The MCRE runs test the clamp against the raw data as identify run does
// (ConfigForTheSupports, identification_run.h: with the defaults a contradicted clamp is
// treated as measured); least squares keeps it rigid.
// Least squares weighs each channel by 1 / s^2 with s = RMS(measured channel) / SNR
// (at SNR inf the RMS alone: only the ratio of the weights matters). Every run
// is seeded, its scans on one thread: the study's numbers do not depend on
// study.threads.
//
// On a matrix model (model.kind: matrix) every zone modulus is identified at once, by
// each functional as identify run does it (app/matrix_identification_run.h: least
// squares normalised by MatrixLeastSquaresMisfitLevels; no error maps or uncertainty),
// from the truth of data: (data.truth_manifest at data.truth_moduli) plus the noise of
// AddMatrixModelNoise, each zone against the truth's modulus. The model errors there:
// density (the model's M 3 % larger), force_gain (every load channel 5 % high),
// displacement_gain (every displacement sensor 3 % high); soft_zone and the supports are
// the bar's only.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace mcrewave {

struct Config;

// The names of the model errors above, in this order.
const std::vector<std::string>& ComparatorModelErrors();

// One modulus of one identification (the bar: E; a matrix model: one per zone).
struct ComparatorRun {
  std::string model_error;  // one of ComparatorModelErrors()
  int zone = 0;             // index in ComparatorStudy::zones
  double snr = 0.0;
  std::uint64_t seed = 0;  // 0 at SNR inf
  bool prefilter = false;
  bool least_squares = false;  // else MCRE
  bool converged = false;
  std::string message;  // the outer loop's, when not converged
  double modulus = std::numeric_limits<double>::quiet_NaN();  // identified E [Pa]
  double error = std::numeric_limits<double>::quiet_NaN();    // E / E_ref - 1
  // Valleys of the functional the global scan ran on (0: no scan; -1: a matrix model
  // without the homogeneous stage, whose zones start from their nominal moduli).
  int local_minima = 0;
  // The search functional's minimiser E_search [Pa] (two stages), NaN otherwise.
  double search_modulus = std::numeric_limits<double>::quiet_NaN();
  int evaluations = 0;   // of every functional: scans and refinements
  double wall_time_s = std::numeric_limits<double>::quiet_NaN();
  // The MCRE's run treated its supports as measured: the test of the first one (the
  // bar's clamp) contradicted one; and that test's t (NaN: not tested).
  bool support_switched = false;
  double support_statistic = std::numeric_limits<double>::quiet_NaN();
  // The paper's formulation's weight in E (SupportBlend::weight): 0 trusted, 1 switched,
  // between: both identified and weighed.
  double support_weight = 0.0;
};

// Over the converged runs of one (model error, functional, pre-filter, SNR, zone).
struct ComparatorStatistics {
  std::string model_error;
  int zone = 0;
  bool least_squares = false;
  bool prefilter = false;
  double snr = 0.0;
  int runs = 0;
  double converged_share = 0.0;
  double mean_error = std::numeric_limits<double>::quiet_NaN();  // the bias
  double std_error = std::numeric_limits<double>::quiet_NaN();
  double rms_error = std::numeric_limits<double>::quiet_NaN();
  double quantile_025 = std::numeric_limits<double>::quiet_NaN();
  double quantile_975 = std::numeric_limits<double>::quiet_NaN();
  double within_2_percent = std::numeric_limits<double>::quiet_NaN();  // share of the runs
  // Share with 1 minimum and mean minima of the global scans (NaN without a scan).
  double one_valley = std::numeric_limits<double>::quiet_NaN();
  double mean_local_minima = std::numeric_limits<double>::quiet_NaN();
  double mean_evaluations = std::numeric_limits<double>::quiet_NaN();
  double mean_wall_time_s = std::numeric_limits<double>::quiet_NaN();
  double switched_share = 0.0;  // of the converged runs, support_switched
};

struct ComparatorStudy {
  // The moduli identified (the bar: "E"; a matrix model: its zones) and their E_ref
  // [Pa] (model.modulus; the truth's zone moduli).
  std::vector<std::string> zones;
  std::vector<double> reference_moduli;
  bool matrix_model = false;              // no global scan: a local search from the nominal moduli
  std::vector<std::string> model_errors;  // study.comparator.errors
  std::vector<double> snrs;               // study.comparator.snr
  std::vector<bool> prefilters;           // study.comparator.data: false raw, true prefilter
  // The MCRE's global scan ran on the pinned search functional (search.functional
  // pinned), not on e^2 itself: its valleys are the search functional's.
  bool mcre_scans_search = false;
  std::vector<ComparatorRun> runs;
  std::vector<ComparatorStatistics> statistics;
  int threads = 0;
  double wall_time_s = 0.0;
};

// Runs study.comparator.errors x study.comparator.snr x seeds (1..study.comparator.seeds
// per finite SNR, one run at SNR inf) x study.comparator.data (raw, pre-filtered) x
// {MCRE, least squares} on the config's case, on study.threads threads, with a progress line per
// data set; runs holds them data set by data set, {MCRE, least squares} x data x zones
// within each. Throws InputError for soft_zone or a truth without one of the zones on a
// matrix model. Precondition: config valid.
// journal_path: as RunRobustnessStudy (study.h), the runs journaled and resumed there.
ComparatorStudy RunComparatorStudy(const Config& config, const std::string& journal_path = "");

// Writes runs.csv, statistics.csv, comparator.png (rms error of E against the SNR,
// one panel per model error) and summary.md into `folder`; returns the paths. With more
// than one zone, a zone column in the CSV files and the tables, and a curve per zone.
std::vector<std::string> WriteComparatorResults(const ComparatorStudy& study,
                                                const std::string& folder, bool figures);

}  // namespace mcrewave
