#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>
#include <algorithm>

#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/mirror/rig_model.hpp"
#include "omnislam/stereo/row_triangulator.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;
using omnislam::mirror::MirrorModel;
using omnislam::stereo::RowTriangulator;
using omnislam::stereo::TriangulationMethod;

namespace {

// A floor point `range_m` away (the camera 1 m up) triangulated from its designed rows in
// panorama column `column`: a misaligned rig's panoramas keep floor points there.
omnislam::stereo::ColumnPoint floor_point_from_designed_rows(const MirrorModel &model,
                                                             const RowTriangulator &triangulator, int column,
                                                             double range_m) {
  const auto inner = model.project_row(Lobe::kInner, {range_m, -1.0});
  const auto outer = model.project_row(Lobe::kOuter, {range_m, -1.0});
  REQUIRE(inner);
  REQUIRE(outer);
  const auto point = triangulator.triangulate(column, static_cast<float>(*inner), static_cast<float>(*outer));
  REQUIRE(point);
  return *point;
}

}  // namespace

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
      CAPTURE(column, range_m);
      const auto point = floor_point_from_designed_rows(model, triangulator, column, range_m);
      // float rows, rays linear between the panorama's pixels: measured up to 29 um (8 um
      // with each pixel's image position interpolated and traced; a row is ~10 mm here).
      CHECK(std::abs(point.range_m - range_m) < 3e-5 * range_m);
      CHECK(std::abs(point.height_m + 1.0) < 4e-5);
      ++checked;
    }
  }
  CHECK(checked == 16);
  CHECK_FALSE(triangulator.triangulate(5, -2.0f, 100.0f).has_value());
  CHECK_FALSE(triangulator.triangulate(5, 100.0f, 90.0f).has_value());  // rays meet behind the mirror
}

namespace {

// Where a lobe's panorama shows an image pixel: (column, row), fractional, by Newton's
// method on the map's bilinear interpolation from the nearest sample among the columns
// around the pixel's angle about `centre`.
Eigen::Vector2d panorama_position(const omnislam::mirror::PanoramaMap &map, const Eigen::Vector2d &centre,
                                  const omnislam::mirror::Pixel &pixel) {
  const auto at = [&](const std::vector<float> &values, double column, double row) {
    const double wrapped = column - map.columns * std::floor(column / map.columns);
    const int left = static_cast<int>(wrapped) % map.columns, right = (left + 1) % map.columns;
    const int below = std::clamp(static_cast<int>(std::floor(row)), 0, map.rows - 2);
    const double across = wrapped - std::floor(wrapped), along = row - below;
    const auto value = [&](int r, int c) {
      return static_cast<double>(values[static_cast<std::size_t>(r) * map.columns + c]);
    };
    const double here = value(below, left) + along * (value(below + 1, left) - value(below, left));
    const double beside = value(below, right) + along * (value(below + 1, right) - value(below, right));
    return here + across * (beside - here);
  };
  const auto image_of = [&](const Eigen::Vector2d &p) {
    return Eigen::Vector2d(at(map.u_px, p.x(), p.y()), at(map.v_px, p.x(), p.y()));
  };
  const Eigen::Vector2d target(pixel.u_px, pixel.v_px);
  Eigen::Vector2d best(0.0, 0.0);
  double best_distance = 1e30;
  const double angle = std::atan2(pixel.v_px - centre.y(), pixel.u_px - centre.x());
  const int near = static_cast<int>(std::lround(angle / (2.0 * std::numbers::pi) * map.columns));
  for (int row = 0; row < map.rows; ++row) {
    for (int offset = -8; offset <= 8; ++offset) {
      const int column = ((near + offset) % map.columns + map.columns) % map.columns;
      const double distance = (image_of({column, row}) - target).squaredNorm();
      if (distance < best_distance) best_distance = distance, best = {column, row};
    }
  }
  for (int step = 0; step < 8; ++step) {
    constexpr double kH = 1e-4;
    Eigen::Matrix2d jacobian;
    jacobian.col(0) = (image_of(best + Eigen::Vector2d(kH, 0.0)) - image_of(best)) / kH;
    jacobian.col(1) = (image_of(best + Eigen::Vector2d(0.0, kH)) - image_of(best)) / kH;
    best -= jacobian.inverse() * (image_of(best) - target);
  }
  return best;
}

}  // namespace

