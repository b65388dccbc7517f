#pragma once

#include <Eigen/Core>
#include <limits>
#include <span>
#include <string>

/// @file
/// The rig's tilt off level from the floor it sees, no target (`omnislam calibrate level`).
/// Where a wall stands on the floor both lobes see its base: the two rays meet on the floor,
/// wherever the rig points, so stereo places those floor contacts on the floor plane as the
/// rig sees it. The floor-plane range (the front-end's default) instead assumes the floor
/// square to the configured level frame; a rig turned off level makes the two disagree by
/// a tilt of the plane. A plane fitted to the stereo floor contacts of a few frames,
/// z = z0 + a x + b y in the configured level frame (pinhole at the origin), gives that
/// tilt (a, b) and the floor's depth z0 below the pinhole. Stereo itself hardly depends on
/// the level (0.1 deg moves a stereo range by ~2 mm at 1-4 m against 3-24 mm for the floor
/// plane: calibrate sensitivity), so the plane is the floor's.
///
/// Robust to what is not floor among the contacts (a skirting board's top taken for a
/// wall's base, a box's edge): Tukey's biweight (c = 4.685 scales: 95% efficiency under
/// Gaussian errors) on the residuals scaled by their MAD. Its covariance is cluster-robust
/// with the frames as clusters: one frame's contacts share its errors (one wall's placement,
/// one exposure), frames are independent, so the uncertainty is what the frames' scatter
/// says, not what a thousand independent points would.

namespace omnislam::calib {

/// A stereo floor contact: the point in the configured level frame (metres, pinhole at the
/// origin, z up) and the frame (image) it was seen in.
struct FloorContact {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  int frame = 0;
};

struct LevelFitConfig {
  double tukey_c = 4.685;  ///< biweight constant in robust scales (95% Gaussian efficiency)
  int max_iterations = 30;
  int min_frames = 3;     ///< the covariance's clusters need a few
  int min_contacts = 30;  ///< over all frames
};

struct LevelFitResult {
  bool ok = false;
  std::string message;  ///< why not
  /// The rotation from the configured level frame to the floor's (RigConfig's convention:
  /// about x, then y, right-handed; rad): what the configured level tilt is off by.
  double tilt_x_rad = 0.0;
  double tilt_y_rad = 0.0;
  double floor_z_m = std::numeric_limits<double>::quiet_NaN();  ///< floor below the pinhole (negative)
  /// Covariance of (floor_z_m, tilt_x_rad, tilt_y_rad), cluster-robust over the frames.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double residual_scale_m = 0.0;  ///< robust scale (1.4826 MAD) of the contacts' heights about the plane
  int contacts = 0;
  int inliers = 0;  ///< contacts with a non-zero weight at the end
  int frames = 0;
};

/// Fits the floor plane to `contacts`; reports (ok false, message) when there are too few
/// contacts or frames, never throws.
[[nodiscard]] LevelFitResult fit_level(std::span<const FloorContact> contacts,
                                       const LevelFitConfig &config = {});

/// The rig's level tilt after `residual` (a LevelFitResult's tilt, found in the frame of
/// `configured`): the two rotations composed, as RigConfig's (x, y) pair.
[[nodiscard]] Eigen::Vector2d compose_level_tilt(const Eigen::Vector2d &configured_rad,
                                                 const Eigen::Vector2d &residual_rad);

}  // namespace omnislam::calib
