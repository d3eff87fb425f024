// Common types of mcrewave: linear algebra aliases, the enums that travel through
// YAML as names (each with a to/from-string pair, as Ceres' types.h), and the
// exception that reports bad user input.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <stdexcept>
#include <string>

namespace mcrewave {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;

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
const char* MassTypeToString(MassType type);
// Returns false (and leaves *type unchanged) when name is not a MassType name.
bool StringToMassType(const std::string& name, MassType* type);

// Shape of the shock load applied at x = L.
enum class LoadKind {
  kHalfSine,  // F(t) = F0 sin(pi t / t_load) for t <= t_load, 0 after
};
const char* LoadKindToString(LoadKind kind);
bool StringToLoadKind(const std::string& name, LoadKind* kind);

// Where the measurements come from.
enum class DataSource {
  kSynthetic,  // simulated on a truth discretisation, then noise is added
  kCsv,        // read from a measurement CSV file (t,u0,uL,f0,fL)
};
const char* DataSourceToString(DataSource source);
bool StringToDataSource(const std::string& name, DataSource* source);

// The "truth" that synthetic measurements are sampled from.
enum class TruthModel {
  kFiniteElement,  // the FE + theta model on a mesh and step refined by truth_refinement
  kExact,          // the exact solution of the continuous bar (d'Alembert's reflected pulses)
};
const char* TruthModelToString(TruthModel model);
bool StringToTruthModel(const std::string& name, TruthModel* model);

// Kind of an interior sensor channel of the bar (CSV header `u@X`, `e@X`).
enum class SensorKind {
  kDisplacement,  // u@X: axial displacement [m] at X m from the clamped end
  kStrain,        // e@X: axial strain [-] at X, BarModel::StrainRow (compression negative)
};
const char* SensorKindToString(SensorKind kind);
bool StringToSensorKind(const std::string& name, SensorKind* kind);

// How the identification's zones of constant modulus are laid over the bar's elements
// (model/bar_model.h, ZoneLayout).
enum class Zoning {
  kEqual,       // model.zone_count zones of equal length
  kPerElement,  // one zone per element
  kBoundaries,  // zones between the interior boundaries model.zone_boundaries [m]
};
const char* ZoningToString(Zoning zoning);
bool StringToZoning(const std::string& name, Zoning* zoning);

// The structure a run identifies (config key model.kind).
enum class ModelKind {
  kBar,     // the built-in bar of the model: section (model/bar_model.h)
  kMatrix,  // matrices from another finite-element code, named by model.manifest
            // (model/matrix_export.h, docs/matrix_models.md)
};
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
const char* ClampModelToString(ClampModel model);
bool StringToClampModel(const std::string& name, ClampModel* model);

// The functional the global search of a bar's identification scans (config key
// search.functional; docs/trusted_clamp.md section 10).
enum class SearchFunctional {
  kPinned,  // the pinned clamp's e^2 with the search: section's weights (one valley over
            // the bounds), then mcre:'s e^2 refined near its minimum
  kSame,    // mcre:'s e^2 itself, scanned and refined
};
const char* SearchFunctionalToString(SearchFunctional functional);
bool StringToSearchFunctional(const std::string& name, SearchFunctional* functional);

}  // namespace mcrewave
