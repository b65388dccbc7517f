#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Correlative scan matching over a whole map by branch and bound: the pose (x, y, yaw) at
/// which a scan best overlays the map's points, searched exhaustively on a grid without
/// visiting most of it. A likelihood grid scores each scan point by its distance to the
/// nearest map point; coarser grids hold the maximum over blocks of 2^k x 2^k cells, so the
/// score of a block of translations is bounded from above by one lookup per point, and
/// blocks that cannot beat what is already found are never opened.

namespace omnislam::slam {

struct CorrelativeMatcherConfig {
  double resolution_m = 0.05;  ///< grid cell; the translation step of the search
  /// Fall-off of a point's score with its distance to the map: the map fuses points within
  /// 0.05 m (PointMapConfig::fusion_radius_m), so a point that far off is still on the wall.
  double sigma_m = 0.05;
  /// The scan is thinned to one point per cell of this size (evenly weighted structure,
  /// bounded cost).
  double scan_voxel_m = 0.05;
};

/// A region of poses to search: within radius_m of the centre and half_angle_rad of its yaw.
struct SearchWindow {
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  double radius_m = 0.0;
  double half_angle_rad = 0.0;
};

struct PoseCandidate {
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  double score = 0.0;  ///< mean point score in [0, 1]
};

class CorrelativeMatcher {
 public:
  /// Builds the likelihood grid and its block maxima over the map's points (metres).
  explicit CorrelativeMatcher(const Points2 &map_points, CorrelativeMatcherConfig config = {});

  /// Every distinct pose (apart by more than `distinct_m` or `distinct_rad` from a better one)
  /// scoring at least `min_score` and at least `relative_score` times the best, best first.
  /// Without a window the whole map is searched, at every yaw.
  [[nodiscard]] std::vector<PoseCandidate> search(const Points2 &scan_base, double min_score,
                                                  double relative_score, double distinct_m,
                                                  double distinct_rad,
                                                  const std::optional<SearchWindow> &window = {}) const;

  /// Mean point score of the scan at a pose (bilinear in the likelihood grid).
  [[nodiscard]] double score(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base) const;

  /// Log-likelihood of the scan at a pose: sum over its points of ln(outlier_share + (1 -
  /// outlier_share) * score), a point off the map's structure costing at most ln(outlier_share).
  [[nodiscard]] double log_likelihood(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                      double outlier_share) const;

  [[nodiscard]] bool empty() const { return width_ == 0; }
  /// The scan thinned to one point per scan_voxel_m cell (what search and log_likelihood use).
  [[nodiscard]] Points2 thinned(const Points2 &scan_base) const;
  [[nodiscard]] const CorrelativeMatcherConfig &config() const { return config_; }

 private:
  /// Value of level `level` at cell (x, y); 0 outside the grid.
  [[nodiscard]] float at(int level, int x, int y) const;
  /// Score of one map-frame point, bilinear in the likelihood grid.
  [[nodiscard]] double point_score(const Eigen::Vector2d &point_map) const;

  CorrelativeMatcherConfig config_;
  Eigen::Vector2d origin_m_ = Eigen::Vector2d::Zero();  ///< map position of cell (0, 0)'s corner
  int width_ = 0;
  int height_ = 0;
  int padding_ = 0;  ///< cells stored before (0, 0) in x and y: blocks that start off the map
  int stride_ = 0;
  /// levels_[k]: for each cell, the maximum likelihood over the 2^k x 2^k block starting
  /// there (level 0: the likelihood itself).
  std::vector<std::vector<float>> levels_;
};

}  // namespace omnislam::slam
