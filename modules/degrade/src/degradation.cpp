#include "omnislam/degrade/degradation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "random.hpp"
#include "static_maps.hpp"

namespace omnislam::degrade {
namespace {

// Poisson-Gaussian sensor noise on a float image in grey levels (DN): variance
// value * 255 / full_well_e (shot noise, Gaussian approximation of Poisson in electrons
// scaled back to DN) + read_noise_dn^2. Box-Muller on two 24-bit uniforms per draw gives
// two normals; the tails are cut at 5.9 sigma.
void add_sensor_noise(cv::Mat &signal_dn, const NoiseConfig &noise, std::mt19937_64 &rng) {
  const auto shot_dn_per_dn = static_cast<float>(255.0 / noise.full_well_e);
  const auto read_variance = static_cast<float>(noise.read_noise_dn * noise.read_noise_dn);
  const auto two_pi = static_cast<float>(2.0 * std::numbers::pi);
  constexpr float kUnit24 = 0x1.0p-24f;
  CV_Assert(signal_dn.isContinuous());
  auto *value = signal_dn.ptr<float>();
  const std::size_t count = signal_dn.total();
  for (std::size_t i = 0; i < count; i += 2) {
    const std::uint64_t bits = rng();
    const float u1 = (static_cast<float>(bits >> 40) + 0.5f) * kUnit24;
    const float u2 = (static_cast<float>((bits >> 16) & 0xffffffULL) + 0.5f) * kUnit24;
    const float radius = std::sqrt(-2.0f * std::log(u1));
    const float normals[2] = {radius * std::cos(two_pi * u2), radius * std::sin(two_pi * u2)};
    for (std::size_t k = 0; k < 2 && i + k < count; ++k) {
      float &v = value[i + k];
      v += std::sqrt(std::max(v, 0.0f) * shot_dn_per_dn + read_variance) * normals[k];
    }
  }
}

}  // namespace

Degrader::Degrader(const DegradationConfig &config, cv::Size image_size)
    : config_(config), size_(image_size) {
  if (size_.width <= 0 || size_.height <= 0) return;
  if (config_.vignetting.enabled) gain_map_ = detail::vignetting_gain(config_, size_);
  if (config_.dust.enabled) {
    const cv::Mat dust = detail::dust_transmission(config_, size_);
    gain_map_ = gain_map_.empty() ? dust : gain_map_.mul(dust);
  }
  if (config_.blur.enabled) blur_kernel_ = detail::disk_kernel(config_.blur.radius_px);
}

Degraded Degrader::apply(const cv::Mat &image_8u_gray, int frame_number) const {
  Degraded out;
  if (image_8u_gray.empty() || image_8u_gray.type() != CV_8UC1) {
    out.error = "degrade: expected a non-empty 8-bit grey image (CV_8UC1)";
    return out;
  }
  if (image_8u_gray.size() != size_) {
    out.error = "degrade: image is " + std::to_string(image_8u_gray.cols) + "x" +
                std::to_string(image_8u_gray.rows) + " px, the degrader was made for " +
                std::to_string(size_.width) + "x" + std::to_string(size_.height);
    return out;
  }
  if (config_.exposure.enabled) {
    std::mt19937_64 rng = detail::generator(config_.seed, detail::Stream::kExposure, frame_number);
    out.exposure_gain = 1.0 + detail::uniform(rng, -config_.exposure.max_change, config_.exposure.max_change);
  }
  const bool analog =
      config_.exposure.enabled || !gain_map_.empty() || !blur_kernel_.empty() || config_.noise.enabled;
  cv::Mat result;
  if (analog) {
    // The light path, in physical order: exposure, vignetting and dust are gains (one
    // multiplication), then the lens blur, then the sensor's noise and 8-bit quantisation.
    cv::Mat signal_dn;
    image_8u_gray.convertTo(signal_dn, CV_32F, out.exposure_gain);
    if (!gain_map_.empty()) cv::multiply(signal_dn, gain_map_, signal_dn);
    if (!blur_kernel_.empty()) {
      cv::Mat blurred;
      cv::filter2D(signal_dn, blurred, -1, blur_kernel_, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT_101);
      signal_dn = blurred;
    }
    if (config_.noise.enabled) {
      std::mt19937_64 rng = detail::generator(config_.seed, detail::Stream::kNoise, frame_number);
      add_sensor_noise(signal_dn, config_.noise, rng);
    }
    signal_dn.convertTo(result, CV_8U);  // rounds to nearest, saturates to 0..255
  } else {
    result = image_8u_gray.clone();
  }
  if (config_.jpeg.enabled) {
    std::vector<std::uint8_t> bytes;
    if (!cv::imencode(".jpg", result, bytes, {cv::IMWRITE_JPEG_QUALITY, config_.jpeg.quality})) {
      out.error = "degrade: JPEG encoding failed";
      return out;
    }
    result = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
    if (result.empty()) {
      out.error = "degrade: JPEG decoding failed";
      return out;
    }
  }
  out.image = result;
  return out;
}

Degraded degrade(const cv::Mat &image_8u_gray, const DegradationConfig &config, int frame_number) {
  return Degrader(config, image_8u_gray.size()).apply(image_8u_gray, frame_number);
}

}  // namespace omnislam::degrade
