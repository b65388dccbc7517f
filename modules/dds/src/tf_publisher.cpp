#include "omnislam/dds/tf_publisher.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "messages.hpp"

namespace omnislam::dds {

TfPublisher::TfPublisher(const Participant &participant)
    : writer_(detail::create_endpoint(participant.handle(), tf2_msgs_msg_dds__TFMessage__desc, "rt/tf",
                                      detail::kTfQos, true)) {}

void TfPublisher::publish(double stamp_s, std::span<const FrameTransform> transforms) const {
  std::vector<geometry_msgs_msg_dds__TransformStamped_> stamped(transforms.size());
  for (std::size_t i = 0; i < transforms.size(); ++i) {
    const FrameTransform &t = transforms[i];
    const Eigen::Rotation2Dd rotation(t.T_parent_child.linear());
    const double yaw = rotation.angle();
    geometry_msgs_msg_dds__TransformStamped_ &out = stamped[i];
    out.header.stamp = detail::to_time(stamp_s);
    out.header.frame_id = const_cast<char *>(t.parent.c_str());
    out.child_frame_id = const_cast<char *>(t.child.c_str());
    out.transform.translation = {t.T_parent_child.translation().x(), t.T_parent_child.translation().y(), 0.0};
    out.transform.rotation = {0.0, 0.0, std::sin(yaw / 2.0), std::cos(yaw / 2.0)};
  }
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms._buffer = stamped.data();
  message.transforms._length = message.transforms._maximum = static_cast<uint32_t>(stamped.size());
  message.transforms._release = false;
  const dds_return_t rc = dds_write(writer_, &message);
  if (rc < 0) throw std::runtime_error(std::string("DDS: write on rt/tf: ") + dds_strretcode(rc));
}

}  // namespace omnislam::dds
