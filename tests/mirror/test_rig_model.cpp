#include <Eigen/Core>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/mirror/rig_model.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorConfig;
using omnislam::mirror::MirrorModel;
using omnislam::mirror::Pixel;
using omnislam::mirror::Ray3;
using omnislam::mirror::RigModel;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A rig at the acceptance limits: focal +1%, mirror 2 mm further, tilted 1 deg and
// 0.6 deg, offset 1 mm and 0.5 mm, centre 3 px off.
MirrorConfig perturbed_config() {
  MirrorConfig config;
  config.center_u_px = 514.5;
  config.center_v_px = 509.0;
  config.rig.focal_scale = 1.01;
  config.rig.mirror_dz_mm = 2.0;
  config.rig.mirror_tilt_x_rad = 1.0 * kDeg;
  config.rig.mirror_tilt_y_rad = -0.6 * kDeg;
  config.rig.mirror_offset_x_mm = 1.0;
  config.rig.mirror_offset_y_mm = -0.5;
  return config;
}

Pixel pixel_at(const MirrorConfig &config, double radius_px, double phi_rad) {
  return {config.center_u_px + radius_px * std::cos(phi_rad),
          config.center_v_px + radius_px * std::sin(phi_rad)};
}

double distance_to_line(const Ray3 &ray, const Eigen::Vector3d &point_m) {
  const Eigen::Vector3d w = point_m - ray.origin_m;
  return (w - w.dot(ray.direction) * ray.direction).norm();
}

}  // namespace

TEST_CASE("rig model: a designed rig's traced rays are the closed-form rays", "[mirror][rig]") {
  const MirrorModel model;
  const RigModel rig;
  REQUIRE(model.config().rig.nominal());
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto annulus = model.radius_range(lobe);
    for (double radius = annulus.min_px + 0.5; radius < annulus.max_px; radius += 17.0) {
      for (double phi_deg : {0.5, 47.0, 133.3, 250.0, 359.5}) {
        CAPTURE(static_cast<int>(lobe), radius, phi_deg);
        const double phi = phi_deg * kDeg;
        const auto ray = rig.back_project(lobe, pixel_at(model.config(), radius, phi));
        REQUIRE(ray);
        const omnislam::mirror::MeridianRay ideal = model.back_project(lobe, radius);
        const Eigen::Vector3d direction(std::sin(ideal.theta_rad) * std::cos(phi),
                                        std::sin(ideal.theta_rad) * std::sin(phi),
                                        -std::cos(ideal.theta_rad));
        const Eigen::Vector3d focus(ideal.origin.range_m * std::cos(phi),
                                    ideal.origin.range_m * std::sin(phi), ideal.origin.height_m);
        CHECK((ray->direction - direction).norm() < 1e-12);
        CHECK(distance_to_line(*ray, focus) < 1e-12);  // metres: the ray passes through the focus
      }
    }
  }
}

TEST_CASE("rig model: a designed rig projects like the closed form", "[mirror][rig]") {
  const MirrorModel model;
  const RigModel rig;
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    for (double range_m : {0.5, 1.0, 2.0, 4.0}) {
      for (double height_m : {-1.0, -0.5, 0.0}) {
        const auto radius = model.project_radius_px(lobe, {range_m, height_m});
        if (!radius) continue;
        const double phi = 1.1;
        CAPTURE(static_cast<int>(lobe), range_m, height_m);
        const auto pixel =
            rig.project(lobe, Eigen::Vector3d(range_m * std::cos(phi), range_m * std::sin(phi), height_m));
        REQUIRE(pixel);
        const Pixel expected = pixel_at(model.config(), *radius, phi);
        CHECK(std::hypot(pixel->u_px - expected.u_px, pixel->v_px - expected.v_px) < 1e-8);
      }
    }
  }
}

