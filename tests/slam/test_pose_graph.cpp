#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/pose_graph.hpp"

using namespace omnislam::slam;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A 4 x 4 m square driven once, a node every 0.5 m, turning 90 deg at each corner, and
// ending where it started: the true poses.
std::vector<Eigen::Isometry2d> square_path() {
  std::vector<Eigen::Isometry2d> poses;
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  for (int side = 0; side < 4; ++side) {
    for (int step = 0; step < 8; ++step) {
      poses.push_back(T);
      T = T * planar_pose(0.5, 0.0, step == 7 ? 90.0 * kDeg : 0.0);
    }
  }
  poses.push_back(T);  // back at the start
  return poses;
}

Eigen::Matrix3d information(double sigma_xy_m, double sigma_yaw_rad) {
  return Eigen::Vector3d(1.0 / (sigma_xy_m * sigma_xy_m), 1.0 / (sigma_xy_m * sigma_xy_m),
                         1.0 / (sigma_yaw_rad * sigma_yaw_rad))
      .asDiagonal();
}

// The graph of the square with drifted sequential edges (each step's measurement off by a
// seeded error, and a systematic 0.15 deg (0.3 sigma) per step heading bias) and nodes initialised by
// chaining the measurements (dead reckoning).
struct DriftedSquare {
  std::vector<Eigen::Isometry2d> truth = square_path();
  PoseGraph graph;
  double sigma_xy_m = 0.01;
  double sigma_yaw_rad = 0.5 * kDeg;

  explicit DriftedSquare(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise_xy(0.0, sigma_xy_m), noise_yaw(0.0, sigma_yaw_rad);
    Eigen::Isometry2d chained = truth.front();
    graph.add_node(chained);
    for (std::size_t i = 1; i < truth.size(); ++i) {
      const Eigen::Isometry2d step = truth[i - 1].inverse() * truth[i];
      const Eigen::Isometry2d measured =
          step * planar_pose(noise_xy(rng), noise_xy(rng), noise_yaw(rng) + 0.15 * kDeg);
      chained = chained * measured;
      graph.add_node(chained);
      graph.add_edge({static_cast<int>(i - 1), static_cast<int>(i), measured,
                      information(sigma_xy_m, sigma_yaw_rad), false});
    }
  }

  [[nodiscard]] double max_error_m() const {
    double worst = 0.0;
    for (int i = 0; i < graph.size(); ++i)
      worst = std::max(
          worst, (graph.pose(i).translation() - truth[static_cast<std::size_t>(i)].translation()).norm());
    return worst;
  }
  [[nodiscard]] int last() const { return graph.size() - 1; }
};

}  // namespace

TEST_CASE("pose graph: a square loop with drifted odometry is closed by one loop edge") {
  DriftedSquare square(7);
  const double drifted_max_m = square.max_error_m();
  const double drifted_end_m = (square.graph.pose(square.last()).translation()).norm();
  // The loop edge: the last node is at the first one (a registration with 5 mm, 0.2 deg).
  square.graph.add_edge(
      {0, square.last(), Eigen::Isometry2d::Identity(), information(0.005, 0.2 * kDeg), true});
  const PoseGraphResult result = square.graph.optimize();
  CHECK(result.converged);
  CHECK(result.rejected_loops == 0);
  CHECK(drifted_end_m > 0.15);  // dead reckoning ends far off: the test has something to fix
  const double closed_end_m = square.graph.pose(square.last()).translation().norm();
  CHECK(closed_end_m < 0.02);
  CHECK(square.max_error_m() < 0.1);
  CHECK(square.max_error_m() < drifted_max_m / 2.0);
  CHECK(std::abs(yaw_rad_of(square.graph.pose(square.last()))) < 1.0 * kDeg);
}

