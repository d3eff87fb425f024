// core/format.h: the one number formatter, format by format.
#include "mcrewave/core/format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace mcrewave {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(FormatTest, RoundTripIsTheShortestTextThatReadsBackExactly) {
  EXPECT_EQ(FormatNumber(0.1, kYamlRoundTrip), "0.1");
  EXPECT_EQ(FormatNumber(199733086714.89133, kYamlRoundTrip), "199733086714.89133");
  EXPECT_EQ(FormatNumber(1.0 / 3.0, kYamlRoundTrip), "0.3333333333333333");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, kYamlRoundTrip), "0.30000000000000004");
  EXPECT_EQ(FormatNumber(800.0, kYamlRoundTrip), "8e+02");
  EXPECT_EQ(FormatNumber(2e11, kYamlRoundTrip), "2e+11");
  for (double value : {1e-300, -2.5e-7, 6.02214076e23, std::nextafter(1.0, 2.0)}) {
    EXPECT_EQ(std::strtod(FormatNumber(value, kYamlRoundTrip).c_str(), nullptr), value);
  }
}

TEST(FormatTest, YamlSpellsNanAndInfinities) {
  EXPECT_EQ(FormatNumber(kNan, kYamlRoundTrip), "null");
  EXPECT_EQ(FormatNumber(kInf, kYamlRoundTrip), ".inf");
  EXPECT_EQ(FormatNumber(-kInf, kYamlRoundTrip), "-.inf");
}

TEST(FormatTest, ConfigWritesTheIntegerDigitsBelowAMillion) {
  EXPECT_EQ(FormatNumber(800.0, kConfigRoundTrip), "800");
  EXPECT_EQ(FormatNumber(123456.5, kConfigRoundTrip), "123456.5");
  EXPECT_EQ(FormatNumber(-20.0, kConfigRoundTrip), "-20");
  EXPECT_EQ(FormatNumber(1e6, kConfigRoundTrip), "1e+06");
  EXPECT_EQ(FormatNumber(2e11, kConfigRoundTrip), "2e+11");
  EXPECT_EQ(FormatNumber(0.36e-6, kConfigRoundTrip), "3.6e-07");
  EXPECT_EQ(FormatNumber(-kInf, kConfigRoundTrip), "-.inf");
}

TEST(FormatTest, SignificantFixedAndScientificAreThoseOfPrintf) {
  EXPECT_EQ(FormatNumber(199733086714.89133, kTenDigits), "1.997330867e+11");
  EXPECT_EQ(FormatNumber(kNan, kTenDigits), "nan");
  EXPECT_EQ(FormatNumber(kNan, kTenDigitsYaml), "null");
  EXPECT_EQ(FormatNumber(-kInf, kTenDigits), "-inf");
  EXPECT_EQ(FormatNumber(0.000123456789, kSixDigits), "0.000123457");
  EXPECT_EQ(FormatNumber(1.23456e-9, kScientificThreeDecimals), "1.235e-09");
  EXPECT_EQ(FormatNumber(1.23456, {NumberFormat::Notation::kFixed, 3, true}), "+1.235");
  EXPECT_EQ(FormatNumber(-1.23456, {NumberFormat::Notation::kFixed, 3, true}), "-1.235");
  EXPECT_EQ(FormatNumber(kInf, {NumberFormat::Notation::kFixed, 3, true}), "+inf");
  EXPECT_EQ(FormatNumber(kNan, {NumberFormat::Notation::kSignificant, 4, false, false, "-"}), "-");
}

}  // namespace
}  // namespace mcrewave
