#include <catch2/catch.hpp>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

// Saving the keyframe graph and continuing it after a resume (issue 13: snapshots carry the
// graph), so that loop closure can close loops against the keyframes of an earlier session.

using namespace omnislam::slam;
using omnislam::test::pose;

namespace {

Points2 some_scan(double offset) { return {{1.0 + offset, 0.0}, {0.0, 1.0}, {-1.0, -0.5 * offset}}; }

// Three keyframes 0.6 m apart along x, and a frame between the first two.
KeyframeGraph three_keyframes() {
  KeyframeGraph graph;
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  for (double x : {0.0, 0.3, 0.6, 1.2})
    (void)graph.add_integrated(some_scan(x), pose(x, 0.0, 0.1 * x), covariance);
  return graph;
}

struct Session {
  Eigen::Isometry2d last_pose = Eigen::Isometry2d::Identity();
  Eigen::Matrix3d last_covariance = Eigen::Matrix3d::Zero();
  double max_error_m = 0.0;
};

// Frames [first, last) of `truth` (map frame = truth[0]) through `slam`, with noisy odometry.
Session run(Slam &slam, const std::vector<Eigen::Isometry2d> &truth, std::size_t first, std::size_t last,
            std::uint64_t seed) {
  const auto walls = omnislam::test::l_room();
  const auto odometry = apply_thesis_odometry_noise(truth, seed);
  std::mt19937_64 rng(seed);
  Session session;
  for (std::size_t i = first; i < last; ++i) {
    const FrameEstimate estimate = slam.process(omnislam::test::scan_from(walls, truth[i], rng), odometry[i]);
    session.last_pose = estimate.T_map_base;
    session.last_covariance = estimate.covariance;
    session.max_error_m =
        std::max(session.max_error_m, (estimate.T_map_base.translation() - truth[i].translation()).norm());
  }
  return session;
}

}  // namespace

TEST_CASE("keyframe graph: its state restores the keyframes, scans, edges and path", "[slam][graph]") {
  const KeyframeGraph original = three_keyframes();
  REQUIRE(original.keyframes().size() == 3);
  const KeyframeGraphState state = original.state();
  CHECK(state.integrations() == 4);
  CHECK(state.edges.size() == 2);
  CHECK(keyframe_graph_state_error(state).empty());

  const KeyframeGraph restored(KeyframeConfig{}, state, true);
  REQUIRE(restored.keyframes().size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(restored.keyframes()[k].T_map_keyframe.isApprox(original.keyframes()[k].T_map_keyframe, 1e-12));
    CHECK(restored.keyframes()[k].path_m == original.keyframes()[k].path_m);
    CHECK(restored.keyframes()[k].scans_keyframe == original.keyframes()[k].scans_keyframe);  // shared
  }
  REQUIRE(restored.graph().edges().size() == 2);
  CHECK(restored.graph().edges()[1].from == 1);
  CHECK(restored.graph().edges()[1].T_from_to.isApprox(original.graph().edges()[1].T_from_to, 1e-12));
  CHECK(restored.graph().edges()[1].information.isApprox(original.graph().edges()[1].information));
  CHECK(restored.integrations() == 4);
  CHECK(restored.graph().pose(2).isApprox(original.keyframes()[2].T_map_keyframe, 1e-12));
  const PointMap rebuilt = restored.rebuilt_map({}, {}, 0), want = original.rebuilt_map({}, {}, 0);
  CHECK(rebuilt.points().size() == want.points().size());
  CHECK(rebuilt.integrations() == want.integrations());

  KeyframeGraphState broken = state;
  broken.edges[0].to = 7;
  CHECK_THROWS_AS(KeyframeGraph(KeyframeConfig{}, broken, true), std::invalid_argument);
}

TEST_CASE("keyframe graph: a keyframe's covariance is the mean of its scans' frames', carried to it",
          "[slam][graph]") {
  KeyframeGraph graph;
  const Eigen::Matrix3d tracked = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  const Eigen::Matrix3d first = Eigen::Vector3d(4e-6, 9e-6, 1e-6).asDiagonal();
  (void)graph.add_integrated(some_scan(0.0), pose(0.0, 0.0, 0.0), tracked);
  graph.add_scan_covariance(first, pose(0.0, 0.0, 0.0));
  CHECK(graph.keyframes()[0].covariance.isApprox(first));
  // A frame 0.2 m on joins the keyframe: its heading variance swings its scan about it,
  // 0.2 m from the keyframe (y variance + 0.04 m2 x yaw variance, the x-yaw cross term).
  const Eigen::Matrix3d second = Eigen::Vector3d(1e-5, 1e-5, 1e-4).asDiagonal();
  CHECK_FALSE(graph.add_integrated(some_scan(0.2), pose(0.2, 0.0, 0.0), tracked));
  graph.add_scan_covariance(second, pose(0.2, 0.0, 0.0));
  Eigen::Matrix3d carried = second;
  carried(1, 1) += 0.04 * 1e-4;
  carried(1, 2) = carried(2, 1) = -0.2 * 1e-4;
  CHECK(graph.keyframes()[0].covariance.isApprox(0.5 * (first + carried), 1e-12));
  // The state carries it, and a restored graph has it back.
  const KeyframeGraphState state = graph.state();
  CHECK(state.keyframes[0].covariance == graph.keyframes()[0].covariance);
  const KeyframeGraph restored(KeyframeConfig{}, state, true);
  CHECK(restored.keyframes()[0].covariance == graph.keyframes()[0].covariance);
  KeyframeGraphState broken = state;
  broken.keyframes[0].covariance(2, 2) = -1.0;
  CHECK(keyframe_graph_state_error(broken) ==
        "keyframe 0: covariance is not symmetric positive semi-definite");
}

