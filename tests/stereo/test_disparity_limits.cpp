#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/disparity_limits.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorModel;
using omnislam::stereo::derive_disparity_limits;

TEST_CASE("floor contacts 0.6..4 m with the camera 1 m up have ~9-13 px of disparity", "[stereo][limits]") {
  const MirrorModel model;
  double low = 1e9, high = -1e9;
  for (double range_m = 0.65; range_m <= 4.0; range_m += 0.05) {
    const auto inner = model.project_row(Lobe::kInner, {range_m, -1.0});
    const auto outer = model.project_row(Lobe::kOuter, {range_m, -1.0});
    REQUIRE(inner);
    REQUIRE(outer);
    low = std::min(low, *outer - *inner);
    high = std::max(high, *outer - *inner);
  }
  CHECK(low == Approx(9.4).margin(0.3));
  CHECK(high == Approx(12.8).margin(0.5));
}

TEST_CASE("per-row bands contain every reachable point and exclude the underground", "[stereo][limits]") {
  const MirrorModel model;
  const auto limits = derive_disparity_limits(model, 1.0, 0.3, 6.0, 0.0);
  REQUIRE(limits.per_inner_row.size() == 225u);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> range(0.3, 6.0), height(-1.0, 0.3);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const omnislam::mirror::MeridianPoint point{range(random), height(random)};
    const auto inner = model.project_row(Lobe::kInner, point);
    const auto outer = model.project_row(Lobe::kOuter, point);
    if (!inner || !outer) continue;
    const int row = static_cast<int>(std::lround(*inner));
    if (row < 0 || row > 224) continue;
    // The band is derived at the integer row; allow for the half-row rounding.
    const auto &band = limits.per_inner_row[static_cast<std::size_t>(row)];
    CAPTURE(point.range_m, point.height_m, *inner, *outer);
    REQUIRE(band.max_px >= band.min_px);
    CHECK(*outer - row >= band.min_px - 0.6);
    CHECK(*outer - row <= band.max_px + 0.6);
    ++checked;
  }
  CHECK(checked > 5000);
  // Inner row 180 looks down steeply and meets the floor (1 m below) at ~0.97 m: the band
  // ends at that floor contact instead of running on to 6 m underground.
  const auto ray = model.back_project(Lobe::kInner, model.radius_px_of_row(Lobe::kInner, 180));
  const double floor_range_m = (ray.origin.height_m + 1.0) * std::tan(ray.theta_rad);
  const auto floor_row = model.project_row(Lobe::kOuter, {floor_range_m, -1.0});
  REQUIRE(floor_row);
  CHECK(floor_range_m == Approx(0.97).margin(0.02));
  CHECK(limits.per_inner_row[180].min_px == Approx(*floor_row - 180.0).margin(0.05));
  const auto unclipped = derive_disparity_limits(model, 50.0, 0.3, 6.0, 0.0);
  CHECK(unclipped.per_inner_row[180].min_px < limits.per_inner_row[180].min_px - 3.0f);
  CHECK(limits.per_inner_row[224].max_px < limits.per_inner_row[224].min_px);  // floor nearer than 0.6 m only
  CHECK(limits.min_px > 4.0f);
  CHECK(limits.max_px < 120.0f);
}

TEST_CASE("a lower camera or a nearer far range narrows the band", "[stereo][limits]") {
  const MirrorModel model;
  const auto wide = derive_disparity_limits(model, 1.0, 0.3, 6.0, 1.0);
  const auto near = derive_disparity_limits(model, 1.0, 0.3, 2.0, 1.0);
  const auto low = derive_disparity_limits(model, 0.5, 0.3, 6.0, 1.0);
  CHECK(near.per_inner_row[60].min_px > wide.per_inner_row[60].min_px + 5.0f);
  CHECK(low.per_inner_row[150].min_px > wide.per_inner_row[150].min_px);
  CHECK(wide.per_inner_row[100].max_px - wide.per_inner_row[100].min_px > 2.0f);
}