TEST_CASE("row triangulator: a misaligned rig's stereo point off the floor follows the epipolar curve",
          "[stereo][rig]") {
  // A table's top edge 0.25 m below the pinhole, crossing the view obliquely: on a rig
  // tilted by 1 deg and offset by 1 mm the outer panorama shows the point the inner
  // column sees a fraction of a column aside, on an edge that climbs across columns.
  MirrorConfig config;
  config.rig.focal_scale = 1.0095;
  config.rig.mirror_dz_mm = -2.6;
  config.rig.mirror_tilt_x_rad = 0.95 * std::numbers::pi / 180.0;
  config.rig.mirror_tilt_y_rad = -0.7 * std::numbers::pi / 180.0;
  config.rig.mirror_offset_x_mm = 0.9;
  config.rig.mirror_offset_y_mm = -1.0;
  config.reference_depth_mm = 1000.0;
  const MirrorModel model(config);
  const omnislam::mirror::RigModel rig(config);
  const RowTriangulator triangulator(model, TriangulationMethod::kExact);
  const omnislam::mirror::PanoramaMap inner_map = omnislam::mirror::make_panorama_map(model, Lobe::kInner);
  const omnislam::mirror::PanoramaMap outer_map = omnislam::mirror::make_panorama_map(model, Lobe::kOuter);
  for (const int column : {40, 130, 220, 310}) {
    for (const double range_m : {1.2, 2.5}) {
      const double phi = omnislam::mirror::column_azimuth_rad(config, column);
      const Eigen::Vector3d radial(std::cos(phi), std::sin(phi), 0.0),
          tangent(-std::sin(phi), std::cos(phi), 0.0);
      const Eigen::Vector3d start = range_m * radial + Eigen::Vector3d(0.0, 0.0, -0.25);
      const Eigen::Vector3d along = (std::cos(0.5) * tangent + std::sin(0.5) * radial).normalized();
      // The edge's panorama position at parameter s, and the s at which it crosses `target`.
      const auto position = [&](Lobe lobe, double s) {
        const auto pixel = rig.project(lobe, start + s * along);
        REQUIRE(pixel);
        return panorama_position(lobe == Lobe::kInner ? inner_map : outer_map,
                                 {config.center_u_px, config.center_v_px}, *pixel);
      };
      const auto crossing = [&](Lobe lobe, double target) {
        double s = 0.0;
        for (int step = 0; step < 10; ++step) {
          constexpr double kH = 1e-5;
          const double value = position(lobe, s).x() - target;
          s -= value * kH / (position(lobe, s + kH).x() - position(lobe, s).x());
        }
        return s;
      };
      const double s_inner = crossing(Lobe::kInner, column);
      const Eigen::Vector3d truth = start + s_inner * along;
      const auto inner_row = static_cast<float>(position(Lobe::kInner, s_inner).y());
      const auto outer_row = static_cast<float>(position(Lobe::kOuter, crossing(Lobe::kOuter, column)).y());
      const double slope = position(Lobe::kOuter, crossing(Lobe::kOuter, column + 0.5)).y() -
                           position(Lobe::kOuter, crossing(Lobe::kOuter, column - 0.5)).y();
      CAPTURE(column, range_m, inner_row, outer_row, slope);
      const auto point = triangulator.triangulate(column, inner_row, outer_row, static_cast<float>(slope));
      REQUIRE(point);
      const double true_range = std::hypot(truth.x(), truth.y());
      // Measured within 0.3 mm at 1.2 m and 0.5 mm at 2.5 m (float rows, linear maps); the
      // column's own outer ray gave 0.7-4.6 mm at both ranges.
      CHECK(std::abs(point->range_m - true_range) < 3e-4 * true_range);
      CHECK(std::abs(point->height_m - truth.z()) < 3e-4 * true_range);
      CHECK(std::abs(point->azimuth_shift_rad -
                     std::remainder(std::atan2(truth.y(), truth.x()) - phi, 2.0 * std::numbers::pi)) < 1e-4);
    }
  }
}

TEST_CASE("row triangulator: a rig turned off level triangulates floor points from their designed rows",
          "[stereo][rig]") {
  // The whole rig (camera and mirror) turned 0.8 / -0.6 deg away from level: without the
  // tilt a floor point 2 m away reads ~(2 m)^2 x 0.0175 rad / 1 m = 70 mm off per degree.
  // With it, the panoramas resample the image so that each designed row and column sees
  // its point of the level floor, and the rays are the level frame's.
  MirrorConfig config;
  config.rig.level_tilt_x_rad = 0.8 * std::numbers::pi / 180.0;
  config.rig.level_tilt_y_rad = -0.6 * std::numbers::pi / 180.0;
  config.reference_depth_mm = 1000.0;
  const MirrorModel model(config);
  const RowTriangulator triangulator(model, TriangulationMethod::kExact);
  const omnislam::mirror::RigModel rig(config);
  for (int column : {10, 100, 190, 280}) {
    for (double range_m : {0.9, 2.0, 3.5}) {
      CAPTURE(column, range_m);
      const auto point = floor_point_from_designed_rows(model, triangulator, column, range_m);
      CHECK(std::abs(point.range_m - range_m) < 3e-5 * range_m * range_m);
      CHECK(std::abs(point.height_m + 1.0) < 4e-5 * range_m);
      CHECK(std::abs(point.azimuth_shift_rad) < 1e-5);
    }
  }
  // Rays and projection in the level frame invert each other.
  const Eigen::Vector3d wall(1.7, -0.9, 0.2);
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto pixel = rig.project(lobe, wall);
    REQUIRE(pixel);
    const auto ray = rig.back_project(lobe, *pixel);
    REQUIRE(ray);
    const Eigen::Vector3d to_wall = (wall - ray->origin_m).normalized();
    CHECK((to_wall - ray->direction).norm() < 1e-8);
  }
}
