#include "target_pose.hpp"

#include <ceres/rotation.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <vector>

namespace omnislam::calib::detail {
namespace {

// Hartley's normalisation of 2D points: centroid to the origin, mean distance sqrt(2).
Eigen::Matrix3d normalisation(const std::vector<Eigen::Vector2d> &points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d &p : points) mean += p / static_cast<double>(points.size());
  double distance = 0.0;
  for (const Eigen::Vector2d &p : points) distance += (p - mean).norm() / static_cast<double>(points.size());
  const double scale = std::sqrt(2.0) / std::max(distance, 1e-12);
  Eigen::Matrix3d T;
  T << scale, 0.0, -scale * mean.x(), 0.0, scale, -scale * mean.y(), 0.0, 0.0, 1.0;
  return T;
}

// The homography taking `from` to `to` (direct linear transform, normalised).
Eigen::Matrix3d homography(const std::vector<Eigen::Vector2d> &from, const std::vector<Eigen::Vector2d> &to) {
  const Eigen::Matrix3d T_from = normalisation(from), T_to = normalisation(to);
  Eigen::MatrixXd A(2 * from.size(), 9);
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d p = T_from * from[i].homogeneous();
    const Eigen::Vector3d q = T_to * to[i].homogeneous();
    const auto row = static_cast<Eigen::Index>(2 * i);
    A.row(row) << p.transpose(), 0.0, 0.0, 0.0, -q.x() * p.transpose();
    A.row(row + 1) << 0.0, 0.0, 0.0, p.transpose(), -q.y() * p.transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Eigen::Matrix3d H;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return T_to.inverse() * H * T_from;
}

}  // namespace

Eigen::Vector3d to_camera(const double *pose, const Eigen::Vector3d &board_m) {
  Eigen::Vector3d camera_m;
  ceres::AngleAxisRotatePoint(pose, board_m.data(), camera_m.data());
  return camera_m + Eigen::Vector3d(pose[3], pose[4], pose[5]);
}

Eigen::Isometry3d isometry_of(const Pose &pose) {
  const Eigen::Vector3d axis_angle(pose[0], pose[1], pose[2]);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (axis_angle.norm() > 0.0)
    T.linear() = Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).matrix();
  T.translation() = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return T;
}

Pose pose_of(const Eigen::Isometry3d &T) {
  const Eigen::AngleAxisd rotation(T.linear());
  const Eigen::Vector3d axis_angle = rotation.angle() * rotation.axis();
  return {axis_angle.x(),      axis_angle.y(),      axis_angle.z(),
          T.translation().x(), T.translation().y(), T.translation().z()};
}

Eigen::Isometry3d floor_isometry(const double *plane, double floor_z_m, bool face_up) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(plane[0], Eigen::Vector3d::UnitZ()).matrix();
  if (!face_up) T.linear() = T.linear() * Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  T.translation() = Eigen::Vector3d(plane[1], plane[2], floor_z_m);
  return T;
}

Eigen::Vector3d floor_to_camera(const double *plane, double floor_z_m, bool face_up,
                                const Eigen::Vector3d &board_m) {
  return floor_isometry(plane, floor_z_m, face_up) * board_m;
}

std::optional<Pose> pose_from_inner_lobe(const mirror::MirrorConfig &camera, const TargetGeometry &target,
                                         const TargetView &view, int min_corners, std::string &error) {
  const mirror::RigModel rig(camera);
  std::vector<Eigen::Vector2d> board, normalised;
  for (const TargetCorner &corner : view.corners) {
    if (corner.lobe != mirror::Lobe::kInner) continue;
    const std::optional<mirror::Ray3> ray = rig.back_project(mirror::Lobe::kInner, corner.pixel);
    if (!ray || !(ray->direction.z() < 0.0)) continue;
    // The looking-down camera's frame: x as the camera's, y and z reversed.
    normalised.emplace_back(ray->direction.x() / -ray->direction.z(),
                            ray->direction.y() / ray->direction.z());
    board.push_back(target.corner_m(corner.index).head<2>());
  }
  if (static_cast<int>(board.size()) < min_corners) {
    error =
        std::to_string(board.size()) + " corner(s) in the inner lobe, need " + std::to_string(min_corners);
    return std::nullopt;
  }
  Eigen::Matrix3d H = homography(board, normalised);
  H /= H.col(0).norm();
  if (H(2, 2) < 0.0) H = -H;  // the board in front of the focus
  Eigen::Matrix3d R;
  R << H.col(0), H.col(1), H.col(0).cross(H.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d T_down_board = Eigen::Isometry3d::Identity();
  T_down_board.linear() = svd.matrixU() * svd.matrixV().transpose();
  T_down_board.translation() = H.col(2);
  Eigen::Isometry3d T_camera_down = Eigen::Isometry3d::Identity();
  T_camera_down.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  T_camera_down.translation() =
      Eigen::Vector3d(camera.rig.mirror_offset_x_mm, camera.rig.mirror_offset_y_mm,
                      rig.design().constants(mirror::Lobe::kInner).focus_z_mm + camera.rig.mirror_dz_mm) /
      1000.0;
  return pose_of(T_camera_down * T_down_board);
}

}  // namespace omnislam::calib::detail
