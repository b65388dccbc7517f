#include "omnislam/vision/texture.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

namespace omnislam::vision {

cv::Mat blackman_kernel(int taps) {
  cv::Mat kernel(taps, 1, CV_32FC1);
  double sum = 0.0;
  for (int n = 0; n < taps; ++n) {
    const double phase = 2.0 * std::numbers::pi * n / (taps - 1);
    const double weight = std::max(0.0, 0.42 - 0.5 * std::cos(phase) + 0.08 * std::cos(2.0 * phase));
    kernel.at<float>(n) = static_cast<float>(weight);
    sum += weight;
  }
  kernel /= sum;
  return kernel;
}

void make_texture(const cv::Mat &panorama, const cv::Mat &kernel, cv::Mat &texture) {
  constexpr double kScale = 1.0 / 255.0;
  if (kernel.empty()) {
    panorama.convertTo(texture, CV_32F, kScale);
    return;
  }
  cv::sepFilter2D(panorama, texture, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  texture *= kScale;
}

}  // namespace omnislam::vision