TEST_CASE("rig model: a designed rig triangulates like thesis eq. 2-6", "[mirror][rig]") {
  const MirrorModel model;
  const RigModel rig;
  int compared = 0;
  for (int inner_row = 10; inner_row < 225; inner_row += 30) {
    for (int outer_row = inner_row + 3; outer_row < 225; outer_row += 25) {
      const auto expected = model.triangulate_rows(inner_row, outer_row);
      const double phi = 2.0;
      const auto inner = rig.back_project(
          Lobe::kInner, pixel_at(model.config(), model.radius_px_of_row(Lobe::kInner, inner_row), phi));
      const auto outer = rig.back_project(
          Lobe::kOuter, pixel_at(model.config(), model.radius_px_of_row(Lobe::kOuter, outer_row), phi));
      REQUIRE(inner);
      REQUIRE(outer);
      const auto meet = RigModel::intersect(*inner, *outer);
      CAPTURE(inner_row, outer_row);
      REQUIRE(meet.has_value() == expected.has_value());
      if (!expected) continue;
      ++compared;
      CHECK(meet->gap_m < 1e-9);
      CHECK(std::hypot(meet->point_m.x(), meet->point_m.y()) == Approx(expected->range_m).epsilon(1e-10));
      CHECK(meet->point_m.z() == Approx(expected->height_m).epsilon(1e-10).margin(1e-10));
    }
  }
  CHECK(compared > 10);
}

TEST_CASE("rig model: back-projection and projection invert each other on a misaligned rig",
          "[mirror][rig]") {
  const MirrorConfig config = perturbed_config();
  const RigModel rig(config);
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto annulus = rig.design().radius_range(lobe);
    for (double radius = annulus.min_px + 2.0; radius < annulus.max_px - 2.0; radius += 23.0) {
      for (double phi_deg : {3.0, 91.0, 181.0, 272.0}) {
        for (double distance_m : {0.5, 2.0, 8.0}) {
          CAPTURE(static_cast<int>(lobe), radius, phi_deg, distance_m);
          const Pixel pixel = pixel_at(config, radius, phi_deg * kDeg);
          const auto ray = rig.back_project(lobe, pixel);
          REQUIRE(ray);
          const Eigen::Vector3d point = ray->origin_m + distance_m * ray->direction;
          const auto back = rig.project(lobe, point);
          REQUIRE(back);
          CHECK(std::hypot(back->u_px - pixel.u_px, back->v_px - pixel.v_px) < 1e-7);
        }
      }
    }
  }
}

TEST_CASE("rig model: the misaligned rig differs from the design by the expected order", "[mirror][rig]") {
  // Guards against a misalignment that is silently ignored: each one alone moves a floor
  // point 1 m out, 1 m down, by a pixel-scale amount in the outer lobe.
  const Eigen::Vector3d floor_point(1.0, 0.3, -1.0);
  const RigModel design;
  const auto reference = design.project(Lobe::kOuter, floor_point);
  REQUIRE(reference);
  const auto moved_by = [&](auto &&perturb) {
    MirrorConfig config;
    perturb(config.rig);
    const auto pixel = RigModel(config).project(Lobe::kOuter, floor_point);
    REQUIRE(pixel);
    return std::hypot(pixel->u_px - reference->u_px, pixel->v_px - reference->v_px);
  };
  using omnislam::mirror::RigConfig;
  CHECK(moved_by([](RigConfig &rig) { rig.focal_scale = 1.01; }) > 2.0);
  CHECK(moved_by([](RigConfig &rig) { rig.mirror_dz_mm = 2.0; }) > 0.5);
  CHECK(moved_by([](RigConfig &rig) { rig.mirror_tilt_x_rad = 0.5 * kDeg; }) > 1.0);
  CHECK(moved_by([](RigConfig &rig) { rig.mirror_tilt_y_rad = 0.5 * kDeg; }) > 1.0);
  CHECK(moved_by([](RigConfig &rig) { rig.mirror_offset_x_mm = 1.0; }) > 1.0);
  CHECK(moved_by([](RigConfig &rig) { rig.mirror_offset_y_mm = 1.0; }) > 1.0);
}

