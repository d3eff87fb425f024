#include "mcrewave/core/types.h"

#include "core/enum_names.h"

namespace mcrewave {

// Each pair reads the enum's table in types.h, the only place where a name is tied
// to a value.

const char* MassTypeToString(MassType type) { return internal::ToName(kMassTypeNames, type); }
bool StringToMassType(const std::string& name, MassType* type) {
  return internal::FromName(kMassTypeNames, name, type);
}

const char* LoadKindToString(LoadKind kind) { return internal::ToName(kLoadKindNames, kind); }
bool StringToLoadKind(const std::string& name, LoadKind* kind) {
  return internal::FromName(kLoadKindNames, name, kind);
}

const char* DataSourceToString(DataSource source) { return internal::ToName(kDataSourceNames, source); }
bool StringToDataSource(const std::string& name, DataSource* source) {
  return internal::FromName(kDataSourceNames, name, source);
}

const char* TruthModelToString(TruthModel model) { return internal::ToName(kTruthModelNames, model); }
bool StringToTruthModel(const std::string& name, TruthModel* model) {
  return internal::FromName(kTruthModelNames, name, model);
}

const char* SensorKindToString(SensorKind kind) { return internal::ToName(kSensorKindNames, kind); }
bool StringToSensorKind(const std::string& name, SensorKind* kind) {
  return internal::FromName(kSensorKindNames, name, kind);
}

const char* ChannelKindToString(ChannelKind kind) {
  return internal::ToName(kChannelKindNames, kind);
}
bool StringToChannelKind(const std::string& name, ChannelKind* kind) {
  return internal::FromName(kChannelKindNames, name, kind);
}

const char* ZoningToString(Zoning zoning) { return internal::ToName(kZoningNames, zoning); }
bool StringToZoning(const std::string& name, Zoning* zoning) {
  return internal::FromName(kZoningNames, name, zoning);
}

const char* ModelKindToString(ModelKind kind) { return internal::ToName(kModelKindNames, kind); }
bool StringToModelKind(const std::string& name, ModelKind* kind) {
  return internal::FromName(kModelKindNames, name, kind);
}

const char* ClampModelToString(ClampModel model) { return internal::ToName(kClampModelNames, model); }
bool StringToClampModel(const std::string& name, ClampModel* model) {
  return internal::FromName(kClampModelNames, name, model);
}

const char* SupportCheckActionToString(SupportCheckAction action) {
  return internal::ToName(kSupportCheckActionNames, action);
}
bool StringToSupportCheckAction(const std::string& name, SupportCheckAction* action) {
  return internal::FromName(kSupportCheckActionNames, name, action);
}

const char* BarClampExportToString(BarClampExport clamp) {
  return internal::ToName(kBarClampExportNames, clamp);
}
bool StringToBarClampExport(const std::string& name, BarClampExport* clamp) {
  return internal::FromName(kBarClampExportNames, name, clamp);
}

const char* SearchFunctionalToString(SearchFunctional functional) { return internal::ToName(kSearchFunctionalNames, functional); }
bool StringToSearchFunctional(const std::string& name, SearchFunctional* functional) {
  return internal::FromName(kSearchFunctionalNames, name, functional);
}

const char* LeastSquaresGradientToString(LeastSquaresGradient gradient) {
  return internal::ToName(kLeastSquaresGradientNames, gradient);
}
bool StringToLeastSquaresGradient(const std::string& name, LeastSquaresGradient* gradient) {
  return internal::FromName(kLeastSquaresGradientNames, name, gradient);
}
const char* FactorizationToString(Factorization factorization) { return internal::ToName(kFactorizationNames, factorization); }
bool StringToFactorization(const std::string& name, Factorization* factorization) {
  return internal::FromName(kFactorizationNames, name, factorization);
}

const char* MatrixMarketStorageToString(MatrixMarketStorage storage) { return internal::ToName(kMatrixMarketStorageNames, storage); }
bool StringToMatrixMarketStorage(const std::string& name, MatrixMarketStorage* storage) {
  return internal::FromName(kMatrixMarketStorageNames, name, storage);
}

const char* CoupledSolverTypeToString(CoupledSolverType type) { return internal::ToName(kCoupledSolverTypeNames, type); }
bool StringToCoupledSolverType(const std::string& name, CoupledSolverType* type) {
  return internal::FromName(kCoupledSolverTypeNames, name, type);
}

const char* TracePreconditionerToString(TracePreconditioner preconditioner) {
  return internal::ToName(kTracePreconditionerNames, preconditioner);
}
bool StringToTracePreconditioner(const std::string& name, TracePreconditioner* preconditioner) {
  return internal::FromName(kTracePreconditionerNames, name, preconditioner);
}

const char* TerminationTypeToString(TerminationType type) { return internal::ToName(kTerminationTypeNames, type); }
bool StringToTerminationType(const std::string& name, TerminationType* type) {
  return internal::FromName(kTerminationTypeNames, name, type);
}

const char* OuterFunctionalToString(OuterFunctional functional) { return internal::ToName(kOuterFunctionalNames, functional); }
bool StringToOuterFunctional(const std::string& name, OuterFunctional* functional) {
  return internal::FromName(kOuterFunctionalNames, name, functional);
}

const char* OptimizerTypeToString(OptimizerType type) { return internal::ToName(kOptimizerTypeNames, type); }
bool StringToOptimizerType(const std::string& name, OptimizerType* type) {
  return internal::FromName(kOptimizerTypeNames, name, type);
}

const char* OuterAlgorithmToString(OuterAlgorithm algorithm) { return internal::ToName(kOuterAlgorithmNames, algorithm); }
bool StringToOuterAlgorithm(const std::string& name, OuterAlgorithm* algorithm) {
  return internal::FromName(kOuterAlgorithmNames, name, algorithm);
}

const char* ZoneNeighbourhoodToString(ZoneNeighbourhood neighbourhood) {
  return internal::ToName(kZoneNeighbourhoodNames, neighbourhood);
}
bool StringToZoneNeighbourhood(const std::string& name, ZoneNeighbourhood* neighbourhood) {
  return internal::FromName(kZoneNeighbourhoodNames, name, neighbourhood);
}
const char* RegularizationKindToString(RegularizationKind kind) { return internal::ToName(kRegularizationKindNames, kind); }
bool StringToRegularizationKind(const std::string& name, RegularizationKind* kind) {
  return internal::FromName(kRegularizationKindNames, name, kind);
}

const char* WeightRuleToString(WeightRule rule) { return internal::ToName(kWeightRuleNames, rule); }
bool StringToWeightRule(const std::string& name, WeightRule* rule) {
  return internal::FromName(kWeightRuleNames, name, rule);
}

const char* FloorMarginToString(FloorMargin margin) {
  return internal::ToName(kFloorMarginNames, margin);
}
bool StringToFloorMargin(const std::string& name, FloorMargin* margin) {
  return internal::FromName(kFloorMarginNames, name, margin);
}

const char* StudyKindToString(StudyKind kind) { return internal::ToName(kStudyKindNames, kind); }
bool StringToStudyKind(const std::string& name, StudyKind* kind) {
  return internal::FromName(kStudyKindNames, name, kind);
}

}  // namespace mcrewave
