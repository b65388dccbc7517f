#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "omnislam/vision/vision_config.hpp"

/// @file
/// Canny edges of one panorama (thesis sec. 3 step 2): Gaussian smoothing, Sobel gradient,
/// non-maximum suppression and hysteresis on the L2 magnitude (cv::Canny's definition, on
/// integers, fused with the next step), then removal of tiny edge fragments.

namespace omnislam::vision {

/// The edge map of one panorama together with the gradient it was computed from.
/// "Row" gradient is d/d(row) (along a panorama column, i.e. radial in the omni image).
struct EdgeImage {
  cv::Mat grad_row;            ///< CV_16SC1, Sobel d/d(row) of the smoothed panorama
  cv::Mat grad_col;            ///< CV_16SC1, Sobel d/d(column)
  cv::Mat edges;               ///< CV_8UC1, 255 on an edge pixel
  double low_threshold = 0.0;  ///< hysteresis thresholds actually used (from the image)
  double high_threshold = 0.0;
  /// The largest high threshold the noise floor set for a row (0: none above the image's).
  double noise_high_threshold = 0.0;
  int canny_px = 0;             ///< edge pixels out of Canny
  int fragment_px_removed = 0;  ///< of which in fragments below min_fragment_px
};

/// Keeps its scratch images between calls, so steady-state frames allocate nothing.
/// Not thread-safe: use one detector per thread.
class EdgeDetector {
 public:
  explicit EdgeDetector(const CannyConfig &config = {});

  /// Edges of an 8-bit single-channel panorama into `out` (buffers reused). `noise_floor`,
  /// when given (one value per panorama row), is the least high threshold of each row under
  /// automatic thresholds: the gradient magnitude the frame's noise alone reaches there
  /// (the low threshold follows at auto_low_ratio). Fixed thresholds ignore it.
  void detect(const cv::Mat &panorama, EdgeImage &out, std::span<const float> noise_floor = {});

  /// Per row of `panorama`, the scale of the Rayleigh law its smoothed gradient magnitude
  /// follows where the panorama shows nothing but noise: the median over the row and the
  /// rows beside it (+-2) over sqrt(2 ln 2). On a panorama of pure noise of known deviation,
  /// the gain from a frame's noise to this detector's gradient, row by row.
  [[nodiscard]] std::vector<float> gradient_noise_per_row(const cv::Mat &panorama);

  [[nodiscard]] const CannyConfig &config() const { return config_; }

 private:
  void choose_thresholds(EdgeImage &out, std::span<const float> noise_floor);
  void choose_auto_thresholds(EdgeImage &out);
  void smooth_and_differentiate(const cv::Mat &panorama, EdgeImage &out);
  /// Local maxima of the gradient magnitude along its direction into state_: edges above
  /// the high threshold (also pushed on trace_), candidates above the low one.
  void suppress_non_maxima(const EdgeImage &out);
  /// Hysteresis (candidates connected to edges become edges) and removal of the edge
  /// fragments below min_fragment_px, into out.edges, canny_px and fragment_px_removed.
  void trace_edges(EdgeImage &out);

  CannyConfig config_;
  cv::Size kernel_size_;
  cv::Mat smoothed_;
  std::vector<std::int32_t> row_low_sq_;  ///< per row, the squared hysteresis thresholds (floored)
  std::vector<std::int32_t> row_high_sq_;
  std::vector<std::int32_t> magnitude_rows_;  ///< three padded rows of squared gradient magnitude
  cv::Mat state_;                             ///< edge map with the same border (kNotEdge ... kEdge)
  std::vector<std::ptrdiff_t> trace_;         ///< the strong pixels, one slot per pixel (offsets into state_)
  std::size_t trace_top_ = 0;
  std::vector<std::ptrdiff_t> component_;  ///< the edge component being traced (offsets into state_)
};

}  // namespace omnislam::vision
