#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "omnislam/mirror/rig_model.hpp"

/// @file
/// Least-squares fit of a rig's parameters (image centre, focal scale, mirror distance, tilt
/// and offset; mirror_config.hpp RigConfig) to observed pixels of points at known positions
/// in the camera frame (issue 12, the core of the target method): Ceres, Levenberg-Marquardt
/// on the reprojection error in pixels, with each parameter's standard deviation from the
/// covariance at the solution scaled by the residual variance.

namespace omnislam::calib {

/// One observation: `lobe` sees the point `point_m` (camera frame, metres) at `pixel`.
struct RigObservation {
  mirror::Lobe lobe = mirror::Lobe::kInner;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  mirror::Pixel pixel;
};

struct RigFitConfig {
  int max_iterations = 100;
};

/// The fitted parameters in the order of RigFitResult::sigma.
enum RigParameter {
  kCenterU,
  kCenterV,
  kFocalScale,
  kMirrorDz,
  kTiltX,
  kTiltY,
  kOffsetX,
  kOffsetY,
  kRigParameters
};

/// The target fit's parameters (target_fit.hpp): the rig's, then the whole rig's level tilt
/// (RigConfig::level_tilt_*, rad), which boards lying on the floor fix (their plane's
/// normal in the camera frame). Known points in the camera frame (fit_rig) say nothing of it.
enum TargetParameter { kLevelX = kRigParameters, kLevelY, kTargetParameters };

struct RigFitResult {
  bool converged = false;
  int iterations = 0;
  int observations = 0;
  double rms_px = 0.0;                         ///< reprojection error at the solution
  mirror::MirrorConfig camera;                 ///< the initial config with the fitted values
  std::array<double, kRigParameters> sigma{};  ///< px, px, 1, mm, rad, rad, mm, mm (NaN: not estimable)
  std::string message;                         ///< why it did not converge, or Ceres's summary line
};

/// Fits from `initial` (the designed rig is a good start: the misalignments are small).
/// Needs at least kRigParameters + 1 observations in each lobe; reports, never throws.
[[nodiscard]] RigFitResult fit_rig(const mirror::MirrorConfig &initial,
                                   const std::vector<RigObservation> &observations,
                                   const RigFitConfig &config = {});

}  // namespace omnislam::calib
