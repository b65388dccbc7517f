#include "omnislam/slam/evaluation.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace

TrajectoryError trajectory_error(const std::vector<Eigen::Isometry2d> &estimate,
                                 const std::vector<Eigen::Isometry2d> &truth) {
  if (estimate.size() != truth.size()) {
    throw std::invalid_argument("trajectory_error: " + std::to_string(estimate.size()) +
                                " estimated poses but " + std::to_string(truth.size()) + " true ones");
  }
  TrajectoryError error;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const double e = (estimate[i].translation() - truth[i].translation()).norm();
    error.per_frame_m.push_back(e);
    sum_sq += e * e;
    if (e > error.max_m) {
      error.max_m = e;
      error.max_frame = static_cast<int>(i);
    }
  }
  if (!truth.empty()) {
    error.rmse_m = std::sqrt(sum_sq / static_cast<double>(truth.size()));
    error.final_m = error.per_frame_m.back();
  }
  return error;
}

double distance_to_segment(const Point2 &p, const Segment2 &segment) {
  const Point2 d = segment.b - segment.a;
  const double length_sq = d.squaredNorm();
  const double t = length_sq > 0.0 ? std::clamp((p - segment.a).dot(d) / length_sq, 0.0, 1.0) : 0.0;
  return (segment.a + t * d - p).norm();
}

MapError map_error(const Points2 &map_points, const std::vector<Segment2> &floorplan,
                   double completeness_radius_m) {
  MapError error;
  error.points = map_points.size();
  std::vector<double> distances;
  distances.reserve(map_points.size());
  for (const Point2 &p : map_points) {
    double best = std::numeric_limits<double>::infinity();
    for (const Segment2 &segment : floorplan) best = std::min(best, distance_to_segment(p, segment));
    distances.push_back(best);
  }
  error.median_distance_m = quantile(distances, 0.5);
  error.p90_distance_m = quantile(distances, 0.9);

  const NearestNeighbors index(map_points);
  constexpr double kStepM = 0.01;
  double total = 0.0, covered = 0.0;
  for (const Segment2 &segment : floorplan) {
    const double length = (segment.b - segment.a).norm();
    const int samples = std::max(1, static_cast<int>(std::ceil(length / kStepM)));
    for (int i = 0; i < samples; ++i) {
      const Point2 p = segment.a + (segment.b - segment.a) * ((i + 0.5) / samples);
      total += length / samples;
      if (index.nearest(p, completeness_radius_m)) covered += length / samples;
    }
  }
  error.completeness = total > 0.0 ? covered / total : 0.0;
  return error;
}

CovarianceConsistency covariance_consistency(const std::vector<Eigen::Isometry2d> &estimate,
                                             const std::vector<Eigen::Isometry2d> &truth,
                                             const std::vector<Eigen::Matrix3d> &covariances) {
  if (estimate.size() != truth.size() || estimate.size() != covariances.size())
    throw std::invalid_argument("covariance_consistency: sequences of different lengths");
  constexpr double kChiSquare95TwoDof = 5.991;
  CovarianceConsistency result;
  double nees_sum = 0.0;
  int inside = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const Eigen::Matrix3d &P = covariances[i];
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(P);
    if (!lu.isInvertible() || !P.allFinite()) continue;
    const Eigen::Vector2d dp = estimate[i].translation() - truth[i].translation();
    const double dyaw =
        std::remainder(yaw_rad_of(estimate[i]) - yaw_rad_of(truth[i]), 2.0 * std::numbers::pi);
    const Eigen::Vector3d e(dp.x(), dp.y(), dyaw);
    nees_sum += e.dot(lu.solve(e));
    const Eigen::Matrix2d P_xy = P.topLeftCorner<2, 2>();
    if (dp.dot(P_xy.ldlt().solve(dp)) <= kChiSquare95TwoDof) ++inside;
    ++result.frames;
  }
  if (result.frames > 0) {
    result.mean_nees = nees_sum / result.frames;
    result.inside_95_share = static_cast<double>(inside) / result.frames;
  }
  return result;
}

}  // namespace omnislam::slam