TEST_CASE("rig model: world points are triangulated back on a misaligned rig", "[mirror][rig]") {
  const RigModel rig(perturbed_config());
  int checked = 0;
  for (double range_m : {0.6, 1.0, 2.0, 4.0}) {
    for (double height_m : {-1.0, -0.5, 0.0}) {
      for (double phi : {0.2, 1.9, 3.5, 5.6}) {
        const Eigen::Vector3d point(range_m * std::cos(phi), range_m * std::sin(phi), height_m);
        const auto inner_px = rig.project(Lobe::kInner, point);
        const auto outer_px = rig.project(Lobe::kOuter, point);
        if (!inner_px || !outer_px) continue;
        const auto inner = rig.back_project(Lobe::kInner, *inner_px);
        const auto outer = rig.back_project(Lobe::kOuter, *outer_px);
        REQUIRE(inner);
        REQUIRE(outer);
        const auto meet = RigModel::intersect(*inner, *outer);
        REQUIRE(meet);
        CAPTURE(range_m, height_m, phi);
        CHECK((meet->point_m - point).norm() < 1e-6);
        ++checked;
      }
    }
  }
  CHECK(checked == 48);
}

TEST_CASE("rig model: rays that miss the lobe and points behind it are reported", "[mirror][rig]") {
  const RigModel rig(perturbed_config());
  // Far outside the image: the camera ray passes beside the outer lobe's mirror sheet.
  CHECK_FALSE(rig.back_project(Lobe::kInner, {511.5 + 5000.0, 511.5}).has_value());
  CHECK_FALSE(rig.project(Lobe::kInner, Eigen::Vector3d(0.0, 0.0, 1.0)).has_value());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(rig.project(Lobe::kOuter, Eigen::Vector3d(nan, 0.0, -1.0)).has_value());
  CHECK_FALSE(RigModel::intersect(Ray3{}, Ray3{}).has_value());  // parallel
}

TEST_CASE("panorama maps: a designed rig is unchanged; a rig misaligned by 1e-12 resamples the same pixels",
          "[mirror][rig][unwarp]") {
  MirrorConfig almost;
  almost.rig.focal_scale = 1.0 + 1e-12;  // takes the general path
  const MirrorModel designed, general(almost);
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto ideal = omnislam::mirror::make_panorama_map(designed, lobe);
    const auto traced = omnislam::mirror::make_panorama_map(general, lobe);
    double worst = 0.0;
    for (std::size_t i = 0; i < ideal.u_px.size(); ++i)
      worst = std::max(worst, static_cast<double>(std::hypot(ideal.u_px[i] - traced.u_px[i],
                                                             ideal.v_px[i] - traced.v_px[i])));
    CAPTURE(static_cast<int>(lobe));
    CHECK(worst < 1e-3);  // float maps: ~1e-4 px is their resolution at radius 512
  }
}

