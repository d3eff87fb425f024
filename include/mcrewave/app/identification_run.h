// One identification as `identify run` performs it, from a validated Config to
// everything the results show, before anything is written (results.h writes).
//
//   1. LoadMeasurements: synthetic data (data.source: synthetic) or the CSV file,
//      checked against the model's time grid.
//   2. The pre-filter (prefilter.h) of the measurements when prefilter.enabled.
//   3. IdentifyWithMcre: the global scan and local refinements of e^2 (objective.h,
//      identification.h) with x = E / outer.initial, on the bar as a structure given by
//      matrices (BarRunModel, the one road of every MCRE solve); by default the scan runs on the
//      search functional (search:, the pinned clamp's e^2) and mcre:'s e^2 is refined
//      near its minimum (IdentifyInTwoStages).
//   4. At the identified E*: the cost curve e^2(E) on output.curve_points points
//      around E*, warm-started point to point, the error map of the constitutive
//      gap (error_map.h) and the uncertainty figure (modulus_uncertainty.h).
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mcrewave/app/config.h"
#include "mcrewave/app/zone_identification_run.h"
#include "mcrewave/data/measurement.h"
#include "mcrewave/least_squares/output_error_modulus_objective.h"
#include "mcrewave/mcre/error_map.h"
#include "mcrewave/mcre/modulus_uncertainty.h"
#include "mcrewave/mcre/objective.h"
#include "mcrewave/mcre/support_check.h"
#include "mcrewave/mcre/zone_uncertainty.h"
#include "mcrewave/model/matrix_export.h"
#include "mcrewave/optim/identification.h"

namespace mcrewave {

// The measurements of config.data: MakeSyntheticMeasurements, or the CSV file
// data.path. Throws InputError naming the file when a CSV is malformed (see
// ReadMeasurementCsv), has a dead channel or an outlier among the file's samples
// (CheckMeasurementChannels) or does not fit the model's time grid. A CSV sampled at
// another uniform rate or origin is resampled onto the grid (resample.h); on the
// grid (time.step to 1e-6 relative) it must hold at least time.window / time.step + 1
// samples, of which the first that many are kept. Synthetic data: see
// SyntheticMeasurements.
ChannelSet LoadMeasurements(const Config& config);

// The CSV branch of LoadMeasurements on a record already read (ReadMeasurementCsv, or
// given in code with the bar's channels and kinds): its checks, resampling, channel
// selection and window, with `name` for the file in messages.
ChannelSet BarMeasurementsOfRecord(const Config& config, ChannelSet record,
                                   const std::string& name);

// MakeSyntheticMeasurements of the config's model, load, time and data sections.
// Throws InputError naming the config's keys when a value is not finite (a load
// or a noise level beyond double range).
ChannelSet SyntheticMeasurements(const Config& config);

// The homogeneous stage of an identification on any structure given by matrices: one
// modulus E in every zone, found by the outer loop of config.outer on mcre:'s e^2
// (IdentifyWithMcre: the global scan, on the search functional by default, then the
// local refinements), then the cost curve around E* and a solve from W = 0 there
// (CompleteModulusStage). The bar's scalar identification, and the start of the zones on
// a structure whose zones share one nominal modulus.
struct ModulusStage {
  // The coupled solver that ran: config.inner.type, or what auto resolved to on this
  // structure and time grid (ResolveCoupledSolverType).
  CoupledSolverType inner_method = CoupledSolverType::kConjugateGradient;
  IdentificationSummary outer;
  // The optimiser's evaluations, in order; evaluations[best_index] is the one
  // at the identified E, and `solution` its coupled solution (a streaming solve's
  // traces in its rows' order).
  std::vector<ObjectiveEvaluation> evaluations;
  int best_index = -1;
  CoupledSolution solution;
  double rest_cost = 0.0;  // J_rest, the cost scale [J s]
  // The cost scale of outer's scan fields [J s]: J_rest of the search functional when
  // outer.scan_of_search, else rest_cost.
  double scan_cost_scale = 0.0;
  // Sweeps of the optimiser's evaluations, the search objective's own included (the
  // scans' copies: outer.scan_sweeps).
  long sweeps = 0;
  long search_sweeps = 0;  // of which the search objective's own (0: one stage)

  std::vector<CostCurvePoint> cost_curve;  // ascending E
  long cost_curve_sweeps = 0;
  // A coupled solve at the identified E from W = 0, for the inner solver's
  // convergence history (the optimiser's solves are warm-started: the one at E*
  // takes few iterations, often none).
  CoupledSolverSummary cold_solve;

