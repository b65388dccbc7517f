#include <algorithm>
#include <catch2/catch.hpp>
#include <optional>
#include <random>
#include <vector>

#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// Resuming from a saved state and localization on a fixed map (the service's persistence).
using omnislam::slam::FrameEstimate;
using omnislam::slam::KeyframeGraphState;
using omnislam::slam::MapPoint;
using omnislam::slam::ResumedGraph;
using omnislam::slam::Slam;
using omnislam::slam::SlamConfig;
using omnislam::test::pose;

namespace {

// Through the L-room and back along its long side, 0.2 m steps, facing the way it goes. The
// way back passes 0.3 m from the boxes at (3.5-4.1, 0.4-0.9) and (0.2-0.8, 2.8-3.3) (it used
// to drive through the first and along the second's front face: scans no robot can take,
// which lost detection keeps out of the map).
std::vector<Eigen::Isometry2d> tour() {
  const std::vector<Eigen::Vector2d> corners = {{0, 0}, {5, 0}, {5, 0.1}, {1.5, 0.1}, {1.5, 2.5}, {0, 2.5}};
  std::vector<Eigen::Isometry2d> truth;
  for (std::size_t c = 0; c + 1 < corners.size(); ++c) {
    const Eigen::Vector2d a = corners[c], b = corners[c + 1];
    const int steps = std::max(1, static_cast<int>(std::round((b - a).norm() / 0.2)));
    for (int s = 0; s < steps; ++s) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
      truth.push_back(pose(p.x(), p.y(), std::atan2(b.y() - a.y(), b.x() - a.x())));
    }
  }
  return truth;
}

double position_error(const Eigen::Isometry2d &estimate, const Eigen::Isometry2d &truth) {
  return (estimate.translation() - truth.translation()).norm();
}

struct Track {
  double max_error_m = 0.0;
  double odometry_max_error_m = 0.0;
  int accepted = 0;
  Eigen::Isometry2d last_pose = Eigen::Isometry2d::Identity();
  Eigen::Matrix3d last_covariance = Eigen::Matrix3d::Zero();
};

// Feeds frames [first, last) of `truth` (map frame = truth[0] = identity) with noisy odometry.
Track run(Slam &slam, const std::vector<Eigen::Isometry2d> &truth, std::size_t first, std::size_t last,
          std::uint64_t seed) {
  const auto walls = omnislam::test::l_room();
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, seed);
  std::mt19937_64 rng(seed);
  Track track;
  for (std::size_t i = first; i < last; ++i) {
    const auto estimate = slam.process(omnislam::test::scan_from(walls, truth[i], rng), odometry[i]);
    track.max_error_m = std::max(track.max_error_m, position_error(estimate.T_map_base, truth[i]));
    const Eigen::Isometry2d odometry_map = odometry[first].inverse() * odometry[i];
    track.odometry_max_error_m =
        std::max(track.odometry_max_error_m, position_error(truth[first] * odometry_map, truth[i]));
    track.accepted += estimate.integrated ? 1 : 0;
    track.last_pose = estimate.T_map_base;
    track.last_covariance = estimate.covariance;
  }
  return track;
}

bool same_points(const std::vector<MapPoint> &a, const std::vector<MapPoint> &b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const MapPoint &p, const MapPoint &q) {
    return p.position_m == q.position_m && p.hits == q.hits && p.first_seen == q.first_seen;
  });
}

}  // namespace