TEST_CASE("pose graph: an injected false loop edge is rejected and moves the result by less than 10 mm") {
  DriftedSquare reference(11), attacked(11);
  const PoseGraphEdge true_loop{0, reference.last(), Eigen::Isometry2d::Identity(),
                                information(0.005, 0.2 * kDeg), true};
  reference.graph.add_edge(true_loop);
  attacked.graph.add_edge(true_loop);
  // A confident loop edge between the first corner and the opposite one, as a matcher
  // fooled by a symmetric room would claim: node 8 "seen" 0.3 m from node 24, turned.
  attacked.graph.add_edge({8, 24, planar_pose(0.3, 0.1, 10.0 * kDeg), information(0.005, 0.2 * kDeg), true});
  const PoseGraphResult clean = reference.graph.optimize();
  const PoseGraphResult result = attacked.graph.optimize();
  CHECK(clean.rejected_loops == 0);
  CHECK(result.rejected_loops == 1);
  CHECK(result.rounds >= 2);
  int loops = 0;
  for (const PoseGraphEdge &edge : attacked.graph.edges()) loops += edge.loop ? 1 : 0;
  CHECK(loops == 1);  // the true loop edge stays
  double moved_m = 0.0;
  for (int i = 0; i < reference.graph.size(); ++i)
    moved_m = std::max(moved_m,
                       (attacked.graph.pose(i).translation() - reference.graph.pose(i).translation()).norm());
  CHECK(moved_m < 0.010);
}

TEST_CASE("pose graph: yaw differences are taken across the +-pi seam") {
  // Two nodes facing almost backwards, one on each side of the seam; a measurement of a
  // 2 deg turn across it must pull them 2 deg apart, not 358.
  PoseGraph graph;
  graph.add_node(planar_pose(0.0, 0.0, 179.0 * kDeg));
  graph.add_node(planar_pose(-1.0, 0.0, -175.0 * kDeg));
  graph.add_edge({0, 1, planar_pose(1.0, 0.0, 2.0 * kDeg), information(0.01, 1.0 * kDeg), false});
  const PoseGraphResult result = graph.optimize();
  CHECK(result.converged);
  const double yaw1 = yaw_rad_of(graph.pose(1));
  CHECK(std::abs(std::remainder(yaw1 - 181.0 * kDeg, 2.0 * std::numbers::pi)) < 1e-6);
  CHECK((graph.pose(1).translation() - Eigen::Vector2d(-1.0, 0.0)).norm() < 0.02);
}

TEST_CASE("pose graph: fewer than two nodes is a no-op") {
  PoseGraph graph;
  CHECK(graph.optimize().converged);
  graph.add_node(planar_pose(1.0, 2.0, 0.5));
  CHECK(graph.optimize().converged);
  CHECK((graph.pose(0).translation() - Eigen::Vector2d(1.0, 2.0)).norm() < 1e-12);
}

TEST_CASE(
    "pose graph: three injected false loop edges are all rejected and move the result by less than 10 mm") {
  DriftedSquare reference(5), attacked(5);
  const PoseGraphEdge true_loop{0, reference.last(), Eigen::Isometry2d::Identity(),
                                information(0.005, 0.2 * kDeg), true};
  reference.graph.add_edge(true_loop);
  attacked.graph.add_edge(true_loop);
  // Confident, mutually inconsistent claims: opposite corners seen as neighbours, a side
  // mistaken for its parallel one, and a node matched one metre along its own side.
  attacked.graph.add_edge({8, 24, planar_pose(0.3, 0.1, 10.0 * kDeg), information(0.005, 0.2 * kDeg), true});
  attacked.graph.add_edge({4, 20, planar_pose(0.0, 0.0, 180.0 * kDeg), information(0.005, 0.2 * kDeg), true});
  attacked.graph.add_edge({12, 14, planar_pose(0.0, 0.0, 0.0), information(0.005, 0.2 * kDeg), true});
  reference.graph.optimize();
  const PoseGraphResult result = attacked.graph.optimize();
  CHECK(result.rejected_loops == 3);
  double moved_m = 0.0;
  for (int i = 0; i < reference.graph.size(); ++i)
    moved_m = std::max(moved_m,
                       (attacked.graph.pose(i).translation() - reference.graph.pose(i).translation()).norm());
  CHECK(moved_m < 0.010);
  CHECK(std::abs(attacked.max_error_m() - reference.max_error_m()) < 0.010);
}
