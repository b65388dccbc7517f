#include "omnislam/slam/point_map.hpp"

#include <algorithm>
#include <limits>
#include <utility>

namespace omnislam::slam {

Points2 positions_of(std::span<const MapPoint> points) {
  Points2 positions;
  positions.reserve(points.size());
  for (const MapPoint &p : points) positions.push_back(p.position_m);
  return positions;
}
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

void PointMap::Box::add(const Point2 &p) {
  min = min.cwiseMin(p);
  max = max.cwiseMax(p);
}

PointMap::Box PointMap::Box::grown(double margin_m) const {
  return {min.array() - margin_m, max.array() + margin_m};
}

bool PointMap::Box::contains(const Point2 &p) const {
  return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
}

bool PointMap::Box::contains(const Box &other) const {
  return (other.min.array() >= min.array()).all() && (other.max.array() <= max.array()).all();
}

PointMap::Box PointMap::Box::everything() {
  return {Point2::Constant(-kInfinity), Point2::Constant(kInfinity)};
}

PointMap::Box PointMap::Box::around(const Points2 &points) {
  Box box = nothing();
  for (const Point2 &p : points) box.add(p);
  return box;
}

PointMap::Box PointMap::Box::nothing() { return {Point2::Constant(kInfinity), Point2::Constant(-kInfinity)}; }

PointMap::PointMap(PointMapConfig config, std::vector<MapPoint> points, int integrations)
    : config_(config), points_(std::move(points)), integrations_(integrations), check_all_(true) {
  index_points_in(Box::everything());
}

void PointMap::integrate(const Points2 &points_map) {
  ++integrations_;
  // Everything this integration changes or checks lies near the scan or near the points
  // removed last time; the index covers that region only, so its cost follows the scan,
  // not the map (a restored map is checked whole once).
  Box touched = Box::around(points_map);
  for (const Point2 &p : removed_since_filter_) touched.add(p);
  const double reach = config_.fusion_radius_m + 2.0 * config_.noise_radius_m;
  const Box region = check_all_ ? Box::everything() : touched.grown(std::max(reach, config_.local_margin_m));
  if (!indexed_.contains(touched.grown(config_.fusion_radius_m))) index_points_in(region);

  // Fusion (thesis sec. 5.3): a point near an existing one becomes their hit-weighted mean.
  std::vector<MapPoint> added;
  for (const Point2 &p : points_map) {
    if (const auto hit = index_.nearest(p, config_.fusion_radius_m)) {
      MapPoint &target = points_[indexed_points_[hit->index]];
      target.position_m = (target.position_m * target.hits + p) / (target.hits + 1);
      ++target.hits;
    } else {
      added.push_back({p, 1, integrations_});
    }
  }
  points_.insert(points_.end(), added.begin(), added.end());
  index_points_in(region);

  // Noise filter: a point needs noise_min_neighbors others within noise_radius_m. Only the
  // points near the scan or near a removed point can fail where they passed before.
  std::vector<char> check(points_.size(), check_all_ ? 1 : 0);
  if (!check_all_) {
    const double near_scan = config_.noise_radius_m + config_.fusion_radius_m;
    for (const Point2 &p : points_map)
      for (const std::size_t i : index_.within(p, near_scan)) check[indexed_points_[i]] = 1;
    for (const Point2 &p : removed_since_filter_)
      for (const std::size_t i : index_.within(p, config_.noise_radius_m)) check[indexed_points_[i]] = 1;
  }
  check_all_ = false;
  removed_since_filter_.clear();
  std::vector<MapPoint> kept;
  kept.reserve(points_.size());
  const auto min_around = static_cast<std::size_t>(config_.noise_min_neighbors) + 1;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!check[i] || index_.count_within(points_[i].position_m, config_.noise_radius_m) >= min_around) {
      kept.push_back(points_[i]);
    } else {
      removed_since_filter_.push_back(points_[i].position_m);
    }
  }
  // Every prune_every integrations, drop points seen fewer than prune_min_hits times.
  if (config_.prune_every > 0 && integrations_ % config_.prune_every == 0) {
    std::erase_if(kept, [&](const MapPoint &point) {
      const bool prune =
          point.hits < config_.prune_min_hits && integrations_ - point.first_seen >= config_.prune_min_age;
      if (prune) removed_since_filter_.push_back(point.position_m);
      return prune;
    });
  }
  if (kept.size() != points_.size()) {
    points_ = std::move(kept);
    index_points_in(region);
  }
}

const NearestNeighbors &PointMap::index_near(const Points2 &points_map, double reach_m) {
  if (check_all_) return index_;  // a restored map: the whole map is indexed until it changes
  const Box needed = Box::around(points_map);
  if (!indexed_.contains(needed.grown(reach_m)))
    index_points_in(needed.grown(std::max(reach_m, config_.local_margin_m)));
  return index_;
}

void PointMap::index_points_in(const Box &region) {
  Points2 positions;
  std::vector<double> hits;  // a point's weight in the normals: it is the mean of that many
  indexed_points_.clear();
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!region.contains(points_[i].position_m)) continue;
    positions.push_back(points_[i].position_m);
    hits.push_back(static_cast<double>(std::max(points_[i].hits, 1)));
    indexed_points_.push_back(i);
  }
  index_ = NearestNeighbors(std::move(positions), std::move(hits));
  indexed_ = region;
}

}  // namespace omnislam::slam
