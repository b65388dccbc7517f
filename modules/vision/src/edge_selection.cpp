#include "omnislam/vision/edge_selection.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "byte_mask.hpp"
#include "omnislam/vision/wide_vectors.hpp"
#include "parabola.hpp"

namespace omnislam::vision {
namespace {

int abs_row_gradient(const cv::Mat &grad_row, int row, int column) {
  return std::abs(static_cast<int>(grad_row.at<std::int16_t>(row, column)));
}

// Inlined into each compiled variant of the selection below: called from its AVX2 variant,
// an out-of-line SSE2 function would switch the vector unit's state twice per call, which
// costs tens of cycles on some CPUs (measured: half the selection's time on one).
[[gnu::always_inline]] inline float contrast_in_window(const cv::Mat &texture, int row, int column,
                                                       int half_rows, int half_columns) {
  float low = 1e30f, high = -1e30f, sum = 0.0f;
  int count = 0;
  const std::size_t step = texture.step[0] / sizeof(float);
  const float *top = texture.ptr<float>(row - half_rows);
  for (int dc = -half_columns; dc <= half_columns; ++dc) {
    int col = column + dc;
    col += col < 0 ? texture.cols : col >= texture.cols ? -texture.cols : 0;
    const float *pixel = top + col;
    for (int r = 0; r <= 2 * half_rows; ++r, pixel += step) {
      const float value = *pixel;
      low = std::min(low, value);
      high = std::max(high, value);
      sum += value;
      ++count;
    }
  }
  const float mean = sum / static_cast<float>(count);
  return mean > 0.0f ? (high - low) / mean : 0.0f;
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
  return contrast_in_window(texture, row, column, half_rows, half_columns);
}

OMNISLAM_WIDE_VECTORS SelectionStats select_nearest_horizontal_edges(const EdgeImage &edges,
                                                                     const cv::Mat &texture,
                                                                     const EdgeSelectionConfig &config,
                                                                     ColumnEdges &out) {
  SelectionStats stats;
  const int rows = edges.edges.rows, columns = edges.edges.cols;
  const int margin = selection_margin_rows(config);
  out.reset(columns, config.max_edges_per_column);
  // Every column is read bottom-up (the bottom rows are the points nearest the robot,
  // mirror.md sec. 0), but all columns advance together, one image row at a time: walking
  // one column at a time would touch a new cache line per pixel. A run of consecutive
  // horizontal edge pixels is represented by its strongest pixel (the nearest one on ties),
  // if that is a local maximum along the column. Each row first updates every column's
  // open run without a branch (a textured floor's edges are random, and a branch per pixel
  // mispredicts), then closes the runs that ended there.
  constexpr int kNoRun = -1;
  std::vector<int> run_peak(static_cast<std::size_t>(columns), kNoRun);
  std::vector<int> run_strength(static_cast<std::size_t>(columns), 0);
  std::vector<int> kept(static_cast<std::size_t>(columns), 0);
  std::vector<std::uint8_t> closing(static_cast<std::size_t>(columns), 0);
  const auto close_run = [&](int column) {
    int &peak = run_peak[static_cast<std::size_t>(column)];
    const int above = abs_row_gradient(edges.grad_row, peak - 1, column);
    const int centre = run_strength[static_cast<std::size_t>(column)];  // |d/d(row)| at the peak
    const int below = abs_row_gradient(edges.grad_row, peak + 1, column);
    const int row = peak;
    peak = kNoRun;
    if (centre < above || centre < below) {
      ++stats.not_local_max;
      return;
    }
    if (contrast_in_window(texture, row, column, config.half_window_rows, config.half_window_columns) <
        config.min_relative_contrast) {
      ++stats.low_contrast;
      return;
    }
    const float offset = parabola_vertex_offset(static_cast<float>(above), static_cast<float>(centre),
                                                static_cast<float>(below));
    out.push(column, {row, static_cast<float>(row) + offset, static_cast<float>(centre)});
    ++kept[static_cast<std::size_t>(column)];
  };
  const int max_kept = config.max_edges_per_column;
  const double ratio = config.horizontal_ratio;
  int *peaks = run_peak.data(), *strengths = run_strength.data(), *kept_here = kept.data();
  std::uint8_t *ends = closing.data();
  for (int row = rows - 1 - margin; row >= margin; --row) {
    const auto *edge = edges.edges.ptr<std::uint8_t>(row);
    const auto *along = edges.grad_row.ptr<std::int16_t>(row);
    const auto *across = edges.grad_col.ptr<std::int16_t>(row);
    int horizontal_px = 0, runs = 0;
    for (int column = 0; column < columns; ++column) {
      // An edge pixel whose gradient points mostly along the column.
      const int strength = std::abs(static_cast<int>(along[column]));
      const double across_strength = std::abs(static_cast<double>(across[column]));
      const bool horizontal =
          (edge[column] != 0) & (strength > 0) & (static_cast<double>(strength) >= ratio * across_strength);
      const bool open = peaks[column] != kNoRun;
      // A full column takes no more runs; an open run ends at a pixel that is not horizontal.
      const bool counted = horizontal & (kept_here[column] < max_kept);
      const bool new_peak = counted & (!open | (strength > strengths[column]));
      ends[column] = static_cast<std::uint8_t>(!horizontal & open);
      horizontal_px += static_cast<int>(counted);
      runs += static_cast<int>(counted & !open);
      peaks[column] = new_peak ? row : peaks[column];
      strengths[column] = new_peak ? strength : strengths[column];
    }
    stats.horizontal_px += horizontal_px;
    stats.runs += runs;
    // Few runs end in any one row: skip eight columns at a time where none does.
    int column = 0;
    for (; column + 8 <= columns; column += 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, ends + column, sizeof word);
      for (; word != 0; word &= word - 1) close_run(column + byte_of_lowest_bit(word));
    }
    for (; column < columns; ++column) {
      if (ends[column] != 0) close_run(column);
    }
  }
  for (int column = 0; column < columns; ++column) {
    if (run_peak[static_cast<std::size_t>(column)] != kNoRun) close_run(column);
  }
  for (const int count : kept) stats.selected += count;
  return stats;
}

}  // namespace omnislam::vision
