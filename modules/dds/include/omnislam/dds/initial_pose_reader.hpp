#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "omnislam/dds/participant.hpp"

/// @file
/// geometry_msgs/PoseWithCovarianceStamped on rt/initialpose, as RViz's "2D Pose Estimate"
/// tool publishes it (reliable, volatile).

namespace omnislam::dds {

/// One received initial pose, planar: the sample's frame_id is passed on for the caller to
/// check (only the map frame makes sense).
struct InitialPose {
  double stamp_s = 0.0;
  std::string frame_id;
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< (x, y, yaw) from the 6x6 covariance
};

/// Reads rt/initialpose without a thread of its own. Not thread-safe: one thread (the
/// pipeline's capture stage) polls.
class InitialPoseReader {
 public:
  explicit InitialPoseReader(const Participant &participant, const std::string &topic = "rt/initialpose");

  /// The samples that arrived since the last call, oldest first. Samples with a non-finite
  /// pose, covariance or stamp are dropped and counted.
  [[nodiscard]] std::vector<InitialPose> poll();

  /// Samples dropped for a non-finite value.
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }

 private:
  std::int32_t reader_ = 0;
  std::uint64_t rejected_ = 0;
};

}  // namespace omnislam::dds
