#include "omnislam/vision/panorama_unwarper.hpp"

#include <opencv2/imgproc.hpp>

#include "omnislam/mirror/panorama_maps.hpp"

namespace omnislam::vision {
namespace {

void build_maps(const mirror::MirrorModel &model, mirror::Lobe lobe, cv::Mat &xy, cv::Mat &fraction) {
  mirror::PanoramaMap map = mirror::make_panorama_map(model, lobe);
  const cv::Mat u(map.rows, map.columns, CV_32FC1, map.u_px.data());
  const cv::Mat v(map.rows, map.columns, CV_32FC1, map.v_px.data());
  // Fixed-point maps skip the per-call float conversion inside cv::remap; the position
  // quantum is 1/32 px, far below the sub-pixel accuracy the stereo needs.
  cv::convertMaps(u, v, xy, fraction, CV_16SC2);
}

}  // namespace

PanoramaUnwarper::PanoramaUnwarper(const mirror::MirrorModel &model)
    : rows_(model.config().rows_per_lobe), columns_(model.config().columns) {
  build_maps(model, mirror::Lobe::kInner, inner_.xy, inner_.fraction);
  build_maps(model, mirror::Lobe::kOuter, outer_.xy, outer_.fraction);
}

void PanoramaUnwarper::unwarp(const cv::Mat &image, mirror::Lobe lobe, cv::Mat &panorama) const {
  const Maps &maps = lobe == mirror::Lobe::kInner ? inner_ : outer_;
  cv::remap(image, panorama, maps.xy, maps.fraction, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
}

}  // namespace omnislam::vision
