#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

using omnislam::slam::Slam;
using omnislam::slam::SlamConfig;
using omnislam::test::pose;

namespace {

struct RunErrors {
  double slam_max_m = 0.0;
  double odometry_max_m = 0.0;
  int integrated = 0;
  std::size_t map_points = 0;
};

const std::vector<Eigen::Vector2d> kLRoomLap = {{0, 0},   {5, 0}, {5, 0.6}, {1.5, 0.6},
                                                {1.5, 3}, {0, 3}, {0, 0}};

// A lap through the corners, 0.2 m steps, turning at the corners or (like the thesis's
// robot) keeping its heading.
std::vector<Eigen::Isometry2d> lap(bool turning = true,
                                   const std::vector<Eigen::Vector2d> &corners = kLRoomLap) {
  std::vector<Eigen::Isometry2d> truth;
  for (std::size_t c = 0; c + 1 < corners.size(); ++c) {
    const Eigen::Vector2d a = corners[c], b = corners[c + 1];
    const double yaw = turning ? std::atan2(b.y() - a.y(), b.x() - a.x()) : 0.0;
    const int steps = std::max(1, static_cast<int>(std::round((b - a).norm() / 0.2)));
    for (int s = 0; s < steps; ++s) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
      truth.push_back(pose(p.x(), p.y(), yaw));
    }
  }
  return truth;
}

RunErrors run(const SlamConfig &config, std::uint64_t seed, const std::vector<Eigen::Isometry2d> &truth,
              const std::vector<omnislam::test::Segment> &walls = omnislam::test::l_room()) {
  std::mt19937_64 rng(seed);
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, seed);
  Slam slam(config);
  RunErrors errors;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto scan = omnislam::test::scan_from(walls, truth[i], rng);
    const auto estimate = slam.process(scan, odometry[i]);
    const Eigen::Isometry2d T_truth = truth.front().inverse() * truth[i];
    const Eigen::Isometry2d T_odometry = odometry.front().inverse() * odometry[i];
    errors.slam_max_m =
        std::max(errors.slam_max_m, (estimate.T_map_base.translation() - T_truth.translation()).norm());
    errors.odometry_max_m =
        std::max(errors.odometry_max_m, (T_odometry.translation() - T_truth.translation()).norm());
    errors.integrated += estimate.integrated ? 1 : 0;
    if (std::getenv("OMNISLAM_TRACE"))
      std::printf("%zu err %.3f odo %.3f int %d att %d srel %.1f rms %.4f inl %.2f\n", i,
                  (estimate.T_map_base.translation() - T_truth.translation()).norm(),
                  (T_odometry.translation() - T_truth.translation()).norm(), estimate.integrated,
                  static_cast<int>(estimate.attempt), estimate.registration.srel_percent,
                  std::sqrt(estimate.registration.final_error_m2), estimate.registration.inlier_share);
  }
  errors.map_points = slam.map().points().size();
  return errors;
}

}  // namespace

TEST_CASE("SLAM with noisy odometry beats odometry on a synthetic L-room lap", "[slam]") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const RunErrors errors = run(SlamConfig{}, seed, lap());
    INFO("seed " << seed << ": slam max " << errors.slam_max_m << " m, odometry max " << errors.odometry_max_m
                 << " m, integrated " << errors.integrated << ", map points " << errors.map_points);
    CHECK(errors.slam_max_m < 0.05);
    CHECK(errors.slam_max_m < 0.5 * errors.odometry_max_m);
    CHECK(errors.integrated >= static_cast<int>(0.9 * lap().size()));
    CHECK(errors.map_points > 200);
  }
}

