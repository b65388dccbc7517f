#include "omnislam/dds/odometry_reader.hpp"

#include <array>
#include <cmath>

#include "messages.hpp"

namespace omnislam::dds {

OdometryReader::OdometryReader(const Participant &participant, const std::string &topic,
                               OdometryLookup lookup, std::size_t keep)
    : reader_(detail::create_endpoint(participant.handle(), nav_msgs_msg_dds__Odometry__desc, topic.c_str(),
                                      detail::kOdomQos, false)),
      lookup_(lookup),
      buffer_(keep) {}

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
      const OdometryBuffer::Sample sample{detail::to_seconds(msg.header.stamp), msg.pose.pose.position.x,
                                          msg.pose.pose.position.y, yaw};
      if (!std::isfinite(sample.stamp_s) || !std::isfinite(sample.x_m) || !std::isfinite(sample.y_m) ||
          !std::isfinite(sample.yaw_rad)) {
        ++rejected_;  // a NaN pose would poison every frame interpolated from it
        continue;
      }
      buffer_.insert(sample);
      ++taken;
    }
    dds_return_loan(reader_, samples.data(), n);
    if (n < kBatch) break;
  }
  return taken;
}

}  // namespace omnislam::dds
