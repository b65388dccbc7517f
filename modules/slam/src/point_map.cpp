#include "omnislam/slam/point_map.hpp"

#include <algorithm>
#include <utility>

namespace omnislam::slam {

PointMap::PointMap(PointMapConfig config, std::vector<MapPoint> points, int integrations)
    : config_(config), points_(std::move(points)), integrations_(integrations), check_all_(true) {
  rebuild_index();
}

void PointMap::integrate(const Points2 &points_map) {
  ++integrations_;
  // Fusion (thesis sec. 5.3): a point near an existing one becomes their hit-weighted mean.
  std::vector<MapPoint> added;
  for (const Point2 &p : points_map) {
    if (const auto hit = index_.nearest(p, config_.fusion_radius_m)) {
      MapPoint &target = points_[hit->index];
      target.position_m = (target.position_m * target.hits + p) / (target.hits + 1);
      ++target.hits;
    } else {
      added.push_back({p, 1, integrations_});
    }
  }
  points_.insert(points_.end(), added.begin(), added.end());
  rebuild_index();

  // Noise filter: a point needs noise_min_neighbors others within noise_radius_m. Only the
  // points near the scan or near a removed point can fail where they passed before.
  std::vector<char> check(points_.size(), check_all_ ? 1 : 0);
  if (!check_all_) {
    const double reach = config_.noise_radius_m + config_.fusion_radius_m;
    for (const Point2 &p : points_map)
      for (const std::size_t i : index_.within(p, reach)) check[i] = 1;
    for (const Point2 &p : removed_since_filter_)
      for (const std::size_t i : index_.within(p, config_.noise_radius_m)) check[i] = 1;
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
    rebuild_index();
  }
}

void PointMap::rebuild_index() {
  Points2 positions;
  positions.reserve(points_.size());
  for (const MapPoint &point : points_) positions.push_back(point.position_m);
  index_ = NearestNeighbors(std::move(positions));
}

}  // namespace omnislam::slam
