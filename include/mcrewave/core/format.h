// The one number formatter of mcrewave: every double that becomes text (YAML, CSV,
// reports, messages) goes through FormatNumber with one of the formats below, so that
// a value is spelt the same way wherever the same kind of text shows it.
#pragma once

#include <string>

namespace mcrewave {

struct NumberFormat {
  enum class Notation {
    kRoundTrip,    // the fewest significant digits (up to 17) that read back as exactly
                   // the value (strtod), in %g style
    kSignificant,  // %.<digits>g
    kFixed,        // %.<digits>f
    kScientific,   // %.<digits>e
  };
  Notation notation = Notation::kRoundTrip;
  int digits = 6;          // significant digits (kSignificant), decimals (kFixed, kScientific)
  bool plus_sign = false;  // a '+' before positive values and zero
  // kRoundTrip: every digit of the integer part below 1e6 (800, not 8e+02).
  bool integer_digits_below_1e6 = false;
  const char* nan = "nan";       // the spelling of NaN
  const char* infinity = "inf";  // of +infinity; -infinity is "-" followed by it
};

// Formats for the kinds of text the project writes.
// YAML values that read back bit for bit: null, .inf and -.inf (results' summary.yaml).
inline constexpr NumberFormat kYamlRoundTrip{
    NumberFormat::Notation::kRoundTrip, 6, false, false, "null", ".inf"};
// Config values (--print-default-config, the resolved config): as kYamlRoundTrip, with
// the integer digits of numbers below 1e6 written out.
inline constexpr NumberFormat kConfigRoundTrip{
    NumberFormat::Notation::kRoundTrip, 6, false, true, "nan", ".inf"};
// Seventeen significant digits (printf's %.17g), enough for any double to read back
// exactly: the values of CSV data, results and Matrix Market files. NaN is nan whatever
// its sign bit (printf writes -nan for a NaN with the sign bit set).
inline constexpr NumberFormat kSeventeenDigits{NumberFormat::Notation::kSignificant, 17};
// Ten significant digits: CSV tables and YAML of the zone runs (NaN as null).
inline constexpr NumberFormat kTenDigitsYaml{
    NumberFormat::Notation::kSignificant, 10, false, false, "null", "inf"};
// Ten significant digits for study CSV files (NaN as nan).
inline constexpr NumberFormat kTenDigits{NumberFormat::Notation::kSignificant, 10};
// Six significant digits (printf's %g): messages and logs.
inline constexpr NumberFormat kSixDigits{NumberFormat::Notation::kSignificant, 6};
// Three decimals in scientific notation: residuals and tolerances in solver messages.
inline constexpr NumberFormat kScientificThreeDecimals{NumberFormat::Notation::kScientific, 3};

// `value` as text in `format`.
std::string FormatNumber(double value, const NumberFormat& format);

}  // namespace mcrewave
