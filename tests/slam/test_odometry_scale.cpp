#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/odometry_scale.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// The odometry's distance factor (slam/odometry_scale.hpp): learnt where the scans pin the
// position, applied along a plain corridor where only the odometry tells how far.

using namespace omnislam::slam;
using omnislam::test::pose;

namespace {

const Eigen::Matrix2d kStepNoise = Eigen::Matrix2d::Identity() * 1e-4;  // 10 mm a step
const Eigen::Matrix2d kPinned = Eigen::Matrix2d::Identity() * 4e-6;     // 2 mm

// Feeds a straight drive of `steps` 0.25 m steps whose odometry reads `factor` times the
// distance, every frame pinned at its true pose.
void drive(OdometryScale &scale, double factor, int steps, double yaw = 0.3) {
  for (int i = 0; i <= steps; ++i) {
    const double d = 0.25 * i;
    const Eigen::Isometry2d truth = pose(d * std::cos(yaw), d * std::sin(yaw), yaw);
    const Eigen::Isometry2d odometry = pose(factor * d, 0.0, 0.0);  // another odom frame
    scale.add_step(odometry, kStepNoise);
    scale.pin(odometry, truth, kPinned);
  }
}

}  // namespace

TEST_CASE("OdometryScale learns how far the odometry reads long or short", "[slam][odometry_scale]") {
  for (const double factor : {1.03, 0.95}) {
    OdometryScale scale;
    drive(scale, factor, 40);
    INFO("odometry reads " << factor << ": learnt " << scale.scale() << " +- " << scale.sigma());
    CHECK(scale.scale() == Approx(1.0 / factor).epsilon(0.003));
    CHECK(scale.sigma() < 0.01);
    CHECK(scale.significant());
    CHECK(scale.applied() == scale.scale());
    CHECK(scale.segments() == 40);
  }
  OdometryScale truthful;
  drive(truthful, 1.0, 40);
  CHECK(truthful.scale() == Approx(1.0).margin(1e-9));
  CHECK_FALSE(truthful.significant());
  CHECK(truthful.applied() == 1.0);  // an odometry that reads true is left exactly as it is
  CHECK(truthful.applied_sigma() == 0.0);
}

TEST_CASE("OdometryScale: a corridor's segment measures the distance between its pinned ends",
          "[slam][odometry_scale]") {
  OdometryScale scale;
  const double factor = 1.04;
  // Pinned at the start, 40 steps unpinned (a plain corridor), pinned at the end.
  for (int i = 0; i <= 40; ++i) {
    const Eigen::Isometry2d odometry = pose(factor * 0.25 * i, 0.0, 0.0);
    scale.add_step(odometry, kStepNoise);
    if (i == 0 || i == 40) scale.pin(odometry, pose(0.25 * i, 0.0, 0.0), kPinned);
  }
  CHECK(scale.segments() == 1);
  // One segment of 10 m: the 40 steps' noise (sqrt(40) x 10 mm) over 10 m, against the prior.
  CHECK(scale.sigma() == Approx(std::sqrt(40.0) * 0.01 / 10.0).epsilon(0.05));
  CHECK(scale.scale() == Approx(1.0 / factor).epsilon(0.002));
}

TEST_CASE("OdometryScale leaves out outliers and segments across a break", "[slam][odometry_scale]") {
  OdometryScale scale;
  drive(scale, 1.0, 20);
  const double before = scale.scale();
  // A registration gone wrong: 1 m off after a 0.25 m step.
  scale.add_step(pose(5.25, 0.0, 0.0), kStepNoise);
  scale.pin(pose(5.25, 0.0, 0.0), pose(6.5, 0.0, 0.0), kPinned);
  CHECK(scale.outliers() == 1);
  CHECK(scale.scale() == before);
  // A break (a gap in the odometry, a carried robot): the next pinned frame measures nothing.
  scale.break_chain();
  scale.add_step(pose(9.0, 0.0, 0.0), kStepNoise);
  scale.pin(pose(9.0, 0.0, 0.0), pose(7.0, 0.0, 0.0), kPinned);
  CHECK(scale.segments() == 20);
  CHECK(scale.scale() == before);
  // Disabled: the odometry as it reads.
  OdometryScale off({.enabled = false});
  drive(off, 1.05, 20);
  CHECK(off.scale() == 1.0);
  CHECK(off.applied() == 1.0);
}

