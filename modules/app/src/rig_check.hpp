#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "omnislam/mirror/mirror_config.hpp"

namespace omnislam::app {

/// A rig whose mirror rim is this far from the configured centre has been knocked (or was
/// never calibrated): range errors of 10-50 mm at 1-4 m per 0.5 px (docs/calibration.md).
inline constexpr double kRigCheckTolerancePx = 0.5;

struct RigCheck {
  bool measured = false;  ///< false when the image shows no rim (the reason is in `message`)
  bool off = false;       ///< measured and more than kRigCheckTolerancePx off
  std::string message;    ///< one line for the journal (and the status when off)
};

/// omnislamd's start-up check: the rim method (calib/rim.hpp) on one live image against
/// the configured centre.
[[nodiscard]] RigCheck check_rig(const cv::Mat &image, const mirror::MirrorConfig &camera);

}  // namespace omnislam::app
