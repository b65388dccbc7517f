#include <catch2/catch.hpp>
#include <cmath>

#include "omnislam/calib/rig_fit.hpp"
#include "omnislam/calib/sensitivity.hpp"
#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/floor_geometry.hpp"

TEST_CASE("range sensitivity: a centre pixel costs one row of floor range", "[calib][sensitivity]") {
  const omnislam::mirror::MirrorConfig camera;
  const auto rows = omnislam::calib::range_sensitivity(camera, 1.0);
  REQUIRE(rows.size() == 3);
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
  // A rig turned 0.1 deg off level about the pinhole turns the inner lobe's rays by as much
  // about its viewpoint, d = 0.2703 m above the pinhole (H = 1.2703 m above the floor), and
  // moves that viewpoint d x tilt sideways: a floor point r away reads about
  // tilt x ((r^2 + H^2) / H - d) off along the tilt (docs/calibration.md; 3.1 / 7.2 / 23.6 mm
  // at 1 / 2 / 4 m). Stereo turns both rays alike: the point turns about the pinhole, its
  // range moved by h x tilt (1.7 mm) wherever it is.
  REQUIRE(rows[2].parameter == "level tilt");
  const double tilt = 0.1 * 3.14159265358979 / 180.0, d = 0.2703, H = 1.0 + d;
  for (std::size_t i = 0; i < omnislam::calib::kSensitivityRangesM.size(); ++i) {
    const double range_m = omnislam::calib::kSensitivityRangesM[i];
    CHECK(rows[2].floor_plane_m[i] == Approx(tilt * ((range_m * range_m + H * H) / H - d)).epsilon(0.05));
    CHECK(rows[2].stereo_m[i] == Approx(1.0 * tilt).epsilon(0.1));
  }
}

TEST_CASE(
    "range uncertainty: a focal sigma of 0.1% costs what the sensitivity table says, a centre or level "
    "tilt sigma 1/sqrt(2) of its worst azimuth",
    "[calib][sensitivity]") {
  const omnislam::mirror::MirrorConfig camera;
  const auto rows = omnislam::calib::range_sensitivity(camera, 1.0);
  using Covariance =
      Eigen::Matrix<double, omnislam::calib::kTargetParameters, omnislam::calib::kTargetParameters>;
  Covariance covariance = Covariance::Zero();
  covariance(omnislam::calib::kFocalScale, omnislam::calib::kFocalScale) = 1e-6;  // sigma 0.1%
  const auto focal = omnislam::calib::range_uncertainty(camera, covariance, 1.0);
  covariance.setZero();
  covariance(omnislam::calib::kCenterU, omnislam::calib::kCenterU) = 1.0;  // sigma 1 px
  const auto centre = omnislam::calib::range_uncertainty(camera, covariance, 1.0);
  covariance.setZero();
  const double tilt_rad = 0.1 * 3.14159265358979 / 180.0;
  covariance(omnislam::calib::kLevelX, omnislam::calib::kLevelX) = tilt_rad * tilt_rad;  // sigma 0.1 deg
  const auto level = omnislam::calib::range_uncertainty(camera, covariance, 1.0);
  for (std::size_t i = 0; i < 3; ++i) {
    CAPTURE(i, level.floor_plane_m[i], level.stereo_m[i]);
    CHECK(level.floor_plane_m[i] == Approx(rows[2].floor_plane_m[i] / std::sqrt(2.0)).epsilon(0.15));
    CHECK(level.stereo_m[i] == Approx(rows[2].stereo_m[i] / std::sqrt(2.0)).epsilon(0.15));
    CAPTURE(i, focal.floor_plane_m[i], focal.stereo_m[i], centre.floor_plane_m[i], centre.stereo_m[i]);
    CHECK(focal.floor_plane_m[i] == Approx(rows[1].floor_plane_m[i]).epsilon(0.1));
    CHECK(focal.stereo_m[i] == Approx(rows[1].stereo_m[i]).epsilon(0.1));
    CHECK(centre.floor_plane_m[i] == Approx(rows[0].floor_plane_m[i] / std::sqrt(2.0)).epsilon(0.15));
    CHECK(centre.stereo_m[i] == Approx(rows[0].stereo_m[i] / std::sqrt(2.0)).epsilon(0.15));
  }
}