TEST_CASE("localization only: tracks the pose on a saved map and never changes it", "[slam][resume]") {
  const auto truth = tour();
  Slam mapping;
  (void)run(mapping, truth, 0, truth.size(), 1);
  const std::vector<MapPoint> saved = mapping.map().points();
  const int integrations = mapping.map().integrations();
  REQUIRE(saved.size() > 200);

  SlamConfig config;
  config.localization_only = true;
  Slam localizer(config);
  localizer.resume(saved, integrations, Eigen::Isometry2d::Identity(), Eigen::Matrix3d::Zero());
  // Other odometry noise and other scan noise than the mapping run.
  const Track track = run(localizer, truth, 0, truth.size(), 9);
  INFO("max error " << track.max_error_m << " m, odometry alone " << track.odometry_max_error_m
                    << " m, accepted " << track.accepted << "/" << truth.size());
  CHECK(track.max_error_m < 0.05);
  CHECK(track.max_error_m < 0.5 * track.odometry_max_error_m);
  CHECK(track.accepted >= static_cast<int>(0.9 * truth.size()));
  CHECK(localizer.map().integrations() == integrations);
  CHECK(same_points(localizer.map().points(), saved));
}

TEST_CASE("localization only on a saved graph: each pose's covariance adds how far the map may be off there",
          "[slam][resume]") {
  const auto truth = tour();
  Slam mapping;
  (void)run(mapping, truth, 0, truth.size(), 1);
  const std::optional<KeyframeGraphState> graph = mapping.graph_state();
  REQUIRE(graph);
  REQUIRE(graph->keyframes.size() > 3);
  // The mapping run's covariances grew along its path: the last keyframes' are the largest.
  const Eigen::Matrix3d &last = graph->keyframes.back().covariance;
  CHECK(last.trace() > graph->keyframes[1].covariance.trace());
  CHECK(graph->keyframes.front().covariance.trace() < last.trace());

  SlamConfig config;
  config.localization_only = true;
  Slam without(config), with(config);
  without.resume(mapping.map().points(), mapping.map().integrations(), Eigen::Isometry2d::Identity(),
                 Eigen::Matrix3d::Zero());
  with.resume(mapping.map().points(), mapping.map().integrations(), Eigen::Isometry2d::Identity(),
              Eigen::Matrix3d::Zero(), {}, ResumedGraph{*graph, false});
  CHECK(without.map_uncertainty_at(truth.back()).isZero());
  const Eigen::Isometry2d at_last = omnislam::slam::planar_pose(
      graph->keyframes.back().T_map_keyframe.x_m, graph->keyframes.back().T_map_keyframe.y_m,
      graph->keyframes.back().T_map_keyframe.yaw_rad);
  CHECK(with.map_uncertainty_at(at_last).isApprox(last, 1e-9));
  // Same scans, same poses; only the published covariances differ, by the map's where each is.
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, 9);
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng_a(9), rng_b(9);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const FrameEstimate a = without.process(omnislam::test::scan_from(walls, truth[i], rng_a), odometry[i]);
    const FrameEstimate b = with.process(omnislam::test::scan_from(walls, truth[i], rng_b), odometry[i]);
    REQUIRE(a.T_map_base.isApprox(b.T_map_base, 1e-12));
    if (!a.integrated) continue;
    CHECK(b.covariance.isApprox(a.covariance + with.map_uncertainty_at(b.T_map_base), 1e-9));
  }
}

TEST_CASE("localization only without a map registers scan to scan and builds nothing", "[slam][resume]") {
  SlamConfig config;
  config.localization_only = true;
  Slam slam(config);
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(3);
  // Odometry 3 cm short of the true 0.2 m step.
  const auto first = slam.process(omnislam::test::scan_from(walls, pose(0, 0, 0), rng), pose(2, 1, 0));
  const auto second = slam.process(omnislam::test::scan_from(walls, pose(0.2, 0, 0), rng), pose(2.17, 1, 0));
  CHECK_FALSE(first.integrated);
  CHECK(first.T_map_base.isApprox(Eigen::Isometry2d::Identity()));
  CHECK(second.integrated);
  CHECK(second.attempt == omnislam::slam::Attempt::kPreviousForward);
  CHECK((second.T_map_base.translation() - Eigen::Vector2d(0.2, 0.0)).norm() < 0.01);
  CHECK(slam.map().empty());
  CHECK(slam.map().integrations() == 0);
}

