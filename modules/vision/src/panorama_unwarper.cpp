#include "omnislam/vision/panorama_unwarper.hpp"

#include <cstddef>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "omnislam/mirror/panorama_maps.hpp"

namespace omnislam::vision {
namespace {

constexpr int kCacheLineBytes = 64;

// The image pixels a lobe's bilinear samples read (each sample's pixel and its right, lower
// and lower-right neighbours, as cv::remap reads them from the fixed-point map), as runs of
// columns per image row; runs closer than a cache line are one run.
std::vector<PanoramaUnwarper::Span> sampled_spans(const cv::Mat &xy, int width, int height) {
  std::vector<std::vector<std::uint8_t>> read(static_cast<std::size_t>(height));
  for (int row = 0; row < xy.rows; ++row) {
    const auto *position = xy.ptr<std::int16_t>(row);
    for (int column = 0; column < xy.cols; ++column) {
      const int x = position[2 * column], y = position[2 * column + 1];
      for (int dy = 0; dy <= 1; ++dy) {
        if (y + dy < 0 || y + dy >= height) continue;
        auto &line = read[static_cast<std::size_t>(y + dy)];
        if (line.empty()) line.assign(static_cast<std::size_t>(width), 0);
        for (int dx = 0; dx <= 1; ++dx) {
          if (x + dx >= 0 && x + dx < width) line[static_cast<std::size_t>(x + dx)] = 1;
        }
      }
    }
  }
  std::vector<PanoramaUnwarper::Span> spans;
  for (int row = 0; row < height; ++row) {
    const auto &line = read[static_cast<std::size_t>(row)];
    for (int x = 0; x < static_cast<int>(line.size()); ++x) {
      if (line[static_cast<std::size_t>(x)] == 0) continue;
      if (!spans.empty() && spans.back().row == row && x - spans.back().last <= kCacheLineBytes) {
        spans.back().last = x;
      } else {
        spans.push_back({row, x, x});
      }
    }
  }
  return spans;
}

}  // namespace

PanoramaUnwarper::PanoramaUnwarper(const mirror::MirrorModel &model)
    : rows_(model.config().rows_per_lobe),
      columns_(model.config().columns),
      inner_(make_maps(model, mirror::Lobe::kInner)),
      outer_(make_maps(model, mirror::Lobe::kOuter)) {}

PanoramaUnwarper::Maps PanoramaUnwarper::make_maps(const mirror::MirrorModel &model, mirror::Lobe lobe) {
  mirror::PanoramaMap map = mirror::make_panorama_map(model, lobe);
  const cv::Mat u(map.rows, map.columns, CV_32FC1, map.u_px.data());
  const cv::Mat v(map.rows, map.columns, CV_32FC1, map.v_px.data());
  Maps maps;
  // Fixed-point maps skip the per-call float conversion inside cv::remap; the position
  // quantum is 1/32 px, far below the sub-pixel accuracy the stereo needs.
  cv::convertMaps(u, v, maps.xy, maps.fraction, CV_16SC2);
  maps.spans = sampled_spans(maps.xy, model.config().image_width_px, model.config().image_height_px);
  return maps;
}

void PanoramaUnwarper::prefetch(const cv::Mat &image, mirror::Lobe lobe) const {
  if (image.empty() || image.elemSize() != 1) return;
  std::uint8_t sum = 0;
  for (const Span &span : maps(lobe).spans) {
    if (span.row >= image.rows || span.last >= image.cols) continue;
    const std::uint8_t *pixels = image.ptr<std::uint8_t>(span.row);
    for (int x = span.first; x < span.last; x += kCacheLineBytes)
      sum = static_cast<std::uint8_t>(sum + pixels[x]);
    sum = static_cast<std::uint8_t>(sum + pixels[span.last]);
  }
  // A volatile store keeps the loads: the sum is otherwise dead and the loop would be dropped.
  [[maybe_unused]] volatile std::uint8_t sink = sum;
}

void PanoramaUnwarper::unwarp(const cv::Mat &image, mirror::Lobe lobe, cv::Mat &panorama) const {
  cv::remap(image, panorama, maps(lobe).xy, maps(lobe).fraction, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(0));
}

}  // namespace omnislam::vision
