#include <Eigen/Cholesky>
#include <catch2/catch.hpp>
#include <random>

#include "omnislam/slam/evaluation.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "synthetic_room.hpp"

using omnislam::slam::Points2;
using omnislam::slam::Segment2;
using omnislam::test::pose;

TEST_CASE("trajectory error: rmse, max and final position error", "[slam][evaluation]") {
  const std::vector<Eigen::Isometry2d> truth = {pose(0, 0, 0), pose(1, 0, 0), pose(2, 0, 0)};
  const std::vector<Eigen::Isometry2d> estimate = {pose(0, 0, 0), pose(1, 0.3, 0.2), pose(2, -0.4, 0)};
  const auto error = omnislam::slam::trajectory_error(estimate, truth);
  CHECK(error.max_m == Approx(0.4));
  CHECK(error.max_frame == 2);
  CHECK(error.final_m == Approx(0.4));
  CHECK(error.rmse_m == Approx(std::sqrt((0.09 + 0.16) / 3.0)));
  CHECK_THROWS_AS(omnislam::slam::trajectory_error(estimate, {pose(0, 0, 0)}), std::invalid_argument);
}

TEST_CASE("map error: distances to the floor plan and completeness", "[slam][evaluation]") {
  const std::vector<Segment2> floorplan = {{{0, 0}, {2, 0}}, {{2, 0}, {2, 1}}};
  Points2 points;
  for (int i = 0; i <= 100; ++i) points.emplace_back(i * 0.01, 0.02);  // covers x in [0, 1] of the first wall
  const auto error = omnislam::slam::map_error(points, floorplan);
  CHECK(error.points == 101);
  CHECK(error.median_distance_m == Approx(0.02));
  // 1 m + 0.1 m reach past the last point, of 3 m of walls.
  CHECK(error.completeness == Approx(1.1 / 3.0).margin(0.01));
  CHECK(omnislam::slam::distance_to_segment({3, 0.5}, floorplan[1]) == Approx(1.0));
  CHECK(omnislam::slam::distance_to_segment({-1, 0}, floorplan[0]) == Approx(1.0));
}

TEST_CASE("thesis odometry noise: seeded, bounded per step, composed", "[slam][odometry]") {
  std::vector<Eigen::Isometry2d> exact;
  for (int i = 0; i < 50; ++i) exact.push_back(pose(0.25 * i, 0.0, i < 25 ? 0.0 : 0.5));
  const auto a = omnislam::slam::apply_thesis_odometry_noise(exact, 1);
  const auto b = omnislam::slam::apply_thesis_odometry_noise(exact, 1);
  const auto c = omnislam::slam::apply_thesis_odometry_noise(exact, 2);
  REQUIRE(a.size() == exact.size());
  CHECK(a.front().isApprox(exact.front()));
  CHECK(a.back().isApprox(b.back()));
  CHECK_FALSE(a.back().isApprox(c.back()));
  for (std::size_t i = 1; i < exact.size(); ++i) {
    const Eigen::Isometry2d true_step = exact[i - 1].inverse() * exact[i];
    const Eigen::Isometry2d noisy_step = a[i - 1].inverse() * a[i];
    const double ratio = noisy_step.translation().norm() / true_step.translation().norm();
    CHECK(ratio >= 0.9);
    CHECK(ratio <= 1.1);
    const double yaw_true = std::atan2(true_step.linear()(1, 0), true_step.linear()(0, 0));
    const double yaw_noisy = std::atan2(noisy_step.linear()(1, 0), noisy_step.linear()(0, 0));
    CHECK(std::abs(yaw_noisy - yaw_true) <=
          std::max(0.1 * std::abs(yaw_true), 1.5 * std::numbers::pi / 180.0) + 1e-12);
  }
}

TEST_CASE("covariance consistency: errors drawn from the covariance give NEES ~3 and 95% inside",
          "[slam][eval]") {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix3d P;
  P << 4e-4, 1e-4, 0.0, 1e-4, 2e-4, 1e-5, 0.0, 1e-5, 1e-4;
  const Eigen::Matrix3d L = P.llt().matrixL();
  std::vector<Eigen::Isometry2d> estimate, truth;
  std::vector<Eigen::Matrix3d> covariances;
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d e = L * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const Eigen::Isometry2d t = omnislam::slam::planar_pose(0.01 * i, -0.02 * i, 0.001 * i);
    truth.push_back(t);
    estimate.push_back(omnislam::slam::planar_pose(t.translation().x() + e.x(), t.translation().y() + e.y(),
                                                   omnislam::slam::yaw_rad_of(t) + e.z()));
    covariances.push_back(P);
  }
  covariances.front().setZero();  // the first frame's: not invertible, left out
  auto consistency = omnislam::slam::covariance_consistency(estimate, truth, covariances);
  CHECK(consistency.frames == 3999);
  CHECK(consistency.mean_nees == Approx(3.0).margin(0.15));
  CHECK(consistency.inside_95_share == Approx(0.95).margin(0.015));
  // A covariance 100 times too small: NEES 100 times larger, few positions inside.
  for (Eigen::Matrix3d &c : covariances) c /= 100.0;
  consistency = omnislam::slam::covariance_consistency(estimate, truth, covariances);
  CHECK(consistency.mean_nees == Approx(300.0).epsilon(0.06));
  CHECK(consistency.inside_95_share < 0.1);
}
