#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "ros2.h"

// Golden bytes of the messages omnislamd reads (rt/odom, rt/initialpose): the CDR that
// Cyclone DDS produces from interfaces/ros2.idl (the layouts omnislamd's readers use) equals
// what rosbags serialises for the same values (tests/dds/golden/*.hex, written by
// tests/python/golden_cdr.py). The sample goes through a writer to a reader of the same
// participant and is taken as serialised data.

namespace {

std::string golden(const char *name) {
  std::ifstream in(std::string(OMNISLAM_GOLDEN_DIR) + "/" + name + ".hex");
  std::string text;
  in >> text;
  return text;
}

std::string hex(const std::vector<unsigned char> &bytes) {
  std::string text;
  char digits[3];
  for (const unsigned char b : bytes) {
    std::snprintf(digits, sizeof digits, "%02x", b);
    text += digits;
  }
  return text;
}

// Writes `sample` on a topic of `type` and returns its serialised form, 4-byte encapsulation
// header included, as a reader of the same participant takes it.
std::vector<unsigned char> cdr_of(const dds_topic_descriptor_t &type, const void *sample) {
  const dds_domainid_t domain = static_cast<dds_domainid_t>(100 + (getpid() * 2 + 15) % 100);
  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  REQUIRE(participant > 0);
  const dds_entity_t topic = dds_create_topic(participant, &type, "golden", nullptr, nullptr);
  dds_qos_t *qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
  const dds_entity_t writer = dds_create_writer(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  REQUIRE(reader > 0);
  REQUIRE(writer > 0);
  REQUIRE(dds_write(writer, sample) == DDS_RETCODE_OK);
  struct ddsi_serdata *serdata = nullptr;
  dds_sample_info_t info;
  int taken = 0;
  for (int attempt = 0; attempt < 200 && taken <= 0; ++attempt) {  // local delivery: at once, in practice
    taken = dds_takecdr(reader, &serdata, 1, &info, 0);
    if (taken <= 0) dds_sleepfor(DDS_MSECS(10));
  }
  REQUIRE(taken == 1);
  std::vector<unsigned char> bytes(ddsi_serdata_size(serdata));
  ddsi_serdata_to_ser(serdata, 0, bytes.size(), bytes.data());
  ddsi_serdata_unref(serdata);
  dds_delete(participant);
  return bytes;
}

geometry_msgs_msg_dds__PoseWithCovariance_ pose_with_covariance() {
  geometry_msgs_msg_dds__PoseWithCovariance_ pose{};
  pose.pose.position = {1.5, -2.25, 0.0};
  pose.pose.orientation = {0.0, 0.0, 0.6, 0.8};
  for (int i = 0; i < 36; ++i) pose.covariance[i] = 0.01 * i;
  return pose;
}

}  // namespace

TEST_CASE("golden bytes: nav_msgs/Odometry as omnislamd's rt/odom reader decodes it", "[dds][golden]") {
  nav_msgs_msg_dds__Odometry_ odometry{};
  odometry.header.stamp = {1700000000, 250000000};
  odometry.header.frame_id = const_cast<char *>("odom");
  odometry.child_frame_id = const_cast<char *>("base_link");
  odometry.pose = pose_with_covariance();
  odometry.twist.twist.linear = {0.3, 0.0, 0.0};
  odometry.twist.twist.angular = {0.0, 0.0, 0.1};
  for (int i = 0; i < 36; ++i) odometry.twist.covariance[i] = 0.01 * i;
  const std::string expected = golden("odometry");
  REQUIRE(expected.size() == 2 * 724);
  CHECK(hex(cdr_of(nav_msgs_msg_dds__Odometry__desc, &odometry)) == expected);
}

TEST_CASE("golden bytes: geometry_msgs/PoseWithCovarianceStamped as rt/initialpose carries it",
          "[dds][golden]") {
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ initial{};
  initial.header.stamp = {1700000000, 250000000};
  initial.header.frame_id = const_cast<char *>("map");
  initial.pose = pose_with_covariance();
  const std::string expected = golden("initialpose");
  REQUIRE(expected.size() == 2 * 364);
  CHECK(hex(cdr_of(geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc, &initial)) == expected);
}
