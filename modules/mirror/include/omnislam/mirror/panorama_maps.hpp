#pragma once

#include <vector>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// Polar -> panorama sampling maps (thesis sec. 4: the "Jacobian" table computed once).
/// For each panorama pixel (row, column) the maps hold the image position (u, v) in pixels
/// to sample, in the layout cv::remap expects (row-major float32 maps).

namespace omnislam::mirror {

struct PanoramaMap {
  int rows = 0;
  int columns = 0;
  std::vector<float> u_px;  ///< rows * columns, row-major
  std::vector<float> v_px;
};

/// Panorama column `column` covers azimuth [column, column + 1) * 360/columns degrees
/// (plus the configured offset) and samples its centre; row `row` samples the radius
/// model.radius_px_of_row(lobe, row). Image convention (architecture.md): a point at robot
/// azimuth phi is at image angle atan2(v - cv, u - cu) = phi.
/// For a misaligned rig (config.rig not nominal) the pixel (row, column) still stands for
/// the designed ray of that row and column: it samples the image position at which the
/// real rig (RigModel) sees the point where that ray meets the reference surface
/// (config.reference_depth_mm below the pinhole: the floor). Rows whose position the lobe
/// does not cover (RigModel::sees_lobe with 0.25 px to spare: near the split and the rim,
/// where a moved mirror shows the other lobe or the housing) repeat the position of the
/// column's nearest covered row, so the lobe's border puts no edge in the panorama.
[[nodiscard]] PanoramaMap make_panorama_map(const MirrorModel &model, Lobe lobe);

/// Azimuth (rad) sampled by a panorama column, including the configured offset.
[[nodiscard]] double column_azimuth_rad(const MirrorConfig &config, double column);

}  // namespace omnislam::mirror
