#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <deque>
#include <optional>

/// @file
/// Odometry samples ordered by time stamp, looked up at frame times: the part of the rt/odom
/// input that does not depend on DDS.

namespace omnislam::dds {

struct OdometryLookup {
  /// A frame up to this long after the newest sample gets the newest sample.
  double max_extrapolation_s = 0.2;
  /// Two samples further apart than this are a gap in the stream: a frame between them
  /// has no odometry (interpolating across the gap would guess the motion).
  double max_interpolation_gap_s = 0.5;
};

class OdometryBuffer {
 public:
  struct Sample {
    double stamp_s;
    double x_m, y_m, yaw_rad;
  };

  /// Keeps at most `keep` samples (the newest).
  explicit OdometryBuffer(std::size_t keep = 2000) : keep_(keep) {}

  /// Inserts in stamp order (an out-of-order sample goes in place); a second sample with an
  /// existing stamp replaces it.
  void insert(const Sample &sample);

  /// The odometry pose (x, y, yaw of the base in the odom frame) at `stamp_s`: interpolated
  /// between the samples around it, or the newest one when stamp_s is at most
  /// max_extrapolation_s after it (the same at the start of a gap). Empty before the first
  /// sample, further into a gap, or too long after the newest sample.
  [[nodiscard]] std::optional<Eigen::Isometry2d> at(double stamp_s, const OdometryLookup &lookup = {}) const;

  [[nodiscard]] std::size_t size() const { return samples_.size(); }

 private:
  std::size_t keep_;
  std::deque<Sample> samples_;
};

}  // namespace omnislam::dds
