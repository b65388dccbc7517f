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
[[nodiscard]] PanoramaMap make_panorama_map(const MirrorModel &model, Lobe lobe);

/// Azimuth (rad) sampled by a panorama column, including the configured offset.
[[nodiscard]] double column_azimuth_rad(const MirrorConfig &config, double column);

}  // namespace omnislam::mirror
