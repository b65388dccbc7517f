#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "omnislam/degrade/degradation_config.hpp"

/// @file
/// Seeded degradation of rendered 8-bit grey images into realistic sensor images
/// (degradation_config.hpp lists the factors, their defaults and why).

namespace omnislam::degrade {

/// One degraded image, or why there is none.
struct Degraded {
  cv::Mat image;               ///< CV_8UC1, the input's size; empty on error
  std::string error;           ///< empty on success
  double exposure_gain = 1.0;  ///< the frame's exposure factor (1 when exposure is off)

  [[nodiscard]] bool ok() const { return error.empty(); }
};

/// Degrades the images of one size. The constructor precomputes the static part (the
/// vignetting x dust gain map and the blur kernel); apply() is const and uses no shared
/// mutable state, so one Degrader may serve several threads at once.
///
/// Determinism: every random draw depends on (config.seed, frame_number) only, never on
/// call order or thread: frame N gives the same bytes alone or in a sequence. Dust depends
/// on the seed only (it is the same in every frame).
class Degrader {
 public:
  /// `image_size`: the size of the images apply() accepts (width x height in pixels).
  Degrader(const DegradationConfig &config, cv::Size image_size);

  /// The degraded copy of `image_8u_gray` (CV_8UC1 of the constructor's size) as frame
  /// `frame_number` (any integer; datasets use their 1-based frame number). With no factor
  /// enabled the result is a byte-identical copy. Another type or size is an error
  /// result, not an exception.
  [[nodiscard]] Degraded apply(const cv::Mat &image_8u_gray, int frame_number) const;

  [[nodiscard]] const DegradationConfig &config() const { return config_; }
  [[nodiscard]] cv::Size image_size() const { return size_; }
  /// The static multiplicative gain (vignetting x dust), CV_32FC1; empty when both are off.
  [[nodiscard]] const cv::Mat &gain_map() const { return gain_map_; }

 private:
  DegradationConfig config_;
  cv::Size size_;
  cv::Mat gain_map_;     ///< CV_32FC1 or empty
  cv::Mat blur_kernel_;  ///< CV_32FC1, sums to 1, or empty
};

/// One-off form: builds a Degrader for the image's size and applies it (tests, tools).
[[nodiscard]] Degraded degrade(const cv::Mat &image_8u_gray, const DegradationConfig &config,
                               int frame_number);

}  // namespace omnislam::degrade
