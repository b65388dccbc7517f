#pragma once

#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "omnislam/stereo/disparity_limits.hpp"
#include "omnislam/stereo/stereo_config.hpp"
#include "omnislam/vision/edge_selection.hpp"

/// @file
/// Dynamic-programming matching of the edge points of one inner/outer column pair, in the
/// spirit of Fielding & Kam (2000) as the thesis uses it (sec. 3 step 5): the two ordered
/// candidate lists are aligned so that every point is either matched once (uniqueness) or
/// left occluded at a fixed cost, matches keep the order of both lists (monotonic
/// ordering), and a pair is admissible only when its disparity lies in the inner row's
/// band. The alignment minimising SAD of the matches + occlusion_cost per unmatched point
/// is exact (an O(n m) edit-distance recursion; n, m are a handful per column).

namespace omnislam::stereo {

/// A matched pair of rows in one column (fractional after sub-pixel refinement).
struct RowMatch {
  int column = 0;
  float inner_row = 0.0f;
  float outer_row = 0.0f;
  float cost = 0.0f;  ///< SAD of the pair, intensity in [0, 1] summed over the window
};

struct MatchStats {
  int admissible_pairs = 0;  ///< pairs inside the disparity band (cost evaluated)
  int matched = 0;
  int occluded_inner = 0;
  int occluded_outer = 0;
};

/// The largest candidate list per column the matcher accepts; longer lists are truncated
/// to their first (nearest) entries.
inline constexpr int kMaxCandidatesPerColumn = 16;

/// SAD between the (2 half_rows + 1) x (2 half_columns + 1) windows centred at
/// (inner_row, column) of `inner` and (outer_row, column) of `outer` (CV_32FC1 textures);
/// columns wrap around, rows must fit.
[[nodiscard]] float window_sad(const cv::Mat &inner, int inner_row, const cv::Mat &outer, int outer_row,
                               int column, int half_rows, int half_columns);

/// Matches one column and appends the matches to `out` (in bottom-up order).
void match_column(std::span<const vision::EdgePoint> inner_points,
                  std::span<const vision::EdgePoint> outer_points, int column, const cv::Mat &inner_texture,
                  const cv::Mat &outer_texture, const DisparityLimits &limits,
                  const vision::EdgeSelectionConfig &window, const StereoConfig &config,
                  std::vector<RowMatch> &out, MatchStats &stats);

}  // namespace omnislam::stereo