  // The outer loop converged; only then are the fields after `outer` filled.
  bool IsUsable() const { return outer.IsSolutionUsable(); }
  double identified_modulus() const { return outer.modulus; }
  // e^2 at the identified E [J s].
  double cost() const { return best_index >= 0 ? evaluations[best_index].cost : -1.0; }
};

// How the two treatments of a run's supports weigh in its E*
// (IdentifyHomogeneousModulusOfSupports below, docs/boundaries.md section 10).
struct SupportBlend {
  double weight = 0.0;             // a, the paper's formulation's weight in E*
  double trusted_modulus = -1.0;   // E of the trusted treatment [Pa]; -1: not identified
  double measured_modulus = -1.0;  // E of the paper's treatment [Pa]; -1: not identified
  // Both treatments weigh in E* (0 < a < 1).
  bool Blends() const { return weight > 0.0 && weight < 1.0; }
  // E* = (1 - a) E_trusted + a E_measured [Pa] (docs/boundaries.md section 10).
  double Modulus() const { return (1.0 - weight) * trusted_modulus + weight * measured_modulus; }
};

// The bar's identification from a coarse mesh (model.coarse_elements, docs/multilevel.md):
// E* first on a bar of coarse_elements elements, then refined up to model.elements.
struct CoarseMeshStage {
  bool ran = false;
  int coarse_elements = 0;
  double coarse_modulus = -1.0;     // E* on the coarse mesh [Pa]
  double coarse_wall_time_s = 0.0;  // [s] the coarse run, its curve, maps and uncertainty
  // [J s/Pa^2] the coarse cost curve's d^2e^2/dE^2 near E*, the refinement's first step
  double curvature = 0.0;
  // E refined up to model.elements from coarse_modulus (RefineFrom, the secant): the last
  // mesh's summary, its evaluations those of every mesh above the coarse one.
  IdentificationSummary refinement;
  long sweeps = 0;  // of the refinements' solves, every mesh above the coarse one
};

// Everything one identification computed, on the bar (RunIdentification) or on a
// structure given by matrices (RunMatrixIdentification, app/matrix_identification_run.h):
// the homogeneous stage this run is (one E in every zone; on a structure whose zones'
// nominal moduli differ it does not run, homogeneous_ran false), then the zones, the
// error maps and the uncertainty. By the MCRE, or by output-error least squares
// (outer.functional: least_squares, RunLeastSquares on the bar): the same data path,
// pre-filter and optimiser, the global scan on J(E), the misfit of the held model driven
// by the measured loads normalised by misfit_levels; then the stage's evaluations,
// solution, cold solve, uncertainty, error maps and model channels are left empty,
// rest_cost is J_rest [s] and, on the bar, `sweeps` counts every simulation (scan,
// refinement, fit, curve).
struct IdentificationRun : ModulusStage {
  // The config the run identified with: the one given, or ConfigForTheSupports' switch
  // to the paper's treatment when the data contradicted a trusted support.
  Config config;
  // The tests of the supports against the raw data (none: not tested), and whether
  // `config` switched their treatment to measured.
  std::vector<SupportCheck> support_checks;
  bool support_switched = false;
  // The two treatments' moduli and the paper's weight in E* (IdentifyHomogeneousModulusOf
  // Supports); weight 0 and both moduli -1 when E* is one treatment's alone.
  SupportBlend support_blend;
  bool least_squares = false;  // outer.functional: least_squares
  // The homogeneous stage (this ModulusStage) ran: always on the bar; on a structure
  // given by matrices when its zones share one nominal modulus.
  bool homogeneous_ran = true;
  // The measurements as compared with, pre-filtered when prefilter.enabled: on the bar
  // the channels of data.channels; on a structure given by matrices every channel of the
  // model, in its order (loads, then sensors).
  ChannelSet data;
  std::string
      data_source;  // a manifest's run: the CSV's path, or "synthetic" (the bar's: config.data)
  // The bar's end displacement channels among them (data.channels).
  EndDisplacementChannels ends;
  // The structure every solve of the run takes: BarRunModel of config.model, data and
  // ends (set by IdentifyModulus), or the manifest's model (set when the run writes maps;
  // shared, so that a copy of the run keeps it).
  std::shared_ptr<const MatrixModelData> model;
  // The pre-filter's cut-off frequency [Hz] (given or derived); 0 when off.
  double prefilter_cutoff = 0.0;
  // Synthetic data: they were made with E = config.model.modulus (the bar), or the
  // truth moduli (truth_moduli), the reference the identified moduli are compared with.
  bool reference_known = false;
  // The noise levels the uncertainty draws (and, on a structure given by matrices, the
  // zones' discrepancy target), and where they come from: "synthetic_snr" (the levels
  // the synthetic noise was drawn with) or "data_differences" (CSV data, or no synthetic
  // noise; MeasurementNoiseLevels, MatrixNoiseLevels).
  NoiseLevels noise;
  std::string noise_source;
  // The bar: DifferenceNoiseLevels of the measurements as given (before the pre-filter),
  // the zones' discrepancy target. The uncertainty draws white noise of `noise` on the
  // channels, unfiltered: with the pre-filter on, it overstates the spread (conservative).
  NoiseLevels estimated_noise;
  // Least squares: the levels that normalise the misfit (s_u, s_f, s_e), and where they
  // come from (LeastSquaresMisfitLevels, MatrixLeastSquaresMisfitLevels).
  NoiseLevels misfit_levels;
  std::string misfit_source;
  NoiseLevels misfit;  // the bar: RMS misfits at the optimum (EndMisfitLevels of model_channels)
  // The bar's channels at the identified E (MatrixMcreProblem::ModelChannels of
  // BarRunModel): fL = fL~ - W_L / alpha; f0, the clamp's force, the load f0~ - W_0 / alpha
  // (clamp measured) or f0~ - W_0 / alpha_0 (pinned), the reaction r(U_j) (trusted);
  // uL, u0 and the sensors, H U. An end displacement the run does not use (data.channels)
  // is read from the stored field, and is missing after a streaming solve.
  ChannelSet model_channels;

