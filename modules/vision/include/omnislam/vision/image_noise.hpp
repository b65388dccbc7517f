#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

/// @file
/// How noisy a camera frame is: the standard deviation of its sensor noise in grey levels,
/// measured on the frame itself, whatever the scene shows.

namespace omnislam::vision {

/// The ring of the frame the mirror's lobes fill: pixels between the two radii about the
/// optical axis.
struct ImageAnnulus {
  cv::Point2d centre_px{511.5, 511.5};
  double inner_radius_px = 62.0;
  double outer_radius_px = 512.0;
};

/// Standard deviation of a frame's noise, in grey levels, as white noise of the raw pixels
/// would have it. Immerkaer's operator (the difference of two discrete Laplacians, zero on
/// any plane, so shading and ramps leave it silent) on 2 x 2 binned pixels, whose sums carry
/// the low-frequency noise a JPEG keeps and Canny's smoothing lets through; the median of its
/// absolute response over the annulus (every eighth binned row), so that edges and texture,
/// which occupy a minority of the pixels, do not count. For white noise of deviation s the
/// response on binned sums has deviation 12 s, and its absolute value a median of 0.6745 x
/// 12 s. Keeps its scratch rows between frames (steady-state frames allocate nothing); one
/// per thread.
class ImageNoiseMeter {
 public:
  explicit ImageNoiseMeter(const ImageAnnulus &annulus = {}) : annulus_(annulus) {}

  /// The noise of an 8-bit single-channel frame; 0 when the annulus holds no pixel.
  [[nodiscard]] double measure(const cv::Mat &image);

 private:
  ImageAnnulus annulus_;
  std::array<std::vector<int>, 3> sums_;  ///< three binned rows (sums of 2 x 2 pixels)
};

}  // namespace omnislam::vision
