#include "static_maps.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "random.hpp"

namespace omnislam::degrade::detail {
namespace {

constexpr double kDustEdgePx = 2.0;   // width of a speck's linear soft edge
constexpr int kCoverageSamples = 32;  // per axis, for the disk kernel's pixel coverage

}  // namespace

cv::Mat vignetting_gain(const DegradationConfig &config, cv::Size size) {
  cv::Mat gain(size, CV_32FC1);
  const double scale =
      config.vignetting.rim_falloff / (config.vignetting.rim_radius_px * config.vignetting.rim_radius_px);
  for (int v = 0; v < size.height; ++v) {
    auto *row = gain.ptr<float>(v);
    const double dv = v - config.center_v_px;
    for (int u = 0; u < size.width; ++u) {
      const double du = u - config.center_u_px;
      row[u] = static_cast<float>(std::max(0.0, 1.0 - scale * (du * du + dv * dv)));
    }
  }
  return gain;
}

cv::Mat dust_transmission(const DegradationConfig &config, cv::Size size) {
  const DustConfig &dust = config.dust;
  cv::Mat transmission(size, CV_32FC1, cv::Scalar(1.0));
  std::mt19937_64 rng = generator(config.seed, Stream::kDust, 0);  // the seed only: dust sits on the mirror
  for (int i = 0; i < dust.count; ++i) {
    // Always four draws per speck, so a speck that does not fit leaves the others in place.
    const double radius_px = uniform(rng, dust.min_radius_px, dust.max_radius_px);
    const double opacity = uniform(rng, dust.min_opacity, dust.max_opacity);
    const double area_draw = uniform01(rng);
    const double angle_rad = uniform(rng, 0.0, 2.0 * std::numbers::pi);
    const double extent_px = radius_px + kDustEdgePx;
    const double rho_min = dust.inner_radius_px + extent_px;
    const double rho_max = dust.outer_radius_px - extent_px;
    if (rho_max < rho_min) continue;
    // Uniform by area in the annulus the whole speck fits in.
    const double rho = std::sqrt(rho_min * rho_min + area_draw * (rho_max * rho_max - rho_min * rho_min));
    const double cu = config.center_u_px + rho * std::cos(angle_rad);
    const double cv = config.center_v_px + rho * std::sin(angle_rad);
    const int u0 = std::max(0, static_cast<int>(std::floor(cu - extent_px)));
    const int u1 = std::min(size.width - 1, static_cast<int>(std::ceil(cu + extent_px)));
    const int v0 = std::max(0, static_cast<int>(std::floor(cv - extent_px)));
    const int v1 = std::min(size.height - 1, static_cast<int>(std::ceil(cv + extent_px)));
    for (int v = v0; v <= v1; ++v) {
      auto *row = transmission.ptr<float>(v);
      for (int u = u0; u <= u1; ++u) {
        const double d = std::hypot(u - cu, v - cv);
        const double coverage = std::clamp((radius_px + kDustEdgePx - d) / kDustEdgePx, 0.0, 1.0);
        row[u] *= static_cast<float>(1.0 - opacity * coverage);
      }
    }
  }
  return transmission;
}

cv::Mat disk_kernel(double radius_px) {
  if (!(radius_px > 0.0)) return {};
  const int half = std::max(0, static_cast<int>(std::ceil(radius_px - 0.5)));
  cv::Mat kernel(2 * half + 1, 2 * half + 1, CV_32FC1);
  const double r2 = radius_px * radius_px;
  double sum = 0.0;
  for (int y = -half; y <= half; ++y) {
    for (int x = -half; x <= half; ++x) {
      int inside = 0;
      for (int sy = 0; sy < kCoverageSamples; ++sy) {
        const double py = y - 0.5 + (sy + 0.5) / kCoverageSamples;
        for (int sx = 0; sx < kCoverageSamples; ++sx) {
          const double px = x - 0.5 + (sx + 0.5) / kCoverageSamples;
          inside += px * px + py * py <= r2 ? 1 : 0;
        }
      }
      const double weight = static_cast<double>(inside) / (kCoverageSamples * kCoverageSamples);
      kernel.at<float>(y + half, x + half) = static_cast<float>(weight);
      sum += weight;
    }
  }
  if (!(sum > 0.0)) return {};  // a disk smaller than one sub-sample: no blur
  kernel /= sum;
  return kernel;
}

}  // namespace omnislam::degrade::detail
