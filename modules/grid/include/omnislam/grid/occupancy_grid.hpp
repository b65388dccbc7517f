#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>
#include <vector>

/// @file
/// An occupancy grid from local scans (issue 14): each ray marks the cells it crosses as
/// free up to how far the floor was seen to be free, and the cell of its boundary point as
/// occupied, in log-odds (the usual inverse sensor model). The grid grows with what is seen.
///
/// The free floor is seen at floor level, under (or over) whatever stands above it: a cell
/// where something above the floor was seen (a table's or a desk's edge, a low box's top) is
/// not cleared by floor seen under or beyond it, before or after (it is an obstacle to a
/// robot as tall as the camera; the rays under a desk see its floor, not its top), once two
/// viewpoints at least `elevated_baseline_m` apart have seen it there: a thing in the room
/// stays where it is when the robot moves, a wrong match that moves with the robot (a
/// reflection, a texture read as a step) does not. Other cells, where the floor itself ended
/// (a wall's base, a leg, a person's feet, a step down's lower floor), are cleared by floor
/// seen through them later.

namespace omnislam::grid {

struct GridConfig {
  double resolution_m = 0.05;
  /// Inverse sensor model: P(occupied) of a cell holding a boundary point, of a cell a ray
  /// crossed as free floor; each observation adds its log-odds, clamped to the bounds.
  double hit_probability = 0.7;
  double miss_probability = 0.4;
  double min_probability = 0.12;
  double max_probability = 0.97;
  /// Trinary cells (nav2 map_server's defaults): occupied at or above, free at or below.
  double occupied_threshold = 0.65;
  double free_threshold = 0.25;
  /// Viewpoints this far apart must both see something above the floor in a cell before floor
  /// seen under it stops clearing it: five cells, so that a wrong point carried along with the
  /// robot lands in another cell from the second viewpoint.
  double elevated_baseline_m = 0.25;
};

/// One ray of a scan in the robot frame: a boundary at hit_m (NaN: none found) and free floor
/// up to free_m (NaN: unknown). `hit_elevated`: the boundary is something above the floor (a
/// table's edge, a shelf), not where something stands on it. `lower_m`: the boundary is a drop
/// (the floor ended; the ray crossed the floor's level at hit_m and went on down to a lower
/// floor seen this far in plan): every cell from hit_m to lower_m lies over the lower floor.
/// NaN: no drop.
struct Ray {
  double azimuth_rad = 0.0;
  double hit_m = 0.0;
  double free_m = 0.0;
  bool hit_elevated = false;
  double lower_m = std::numeric_limits<double>::quiet_NaN();
};

/// The grid as nav_msgs/OccupancyGrid lays it out: row-major from the cell at `origin_m`
/// (its lower-left corner), x along a row, rows towards +y; -1 unknown, 0 free, 100 occupied.
struct GridImage {
  int width = 0;
  int height = 0;
  double resolution_m = 0.05;
  Eigen::Vector2d origin_m = Eigen::Vector2d::Zero();
  std::vector<std::int8_t> cells;
  /// Per cell in the layout of `cells`, 1 where something above the floor was seen from two
  /// viewpoints (floor seen under it no longer clears it), else 0; empty when not known (a
  /// grid read from a map file). Not part of nav_msgs/OccupancyGrid: kept for resuming.
  std::vector<std::uint8_t> above_floor;
};

class OccupancyGrid {
 public:
  explicit OccupancyGrid(const GridConfig &config = {});

  /// Adds one scan taken at `T_map_base`.
  void add_scan(const Eigen::Isometry2d &T_map_base, std::span<const Ray> rays);

  /// Starts from a trinary grid (a resumed snapshot's): its occupied cells at the
  /// max_probability bound, its free cells at min_probability, its unknown cells at even
  /// odds, and the cells it marks above the floor as confirmed, so that image() gives it back
  /// (extent included) until new scans change it. Cells are matched by position; `start`
  /// should have this grid's resolution.
  void seed(const GridImage &start);

  /// The trinary grid over every cell observed so far (empty when none is).
  [[nodiscard]] GridImage image() const;

  [[nodiscard]] const GridConfig &config() const { return config_; }

 private:
  using Cell = Eigen::Vector2i;
  [[nodiscard]] Cell cell_of(const Eigen::Vector2d &point_m) const;
  /// A cell's log-odds, and whether something above the floor was seen there from two
  /// viewpoints elevated_baseline_m apart (then floor seen under it no longer counts).
  struct CellState {
    float log_odds = 0.0f;
    bool above_floor = false;
  };
  void update(CellState &state, float log_odds) const;
  /// Calls visit(cell) for the cells from `from_m` towards `to_m`, each once, in order,
  /// excluding the cell of `to_m`.
  template <typename Visit>
  void traverse(const Eigen::Vector2d &from_m, const Eigen::Vector2d &to_m, Visit &&visit) const;
  /// A boundary in `cell` seen from `origin_m`; `elevated`: something above the floor (kept
  /// against floor seen under it once two viewpoints saw it there).
  void mark_hit(const Cell &cell, const Eigen::Vector2d &origin_m, bool elevated);

  [[nodiscard]] static std::uint64_t key(const Cell &cell);

  GridConfig config_;
  float hit_ = 0.0f, miss_ = 0.0f, min_ = 0.0f, max_ = 0.0f;
  std::unordered_map<std::uint64_t, CellState> cells_;
  /// Cells where something above the floor was seen from one viewpoint so far: from where.
  std::unordered_map<std::uint64_t, Eigen::Vector2f> first_seen_above_;
};

}  // namespace omnislam::grid
