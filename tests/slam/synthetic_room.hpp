#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"
#include "omnislam/slam/planar_pose.hpp"

// A synthetic world for SLAM tests: wall segments, scans by ray casting one beam per degree
// with range noise, and the thesis odometry noise model.
namespace omnislam::test {

struct Segment {
  Eigen::Vector2d a, b;
};

/// An L-shaped room with two boxes, about 7 x 5 m.
inline std::vector<Segment> l_room() {
  const std::vector<Eigen::Vector2d> outline = {{-1, -1}, {6, -1}, {6, 1.5}, {2.5, 1.5}, {2.5, 4}, {-1, 4}};
  std::vector<Segment> walls;
  for (std::size_t i = 0; i < outline.size(); ++i)
    walls.push_back({outline[i], outline[(i + 1) % outline.size()]});
  auto box = [&](double x0, double y0, double x1, double y1) {
    walls.push_back({{x0, y0}, {x1, y0}});
    walls.push_back({{x1, y0}, {x1, y1}});
    walls.push_back({{x1, y1}, {x0, y1}});
    walls.push_back({{x0, y1}, {x0, y0}});
  };
  box(3.5, 0.4, 4.1, 0.9);
  box(0.2, 2.8, 0.8, 3.3);
  return walls;
}

/// A 4 x 4 m room with one box: every wall stays within scan range of a path inside it.
inline std::vector<Segment> square_room() {
  std::vector<Segment> walls = {
      {{-1, -1}, {3, -1}}, {{3, -1}, {3, 3}}, {{3, 3}, {-1, 3}}, {{-1, 3}, {-1, -1}}};
  walls.push_back({{0.8, 0.8}, {1.2, 0.8}});
  walls.push_back({{1.2, 0.8}, {1.2, 1.2}});
  walls.push_back({{1.2, 1.2}, {0.8, 1.2}});
  walls.push_back({{0.8, 1.2}, {0.8, 0.8}});
  return walls;
}

/// A square grid of rooms_per_side^2 rooms of room_m, a door of door_m in the middle of every
/// inner wall: a building whose rooms all look alike (4-fold symmetric as a whole).
inline std::vector<Segment> building(int rooms_per_side, double room_m = 5.0, double door_m = 1.0) {
  std::vector<Segment> walls;
  for (int i = 0; i <= rooms_per_side; ++i) {
    const double at = i * room_m;
    for (int j = 0; j < rooms_per_side; ++j) {
      const double from = j * room_m, door_from = from + (room_m - door_m) / 2, door_to = door_from + door_m;
      const bool outer = i == 0 || i == rooms_per_side;
      walls.push_back({{at, from}, {at, outer ? from + room_m : door_from}});
      if (!outer) walls.push_back({{at, door_to}, {at, from + room_m}});
      walls.push_back({{from, at}, {outer ? from + room_m : door_from, at}});
      if (!outer) walls.push_back({{door_to, at}, {from + room_m, at}});
    }
  }
  return walls;
}

/// Distance along the ray from `origin` in direction `angle` to the nearest segment.
inline std::optional<double> cast(const std::vector<Segment> &walls, const Eigen::Vector2d &origin,
                                  double angle) {
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
  std::optional<double> best;
  for (const Segment &s : walls) {
    const Eigen::Vector2d e = s.b - s.a;
    const double denom = d.x() * e.y() - d.y() * e.x();
    if (std::abs(denom) < 1e-12) continue;
    const Eigen::Vector2d w = s.a - origin;
    const double t = (w.x() * e.y() - w.y() * e.x()) / denom;
    const double u = (w.x() * d.y() - w.y() * d.x()) / denom;
    if (t > 0 && u >= 0 && u <= 1 && (!best || t < *best)) best = t;
  }
  return best;
}

/// A scan in base_link: one point per degree within [min, max] range, Gaussian range noise.
inline slam::Points2 scan_from(const std::vector<Segment> &walls, const Eigen::Isometry2d &T_map_base,
                               std::mt19937_64 &rng, double noise_m = 0.01, double max_range_m = 3.0) {
  std::normal_distribution<double> noise(0.0, noise_m);
  const double yaw = slam::yaw_rad_of(T_map_base);
  slam::Points2 scan;
  for (int deg = 0; deg < 360; ++deg) {
    const double azimuth = (deg + 0.5) * std::numbers::pi / 180.0;
    const auto range = cast(walls, T_map_base.translation(), yaw + azimuth);
    if (!range || *range > max_range_m || *range < 0.3) continue;
    const double r = *range + noise(rng);
    scan.emplace_back(r * std::cos(azimuth), r * std::sin(azimuth));
  }
  return scan;
}

inline Eigen::Isometry2d pose(double x, double y, double yaw) { return slam::planar_pose(x, y, yaw); }

/// `laps` tours along the closed polyline `corners` (first = last), facing each leg, in steps
/// of about 0.2 m; the tour ends back at its first pose.
inline std::vector<Eigen::Isometry2d> laps_along(const std::vector<Eigen::Vector2d> &corners, int laps) {
  std::vector<Eigen::Isometry2d> truth;
  for (int lap = 0; lap < laps; ++lap) {
    for (std::size_t c = 0; c + 1 < corners.size(); ++c) {
      const Eigen::Vector2d a = corners[c], b = corners[c + 1];
      const double yaw = std::atan2(b.y() - a.y(), b.x() - a.x());
      const int steps = std::max(1, static_cast<int>(std::round((b - a).norm() / 0.2)));
      for (int s = 0; s < steps; ++s) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
        truth.push_back(pose(p.x(), p.y(), yaw));
      }
    }
  }
  truth.push_back(truth.front());
  return truth;
}

/// The corners of a tour of l_room() along its corridor-like legs.
inline std::vector<Eigen::Vector2d> l_room_tour() {
  return {{0, 0}, {5, 0}, {5, 0.6}, {1.5, 0.6}, {1.5, 3}, {0, 3}, {0, 0}};
}

}  // namespace omnislam::test