TEST_CASE("panorama maps: on a misaligned rig floor points keep their designed rows",
          "[mirror][rig][unwarp]") {
  MirrorConfig config = perturbed_config();
  config.reference_depth_mm = 800.0;
  const MirrorModel model(config);
  const RigModel rig(config);
  for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
    const auto map = omnislam::mirror::make_panorama_map(model, lobe);
    int covered = 0, repeated = 0;
    for (int row = 0; row < map.rows; ++row) {
      for (int column = 0; column < map.columns; column += 10) {
        CAPTURE(static_cast<int>(lobe), row, column);
        const std::size_t index = static_cast<std::size_t>(row) * map.columns + column;
        const Pixel pixel{map.u_px[index], map.v_px[index]};
        const std::size_t inward = row < map.rows / 2 ? index + map.columns : index - map.columns;
        if (map.u_px[index] == map.u_px[inward] && map.v_px[index] == map.v_px[inward]) {
          // A row off the lobe repeats the nearest covered row of its column (at an end).
          ++repeated;
          continue;
        }
        ++covered;
        CHECK(rig.sees_lobe(lobe, pixel, 0.25 - 1e-3));
        const auto ray = rig.back_project(lobe, pixel);
        REQUIRE(ray);
        // The designed ray of this row and column meets the floor (0.8 m down) at a point
        // the real rig's ray of the sampled pixel must pass through.
        const auto ideal = model.back_project(lobe, model.radius_px_of_row(lobe, row));
        const double phi = omnislam::mirror::column_azimuth_rad(config, column);
        const double along = (ideal.origin.height_m + 0.8) / std::cos(ideal.theta_rad);
        const double range = ideal.origin.range_m + along * std::sin(ideal.theta_rad);
        const Eigen::Vector3d floor(range * std::cos(phi), range * std::sin(phi), -0.8);
        // float maps: 1e-4 px of position is ~1e-6 rad of ray.
        CHECK(distance_to_line(*ray, floor) < 2e-6 * (floor - ray->origin_m).norm());
      }
    }
    CAPTURE(static_cast<int>(lobe), covered, repeated);
    // This rig takes rows off both lobes: its centre side of the outer lobe moves by up to
    // ~30 px relative to the inner lobe's rim, which then hides it (1 deg of tilt about a
    // pivot 134 mm below that edge, and 1 mm of offset).
    CHECK(repeated > 0);
    CHECK(covered > 36 * 190);
  }
}

TEST_CASE("rig model: rays agree with the renderer's tracer (scripts/omnislam_render/mirror.py)",
          "[mirror][rig]") {
  // Reference rays (camera frame, mm) printed by mirror.trace(lobe, u, v, rig) for
  // perturbed_config()'s rig: Rig(focal_scale=1.01, mirror_dz_mm=2.0, tilt_deg=(1.0, -0.6),
  // offset_mm=(1.0, -0.5), center_px=(514.5, 509.0)). The tracer bisects the lobe profile
  // and differentiates it numerically, sharing no code with RigModel; it is the geometry
  // the POV-Ray scene is checked against (tests/python/test_rig.py).
  struct Reference {
    Lobe lobe;
    double u_px, v_px;
    Eigen::Vector3d origin_mm, direction;
  };
  const Reference references[] = {
      {Lobe::kInner,
       700.0,
       400.0,
       {13.690969987167307, -8.044828725613066, 265.450262990289},
       {0.7918383556336687, -0.4462068340161421, -0.417002973400261}},
      {Lobe::kInner,
       430.0,
       620.0,
       {-6.193641689217993, 8.136026360984788, 263.6223479435147},
       {-0.4911043165685821, 0.6231826120263073, -0.6086542387232465}},
      {Lobe::kOuter,
       900.0,
       520.0,
       {43.95035220181366, 1.2540956529697214, 410.0443506265035},
       {0.8343113459497917, 0.09653623489547677, -0.5427755828808553}},
      {Lobe::kOuter,
       200.0,
       250.0,
       {-35.71857858047681, -29.415300007451247, 408.4758390487544},
       {-0.6421123864290799, -0.4737610224180848, -0.602695758099991}},
      {Lobe::kOuter,
       514.5,
       40.0,
       {7.682743330406083e-14, -53.71597332848289, 411.9300383348209},
       {0.021820167078413725, -0.9248920890056535, -0.37960308745244503}},
  };
  const RigModel rig(perturbed_config());
  for (const Reference &reference : references) {
    CAPTURE(reference.u_px, reference.v_px);
    const auto ray = rig.back_project(reference.lobe, {reference.u_px, reference.v_px});
    REQUIRE(ray);
    CHECK((ray->origin_m * 1000.0 - reference.origin_mm).norm() < 1e-6);
    CHECK((ray->direction - reference.direction).norm() < 1e-7);
  }
}
