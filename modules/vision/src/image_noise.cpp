#include "omnislam/vision/image_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace omnislam::vision {
namespace {

constexpr int kBinnedRowStep = 8;    // every eighth binned row: ~15,000 responses a frame
constexpr int kResponseBins = 4096;  // |response| on binned sums, capped (noise of ~50 grey levels fits)
constexpr double kMedianOfAbsNormal = 0.6744897501960817;
constexpr double kResponseGain = 12.0;  // deviation of the response on 2 x 2 sums, per unit of pixel noise

}  // namespace

double ImageNoiseMeter::measure(const cv::Mat &image) {
  CV_Assert(image.type() == CV_8UC1);
  const ImageAnnulus &annulus = annulus_;
  const int binned_rows = image.rows / 2, binned_cols = image.cols / 2;
  if (binned_rows < 3 || binned_cols < 3) return 0.0;
  // Binned pixel (i, j) holds raw pixels (2i..2i+1, 2j..2j+1); its centre is (2j + 0.5, 2i + 0.5).
  for (auto &row : sums_) row.resize(static_cast<std::size_t>(binned_cols));
  const auto bin_row = [&](int i, int first, int last, std::vector<int> &out) {
    const std::uint8_t *a = image.ptr<std::uint8_t>(2 * i);
    const std::uint8_t *b = image.ptr<std::uint8_t>(2 * i + 1);
    for (int j = first; j <= last; ++j)
      out[static_cast<std::size_t>(j)] = a[2 * j] + a[2 * j + 1] + b[2 * j] + b[2 * j + 1];
  };
  std::array<int, kResponseBins> histogram{};
  long samples = 0;
  const double inner_sq = annulus.inner_radius_px * annulus.inner_radius_px;
  const double outer_sq = annulus.outer_radius_px * annulus.outer_radius_px;
  for (int i = 1; i + 1 < binned_rows; i += kBinnedRowStep) {
    const double dv = 2.0 * i + 0.5 - annulus.centre_px.y;
    if (dv * dv >= outer_sq) continue;
    // The columns of this binned row inside the outer circle (the inner one is tested per pixel).
    const double half_width = std::sqrt(outer_sq - dv * dv);
    const int first =
        std::max(1, static_cast<int>(std::ceil((annulus.centre_px.x - half_width - 0.5) / 2.0)));
    const int last = std::min(binned_cols - 2,
                              static_cast<int>(std::floor((annulus.centre_px.x + half_width - 0.5) / 2.0)));
    if (first > last) continue;
    bin_row(i - 1, first - 1, last + 1, sums_[0]);
    bin_row(i, first - 1, last + 1, sums_[1]);
    bin_row(i + 1, first - 1, last + 1, sums_[2]);
    const int *up = sums_[0].data(), *mid = sums_[1].data(), *down = sums_[2].data();
    for (int j = first; j <= last; ++j) {
      const double du = 2.0 * j + 0.5 - annulus.centre_px.x;
      if (du * du + dv * dv < inner_sq) continue;
      // [1 -2 1; -2 4 -2; 1 -2 1]
      const int response = (up[j - 1] + up[j + 1] + down[j - 1] + down[j + 1]) -
                           2 * (up[j] + down[j] + mid[j - 1] + mid[j + 1]) + 4 * mid[j];
      ++histogram[static_cast<std::size_t>(std::min(std::abs(response), kResponseBins - 1))];
      ++samples;
    }
  }
  if (samples == 0) return 0.0;
  // The median, interpolated within its bin (responses are integers: a bin holds one value).
  const double half = 0.5 * static_cast<double>(samples);
  double below = 0.0;
  for (int bin = 0; bin < kResponseBins; ++bin) {
    const double count = histogram[static_cast<std::size_t>(bin)];
    if (below + count >= half) {
      const double median = bin + (count > 0.0 ? (half - below) / count : 0.0) - 0.5;
      return std::max(0.0, median) / (kMedianOfAbsNormal * kResponseGain);
    }
    below += count;
  }
  return (kResponseBins - 1) / (kMedianOfAbsNormal * kResponseGain);
}

}  // namespace omnislam::vision
