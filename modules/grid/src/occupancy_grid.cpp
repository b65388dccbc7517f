#include "omnislam/grid/occupancy_grid.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>

namespace omnislam::grid {
namespace {

float log_odds_of(double probability) {
  return static_cast<float>(std::log(probability / (1.0 - probability)));
}

}  // namespace

OccupancyGrid::OccupancyGrid(const GridConfig &config)
    : config_(config),
      hit_(log_odds_of(config.hit_probability)),
      miss_(log_odds_of(config.miss_probability)),
      min_(log_odds_of(config.min_probability)),
      max_(log_odds_of(config.max_probability)) {}

std::uint64_t OccupancyGrid::key(const Cell &cell) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(cell.x())) << 32) |
         static_cast<std::uint32_t>(cell.y());
}

OccupancyGrid::Cell OccupancyGrid::cell_of(const Eigen::Vector2d &point_m) const {
  return {static_cast<int>(std::floor(point_m.x() / config_.resolution_m)),
          static_cast<int>(std::floor(point_m.y() / config_.resolution_m))};
}

void OccupancyGrid::update(CellState &state, float log_odds) const {
  state.log_odds = std::clamp(state.log_odds + log_odds, min_, max_);
}

template <typename Visit>
void OccupancyGrid::traverse(const Eigen::Vector2d &from_m, const Eigen::Vector2d &to_m,
                             Visit &&visit) const {
  // Amanatides-Woo traversal: every cell the segment crosses, in order.
  const Eigen::Vector2d start = from_m / config_.resolution_m, end = to_m / config_.resolution_m;
  Cell cell = cell_of(from_m);
  const Cell last = cell_of(to_m);
  const Eigen::Vector2d direction = end - start;
  Eigen::Vector2i step;
  Eigen::Vector2d next, delta;
  for (int axis = 0; axis < 2; ++axis) {
    step[axis] = direction[axis] > 0.0 ? 1 : (direction[axis] < 0.0 ? -1 : 0);
    const double boundary = step[axis] > 0 ? std::floor(start[axis]) + 1.0 : std::floor(start[axis]);
    next[axis] = step[axis] != 0 ? (boundary - start[axis]) / direction[axis]
                                 : std::numeric_limits<double>::infinity();
    delta[axis] = step[axis] != 0 ? std::abs(1.0 / direction[axis]) : std::numeric_limits<double>::infinity();
  }
  while (cell != last) {
    visit(cell);
    const int axis = next.x() < next.y() ? 0 : 1;
    if (next[axis] > 1.0) break;  // the end lies in this cell after all (rounding)
    cell[axis] += step[axis];
    next[axis] += delta[axis];
  }
}

void OccupancyGrid::mark_hit(const Cell &cell, const Eigen::Vector2d &origin_m, bool elevated) {
  const std::uint64_t cell_key = key(cell);
  CellState &state = cells_[cell_key];
  if (elevated && !state.above_floor) {
    const auto [first_seen, first] = first_seen_above_.try_emplace(cell_key, origin_m.cast<float>());
    if (!first && (origin_m.cast<float>() - first_seen->second).norm() >= config_.elevated_baseline_m) {
      state.above_floor = true;
      state.log_odds = std::max(state.log_odds, 0.0f);  // the floor seen under it said nothing of it
      first_seen_above_.erase(first_seen);
    }
  }
  update(state, hit_);
}

void OccupancyGrid::add_scan(const Eigen::Isometry2d &T_map_base, std::span<const Ray> rays) {
  const Eigen::Vector2d origin = T_map_base.translation();
  for (const Ray &ray : rays) {
    const Eigen::Vector2d direction =
        T_map_base.linear() * Eigen::Vector2d(std::cos(ray.azimuth_rad), std::sin(ray.azimuth_rad));
    const bool hit = std::isfinite(ray.hit_m) && ray.hit_m > 0.0;
    // Free floor up to the boundary (never past it) or, with none, as far as it was seen.
    double free_m = std::isfinite(ray.free_m) ? ray.free_m : 0.0;
    if (hit) free_m = std::min(free_m, ray.hit_m);
    if (free_m > 0.0) {
      traverse(origin, origin + free_m * direction, [&](const Cell &cell) {
        CellState &state = cells_[key(cell)];
        if (!state.above_floor) update(state, miss_);
      });
    }
    if (!hit) continue;
    const Eigen::Vector2d boundary = origin + ray.hit_m * direction;
    if (!std::isfinite(ray.lower_m)) {
      mark_hit(cell_of(boundary), origin, ray.hit_elevated);
      continue;
    }
    // A drop: every cell the ray crossed over the lower floor, the last one included. Like a
    // wall's base, floor seen through them later clears them: a chance twin under a floor edge
    // reads as a lower floor too, and a real one is seen again from every side.
    const Eigen::Vector2d lower = origin + std::max(ray.lower_m, ray.hit_m) * direction;
    traverse(boundary, lower, [&](const Cell &cell) { mark_hit(cell, origin, false); });
    mark_hit(cell_of(lower), origin, false);
  }
}

void OccupancyGrid::seed(const GridImage &start) {
  const Eigen::Vector2i low = (start.origin_m / config_.resolution_m).array().round().cast<int>();
  const bool flagged = start.above_floor.size() == start.cells.size();
  for (int y = 0; y < start.height; ++y) {
    for (int x = 0; x < start.width; ++x) {
      const std::size_t index =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(start.width) + static_cast<std::size_t>(x);
      const std::int8_t cell = start.cells[index];
      // Unknown cells too (at even odds): the grid keeps the extent it had.
      CellState &state = cells_[key(low + Cell(x, y))];
      state.log_odds = cell == 100 ? max_ : (cell == 0 ? min_ : 0.0f);
      state.above_floor = flagged && start.above_floor[index] != 0;
    }
  }
}

GridImage OccupancyGrid::image() const {
  GridImage image;
  image.resolution_m = config_.resolution_m;
  if (cells_.empty()) return image;
  Cell low(INT_MAX, INT_MAX), high(INT_MIN, INT_MIN);
  for (const auto &[cell_key, state] : cells_) {
    const Cell cell(static_cast<int>(static_cast<std::int32_t>(cell_key >> 32)),
                    static_cast<int>(static_cast<std::int32_t>(cell_key & 0xffffffffu)));
    low = low.cwiseMin(cell);
    high = high.cwiseMax(cell);
  }
  image.width = high.x() - low.x() + 1;
  image.height = high.y() - low.y() + 1;
  image.origin_m = low.cast<double>() * config_.resolution_m;
  image.cells.assign(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height), -1);
  image.above_floor.assign(image.cells.size(), 0);
  const float occupied = log_odds_of(config_.occupied_threshold), free = log_odds_of(config_.free_threshold);
  for (const auto &[cell_key, state] : cells_) {
    const int x = static_cast<int>(static_cast<std::int32_t>(cell_key >> 32)) - low.x();
    const int y = static_cast<int>(static_cast<std::int32_t>(cell_key & 0xffffffffu)) - low.y();
    const std::size_t index =
        static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x);
    image.cells[index] = state.log_odds >= occupied ? 100 : (state.log_odds <= free ? 0 : -1);
    image.above_floor[index] = state.above_floor ? 1 : 0;
  }
  return image;
}

}  // namespace omnislam::grid
