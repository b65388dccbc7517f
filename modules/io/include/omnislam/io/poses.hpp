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

}  // namespace omnislam::io
