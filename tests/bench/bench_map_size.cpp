// bench_map_size [--frames N]: per-frame SLAM cost (registration + integration) against the
// size of the map, on one thread. A building of 5 x 5 m rooms (doors in every wall) is
// mapped already, from 5,000 to 100,000 points; the robot then drives a loop inside one
// room with exact odometry and a synthetic scan (one beam per degree, 6 m, 1 cm noise).
// What grows with the map is what the map costs per frame (issue 13: "bounded cost").
// --loop-closure background: loop closure handed out as jobs (as omnislamd live runs it);
// each job is run between two frames, untimed, as the worker thread would run it beside
// the tracking, and its result is applied (timed) before the next frame.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "omnislam/slam/slam.hpp"
#include "synthetic_room.hpp"

namespace {

using omnislam::slam::MapPoint;
using omnislam::test::Segment;

constexpr double kPointSpacingM = 0.02;

std::vector<MapPoint> sample(const std::vector<Segment> &walls) {
  std::vector<MapPoint> points;
  for (const Segment &s : walls) {
    const double length = (s.b - s.a).norm();
    const int n = std::max(1, static_cast<int>(length / kPointSpacingM));
    for (int k = 0; k <= n; ++k) points.push_back({s.a + (s.b - s.a) * (static_cast<double>(k) / n), 5, 0});
  }
  return points;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char **argv) {
  int frames = 200;
  omnislam::slam::SlamConfig config;  // the defaults: loop closure on
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--frames" && i + 1 < argc) frames = std::max(10, std::atoi(argv[i + 1]));
    if (std::string(argv[i]) == "--no-loop-closure") config.loop_closure.enabled = false;
    if (std::string(argv[i]) == "--loop-closure" && i + 1 < argc)
      config.loop_closure.background = std::string(argv[i + 1]) == "background";
  }
  std::printf(
      "bench_map_size: %d frames per map, one thread, loop closure %s; per-frame SLAM "
      "(registration + integration) in ms\n",
      frames,
      !config.loop_closure.enabled     ? "off"
      : config.loop_closure.background ? "in the background (its jobs untimed)"
                                       : "inline");
  std::printf("  %-10s %-8s %8s %8s %8s\n", "map points", "rooms", "median", "p99", "max");
  for (const int side : {3, 6, 10, 15}) {
    const std::vector<Segment> walls = omnislam::test::building(side);
    std::vector<MapPoint> points = sample(walls);
    const std::size_t size = points.size();
    omnislam::slam::Slam slam(config);
    const Eigen::Isometry2d start = omnislam::test::pose(2.5, 2.5, 0.0);
    slam.resume(std::move(points), 100, start, Eigen::Matrix3d::Identity() * 1e-4, start);
    std::mt19937_64 rng(1);
    std::vector<double> ms;
    for (int frame = 1; frame <= frames; ++frame) {
      // A circle of 1 m radius about the room's centre, 0.1 m per frame.
      const double angle = 0.1 * frame;
      const Eigen::Isometry2d truth = omnislam::test::pose(2.5 + std::cos(angle) - 1.0, 2.5 + std::sin(angle),
                                                           angle + std::numbers::pi / 2);
      const omnislam::slam::Points2 scan = omnislam::test::scan_from(walls, truth, rng, 0.01, 6.0);
      std::optional<omnislam::slam::LoopResult> result;
      if (std::optional<omnislam::slam::LoopJob> job = slam.take_loop_job())
        result = omnislam::slam::run_loop_job(std::move(*job));  // the worker's share, untimed
      const auto begin = std::chrono::steady_clock::now();
      if (result) slam.apply_loop_result(std::move(*result));
      const auto estimate = slam.process(scan, truth);
      const auto end = std::chrono::steady_clock::now();
      (void)estimate;
      if (frame > 5) ms.push_back(std::chrono::duration<double, std::milli>(end - begin).count());
    }
    std::printf("  %-10zu %-8d %8.3f %8.3f %8.3f\n", size, side * side, quantile(ms, 0.5), quantile(ms, 0.99),
                quantile(ms, 1.0));
  }
  return 0;
}
