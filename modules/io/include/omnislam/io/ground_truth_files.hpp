#pragma once

#include <filesystem>
#include <vector>

/// @file
/// Trajectory (TUM) and floor-plan (CSV) files of a dataset (architecture.md).

namespace omnislam::io {

/// One line of a TUM trajectory: "t x y z qx qy qz qw" (seconds, metres, unit quaternion).
struct StampedPose {
  double t_s = 0.0;
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;
  /// Rotation about z (rad) of the pose, from the quaternion.
  [[nodiscard]] double yaw_rad() const;
};

/// Reads a TUM file ('#' comments and blank lines skipped). Throws std::runtime_error
/// naming file:line on a malformed line or an unreadable file.
[[nodiscard]] std::vector<StampedPose> read_tum_file(const std::filesystem::path &file);

/// Reads odometry in the thesis's format (annex A; architecture.md odometry.txt): line 1 is
/// the frame count, then per frame "distance_mm angle_deg" of the translation since the
/// previous frame (angle in the map frame from +x towards +y; heading constant). Returns
/// one pose per frame in metres, yaw 0, t = frame index. Throws naming file:line on a
/// malformed or non-finite value or a count that does not match the lines.
[[nodiscard]] std::vector<StampedPose> read_thesis_odometry(const std::filesystem::path &file);

/// A floor-plan segment in the map frame, metres.
struct FloorplanSegment {
  double x1_m = 0.0, y1_m = 0.0, x2_m = 0.0, y2_m = 0.0;
};

/// Reads floorplan.csv (header "x1,y1,x2,y2"). Throws std::runtime_error naming file:line.
[[nodiscard]] std::vector<FloorplanSegment> read_floorplan_csv(const std::filesystem::path &file);

}  // namespace omnislam::io
