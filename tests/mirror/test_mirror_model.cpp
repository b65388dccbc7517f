#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "omnislam/mirror/mirror_model.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MeridianPoint;
using omnislam::mirror::MirrorModel;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kPitchMm = 3.5945 / 512.0;

}  // namespace

TEST_CASE("derived lobe constants match mirror.md table 1", "[mirror]") {
  const MirrorModel model;
  const auto &inner = model.constants(Lobe::kInner);
  const auto &outer = model.constants(Lobe::kOuter);
  CHECK(inner.c_mm == Approx(135.15).epsilon(1e-12));
  CHECK(inner.b_mm == Approx(54.22700).margin(1e-5));
  CHECK(inner.k == Approx(0.043855).margin(1e-6));
  CHECK(inner.beta_rad == 0.0);
  CHECK(outer.c_mm == Approx(210.54421).margin(1e-5));
  CHECK(outer.b_mm == Approx(82.72867).margin(1e-5));
  CHECK(outer.k == Approx(0.041900).margin(1e-6));
  CHECK(outer.beta_rad / kDeg == Approx(3.5067024).margin(1e-7));
}

TEST_CASE("row table: radius and elevation of panorama rows (mirror.md sec. 6)", "[mirror]") {
  const MirrorModel model;
  struct Row {
    int row;
    double rho_inner_mm, theta_inner_deg, rho_outer_mm, theta_outer_deg;
  };
  const Row reference[] = {
      {0, 2.011375, 84.96715, 3.590990, 84.90221},   {50, 1.660350, 74.20525, 3.239964, 74.36274},
      {100, 1.309325, 61.64955, 2.888939, 61.94911}, {150, 0.958299, 47.19814, 2.537914, 47.49426},
      {200, 0.607274, 30.95537, 2.186888, 31.03142}, {224, 0.438782, 22.62979, 2.018396, 22.50794},
  };
  for (const Row &r : reference) {
    CAPTURE(r.row);
    const double radius_inner = model.radius_px_of_row(Lobe::kInner, r.row);
    const double radius_outer = model.radius_px_of_row(Lobe::kOuter, r.row);
    CHECK(radius_inner * kPitchMm == Approx(r.rho_inner_mm).margin(1e-6));
    CHECK(radius_outer * kPitchMm == Approx(r.rho_outer_mm).margin(1e-6));
    CHECK(model.theta_of_radius_px(Lobe::kInner, radius_inner) / kDeg ==
          Approx(r.theta_inner_deg).margin(1e-5));
    CHECK(model.theta_of_radius_px(Lobe::kOuter, radius_outer) / kDeg ==
          Approx(r.theta_outer_deg).margin(1e-5));
  }
  // Every row: the half-pixel convention and a monotonic elevation (row 0 = horizon side).
  double previous_inner = 10.0, previous_outer = 10.0;
  for (int row = 0; row < 225; ++row) {
    CAPTURE(row);
    REQUIRE(model.radius_px_of_row(Lobe::kInner, row) == 286.5 - row);
    REQUIRE(model.radius_px_of_row(Lobe::kOuter, row) == 511.5 - row);
    REQUIRE(model.row_of_radius_px(Lobe::kOuter, 511.5 - row) == row);
    const double theta_inner = model.theta_of_radius_px(Lobe::kInner, 286.5 - row);
    const double theta_outer = model.theta_of_radius_px(Lobe::kOuter, 511.5 - row);
    REQUIRE(theta_inner < previous_inner);
    REQUIRE(theta_outer < previous_outer);
    REQUIRE(model.radius_px_of_theta(Lobe::kInner, theta_inner).value() ==
            Approx(286.5 - row).epsilon(1e-12));
    REQUIRE(model.radius_px_of_theta(Lobe::kOuter, theta_outer).value() ==
            Approx(511.5 - row).epsilon(1e-12));
    previous_inner = theta_inner;
    previous_outer = theta_outer;
  }
}

TEST_CASE("lobe radial ranges: the pixel annuli and their elevations", "[mirror]") {
  const MirrorModel model;
  CHECK(model.radius_range(Lobe::kInner).min_px == 62.0);
  CHECK(model.radius_range(Lobe::kInner).max_px == 287.0);
  CHECK(model.radius_range(Lobe::kOuter).min_px == 287.0);
  CHECK(model.radius_range(Lobe::kOuter).max_px == 512.0);
  CHECK(model.theta_range(Lobe::kInner).min_rad / kDeg == Approx(22.453).margin(2e-3));
  CHECK(model.theta_range(Lobe::kInner).max_rad / kDeg == Approx(85.066).margin(2e-3));
  CHECK(model.theta_range(Lobe::kOuter).min_rad / kDeg == Approx(22.327).margin(2e-3));
  CHECK(model.theta_range(Lobe::kOuter).max_rad / kDeg == Approx(84.999).margin(2e-3));
}

