// Common types of mcrewave: linear algebra aliases, the exception that reports bad
// user input, and every enum of the library, each with its name table (the names
// that travel through YAML and reports) and a to/from-string pair, as Ceres'
// types.h. Iterate a table (kXNames) to list the names of an enum in a message.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <stdexcept>
#include <string>
#include <utility>

namespace mcrewave {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;
// A sparse row, 1 x n: stored by rows, its memory is O(nnz), where a column-major 1 x n
// matrix keeps n + 1 column starts (a thousand full-field channels on 1e5 dofs: 400 MB).
using SparseRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Bad user input (config, CSV, command-line option). The message names the file,
// the key or line, and what was expected. Thrown at load time and caught once in
// identify's main; never used for programmer errors (those are asserts).
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Mass matrix of the bar elements.
enum class MassType {
  kConsistent,  // consistent linear-element mass (rho S h_e / 6) [2 1; 1 2]
  kLumped,      // row-sum lumped mass (rho S h_e / 2) diag(1, 1)
};
inline constexpr std::array<std::pair<MassType, const char*>, 2> kMassTypeNames{{
    {MassType::kConsistent, "consistent"},
    {MassType::kLumped, "lumped"},
}};
const char* MassTypeToString(MassType type);
// Returns false (and leaves *type unchanged) when name is not a MassType name.
bool StringToMassType(const std::string& name, MassType* type);

// Shape of the shock load applied at x = L.
enum class LoadKind {
  kHalfSine,  // F(t) = F0 sin(pi t / t_load) for t <= t_load, 0 after
};
inline constexpr std::array<std::pair<LoadKind, const char*>, 1> kLoadKindNames{{
    {LoadKind::kHalfSine, "half_sine"},
}};
const char* LoadKindToString(LoadKind kind);
bool StringToLoadKind(const std::string& name, LoadKind* kind);

// Where the measurements come from.
enum class DataSource {
  kSynthetic,  // simulated on a truth discretisation, then noise is added
  kCsv,        // read from a measurement CSV file (t,u0,uL,f0,fL)
};
inline constexpr std::array<std::pair<DataSource, const char*>, 2> kDataSourceNames{{
    {DataSource::kSynthetic, "synthetic"},
    {DataSource::kCsv, "csv"},
}};
const char* DataSourceToString(DataSource source);
bool StringToDataSource(const std::string& name, DataSource* source);

// The "truth" that synthetic measurements are sampled from.
enum class TruthModel {
  kFiniteElement,  // the FE + theta model on a mesh and step refined by truth_refinement
  kExact,          // the exact solution of the continuous bar (d'Alembert's reflected pulses)
};
inline constexpr std::array<std::pair<TruthModel, const char*>, 2> kTruthModelNames{{
    {TruthModel::kFiniteElement, "finite_element"},
    {TruthModel::kExact, "exact"},
}};
const char* TruthModelToString(TruthModel model);
bool StringToTruthModel(const std::string& name, TruthModel* model);

// Kind of an interior sensor channel of the bar (CSV header `u@X`, `e@X`).
enum class SensorKind {
  kDisplacement,  // u@X: axial displacement [m] at X m from the clamped end
  kStrain,        // e@X: axial strain [-] at X, BarModel::StrainRow (compression negative)
};
inline constexpr std::array<std::pair<SensorKind, const char*>, 2> kSensorKindNames{{
    {SensorKind::kDisplacement, "displacement"},
    {SensorKind::kStrain, "strain"},
}};
const char* SensorKindToString(SensorKind kind);
bool StringToSensorKind(const std::string& name, SensorKind* kind);

// Kind of a measured channel (data/channel_set.h): what its values are.
enum class ChannelKind {
  kDisplacement,  // a displacement [m]
  kStrain,        // a strain [-]
  kForce,         // a force [N]
};
inline constexpr std::array<std::pair<ChannelKind, const char*>, 3> kChannelKindNames{{
    {ChannelKind::kDisplacement, "displacement"},
    {ChannelKind::kStrain, "strain"},
    {ChannelKind::kForce, "force"},
}};
const char* ChannelKindToString(ChannelKind kind);
bool StringToChannelKind(const std::string& name, ChannelKind* kind);

// How the identification's zones of constant modulus are laid over the bar's elements
// (model/bar_model.h, ZoneLayout).
enum class Zoning {
  kEqual,       // model.zone_count zones of equal length
  kPerElement,  // one zone per element
  kBoundaries,  // zones between the interior boundaries model.zone_boundaries [m]
  kGrid,        // the boxes of a regular grid over the elements' positions (model.zone_grid)
};
inline constexpr std::array<std::pair<Zoning, const char*>, 4> kZoningNames{{
    {Zoning::kEqual, "equal"},
    {Zoning::kPerElement, "per_element"},
    {Zoning::kBoundaries, "boundaries"},
    {Zoning::kGrid, "grid"},
}};
const char* ZoningToString(Zoning zoning);
bool StringToZoning(const std::string& name, Zoning* zoning);

// The structure a run identifies (config key model.kind).
enum class ModelKind {
  kBar,     // the built-in bar of the model: section (model/bar_model.h)
  kMatrix,  // matrices from another finite-element code, named by model.manifest
            // (model/matrix_export.h, docs/matrix_models.md)
};
inline constexpr std::array<std::pair<ModelKind, const char*>, 2> kModelKindNames{{
    {ModelKind::kBar, "bar"},
    {ModelKind::kMatrix, "matrix"},
}};
const char* ModelKindToString(ModelKind kind);
bool StringToModelKind(const std::string& name, ModelKind* kind);

// How the MCRE treats the bar's clamp at x = 0 (config key mcre.clamp;
// docs/trusted_clamp.md).
enum class ClampModel {
  kMeasured,  // the paper's: known only through the measured u0 and f0; free-free
              // model, f0 a load with its alpha term, u0 an output with its beta term
  kTrusted,   // u(0) = 0 imposed exactly (the least-squares comparator's assumption);
              // f0 compared with the model's clamp reaction as a measured output
  kPinned,    // the paper's free-free model with the known u(0) = 0 as the datum of
              // u0 (weight w_u0, not the measured u0) and f0 a load of weight w_r
};
inline constexpr std::array<std::pair<ClampModel, const char*>, 3> kClampModelNames{{
    {ClampModel::kMeasured, "measured"},
    {ClampModel::kTrusted, "trusted"},
    {ClampModel::kPinned, "pinned"},
}};
const char* ClampModelToString(ClampModel model);
bool StringToClampModel(const std::string& name, ClampModel* model);

// What a run does when its data contradict a trusted support (config key
// mcre.support_check; mcre/support_check.h, docs/boundaries.md).
enum class SupportCheckAction {
  kSwitch,  // test; a contradicted support is treated as measured (the paper's free-free
            // formulation, its weights and scan), with a warning
  kWarn,    // test and warn; the support stays trusted
  kOff,     // no test
};
inline constexpr std::array<std::pair<SupportCheckAction, const char*>, 3> kSupportCheckActionNames{
    {
        {SupportCheckAction::kSwitch, "switch"},
        {SupportCheckAction::kWarn, "warn"},
        {SupportCheckAction::kOff, "off"},
    }};
const char* SupportCheckActionToString(SupportCheckAction action);
bool StringToSupportCheckAction(const std::string& name, SupportCheckAction* action);

// How BarMatrixModel (model/matrix_export.h) exports the bar's clamp at x = 0.
enum class BarClampExport {
  kLoadAndSensor,  // the load f0 (e_0) and the sensor u0 (e_0^T): the free-free model
  kSupport,        // a support "clamp" at dof 0, channels f0 and u0, treated as mcre.clamp says
};
inline constexpr std::array<std::pair<BarClampExport, const char*>, 2> kBarClampExportNames{{
    {BarClampExport::kLoadAndSensor, "load_and_sensor"},
    {BarClampExport::kSupport, "support"},
}};
const char* BarClampExportToString(BarClampExport clamp);
bool StringToBarClampExport(const std::string& name, BarClampExport* clamp);

// The functional the global search of a bar's identification scans (config key
// search.functional; docs/trusted_clamp.md section 10).
enum class SearchFunctional {
  kPinned,    // the pinned clamp's e^2 with the search: section's weights (one valley over
              // the bounds), then mcre:'s e^2 refined near its minimum
  kSame,      // mcre:'s e^2 itself, scanned and refined
  kMeasured,  // the measured clamp's e^2 (the paper's free-free formulation) with the
              // search: section's w_u and w_e, then mcre:'s e^2 refined near its minimum
              // (docs/boundaries.md section 9)
};
inline constexpr std::array<std::pair<SearchFunctional, const char*>, 3> kSearchFunctionalNames{{
    {SearchFunctional::kPinned, "pinned"},
    {SearchFunctional::kSame, "same"},
    {SearchFunctional::kMeasured, "measured"},
}};
const char* SearchFunctionalToString(SearchFunctional functional);
bool StringToSearchFunctional(const std::string& name, SearchFunctional* functional);

// How the iteration matrix S = M + h^2 theta^2 K is factorised.
enum class Factorization {
  kAutomatic,  // kBand when the band of S is narrow (ChooseFactorization), else kSparse
  kBand,       // band LDL^T (tridiagonal: the twisted factorisation), band_matrix.h
  kSparse,     // sparse LDL^T with AMD ordering, sparse_theta_step.h
};
inline constexpr std::array<std::pair<Factorization, const char*>, 3> kFactorizationNames{{
    {Factorization::kAutomatic, "automatic"},
    {Factorization::kBand, "band"},
    {Factorization::kSparse, "sparse"},
}};
const char* FactorizationToString(Factorization factorization);
bool StringToFactorization(const std::string& name, Factorization* factorization);

// How output-error least squares gets its gradient over Z zone moduli
// (least_squares/matrix_output_error_objective.h; config key
// zone_identification.least_squares_gradient).
enum class LeastSquaresGradient {
  kForwardSensitivities,  // one sensitivity sweep per zone: 1 + Z sweeps
  kAdjoint,               // one backward sweep of the discrete adjoint, whatever Z: 2 sweeps
};
inline constexpr std::array<std::pair<LeastSquaresGradient, const char*>, 2>
    kLeastSquaresGradientNames{{
        {LeastSquaresGradient::kForwardSensitivities, "forward_sensitivities"},
        {LeastSquaresGradient::kAdjoint, "adjoint"},
    }};
const char* LeastSquaresGradientToString(LeastSquaresGradient gradient);
bool StringToLeastSquaresGradient(const std::string& name, LeastSquaresGradient* gradient);

// How a sparse matrix is written.
enum class MatrixMarketStorage {
  kGeneral,    // every stored entry
  kSymmetric,  // the lower triangle (i >= j) only; the matrix is taken as symmetric
};
inline constexpr std::array<std::pair<MatrixMarketStorage, const char*>, 2> kMatrixMarketStorageNames{{
    {MatrixMarketStorage::kGeneral, "general"},
    {MatrixMarketStorage::kSymmetric, "symmetric"},
}};
const char* MatrixMarketStorageToString(MatrixMarketStorage storage);
bool StringToMatrixMarketStorage(const std::string& name, MatrixMarketStorage* storage);

enum class CoupledSolverType {
  kAllAtOnce,
  kRelaxation,
  kAdaptiveRelaxation,
  kConjugateGradient,
  kRiccati,
  kSingleShooting,
  kMultipleShooting,
  // Conjugate gradients on the sensor traces (docs/streaming.md): no space-time field
  // is stored, the states at checkpoints, O(n sqrt(m)) memory.
  kStreamingConjugateGradient,
  // Not a solver of its own: conjugate_gradient when its stored fields fit
  // CoupledSolverOptions::max_field_bytes, streaming_conjugate_gradient when they do not
  // (on a StreamingCoupledProblem, every model). Resolved
  // by ResolveCoupledSolverType (mcre/coupled_solver.h). Last, so that the solvers keep
  // their order in the lists of names.
  kAuto,
};
inline constexpr std::array<std::pair<CoupledSolverType, const char*>, 9> kCoupledSolverTypeNames{{
    {CoupledSolverType::kAllAtOnce, "all_at_once"},
    {CoupledSolverType::kRelaxation, "relaxation"},
    {CoupledSolverType::kAdaptiveRelaxation, "adaptive_relaxation"},
    {CoupledSolverType::kConjugateGradient, "conjugate_gradient"},
    {CoupledSolverType::kRiccati, "riccati"},
    {CoupledSolverType::kSingleShooting, "single_shooting"},
    {CoupledSolverType::kMultipleShooting, "multiple_shooting"},
    {CoupledSolverType::kStreamingConjugateGradient, "streaming_conjugate_gradient"},
    {CoupledSolverType::kAuto, "auto"},
}};
const char* CoupledSolverTypeToString(CoupledSolverType type);
bool StringToCoupledSolverType(const std::string& name, CoupledSolverType* type);

// The preconditioner of the streaming CG (inner.preconditioner; docs/streaming.md
// section 6).
enum class TracePreconditioner {
  kNone,  // CG on the traces as it is
  // M = I - L at moduli near the current ones, as a dense Cholesky factor over the
  // traces (MatrixMcreProblem::SymmetricTraceOperator), rebuilt when a modulus moved
  // more than CoupledSolverOptions::preconditioner_rebuild_change.
  kDenseTraces,
};
inline constexpr std::array<std::pair<TracePreconditioner, const char*>, 2>
    kTracePreconditionerNames{{
        {TracePreconditioner::kNone, "none"},
        {TracePreconditioner::kDenseTraces, "dense_traces"},
    }};
const char* TracePreconditionerToString(TracePreconditioner preconditioner);
bool StringToTracePreconditioner(const std::string& name, TracePreconditioner* preconditioner);

enum class TerminationType {
  kConvergence,    // the residual reached the tolerance
  kNoConvergence,  // the iteration limit was reached first
  kDivergence,     // the residual grew (or became non-finite): the iteration diverges
  kFailure,        // refused or broke down (problem too large, singular system...)
};
inline constexpr std::array<std::pair<TerminationType, const char*>, 4> kTerminationTypeNames{{
    {TerminationType::kConvergence, "convergence"},
    {TerminationType::kNoConvergence, "no_convergence"},
    {TerminationType::kDivergence, "divergence"},
    {TerminationType::kFailure, "failure"},
}};
const char* TerminationTypeToString(TerminationType type);
bool StringToTerminationType(const std::string& name, TerminationType* type);

// The functional the outer loop minimises over E. Identify minimises whatever
// ModulusObjective it is given; identify run (app/identification_run.h) builds it
// from this choice.
enum class OuterFunctional {
  kMcre,          // the MCRE cost e^2(E) (McreObjective)
  kLeastSquares,  // output-error least squares J(E) (OutputErrorModulusObjective), the comparator
};
inline constexpr std::array<std::pair<OuterFunctional, const char*>, 2> kOuterFunctionalNames{{
    {OuterFunctional::kMcre, "mcre"},
    {OuterFunctional::kLeastSquares, "least_squares"},
}};
const char* OuterFunctionalToString(OuterFunctional functional);
bool StringToOuterFunctional(const std::string& name, OuterFunctional* functional);

enum class OptimizerType {
  kNlopt,
  kCeres,
};
inline constexpr std::array<std::pair<OptimizerType, const char*>, 2> kOptimizerTypeNames{{
    {OptimizerType::kNlopt, "nlopt"},
    {OptimizerType::kCeres, "ceres"},
}};
const char* OptimizerTypeToString(OptimizerType type);
bool StringToOptimizerType(const std::string& name, OptimizerType* type);

// The algorithm of an optimiser (optim/algorithms.h says which offers which), for one
// parameter (outer.algorithm) or many (zone_identification.algorithm).
enum class OuterAlgorithm {
  kDefault,  // bobyqa for nlopt, lbfgs for ceres
  kBobyqa,   // nlopt: Powell's BOBYQA, quadratic models, derivative-free, bounded
  kCobyla,   // nlopt: Powell's COBYLA, linear models, derivative-free, bounded
  kSbplx,    // nlopt: Subplex (Nelder-Mead on subspaces), derivative-free, bounded
  kMma,      // nlopt: method of moving asymptotes, adjoint gradient, bounded
  kLbfgs,    // nlopt or ceres: limited-memory BFGS, adjoint gradient
  kSlsqp,    // nlopt: sequential quadratic programming, adjoint gradient, bounded
  kBfgs,     // ceres: dense BFGS, adjoint gradient
  kBrent,    // under nlopt, one parameter: Brent's bounded minimiser (mcrewave's own),
             // derivative-free
  kSecant,   // under nlopt, one parameter: a safeguarded secant iteration on the adjoint
             // gradient (mcrewave's own)
};
inline constexpr std::array<std::pair<OuterAlgorithm, const char*>, 10> kOuterAlgorithmNames{{
    {OuterAlgorithm::kDefault, "default"},
    {OuterAlgorithm::kBobyqa, "bobyqa"},
    {OuterAlgorithm::kCobyla, "cobyla"},
    {OuterAlgorithm::kSbplx, "sbplx"},
    {OuterAlgorithm::kMma, "mma"},
    {OuterAlgorithm::kLbfgs, "lbfgs"},
    {OuterAlgorithm::kSlsqp, "slsqp"},
    {OuterAlgorithm::kBfgs, "bfgs"},
    {OuterAlgorithm::kBrent, "brent"},
    {OuterAlgorithm::kSecant, "secant"},
}};
const char* OuterAlgorithmToString(OuterAlgorithm algorithm);
bool StringToOuterAlgorithm(const std::string& name, OuterAlgorithm* algorithm);

enum class RegularizationKind {
  kNone,
  kTikhonov,
  kTotalVariation,
};
inline constexpr std::array<std::pair<RegularizationKind, const char*>, 3> kRegularizationKindNames{{
    {RegularizationKind::kNone, "none"},
    {RegularizationKind::kTikhonov, "tikhonov"},
    {RegularizationKind::kTotalVariation, "total_variation"},
}};
const char* RegularizationKindToString(RegularizationKind kind);
bool StringToRegularizationKind(const std::string& name, RegularizationKind* kind);

// Which zones' jumps of log E the penalty counts.
enum class ZoneNeighbourhood {
  kOrder,        // consecutive zones in the model's order (along the bar)
  kSharedNodes,  // zones whose stiffness shares a node, weighted by the dofs shared
};
inline constexpr std::array<std::pair<ZoneNeighbourhood, const char*>, 2> kZoneNeighbourhoodNames{{
    {ZoneNeighbourhood::kOrder, "order"},
    {ZoneNeighbourhood::kSharedNodes, "shared_nodes"},
}};
const char* ZoneNeighbourhoodToString(ZoneNeighbourhood neighbourhood);
bool StringToZoneNeighbourhood(const std::string& name, ZoneNeighbourhood* neighbourhood);

// How an automatic weight is chosen.
enum class WeightRule {
  kLCurve,       // the L-curve's corner, down to the first weight that meets the target
  kDiscrepancy,  // the discrepancy principle, the L-curve when its target is missed
};
inline constexpr std::array<std::pair<WeightRule, const char*>, 2> kWeightRuleNames{{
    {WeightRule::kLCurve, "l_curve"},
    {WeightRule::kDiscrepancy, "discrepancy"},
}};
const char* WeightRuleToString(WeightRule rule);
bool StringToWeightRule(const std::string& name, WeightRule* rule);

// The margin over the misfit floor when no weight meets the discrepancy target and the
// L-curve has no corner (optim/regularization.h).
enum class FloorMargin {
  kTenPercent,  // the floor + 10 %
  kNoiseFit,    // the floor + what the free zones fit of the noise (the draws' spread)
};
inline constexpr std::array<std::pair<FloorMargin, const char*>, 2> kFloorMarginNames{{
    {FloorMargin::kTenPercent, "ten_percent"},
    {FloorMargin::kNoiseFit, "noise_fit"},
}};
const char* FloorMarginToString(FloorMargin margin);
bool StringToFloorMargin(const std::string& name, FloorMargin* margin);

enum class StudyKind {
  kRobustness,
  kRelaxation,
  kCostCurves,
  kAll,         // the three above
  kDamage,      // damage localisation with zones and sensors (damage_study.h); not in kAll
  kComparator,  // MCRE against output-error least squares (comparator_study.h); not in kAll
  kReadme,      // no study: only results/README.md gathered from the study folders there
};
inline constexpr std::array<std::pair<StudyKind, const char*>, 7> kStudyKindNames{{
    {StudyKind::kRobustness, "robustness"},
    {StudyKind::kRelaxation, "relaxation"},
    {StudyKind::kCostCurves, "cost_curves"},
    {StudyKind::kAll, "all"},
    {StudyKind::kDamage, "damage"},
    {StudyKind::kComparator, "comparator"},
    {StudyKind::kReadme, "readme"},
}};
const char* StudyKindToString(StudyKind kind);
bool StringToStudyKind(const std::string& name, StudyKind* kind);

}  // namespace mcrewave