TEST_CASE("SLAM: along a plain corridor the learnt factor keeps a long-reading odometry's robot in place",
          "[slam][odometry_scale]") {
  // A 4 x 4 m room opening into a corridor 1.2 m wide and 16 m long; scans reach 3 m, so
  // deep in the corridor nothing pins the position along it. The robot drives two laps of
  // the room (the scans pin every frame there), then 10 m down the corridor. Its wheels read
  // every distance 5% long, with the thesis model's random error on top.
  std::vector<omnislam::test::Segment> walls = {
      {{0, 0}, {4, 0}}, {{4, 0}, {4, 1.4}},    {{4, 2.6}, {4, 4}},    {{4, 4}, {0, 4}},
      {{0, 4}, {0, 0}}, {{4, 1.4}, {20, 1.4}}, {{4, 2.6}, {20, 2.6}}, {{20, 1.4}, {20, 2.6}}};
  walls.push_back({{1.2, 1.2}, {1.8, 1.2}});  // a box in the room
  walls.push_back({{1.8, 1.2}, {1.8, 1.8}});
  walls.push_back({{1.8, 1.8}, {1.2, 1.8}});
  walls.push_back({{1.2, 1.8}, {1.2, 1.2}});
  const std::vector<Eigen::Vector2d> room_lap = {{1, 1}, {3, 1}, {3, 3}, {1, 3}, {1, 1}};
  std::vector<Eigen::Isometry2d> truth = omnislam::test::laps_along(room_lap, 2);
  for (double x = 1.0; x <= 3.0; x += 0.2) truth.push_back(pose(x, 2.0, 0.0));
  for (double x = 3.2; x <= 14.0; x += 0.2) truth.push_back(pose(x, 2.0, 0.0));
  const std::vector<Eigen::Isometry2d> exact = [&] {
    std::vector<Eigen::Isometry2d> odometry;
    for (const Eigen::Isometry2d &T : truth) {
      const Eigen::Isometry2d relative = truth.front().inverse() * T;
      odometry.push_back(
          pose(1.05 * relative.translation().x(), 1.05 * relative.translation().y(), yaw_rad_of(relative)));
    }
    return odometry;
  }();
  const auto odometry = apply_thesis_odometry_noise(exact, 7);
  const auto deepest_error = [&](bool learn) {
    SlamConfig config;
    config.odometry_scale.enabled = learn;
    config.loop_closure.enabled = false;
    Slam slam(config);
    std::mt19937_64 rng(3);
    double error = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const FrameEstimate estimate =
          slam.process(omnislam::test::scan_from(walls, truth[i], rng), odometry[i]);
      error = (estimate.T_map_base.translation() - (truth.front().inverse() * truth[i]).translation()).norm();
    }
    INFO("learnt " << slam.odometry_scale().scale() << " +- " << slam.odometry_scale().sigma());
    if (learn) CHECK(slam.odometry_scale().applied() == Approx(1.0 / 1.05).epsilon(0.02));
    return error;
  };
  const double as_read = deepest_error(false), learnt = deepest_error(true);
  INFO("error 10 m down the corridor: odometry as read " << as_read << " m, with the learnt factor " << learnt
                                                         << " m");
  CHECK(as_read > 0.3);  // 5% of the ~10 m the prior alone holds
  CHECK(learnt < 0.5 * as_read);
}

TEST_CASE("OdometryScale restores what an earlier run learnt and goes on learning from it",
          "[slam][odometry_scale]") {
  // A snapshot keeps the estimate and its sigma (io/snapshot.hpp, version 7); the same
  // wheels resumed start from it: applied from the first step, and later segments add to it
  // as if they had been measured in one run.
  OdometryScale learnt;
  drive(learnt, 1.04, 20);
  OdometryScale resumed;
  resumed.restore(learnt.scale(), learnt.sigma());
  CHECK(resumed.scale() == Approx(learnt.scale()).epsilon(1e-12));
  CHECK(resumed.sigma() == Approx(learnt.sigma()).epsilon(1e-12));
  CHECK(resumed.significant());
  CHECK(resumed.applied() == Approx(1.0 / 1.04).epsilon(0.003));
  OdometryScale one_run;
  drive(one_run, 1.04, 20);
  one_run.break_chain();  // a second drive, its chain starting afresh as the resumed one's
  drive(one_run, 1.04, 20);
  drive(resumed, 1.04, 20);
  CHECK(resumed.scale() == Approx(one_run.scale()).epsilon(1e-9));
  CHECK(resumed.sigma() == Approx(one_run.sigma()).epsilon(1e-9));
  // Nothing learnt (a sigma at the prior's, or none), or the estimator disabled: no change.
  OdometryScale fresh;
  fresh.restore(0.9, 0.05);
  CHECK(fresh.scale() == 1.0);
  fresh.restore(0.9, 0.0);
  CHECK(fresh.scale() == 1.0);
  fresh.restore(std::nan(""), 0.01);
  CHECK(fresh.scale() == 1.0);
  OdometryScale disabled(OdometryScaleConfig{.enabled = false});
  disabled.restore(0.95, 0.002);
  CHECK(disabled.applied() == 1.0);
}
