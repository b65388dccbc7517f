#include "rig_check.hpp"

#include <cstdio>

#include "omnislam/calib/rim.hpp"

namespace omnislam::app {

RigCheck check_rig(const cv::Mat &image, const mirror::MirrorConfig &camera) {
  RigCheck check;
  const calib::RimEstimate estimate = calib::find_rim(image, camera);
  if (!estimate.ok()) {
    check.message = "rig check: no centre measured in the first image (" + estimate.error + ")";
    return check;
  }
  check.measured = true;
  const Eigen::Vector2d configured(camera.center_u_px, camera.center_v_px);
  const double off_px = (estimate.centre_px - configured).norm();
  check.off = off_px > kRigCheckTolerancePx;
  char text[320];
  std::snprintf(text, sizeof text,
                "rig check: mirror centre in the first image (%.2f, %.2f) px, %.2f px from the configured "
                "(%.2f, %.2f)%s",
                estimate.centre_px.x(), estimate.centre_px.y(), off_px, configured.x(), configured.y(),
                check.off
                    ? ": more than 0.5 px, the rig was knocked or never calibrated; run `omnislam calibrate "
                      "rim` on a few images and set camera.center_px"
                    : "");
  check.message = text;
  return check;
}

}  // namespace omnislam::app
