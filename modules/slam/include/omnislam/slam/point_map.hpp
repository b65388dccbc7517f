#pragma once

#include <cstddef>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// The global 2D point map of the thesis's SLAM loop (sec. 5.3): fusion of near points,
/// noise filter, and periodic removal of rarely seen points.

namespace omnislam::slam {

struct PointMapConfig {
  double fusion_radius_m = 0.05;  ///< thesis Fusao: a new point this close to a map point merges
  double noise_radius_m = 0.125;  ///< thesis RaioFiltro
  int noise_min_neighbors = 1;    ///< thesis PontosFiltro: fewer neighbours -> dropped
  int prune_every = 5;            ///< thesis Iteracoes: prune after this many integrations
  int prune_min_hits = 3;         ///< thesis PontosRepetidos
  int prune_min_age = 5;          ///< only points at least this many integrations old are pruned
                                  ///< (0 = the thesis: every point, even one just added)
};

struct MapPoint {
  Point2 position_m = Point2::Zero();
  int hits = 1;        ///< how many observations were fused into it
  int first_seen = 0;  ///< integration count when it was added
};

class PointMap {
 public:
  explicit PointMap(PointMapConfig config = {}) : config_(config) {}

  /// A map restored from saved points (e.g. a snapshot): `integrations` is the integration
  /// count it had, so the age of each point (its first_seen) keeps its meaning.
  PointMap(PointMapConfig config, std::vector<MapPoint> points, int integrations);

  /// Fuses `points_map` (already in the map frame) into the map, filters noise and, every
  /// prune_every integrations, drops rarely seen points; then rebuilds the search index.
  /// The noise filter gives the thesis's result (every map point checked) but checks only
  /// where a neighbour count can have dropped since the last integration: around the new
  /// scan (fused points move) and around the points removed last time. Elsewhere counts
  /// can only have grown, so the cost follows the scan, not the map.
  void integrate(const Points2 &points_map);

  [[nodiscard]] const std::vector<MapPoint> &points() const { return points_; }
  [[nodiscard]] const NearestNeighbors &index() const { return index_; }
  [[nodiscard]] int integrations() const { return integrations_; }
  [[nodiscard]] bool empty() const { return points_.empty(); }

 private:
  void rebuild_index();

  PointMapConfig config_;
  std::vector<MapPoint> points_;
  NearestNeighbors index_;
  int integrations_ = 0;
  bool check_all_ = false;        ///< the next noise filter checks every point (a restored map)
  Points2 removed_since_filter_;  ///< positions of the points removed after the last filter
};

}  // namespace omnislam::slam
