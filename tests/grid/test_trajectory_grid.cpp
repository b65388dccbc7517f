#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

#include "omnislam/grid/trajectory_grid.hpp"

using omnislam::grid::GridImage;
using omnislam::grid::Ray;
using omnislam::grid::TrajectoryGrid;

namespace {

// A scan from `T_map_base` inside the square room [-2, 2] x [-2, 2] m: one ray per degree,
// hitting the wall, the floor seen free up to it.
std::vector<Ray> room_scan(const Eigen::Isometry2d &T_map_base) {
  std::vector<Ray> rays;
  const Eigen::Vector2d origin = T_map_base.translation();
  const double yaw = std::atan2(T_map_base.linear()(1, 0), T_map_base.linear()(0, 0));
  for (int degree = 0; degree < 360; ++degree) {
    const double azimuth = degree * std::numbers::pi / 180.0;
    const Eigen::Vector2d direction(std::cos(yaw + azimuth), std::sin(yaw + azimuth));
    double range = 1e9;
    for (int axis = 0; axis < 2; ++axis) {
      if (std::abs(direction[axis]) < 1e-12) continue;
      const double wall = direction[axis] > 0.0 ? 2.0 : -2.0;
      range = std::min(range, (wall - origin[axis]) / direction[axis]);
    }
    rays.push_back({azimuth, range, range});
  }
  return rays;
}

Eigen::Isometry2d pose(double x, double y, double yaw) {
  return Eigen::Translation2d(x, y) * Eigen::Rotation2Dd(yaw);
}

// Occupied cells farther than `tolerance_m` from the room's walls.
int off_wall(const GridImage &image, double tolerance_m) {
  int count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (image.cells[static_cast<std::size_t>(y * image.width + x)] != 100) continue;
      const Eigen::Vector2d centre =
          image.origin_m + (Eigen::Vector2d(x, y).array() + 0.5).matrix() * image.resolution_m;
      const double to_wall = 2.0 - centre.cwiseAbs().maxCoeff();
      count += std::abs(to_wall) > tolerance_m ? 1 : 0;
    }
  }
  return count;
}

}  // namespace

TEST_CASE("trajectory grid: scans that cannot change the grid are not kept", "[grid]") {
  TrajectoryGrid grid;  // 0.05 m cells
  CHECK(grid.add_scan(0, pose(0.0, 0.0, 0.0), room_scan(pose(0.0, 0.0, 0.0))));
  // Standing still, or moving less than a cell: nothing new.
  CHECK_FALSE(grid.add_scan(1, pose(0.0, 0.0, 0.0), room_scan(pose(0.0, 0.0, 0.0))));
  CHECK_FALSE(grid.add_scan(2, pose(0.03, 0.0, 0.0), room_scan(pose(0.03, 0.0, 0.0))));
  // The longest ray reaches a corner, 2.83 m: a turn moves its end by a cell at 1 deg.
  CHECK_FALSE(
      grid.add_scan(3, pose(0.0, 0.0, 0.5 * std::numbers::pi / 180.0), room_scan(pose(0.0, 0.0, 0.0))));
  CHECK(grid.add_scan(4, pose(0.0, 0.0, 1.2 * std::numbers::pi / 180.0), room_scan(pose(0.0, 0.0, 0.0))));
  CHECK(grid.add_scan(5, pose(0.06, 0.0, 0.0), room_scan(pose(0.06, 0.0, 0.0))));
  CHECK(grid.kept_scans() == 3u);
}

TEST_CASE("trajectory grid: a scan added but not kept is in the grid until the next rebuild", "[grid]") {
  TrajectoryGrid grid;
  const Eigen::Isometry2d first = pose(-1.0, 0.0, 0.0);
  const Eigen::Isometry2d second = pose(1.0, 0.0, 0.0);
  CHECK(grid.add_scan(0, first, room_scan(first)));
  const GridImage one = grid.image();
  // Not kept (the service keeps only the frames the SLAM keeps): added all the same, and
  // the next scan must move a cell from it, not from the last kept one.
  CHECK(grid.add_scan(1, second, room_scan(second), false));
  CHECK_FALSE(grid.add_scan(2, second, room_scan(second)));
  CHECK(grid.kept_scans() == 1u);
  CHECK(grid.image().cells != one.cells);
  grid.rebuild(std::vector<Eigen::Isometry2d>{first, second});
  const GridImage rebuilt = grid.image();
  CHECK(rebuilt.cells == one.cells);
}