TEST_CASE("forward projection reproduces the reference points (mirror.md sec. 6)", "[mirror]") {
  const MirrorModel model;
  struct Sample {
    double r_mm, z_mm, rho_inner_mm, row_inner, rho_outer_mm, row_outer, disparity;
  };
  const Sample reference[] = {
      {500, -500, 0.64937, 194.004, 2.11152, 210.735, 16.731},
      {500, 0, 1.30815, 100.167, 2.55969, 146.899, 46.731},
      {1000, -1000, 0.75971, 178.288, 2.25658, 190.073, 11.785},
      {1000, -500, 1.07930, 132.764, 2.51842, 152.777, 20.013},
      {1000, 0, 1.68064, 47.110, 3.01577, 81.934, 34.824},
      {2000, -1000, 1.20564, 114.769, 2.69618, 127.457, 12.688},
      {2000, -500, 1.50659, 71.901, 2.97038, 88.399, 16.498},
      {2000, 0, 1.91916, 13.136, 3.35403, 33.753, 20.617},
      {4000, -1000, 1.60596, 57.747, 3.11977, 67.120, 9.373},
      {4000, -500, 1.81315, 28.235, 3.32126, 38.420, 10.184},
  };
  for (const Sample &s : reference) {
    CAPTURE(s.r_mm, s.z_mm);
    const MeridianPoint point{s.r_mm / 1000.0, s.z_mm / 1000.0};
    const auto radius_inner = model.project_radius_px(Lobe::kInner, point);
    const auto radius_outer = model.project_radius_px(Lobe::kOuter, point);
    REQUIRE(radius_inner);
    REQUIRE(radius_outer);
    CHECK(*radius_inner * kPitchMm == Approx(s.rho_inner_mm).margin(1e-5));
    CHECK(*radius_outer * kPitchMm == Approx(s.rho_outer_mm).margin(1e-5));
    const double row_inner = model.project_row(Lobe::kInner, point).value();
    const double row_outer = model.project_row(Lobe::kOuter, point).value();
    CHECK(row_inner == Approx(s.row_inner).margin(1e-3));
    CHECK(row_outer == Approx(s.row_outer).margin(1e-3));
    CHECK(row_outer - row_inner == Approx(s.disparity).margin(1e-3));
  }
  // (4000, 0): outside the inner annulus (theta_I = 86.1 deg), still seen by the outer lobe.
  CHECK_FALSE(model.project_radius_px(Lobe::kInner, {4.0, 0.0}));
  CHECK(model.project_row(Lobe::kOuter, {4.0, 0.0}).value() == Approx(4.810).margin(1e-3));
  // (500, -1000): below both fields of view.
  CHECK_FALSE(model.project_radius_px(Lobe::kInner, {0.5, -1.0}));
  CHECK_FALSE(model.project_radius_px(Lobe::kOuter, {0.5, -1.0}));
}

TEST_CASE("convention-check geometry: floor-wall boundary rows", "[mirror]") {
  // shared/reference/convention-check: wall 3 m away, floor 1 m below the pinhole.
  const MirrorModel model;
  const MeridianPoint along_x{3.0, -1.0};
  CHECK(model.project_row(Lobe::kInner, along_x).value() == Approx(79.40).margin(0.01));
  CHECK(model.project_row(Lobe::kOuter, along_x).value() == Approx(90.45).margin(0.01));
  const MeridianPoint corner{3.0 * std::numbers::sqrt2, -1.0};
  CHECK(model.project_row(Lobe::kInner, corner).value() == Approx(53.73).margin(0.01));
  CHECK(model.project_row(Lobe::kOuter, corner).value() == Approx(62.74).margin(0.01));
}

