#include "omnislam/stereo/column_matching.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace omnislam::stereo {
namespace {

constexpr int kSize = kMaxCandidatesPerColumn + 1;
constexpr float kInadmissible = std::numeric_limits<float>::infinity();

enum class Step : unsigned char { kMatch, kSkipInner, kSkipOuter };

// Equiangular ("V") fit through SAD costs at -1, 0, +1: SAD is piecewise linear near its
// minimum, so two lines of equal and opposite slope locate it better than a parabola.
float equiangular_offset(float before, float at, float after) {
  const float slope = std::max(before, after) - at;
  if (!(slope > 0.0f)) return 0.0f;
  return std::clamp(0.5f * (before - after) / slope, -0.5f, 0.5f);
}

RowMatch refine(const vision::EdgePoint &inner, const vision::EdgePoint &outer, int column, float cost,
                const cv::Mat &inner_texture, const cv::Mat &outer_texture,
                const vision::EdgeSelectionConfig &window, SubpixelMethod method) {
  RowMatch match{column, static_cast<float>(inner.row), static_cast<float>(outer.row), cost};
  if (method == SubpixelMethod::kEdgePeak) {
    match.inner_row = inner.row_subpx;
    match.outer_row = outer.row_subpx;
  } else if (method == SubpixelMethod::kCostCurve) {
    const int hr = window.half_window_rows, hc = window.half_window_columns;
    const float before = window_sad(inner_texture, inner.row, outer_texture, outer.row - 1, column, hr, hc);
    const float after = window_sad(inner_texture, inner.row, outer_texture, outer.row + 1, column, hr, hc);
    const float disparity =
        static_cast<float>(outer.row - inner.row) + equiangular_offset(before, cost, after);
    match.inner_row = inner.row_subpx;
    match.outer_row = inner.row_subpx + disparity;
  }
  return match;
}

}  // namespace

float window_sad(const cv::Mat &inner, int inner_row, const cv::Mat &outer, int outer_row, int column,
                 int half_rows, int half_columns) {
  float sum = 0.0f;
  for (int dc = -half_columns; dc <= half_columns; ++dc) {
    const int col = (column + dc + inner.cols) % inner.cols;
    for (int dr = -half_rows; dr <= half_rows; ++dr) {
      sum += std::abs(inner.at<float>(inner_row + dr, col) - outer.at<float>(outer_row + dr, col));
    }
  }
  return sum;
}

void match_column(std::span<const vision::EdgePoint> inner_points,
                  std::span<const vision::EdgePoint> outer_points, int column, const cv::Mat &inner_texture,
                  const cv::Mat &outer_texture, const DisparityLimits &limits,
                  const vision::EdgeSelectionConfig &window, const StereoConfig &config,
                  std::vector<RowMatch> &out, MatchStats &stats) {
  const int n = std::min<int>(static_cast<int>(inner_points.size()), kMaxCandidatesPerColumn);
  const int m = std::min<int>(static_cast<int>(outer_points.size()), kMaxCandidatesPerColumn);
  if (n == 0 || m == 0) {
    stats.occluded_inner += n;
    stats.occluded_outer += m;
    return;
  }
  std::array<float, kSize * kSize> pair_cost;
  for (int i = 0; i < n; ++i) {
    const vision::EdgePoint &inner = inner_points[static_cast<std::size_t>(i)];
    const DisparityBand &band = limits.per_inner_row[static_cast<std::size_t>(inner.row)];
    for (int j = 0; j < m; ++j) {
      const vision::EdgePoint &outer = outer_points[static_cast<std::size_t>(j)];
      float &cost = pair_cost[static_cast<std::size_t>(i * kSize + j)];
      cost = kInadmissible;
      if (!band.contains(static_cast<float>(outer.row - inner.row))) continue;
      ++stats.admissible_pairs;
      cost = window_sad(inner_texture, inner.row, outer_texture, outer.row, column, window.half_window_rows,
                        window.half_window_columns);
    }
  }

  // total[i][j]: best cost of aligning the first i inner and first j outer points.
  std::array<float, kSize * kSize> total;
  std::array<Step, kSize * kSize> step;
  const auto at = [](int i, int j) { return static_cast<std::size_t>(i * kSize + j); };
  const auto occlusion = static_cast<float>(config.occlusion_cost);
  total[0] = 0.0f;
  for (int i = 1; i <= n; ++i)
    total[at(i, 0)] = total[at(i - 1, 0)] + occlusion, step[at(i, 0)] = Step::kSkipInner;
  for (int j = 1; j <= m; ++j)
    total[at(0, j)] = total[at(0, j - 1)] + occlusion, step[at(0, j)] = Step::kSkipOuter;
  for (int i = 1; i <= n; ++i) {
    for (int j = 1; j <= m; ++j) {
      float best = total[at(i - 1, j)] + occlusion;
      Step how = Step::kSkipInner;
      if (total[at(i, j - 1)] + occlusion < best)
        best = total[at(i, j - 1)] + occlusion, how = Step::kSkipOuter;
      const float matched = total[at(i - 1, j - 1)] + pair_cost[at(i - 1, j - 1)];
      if (matched < best) best = matched, how = Step::kMatch;
      total[at(i, j)] = best;
      step[at(i, j)] = how;
    }
  }

  // Backtrack from the full alignment; matches come out top-down, so reverse them after.
  const std::size_t first = out.size();
  for (int i = n, j = m; i > 0 || j > 0;) {
    const Step how = step[at(i, j)];
    if (how == Step::kMatch) {
      const auto &inner = inner_points[static_cast<std::size_t>(i - 1)];
      const auto &outer = outer_points[static_cast<std::size_t>(j - 1)];
      out.push_back(refine(inner, outer, column, pair_cost[at(i - 1, j - 1)], inner_texture, outer_texture,
                           window, config.subpixel));
      ++stats.matched;
      --i, --j;
    } else if (how == Step::kSkipInner) {
      ++stats.occluded_inner;
      --i;
    } else {
      ++stats.occluded_outer;
      --j;
    }
  }
  std::reverse(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
}

}  // namespace omnislam::stereo
