#include "omnislam/dds/odometry_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "messages.hpp"

namespace omnislam::dds {
namespace {

Eigen::Isometry2d planar(double x_m, double y_m, double yaw_rad) {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  T.translation() = Eigen::Vector2d(x_m, y_m);
  T.linear() = Eigen::Rotation2Dd(yaw_rad).toRotationMatrix();
  return T;
}

}  // namespace

OdometryReader::OdometryReader(const Participant &participant, const std::string &topic, std::size_t keep)
    : reader_(detail::create_endpoint(participant.handle(), nav_msgs_msg_dds__Odometry__desc, topic.c_str(),
                                      detail::kOdomQos, false)),
      keep_(keep) {}

std::size_t OdometryReader::poll() {
  constexpr int kBatch = 32;
  std::size_t taken = 0;
  for (;;) {
    std::array<void *, kBatch> samples{};
    std::array<dds_sample_info_t, kBatch> infos{};
    const int n = dds_take(reader_, samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) break;
    for (int i = 0; i < n; ++i) {
      if (!infos[static_cast<std::size_t>(i)].valid_data) continue;
      const auto &msg =
          *static_cast<const nav_msgs_msg_dds__Odometry_ *>(samples[static_cast<std::size_t>(i)]);
      const auto &q = msg.pose.pose.orientation;
      const double yaw = std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
      const Sample sample{detail::to_seconds(msg.header.stamp), msg.pose.pose.position.x,
                          msg.pose.pose.position.y, yaw};
      // Keep the buffer ordered; an out-of-order sample is inserted in place.
      const auto at = std::upper_bound(samples_.begin(), samples_.end(), sample.stamp_s,
                                       [](double t, const Sample &s) { return t < s.stamp_s; });
      samples_.insert(at, sample);
      ++taken;
    }
    dds_return_loan(reader_, samples.data(), n);
    if (n < kBatch) break;
  }
  while (samples_.size() > keep_) samples_.pop_front();
  return taken;
}

std::optional<Eigen::Isometry2d> OdometryReader::at(double stamp_s, double max_extrapolation_s) const {
  if (samples_.empty() || stamp_s < samples_.front().stamp_s) return std::nullopt;
  const auto after = std::lower_bound(samples_.begin(), samples_.end(), stamp_s,
                                      [](const Sample &s, double t) { return s.stamp_s < t; });
  if (after == samples_.end()) {
    const Sample &last = samples_.back();
    if (stamp_s - last.stamp_s > max_extrapolation_s) return std::nullopt;
    return planar(last.x_m, last.y_m, last.yaw_rad);
  }
  if (after->stamp_s == stamp_s || after == samples_.begin())
    return planar(after->x_m, after->y_m, after->yaw_rad);
  const Sample &a = *(after - 1);
  const Sample &b = *after;
  const double w = (stamp_s - a.stamp_s) / (b.stamp_s - a.stamp_s);
  const double dyaw = std::remainder(b.yaw_rad - a.yaw_rad, 2.0 * std::numbers::pi);
  return planar(a.x_m + w * (b.x_m - a.x_m), a.y_m + w * (b.y_m - a.y_m), a.yaw_rad + w * dyaw);
}

}  // namespace omnislam::dds
