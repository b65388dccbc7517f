#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>

#include "omnislam/dds/odometry_buffer.hpp"
#include "omnislam/dds/participant.hpp"

/// @file
/// nav_msgs/Odometry from the robot base (rt/odom), matched to frames by timestamp.

namespace omnislam::dds {

/// Reads rt/odom (or another topic) without a thread of its own: poll() takes what has
/// arrived. Not thread-safe: one thread (the pipeline's capture stage) polls and looks up.
class OdometryReader {
 public:
  explicit OdometryReader(const Participant &participant, const std::string &topic = "rt/odom",
                          OdometryLookup lookup = {}, std::size_t keep = 2000);

  /// Takes the samples that arrived since the last call; returns how many.
  std::size_t poll();

  /// The odometry pose at `stamp_s` (OdometryBuffer::at); empty in a gap of the stream.
  [[nodiscard]] std::optional<Eigen::Isometry2d> at(double stamp_s) const {
    return buffer_.at(stamp_s, lookup_);
  }

  [[nodiscard]] std::size_t size() const { return buffer_.size(); }
  /// Samples dropped for a non-finite stamp or pose.
  [[nodiscard]] std::size_t rejected() const { return rejected_; }

 private:
  std::int32_t reader_ = 0;
  OdometryLookup lookup_;
  OdometryBuffer buffer_;
  std::size_t rejected_ = 0;
};

}  // namespace omnislam::dds
