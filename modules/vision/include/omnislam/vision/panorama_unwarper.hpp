#pragma once

#include <opencv2/core.hpp>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// Polar -> panorama unwarping of both lobes (thesis sec. 3 step 1) with cv::remap on the
/// mirror module's sampling maps, converted once to OpenCV's fixed-point form.

namespace omnislam::vision {

/// Holds the remap tables of both lobes; build once per camera, then unwarp every frame.
/// unwarp() is const and may run on several threads with distinct outputs.
class PanoramaUnwarper {
 public:
  explicit PanoramaUnwarper(const mirror::MirrorModel &model);

  /// Bilinear remap of an 8-bit single-channel image (the full camera frame) into a
  /// rows_per_lobe x columns panorama of `lobe`. Samples outside the image read 0.
  /// `panorama` is reallocated only when its size or type differ.
  void unwarp(const cv::Mat &image, mirror::Lobe lobe, cv::Mat &panorama) const;

  /// Reads one byte per cache line of the image rows both lobes sample, in raster order.
  /// A fresh frame is usually not in cache, and remap's arcs defeat the hardware prefetcher;
  /// one streaming pass first makes both unwarps read from cache (2-3x faster on a new frame).
  void prefetch(const cv::Mat &image) const;

  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] int columns() const { return columns_; }

 private:
  struct Maps {
    cv::Mat xy;        ///< CV_16SC2 integer sample positions
    cv::Mat fraction;  ///< CV_16UC1 interpolation table index
  };
  int rows_ = 0;
  int columns_ = 0;
  int first_row_ = 0;  ///< image rows any lobe sample touches: [first_row_, last_row_]
  int last_row_ = -1;
  Maps inner_;
  Maps outer_;
};

}  // namespace omnislam::vision
