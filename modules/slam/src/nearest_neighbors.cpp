#include "omnislam/slam/nearest_neighbors.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <nanoflann.hpp>
#include <stdexcept>
#include <string>
#include <utility>

namespace omnislam::slam {

// nanoflann reads the points through this adaptor; the tree keeps a reference to it, so
// both live together behind the pointer and survive moves of NearestNeighbors.
struct NearestNeighbors::Index {
  struct Adaptor {
    const Points2 *points;
    [[nodiscard]] std::size_t kdtree_get_point_count() const { return points->size(); }
    [[nodiscard]] double kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][dim]; }
    template <class Box>
    bool kdtree_get_bbox(Box &) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>, Adaptor, 2,
                                                   std::size_t>;

  explicit Index(const Points2 *points) : adaptor{points}, tree(2, adaptor, {10}) { tree.buildIndex(); }
  Adaptor adaptor;
  Tree tree;
};

NearestNeighbors::NearestNeighbors(Points2 points) : points_(std::move(points)) {
  if (!points_.empty()) index_ = std::make_unique<Index>(&points_);
}

NearestNeighbors::NearestNeighbors(Points2 points, std::vector<double> weights)
    : NearestNeighbors(std::move(points)) {
  if (weights.size() != points_.size()) {
    throw std::invalid_argument("NearestNeighbors: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(points_.size()) + " points");
  }
  for (const double w : weights) {
    if (!(w > 0.0 && std::isfinite(w)))
      throw std::invalid_argument("NearestNeighbors: a weight is not finite and positive");
  }
  weights_ = std::move(weights);
}

NearestNeighbors::~NearestNeighbors() = default;

// A moved std::vector keeps its buffer, so the tree's pointer to points_ must follow it.
NearestNeighbors::NearestNeighbors(NearestNeighbors &&other) noexcept
    : points_(std::move(other.points_)),
      weights_(std::move(other.weights_)),
      index_(std::move(other.index_)),
      normals_(std::move(other.normals_)),
      normal_known_(std::move(other.normal_known_)) {
  if (index_) index_->adaptor.points = &points_;
}

NearestNeighbors &NearestNeighbors::operator=(NearestNeighbors &&other) noexcept {
  points_ = std::move(other.points_);
  weights_ = std::move(other.weights_);
  index_ = std::move(other.index_);
  normals_ = std::move(other.normals_);
  normal_known_ = std::move(other.normal_known_);
  if (index_) index_->adaptor.points = &points_;
  return *this;
}

std::optional<Neighbor> NearestNeighbors::nearest(const Point2 &query, double radius_m) const {
  if (!index_) return std::nullopt;
  std::size_t index = 0;
  double distance_sq = 0.0;
  nanoflann::KNNResultSet<double, std::size_t> result(1);
  result.init(&index, &distance_sq);
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (result.size() == 0 || distance_sq > radius_m * radius_m) return std::nullopt;
  return Neighbor{index, distance_sq};
}

std::size_t NearestNeighbors::count_within(const Point2 &query, double radius_m) const {
  if (!index_) return 0;
  std::vector<std::pair<std::size_t, double>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  return index_->tree.radiusSearch(query.data(), radius_m * radius_m, found, params);
}

std::vector<std::size_t> NearestNeighbors::within(const Point2 &query, double radius_m) const {
  std::vector<std::size_t> indices;
  if (!index_) return indices;
  std::vector<std::pair<std::size_t, double>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  index_->tree.radiusSearch(query.data(), radius_m * radius_m, found, params);
  indices.reserve(found.size());
  for (const auto &neighbor : found) indices.push_back(neighbor.first);
  return indices;
}

const Point2 &NearestNeighbors::normal(std::size_t index) const {
  if (normal_known_.empty()) {
    normals_.assign(points_.size(), Point2::Zero());
    normal_known_.assign(points_.size(), false);
  }
  if (normal_known_[index]) return normals_[index];
  normal_known_[index] = true;
  std::vector<std::pair<std::size_t, double>> found;
  nanoflann::SearchParams params;
  params.sorted = false;
  index_->tree.radiusSearch(points_[index].data(), kNormalRadiusM * kNormalRadiusM, found, params);
  if (found.size() < 3) return normals_[index];
  // Weighted by each point's inverse variance: a map point seen 30 times is a mean of 30
  // observations, one seen 3 times (a skirting board's top taken now and then for the
  // wall's base, 0.1 m behind it) is not, and would otherwise turn the wall's normals
  // beside it by degrees, by tens where the wall has few points yet.
  auto weight = [this](std::size_t i) { return weights_.empty() ? 1.0 : weights_[i]; };
  Point2 mean = Point2::Zero();
  double total = 0.0;
  for (const auto &neighbor : found) {
    mean += weight(neighbor.first) * points_[neighbor.first];
    total += weight(neighbor.first);
  }
  mean /= total;
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto &neighbor : found) {
    const Point2 d = points_[neighbor.first] - mean;
    scatter += weight(neighbor.first) * d * d.transpose();
  }
  // Eigenvalues ascending: the first eigenvector is across the local line.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
  normals_[index] = solver.eigenvectors().col(0).normalized();
  return normals_[index];
}

}  // namespace omnislam::slam
