#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "omnislam/calib/rig_fit.hpp"
#include "omnislam/calib/rim.hpp"
#include "omnislam/mirror/rig_model.hpp"

/// @file
/// The target method of issue 12: a printed checkerboard held around the robot, its pose in
/// each image unknown. Every parameter of the rig (RigParameter) and every board pose are
/// fitted together (bundle adjustment, Ceres Levenberg-Marquardt) to the corners' pixels in
/// both lobes. A board's known square size fixes the scale; seeing it in both lobes ties the
/// lobes' geometry together.
///
/// The image centre needs the floor. Moving the centre by du px acts, to first order, like
/// turning the camera about its pinhole by du / focal_px, i.e. like turning the mirror and
/// the world together the other way: a tilt plus an offset of the mirror, and every board
/// pose turned. Boards of unknown pose cannot tell the two apart, nor can the rim circles
/// (seen directly through the same camera, they turn with the mirror); only the pinhole
/// camera's perspective (second order, (512 / 3561)^2 = 2% at the rim) separates them, and
/// weakly (measured: centre sigma ~5 px from 12 held boards and the rim). Boards on the floor
/// (TargetView::on_floor) lie on one plane, level in the level frame: its normal in the
/// camera frame is the rig's level tilt (RigConfig::level_tilt_*). Held at the configured
/// tilt, they fix the rotation and with it the centre (sigma ~1 px); fitted, the tilt takes
/// the rotation's place (sigma ~0.07 deg, the centre's ~5 px again) and the floor ranges,
/// which depend on the two together, stay as well determined. The fit keeps the tilt where
/// the boards show one (Akaike's criterion), else holds the configured one.
/// The rim circles (rim.hpp), when given, enter the same problem as residuals in units of
/// their standard deviation; they constrain the mirror's tilt and offset a little more.

namespace omnislam::calib {

/// A chessboard of `squares_x` by `squares_y` squares of `square_m`; its inner corners are
/// the points (corners_x() by corners_y() of them), numbered row by row: index = y *
/// corners_x() + x at (x, y, 0) * square_m in the board's frame.
struct TargetGeometry {
  int squares_x = 8;
  int squares_y = 6;
  double square_m = 0.045;

  [[nodiscard]] int corners_x() const { return squares_x - 1; }
  [[nodiscard]] int corners_y() const { return squares_y - 1; }
  [[nodiscard]] int corners() const { return corners_x() * corners_y(); }
  [[nodiscard]] Eigen::Vector3d corner_m(int index) const;
};

/// One corner of the board found in one lobe of an image.
struct TargetCorner {
  int index = 0;  ///< TargetGeometry numbering
  mirror::Lobe lobe = mirror::Lobe::kInner;
  mirror::Pixel pixel;
};

/// What one image shows of the board (one pose).
struct TargetView {
  std::vector<TargetCorner> corners;
  /// The board lies on the floor: its normal is the level frame's axis (the robot stands on
  /// a flat floor; the rig's level tilt turns it into the camera frame) and all boards on
  /// the floor share its height and tilt (see the file's note).
  bool on_floor = false;
};

/// The rim method's circles (either may be missing), as RimEstimate has them: one
/// measurement for the rig (e.g. the mean over the images), not one per image, since their
/// errors come mostly from the rig's edges and repeat from image to image.
struct RimCircles {
  std::optional<CircleFit> rim;
  std::optional<CircleFit> central;
};

struct TargetFitConfig {
  int max_iterations = 100;
  /// Floor of a rim circle centre's standard deviation (px): the circle fit's own sigma
  /// is a few hundredths of a pixel and leaves out what the edge's profile does (measured
  /// on renders: the fitted centres sit within 0.05 px of the predicted ones, rim.hpp).
  double min_rim_sigma_px = 0.05;
  /// Corners farther than this from their projection after the first fit are dropped and
  /// the fit repeated (a corner detected on the wrong square).
  double outlier_px = 2.0;
  /// A view needs at least this many corners in the inner lobe (its pose starts from them).
  int min_corners = 6;
  /// When set (the configured camera height, m), a view not flagged on_floor counts as on
  /// the floor if its starting pose lies level (within `floor_level_deg`) and within
  /// `floor_tolerance_m` of the floor: the user need not say which images those are.
  double floor_height_m = std::numeric_limits<double>::quiet_NaN();
  double floor_level_deg = 10.0;
  double floor_tolerance_m = 0.15;
  /// Fit the rig's level tilt (the floor's normal in the camera frame, from the boards on
  /// it) when the boards show one (Akaike's criterion against the initial config's tilt,
  /// TargetFitResult::level_chi2); when false, the initial config's tilt is held (e.g. from
  /// an inclinometer).
  bool fit_level = true;
};

struct TargetFitResult {
  bool converged = false;
  int iterations = 0;
  int views_used = 0;
  std::vector<int> rejected_views;  ///< indices into the views given, with `view_errors`
  std::vector<std::string> view_errors;
  int corners = 0;              ///< corner observations used
  int outliers = 0;             ///< corner observations dropped (TargetFitConfig::outlier_px)
  double rms_px = 0.0;          ///< corners' reprojection error
  double rim_rms_sigma = 0.0;   ///< rim circle centres' residuals in their sigmas (NaN: none)
  mirror::MirrorConfig camera;  ///< the initial config with the fitted values
  double camera_height_m =
      std::numeric_limits<double>::quiet_NaN();  ///< pinhole above the floor (boards on it)
  double camera_height_sigma_m = std::numeric_limits<double>::quiet_NaN();
  /// The level tilt was fitted (false: held at the initial config's, by request or because
  /// the boards did not show it); `level_chi2` is what fitting it took off the chi-square
  /// (kept when above 4, 2 per parameter; NaN when not tried).
  bool level_fitted = false;
  double level_chi2 = std::numeric_limits<double>::quiet_NaN();
  /// As RigFitResult::sigma, then the level tilt's (rad; 0 when held, NaN when no board lay
  /// on the floor).
  std::array<double, kTargetParameters> sigma{};
  std::vector<Eigen::Isometry3d> T_camera_board;  ///< per used view (metres)
  std::vector<int> used_views;                    ///< their indices into the views given
  std::vector<bool> on_floor;                     ///< per used view: fitted as lying on the floor
  /// Covariance of the parameters (TargetParameter order: RigParameter, then kLevelX, kLevelY, the units of
  /// `sigma`).
  Eigen::Matrix<double, kTargetParameters, kTargetParameters> covariance =
      Eigen::Matrix<double, kTargetParameters, kTargetParameters>::Constant(
          std::numeric_limits<double>::quiet_NaN());
  std::string message;
};

/// Fits the rig from `initial` (the design is a good start) to `views` of `target` and the
/// rim circles of the same rig (`rim` may hold neither: then the centre rests on the board
/// alone and is weak). Each view's pose starts from its corners triangulated with the
/// initial rig. Needs two usable views; reports, never throws.
[[nodiscard]] TargetFitResult fit_target(const mirror::MirrorConfig &initial, const TargetGeometry &target,
                                         const std::vector<TargetView> &views, const RimCircles &rim,
                                         const TargetFitConfig &config = {});

}  // namespace omnislam::calib
