#pragma once

#include <opencv2/calib3d.hpp>
#include <vector>

#include "omnislam/stereo/scan_reconstructor.hpp"

/// @file
/// OpenCV StereoSGBM on the same panorama pair, for comparison with the DP matcher.
/// Epipolar lines are panorama columns, so both panoramas are transposed (one azimuth per
/// image row). With d = outer_row - inner_row >= 0, the outer panorama is SGBM's left
/// image (x_right = x_left - d). Both are padded on the left by the search width so every
/// outer row gets a disparity. The dense disparity is then read at the outer lobe's edge
/// candidates and triangulated by the same code as the DP matches.

namespace omnislam::bench {

class SgbmMatcher {
 public:
  explicit SgbmMatcher(const stereo::DisparityLimits &limits);

  /// Dense disparity of the reconstructor's current panoramas, then RowMatches at the
  /// outer candidates (inner_row = outer_row - d).
  void match(const stereo::ScanReconstructor &reconstructor, std::vector<stereo::RowMatch> &out);

  [[nodiscard]] int min_disparity() const { return min_disparity_; }
  [[nodiscard]] int num_disparities() const { return num_disparities_; }

 private:
  int min_disparity_ = 0;
  int num_disparities_ = 16;
  cv::Ptr<cv::StereoSGBM> sgbm_;
  cv::Mat left_, right_, disparity_;
};

}  // namespace omnislam::bench
