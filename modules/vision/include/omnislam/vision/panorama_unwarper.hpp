#pragma once

#include <opencv2/core.hpp>
#include <vector>

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

  /// Reads one byte per cache line of the image pixels `lobe`'s samples read, in raster
  /// order; call it just before unwarp() of that lobe. A fresh frame is usually not in
  /// cache, and remap's arcs defeat the hardware prefetcher: one streaming pass first makes
  /// the unwarp read from cache (2-3x faster on a new frame). Only the lobe's own part is
  /// read (the inner lobe's disk, the outer lobe's ring: 28% and 60% of the frame's cache
  /// lines), so it is still in cache beside the lobe's maps when the remap runs
  /// (docs/frontend.md, "Speed").
  void prefetch(const cv::Mat &image, mirror::Lobe lobe) const;

  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] int columns() const { return columns_; }

  /// Image pixels [first, last] of one row that a lobe's samples read.
  struct Span {
    int row = 0;
    int first = 0;
    int last = 0;
  };
  /// What prefetch() reads for `lobe`: every pixel its samples read, in raster order.
  [[nodiscard]] const std::vector<Span> &spans(mirror::Lobe lobe) const { return maps(lobe).spans; }

 private:
  struct Maps {
    cv::Mat xy;               ///< CV_16SC2 integer sample positions
    cv::Mat fraction;         ///< CV_16UC1 interpolation table index
    std::vector<Span> spans;  ///< the pixels the samples read, row by row
  };
  static Maps make_maps(const mirror::MirrorModel &model, mirror::Lobe lobe);
  [[nodiscard]] const Maps &maps(mirror::Lobe lobe) const {
    return lobe == mirror::Lobe::kInner ? inner_ : outer_;
  }

  int rows_ = 0;
  int columns_ = 0;
  Maps inner_;
  Maps outer_;
};

}  // namespace omnislam::vision
