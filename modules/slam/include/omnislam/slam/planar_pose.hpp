#pragma once

#include <Eigen/Geometry>
#include <cmath>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Planar poses (x, y, yaw about z) as Eigen::Isometry2d.

namespace omnislam::slam {

/// The rotation angle of `T`, in (-pi, pi].
[[nodiscard]] inline double yaw_rad_of(const Eigen::Isometry2d &T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

/// The pose at (x_m, y_m) turned by yaw_rad.
[[nodiscard]] inline Eigen::Isometry2d planar_pose(double x_m, double y_m, double yaw_rad) {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  T.linear() = Eigen::Rotation2Dd(yaw_rad).toRotationMatrix();
  T.translation() = Eigen::Vector2d(x_m, y_m);
  return T;
}

/// `T` with its rotation part made a rotation again (same translation and yaw). Eigen's
/// Isometry2d::inverse() takes the transpose of linear() for its inverse, so a correction
/// composed as `A * B.inverse()` and applied to B again squares B's rounding error in scale
/// (det(linear) 1 - e becomes 1 - 2e): repeated, it grows exponentially. Every pose that
/// such a correction moves is re-made with this.
[[nodiscard]] inline Eigen::Isometry2d orthonormalized(const Eigen::Isometry2d &T) {
  return planar_pose(T.translation().x(), T.translation().y(), yaw_rad_of(T));
}

/// The points moved by `T` (base_link -> map, keyframe -> map, ...).
[[nodiscard]] inline Points2 transformed(const Points2 &points, const Eigen::Isometry2d &T) {
  Points2 out;
  out.reserve(points.size());
  for (const Point2 &p : points) out.push_back(T * p);
  return out;
}

/// An (x, y, yaw) covariance given in one frame, expressed in another: R rotates vectors
/// from the first frame into the second (a keyframe's linear() takes keyframe to map).
[[nodiscard]] inline Eigen::Matrix3d rotated_covariance(const Eigen::Matrix3d &covariance,
                                                        const Eigen::Matrix2d &R) {
  Eigen::Matrix3d rotate = Eigen::Matrix3d::Identity();
  rotate.topLeftCorner<2, 2>() = R;
  return rotate * covariance * rotate.transpose();
}

/// A pose covariance (x, y, yaw in the map frame) carried from pose `from` to pose `to` by a
/// motion taken as exact: the heading's error swings the position by the lever arm.
[[nodiscard]] inline Eigen::Matrix3d carried(const Eigen::Matrix3d &covariance, const Eigen::Isometry2d &from,
                                             const Eigen::Isometry2d &to) {
  const Eigen::Vector2d lever = to.translation() - from.translation();
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 2) = -lever.y();
  F(1, 2) = lever.x();
  return F * covariance * F.transpose();
}

}  // namespace omnislam::slam
