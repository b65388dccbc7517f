#include "sgbm_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>

namespace omnislam::bench {
namespace {

constexpr int kBlockSize = 5;

}  // namespace

SgbmMatcher::SgbmMatcher(const stereo::DisparityLimits &limits) {
  min_disparity_ = std::max(0, static_cast<int>(std::floor(limits.min_px)));
  const int span = static_cast<int>(std::ceil(limits.max_px)) - min_disparity_ + 1;
  num_disparities_ = std::max(16, (span + 15) / 16 * 16);
  sgbm_ = cv::StereoSGBM::create(min_disparity_, num_disparities_, kBlockSize, 8 * kBlockSize * kBlockSize,
                                 32 * kBlockSize * kBlockSize, 1, 0, 10, 0, 0, cv::StereoSGBM::MODE_SGBM);
}

void SgbmMatcher::match(const stereo::ScanReconstructor &reconstructor, std::vector<stereo::RowMatch> &out) {
  const int pad = min_disparity_ + num_disparities_;
  cv::copyMakeBorder(reconstructor.outer().panorama.t(), left_, 0, 0, pad, 0, cv::BORDER_REPLICATE);
  cv::copyMakeBorder(reconstructor.inner().panorama.t(), right_, 0, 0, pad, 0, cv::BORDER_REPLICATE);
  sgbm_->compute(left_, right_, disparity_);  // CV_16S, 16 x disparity, < min_disparity * 16 if invalid
  out.clear();
  const vision::ColumnEdges &candidates = reconstructor.outer().candidates;
  for (int column = 0; column < candidates.columns(); ++column) {
    for (const vision::EdgePoint &point : candidates.column(column)) {
      const std::int16_t raw = disparity_.at<std::int16_t>(column, point.row + pad);
      if (raw < min_disparity_ * 16) continue;
      const float disparity = static_cast<float>(raw) / 16.0f;
      const auto outer_row = static_cast<float>(point.row);
      out.push_back({column, outer_row - disparity, outer_row, 0.0f});
    }
  }
}

}  // namespace omnislam::bench
