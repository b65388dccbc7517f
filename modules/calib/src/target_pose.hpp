#pragma once

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>

#include "omnislam/calib/target_fit.hpp"

/// @file
/// A board's pose for the target fit (target_fit.cpp): its parameter blocks and the start
/// from one view's inner-lobe corners.

namespace omnislam::calib::detail {

/// T_camera_board of a board anywhere: angle-axis (rad), then translation (m).
using Pose = std::array<double, 6>;

[[nodiscard]] Eigen::Vector3d to_camera(const double *pose, const Eigen::Vector3d &board_m);
[[nodiscard]] Eigen::Isometry3d isometry_of(const Pose &pose);
[[nodiscard]] Pose pose_of(const Eigen::Isometry3d &T);

/// T_camera_board of a board lying on the floor, normal along the camera axis: `plane` is
/// (yaw rad, x m, y m), `floor_z_m` the floor's height in the camera frame; `face_up` when
/// the board's z (x cross y of its corner numbering) points up at the camera.
[[nodiscard]] Eigen::Vector3d floor_to_camera(const double *plane, double floor_z_m, bool face_up,
                                              const Eigen::Vector3d &board_m);
[[nodiscard]] Eigen::Isometry3d floor_isometry(const double *plane, double floor_z_m, bool face_up);

/// A view's pose from its corners in the inner lobe of the rig `camera` (nullopt and
/// `error` set when it has fewer than `min_corners` there). The inner lobe is central: every
/// ray passes through its focus (a tilt about that focus keeps it in place), so its rays
/// are a pinhole camera looking down from the focus, and the board's homography to that
/// camera gives the pose (Zhang 2000, sec. 3.1; the rotation made orthonormal by SVD).
[[nodiscard]] std::optional<Pose> pose_from_inner_lobe(const mirror::MirrorConfig &camera,
                                                       const TargetGeometry &target, const TargetView &view,
                                                       int min_corners, std::string &error);

}  // namespace omnislam::calib::detail