TEST_CASE(
    "keyframe graph: a chained resume joins the next keyframe to the saved last one, an unchained "
    "one starts a keyframe without an edge",
    "[slam][graph]") {
  const KeyframeGraphState state = three_keyframes().state();
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();

  KeyframeGraph chained(KeyframeConfig{}, state, true);
  CHECK_FALSE(chained.add_integrated(some_scan(1.3), pose(1.3, 0.0, 0.13), covariance));  // 0.1 m on
  CHECK(chained.add_integrated(some_scan(1.9), pose(1.9, 0.0, 0.19), covariance));
  REQUIRE(chained.graph().edges().size() == 3);
  CHECK(chained.graph().edges().back().from == 2);
  CHECK(chained.graph().edges().back().to == 3);
  CHECK(chained.keyframes().back().path_m == Approx(1.9));  // the path continues

  KeyframeGraph unchained(KeyframeConfig{}, state, false);
  CHECK(unchained.add_integrated(some_scan(1.3), pose(1.3, 0.0, 0.13), covariance));  // a keyframe at once
  CHECK(unchained.graph().edges().size() == 2);                                       // tied to nothing
  CHECK(unchained.add_integrated(some_scan(1.9), pose(1.9, 0.0, 0.19), covariance));
  REQUIRE(unchained.graph().edges().size() == 3);  // chained from then on
  CHECK(unchained.graph().edges().back().from == 3);
}

TEST_CASE("resume with the saved graph: loop closure closes a loop against a keyframe of the first session",
          "[slam][graph][resume]") {
  const std::vector<Eigen::Isometry2d> truth = omnislam::test::laps_along(omnislam::test::l_room_tour(), 2);
  // The first session ends after the outbound leg (about 6 m); the second continues from the
  // same place for the rest of the two laps, past the first session's keyframes twice.
  const std::size_t split = 30;
  Slam first;
  const Session before = run(first, truth, 0, split, 11);
  const std::optional<KeyframeGraphState> saved = first.graph_state();
  REQUIRE(saved);
  const std::size_t saved_keyframes = saved->keyframes.size();
  REQUIRE(saved_keyframes >= 5);
  REQUIRE(saved->integrations() == static_cast<std::size_t>(first.map().integrations()));

  // Chained (the saved pose taken as is, as omnislamd does), and unchained (as after a
  // relocalisation): then only loop edges tie the new keyframes to the saved ones.
  const bool chained = GENERATE(true, false);
  Slam second;
  second.resume(first.map().points(), first.map().integrations(), before.last_pose, before.last_covariance,
                {}, ResumedGraph{*saved, chained});
  REQUIRE(second.keyframes().keyframes().size() == saved_keyframes);
  const Session after = run(second, truth, split - 1, truth.size(), 12);

  const std::vector<PoseGraphEdge> &edges = second.keyframes().graph().edges();
  const auto into_first_session = std::count_if(edges.begin(), edges.end(), [&](const PoseGraphEdge &edge) {
    return edge.loop && static_cast<std::size_t>(edge.from) < saved_keyframes &&
           static_cast<std::size_t>(edge.to) >= saved_keyframes;
  });
  const bool joined = std::any_of(edges.begin(), edges.end(), [&](const PoseGraphEdge &edge) {
    return !edge.loop && static_cast<std::size_t>(edge.from) == saved_keyframes - 1 &&
           static_cast<std::size_t>(edge.to) == saved_keyframes;
  });
  INFO((chained ? "chained: " : "unchained: ")
       << second.loop_closures() << " closures, " << into_first_session
       << " loop edges into the first session; max " << after.max_error_m << " m");
  CHECK(second.loop_closures() > 0);
  CHECK(into_first_session > 0);
  CHECK(joined == chained);
  CHECK(after.max_error_m < 0.05);
  // The map follows the graph: every integration of the map is one of its scans, from both
  // sessions (a rebuilt map holds them all), so the next snapshot can carry it again.
  CHECK(second.map().integrations() == static_cast<int>(second.keyframes().integrations()));
  CHECK(second.keyframes().integrations() > saved->integrations());
  CHECK(second.graph_state());
}

TEST_CASE("resume without a graph keeps today's fixed base; a graph that is not the map's is refused",
          "[slam][graph][resume]") {
  const std::vector<Eigen::Isometry2d> truth = omnislam::test::laps_along(omnislam::test::l_room_tour(), 1);
  Slam first;
  const Session before = run(first, truth, 0, 30, 11);
  Slam second;
  second.resume(first.map().points(), first.map().integrations(), before.last_pose, before.last_covariance);
  CHECK(second.keyframes().keyframes().empty());
  (void)run(second, truth, 29, 40, 12);
  // The restored points belong to no keyframe: the graph does not describe the map.
  CHECK_FALSE(second.graph_state());
  CHECK(second.map().integrations() > static_cast<int>(second.keyframes().integrations()));

  Slam refused;
  CHECK_THROWS_AS(refused.resume(first.map().points(), first.map().integrations() - 1, before.last_pose,
                                 before.last_covariance, {}, ResumedGraph{*first.graph_state(), true}),
                  std::invalid_argument);
  CHECK(refused.map().empty());  // left as it was
  CHECK(refused.keyframes().keyframes().empty());
}
