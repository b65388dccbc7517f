#pragma once

#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "omnislam/vision/edge_detector.hpp"
#include "omnislam/vision/vision_config.hpp"

/// @file
/// Nearest horizontal edges (thesis sec. 3 step 3, with the step-4 contrast test). The
/// thesis gives no detail; this is the reading of thesis.md: an edge pixel is horizontal
/// when its gradient points mostly along the column; along each column, consecutive
/// horizontal edge pixels form a run, represented by its peak of |d/d(row)| if that peak
/// is a local maximum along the column; runs are taken from the bottom row up (nearest the
/// robot first) and a run whose similarity window lacks relative contrast is skipped.

namespace omnislam::vision {

/// One candidate edge point of a panorama column.
struct EdgePoint {
  int row = 0;             ///< integer row of the gradient peak
  float row_subpx = 0.0f;  ///< peak refined by a parabola through |d/d(row)| at row-1..row+1
  float strength = 0.0f;   ///< |d/d(row)| at the peak (Sobel units)
};

/// Candidates of every column, at most `capacity` per column, ordered from the bottom of
/// the panorama up (nearest the robot first). Storage is reused between frames.
class ColumnEdges {
 public:
  void reset(int columns, int capacity);
  void push(int column, const EdgePoint &point);
  [[nodiscard]] std::span<const EdgePoint> column(int column) const;
  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] int total() const;

 private:
  int columns_ = 0;
  int capacity_ = 0;
  std::vector<EdgePoint> points_;
  std::vector<int> counts_;
};

struct SelectionStats {
  int horizontal_px = 0;  ///< edge pixels passing the horizontality test
  int runs = 0;           ///< horizontal runs examined (bottom-up, until the column is full)
  int not_local_max = 0;  ///< runs whose peak is not a local maximum along the column
  int low_contrast = 0;   ///< runs failing the relative-contrast test
  int selected = 0;       ///< candidates kept
};

/// Rows whose similarity window (and sub-pixel neighbours) do not fit are never selected.
[[nodiscard]] int selection_margin_rows(const EdgeSelectionConfig &config);

/// Selects the candidates of one panorama. `texture` is the CV_32FC1 image (intensity in
/// [0, 1], Blackman-smoothed or not) that the similarity cost will read.
SelectionStats select_nearest_horizontal_edges(const EdgeImage &edges, const cv::Mat &texture,
                                               const EdgeSelectionConfig &config, ColumnEdges &out);

/// Relative contrast (max - min) / mean of the texture window centred at (row, column),
/// columns wrapping around the panorama; 0 when the mean is 0.
[[nodiscard]] float relative_contrast(const cv::Mat &texture, int row, int column, int half_rows,
                                      int half_columns);

}  // namespace omnislam::vision
