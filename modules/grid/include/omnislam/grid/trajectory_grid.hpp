#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "omnislam/grid/occupancy_grid.hpp"

/// @file
/// An occupancy grid that follows a corrected trajectory (issue 14: "rebuilt when the map is
/// corrected"). It keeps the scans it was built from, each with the index of its frame in
/// the trajectory, so that after a loop closure the grid is built again from the corrected
/// poses. A scan is added only when it can change what the grid says: the robot moved by a
/// cell since the last added scan, or turned by the angle that moves the end of that scan's
/// longest ray by a cell. A robot standing still adds nothing. An added scan is kept for
/// the rebuilds when its caller says so (the service keeps those the SLAM keeps, so the
/// grid's memory is bounded as the map's is), at most 7.2 kB per kept scan of 360 rays (20
/// bytes a ray). Not thread-safe.

namespace omnislam::grid {

class TrajectoryGrid {
 public:
  explicit TrajectoryGrid(const GridConfig &config = {});

  /// Starts from a saved grid (a resumed snapshot's); it stays under every rebuild.
  void seed(const GridImage &start);

  /// Adds the scan of frame `trajectory_index` (-1: a frame whose pose no correction will
  /// move; it keeps `T_map_base`) taken at `T_map_base`, and with `keep` keeps it for the
  /// rebuilds. Returns whether it was added.
  bool add_scan(int trajectory_index, const Eigen::Isometry2d &T_map_base, std::span<const Ray> rays,
                bool keep = true);

  /// Builds the grid again: the seed, then every kept scan at `trajectory[index]` (at the
  /// pose it was added with where the index is -1 or beyond the trajectory). Scans added
  /// but not kept are gone from it.
  void rebuild(std::span<const Eigen::Isometry2d> trajectory);

  [[nodiscard]] GridImage image() const { return grid_.image(); }
  [[nodiscard]] const GridConfig &config() const { return grid_.config(); }
  [[nodiscard]] std::size_t kept_scans() const { return scans_.size(); }

 private:
  struct KeptRay {
    float azimuth_rad, hit_m, free_m, lower_m;
    bool hit_elevated;
  };
  struct KeptScan {
    int trajectory_index = -1;
    Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
    std::vector<KeptRay> rays;
    double reach_m = 0.0;  ///< the longest ray (hit or free floor)
  };
  [[nodiscard]] bool adds_to_last(const Eigen::Isometry2d &T_map_base) const;
  void add_to_grid(const KeptScan &scan, const Eigen::Isometry2d &T_map_base);

  OccupancyGrid grid_;
  std::optional<GridImage> seed_;
  std::vector<KeptScan> scans_;
  /// The last added scan's pose and longest ray (what the next one must move by a cell from).
  std::optional<std::pair<Eigen::Isometry2d, double>> last_added_;
};

}  // namespace omnislam::grid
