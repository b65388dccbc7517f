#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "omnislam/calib/rig_fit.hpp"
#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// What an error in a rig parameter costs in range: a wall's base on the floor at 1, 2 and
/// 4 m is imaged by the rig as it is (the parameter off by one step) and read back with the
/// parameters as configured, by the floor plane (the default front-end's range) and by
/// stereo triangulation of the two lobes.

namespace omnislam::calib {

inline constexpr std::array<double, 3> kSensitivityRangesM{1.0, 2.0, 4.0};

struct RangeSensitivity {
  std::string parameter;                  ///< "centre", "focal length", ...
  std::string step;                       ///< the error the row is for, e.g. "1 px", "0.1%"
  std::array<double, 3> floor_plane_m{};  ///< |range error| at kSensitivityRangesM, floor plane
  std::array<double, 3> stereo_m{};       ///< the same, triangulated (NaN where unseen)
};

/// One row per parameter the mirror model represents (the centre, worst azimuth; the focal
/// length; the whole rig turned off level, worst azimuth), for a camera `camera_height_m`
/// above the floor.
[[nodiscard]] std::vector<RangeSensitivity> range_sensitivity(const mirror::MirrorConfig &camera,
                                                              double camera_height_m);

/// The range error (1 sigma) that an uncertain rig implies for a wall's base on the floor
/// at kSensitivityRangesM: `camera` is the rig as fitted, `covariance` its parameters'
/// (RigParameter order and units: px, px, 1, mm, rad, rad, mm, mm; then the level tilt's x
/// and y, rad: zero rows and columns where it was not fitted). The derivative of the
/// range read back with `camera` from where a rig off by each parameter images the point
/// (general rig model) is propagated through the covariance, so correlated errors that
/// cancel in the image cancel here too; RMS over eight azimuths.
struct RangeUncertainty {
  std::array<double, 3> floor_plane_m{};  ///< the inner lobe's ray met with the floor
  std::array<double, 3> stereo_m{};       ///< the two lobes' rays triangulated
};
[[nodiscard]] RangeUncertainty range_uncertainty(
    const mirror::MirrorConfig &camera,
    const Eigen::Matrix<double, kTargetParameters, kTargetParameters> &covariance, double camera_height_m);

}  // namespace omnislam::calib
