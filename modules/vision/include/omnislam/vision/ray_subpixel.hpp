#pragma once

#include <opencv2/core.hpp>

#include "omnislam/vision/edge_detector.hpp"
#include "omnislam/vision/edge_selection.hpp"

/// @file
/// The sub-pixel row of an edge measured along the mirror's rays. Every panorama column is
/// one ray (one azimuth), and the range of a floor contact follows from where the edge
/// crosses that ray. Canny's gradient (edge_detector.hpp), from which EdgePoint::row_subpx
/// is refined, is smoothed across columns too: on a steep edge (a wall seen obliquely
/// crosses 2-3 rows per column) it mixes neighbouring rays whose edges lie rows apart,
/// weighted by their contrast, so where the contrast changes along the edge (soft light
/// falling off along a wall) the row is pulled toward the brighter neighbour. Measured on
/// the planked L-room: floor contacts at 1-1.5 m read 0.29 px (0.4%) short, and a straight
/// wall seen from the robot bends toward it by 9 mm at 1.1 m and 19 mm at 1.4 m to either
/// side; as the robot drives along it, each scan meets the map's differently bent copy and
/// turns it by ~0.15 deg per frame.

namespace omnislam::vision {

/// The row (panorama units) where `edge`, found in `column`, crosses that column's ray:
/// the vertex of a parabola through the gradient of `texture` (the panorama as float)
/// smoothed along the column only (a Gaussian of `sigma_px`), at the strongest of the
/// edge's row - 1 .. row + 1 with its polarity; followed along the edge (its direction
/// from Canny's gradient) into the columns on either side, and the mean of the three when
/// both show it (the middle column's row on a straight edge, a third of the variance).
/// Returns edge.row_subpx when sigma_px <= 0 or the column shows no such peak.
[[nodiscard]] float ray_subpixel_row(const cv::Mat &texture, const EdgeImage &edges, const EdgePoint &edge,
                                     int column, double sigma_px);

}  // namespace omnislam::vision
