#include "omnislam/calib/circle_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

namespace omnislam::calib {
namespace {

constexpr int kMinPoints = 3;
constexpr int kRejectionRounds = 3;
constexpr int kGaussNewtonIterations = 10;
// Points within this many robust residual scales are inliers; a floor keeps an exact fit
// (every residual ~0) from rejecting points for rounding.
constexpr double kInlierScales = 3.0;
constexpr double kMinScalePx = 0.01;
// Median absolute deviation to the standard deviation of a normal distribution.
constexpr double kMadToSigma = 1.4826;

struct Circle {
  Eigen::Vector2d centre;
  double radius;
};

// Kasa: u^2 + v^2 + a u + b v + c = 0 in least squares; biased on short arcs, good as a start.
std::optional<Circle> algebraic_fit(std::span<const Eigen::Vector2d> points) {
  Eigen::MatrixXd design(points.size(), 3);
  Eigen::VectorXd rhs(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    design.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), 1.0;
    rhs(static_cast<Eigen::Index>(i)) = -points[i].squaredNorm();
  }
  const Eigen::Vector3d abc = design.colPivHouseholderQr().solve(rhs);
  const Eigen::Vector2d centre(-0.5 * abc(0), -0.5 * abc(1));
  const double squared = centre.squaredNorm() - abc(2);
  if (!(squared > 0.0) || !centre.allFinite()) return std::nullopt;
  return Circle{centre, std::sqrt(squared)};
}

// Gauss-Newton on the geometric residuals |p - c| - r of the points flagged in `use`.
// Returns J^T J of the last iteration (for the covariance).
Eigen::Matrix3d geometric_fit(std::span<const Eigen::Vector2d> points, const std::vector<bool> &use,
                              Circle &circle) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  for (int iteration = 0; iteration < kGaussNewtonIterations; ++iteration) {
    normal.setZero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d offset = points[i] - circle.centre;
      const double distance = offset.norm();
      if (distance <= 0.0) continue;
      const Eigen::Vector3d jacobian(-offset.x() / distance, -offset.y() / distance, -1.0);
      const double residual = distance - circle.radius;
      normal += jacobian * jacobian.transpose();
      gradient += jacobian * residual;
    }
    const Eigen::Vector3d step = normal.ldlt().solve(-gradient);
    if (!step.allFinite()) break;
    circle.centre += step.head<2>();
    circle.radius += step(2);
    if (step.norm() < 1e-9) break;
  }
  return normal;
}

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::optional<CircleFit> fit_circle(std::span<const Eigen::Vector2d> points) {
  if (points.size() < static_cast<std::size_t>(kMinPoints)) return std::nullopt;
  std::optional<Circle> start = algebraic_fit(points);
  if (!start) return std::nullopt;
  Circle circle = *start;
  std::vector<bool> use(points.size(), true);
  for (int round = 0; round < kRejectionRounds; ++round) {
    geometric_fit(points, use, circle);
    std::vector<double> residuals;
    residuals.reserve(points.size());
    for (const Eigen::Vector2d &point : points)
      residuals.push_back((point - circle.centre).norm() - circle.radius);
    const double centre_of_residuals = median(residuals);
    std::vector<double> deviations;
    deviations.reserve(residuals.size());
    for (const double residual : residuals) deviations.push_back(std::abs(residual - centre_of_residuals));
    const double scale = std::max(kMinScalePx, kMadToSigma * median(deviations));
    for (std::size_t i = 0; i < points.size(); ++i) use[i] = std::abs(residuals[i]) <= kInlierScales * scale;
  }
  const Eigen::Matrix3d normal = geometric_fit(points, use, circle);
  CircleFit fit;
  fit.centre_px = circle.centre;
  fit.radius_px = circle.radius;
  fit.points = static_cast<int>(points.size());
  double squares = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    const double residual = (points[i] - circle.centre).norm() - circle.radius;
    squares += residual * residual;
    ++fit.inliers;
  }
  if (fit.inliers < kMinPoints || !circle.centre.allFinite() || !(circle.radius > 0.0)) return std::nullopt;
  fit.rms_px = std::sqrt(squares / fit.inliers);
  const double variance = fit.inliers > kMinPoints ? squares / (fit.inliers - kMinPoints) : 0.0;
  const Eigen::Matrix3d covariance = variance * normal.inverse();
  fit.centre_sigma_px =
      Eigen::Vector2d(std::sqrt(std::max(0.0, covariance(0, 0))), std::sqrt(std::max(0.0, covariance(1, 1))));
  return fit;
}

}  // namespace omnislam::calib