TEST_CASE("resume: a restarted SLAM continues the map and the trajectory where they were", "[slam][resume]") {
  const auto truth = tour();
  const std::size_t half = truth.size() / 2;
  Slam before;
  const Track first_half = run(before, truth, 0, half, 4);
  const std::vector<MapPoint> saved = before.map().points();
  const int integrations = before.map().integrations();

  // The restarted instance sees the last frame's place again (the robot stood still), with
  // its odometry counting from wherever the restarted odometry starts.
  Slam after;
  after.resume(saved, integrations, first_half.last_pose, first_half.last_covariance);
  const Track second_half = run(after, truth, half - 1, truth.size(), 5);
  INFO("first half max " << first_half.max_error_m << " m, second half max " << second_half.max_error_m
                         << " m, odometry alone " << second_half.odometry_max_error_m << " m");
  CHECK(first_half.max_error_m < 0.05);
  CHECK(second_half.max_error_m < 0.05);
  CHECK(second_half.max_error_m < 0.5 * second_half.odometry_max_error_m);
  CHECK(second_half.accepted >= static_cast<int>(0.9 * (truth.size() - half + 1)));
  // The map kept growing from the saved one: more integrations, and points of the second
  // half (the corridor beyond x = 1.5 m, y > 1.5 m) that the first half never saw.
  CHECK(after.map().integrations() > integrations + static_cast<int>(0.9 * (truth.size() - half)));
  const auto upper = [](const std::vector<MapPoint> &points) {
    return std::count_if(points.begin(), points.end(),
                         [](const MapPoint &p) { return p.position_m.y() > 3.5 && p.position_m.x() < 0.5; });
  };
  CHECK(upper(after.map().points()) > upper(saved) + 10);
}

TEST_CASE("odometry gaps: frames without odometry keep the pose, and no motion is lost across the gap",
          "[slam][odometry]") {
  const auto truth = tour();
  const auto walls = omnislam::test::l_room();
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, 6);
  // Frames 10..14 and 30..31 arrive without odometry (the odometry stream stalled).
  const auto in_gap = [](std::size_t i) { return (i >= 10 && i < 15) || (i >= 30 && i < 32); };
  Slam with_gaps;
  Slam identity_for_gaps;  // what treating a gap as odometry (0, 0, 0) would do
  std::mt19937_64 rng_a(6), rng_b(6);
  double max_error = 0.0, max_error_identity = 0.0;
  int accepted_in_gaps = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::optional<Eigen::Isometry2d> odom =
        in_gap(i) ? std::nullopt : std::optional<Eigen::Isometry2d>(odometry[i]);
    const auto estimate = with_gaps.process(omnislam::test::scan_from(walls, truth[i], rng_a), odom);
    const auto bad = identity_for_gaps.process(omnislam::test::scan_from(walls, truth[i], rng_b),
                                               odom.value_or(Eigen::Isometry2d::Identity()));
    max_error = std::max(max_error, position_error(estimate.T_map_base, truth[i]));
    max_error_identity = std::max(max_error_identity, position_error(bad.T_map_base, truth[i]));
    if (in_gap(i) && estimate.integrated) ++accepted_in_gaps;
  }
  Slam without_gaps;
  std::mt19937_64 rng_c(6);
  double max_error_no_gaps = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto estimate =
        without_gaps.process(omnislam::test::scan_from(walls, truth[i], rng_c), odometry[i]);
    max_error_no_gaps = std::max(max_error_no_gaps, position_error(estimate.T_map_base, truth[i]));
  }
  INFO("max error with gaps " << max_error << " m, without gaps " << max_error_no_gaps
                              << " m; gaps read as identity odometry " << max_error_identity << " m");
  // The gap frames keep the motion (constant velocity) and are registered.
  CHECK(accepted_in_gaps >= 6);
  CHECK(max_error < max_error_no_gaps + 0.02);
  CHECK(max_error_identity > 1.0);
}