TEST_CASE("SLAM in thesis mode (previous scan, point-to-point, Srel test) stays bounded", "[slam]") {
  SlamConfig config;
  config.target = omnislam::slam::RegistrationTarget::kPreviousScan;
  config.use_srel_test = true;
  config.icp.metric = omnislam::slam::IcpMetric::kPointToPoint;
  for (std::uint64_t seed : {4u, 5u}) {
    const RunErrors errors = run(config, seed, lap(false));
    INFO("seed " << seed << ": slam max " << errors.slam_max_m << " m, odometry max " << errors.odometry_max_m
                 << " m, integrated " << errors.integrated);
    // The thesis chain of scan-to-scan registrations drifts along the corridor-like part of
    // the room (point-to-point pairs of sparse scans stick together; thesis sec. 5.2 saw the
    // same), and its relative Srel test rejects large corrections: it is bounded, not good.
    CHECK(errors.slam_max_m < 0.6);
    CHECK(errors.integrated >= static_cast<int>(0.4 * lap(false).size()));
  }
}

TEST_CASE("SLAM: a frame with too few points follows odometry and is not integrated", "[slam]") {
  Slam slam;
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(5);
  (void)slam.process(omnislam::test::scan_from(walls, pose(0, 0, 0), rng), pose(0, 0, 0));
  const auto estimate = slam.process({{1.0, 0.0}}, pose(0.2, 0.0, 0.0));
  CHECK_FALSE(estimate.integrated);
  CHECK(estimate.T_map_base.translation().isApprox(Eigen::Vector2d(0.2, 0.0)));
  CHECK(estimate.covariance(0, 0) > 0.0);
}

TEST_CASE("SLAM without odometry (thesis sec. 5.2) tracks a lap in a well-constrained room", "[slam]") {
  // Along the corridor-like legs of the L-room the walls cannot tell how far the robot
  // went, and without odometry nothing else can (the thesis's real-room failure); a room
  // whose walls are all in range shows the mode itself.
  SlamConfig config;
  config.use_odometry = false;
  const auto path = lap(false, {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}});
  const RunErrors errors = run(config, 6, path, omnislam::test::square_room());
  INFO("slam max " << errors.slam_max_m << " m, odometry max " << errors.odometry_max_m << " m, integrated "
                   << errors.integrated);
  CHECK(errors.slam_max_m < 0.05);
  CHECK(errors.integrated >= static_cast<int>(0.9 * path.size()));
}

TEST_CASE("SLAM: the published covariance carries the previous pose's and adds each registration's",
          "[slam][covariance]") {
  // The map each frame registers against was built from the frames before it: the covariance
  // is a random walk, the previous one carried to this pose (its heading variance swinging
  // into the position by the lever arm between the two poses) plus this registration's
  // robust one, so over a run it grows; a frame without a registration adds its odometry
  // step's instead. Each registration's is estimated with few degrees of freedom (its sectors
  // less one), summed over the walk as Welch and Satterthwaite do (terms sized by their
  // position variance), and the walk is published as the t's covariance, dof / (dof - 2)
  // times it: 1.4x after the first registration, nearer 1 as the walk sums more of them.
  Slam slam;
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(9);
  Eigen::Matrix3d walk = Eigen::Matrix3d::Zero();
  double shares = 0.0;  // sum of size^2 / dof over the walk's terms
  Eigen::Isometry2d previous_pose = Eigen::Isometry2d::Identity();
  Eigen::Matrix3d previous = Eigen::Matrix3d::Zero();
  double factor = 0.0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Isometry2d truth = pose(0.1 * i, 0.02 * i, 0.01 * i);
    const auto estimate = slam.process(omnislam::test::scan_from(walls, truth, rng), truth);
    if (i > 0) {
      REQUIRE(estimate.integrated);
      const Eigen::Matrix3d before = omnislam::slam::carried(walk, previous_pose, estimate.T_map_base);
      const double carried_size = before.topLeftCorner<2, 2>().trace();
      const double walk_size = walk.topLeftCorner<2, 2>().trace();
      // Carrying rescales the walk's earlier terms alike: its degrees of freedom stay.
      if (walk_size > 0.0) shares *= (carried_size * carried_size) / (walk_size * walk_size);
      const Eigen::Matrix3d &term = estimate.registration.robust_covariance;
      REQUIRE(estimate.registration.covariance_dof == 7.0);
      shares += std::pow(term.topLeftCorner<2, 2>().trace(), 2) / 7.0;
      walk = before + term;
      const double dof = std::pow(walk.topLeftCorner<2, 2>().trace(), 2) / shares;
      factor = dof / (dof - 2.0);
      const Eigen::Matrix3d expected = factor * walk;
      INFO("frame " << i << " dof " << dof << " covariance\n"
                    << estimate.covariance << "\nexpected\n"
                    << expected);
      CHECK(estimate.covariance.isApprox(expected, 1e-9));
      if (i == 1) CHECK(factor == Approx(1.4));
      CHECK(estimate.covariance.trace() > previous.trace());
    }
    previous = estimate.covariance;
    previous_pose = estimate.T_map_base;
  }
  CHECK(factor < 1.1);  // seven registrations of about one size: ~45 degrees of freedom
  // Too few points: no registration, the odometry step's uncertainty is added.
  const auto blind = slam.process({{1.0, 0.0}}, pose(0.9, 0.16, 0.08));
  CHECK_FALSE(blind.integrated);
  CHECK(blind.covariance(0, 0) > previous(0, 0));
}

