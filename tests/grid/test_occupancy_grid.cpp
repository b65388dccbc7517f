#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "omnislam/grid/occupancy_grid.hpp"

using omnislam::grid::GridImage;
using omnislam::grid::OccupancyGrid;
using omnislam::grid::Ray;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

int at(const GridImage &image, double x_m, double y_m) {
  const int x = static_cast<int>(std::floor((x_m - image.origin_m.x()) / image.resolution_m));
  const int y = static_cast<int>(std::floor((y_m - image.origin_m.y()) / image.resolution_m));
  REQUIRE(x >= 0);
  REQUIRE(y >= 0);
  REQUIRE(x < image.width);
  REQUIRE(y < image.height);
  return image.cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                     static_cast<std::size_t>(x)];
}

}  // namespace

TEST_CASE("occupancy grid: free floor up to the boundary, the boundary occupied, the rest unknown",
          "[grid]") {
  OccupancyGrid grid({.resolution_m = 0.1});
  const Eigen::Isometry2d pose = Eigen::Translation2d(0.05, 0.05) * Eigen::Rotation2Dd(0.0);
  // Along +x a wall at 1 m; along +y free floor seen to 0.5 m, no boundary; along -x nothing.
  const std::vector<Ray> rays = {{0.0, 1.0, 1.0}, {M_PI / 2, kNaN, 0.5}, {M_PI, kNaN, kNaN}};
  for (int i = 0; i < 3; ++i) grid.add_scan(pose, rays);
  const GridImage image = grid.image();
  CHECK(image.resolution_m == 0.1);
  CHECK(image.origin_m.x() == Approx(0.0));
  CHECK(image.origin_m.y() == Approx(0.0));
  CHECK(image.width == 11);  // cells 0..10 along x: 0..9 free, 10 the wall
  CHECK(image.height == 5);  // cells 0..4 along y, free to 0.5 m (the cell of 0.55 m not reached)
  for (double x = 0.05; x < 1.0; x += 0.1) CHECK(at(image, x, 0.05) == 0);
  CHECK(at(image, 1.05, 0.05) == 100);
  for (double y = 0.05; y < 0.5; y += 0.1) CHECK(at(image, 0.05, y) == 0);
  CHECK(at(image, 0.55, 0.35) == -1);  // never observed
}

TEST_CASE("occupancy grid: one free pass over a boundary cell does not clear it; the pose rotates the rays",
          "[grid]") {
  OccupancyGrid grid({.resolution_m = 0.1});
  const Eigen::Isometry2d facing_y = Eigen::Translation2d(0.05, 0.05) * Eigen::Rotation2Dd(M_PI / 2);
  const std::vector<Ray> wall = {{0.0, 0.6, 0.6}};  // ahead, i.e. along +y in the map
  grid.add_scan(facing_y, wall);
  grid.add_scan(facing_y, wall);
  grid.add_scan(facing_y, std::vector<Ray>{{0.0, kNaN, 1.0}});  // one look past it
  const GridImage image = grid.image();
  CHECK(at(image, 0.05, 0.65) == 100);  // hit twice (+0.85 each), missed once (-0.41): still occupied
  CHECK(at(image, 0.05, 0.35) == 0);    // missed three times: P 0.23, free
  CHECK(at(image, 0.05, 0.85) == -1);   // missed once: P 0.40, not yet free
  CHECK(grid.image().width == 1);
}

TEST_CASE("occupancy grid: seeded from a trinary image (a resumed snapshot) gives it back, then learns",
          "[grid]") {
  OccupancyGrid first({.resolution_m = 0.1});
  const Eigen::Isometry2d pose = Eigen::Translation2d(-0.35, 0.25) * Eigen::Rotation2Dd(0.3);
  first.add_scan(pose, std::vector<Ray>{{0.0, 1.0, 1.0}, {M_PI / 2, kNaN, 0.5}, {-2.0, 0.7, 0.7}});
  const GridImage saved = first.image();
  REQUIRE(saved.width > 1);

  OccupancyGrid resumed({.resolution_m = 0.1});
  resumed.seed(saved);
  const GridImage again = resumed.image();
  CHECK(again.width == saved.width);
  CHECK(again.height == saved.height);
  CHECK(again.origin_m.isApprox(saved.origin_m, 1e-12));
  CHECK(again.cells == saved.cells);

  // A seeded occupied cell is at the confidence bound: three free passes (-0.41 each from
  // 3.48) leave it occupied.
  const Eigen::Vector2d wall = pose * Eigen::Vector2d(1.0, 0.0);
  for (int i = 0; i < 3; ++i) resumed.add_scan(pose, std::vector<Ray>{{0.0, kNaN, 1.5}});
  CHECK(at(resumed.image(), wall.x(), wall.y()) == 100);
}

