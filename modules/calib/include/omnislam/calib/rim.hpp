#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "omnislam/calib/circle_fit.hpp"
#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// The image centre of a rig from its own images, no target (issue 12, "rim method"): the
/// mirror's outer rim (bright mirror, dark housing beyond) and the dark disc at the centre
/// (the camera seen in the inner lobe) are circles about the mirror's axis. Each is found
/// as the strongest step of the expected polarity on radial intensity profiles around the
/// expected radius, located to a fraction of a pixel, and fitted with a robust circle;
/// profiles where the scene offers no step (a dark object at the rim) fall out of the fit.

namespace omnislam::calib {

struct RimConfig {
  int rays = 720;           ///< radial profiles around the image
  double search_px = 24.0;  ///< each profile spans the expected radius +- this (focal, offset)
  /// A step counts only if its dark side is at most this share of its bright side: the
  /// housing beyond the rim and the camera at the centre are dark whatever the room shows.
  double max_dark_share = 0.5;
  /// A circle needs edges on at least this share of the rays (a rim mostly out of the
  /// image or hidden is no measurement).
  double min_ray_share = 0.25;
};

/// One image's estimate.
struct RimEstimate {
  std::optional<CircleFit> rim;                         ///< outer rim of the mirror
  std::optional<CircleFit> central;                     ///< dark central disc
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  ///< inverse-variance mean of the two
  Eigen::Vector2d centre_sigma_px = Eigen::Vector2d::Zero();
  std::string error;  ///< empty when a centre was found

  [[nodiscard]] bool ok() const { return error.empty(); }
};

/// Where the rig described by `camera` shows the two circles: the images (seen directly)
/// of the mirror's rim and of the inner lobe's central opening, each fitted with a circle.
/// Both centres are the configured centre for a designed rig; a tilted or offset mirror
/// moves them apart (e.g. 0.8 deg and 0.7 mm: by ~12 and ~14 px).
struct RimPrediction {
  Eigen::Vector2d rim_centre_px = Eigen::Vector2d::Zero();
  double rim_radius_px = 0.0;
  Eigen::Vector2d central_centre_px = Eigen::Vector2d::Zero();
  double central_radius_px = 0.0;
};
[[nodiscard]] RimPrediction predict_rim(const mirror::MirrorConfig &camera);

/// Finds both circles in an 8-bit grey image of the rig described by `camera` (the search
/// starts at their predicted places). The centre estimated is the optical axis: the
/// configured centre moved by the (inverse-variance mean) offset of the circles found from
/// where the configured rig puts them (for a designed rig, simply their mean centre).
[[nodiscard]] RimEstimate find_rim(const cv::Mat &image, const mirror::MirrorConfig &camera,
                                   const RimConfig &config = {});

}  // namespace omnislam::calib