TEST_CASE("trajectory grid: rebuilt from corrected poses, the walls move to where they are", "[grid]") {
  // The robot crosses the room; its poses drift 1 cm per step in y (a loop closure later
  // finds the true ones). The scans are what it saw from the true poses.
  std::vector<Eigen::Isometry2d> truth, drifted;
  TrajectoryGrid grid;
  for (int step = 0; step < 30; ++step) {
    truth.push_back(pose(-1.5 + 0.1 * step, 0.0, 0.02 * step));
    drifted.push_back(pose(-1.5 + 0.1 * step, 0.01 * step, 0.02 * step));
    grid.add_scan(step, drifted.back(), room_scan(truth.back()));
  }
  const GridImage before = grid.image();
  CHECK(off_wall(before, 0.1) > 50);  // walls smeared by up to 0.29 m

  SECTION("the same poses give the same grid, cell for cell") {
    grid.rebuild(drifted);
    const GridImage again = grid.image();
    CHECK(again.width == before.width);
    CHECK(again.height == before.height);
    CHECK(again.origin_m.isApprox(before.origin_m));
    CHECK(again.cells == before.cells);
  }
  SECTION("the corrected poses put every occupied cell on a wall") {
    grid.rebuild(truth);
    CHECK(off_wall(grid.image(), 0.05) == 0);
  }
  SECTION("a scan of a frame the trajectory does not hold keeps its pose") {
    grid.rebuild(std::vector<Eigen::Isometry2d>(truth.begin(), truth.begin() + 10));
    CHECK(off_wall(grid.image(), 0.1) > 0);
  }
}

TEST_CASE("trajectory grid: a seed from a snapshot stays under every rebuild", "[grid]") {
  GridImage seed;
  seed.width = 2;
  seed.height = 1;
  seed.resolution_m = 0.05;
  seed.origin_m = Eigen::Vector2d(10.0, 10.0);  // far from anything the scans see
  seed.cells = {100, 0};
  TrajectoryGrid grid;
  grid.seed(seed);
  grid.add_scan(0, pose(0.0, 0.0, 0.0), room_scan(pose(0.0, 0.0, 0.0)));
  grid.rebuild(std::vector<Eigen::Isometry2d>{pose(0.0, 0.0, 0.0)});
  const GridImage image = grid.image();
  const int x = static_cast<int>(std::lround((10.0 - image.origin_m.x()) / image.resolution_m));
  const int y = static_cast<int>(std::lround((10.0 - image.origin_m.y()) / image.resolution_m));
  CHECK(image.cells[static_cast<std::size_t>(y * image.width + x)] == 100);
  CHECK(image.cells[static_cast<std::size_t>(y * image.width + x + 1)] == 0);
}

TEST_CASE("trajectory grid: an edge seen above the floor stays through a rebuild", "[grid]") {
  // A table's edge at (1.025, 0.025) seen from (0, 0) and from 0.5 m beside, then the floor
  // under it seen eight times from farther back, each scan its own frame.
  TrajectoryGrid grid;
  std::vector<Eigen::Isometry2d> trajectory = {pose(0.0, 0.0, 0.0), pose(0.0, 0.5, 0.0)};
  const Eigen::Vector2d edge(1.025, 0.025);
  for (int frame = 0; frame < 2; ++frame) {
    const Eigen::Vector2d to_edge = edge - trajectory[static_cast<std::size_t>(frame)].translation();
    REQUIRE(grid.add_scan(
        frame, trajectory[static_cast<std::size_t>(frame)],
        std::vector<Ray>{{std::atan2(to_edge.y(), to_edge.x()), to_edge.norm(), to_edge.norm(), true}}));
  }
  for (int frame = 2; frame < 10; ++frame) {
    trajectory.push_back(pose(-0.1 * frame, 0.025, 0.0));
    REQUIRE(grid.add_scan(frame, trajectory.back(), std::vector<Ray>{{0.0, NAN, 1.8 + 0.1 * frame, false}}));
  }
  const auto cell = [](const GridImage &image, const Eigen::Vector2d &at) {
    const int x = static_cast<int>(std::floor((at.x() - image.origin_m.x()) / image.resolution_m));
    const int y = static_cast<int>(std::floor((at.y() - image.origin_m.y()) / image.resolution_m));
    return image.cells[static_cast<std::size_t>(y * image.width + x)];
  };
  CHECK(cell(grid.image(), edge) == 100);
  CHECK(cell(grid.image(), Eigen::Vector2d(1.325, 0.025)) == 0);  // the floor under and beyond it
  grid.rebuild(trajectory);
  CHECK(cell(grid.image(), edge) == 100);
  CHECK(cell(grid.image(), Eigen::Vector2d(1.325, 0.025)) == 0);
}

TEST_CASE("trajectory grid: a drop keeps the lower floor it reached through a rebuild", "[grid]") {
  // A ray crossing the floor's level at 1 m that reached a lower floor 0.3 m farther.
  TrajectoryGrid grid;
  const std::vector<Eigen::Isometry2d> trajectory = {pose(0.0, 0.0, 0.0)};
  Ray drop{0.0, 1.025, 0.5};
  drop.lower_m = 1.325;
  REQUIRE(grid.add_scan(0, trajectory[0], std::vector<Ray>{drop}));
  const auto cell = [](const GridImage &image, double x) {
    const int column = static_cast<int>(std::floor((x - image.origin_m.x()) / image.resolution_m));
    const int row = static_cast<int>(std::floor((0.025 - image.origin_m.y()) / image.resolution_m));
    return image.cells[static_cast<std::size_t>(row * image.width + column)];
  };
  const auto over_lower_floor = [&] {
    int occupied = 0;
    for (double x = 1.025; x < 1.35; x += 0.05) occupied += cell(grid.image(), x) == 100 ? 1 : 0;
    return occupied;
  };
  CHECK(over_lower_floor() == 7);
  grid.rebuild(trajectory);
  CHECK(over_lower_floor() == 7);
}
