#include "omnislam/dds/echo.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <thread>

#include "messages.hpp"

namespace omnislam::dds {
namespace {

using namespace detail;
using Printer = std::function<void(const void *, std::FILE *)>;

double yaw_of(const geometry_msgs_msg_dds__Quaternion_ &q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

void print_pose(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const geometry_msgs_msg_dds__PoseWithCovarianceStamped_ *>(sample);
  std::fprintf(out, "pose stamp=%.9f frame=%s x=%.9f y=%.9f yaw=%.9f var_x=%.3e var_y=%.3e var_yaw=%.3e\n",
               to_seconds(m.header.stamp), m.header.frame_id, m.pose.pose.position.x, m.pose.pose.position.y,
               yaw_of(m.pose.pose.orientation), m.pose.covariance[0], m.pose.covariance[7],
               m.pose.covariance[35]);
}

void print_odometry(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const nav_msgs_msg_dds__Odometry_ *>(sample);
  std::fprintf(out, "odom stamp=%.9f x=%.9f y=%.9f yaw=%.9f\n", to_seconds(m.header.stamp),
               m.pose.pose.position.x, m.pose.pose.position.y, yaw_of(m.pose.pose.orientation));
}

void print_map(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const sensor_msgs_msg_dds__PointCloud2_ *>(sample);
  std::fprintf(out, "map stamp=%.9f frame=%s points=%u point_step=%u fields=%u\n", to_seconds(m.header.stamp),
               m.header.frame_id, m.width * m.height, m.point_step, m.fields._length);
}

void print_scan(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const sensor_msgs_msg_dds__LaserScan_ *>(sample);
  unsigned valid = 0;
  for (uint32_t i = 0; i < m.ranges._length; ++i) valid += std::isfinite(m.ranges._buffer[i]) ? 1u : 0u;
  std::fprintf(out, "scan stamp=%.9f beams=%u valid=%u\n", to_seconds(m.header.stamp), m.ranges._length,
               valid);
}

void print_profile(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const omnislam_msg_dds__StageProfile_ *>(sample);
  std::fprintf(
      out, "profile stamp=%.9f captured=%llu dropped=%llu out=%llu latency_p50_ms=%.3f latency_p99_ms=%.3f",
      to_seconds(m.header.stamp), static_cast<unsigned long long>(m.frames_captured),
      static_cast<unsigned long long>(m.frames_dropped), static_cast<unsigned long long>(m.frames_out),
      m.latency.p50_ms, m.latency.p99_ms);
  for (uint32_t i = 0; i < m.stages._length; ++i) {
    std::fprintf(out, " %s_ms=%.3f", m.stages._buffer[i].name, m.stages._buffer[i].mean_ms);
  }
  for (uint32_t i = 0; i < m.queues._length; ++i) {
    std::fprintf(out, " depth_%s=%d/%d", m.queues._buffer[i].name, m.queues._buffer[i].depth_max,
                 m.queues._buffer[i].capacity);
  }
  std::fputc('\n', out);
}

void print_status(const void *sample, std::FILE *out) {
  const auto &m = *static_cast<const omnislam_msg_dds__Status_ *>(sample);
  std::fprintf(out, "status stamp=%.9f state=%s in=%llu out=%llu dropped=%llu error=\"%s\"\n",
               to_seconds(m.header.stamp), m.state_name, static_cast<unsigned long long>(m.frames_in),
               static_cast<unsigned long long>(m.frames_out),
               static_cast<unsigned long long>(m.frames_dropped), m.last_error);
}

struct TopicType {
  const char *name;
  const dds_topic_descriptor_t *type;
  TopicQos qos;
  Printer print;
};

const TopicType &topic_type(const std::string &topic) {
  static const std::array<TopicType, 6> kTopics = {{
      {"rt/omnislam/pose", &geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, kPoseQos, print_pose},
      {"rt/omnislam/map", &sensor_msgs_msg_dds__PointCloud2__desc, kMapQos, print_map},
      {"rt/omnislam/scan", &sensor_msgs_msg_dds__LaserScan__desc, kScanQos, print_scan},
      {"rt/omnislam/profile", &omnislam_msg_dds__StageProfile__desc, kProfileQos, print_profile},
      {"rt/omnislam/status", &omnislam_msg_dds__Status__desc, kStatusQos, print_status},
      {"rt/odom", &nav_msgs_msg_dds__Odometry__desc, kOdomQos, print_odometry},
  }};
  for (const TopicType &t : kTopics) {
    if (topic == t.name) return t;
  }
  throw std::invalid_argument("unknown topic " + topic +
                              " (rt/omnislam/{pose,map,scan,profile,status} or rt/odom)");
}

}  // namespace

std::string dds_topic_name(const std::string &name) {
  if (name.rfind("rt/", 0) == 0) return name;
  return "rt/" + (name.rfind('/', 0) == 0 ? name.substr(1) : name);
}

long echo(const Participant &participant, const std::string &topic, const EchoOptions &options,
          const std::atomic<bool> &stop, std::FILE *out) {
  const TopicType &type = topic_type(dds_topic_name(topic));
  // A reader is transient-local where the writer is, so the last map and status arrive.
  const dds_entity_t reader = create_endpoint(participant.handle(), *type.type, type.name, type.qos, false);
  const auto start = std::chrono::steady_clock::now();
  long printed = 0;
  constexpr int kBatch = 16;
  while (!stop.load(std::memory_order_relaxed)) {
    if (options.timeout_s > 0.0 &&
        std::chrono::steady_clock::now() - start > std::chrono::duration<double>(options.timeout_s)) {
      break;
    }
    std::array<void *, kBatch> samples{};
    std::array<dds_sample_info_t, kBatch> infos{};
    const int n = dds_take(reader, samples.data(), infos.data(), kBatch, kBatch);
    for (int i = 0; i < n && (options.max_messages == 0 || printed < options.max_messages); ++i) {
      if (!infos[static_cast<std::size_t>(i)].valid_data) continue;
      type.print(samples[static_cast<std::size_t>(i)], out);
      ++printed;
    }
    if (n > 0) dds_return_loan(reader, samples.data(), n);
    std::fflush(out);
    if (options.max_messages > 0 && printed >= options.max_messages) break;
    if (n <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  dds_delete(reader);
  return printed;
}

}  // namespace omnislam::dds
