#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/stereo/row_triangulator.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;
using omnislam::mirror::MirrorModel;
using omnislam::stereo::RowTriangulator;
using omnislam::stereo::TriangulationMethod;

TEST_CASE("row triangulator: a designed rig's column-aware path is the closed form", "[stereo][rig]") {
  const MirrorModel model;
  for (const TriangulationMethod method : {TriangulationMethod::kExact, TriangulationMethod::kTable}) {
    const RowTriangulator triangulator(model, method);
    for (float inner = 0.0f; inner < 225.0f; inner += 13.7f) {
      for (float outer = inner; outer < 225.0f; outer += 9.3f) {
        const auto expected = triangulator.triangulate(inner, outer);
        const auto got = triangulator.triangulate(123, inner, outer);
        REQUIRE(got.has_value() == expected.has_value());
        if (!got) continue;
        CHECK(got->range_m == expected->range_m);  // the same code path: bit-identical
        CHECK(got->height_m == expected->height_m);
      }
    }
  }
}

TEST_CASE("row triangulator: a misaligned rig triangulates floor points from their designed rows",
          "[stereo][rig]") {
  // The panorama of a misaligned rig keeps floor points on their designed rows
  // (panorama_maps.hpp), so the designed rows of a floor point must triangulate back to it
  // through the real rays; fractional rows interpolate the maps linearly.
  MirrorConfig config;
  config.rig.focal_scale = 1.008;
  config.rig.mirror_dz_mm = 2.5;
  config.rig.mirror_tilt_x_rad = 0.8 * std::numbers::pi / 180.0;
  config.rig.mirror_tilt_y_rad = -0.5 * std::numbers::pi / 180.0;
  config.rig.mirror_offset_x_mm = 0.7;
  config.rig.mirror_offset_y_mm = -0.4;
  config.reference_depth_mm = 1000.0;
  const MirrorModel model(config);
  const RowTriangulator triangulator(model, TriangulationMethod::kExact);
  int checked = 0;
  for (int column : {5, 95, 185, 275}) {
    for (double range_m : {0.9, 1.3, 2.0, 3.0}) {
      const auto inner = model.project_row(Lobe::kInner, {range_m, -1.0});
      const auto outer = model.project_row(Lobe::kOuter, {range_m, -1.0});
      REQUIRE(inner);
      REQUIRE(outer);
      CAPTURE(column, range_m, *inner, *outer);
      const auto point =
          triangulator.triangulate(column, static_cast<float>(*inner), static_cast<float>(*outer));
      REQUIRE(point);
      // float rows and maps, linear interpolation between rows: measured up to 8 um.
      CHECK(std::abs(point->range_m - range_m) < 1e-5 * range_m);
      CHECK(std::abs(point->height_m + 1.0) < 2e-5);
      ++checked;
    }
  }
  CHECK(checked == 16);
  CHECK_FALSE(triangulator.triangulate(5, -2.0f, 100.0f).has_value());
  CHECK_FALSE(triangulator.triangulate(5, 100.0f, 90.0f).has_value());  // rays meet behind the mirror
}
