#include "omnislam/dds/odometry_buffer.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace omnislam::dds {
void OdometryBuffer::insert(const Sample &sample) {
  const auto at = std::lower_bound(samples_.begin(), samples_.end(), sample.stamp_s,
                                   [](const Sample &s, double t) { return s.stamp_s < t; });
  if (at != samples_.end() && at->stamp_s == sample.stamp_s) {
    *at = sample;
  } else {
    samples_.insert(at, sample);
  }
  while (samples_.size() > keep_) samples_.pop_front();
}

std::optional<Eigen::Isometry2d> OdometryBuffer::at(double stamp_s, const OdometryLookup &lookup) const {
  if (samples_.empty() || stamp_s < samples_.front().stamp_s) return std::nullopt;
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp_s,
                                      [](const Sample &s, double t) { return s.stamp_s < t; });
  if (after == samples_.end()) {
    const Sample &last = samples_.back();
    if (stamp_s - last.stamp_s > lookup.max_extrapolation_s) return std::nullopt;
    return slam::planar_pose(last.x_m, last.y_m, last.yaw_rad);
  }
  if (after->stamp_s == stamp_s) return slam::planar_pose(after->x_m, after->y_m, after->yaw_rad);
  const Sample &a = *(after - 1);  // after != begin: stamp_s >= the first stamp
  const Sample &b = *after;
  if (b.stamp_s - a.stamp_s > lookup.max_interpolation_gap_s) {
    // A gap: only a frame close after its start gets the sample before it (as live frames
    // get the newest sample).
    if (stamp_s - a.stamp_s > lookup.max_extrapolation_s) return std::nullopt;
    return slam::planar_pose(a.x_m, a.y_m, a.yaw_rad);
  }
  const double w = (stamp_s - a.stamp_s) / (b.stamp_s - a.stamp_s);
  const double dyaw = std::remainder(b.yaw_rad - a.yaw_rad, 2.0 * std::numbers::pi);
  return slam::planar_pose(a.x_m + w * (b.x_m - a.x_m), a.y_m + w * (b.y_m - a.y_m), a.yaw_rad + w * dyaw);
}

}  // namespace omnislam::dds
