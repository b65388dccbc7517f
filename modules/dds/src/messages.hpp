#pragma once

#include <dds/dds.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "omnislam.h"
#include "ros2.h"

// Cyclone helpers shared by the writers and readers (private to dds/).
namespace omnislam::dds::detail {

inline builtin_interfaces_msg_dds__Time_ to_time(double stamp_s) {
  double whole = std::floor(stamp_s);
  auto nanosec = static_cast<std::int64_t>(std::llround((stamp_s - whole) * 1e9));
  if (nanosec >= 1000000000) {
    nanosec -= 1000000000;
    whole += 1.0;
  }
  return {static_cast<int32_t>(whole), static_cast<uint32_t>(nanosec)};
}

inline double to_seconds(const builtin_interfaces_msg_dds__Time_ &time) {
  return static_cast<double>(time.sec) + static_cast<double>(time.nanosec) * 1e-9;
}

enum class Durability { kVolatile, kTransientLocal };

struct TopicQos {
  bool reliable = true;
  Durability durability = Durability::kVolatile;
  int depth = 10;
};

/// Creates topic + writer (or reader) with the QoS of architecture.md "DDS"; throws naming the topic.
inline dds_entity_t create_endpoint(dds_entity_t participant, const dds_topic_descriptor_t &type,
                                    const char *topic_name, TopicQos qos, bool writer) {
  dds_qos_t *q = dds_create_qos();
  dds_qset_reliability(q, qos.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
  dds_qset_durability(q, qos.durability == Durability::kTransientLocal ? DDS_DURABILITY_TRANSIENT_LOCAL
                                                                       : DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, qos.depth);
  const dds_entity_t topic = dds_create_topic(participant, &type, topic_name, nullptr, nullptr);
  dds_entity_t entity = topic;
  if (topic >= 0) {
    entity = writer ? dds_create_writer(participant, topic, q, nullptr)
                    : dds_create_reader(participant, topic, q, nullptr);
  }
  dds_delete_qos(q);
  if (entity < 0) {
    throw std::runtime_error(std::string("DDS: cannot create ") + (writer ? "a writer" : "a reader") +
                             " for " + topic_name + ": " + dds_strretcode(entity));
  }
  return entity;
}

}  // namespace omnislam::dds::detail

namespace omnislam::dds::detail {

/// Topic names and QoS (architecture.md "DDS"); readers use the same QoS to match.
inline constexpr TopicQos kPoseQos{true, Durability::kVolatile, 10};
inline constexpr TopicQos kMapQos{true, Durability::kTransientLocal, 1};
inline constexpr TopicQos kScanQos{false, Durability::kVolatile, 5};
inline constexpr TopicQos kProfileQos{true, Durability::kVolatile, 10};
inline constexpr TopicQos kStatusQos{true, Durability::kTransientLocal, 1};
/// rt/map and rt/map_metadata as nav2_map_server publishes them: a late subscriber gets the last.
inline constexpr TopicQos kGridQos{true, Durability::kTransientLocal, 1};
/// rt/tf as tf2's TransformBroadcaster writes it.
inline constexpr TopicQos kTfQos{true, Durability::kVolatile, 100};
/// rt/odom is read best effort: a best-effort reader matches reliable writers and the
/// sensor-data QoS (best effort) that base drivers use; a reliable one matches only the former.
inline constexpr TopicQos kOdomQos{false, Durability::kVolatile, 50};
/// rt/initialpose as RViz writes it (ROS 2 defaults: reliable, volatile).
inline constexpr TopicQos kInitialPoseQos{true, Durability::kVolatile, 10};

}  // namespace omnislam::dds::detail