TEST_CASE("SLAM: frames registered on the map without joining it share its covariance",
          "[slam][covariance]") {
  // Standing still (or creeping, under map_min_step_m a frame), each frame registers on the
  // same map: their errors are the map's plus their own registration's, not a sum over the
  // frames. A robot parked for an hour must publish what it published after a second; one
  // that creeps over a metre what one that drove it in map steps publishes.
  const auto walls = omnislam::test::l_room();
  auto drive = [&](const std::vector<Eigen::Isometry2d> &truth, std::vector<Eigen::Matrix3d> &covariances) {
    Slam slam;
    std::mt19937_64 rng(21);
    int mapped = 0;
    for (const Eigen::Isometry2d &T : truth) {
      const auto estimate = slam.process(omnislam::test::scan_from(walls, T, rng), T);
      REQUIRE(estimate.integrated);
      mapped += estimate.mapped ? 1 : 0;
      covariances.push_back(estimate.covariance);
    }
    return mapped;
  };
  std::vector<Eigen::Isometry2d> truth;
  for (int i = 0; i < 6; ++i) truth.push_back(pose(0.1 * i, 0.0, 0.0));
  for (int i = 0; i < 400; ++i) truth.push_back(truth.back());  // parked
  std::vector<Eigen::Matrix3d> parked;
  CHECK(drive(truth, parked) == 6);
  const double at_first_stop = parked[6].topLeftCorner<2, 2>().trace();
  double largest = 0.0, smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 6; i < parked.size(); ++i) {
    largest = std::max(largest, parked[i].topLeftCorner<2, 2>().trace());
    smallest = std::min(smallest, parked[i].topLeftCorner<2, 2>().trace());
  }
  INFO("position variance parked: first " << at_first_stop << " smallest " << smallest << " largest "
                                          << largest << " m^2");
  CHECK(largest < 1.5 * at_first_stop);
  CHECK(smallest > parked[5].topLeftCorner<2, 2>().trace());  // never below the map's own

  // The same metre driven in 0.1 m steps and crept in 0.01 m steps (a tenth under
  // map_min_step_m: every fifth frame joins the map).
  std::vector<Eigen::Isometry2d> fast, slow;
  for (int i = 0; i <= 10; ++i) fast.push_back(pose(0.1 * i, 0.0, 0.0));
  for (int i = 0; i <= 100; ++i) slow.push_back(pose(0.01 * i, 0.0, 0.0));
  std::vector<Eigen::Matrix3d> fast_covariances, slow_covariances;
  drive(fast, fast_covariances);
  CHECK(drive(slow, slow_covariances) < 30);
  const double fast_end = fast_covariances.back().topLeftCorner<2, 2>().trace();
  const double slow_end = slow_covariances.back().topLeftCorner<2, 2>().trace();
  INFO("position variance after a metre: fast " << fast_end << " slow " << slow_end << " m^2");
  CHECK(slow_end < 3.0 * fast_end);
}

