#include "omnislam/dds/initial_pose_reader.hpp"

#include <array>
#include <cmath>

#include "messages.hpp"

namespace omnislam::dds {

InitialPoseReader::InitialPoseReader(const Participant &participant, const std::string &topic)
    : reader_(detail::create_endpoint(participant.handle(),
                                      geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, topic.c_str(),
                                      detail::kInitialPoseQos, false)) {}

std::vector<InitialPose> InitialPoseReader::poll() {
  constexpr int kBatch = 8;
  std::vector<InitialPose> received;
  for (;;) {
    std::array<void *, kBatch> samples{};
    std::array<dds_sample_info_t, kBatch> infos{};
    const int n = dds_take(reader_, samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) break;
    for (int i = 0; i < n; ++i) {
      if (!infos[static_cast<std::size_t>(i)].valid_data) continue;
      const auto &msg = *static_cast<const geometry_msgs_msg_dds__PoseWithCovarianceStamped_ *>(
          samples[static_cast<std::size_t>(i)]);
      const auto &p = msg.pose.pose.position;
      const auto &q = msg.pose.pose.orientation;
      const double yaw = std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
      InitialPose pose;
      pose.stamp_s = detail::to_seconds(msg.header.stamp);
      pose.frame_id = msg.header.frame_id != nullptr ? msg.header.frame_id : "";
      pose.T_map_base = Eigen::Translation2d(p.x, p.y) * Eigen::Rotation2Dd(yaw);
      // Rows and columns x, y and rot z of ROS's (x, y, z, rot x, rot y, rot z).
      constexpr std::array<int, 3> kIndex = {0, 1, 5};
      bool finite =
          std::isfinite(pose.stamp_s) && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(yaw);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          const double v =
              msg.pose
                  .covariance[kIndex[static_cast<std::size_t>(r)] * 6 + kIndex[static_cast<std::size_t>(c)]];
          finite = finite && std::isfinite(v);
          pose.covariance(r, c) = v;
        }
      }
      if (!finite) {
        ++rejected_;
        continue;
      }
      received.push_back(std::move(pose));
    }
    dds_return_loan(reader_, samples.data(), n);
    if (n < kBatch) break;
  }
  return received;
}

}  // namespace omnislam::dds
