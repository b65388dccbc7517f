#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>

/// @file
/// One chessboard corner located in the raw image by fitting the image of a corner to the
/// pixels round it (target_detect.cpp refines the detector's corners with it).
///
/// Near a corner the board's two edges are straight lines crossing at the corner, and the
/// image is the board's black and white seen through a blur: I(q) = m + k erf(d1(q) / (sqrt(2)
/// sigma)) erf(d2(q) / (sqrt(2) sigma)), d1 and d2 the signed distances of pixel q from the
/// two edge lines. The corner (2), the lines' directions (2), m, k and sigma are fitted
/// (Ceres, least squares on the raw grey levels) over the corner's own quarter squares: the
/// pixels within `window` of a square's side of it along both board axes, short of the next
/// corners' edges at one square. Fitting the raw pixels leaves out the resampled panorama
/// the detector works on; the detector's corners carried systematic errors of a few
/// hundredths of a pixel per image, which no number of corners averages away (measured on
/// datasets/calib-target-rig: the target fit's focal error 0.17% -> 0.035%, mirror distance
/// 0.33% -> 0.08%, tilt 0.034 -> 0.011 deg).

namespace omnislam::calib::detail {

struct CornerRefineConfig {
  /// Half width of the fitted window along each board axis, in squares (the next corners'
  /// edges are one square away; 0.5 would reach halfway to them).
  double window = 0.45;
  int min_pixels = 12;  ///< fewer pixels in the window: no fit (a square a few pixels wide)
  int max_iterations = 50;
};

/// The corner near `corner_px` (u, v) in the 8-bit grey `image`. `axes_px` holds, as
/// columns, one square's step along the board's x and y axes in the image at the corner
/// (from the neighbouring corners). nullopt when the window leaves the image, holds too few
/// pixels, shows no contrast, the fit fails, or the fitted corner moved out of its own
/// quarter of the window (not the corner it started from).
[[nodiscard]] std::optional<Eigen::Vector2d> refine_corner(const cv::Mat &image,
                                                           const Eigen::Vector2d &corner_px,
                                                           const Eigen::Matrix2d &axes_px,
                                                           const CornerRefineConfig &config = {});

}  // namespace omnislam::calib::detail
