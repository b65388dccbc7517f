#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "omnislam/mirror/mirror_config.hpp"
#include "omnislam/stereo/local_scan.hpp"
#include "scan_rays.hpp"

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
}

TEST_CASE("scan rays: a column's nearest boundary is its hit; a drop before it takes its place, floor-level",
          "[app][grid]") {
  const omnislam::mirror::MirrorConfig camera;
  omnislam::stereo::LocalScan scan;
  scan.free_range_m.assign(static_cast<std::size_t>(camera.columns), kNaN);
  scan.drop_range_m.assign(static_cast<std::size_t>(camera.columns), kNaN);
  scan.drop_lower_range_m.assign(static_cast<std::size_t>(camera.columns), kNaN);
  omnislam::stereo::ScanPoint table;  // an edge above the floor in column 5 at 2 m, another in 6
  table.column = 5;
  table.range_m = 2.0;
  table.elevated = true;
  scan.points.push_back(table);
  table.column = 6;
  scan.points.push_back(table);
  scan.free_range_m[5] = 0.5f;
  scan.drop_range_m[5] = 1.5f;  // the floor ended in a drop before the table's edge
  scan.drop_lower_range_m[5] = 1.7f;
  scan.drop_range_m[6] = 2.5f;  // beyond it: the edge stays the hit
  scan.drop_lower_range_m[6] = 2.8f;
  scan.drop_range_m[7] = 1.2f;  // a drop alone
  scan.drop_lower_range_m[7] = 1.4f;
  const std::vector<omnislam::grid::Ray> rays = omnislam::app::scan_rays(scan, camera);
  REQUIRE(rays.size() == static_cast<std::size_t>(camera.columns));
  CHECK(rays[5].hit_m == Approx(1.5));
  CHECK_FALSE(rays[5].hit_elevated);
  CHECK(rays[5].free_m == Approx(0.5));
  CHECK(rays[5].lower_m == Approx(1.7));  // the lower floor it reached
  CHECK(rays[6].hit_m == Approx(2.0));
  CHECK(rays[6].hit_elevated);
  CHECK(std::isnan(rays[6].lower_m));  // the hit is no drop
  CHECK(rays[7].hit_m == Approx(1.2));
  CHECK(rays[7].lower_m == Approx(1.4));
  CHECK(std::isnan(rays[7].free_m));
  CHECK(std::isnan(rays[8].hit_m));
}
