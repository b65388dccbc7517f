#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "omnislam/slam/point_map.hpp"

// The map's noise filter checks only near the new scan and near removed points; its result
// must equal the thesis's filter over every point of the map.
using omnislam::slam::MapPoint;
using omnislam::slam::NearestNeighbors;
using omnislam::slam::Point2;
using omnislam::slam::PointMap;
using omnislam::slam::PointMapConfig;
using omnislam::slam::Points2;

namespace {

// The thesis's integration written plainly: fuse, filter every point, prune.
class ReferenceMap {
 public:
  explicit ReferenceMap(PointMapConfig config) : config_(config) {}

  void integrate(const Points2 &scan) {
    ++integrations_;
    const NearestNeighbors before(positions());
    std::vector<MapPoint> added;
    for (const Point2 &p : scan) {
      if (const auto hit = before.nearest(p, config_.fusion_radius_m)) {
        MapPoint &target = points_[hit->index];
        target.position_m = (target.position_m * target.hits + p) / (target.hits + 1);
        ++target.hits;
      } else {
        added.push_back({p, 1, integrations_});
      }
    }
    points_.insert(points_.end(), added.begin(), added.end());
    const NearestNeighbors all(positions());
    std::vector<MapPoint> kept;
    for (const MapPoint &point : points_) {
      if (all.count_within(point.position_m, config_.noise_radius_m) >=
          static_cast<std::size_t>(config_.noise_min_neighbors) + 1)
        kept.push_back(point);
    }
    if (config_.prune_every > 0 && integrations_ % config_.prune_every == 0) {
      std::erase_if(kept, [&](const MapPoint &point) {
        return point.hits < config_.prune_min_hits &&
               integrations_ - point.first_seen >= config_.prune_min_age;
      });
    }
    points_ = std::move(kept);
  }

  [[nodiscard]] const std::vector<MapPoint> &points() const { return points_; }

 private:
  [[nodiscard]] Points2 positions() const {
    Points2 out;
    for (const MapPoint &point : points_) out.push_back(point.position_m);
    return out;
  }
  PointMapConfig config_;
  std::vector<MapPoint> points_;
  int integrations_ = 0;
};

bool same(const std::vector<MapPoint> &a, const std::vector<MapPoint> &b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const MapPoint &p, const MapPoint &q) {
    return p.position_m == q.position_m && p.hits == q.hits && p.first_seen == q.first_seen;
  });
}

// Wall points of a 6 x 4 m room seen from `x`, with noise and some isolated outliers.
Points2 scan(std::mt19937_64 &rng, double x) {
  std::uniform_real_distribution<double> along(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::uniform_real_distribution<double> anywhere(-1.0, 7.0);
  Points2 points;
  for (int i = 0; i < 240; ++i) {
    const double t = along(rng);
    Point2 p;
    switch (i % 4) {
      case 0:
        p = {6.0 * t, 0.0};
        break;
      case 1:
        p = {6.0 * t, 4.0};
        break;
      case 2:
        p = {0.0, 4.0 * t};
        break;
      default:
        p = {6.0, 4.0 * t};
        break;
    }
    if (std::abs(p.x() - x) < 3.0) points.push_back(p + Point2(noise(rng), noise(rng)));
  }
  for (int i = 0; i < 15; ++i) points.emplace_back(anywhere(rng), anywhere(rng) * 0.5);
  return points;
}

}  // namespace

TEST_CASE("point map: the local noise filter gives the whole-map filter's map", "[slam][map]") {
  for (const PointMapConfig config :
       {PointMapConfig{}, PointMapConfig{0.05, 0.125, 2, 3, 2, 0}, PointMapConfig{0.08, 0.2, 1, 0, 3, 5}}) {
    PointMap map(config);
    ReferenceMap reference(config);
    std::mt19937_64 rng(11);
    for (int k = 0; k < 60; ++k) {
      const Points2 points = scan(rng, 0.1 * (k % 30) + (k >= 30 ? 1.0 : 0.0));
      map.integrate(points);
      reference.integrate(points);
      INFO("integration " << k + 1 << ", noise_min_neighbors " << config.noise_min_neighbors);
      REQUIRE(same(map.points(), reference.points()));
    }
    CHECK(map.points().size() > 300);
  }
}

TEST_CASE("point map: a restored map is filtered whole at its first integration", "[slam][map]") {
  // An isolated point in a restored map goes at the next integration, wherever the scan is.
  std::vector<MapPoint> saved = {{{0.0, 0.0}, 5, 0}, {{0.05, 0.0}, 5, 0}, {{10.0, 10.0}, 5, 0}};
  PointMap map(PointMapConfig{}, saved, 1);
  map.integrate({{3.0, 3.0}, {3.05, 3.0}});
  REQUIRE(map.points().size() == 4);
  CHECK(map.points()[0].position_m == Point2(0.0, 0.0));
  CHECK(map.points()[2].position_m == Point2(3.0, 3.0));
}

TEST_CASE("point map: a wall's normals weigh each point by how often it was seen", "[slam][map]") {
  // A wall along x seen thirty times, and once in a while its skirting board's top taken for
  // its base: a point 0.1 m behind it, seen three times. Unweighted, the normal of the wall
  // beside that point turns by 5 deg (along a corridor, 0.8% of a pair's information then
  // lies along it, from nothing); weighted by the points' hits, by a tenth of that.
  PointMap map;
  Points2 wall;
  for (double x = 0.0; x <= 1.0; x += 0.06) wall.emplace_back(x, 0.0);
  Points2 with_top = wall;
  with_top.emplace_back(0.51, 0.1);
  for (int i = 0; i < 30; ++i) map.integrate(i < 3 ? with_top : wall);
  const NearestNeighbors &index = map.index();
  const auto beside = index.nearest(Point2(0.48, 0.0), 0.01);
  REQUIRE(beside);
  const Point2 weighted = index.normal(beside->index);
  const NearestNeighbors plain(index.points());
  const Point2 unweighted = plain.normal(beside->index);
  const double weighted_deg = std::acos(std::min(1.0, std::abs(weighted.y()))) * 180.0 / M_PI;
  const double unweighted_deg = std::acos(std::min(1.0, std::abs(unweighted.y()))) * 180.0 / M_PI;
  INFO("turned " << weighted_deg << " deg weighted, " << unweighted_deg << " deg plain");
  CHECK(unweighted_deg > 3.0);
  CHECK(weighted_deg < 0.2 * unweighted_deg);
  CHECK_THROWS_AS(NearestNeighbors(wall, std::vector<double>(wall.size() - 1, 1.0)), std::invalid_argument);
  CHECK_THROWS_AS(NearestNeighbors(wall, std::vector<double>(wall.size(), 0.0)), std::invalid_argument);
}
