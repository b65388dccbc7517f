#pragma once

#include <vector>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// Disparity search limits derived from the mirror model (replaces the thesis's fixed
/// DisparidadeMinima/Maxima = 10..90 px, which suit its camera height, not ours).
///
/// Why per inner row: the DP walks an inner/outer column pair, and an inner row fixes the
/// inner ray. Along that ray the only points that can exist lie between the near range
/// and the far range *and above the floor*; their outer rows give the only disparities a
/// true match can have. With the camera 1 m up, floor contacts from 0.6 to 4 m span just
/// ~9-13 px, and a given inner row spans an even narrower interval, so a band per row
/// rejects most wrong pairings outright. Disparity is d = outer_row - inner_row (mirror.md).

namespace omnislam::stereo {

struct DisparityBand {
  float min_px = 0.0f;
  float max_px = -1.0f;  ///< max < min: nothing on this inner row can be matched
  [[nodiscard]] bool contains(float disparity_px) const {
    return disparity_px >= min_px && disparity_px <= max_px;
  }
};

struct DisparityLimits {
  std::vector<DisparityBand> per_inner_row;  ///< indexed by integer inner row
  float min_px = 0.0f;                       ///< the union over all rows (for reports, SGBM)
  float max_px = 0.0f;
};

/// Band of every inner row for points with horizontal range in [min_range_m, max_range_m]
/// and height at least -camera_height_m relative to the pinhole, visible in both lobes,
/// widened by margin_px on both sides.
[[nodiscard]] DisparityLimits derive_disparity_limits(const mirror::MirrorModel &model,
                                                      double camera_height_m, double min_range_m,
                                                      double max_range_m, double margin_px);

}  // namespace omnislam::stereo