  double alpha = 0.0;  // the bar's force weight used [m/N]
  double beta = 0.0;   // the bar's displacement weight used [N/m]

  // The bar's uncertainty of E* (from the cost curve's curvature and the noise draws).
  ModulusUncertainty uncertainty;
  // The bar's error map along x at the identified (homogeneous) E, from `solution`.
  ErrorMap error_map;
  // The zone moduli from E* (on the bar ran = false with one zone), or from the nominal
  // moduli when they differ.
  ZoneIdentificationRun zones;
  double wall_time_s = -1.0;  // the whole of the run
  // The bar from a coarse mesh (ran: model.elements above model.coarse_elements): the cost
  // curve, the cold solve, the uncertainty and the zones are then the coarse mesh's, and
  // E*, `solution`, the error map and the model's channels the refinement's on
  // model.elements.
  CoarseMeshStage coarse_mesh;

  // Least squares on the bar: the model's outputs and J at the identified E, and on the
  // cost curve J(E) and dJ/dE over E* +- 5 %, the curvature d^2J/dE^2 at E* [s / Pa^2]
  // (the slope of dJ/dE over the curve, ripple included).
  OutputErrorFit fit;
  double curvature = 0.0;
  // 1 / sqrt(fit.fisher_information) [Pa]: the Cramer-Rao bound of E under white noise of
  // the levels misfit_levels on the outputs with the measured load taken as exact. The
  // noise of the load that drives the model is not counted, so the spread of E over
  // noise draws is larger (docs/comparator.md). NaN when the information is not positive.
  double modulus_std_bound = std::numeric_limits<double>::quiet_NaN();

