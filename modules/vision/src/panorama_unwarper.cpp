#include "omnislam/vision/panorama_unwarper.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "omnislam/mirror/panorama_maps.hpp"

namespace omnislam::vision {
namespace {

constexpr int kCacheLineBytes = 64;

// Returns the range of image rows the lobe's samples (and their bilinear neighbours) touch.
std::pair<int, int> build_maps(const mirror::MirrorModel &model, mirror::Lobe lobe, cv::Mat &xy,
                               cv::Mat &fraction) {
  mirror::PanoramaMap map = mirror::make_panorama_map(model, lobe);
  const cv::Mat u(map.rows, map.columns, CV_32FC1, map.u_px.data());
  const cv::Mat v(map.rows, map.columns, CV_32FC1, map.v_px.data());
  double v_min = 0.0, v_max = 0.0;
  cv::minMaxLoc(v, &v_min, &v_max);
  // Fixed-point maps skip the per-call float conversion inside cv::remap; the position
  // quantum is 1/32 px, far below the sub-pixel accuracy the stereo needs.
  cv::convertMaps(u, v, xy, fraction, CV_16SC2);
  return {static_cast<int>(std::floor(v_min)), static_cast<int>(std::ceil(v_max)) + 1};
}

}  // namespace

PanoramaUnwarper::PanoramaUnwarper(const mirror::MirrorModel &model)
    : rows_(model.config().rows_per_lobe), columns_(model.config().columns) {
  const auto [inner_first, inner_last] = build_maps(model, mirror::Lobe::kInner, inner_.xy, inner_.fraction);
  const auto [outer_first, outer_last] = build_maps(model, mirror::Lobe::kOuter, outer_.xy, outer_.fraction);
  first_row_ = std::max(0, std::min(inner_first, outer_first));
  last_row_ = std::min(model.config().image_height_px - 1, std::max(inner_last, outer_last));
}

void PanoramaUnwarper::prefetch(const cv::Mat &image) const {
  if (image.empty()) return;
  const int last = std::min(last_row_, image.rows - 1);
  const auto row_bytes = static_cast<int>(image.cols * image.elemSize());
  std::uint8_t sum = 0;
  for (int row = first_row_; row <= last; ++row) {
    const std::uint8_t *pixels = image.ptr<std::uint8_t>(row);
    for (int byte = 0; byte < row_bytes; byte += kCacheLineBytes)
      sum = static_cast<std::uint8_t>(sum + pixels[byte]);
  }
  // A volatile store keeps the loads: the sum is otherwise dead and the loop would be dropped.
  [[maybe_unused]] volatile std::uint8_t sink = sum;
}

void PanoramaUnwarper::unwarp(const cv::Mat &image, mirror::Lobe lobe, cv::Mat &panorama) const {
  const Maps &maps = lobe == mirror::Lobe::kInner ? inner_ : outer_;
  cv::remap(image, panorama, maps.xy, maps.fraction, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
}

}  // namespace omnislam::vision
