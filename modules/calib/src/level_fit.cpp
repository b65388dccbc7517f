#include "omnislam/calib/level_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "omnislam/mirror/rig_model.hpp"

namespace omnislam::calib {
namespace {

// 1.4826 MAD: the standard deviation of Gaussian residuals from their median absolute value.
constexpr double kMadToSigma = 1.4826;

double median_abs(std::vector<double> values) {
  for (double &v : values) v = std::abs(v);
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

Eigen::Vector3d row_of(const FloorContact &contact) {
  return {1.0, contact.point_m.x(), contact.point_m.y()};
}

// The plane's (z0, slope x, slope y) as (z0, tilt x, tilt y) and the Jacobian between them.
// The floor's normal in the configured frame, turned by Ry(ty) Rx(tx), is (-sin ty,
// sin tx cos ty, cos tx cos ty): z = z0 + a x + b y with b = -tan tx, a = tan ty / cos tx.
Eigen::Vector3d tilt_of(const Eigen::Vector3d &plane, Eigen::Matrix3d &jacobian) {
  const double tx = -std::atan(plane(2));
  const double ca = plane(1) * std::cos(tx);
  const double ty = std::atan(ca);
  jacobian.setZero();
  jacobian(0, 0) = 1.0;
  jacobian(1, 2) = -1.0 / (1.0 + plane(2) * plane(2));
  jacobian(2, 1) = std::cos(tx) / (1.0 + ca * ca);
  jacobian(2, 2) = plane(1) * std::sin(tx) * jacobian(1, 2) * -1.0 / (1.0 + ca * ca);
  return {plane(0), tx, ty};
}

Eigen::Matrix3d level_rotation(const Eigen::Vector2d &tilt_rad) {
  return mirror::tilt_rotation(tilt_rad.x(), tilt_rad.y());
}

}  // namespace

LevelFitResult fit_level(std::span<const FloorContact> contacts, const LevelFitConfig &config) {
  LevelFitResult result;
  result.contacts = static_cast<int>(contacts.size());
  std::map<int, int> cluster_of_frame;
  for (const FloorContact &c : contacts)
    cluster_of_frame.emplace(c.frame, static_cast<int>(cluster_of_frame.size()));
  result.frames = static_cast<int>(cluster_of_frame.size());
  if (result.contacts < config.min_contacts || result.frames < config.min_frames) {
    result.message = std::to_string(result.contacts) + " floor contact(s) in " +
                     std::to_string(result.frames) + " image(s); need " +
                     std::to_string(config.min_contacts) + " in " + std::to_string(config.min_frames);
    return result;
  }
  // Start: least squares on every contact; then the biweight's iteratively reweighted fits.
  const std::size_t n = contacts.size();
  std::vector<double> weight(n, 1.0), residual(n, 0.0);
  Eigen::Vector3d plane = Eigen::Vector3d::Zero();
  double scale = 0.0;
  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d x = row_of(contacts[i]);
      normal += weight[i] * x * x.transpose();
      rhs += weight[i] * x * contacts[i].point_m.z();
    }
    const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
    if (solver.info() != Eigen::Success || !(solver.rcond() > 1e-12)) {
      result.message = "the floor contacts do not span a plane (all on one line?)";
      return result;
    }
    const Eigen::Vector3d next = solver.solve(rhs);
    for (std::size_t i = 0; i < n; ++i) residual[i] = contacts[i].point_m.z() - row_of(contacts[i]).dot(next);
    scale = kMadToSigma * median_abs(residual);
    if (!(scale > 0.0)) {
      result.message = "the floor contacts' heights have no spread (a degenerate input)";
      return result;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double u = residual[i] / (config.tukey_c * scale);
      weight[i] = std::abs(u) < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
    }
    const bool converged = (next - plane).lpNorm<Eigen::Infinity>() < 1e-9;
    plane = next;
    if (converged) break;
  }
  // Huber's sandwich with the frames as clusters: bread sum psi'(r) x x^T, meat the frames'
  // summed scores psi(r) x, with G / (G - 1) for the scores' own fit.
  Eigen::Matrix3d bread = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> score(static_cast<std::size_t>(result.frames), Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    const double u = residual[i] / (config.tukey_c * scale);
    if (!(std::abs(u) < 1.0)) continue;
    ++result.inliers;
    const Eigen::Vector3d x = row_of(contacts[i]);
    bread += (1.0 - u * u) * (1.0 - 5.0 * u * u) * x * x.transpose();
    score[static_cast<std::size_t>(cluster_of_frame.at(contacts[i].frame))] += weight[i] * residual[i] * x;
  }
  Eigen::Matrix3d meat = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d &s : score) meat += s * s.transpose();
  const double g = result.frames;
  meat *= g / (g - 1.0);
  const Eigen::LDLT<Eigen::Matrix3d> bread_solver(bread);
  if (bread_solver.info() != Eigen::Success || !bread_solver.isPositive() ||
      !(bread_solver.rcond() > 1e-12)) {
    result.message = "the fit's covariance is not defined (too few contacts fit the plane)";
    return result;
  }
  const Eigen::Matrix3d bread_inverse = bread_solver.solve(Eigen::Matrix3d::Identity());
  Eigen::Matrix3d jacobian;
  const Eigen::Vector3d tilt = tilt_of(plane, jacobian);
  result.covariance = jacobian * bread_inverse * meat * bread_inverse * jacobian.transpose();
  result.floor_z_m = tilt(0);
  result.tilt_x_rad = tilt(1);
  result.tilt_y_rad = tilt(2);
  result.residual_scale_m = scale;
  result.ok = true;
  return result;
}

Eigen::Vector2d compose_level_tilt(const Eigen::Vector2d &configured_rad,
                                   const Eigen::Vector2d &residual_rad) {
  // camera -> configured level -> the floor's level. The tilt is where the product sends the
  // floor's normal: Ry(b) Rx(a) has the last row (-sin b, cos b sin a, cos b cos a). A turn
  // about the vertical the two compose to (second order) is not a tilt and is left out.
  const Eigen::Matrix3d R = level_rotation(residual_rad) * level_rotation(configured_rad);
  return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2)))};
}

}  // namespace omnislam::calib
