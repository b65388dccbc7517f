#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// The global 2D point map of the thesis's SLAM loop (sec. 5.3): fusion of near points,
/// noise filter, and periodic removal of rarely seen points. Its search index covers only
/// the region around the last scan, so an integration costs what the scan touches plus a
/// linear pass over the points, not an index over the whole map.

namespace omnislam::slam {

struct PointMapConfig {
  double fusion_radius_m = 0.05;  ///< thesis Fusao: a new point this close to a map point merges
  double noise_radius_m = 0.125;  ///< thesis RaioFiltro
  int noise_min_neighbors = 1;    ///< thesis PontosFiltro: fewer neighbours -> dropped
  int prune_every = 5;            ///< thesis Iteracoes: prune after this many integrations
  int prune_min_hits = 3;         ///< thesis PontosRepetidos
  int prune_min_age = 5;          ///< only points at least this many integrations old are pruned
                                  ///< (0 = the thesis: every point, even one just added)
  /// The search index (registration, fusion, noise filter) covers the last scan's bounding
  /// box grown by this much, not the whole map: enough for the next frame's motion (~0.3 m
  /// at 10 Hz), the registration's first search radius (0.5 m) and its largest accepted
  /// correction (0.3 m); structure first seen beyond it joins from the frame after.
  double local_margin_m = 1.0;
};

struct MapPoint {
  Point2 position_m = Point2::Zero();
  int hits = 1;        ///< how many observations were fused into it
  int first_seen = 0;  ///< integration count when it was added
};

/// The positions of map points (what the searches over a map take).
[[nodiscard]] Points2 positions_of(std::span<const MapPoint> points);

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
  /// The search index over the map points near the last scan (all of a restored map until
  /// its first integration); its point i is points()[indexed_points()[i]].
  [[nodiscard]] const NearestNeighbors &index() const { return index_; }
  [[nodiscard]] const std::vector<std::size_t> &indexed_points() const { return indexed_points_; }
  /// The index, first rebuilt (over the bounding box grown by local_margin_m) unless it
  /// already covers every point of `points_map` with `reach_m` to spare: what a
  /// registration of those points needs (its search radius plus its largest correction).
  [[nodiscard]] const NearestNeighbors &index_near(const Points2 &points_map, double reach_m);
  [[nodiscard]] int integrations() const { return integrations_; }
  [[nodiscard]] bool empty() const { return points_.empty(); }

 private:
  /// An axis-aligned region of the map plane.
  struct Box {
    Point2 min;
    Point2 max;
    void add(const Point2 &p);
    [[nodiscard]] Box grown(double margin_m) const;
    [[nodiscard]] bool contains(const Point2 &p) const;
    [[nodiscard]] bool contains(const Box &other) const;
    static Box everything();
    static Box nothing();
    static Box around(const Points2 &points);  ///< the bounding box of the points
  };
  /// Rebuilds the index over the points inside `region`.
  void index_points_in(const Box &region);

  PointMapConfig config_;
  std::vector<MapPoint> points_;
  NearestNeighbors index_;
  std::vector<std::size_t> indexed_points_;  ///< index point -> points_ position
  Box indexed_ = Box::nothing();             ///< the region index_ covers
  int integrations_ = 0;
  bool check_all_ = false;        ///< the next noise filter checks every point (a restored map)
  Points2 removed_since_filter_;  ///< positions of the points removed after the last filter
};

}  // namespace omnislam::slam
