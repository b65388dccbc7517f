#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "omnislam/mirror/panorama_maps.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorModel;

TEST_CASE("panorama maps sample bin centres under the binding image convention", "[mirror][unwarp]") {
  const MirrorModel model;
  const auto inner = omnislam::mirror::make_panorama_map(model, Lobe::kInner);
  const auto outer = omnislam::mirror::make_panorama_map(model, Lobe::kOuter);
  REQUIRE(inner.rows == 225);
  REQUIRE(inner.columns == 360);
  REQUIRE(inner.u_px.size() == 225u * 360u);
  REQUIRE(outer.v_px.size() == 225u * 360u);
  for (int row : {0, 79, 224}) {
    for (int column : {0, 18, 89, 90, 180, 359}) {
      CAPTURE(row, column);
      const std::size_t index = static_cast<std::size_t>(row) * 360 + column;
      const double phi = (column + 0.5) * std::numbers::pi / 180.0;
      // u along base_link +x, v along +y: image angle atan2(v - cy, u - cx) equals azimuth.
      CHECK(inner.u_px[index] == Approx(511.5 + (286.5 - row) * std::cos(phi)).margin(1e-4));
      CHECK(inner.v_px[index] == Approx(511.5 + (286.5 - row) * std::sin(phi)).margin(1e-4));
      CHECK(std::atan2(outer.v_px[index] - 511.5, outer.u_px[index] - 511.5) ==
            Approx(std::remainder(phi, 2 * std::numbers::pi)).margin(1e-6));
      CHECK(std::hypot(outer.u_px[index] - 511.5, outer.v_px[index] - 511.5) ==
            Approx(511.5 - row).margin(1e-4));
    }
  }
}

TEST_CASE("azimuth offset rotates the columns", "[mirror][unwarp]") {
  omnislam::mirror::MirrorConfig config;
  config.azimuth_offset_deg = 90.0;
  CHECK(omnislam::mirror::column_azimuth_rad(config, 0) * 180.0 / std::numbers::pi == Approx(90.5));
  const auto map = omnislam::mirror::make_panorama_map(MirrorModel(config), Lobe::kInner);
  CHECK(map.u_px[0] == Approx(511.5 + 286.5 * std::cos(90.5 * std::numbers::pi / 180.0)).margin(1e-4));
  CHECK(map.v_px[0] == Approx(511.5 + 286.5 * std::sin(90.5 * std::numbers::pi / 180.0)).margin(1e-4));
}
