#include "mcrewave/core/format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mcrewave {

std::string FormatNumber(double value, const NumberFormat& format) {
  if (std::isnan(value)) return format.nan;
  if (std::isinf(value)) {
    const std::string infinity = format.infinity;
    return value > 0 ? (format.plus_sign ? "+" + infinity : infinity) : "-" + infinity;
  }
  const char* sign = format.plus_sign ? "%+.*" : "%.*";
  char pattern[8];
  char text[64];
  switch (format.notation) {
    case NumberFormat::Notation::kSignificant:
      std::snprintf(pattern, sizeof(pattern), "%sg", sign);
      std::snprintf(text, sizeof(text), pattern, format.digits, value);
      return text;
    case NumberFormat::Notation::kFixed:
      std::snprintf(pattern, sizeof(pattern), "%sf", sign);
      std::snprintf(text, sizeof(text), pattern, format.digits, value);
      return text;
    case NumberFormat::Notation::kScientific:
      std::snprintf(pattern, sizeof(pattern), "%se", sign);
      std::snprintf(text, sizeof(text), pattern, format.digits, value);
      return text;
    case NumberFormat::Notation::kRoundTrip:
      break;
  }
  std::snprintf(pattern, sizeof(pattern), "%sg", sign);
  int precision = 1;
  for (; precision < 17; ++precision) {
    std::snprintf(text, sizeof(text), pattern, precision, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  const double magnitude = std::abs(value);
  if (format.integer_digits_below_1e6 && magnitude >= 1.0 && magnitude < 1e6) {
    // %g switches to exponents once the exponent reaches the precision.
    precision = std::max(precision, 1 + static_cast<int>(std::floor(std::log10(magnitude))));
  }
  std::snprintf(text, sizeof(text), pattern, precision, value);
  return text;
}

}  // namespace mcrewave
