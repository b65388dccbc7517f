#include "omnislam/grid/trajectory_grid.hpp"

#include <algorithm>
#include <cmath>

namespace omnislam::grid {

TrajectoryGrid::TrajectoryGrid(const GridConfig &config) : grid_(config) {}

void TrajectoryGrid::seed(const GridImage &start) {
  seed_ = start;
  grid_.seed(start);
}

bool TrajectoryGrid::adds_to_last(const Eigen::Isometry2d &T_map_base) const {
  if (!last_added_) return true;
  const auto &[T_map_last, reach_m] = *last_added_;
  const Eigen::Isometry2d step = T_map_last.inverse() * T_map_base;
  const double resolution_m = grid_.config().resolution_m;
  if (step.translation().norm() >= resolution_m) return true;
  const double turn_rad = std::abs(std::atan2(step.linear()(1, 0), step.linear()(0, 0)));
  return turn_rad * reach_m >= resolution_m;
}

bool TrajectoryGrid::add_scan(int trajectory_index, const Eigen::Isometry2d &T_map_base,
                              std::span<const Ray> rays, bool keep) {
  if (!adds_to_last(T_map_base)) return false;
  KeptScan scan{trajectory_index, T_map_base, {}, 0.0};
  scan.rays.reserve(rays.size());
  for (const Ray &ray : rays) {
    if (!std::isfinite(ray.hit_m) && !std::isfinite(ray.free_m)) continue;  // nothing seen
    scan.rays.push_back({static_cast<float>(ray.azimuth_rad), static_cast<float>(ray.hit_m),
                         static_cast<float>(ray.free_m), static_cast<float>(ray.lower_m), ray.hit_elevated});
    for (const double range_m : {ray.hit_m, ray.free_m, ray.lower_m})
      if (std::isfinite(range_m)) scan.reach_m = std::max(scan.reach_m, range_m);
  }
  add_to_grid(scan, T_map_base);
  last_added_ = {T_map_base, scan.reach_m};
  if (keep) scans_.push_back(std::move(scan));
  return true;
}

void TrajectoryGrid::add_to_grid(const KeptScan &scan, const Eigen::Isometry2d &T_map_base) {
  std::vector<Ray> rays;
  rays.reserve(scan.rays.size());
  for (const KeptRay &ray : scan.rays)
    rays.push_back({ray.azimuth_rad, ray.hit_m, ray.free_m, ray.hit_elevated, ray.lower_m});
  grid_.add_scan(T_map_base, rays);
}

void TrajectoryGrid::rebuild(std::span<const Eigen::Isometry2d> trajectory) {
  grid_ = OccupancyGrid(grid_.config());
  if (seed_) grid_.seed(*seed_);
  for (KeptScan &scan : scans_) {
    const bool moved =
        scan.trajectory_index >= 0 && static_cast<std::size_t>(scan.trajectory_index) < trajectory.size();
    if (moved) scan.T_map_base = trajectory[static_cast<std::size_t>(scan.trajectory_index)];
    add_to_grid(scan, scan.T_map_base);
  }
}

}  // namespace omnislam::grid