TEST_CASE(
    "occupancy grid: floor seen under a table's edge does not clear it once two viewpoints saw the edge",
    "[grid]") {
  // A table's edge at (2.05, 0.05), seen from (0, 0) and from 0.5 m along it; then the robot
  // drives round and sees the floor beyond it, under the table, eight times from (0, 0) (two
  // hits, +0.85 each, need seven misses of -0.41 to read free).
  const Eigen::Isometry2d here = Eigen::Translation2d(0.0, 0.05) * Eigen::Rotation2Dd(0.0);
  const Eigen::Isometry2d along = Eigen::Translation2d(0.0, 0.55) * Eigen::Rotation2Dd(0.0);
  const double to_edge_along = std::hypot(2.05, 0.5);
  const Ray edge_here{0.0, 2.05, 2.05, true};
  const Ray edge_along{std::atan2(-0.5, 2.05), to_edge_along, to_edge_along, true};
  const Ray floor_under{0.0, kNaN, 3.0};
  const auto seen_under = [&](OccupancyGrid &grid) {
    for (int i = 0; i < 8; ++i) grid.add_scan(here, std::vector<Ray>{floor_under});
  };
  SECTION("from two viewpoints 0.5 m apart: it stays, the floor before and beyond it is free") {
    OccupancyGrid grid({.resolution_m = 0.1});
    grid.add_scan(here, std::vector<Ray>{edge_here});
    grid.add_scan(along, std::vector<Ray>{edge_along});
    seen_under(grid);
    const GridImage image = grid.image();
    CHECK(at(image, 2.05, 0.05) == 100);
    CHECK(at(image, 1.05, 0.05) == 0);
    CHECK(at(image, 2.55, 0.05) == 0);
  }
  SECTION("the floor seen under it before it was seen counts neither") {
    OccupancyGrid grid({.resolution_m = 0.1});
    seen_under(grid);
    grid.add_scan(here, std::vector<Ray>{edge_here});
    grid.add_scan(along, std::vector<Ray>{edge_along});
    CHECK(at(grid.image(), 2.05, 0.05) == 100);
  }
  SECTION("from one viewpoint only (a wrong point that moves with the robot): cleared like any") {
    OccupancyGrid grid({.resolution_m = 0.1});
    grid.add_scan(here, std::vector<Ray>{edge_here});
    grid.add_scan(here, std::vector<Ray>{edge_here});
    seen_under(grid);
    CHECK(at(grid.image(), 2.05, 0.05) == 0);
  }
  SECTION("a grid resumed from its image (a snapshot) still keeps it; without the flags it did not") {
    OccupancyGrid grid({.resolution_m = 0.1});
    grid.add_scan(here, std::vector<Ray>{edge_here});
    grid.add_scan(along, std::vector<Ray>{edge_along});
    const GridImage saved = grid.image();
    REQUIRE(saved.above_floor.size() == saved.cells.size());
    CHECK(std::count(saved.above_floor.begin(), saved.above_floor.end(), 1) == 1);
    OccupancyGrid resumed({.resolution_m = 0.1});
    resumed.seed(saved);
    CHECK(resumed.image().above_floor == saved.above_floor);
    seen_under(resumed);
    CHECK(at(resumed.image(), 2.05, 0.05) == 100);
    GridImage unflagged = saved;  // as a map file or a version-4 snapshot gives it
    unflagged.above_floor.clear();
    OccupancyGrid forgetting({.resolution_m = 0.1});
    forgetting.seed(unflagged);
    seen_under(forgetting);
    seen_under(forgetting);
    CHECK(at(forgetting.image(), 2.05, 0.05) == 0);
  }
  SECTION(
      "a boundary on the floor (a wall's base, a person's feet) is cleared when the floor is seen there") {
    OccupancyGrid grid({.resolution_m = 0.1});
    grid.add_scan(here, std::vector<Ray>{{0.0, 2.05, 2.05, false}});
    grid.add_scan(along, std::vector<Ray>{{edge_along.azimuth_rad, to_edge_along, to_edge_along, false}});
    seen_under(grid);
    CHECK(at(grid.image(), 2.05, 0.05) == 0);
  }
}

TEST_CASE("occupancy grid: a drop marks the cells over the lower floor, which floor seen there clears",
          "[grid]") {
  // A sunken floor: the ray from (0, 0.05) crosses the floor's level at 1.55 m and reaches the
  // lower floor at 1.85 m.
  const Eigen::Isometry2d here = Eigen::Translation2d(0.0, 0.05) * Eigen::Rotation2Dd(0.0);
  Ray drop{0.0, 1.55, 0.0};
  drop.lower_m = 1.85;
  OccupancyGrid grid({.resolution_m = 0.1});
  grid.add_scan(here, std::vector<Ray>{drop});
  SECTION("each cell from the crossing to the lower floor is occupied, nothing else seen") {
    const GridImage image = grid.image();
    for (const double x : {1.55, 1.65, 1.75, 1.85}) CHECK(at(image, x, 0.05) == 100);
    CHECK(image.width == 4);  // the floor nearer is unknown
    CHECK(std::count(image.above_floor.begin(), image.above_floor.end(), 1) == 0);
  }
  SECTION("seen twice and then crossed by floor seen free eight times (a chance twin): cleared") {
    grid.add_scan(here, std::vector<Ray>{drop});
    for (int i = 0; i < 8; ++i) grid.add_scan(here, std::vector<Ray>{{0.0, kNaN, 3.0}});
    for (const double x : {1.55, 1.75, 1.85}) CHECK(at(grid.image(), x, 0.05) == 0);
  }
  SECTION("seen as often as floor is claimed across it: it stays") {
    for (int i = 0; i < 3; ++i) {
      grid.add_scan(here, std::vector<Ray>{drop});
      grid.add_scan(here, std::vector<Ray>{{0.0, kNaN, 3.0}});
    }
    for (const double x : {1.55, 1.75, 1.85}) CHECK(at(grid.image(), x, 0.05) == 100);
  }
}
