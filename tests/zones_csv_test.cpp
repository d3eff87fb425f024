// zones.csv, one layout for every model kind (app/zones_csv.h).
#include "mcrewave/app/zones_csv.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace mcrewave {
namespace {

TEST(ZonesCsvTest, OneLayoutWithEmptyCellsWhereAValueDoesNotApply) {
  ZoneRow bar_zone;
  bar_zone.name = "zone0";
  bar_zone.start_m = 0.0;
  bar_zone.end_m = 0.5;
  bar_zone.nominal_modulus = 200e9;
  bar_zone.modulus = 150e9;
  bar_zone.truth_modulus = 160e9;
  ZoneRow matrix_zone;
  matrix_zone.name = "inclusion, soft";
  matrix_zone.nominal_modulus = 200e9;
  matrix_zone.modulus = 100e9;
  matrix_zone.error_share_nominal = 0.25;
  matrix_zone.error_share_identified = 0.5;
  matrix_zone.relative_gap_nominal = 0.125;
  matrix_zone.relative_gap_identified = 0.0625;
  const std::string csv = ZonesCsv({bar_zone, matrix_zone});
  EXPECT_EQ(csv,
            "zone,name,start_m,end_m,nominal_modulus_pa,modulus_pa,relative_to_nominal,"
            "truth_modulus_pa,relative_error,error_share_nominal,error_share_identified,"
            "relative_gap_nominal,relative_gap_identified\n"
            "0,zone0,0,0.5,2e+11,1.5e+11,0.75,1.6e+11,-0.0625,,,,\n"
            "1,\"inclusion, soft\",,,2e+11,1e+11,0.5,,,0.25,0.5,0.125,0.0625\n");
}

}  // namespace
}  // namespace mcrewave
