#pragma once

#include <optional>
#include <span>

#include <Eigen/Core>

/// @file
/// A circle through sub-pixel edge points: algebraic start (Kasa), then the geometric
/// least-squares fit, with points farther off than three robust residual scales left out
/// (a dark object reflected at the rim makes no edge there, and the strongest step of its
/// profile is somewhere else).

namespace omnislam::calib {

struct CircleFit {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  ///< (u, v)
  double radius_px = 0.0;
  double rms_px = 0.0;                                        ///< geometric residual of the inliers
  Eigen::Vector2d centre_sigma_px = Eigen::Vector2d::Zero();  ///< 1-sigma of the centre (from the fit)
  int points = 0;                                             ///< points given
  int inliers = 0;                                            ///< points the final fit used
};

/// Fits a circle to `points` (at least 3, not collinear); std::nullopt otherwise.
[[nodiscard]] std::optional<CircleFit> fit_circle(std::span<const Eigen::Vector2d> points);

}  // namespace omnislam::calib