TEST_CASE("SLAM: a sequential edge carries the tracking's covariance between its keyframes",
          "[slam][covariance]") {
  // The relative pose of two consecutive keyframes is as uncertain as the tracking made it:
  // the published walk's terms (each registration's robust covariance) summed over the frames
  // after the first keyframe up to the second, each sum carried by the lever arm of the
  // motion, in the first keyframe's frame, plus the floor. Along a plain corridor that is the
  // odometry prior's share, across it and in heading the registrations', so a loop closure
  // stretches the corridor instead of turning the loop.
  SlamConfig config;
  config.loop_closure.keyframes.keyframe_distance_m = 0.35;
  Slam slam(config);
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(4);
  Eigen::Matrix3d since = Eigen::Matrix3d::Zero();
  Eigen::Isometry2d previous_pose = Eigen::Isometry2d::Identity();
  Eigen::Isometry2d keyframe_pose = Eigen::Isometry2d::Identity();
  int edges_checked = 0;
  for (int i = 0; i < 12; ++i) {
    const Eigen::Isometry2d truth = pose(0.1 * i, 0.01 * i, 0.02 * i);
    const auto estimate = slam.process(omnislam::test::scan_from(walls, truth, rng), truth);
    if (i == 0) {
      REQUIRE(estimate.keyframe);
      previous_pose = keyframe_pose = estimate.T_map_base;
      continue;
    }
    REQUIRE(estimate.integrated);
    since = omnislam::slam::carried(since, previous_pose, estimate.T_map_base) +
            estimate.registration.robust_covariance;
    previous_pose = estimate.T_map_base;
    if (!estimate.keyframe) continue;
    const omnislam::slam::KeyframeConfig &floor = config.loop_closure.keyframes;
    const Eigen::Matrix3d expected =
        omnislam::slam::rotated_covariance(since, keyframe_pose.linear().transpose()) +
        Eigen::Vector3d(floor.edge_floor_xy_m * floor.edge_floor_xy_m,
                        floor.edge_floor_xy_m * floor.edge_floor_xy_m,
                        floor.edge_floor_yaw_rad * floor.edge_floor_yaw_rad)
            .asDiagonal()
            .toDenseMatrix();
    const auto &edges = slam.keyframes().graph().edges();
    REQUIRE(edges.size() == static_cast<std::size_t>(edges_checked + 1));
    const Eigen::Matrix3d edge_covariance = edges.back().information.inverse();
    INFO("edge " << edges_checked << "\n" << edge_covariance << "\nexpected\n" << expected);
    CHECK(edge_covariance.isApprox(expected, 1e-6));
    ++edges_checked;
    since.setZero();
    keyframe_pose = estimate.T_map_base;
  }
  CHECK(edges_checked >= 2);
}

TEST_CASE("SLAM: frames without odometry extrapolate the last motion and keep the pose a rotation",
          "[slam]") {
  // The extrapolated step is the last pose's inverse times this one's; Isometry2d::inverse()
  // transposes, so a step taken from poses whose rotation has rounding error feeds it back
  // multiplied: it must be re-made a rotation (planar_pose.hpp orthonormalized()).
  const auto path = lap(false, {{0, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}});
  std::mt19937_64 rng(8);
  Slam slam;
  double worst_scale_error = 0.0, worst_m = 0.0;
  for (const Eigen::Isometry2d &truth : path) {
    const auto estimate =
        slam.process(omnislam::test::scan_from(omnislam::test::square_room(), truth, rng), std::nullopt);
    worst_scale_error =
        std::max(worst_scale_error, std::abs(estimate.T_map_base.linear().determinant() - 1.0));
    worst_m = std::max(
        worst_m, (estimate.T_map_base.translation() - (path.front().inverse() * truth).translation()).norm());
  }
  INFO("worst |det - 1| " << worst_scale_error << ", worst error " << worst_m << " m over " << path.size()
                          << " frames");
  CHECK(worst_scale_error < 1e-12);
  CHECK(worst_m < 0.05);
}