  // A structure given by matrices: its zones' moduli [Pa] (identified: empty when no
  // usable point; truth: empty when unknown).
  Vector nominal_moduli, identified_moduli, truth_moduli;
  // e^2 [J s] (least squares: J [s]) at E* in every zone, at the identified and at the
  // nominal moduli, and J_rest of the zones' objective.
  double homogeneous_cost = 0.0, zone_cost = 0.0, nominal_cost = 0.0, zone_rest_cost = 0.0;
  // Constitutive part of e^2 per zone and per dof [J s], at the nominal moduli (where
  // the model is wrong) and at the identified ones.
  Vector nominal_zone_map, zone_map, nominal_dof_map, dof_map;
  // Each zone's gap relative to its strain energy over the window [-]: e_z^2 over the
  // same sum of U, (E_z / E_z,nom) sum_j c_j h 1/2 U_j^T K_z U_j. Independent of the
  // zone's size, it is the map that points at a wrong zone.
  Vector nominal_zone_gap, zone_gap;
  // Constitutive part of e^2 per element [J s] with its space-time picture
  // (mcre/element_error_map.h), at the nominal and the identified moduli, when the model
  // has element blocks.
  ErrorMap nominal_element_map, element_map;
  // The model's outputs H U at the identified moduli, a row per sensor: its response to
  // the measured loads and, when some were not measured (mcre.unmeasured_loads), to the
  // identified ones, the histories in model_loads.
  Matrix model_outputs;
  // With unmeasured loads: every load channel's history the model was driven by [N], a
  // row per load of the model (the data's when measured, the MCRE's identified force
  // F = -a G^T W / alpha_u when not); empty otherwise.
  Matrix model_loads;
  // The first-order uncertainty of the identified zone moduli (uncertainty:), drawn at
  // `noise` (EstimateZoneUncertainty; on the bar BarZoneUncertainty, with zones).
  ZoneUncertainty zone_uncertainty;
  // Why a run on a structure given by matrices is not usable ("" when it is).
  std::string failure;

