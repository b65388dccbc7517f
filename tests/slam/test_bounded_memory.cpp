#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <vector>

#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// What a long run keeps: a frame is integrated into the map only once it lies
// map_min_step_m from the last integrated one, and a keyframe holds at most max_scans
// scans, so a robot standing still or driving the same laps again and again keeps a
// bounded number of scans (memory, and the work of every map rebuild).

using namespace omnislam::slam;
using omnislam::test::pose;

namespace {

std::size_t fullest_keyframe(const KeyframeGraph &graph) {
  std::size_t most = 0;
  for (const Keyframe &keyframe : graph.keyframes()) most = std::max(most, keyframe.scans_keyframe.size());
  return most;
}

}  // namespace

TEST_CASE("keyframe graph: a keyframe has room for max_scans scans, a new keyframe always", "[slam][graph]") {
  KeyframeConfig config;
  config.max_scans = 3;
  KeyframeGraph graph(config);
  const Points2 scan = {{1.0, 0.0}, {0.0, 1.0}};
  const Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity() * 1e-4;
  CHECK(graph.makes_keyframe(pose(0, 0, 0)));  // the first frame
  CHECK(graph.has_room(pose(0, 0, 0), -1));
  for (int i = 0; i < 3; ++i) {
    REQUIRE(graph.has_room(pose(0.1 * i, 0, 0), -1));
    graph.add_integrated(scan, pose(0.1 * i, 0, 0), covariance);
  }
  REQUIRE(graph.keyframes().size() == 1);
  CHECK_FALSE(graph.makes_keyframe(pose(0.3, 0, 0)));
  CHECK_FALSE(graph.has_room(pose(0.3, 0, 0), -1));  // it would join keyframe 0, which is full
  CHECK(graph.makes_keyframe(pose(0.6, 0, 0)));      // keyframe_distance_m away: a keyframe of its own
  CHECK(graph.has_room(pose(0.6, 0, 0), -1));
  CHECK(graph.makes_keyframe(pose(0.0, 0, 0.5)));   // or turned by keyframe_angle_rad
  CHECK_FALSE(graph.has_room(pose(0.6, 0, 0), 0));  // revisiting keyframe 0: full, however far
  // A revisit that is not stored is only a pose, anchored to its keyframe.
  graph.add_integrated(scan, pose(0.6, 0, 0), covariance);
  const std::size_t stored = graph.integrations();
  graph.add_revisit(0, pose(0.05, 0.02, 0));
  CHECK(graph.integrations() == stored);
  CHECK(graph.anchor_keyframe() == 0);
  CHECK(graph.trajectory().back().translation().isApprox(Eigen::Vector2d(0.05, 0.02), 1e-12));
}

TEST_CASE("SLAM: a robot standing still integrates its first frame only", "[slam]") {
  const auto room = omnislam::test::square_room();
  const Eigen::Isometry2d still = pose(1.0, 0.5, 0.3);
  std::mt19937_64 rng(3);
  struct Run {
    int mapped = 0;
    int map_integrations = 0;
    std::size_t stored = 0;
    std::size_t fullest = 0;
  };
  auto run = [&](SlamConfig config) {
    Slam slam(config);
    Run result;
    for (int i = 0; i < 100; ++i) {
      const FrameEstimate estimate = slam.process(omnislam::test::scan_from(room, still, rng), still);
      CHECK(estimate.integrated);  // every frame is tracked ...
      result.mapped += estimate.mapped ? 1 : 0;
    }
    CHECK(slam.trajectory().size() == 100);
    // ... the map and the graph hold the same scans (a rebuild gives the live map).
    if (config.loop_closure.enabled)
      CHECK(slam.keyframes().integrations() == static_cast<std::size_t>(slam.map().integrations()));
    result.map_integrations = slam.map().integrations();
    result.stored = slam.keyframes().integrations();
    result.fullest = fullest_keyframe(slam.keyframes());
    return result;
  };
  SECTION("the default: nearer than map_min_step_m adds nothing") {
    const Run still_run = run(SlamConfig{});
    CHECK(still_run.mapped == 1);
    CHECK(still_run.map_integrations == 1);
  }
  SECTION("every frame (the thesis): the keyframe stops at max_scans") {
    SlamConfig config;
    config.map_min_step_m = 0.0;
    const Run still_run = run(config);
    CHECK(still_run.mapped == config.loop_closure.keyframes.max_scans);
    CHECK(still_run.fullest == static_cast<std::size_t>(config.loop_closure.keyframes.max_scans));
  }
  SECTION("every frame without loop closure: nothing is stored, every frame refines the map") {
    SlamConfig config;
    config.map_min_step_m = 0.0;
    config.loop_closure.enabled = false;
    const Run still_run = run(config);
    CHECK(still_run.mapped == 100);
    CHECK(still_run.stored == 0);
  }
}

TEST_CASE("SLAM: laps driven again and again keep at most max_scans per keyframe", "[slam][loop]") {
  const auto truth = omnislam::test::laps_along(omnislam::test::l_room_tour(), 8);
  const auto odometry = apply_thesis_odometry_noise(truth, 4);
  auto run = [&](int max_scans) {
    SlamConfig config;
    config.loop_closure.keyframes.max_scans = max_scans;
    // The tour drives through the room's boxes: scans from inside a box contradict the map,
    // and lost detection keeps them out of it (test_kidnap). This test is about the bound.
    config.lost_after_frames = 0;
    std::mt19937_64 rng(4);
    Slam slam(config);
    int mapped = 0;
    int accepted = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const FrameEstimate estimate =
          slam.process(omnislam::test::scan_from(omnislam::test::l_room(), truth[i], rng), odometry[i]);
      REQUIRE(estimate.trajectory_index == static_cast<int>(i));
      mapped += estimate.mapped ? 1 : 0;
      accepted += estimate.integrated ? 1 : 0;
    }
    double worst_m = 0.0;
    const auto optimised = slam.trajectory();
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const Eigen::Isometry2d expected = truth.front().inverse() * truth[i];
      worst_m = std::max(worst_m, (optimised[i].translation() - expected.translation()).norm());
    }
    CHECK(slam.keyframes().integrations() == static_cast<std::size_t>(slam.map().integrations()));
    CHECK(static_cast<int>(slam.keyframes().integrations()) == mapped);
    CHECK(fullest_keyframe(slam.keyframes()) <= static_cast<std::size_t>(max_scans));
    return std::tuple{mapped, accepted, worst_m, slam.keyframes().keyframes().size()};
  };
  const auto [mapped_all, accepted_all, worst_all_m, keyframes_all] = run(1000);
  const auto [mapped_few, accepted_few, worst_few_m, keyframes_few] = run(4);
  INFO("frames " << truth.size() << "; integrated / worst error / keyframes: unbounded " << mapped_all
                 << " / " << worst_all_m << " m / " << keyframes_all << ", at most 4 per keyframe "
                 << mapped_few << " / " << worst_few_m << " m / " << keyframes_few);
  CHECK(mapped_all == accepted_all);  // 0.2 m steps: every accepted frame, unbounded
  CHECK(accepted_few >= static_cast<int>(truth.size()) * 99 / 100);
  CHECK(mapped_few <= 4 * static_cast<int>(keyframes_few));
  CHECK(mapped_few < mapped_all / 2);
  // The place's map is made of fewer views; the laps stay as accurate.
  CHECK(worst_all_m < 0.065);
  CHECK(worst_few_m < 0.065);
}
