// core/types.h: every enum's name table ties each value to one name and back, and
// the XToString / StringToX pairs read it.
#include "mcrewave/core/types.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace mcrewave {
namespace {

// Every entry of `table` round-trips through the pair, the names are distinct and
// non-empty, and an unknown name is refused with the value left unchanged.
template <typename Enum, std::size_t N>
void ExpectTableRoundTrips(const std::array<std::pair<Enum, const char*>, N>& table,
                           const char* (*to_string)(Enum),
                           bool (*from_string)(const std::string&, Enum*)) {
  std::set<std::string> names;
  std::set<int> values;
  for (const auto& [value, name] : table) {
    EXPECT_STREQ(to_string(value), name);
    Enum read = table[0].first;
    ASSERT_TRUE(from_string(name, &read)) << name;
    EXPECT_EQ(read, value) << name;
    EXPECT_FALSE(std::string(name).empty());
    names.insert(name);
    values.insert(static_cast<int>(value));
  }
  EXPECT_EQ(names.size(), N);
  EXPECT_EQ(values.size(), N);
  Enum unchanged = table[N - 1].first;
  EXPECT_FALSE(from_string("no_such_name", &unchanged));
  EXPECT_EQ(unchanged, table[N - 1].first);
}

TEST(TypesTest, EveryEnumRoundTripsThroughItsNameTable) {
  ExpectTableRoundTrips(kMassTypeNames, MassTypeToString, StringToMassType);
  ExpectTableRoundTrips(kLoadKindNames, LoadKindToString, StringToLoadKind);
  ExpectTableRoundTrips(kDataSourceNames, DataSourceToString, StringToDataSource);
  ExpectTableRoundTrips(kTruthModelNames, TruthModelToString, StringToTruthModel);
  ExpectTableRoundTrips(kSensorKindNames, SensorKindToString, StringToSensorKind);
  ExpectTableRoundTrips(kChannelKindNames, ChannelKindToString, StringToChannelKind);
  ExpectTableRoundTrips(kZoningNames, ZoningToString, StringToZoning);
  ExpectTableRoundTrips(kModelKindNames, ModelKindToString, StringToModelKind);
  ExpectTableRoundTrips(kClampModelNames, ClampModelToString, StringToClampModel);
  ExpectTableRoundTrips(kSupportCheckActionNames, SupportCheckActionToString,
                        StringToSupportCheckAction);
  ExpectTableRoundTrips(kBarClampExportNames, BarClampExportToString, StringToBarClampExport);
  ExpectTableRoundTrips(kSearchFunctionalNames, SearchFunctionalToString, StringToSearchFunctional);
  ExpectTableRoundTrips(kFactorizationNames, FactorizationToString, StringToFactorization);
  ExpectTableRoundTrips(kLeastSquaresGradientNames, LeastSquaresGradientToString,
                        StringToLeastSquaresGradient);
  ExpectTableRoundTrips(kMatrixMarketStorageNames, MatrixMarketStorageToString,
                        StringToMatrixMarketStorage);
  ExpectTableRoundTrips(kCoupledSolverTypeNames, CoupledSolverTypeToString,
                        StringToCoupledSolverType);
  ExpectTableRoundTrips(kTerminationTypeNames, TerminationTypeToString, StringToTerminationType);
  ExpectTableRoundTrips(kOuterFunctionalNames, OuterFunctionalToString, StringToOuterFunctional);
  ExpectTableRoundTrips(kOptimizerTypeNames, OptimizerTypeToString, StringToOptimizerType);
  ExpectTableRoundTrips(kOuterAlgorithmNames, OuterAlgorithmToString, StringToOuterAlgorithm);
  ExpectTableRoundTrips(kRegularizationKindNames, RegularizationKindToString,
                        StringToRegularizationKind);
  ExpectTableRoundTrips(kZoneNeighbourhoodNames, ZoneNeighbourhoodToString,
                        StringToZoneNeighbourhood);
  ExpectTableRoundTrips(kWeightRuleNames, WeightRuleToString, StringToWeightRule);
  ExpectTableRoundTrips(kFloorMarginNames, FloorMarginToString, StringToFloorMargin);
  ExpectTableRoundTrips(kStudyKindNames, StudyKindToString, StringToStudyKind);
}

// The names the config and summary.yaml spell (a table edit that renames one fails here).
TEST(TypesTest, NamesAreTheConfigsSpelling) {
  EXPECT_STREQ(TerminationTypeToString(TerminationType::kNoConvergence), "no_convergence");
  EXPECT_STREQ(CoupledSolverTypeToString(CoupledSolverType::kStreamingConjugateGradient),
               "streaming_conjugate_gradient");
  EXPECT_STREQ(StudyKindToString(StudyKind::kCostCurves), "cost_curves");
  EXPECT_STREQ(OuterAlgorithmToString(OuterAlgorithm::kBrent), "brent");
  EXPECT_STREQ(OuterAlgorithmToString(OuterAlgorithm::kSecant), "secant");
  EXPECT_STREQ(WeightRuleToString(WeightRule::kLCurve), "l_curve");
}

}  // namespace
}  // namespace mcrewave
