#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Accuracy of a run against ground truth (architecture.md `omnislam evaluate`): trajectory
/// error without alignment (both trajectories start at the map frame) and map error against
/// floor-plan segments.

namespace omnislam::slam {

struct TrajectoryError {
  double rmse_m = 0.0;
  double max_m = 0.0;
  double final_m = 0.0;
  int max_frame = 0;                ///< 0-based index of the largest error
  std::vector<double> per_frame_m;  ///< position error of each frame
};

/// Position errors of `estimate` against `truth`, frame by frame (equal lengths required;
/// throws std::invalid_argument otherwise). Both are poses of base_link in the map frame.
[[nodiscard]] TrajectoryError trajectory_error(const std::vector<Eigen::Isometry2d> &estimate,
                                               const std::vector<Eigen::Isometry2d> &truth);

/// Whether a run's covariances describe its errors (issue 13, "honest covariance").
struct CovarianceConsistency {
  int frames = 0;                ///< frames with an invertible covariance (the first, P = 0, is not)
  double mean_nees = 0.0;        ///< of (x, y, yaw): about 3 when the covariance is consistent
  double inside_95_share = 0.0;  ///< positions inside their own 95% ellipse (0.95 when consistent)
};

/// NEES e^T P^-1 e of each frame's (x, y, yaw) error (yaw wrapped) and the share of positions
/// with e_xy^T P_xy^-1 e_xy within the chi-square 95% bound of 2 degrees of freedom.
[[nodiscard]] CovarianceConsistency covariance_consistency(const std::vector<Eigen::Isometry2d> &estimate,
                                                           const std::vector<Eigen::Isometry2d> &truth,
                                                           const std::vector<Eigen::Matrix3d> &covariances);

struct Segment2 {
  Point2 a = Point2::Zero();
  Point2 b = Point2::Zero();
};

/// Distance from a point to a segment.
[[nodiscard]] double distance_to_segment(const Point2 &p, const Segment2 &segment);

struct MapError {
  std::size_t points = 0;
  double median_distance_m = 0.0;  ///< of map points to their nearest floor-plan segment
  double p90_distance_m = 0.0;
  double completeness = 0.0;  ///< share of floor-plan length with a map point within the radius
};

/// Map points against the floor plan; completeness samples the segments every 1 cm.
[[nodiscard]] MapError map_error(const Points2 &map_points, const std::vector<Segment2> &floorplan,
                                 double completeness_radius_m = 0.1);

}  // namespace omnislam::slam