  bool IsUsable() const {
    return failure.empty() && (!homogeneous_ran || ModulusStage::IsUsable());
  }
  // Evaluations and sweeps of the identification: the homogeneous stage's (its scan's
  // and refinements') and the zones'.
  long TotalEvaluations() const {
    const long stage = homogeneous_ran ? outer.scan_evaluations + outer.evaluations : 0;
    return stage + zones.summary.evaluations;
  }
  long TotalSweeps() const {
    const long stage = homogeneous_ran ? outer.scan_sweeps + sweeps : 0;
    return stage + zones.summary.sweeps;
  }
};

// Step 3 on mcre:'s e^2.
struct McreIdentification {
  std::unique_ptr<McreObjective> objective;  // mcre:'s e^2, with every evaluation of it
  IdentificationSummary outer;
  long search_sweeps = 0;        // the search objective's own sweeps (0: one stage)
  double scan_cost_scale = 0.0;  // [J s] J_rest of the functional outer's scan ran on
};

// The time-step factor k of the search functional (docs/performance.md, issue 41's
// section): the largest k <= search.time_step_factor at which the theta method's
// shift of the search's minimiser stays within search.refine_window / 10. At
// theta = 1/2 a period of angular frequency omega is lengthened by about
// (omega k h)^2 / 12, so a wave speed, and the E that matches it (E ~ c^2), by about
// (omega k h)^2 / 6; omega is the largest rms angular frequency of the model's force
// channels in `data` (its loads' and its supports' measured forces), from their first
// differences. k = 1 at theta != 1/2 (a dissipation of first order), when no force
// channel carries a signal, and k keeps at least kSearchMinimumSteps steps. *force_frequency
// (nullable): that rms frequency [Hz] (0: none).
int SearchTimeStepFactor(const ChannelSet& data, const MatrixModelData& model, double theta,
                         const SearchOptions& search, double* force_frequency = nullptr);
constexpr int kSearchMinimumSteps = 64;

// `data` resampled to `factor` times its step (ResampleMeasurements, its low-pass at
// 0.4 / (factor h)) on floor(m / factor) steps, so a window not a multiple of the
// factor loses its last steps; at 1 the data as they are. Precondition: factor >= 1,
// m / factor >= 1.
ChannelSet SearchData(const ChannelSet& data, int factor);

// The outer loop of config.outer on mcre:'s e^2 of `data` (the identification's
// measurements: selected and pre-filtered) with the model `model` (BarRunModel, or any
// structure given by matrices), its supports treated as mcre.clamp says and
// x = E / outer.initial; model and data must outlive the result's objective. When
// IdentifiesInTwoStages: IdentifyInTwoStages with the search functional
// (SearchMcreOptions, its inner solves to search.inner_tolerance, on SearchData at
// SearchTimeStepFactor). Else Identify,
// its scan of search.scan_points when the search functional is e^2 itself on this model.
// element_maps false: the streaming solves leave the element map out (a stage whose
// solution only warm-starts another). Precondition: config valid.
McreIdentification IdentifyWithMcre(const Config& config, const MatrixModelData& model,
                                    const ChannelSet& data, bool element_maps = true);

// Whether IdentifyWithMcre scans the search functional first: ScansTheSearchFunctional
// (config.h) and the search functional is not e^2 itself on this model
// (SearchIsTheObjective, objective.h: no supports and the same w_u and w_e, say).
bool IdentifiesInTwoStages(const Config& config, const MatrixModelData& model);

// The homogeneous stage up to `solution`: IdentifyWithMcre, then the objective's best
// evaluation, solved once more at E* when another evaluation went lower. model and data:
// as IdentifyWithMcre's, and element_maps. Precondition: config valid. Never throws for
// a failed identification: see IsUsable() and outer.message.
ModulusStage IdentifyHomogeneousModulus(const Config& config, const MatrixModelData& model,
                                        const ChannelSet& data, bool element_maps = true);

// The rest of the stage at E*: with cost_curve, the cost curve e^2(E) on
// output.curve_points points around E* (and over the optimiser's evaluations when they
// reach farther), warm-started point to point from `solution`; then cold_solve. Returns
// the objective of the cold solve, its problem's moduli at E*.
// Precondition: stage->IsUsable().
McreObjective CompleteModulusStage(const Config& config, const MatrixModelData& model,
                                   const ChannelSet& data, bool cost_curve, ModulusStage* stage);

// config with the paper's treatment of the supports (configs/paper_bar_free_free.yaml's
// mcre: section): mcre.clamp measured, w_u and w_e the paper's (McreWeights' defaults),
// and the global scan on the same formulation at w_u = w_e = 1 (search.functional
// measured), one valley where e^2's own may have two, e^2 then refined near its minimum
// (docs/boundaries.md section 9).
Config MeasuredSupportConfig(const Config& config);

// The config a run's many zones are identified with (zone_identification.measured_clamp,
// docs/boundaries.md section 8): MeasuredSupportConfig(config) when the key is on,
// mcre.clamp is trusted and the data hold every support's displacement
// (`supports_displaced`); else config.
Config ConfigForTheZones(const Config& config, bool supports_displaced);

// The config an MCRE run identifies with on `raw` data (before the pre-filter) and the
// data it compares with (`data`, pre-filtered when prefilter.enabled): with mcre.clamp
// trusted and mcre.support_check not off, each support of `model` whose displacement the
// raw data hold is tested (CheckSupports, its force from `data`) and the result logged, a
// contradiction as a warning; when mcre.support_check is switch, the paper's weight
// a = SupportSwitchWeight of the tests (mcre.support_check_ramp_start and _threshold; 0
// otherwise) into *weight, and MeasuredSupportConfig(config) when a >= 1/2, the
// treatment that weighs more, else config. *checks gets the tests
// (none when not tested), *switched whether the config was switched. log false: nothing
// logged (a study's runs).
Config ConfigForTheSupports(const Config& config, const MatrixModelData& model,
                            const ChannelSet& raw, const ChannelSet& data,
                            std::vector<SupportCheck>* checks, bool* switched, double* weight,
                            bool log = true);

// The homogeneous stage of a run whose supports were tested (ConfigForTheSupports gave
// `config` and the paper's weight a): IdentifyHomogeneousModulus with config, and when
// 0 < a < 1 with the other treatment too (`given`, trusted, or MeasuredSupportConfig of
// it), then E* = (1 - a) E_trusted + a E_measured, the stage's solution solved once more
// at that E* with config (docs/boundaries.md section 10). *blend gets both moduli (-1 for
// one not identified). The other identification failing leaves config's stage as it
// is, with a warning. Preconditions: those of IdentifyHomogeneousModulus, a in [0, 1]
// (SupportBlend above IdentificationRun).
ModulusStage IdentifyHomogeneousModulusOfSupports(const Config& given, const Config& config,
                                                  const MatrixModelData& model,
                                                  const ChannelSet& data, bool element_maps,
                                                  SupportBlend* blend);

// Runs steps 2 and 3 on measurements made by LoadMeasurements(config): the
// fields up to `solution` (and wall_time_s); no cost curve, no uncertainty.
// Precondition: config valid. Never throws for a failed identification.
IdentificationRun IdentifyModulus(const Config& config, const ChannelSet& data);

// Why `modulus` [Pa] cannot be reported as identified: it lies on a bound of
// the search (within kOnBoundTolerance relative), where e^2 has no minimum but
// only its least value inside the bounds; "" when it lies inside.
constexpr double kOnBoundTolerance = 1e-6;
std::string ModulusOnBoundMessage(double modulus, const IdentificationOptions& outer);

// Why the identified E cannot be reported: at E* the model misses the measured
// displacements (or forces) by an RMS misfit (run.misfit) above
// kImplausibleMisfitFactor times the RMS of those measurements (run.data, both
// ends), i.e. it explains nothing of them, as data in wrong units or from
// another structure give, whatever the bounds; "" otherwise (the factor's margins:
// docs/hardening.md). Precondition: run.IsUsable() and RunIdentification ran
// (run.misfit is set).
constexpr double kImplausibleMisfitFactor = 10.0;
std::string ImplausibleMisfitMessage(const IdentificationRun& run);

// The first-order uncertainty of the bar's zone moduli (EstimateZoneUncertainty on the
// zoned bar, at run.zones' moduli, from a solve there warm-started from run.solution,
// drawn at run.noise). Precondition: by the MCRE, run.zones ran with usable moduli.
ZoneUncertainty BarZoneUncertainty(const Config& config, const IdentificationRun& run);

// Why the run's results cannot be reported, "" when they can: a structure given by
// matrices says so in run.failure; the bar's identification did not converge
// (outer.message), its E lies on a bound (ModulusOnBoundMessage) or, by the MCRE,
// explains nothing of the data (ImplausibleMisfitMessage).
std::string UnreportableMessage(const IdentificationRun& run);

// The run's error map and sensitivity map at E* (error_map.h): from the stored fields,
// with `problem` (run.config's, on run.model and run.data; its moduli set to E* here),
// or from the element sums a streaming solve gathered on BarRunModel's elements
// (mcre/element_error_map.h). Precondition: run.IsUsable().
ErrorMap BarErrorMap(const Config& config, const IdentificationRun& run,
                     MatrixMcreProblem* problem);

// Runs steps 2 to 4 on measurements made by LoadMeasurements(config); RunLeastSquares
// with outer.functional: least_squares. Precondition: config valid (as LoadConfig
// returns it). Never throws for a failed identification: see IsUsable() and
// outer.message.
//
// From a coarse mesh when UsesCoarseMesh(config) (docs/multilevel.md): steps 2 to 4 on a
// bar of model.coarse_elements elements with the same data, then E refined up a ladder
// of meshes, 10, 100, ... times model.coarse_elements below model.elements, then
// model.elements: on each, the secant from the previous mesh's E*, its first step
// Newton's with the previous curvature (the coarse cost curve's, then each secant's last
// slope), within E* (1 -+ search.refine_window), warm-started from the previous solution
// (its traces for the streaming solver, W interpolated onto the nodes for the stored
// one), its inner solves to at most 10 outer.relative_tolerance, with what
// outer.max_evaluations and outer.max_time left. At the refined E*, the
// error map and the model's channels (coarse_mesh says what stays the coarse mesh's). A
// refinement that ends on an edge of its window fails the run, naming the keys.
IdentificationRun RunIdentification(const Config& config, const ChannelSet& data);

// The bar's MCRE identification starts on a coarse mesh: model.coarse_elements > 0,
// model.elements above it, and inner.method auto or one of the conjugate-gradient
// solvers, which take the previous mesh's warm start (least squares, and the other
// inner methods, run on model.elements alone).
bool UsesCoarseMesh(const Config& config);

// The noise levels of the measurements `data` (as LoadMeasurements made them):
// for synthetic data with noise, those the noise was drawn with (RMS of the
// truth's channel / SNR, noise.h; *source = "synthetic_snr"); otherwise estimated
// from the data's second differences (DifferenceNoiseLevels; "data_differences").
NoiseLevels MeasurementNoiseLevels(const Config& config, const ChannelSet& data,
                                   std::string* source);

// The noise levels that normalise the output-error misfit: MeasurementNoiseLevels of
// the measurements `data` or, for a kind without noise (noise-free data), the RMS of
// the channels in use (`used`: uL, fL, the strain channels), *source then
// "channel_rms".
NoiseLevels LeastSquaresMisfitLevels(const Config& config, const ChannelSet& data,
                                     const ChannelSet& used, std::string* source);

// Runs the least-squares identification on measurements made by
// LoadMeasurements(config), then its fit and cost curve at E* and, with zones, every
// zone from E* (RunLeastSquaresZoneIdentification). Precondition:
// config valid with outer.functional = least_squares. Never throws for a failed
// identification: see IsUsable() and outer.message.
IdentificationRun RunLeastSquares(const Config& config, const ChannelSet& data);

}  // namespace mcrewave