TEST_CASE("resume with the saved odometry pose predicts the first frame from the motion since",
          "[slam][resume]") {
  const auto truth = tour();
  const auto odometry = omnislam::slam::apply_thesis_odometry_noise(truth, 4);
  const std::size_t stop = 15;  // along the first leg, which the map covers
  Slam before;
  const Track first = run(before, truth, 0, stop, 4);
  // Restart three frames later (frames 15..17 were lost with the process): 0.6 m of motion,
  // beyond the plausible correction of a prediction that assumes the robot stood still.
  const std::size_t next = stop + 3;
  const auto walls = omnislam::test::l_room();
  const auto resumed_estimate = [&](const std::optional<Eigen::Isometry2d> &saved_odometry) {
    Slam after;
    after.resume(before.map().points(), before.map().integrations(), first.last_pose, first.last_covariance,
                 saved_odometry);
    std::mt19937_64 rng(9);
    return after.process(omnislam::test::scan_from(walls, truth[next], rng), odometry[next]);
  };
  const auto with_odometry = resumed_estimate(odometry[stop - 1]);
  CHECK(with_odometry.integrated);
  CHECK(position_error(with_odometry.T_map_base, truth[next]) < 0.05);
  const auto standing_still = resumed_estimate(std::nullopt);
  CHECK_FALSE(standing_still.integrated);
  CHECK(position_error(standing_still.T_map_base, truth[next]) > 0.5);
}

TEST_CASE("set_pose (rt/initialpose): before the first frame the map starts at the given pose",
          "[slam][resume]") {
  const auto walls = omnislam::test::l_room();
  std::mt19937_64 rng(11);
  const Eigen::Isometry2d start = pose(2.0, 0.3, 0.4);
  Slam slam;
  slam.set_pose(start, Eigen::Matrix3d::Identity() * 0.01);
  const auto first = slam.process(omnislam::test::scan_from(walls, pose(0, 0, 0), rng), pose(0, 0, 0));
  CHECK(first.T_map_base.isApprox(start, 1e-12));
  // The next frame, 0.2 m further along the robot's heading, is tracked in that map frame.
  const auto next = slam.process(omnislam::test::scan_from(walls, pose(0.2, 0, 0), rng), pose(0.2, 0, 0));
  CHECK(next.integrated);
  CHECK(position_error(next.T_map_base, start * pose(0.2, 0, 0)) < 0.02);
}

TEST_CASE("set_pose (rt/initialpose): mid-run, the next frame starts from it and the map is kept",
          "[slam][resume]") {
  const auto truth = tour();
  const std::size_t half = truth.size() / 2;
  Slam slam;
  const Track first_half = run(slam, truth, 0, half, 6);
  const int integrations = slam.map().integrations();
  const std::size_t points = slam.map().points().size();

  // A frame with no scan points follows the prediction exactly: the operator's pose.
  const Eigen::Isometry2d given = truth[half] * pose(0.08, -0.05, 0.05);
  slam.set_pose(given, Eigen::Matrix3d::Identity() * 0.01);
  const auto blind = slam.process({}, pose(100, 100, 2));  // an odometry frame of its own
  CHECK(blind.T_map_base.isApprox(given, 1e-12));
  CHECK_FALSE(blind.integrated);
  CHECK(slam.map().integrations() == integrations);
  CHECK(slam.map().points().size() == points);

  // Again, with odometry in yet another frame: tracking resumes on the kept map.
  slam.set_pose(given, Eigen::Matrix3d::Identity() * 0.01);
  const Track second_half = run(slam, truth, half, truth.size(), 7);
  INFO("first half max " << first_half.max_error_m << " m, after set_pose max " << second_half.max_error_m
                         << " m");
  CHECK(second_half.max_error_m < 0.05);
  CHECK(slam.map().integrations() > integrations);
}
