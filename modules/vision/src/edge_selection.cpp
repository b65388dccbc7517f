#include "omnislam/vision/edge_selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace omnislam::vision {
namespace {

int abs_row_gradient(const cv::Mat &grad_row, int row, int column) {
  return std::abs(static_cast<int>(grad_row.at<std::int16_t>(row, column)));
}

bool is_horizontal_edge(const EdgeImage &edges, int row, int column, double ratio) {
  if (edges.edges.at<std::uint8_t>(row, column) == 0) return false;
  const double along = std::abs(static_cast<double>(edges.grad_row.at<std::int16_t>(row, column)));
  const double across = std::abs(static_cast<double>(edges.grad_col.at<std::int16_t>(row, column)));
  return along >= ratio * across && along > 0.0;
}

// Vertex of the parabola through (-1, a), (0, b), (1, c), clamped to half a pixel.
float parabola_offset(float a, float b, float c) {
  const float curvature = a - 2.0f * b + c;
  if (!(curvature < 0.0f)) return 0.0f;
  return std::clamp(0.5f * (a - c) / curvature, -0.5f, 0.5f);
}

}  // namespace

void ColumnEdges::reset(int columns, int capacity) {
  columns_ = columns;
  capacity_ = capacity;
  points_.resize(static_cast<std::size_t>(columns) * static_cast<std::size_t>(capacity));
  counts_.assign(static_cast<std::size_t>(columns), 0);
}

void ColumnEdges::push(int column, const EdgePoint &point) {
  int &count = counts_[static_cast<std::size_t>(column)];
  if (count >= capacity_) return;
  points_[static_cast<std::size_t>(column) * capacity_ + count] = point;
  ++count;
}

std::span<const EdgePoint> ColumnEdges::column(int column) const {
  return {points_.data() + static_cast<std::size_t>(column) * capacity_,
          static_cast<std::size_t>(counts_[static_cast<std::size_t>(column)])};
}

int ColumnEdges::total() const {
  int sum = 0;
  for (int count : counts_) sum += count;
  return sum;
}

int selection_margin_rows(const EdgeSelectionConfig &config) { return config.half_window_rows + 1; }

float relative_contrast(const cv::Mat &texture, int row, int column, int half_rows, int half_columns) {
  float low = 1e30f, high = -1e30f, sum = 0.0f;
  int count = 0;
  for (int dc = -half_columns; dc <= half_columns; ++dc) {
    const int col = (column + dc + texture.cols) % texture.cols;
    for (int r = row - half_rows; r <= row + half_rows; ++r) {
      const float value = texture.at<float>(r, col);
      low = std::min(low, value);
      high = std::max(high, value);
      sum += value;
      ++count;
    }
  }
  const float mean = sum / static_cast<float>(count);
  return mean > 0.0f ? (high - low) / mean : 0.0f;
}

SelectionStats select_nearest_horizontal_edges(const EdgeImage &edges, const cv::Mat &texture,
                                               const EdgeSelectionConfig &config, ColumnEdges &out) {
  SelectionStats stats;
  const int rows = edges.edges.rows, columns = edges.edges.cols;
  const int margin = selection_margin_rows(config);
  out.reset(columns, config.max_edges_per_column);
  for (int column = 0; column < columns; ++column) {
    int kept = 0;
    // Bottom-up: the bottom rows are the points nearest the robot (mirror.md sec. 0).
    for (int row = rows - 1 - margin; row >= margin && kept < config.max_edges_per_column; --row) {
      if (!is_horizontal_edge(edges, row, column, config.horizontal_ratio)) continue;
      int peak = row, end = row;
      while (end - 1 >= margin && is_horizontal_edge(edges, end - 1, column, config.horizontal_ratio)) {
        --end;
        if (abs_row_gradient(edges.grad_row, end, column) > abs_row_gradient(edges.grad_row, peak, column)) {
          peak = end;
        }
      }
      stats.horizontal_px += row - end + 1;
      ++stats.runs;
      row = end;  // the loop's --row continues above the run
      const int above = abs_row_gradient(edges.grad_row, peak - 1, column);
      const int centre = abs_row_gradient(edges.grad_row, peak, column);
      const int below = abs_row_gradient(edges.grad_row, peak + 1, column);
      if (centre < above || centre < below) {
        ++stats.not_local_max;
        continue;
      }
      if (relative_contrast(texture, peak, column, config.half_window_rows, config.half_window_columns) <
          config.min_relative_contrast) {
        ++stats.low_contrast;
        continue;
      }
      const float offset =
          parabola_offset(static_cast<float>(above), static_cast<float>(centre), static_cast<float>(below));
      out.push(column, {peak, static_cast<float>(peak) + offset, static_cast<float>(centre)});
      ++kept;
    }
    stats.selected += kept;
  }
  return stats;
}

}  // namespace omnislam::vision
