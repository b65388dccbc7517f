#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string>

#include "omnislam/dds/participant.hpp"

namespace omnislam::dds {

/// A planar transform between two named frames (REP-105: parent "map", child "odom", ...).
struct FrameTransform {
  std::string parent;
  std::string child;
  Eigen::Isometry2d T_parent_child = Eigen::Isometry2d::Identity();
};

/// Writer of rt/tf (tf2_msgs/TFMessage; reliable, volatile, depth 100 as tf2's broadcaster).
/// publish() may be called from several threads: Cyclone's write is thread-safe.
class TfPublisher {
 public:
  explicit TfPublisher(const Participant &participant);
  TfPublisher(const TfPublisher &) = delete;
  TfPublisher &operator=(const TfPublisher &) = delete;

  /// One TFMessage holding every transform, each stamped `stamp_s` (seconds).
  void publish(double stamp_s, std::span<const FrameTransform> transforms) const;

 private:
  std::int32_t writer_ = 0;
};

}  // namespace omnislam::dds
