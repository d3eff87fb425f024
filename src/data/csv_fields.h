// Fields of the CSV files of data/ (channel_set.h, measurement.h): private helpers of
// their readers and messages.
#pragma once

#include <cstdlib>
#include <string>

#include "mcrewave/core/format.h"

namespace mcrewave::internal {

// `line` without trailing spaces, tabs and carriage returns (Windows line ends).
inline std::string StripLineEnd(const std::string& line) {
  const std::size_t last = line.find_last_not_of(" \t\r");
  return last == std::string::npos ? "" : line.substr(0, last + 1);
}

// Parses a whole field (surrounding spaces allowed) as a number with strtod;
// false when anything else is left over or the field is empty.
inline bool ParseNumber(const std::string& field, double* value) {
  const char* begin = field.c_str();
  char* end = nullptr;
  *value = std::strtod(begin, &end);
  if (end == begin) return false;
  while (*end == ' ' || *end == '\t') ++end;
  return *end == '\0';
}

// Formats "%g" with the default 6 significant digits, for messages.
inline std::string ShortNumber(double value) { return FormatNumber(value, kSixDigits); }

}  // namespace mcrewave::internal
