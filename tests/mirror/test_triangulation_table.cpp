#include <catch2/catch.hpp>

#include "omnislam/mirror/triangulation_table.hpp"

using omnislam::mirror::MirrorModel;
using omnislam::mirror::TriangulationTable;

TEST_CASE("triangulation table reproduces mirror.md's LUT samples", "[mirror][lut]") {
  const MirrorModel model;
  const TriangulationTable table(model);
  REQUIRE(table.rows() == 225);
  struct Sample {
    int inner, outer;
    double r_mm, z_mm;
  };
  const Sample samples[] = {
      {0, 0, 133309.880, -11469.820}, {20, 30, 4147.564, -396.566},  {45, 60, 2514.909, -386.693},
      {80, 100, 1540.917, -387.052},  {100, 130, 846.467, -186.437}, {150, 160, 1824.348, -1419.175},
      {200, 224, 284.373, -203.813},
  };
  for (const Sample &s : samples) {
    CAPTURE(s.inner, s.outer);
    const auto point = table.at(s.inner, s.outer);
    REQUIRE(point);
    CHECK(point->range_m * 1e3 == Approx(s.r_mm).margin(1.5e-3));
    CHECK(point->height_m * 1e3 == Approx(s.z_mm).margin(1.5e-3));
  }
  CHECK_FALSE(table.at(112, 112));
  CHECK_FALSE(table.at(-1, 0));
  CHECK_FALSE(table.at(0, 225));
  CHECK(table.valid_count() == 25162);
}

TEST_CASE("triangulation table: validity boundary lies 0 to 2 rows right of the diagonal", "[mirror][lut]") {
  const MirrorModel model;
  const TriangulationTable table(model);
  for (int inner = 0; inner < table.rows(); ++inner) {
    int first_valid = -1;
    for (int outer = 0; outer < table.rows() && first_valid < 0; ++outer) {
      if (table.at(inner, outer)) first_valid = outer;
    }
    if (first_valid < 0) continue;  // the last rows may have no valid outer row
    CAPTURE(inner, first_valid);
    CHECK(first_valid - inner >= 0);
    CHECK(first_valid - inner <= 2);
    for (int outer = first_valid; outer < table.rows(); ++outer) REQUIRE(table.at(inner, outer));
  }
}
