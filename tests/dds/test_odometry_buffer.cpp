#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "omnislam/dds/odometry_buffer.hpp"
#include "omnislam/slam/planar_pose.hpp"

// rt/odom samples matched to frame times, and the gaps of the stream (no DDS needed).
using omnislam::dds::OdometryBuffer;
using omnislam::dds::OdometryLookup;

TEST_CASE("odometry buffer: interpolates between samples, also across +-pi", "[dds][odometry]") {
  OdometryBuffer buffer;
  buffer.insert({10.0, 1.0, 2.0, 3.0});
  buffer.insert({10.1, 2.0, 4.0, -3.0});  // +3 rad to -3 rad: the short way, through pi
  const auto mid = buffer.at(10.05);
  REQUIRE(mid);
  CHECK(mid->translation().isApprox(Eigen::Vector2d(1.5, 3.0), 1e-9));
  CHECK(std::abs(std::remainder(omnislam::slam::yaw_rad_of(*mid) - std::numbers::pi,
                                2.0 * std::numbers::pi)) < 1e-9);
  CHECK(buffer.at(10.0)->translation().isApprox(Eigen::Vector2d(1.0, 2.0)));
}

TEST_CASE("odometry buffer: nothing before the first sample or too long after the newest",
          "[dds][odometry]") {
  OdometryBuffer buffer;
  CHECK_FALSE(buffer.at(1.0));
  buffer.insert({10.0, 1.0, 0.0, 0.0});
  CHECK_FALSE(buffer.at(9.99));
  CHECK(buffer.at(10.2)->translation().x() == 1.0);  // the newest, 0.2 s old at most
  CHECK_FALSE(buffer.at(10.21));
  CHECK(buffer.at(10.5, OdometryLookup{0.6, 0.5}));
}

TEST_CASE("odometry buffer: a gap in the stream leaves the frames inside it without odometry",
          "[dds][odometry]") {
  OdometryBuffer buffer;
  for (int i = 0; i <= 10; ++i) buffer.insert({0.05 * i, 0.01 * i, 0.0, 0.0});
  // 1.5 s without samples, then the stream resumes.
  for (int i = 0; i <= 10; ++i) buffer.insert({2.0 + 0.05 * i, 1.0 + 0.01 * i, 0.0, 0.0});
  CHECK(buffer.at(0.42));
  CHECK_FALSE(buffer.at(0.9));  // inside the gap: neither interpolated nor extrapolated
  CHECK_FALSE(buffer.at(1.9));
  CHECK(buffer.at(0.6));                            // within 0.2 s of the last sample before the gap
  CHECK(buffer.at(1.3, OdometryLookup{0.2, 2.0}));  // a larger max gap interpolates it
  CHECK(buffer.at(2.02));
}

TEST_CASE("odometry buffer: out-of-order samples go in place, duplicates replace, old ones expire",
          "[dds][odometry]") {
  OdometryBuffer buffer(3);
  buffer.insert({1.0, 1.0, 0.0, 0.0});
  buffer.insert({1.2, 3.0, 0.0, 0.0});
  buffer.insert({1.1, 2.0, 0.0, 0.0});  // late
  CHECK(buffer.at(1.05)->translation().x() == Approx(1.5));
  CHECK(buffer.at(1.15)->translation().x() == Approx(2.5));
  buffer.insert({1.1, 2.2, 0.0, 0.0});  // the same stamp again
  CHECK(buffer.size() == 3);
  CHECK(buffer.at(1.1)->translation().x() == 2.2);
  buffer.insert({1.3, 4.0, 0.0, 0.0});
  CHECK(buffer.size() == 3);
  CHECK_FALSE(buffer.at(1.05));  // the oldest sample is gone
}
