#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

/// @file
/// A 2D point set with a k-d tree (nanoflann) for nearest-neighbour and radius queries.

namespace omnislam::slam {

using Point2 = Eigen::Vector2d;
using Points2 = std::vector<Point2>;

struct Neighbor {
  std::size_t index = 0;
  double distance_sq_m2 = 0.0;
};

/// Radius of the neighbourhood a point's normal is fitted to.
inline constexpr double kNormalRadiusM = 0.15;

/// Owns its points and an index built once in the constructor. Move-only; not thread-safe
/// (normals are computed lazily).
class NearestNeighbors {
 public:
  explicit NearestNeighbors(Points2 points = {});
  /// With a weight per point, its inverse variance up to a common factor (a map point fused
  /// from n observations, their mean: n), so each normal is the weighted line fit.
  /// std::invalid_argument unless there is one finite positive weight per point.
  NearestNeighbors(Points2 points, std::vector<double> weights);
  ~NearestNeighbors();
  NearestNeighbors(NearestNeighbors &&) noexcept;
  NearestNeighbors &operator=(NearestNeighbors &&) noexcept;
  NearestNeighbors(const NearestNeighbors &) = delete;
  NearestNeighbors &operator=(const NearestNeighbors &) = delete;

  [[nodiscard]] const Points2 &points() const { return points_; }

  /// Unit normal of the local line through point `index` (PCA of its neighbours within
  /// kNormalRadiusM, weighted when the points are), or zero where fewer than 3 points lie
  /// there. Computed on first use and cached, so a registration pays only for the points it
  /// pairs with.
  [[nodiscard]] const Point2 &normal(std::size_t index) const;
  [[nodiscard]] bool empty() const { return points_.empty(); }

  /// Nearest point within `radius_m` of `query`, or nullopt (also for an empty set).
  [[nodiscard]] std::optional<Neighbor> nearest(const Point2 &query, double radius_m) const;

  /// Number of points within `radius_m` of `query` (the query itself counts if present).
  [[nodiscard]] std::size_t count_within(const Point2 &query, double radius_m) const;

  /// Indices of the points within `radius_m` of `query`, in no particular order.
  [[nodiscard]] std::vector<std::size_t> within(const Point2 &query, double radius_m) const;

 private:
  struct Index;
  Points2 points_;
  std::vector<double> weights_;  ///< empty: every point weighs 1
  std::unique_ptr<Index> index_;
  mutable Points2 normals_;
  mutable std::vector<bool> normal_known_;
};

}  // namespace omnislam::slam
