#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "omnislam/dds/participant.hpp"

/// @file
/// nav_msgs/Odometry from the robot base (rt/odom), matched to frames by timestamp.

namespace omnislam::dds {

/// Reads rt/odom (or another topic) without a thread of its own: poll() takes what has
/// arrived. Not thread-safe: one thread (the pipeline's capture stage) polls and looks up.
class OdometryReader {
 public:
  explicit OdometryReader(const Participant &participant, const std::string &topic = "rt/odom",
                          std::size_t keep = 2000);

  /// Takes the samples that arrived since the last call; returns how many.
  std::size_t poll();

  /// The odometry pose (x, y, yaw of child in the odom frame) at `stamp_s`: interpolated
  /// between the samples around it, or the newest one when stamp_s is at most
  /// `max_extrapolation_s` after it. Empty when nothing fits.
  [[nodiscard]] std::optional<Eigen::Isometry2d> at(double stamp_s, double max_extrapolation_s = 0.2) const;

  [[nodiscard]] std::size_t size() const { return samples_.size(); }

 private:
  struct Sample {
    double stamp_s;
    double x_m, y_m, yaw_rad;
  };
  std::int32_t reader_ = 0;
  std::size_t keep_;
  std::deque<Sample> samples_;  ///< ordered by stamp
};

}  // namespace omnislam::dds
