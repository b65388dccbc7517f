#include "omnislam/vision/edge_detector.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>

namespace omnislam::vision {
namespace {

// Sobel 3x3 on 8-bit input: |g| <= 4 * 255 * sqrt(2) < 1443.
constexpr int kMagnitudeBins = 1448;

}  // namespace

EdgeDetector::EdgeDetector(const CannyConfig &config) : config_(config) {
  const int half = config.half_window_px > 0
                       ? config.half_window_px
                       : std::max(1, static_cast<int>(std::ceil(3.0 * config.sigma_px)));
  kernel_size_ = cv::Size(2 * half + 1, 2 * half + 1);
}

void EdgeDetector::detect(const cv::Mat &panorama, EdgeImage &out) {
  if (config_.sigma_px > 0.0) {
    cv::GaussianBlur(panorama, smoothed_, kernel_size_, config_.sigma_px, config_.sigma_px,
                     cv::BORDER_REPLICATE);
  } else {
    panorama.copyTo(smoothed_);
  }
  cv::spatialGradient(smoothed_, out.grad_col, out.grad_row, 3, cv::BORDER_REPLICATE);  // Sobel 3x3
  choose_thresholds(out);
  cv::Canny(out.grad_col, out.grad_row, out.edges, out.low_threshold, out.high_threshold, true);
  out.canny_px = cv::countNonZero(out.edges);
  remove_fragments(out);
}

void EdgeDetector::choose_thresholds(EdgeImage &out) {
  if (!config_.auto_thresholds) {
    out.high_threshold = config_.high_threshold;
    out.low_threshold = config_.low_threshold;
    return;
  }
  // Quantile of the L2 gradient magnitude via an integer histogram of every other pixel
  // of every other row (a quarter of the pixels estimates a quantile to well under 1%).
  std::array<int, kMagnitudeBins> histogram{};
  int sampled = 0;
  for (int row = 0; row < out.grad_row.rows; row += 2) {
    const auto *gr = out.grad_row.ptr<std::int16_t>(row);
    const auto *gc = out.grad_col.ptr<std::int16_t>(row);
    for (int col = 0; col < out.grad_row.cols; col += 2, ++sampled) {
      const int squared = gr[col] * gr[col] + gc[col] * gc[col];
      const int bin = static_cast<int>(std::sqrt(static_cast<float>(squared)));
      ++histogram[static_cast<std::size_t>(std::min(bin, kMagnitudeBins - 1))];
    }
  }
  const double wanted = config_.auto_not_edge_fraction * sampled;
  double cumulative = 0.0;
  int quantile = kMagnitudeBins - 1;
  for (int bin = 0; bin < kMagnitudeBins; ++bin) {
    cumulative += histogram[static_cast<std::size_t>(bin)];
    if (cumulative >= wanted) {
      quantile = bin + 1;
      break;
    }
  }
  out.high_threshold = std::max(static_cast<double>(quantile), config_.auto_min_high_threshold);
  out.low_threshold = config_.auto_low_ratio * out.high_threshold;
}

void EdgeDetector::remove_fragments(EdgeImage &out) {
  // 8-connected flood fill over the (sparse) edge pixels only; much cheaper than labelling
  // the whole image. A zero border of one pixel spares every bounds check; visited pixels
  // are marked kVisited and the survivors written back as 255.
  constexpr std::uint8_t kVisited = 128;
  out.fragment_px_removed = 0;
  if (config_.min_fragment_px <= 1 || out.canny_px == 0) return;
  cv::copyMakeBorder(out.edges, padded_, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  std::uint8_t *data = padded_.ptr<std::uint8_t>(0);
  const auto step = static_cast<std::ptrdiff_t>(padded_.step);
  const std::array<std::ptrdiff_t, 8> neighbours{-step - 1, -step,    -step + 1, -1,
                                                 1,         step - 1, step,      step + 1};
  for (int row = 1; row <= out.edges.rows; ++row) {
    std::uint8_t *line = padded_.ptr<std::uint8_t>(row);
    for (int col = 1; col <= out.edges.cols; ++col) {
      if (line[col] != 255) continue;
      component_.clear();
      stack_.clear();
      stack_.push_back(line + col - data);
      line[col] = kVisited;
      while (!stack_.empty()) {
        const std::ptrdiff_t index = stack_.back();
        stack_.pop_back();
        component_.push_back(index);
        for (const std::ptrdiff_t offset : neighbours) {
          std::uint8_t &pixel = data[index + offset];
          if (pixel == 255) {
            pixel = kVisited;
            stack_.push_back(index + offset);
          }
        }
      }
      if (static_cast<int>(component_.size()) < config_.min_fragment_px) {
        for (const std::ptrdiff_t index : component_) data[index] = 0;
        out.fragment_px_removed += static_cast<int>(component_.size());
      }
    }
  }
  cv::compare(padded_(cv::Rect(1, 1, out.edges.cols, out.edges.rows)), 0, out.edges, cv::CMP_NE);
}

}  // namespace omnislam::vision
