#pragma once

#include <opencv2/core.hpp>

#include "omnislam/degrade/degradation_config.hpp"

// The parts of the degradation that are the same in every frame (private to degrade/).

namespace omnislam::degrade::detail {

/// Vignetting gain 1 - rim_falloff * (r / rim_radius_px)^2 (clamped at 0) of each pixel,
/// r about the config's centre; CV_32FC1 of `size`.
[[nodiscard]] cv::Mat vignetting_gain(const DegradationConfig &config, cv::Size size);

/// Transmission of the dust specks (1 = clean), CV_32FC1 of `size`; depends on the seed.
[[nodiscard]] cv::Mat dust_transmission(const DegradationConfig &config, cv::Size size);

/// Normalised pillbox kernel of `radius_px` (each weight the share of its pixel inside
/// the disk), CV_32FC1, odd size; empty for a radius <= 0.
[[nodiscard]] cv::Mat disk_kernel(double radius_px);

}  // namespace omnislam::degrade::detail
