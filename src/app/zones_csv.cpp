#include "mcrewave/app/zones_csv.h"

#include "mcrewave/core/format.h"

namespace mcrewave {

namespace {

// A cell: the value in round-trip digits, or empty for NaN.
std::string Cell(double value) {
  return std::isnan(value) ? std::string() : FormatNumber(value, kYamlRoundTrip);
}

// A text cell, quoted (RFC 4180) when it holds a comma, a quote or a line break.
std::string TextCell(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

std::string ZonesCsv(const std::vector<ZoneRow>& rows) {
  std::string csv =
      "zone,name,start_m,end_m,nominal_modulus_pa,modulus_pa,relative_to_nominal,"
      "truth_modulus_pa,relative_error,error_share_nominal,error_share_identified,"
      "relative_gap_nominal,relative_gap_identified\n";
  for (std::size_t z = 0; z < rows.size(); ++z) {
    const ZoneRow& row = rows[z];
    csv += std::to_string(z) + "," + TextCell(row.name) + "," + Cell(row.start_m) + "," +
           Cell(row.end_m) + "," + Cell(row.nominal_modulus) + "," + Cell(row.modulus) + "," +
           Cell(row.modulus / row.nominal_modulus) + "," + Cell(row.truth_modulus) + "," +
           Cell(row.modulus / row.truth_modulus - 1.0) + "," + Cell(row.error_share_nominal) + "," +
           Cell(row.error_share_identified) + "," + Cell(row.relative_gap_nominal) + "," +
           Cell(row.relative_gap_identified) + "\n";
  }
  return csv;
}

}  // namespace mcrewave
