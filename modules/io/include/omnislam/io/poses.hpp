#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/slam/planar_pose.hpp"

/// @file
/// Conversions between TUM records and planar poses (yaw about z, z = 0 at floor level).
namespace omnislam::io {

inline Eigen::Isometry2d to_isometry(const StampedPose &pose) {
  return slam::planar_pose(pose.x_m, pose.y_m, pose.yaw_rad());
}

inline std::vector<Eigen::Isometry2d> to_isometries(const std::vector<StampedPose> &poses) {
  std::vector<Eigen::Isometry2d> out;
  out.reserve(poses.size());
  for (const StampedPose &pose : poses) out.push_back(to_isometry(pose));
  return out;
}

inline StampedPose to_stamped(double t_s, const Eigen::Isometry2d &T) {
  const double yaw = slam::yaw_rad_of(T);
  StampedPose pose;
  pose.t_s = t_s;
  pose.x_m = T.translation().x();
  pose.y_m = T.translation().y();
  pose.qz = std::sin(yaw / 2.0);
  pose.qw = std::cos(yaw / 2.0);
  return pose;
}

/// Poses relative to the first one: the map frame is the robot pose at the first frame.
inline std::vector<Eigen::Isometry2d> relative_to_first(const std::vector<Eigen::Isometry2d> &poses) {
  std::vector<Eigen::Isometry2d> out;
  out.reserve(poses.size());
  for (const Eigen::Isometry2d &T : poses) out.push_back(poses.front().inverse() * T);
  return out;
}

/// What moves one pass's odometry onto the next's when a dataset is driven round again
/// (omnislamd's input.loops, the benchmarks): the odometry accumulated over a pass, then the
/// true step from the last pose back to the first, so the odometry stays continuous, as a
/// robot's does when it drives round a room for hours. Without ground truth for every
/// frame, the identity: the odometry jumps back to its start (a robot carried back to where
/// it began, which SLAM sees as a kidnapping, the prediction off by the pass's drift).
inline Eigen::Isometry2d loop_seam(const std::vector<Eigen::Isometry2d> &odometry,
                                   const std::vector<Eigen::Isometry2d> &groundtruth) {
  const std::size_t n = odometry.size();
  if (n == 0 || groundtruth.size() != n) return Eigen::Isometry2d::Identity();
  return slam::orthonormalized(odometry[n - 1] * groundtruth[n - 1].inverse() * groundtruth[0] *
                               odometry[0].inverse());
}

/// The odometry of frame `f` (0-based) of a dataset's passes joined by `seam` (loop_seam):
/// seam^(f / n) * odometry[f % n].
inline Eigen::Isometry2d looped_odometry(const std::vector<Eigen::Isometry2d> &odometry,
                                         const Eigen::Isometry2d &seam, std::size_t f) {
  const std::size_t n = odometry.size();
  Eigen::Isometry2d offset = Eigen::Isometry2d::Identity();
  for (std::size_t pass = 0; pass < f / n; ++pass) offset = slam::orthonormalized(offset * seam);
  return offset * odometry[f % n];
}

}  // namespace omnislam::io