TEST_CASE("disparity at infinity is not zero (mirror.md sec. 8)", "[mirror]") {
  const MirrorModel model;
  const double theta_deg[] = {22.6, 30, 40, 50, 60, 70, 80, 85};
  const double expected_px[] = {-0.34, 0.16, 0.69, 1.03, 1.13, 0.91, 0.23, -0.34};
  for (int i = 0; i < 8; ++i) {
    CAPTURE(theta_deg[i]);
    CHECK(model.disparity_at_infinity(theta_deg[i] * kDeg) == Approx(expected_px[i]).margin(0.006));
  }
}

TEST_CASE("visibility wedge at floor and pinhole height (mirror.md sec. 8)", "[mirror]") {
  const MirrorModel model;
  auto seen_by_both = [&](double r_m, double z_m) {
    return model.project_radius_px(Lobe::kInner, {r_m, z_m}) &&
           model.project_radius_px(Lobe::kOuter, {r_m, z_m});
  };
  CHECK_FALSE(seen_by_both(0.195, 0.0));
  CHECK(seen_by_both(0.205, 0.0));
  CHECK(seen_by_both(3.12, 0.0));
  CHECK_FALSE(seen_by_both(3.135, 0.0));
  CHECK_FALSE(seen_by_both(0.609, -1.0));
  CHECK(seen_by_both(0.619, -1.0));
  CHECK(seen_by_both(14.7, -1.0));
  CHECK_FALSE(seen_by_both(14.73, -1.0));
}

TEST_CASE("project then triangulate round trip over random visible points", "[mirror]") {
  const MirrorModel model;
  std::mt19937_64 rng(20081);
  std::uniform_real_distribution<double> range_m(0.2, 15.0);
  std::uniform_real_distribution<double> height_m(-3.0, 0.3);
  int visible = 0;
  double worst = 0.0;
  for (int i = 0; i < 200000 && visible < 20000; ++i) {
    const MeridianPoint point{range_m(rng), height_m(rng)};
    const auto radius_inner = model.project_radius_px(Lobe::kInner, point);
    const auto radius_outer = model.project_radius_px(Lobe::kOuter, point);
    if (!radius_inner || !radius_outer) continue;
    ++visible;
    const auto back = model.triangulate(model.theta_of_radius_px(Lobe::kInner, *radius_inner),
                                        model.theta_of_radius_px(Lobe::kOuter, *radius_outer));
    REQUIRE(back);
    const double error = std::hypot(back->range_m - point.range_m, back->height_m - point.height_m) /
                         std::hypot(point.range_m, point.height_m);
    worst = std::max(worst, error);
  }
  INFO("visible points " << visible << ", worst relative error " << worst);
  CHECK(visible >= 10000);
  CHECK(worst < 1e-9);
}

TEST_CASE("degenerate inputs give an invalid result, not garbage", "[mirror]") {
  const MirrorModel model;
  // A point on the axis is imaged at the centre, which no lobe's annulus covers.
  CHECK_FALSE(model.project_radius_px(Lobe::kInner, {0.0, -1.0}));
  CHECK_FALSE(model.project_radius_px(Lobe::kOuter, {0.0, -1.0}));
  // Points above the mirror, behind the camera, or not finite.
  CHECK_FALSE(model.project_radius_px(Lobe::kInner, {0.1, 5.0}));
  CHECK_FALSE(model.project_radius_px(Lobe::kOuter, {1.0, 1.0}));
  CHECK_FALSE(model.project_radius_px(Lobe::kInner, {std::nan(""), -1.0}));
  CHECK_FALSE(model.project_row(Lobe::kOuter, {1.0, std::numeric_limits<double>::infinity()}));
  // Parallel rays and rays that would meet behind the foci.
  CHECK_FALSE(model.triangulate(60 * kDeg, 60 * kDeg));
  CHECK_FALSE(model.triangulate(50 * kDeg, 60 * kDeg));
  CHECK_FALSE(model.triangulate(std::nan(""), 60 * kDeg));
  CHECK_FALSE(model.triangulate_rows(112, 112));
  CHECK(std::isnan(model.disparity_at_infinity(-1.0)));
}

TEST_CASE("a config that describes no hyperbola is rejected", "[mirror]") {
  omnislam::mirror::MirrorConfig config;
  config.inner.a_mm = 200.0;  // a > c
  CHECK_THROWS_AS(MirrorModel(config), std::invalid_argument);
  config = {};
  config.focal_mm = 0.0;
  CHECK_THROWS_AS(MirrorModel(config), std::invalid_argument);
  config = {};
  config.rows_per_lobe = 0;
  CHECK_THROWS_AS(MirrorModel(config), std::invalid_argument);
}
