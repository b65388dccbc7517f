#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "omnislam/calib/target_fit.hpp"

/// @file
/// Finding a chessboard's inner corners in both lobes of one image (the target method).
///
/// A chessboard detector wants a board that looks like a board: in the raw image each lobe
/// shows it bent round the centre, and the outer lobe squeezes it radially (a board on the
/// floor has squares ~4 px tall there). So each lobe is first unrolled into a panorama with
/// the configured rig (rows: image radius, 3 per pixel; columns: azimuth, 420 degrees so a
/// board across 0 degrees is whole once), where the board is upright, only mildly bent and
/// its squares large enough; cv::findChessboardCornersSB finds it there (first at half
/// resolution, then at full resolution round what it found) with its sub-pixel refinement
/// (CALIB_CB_ACCURACY), and the corners go back to the raw image through the same mapping
/// (exact: the panorama is a pure resampling). Each corner is then fitted in the raw image
/// (corner_refine.hpp: a blurred corner over its own quarter squares), which removes most of
/// the detector's systematic error. Measured on renders (datasets/calib-target-rig, 24
/// images) against the truth: 0.085 px rms in the inner lobe, 0.12 px in the outer (0.09 and
/// 0.15 as detected). cv::cornerSubPix did worse: in the raw image 0.1-1.1 px on the outer lobe's small
/// squares (its window reaches the next corners), in the panorama 0.36 px overall.
/// Both lobes see a point at nearly the same azimuth and in the same vertical order, so the
/// outer lobe's corners are numbered as the inner lobe's (the detector's start corner is
/// arbitrary on a symmetric board).

namespace omnislam::calib {

struct TargetDetectConfig {
  /// Panorama rows per pixel of image radius: the lobes squeeze a board radially.
  double radial_scale = 3.0;
  double inner_azimuth_scale = 2.0;  ///< panorama columns per image pixel across, inner lobe
  double outer_azimuth_scale = 1.0;  ///< and outer lobe (at the annulus's middle)
  /// Each panorama reaches this far past its lobe's designed annulus (image px): a
  /// misaligned rig's lobes sit off the designed circles, and a board at a lobe's edge must
  /// be whole.
  double margin_px = 20.0;
  double wrap_deg = 60.0;  ///< the panorama's columns past 360 degrees
  /// Each corner is then fitted in the raw image over this far (in squares, along both
  /// board axes) round it (corner_refine.hpp); 0 keeps the detector's corners.
  double refine_window_squares = 0.45;
};

/// One image's corners.
struct TargetDetection {
  TargetView view;
  int inner_corners = 0;
  int outer_corners = 0;
  std::string error;  ///< empty when the board was found in at least one lobe

  [[nodiscard]] bool ok() const { return error.empty(); }
};

/// Finds `target` in an 8-bit grey `image` of the rig described by `camera`.
[[nodiscard]] TargetDetection detect_target(const cv::Mat &image, const mirror::MirrorConfig &camera,
                                            const TargetGeometry &target,
                                            const TargetDetectConfig &config = {});

}  // namespace omnislam::calib
