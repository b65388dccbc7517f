#include <catch2/catch.hpp>
#include <cmath>

#include "omnislam/calib/sensitivity.hpp"
#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/floor_geometry.hpp"

TEST_CASE("range sensitivity: a centre pixel costs one row of floor range", "[calib][sensitivity]") {
  const omnislam::mirror::MirrorConfig camera;
  const auto rows = omnislam::calib::range_sensitivity(camera, 1.0);
  REQUIRE(rows.size() == 2);
  const omnislam::mirror::MirrorModel model(camera);
  const omnislam::stereo::FloorGeometry floor(model, 1.0);
  for (std::size_t i = 0; i < omnislam::calib::kSensitivityRangesM.size(); ++i) {
    const double range_m = omnislam::calib::kSensitivityRangesM[i];
    const double row = *model.project_row(omnislam::mirror::Lobe::kInner, {range_m, -1.0});
    // A radius one pixel short is one row farther out (rows grow towards the centre).
    CHECK(rows[0].floor_plane_m[i] ==
          Approx(std::abs(floor.floor_range_at(row + 1.0) - range_m)).epsilon(1e-6));
    for (const auto &row_errors : rows) {
      CHECK(row_errors.floor_plane_m[i] > 0.0);
      CHECK(std::isfinite(row_errors.stereo_m[i]));
    }
  }
  for (const auto &row_errors : rows) {
    CHECK(row_errors.floor_plane_m[0] < row_errors.floor_plane_m[1]);
    CHECK(row_errors.floor_plane_m[1] < row_errors.floor_plane_m[2]);
  }
  // The floor plane reads range from one lobe's radius, stereo from both: a focal error
  // scales both radii and so the disparity, a centre error shifts both alike.
  CHECK(rows[1].floor_plane_m[2] < rows[1].stereo_m[2]);
  CHECK(rows[0].stereo_m[2] < rows[0].floor_plane_m[2]);
}
