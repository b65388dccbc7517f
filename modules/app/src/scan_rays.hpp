#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "omnislam/grid/occupancy_grid.hpp"
#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/stereo/local_scan.hpp"

namespace omnislam::app {

/// A local scan as occupancy-grid rays, one per panorama column: the boundary point of the
/// column (if any) and how far the floor was seen to be free there (floor-boundary scans).
[[nodiscard]] inline std::vector<grid::Ray> scan_rays(const stereo::LocalScan &scan,
                                                      const mirror::MirrorConfig &camera) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const int columns = camera.columns;
  std::vector<grid::Ray> rays(static_cast<std::size_t>(columns));
  for (int column = 0; column < columns; ++column) {
    const double free_m = static_cast<std::size_t>(column) < scan.free_range_m.size()
                              ? static_cast<double>(scan.free_range_m[static_cast<std::size_t>(column)])
                              : kNaN;
    rays[static_cast<std::size_t>(column)] = {mirror::column_azimuth_rad(camera, column), kNaN, free_m};
  }
  for (const stereo::ScanPoint &point : scan.points) {
    grid::Ray &ray = rays[static_cast<std::size_t>(point.column)];
    if (!std::isfinite(ray.hit_m) || point.range_m < ray.hit_m) {
      ray.hit_m = point.range_m;
      ray.hit_elevated = point.elevated;
    }
  }
  // A drop (the floor ended before a lower floor) is where the robot cannot go, from where the
  // ray crossed the floor's level to the lower floor it saw (grid::Ray); floor seen there later
  // clears it like a wall's base.
  for (std::size_t column = 0; column < scan.drop_range_m.size() && column < rays.size(); ++column) {
    grid::Ray &ray = rays[column];
    const double drop_m = scan.drop_range_m[column];
    if (std::isfinite(drop_m) && (!std::isfinite(ray.hit_m) || drop_m < ray.hit_m)) {
      ray.hit_m = drop_m;
      ray.hit_elevated = false;
      ray.lower_m = column < scan.drop_lower_range_m.size() ? scan.drop_lower_range_m[column] : drop_m;
    }
  }
  return rays;
}

}  // namespace omnislam::app
