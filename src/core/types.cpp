#include "mcrewave/core/types.h"

#include <array>
#include <utility>

#include "core/enum_names.h"

namespace mcrewave {
namespace {

using internal::FromName;
using internal::ToName;

// One table per enum: the only place where a name is tied to a value.

constexpr std::array<std::pair<MassType, const char*>, 2> kMassTypes{
    {{MassType::kConsistent, "consistent"}, {MassType::kLumped, "lumped"}}};
constexpr std::array<std::pair<LoadKind, const char*>, 1> kLoadKinds{
    {{LoadKind::kHalfSine, "half_sine"}}};
constexpr std::array<std::pair<DataSource, const char*>, 2> kDataSources{
    {{DataSource::kSynthetic, "synthetic"}, {DataSource::kCsv, "csv"}}};
constexpr std::array<std::pair<TruthModel, const char*>, 2> kTruthModels{
    {{TruthModel::kFiniteElement, "finite_element"}, {TruthModel::kExact, "exact"}}};

constexpr std::array<std::pair<SensorKind, const char*>, 2> kSensorKinds{
    {{SensorKind::kDisplacement, "displacement"}, {SensorKind::kStrain, "strain"}}};
constexpr std::array<std::pair<ModelKind, const char*>, 2> kModelKinds{
    {{ModelKind::kBar, "bar"}, {ModelKind::kMatrix, "matrix"}}};
constexpr std::array<std::pair<ClampModel, const char*>, 3> kClampModels{
    {{ClampModel::kMeasured, "measured"},
     {ClampModel::kTrusted, "trusted"},
     {ClampModel::kPinned, "pinned"}}};
constexpr std::array<std::pair<SearchFunctional, const char*>, 2> kSearchFunctionals{
    {{SearchFunctional::kPinned, "pinned"}, {SearchFunctional::kSame, "same"}}};
constexpr std::array<std::pair<Zoning, const char*>, 3> kZonings{{{Zoning::kEqual, "equal"},
                                                                  {Zoning::kPerElement, "per_element"},
                                                                  {Zoning::kBoundaries, "boundaries"}}};

}  // namespace

const char* SensorKindToString(SensorKind kind) { return ToName(kSensorKinds, kind); }
bool StringToSensorKind(const std::string& name, SensorKind* kind) {
  return FromName(kSensorKinds, name, kind);
}
const char* ZoningToString(Zoning zoning) { return ToName(kZonings, zoning); }
bool StringToZoning(const std::string& name, Zoning* zoning) {
  return FromName(kZonings, name, zoning);
}
const char* MassTypeToString(MassType type) { return ToName(kMassTypes, type); }
bool StringToMassType(const std::string& name, MassType* type) {
  return FromName(kMassTypes, name, type);
}
const char* LoadKindToString(LoadKind kind) { return ToName(kLoadKinds, kind); }
bool StringToLoadKind(const std::string& name, LoadKind* kind) {
  return FromName(kLoadKinds, name, kind);
}
const char* DataSourceToString(DataSource source) { return ToName(kDataSources, source); }
bool StringToDataSource(const std::string& name, DataSource* source) {
  return FromName(kDataSources, name, source);
}
const char* TruthModelToString(TruthModel model) { return ToName(kTruthModels, model); }
bool StringToTruthModel(const std::string& name, TruthModel* model) {
  return FromName(kTruthModels, name, model);
}

const char* ModelKindToString(ModelKind kind) { return ToName(kModelKinds, kind); }
bool StringToModelKind(const std::string& name, ModelKind* kind) {
  return FromName(kModelKinds, name, kind);
}

const char* ClampModelToString(ClampModel model) { return ToName(kClampModels, model); }
bool StringToClampModel(const std::string& name, ClampModel* model) {
  return FromName(kClampModels, name, model);
}

const char* SearchFunctionalToString(SearchFunctional functional) {
  return ToName(kSearchFunctionals, functional);
}
bool StringToSearchFunctional(const std::string& name, SearchFunctional* functional) {
  return FromName(kSearchFunctionals, name, functional);
}

}  // namespace mcrewave
