#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "degrade_helpers.hpp"

using namespace omnislam::degrade;
using namespace omnislam::degrade::test;

namespace {

// Sample mean and standard deviation of (image - level).
cv::Scalar residual_stats(const cv::Mat &image, int level) {
  cv::Mat residual;
  image.convertTo(residual, CV_64F, 1.0, -level);
  cv::Scalar mean, stddev;
  cv::meanStdDev(residual, mean, stddev);
  return {mean[0], stddev[0]};
}

// Largest horizontal step between neighbouring pixels of one row.
double max_row_gradient(const cv::Mat &image, int row) {
  double largest = 0.0;
  for (int u = 1; u < image.cols; ++u) {
    largest = std::max(largest, std::abs(double(image.at<float>(row, u)) - image.at<float>(row, u - 1)));
  }
  return largest;
}

// Share of a pillbox of radius r in the one-pixel-wide column through its centre: the
// largest step of a blurred unit step edge (the disk's line-spread function over a pixel).
double central_column_share(double r) {
  const double x = 0.5;
  const double half_area = x * std::sqrt(r * r - x * x) + r * r * std::asin(x / r);
  return 2.0 * half_area / (std::numbers::pi * r * r);
}

}  // namespace

TEST_CASE("degrade: noise std on a flat image is sqrt(shot + read) within 10%", "[degrade]") {
  for (const auto &[level, full_well_e, read_noise_dn] :
       {std::tuple{128, 6000.0, 2.0}, std::tuple{200, 1000.0, 0.5}, std::tuple{30, 6000.0, 2.0}}) {
    DegradationConfig config = only("noise");
    config.noise.full_well_e = full_well_e;
    config.noise.read_noise_dn = read_noise_dn;
    const Degraded out = degrade(flat(level, 512), config, 1);
    REQUIRE(out.ok());
    const double expected = std::sqrt(level * 255.0 / full_well_e + read_noise_dn * read_noise_dn);
    const cv::Scalar stats = residual_stats(out.image, level);
    CAPTURE(level, full_well_e, read_noise_dn, expected, stats[1]);
    CHECK(stats[1] == Approx(expected).epsilon(0.10));
    CHECK(std::abs(stats[0]) < 0.05);  // zero mean: no bias from rounding
  }
}

TEST_CASE("degrade: vignetting darkens the rim by the configured share within 2%", "[degrade]") {
  const Degraded out = degrade(flat(200), only("vignetting"), 1);
  REQUIRE(out.ok());
  CHECK(out.image.at<std::uint8_t>(511, 511) == 200);
  double ratio_sum = 0.0, model_sum = 0.0;
  int count = 0;
  for (int v = 0; v < 1024; ++v) {
    for (int u = 0; u < 1024; ++u) {
      const double r = radius_px(u, v);
      if (r < 508.0 || r > 512.0) continue;
      ratio_sum += out.image.at<std::uint8_t>(v, u) / 200.0;
      model_sum += 1.0 - 0.30 * (r / 512.0) * (r / 512.0);
      ++count;
    }
  }
  REQUIRE(count > 1000);
  CHECK(ratio_sum / count == Approx(model_sum / count).epsilon(0.02));
  CHECK(ratio_sum / count == Approx(0.70).epsilon(0.02));  // ~30% darker at r = 512 px
}

TEST_CASE("degrade: a 1 px and a 2 px defocus flatten a step edge like a pillbox", "[degrade]") {
  cv::Mat step = flat(50);
  step.colRange(512, 1024).setTo(200);
  for (const double radius : {1.0, 2.0}) {
    DegradationConfig config = only("blur");
    config.blur.radius_px = radius;
    const Degraded out = degrade(step, config, 1);
    REQUIRE(out.ok());
    cv::Mat blurred;
    out.image.convertTo(blurred, CV_32F);
    const double ratio = max_row_gradient(blurred, 300) / 150.0;
    CAPTURE(radius, ratio);
    CHECK(ratio == Approx(central_column_share(radius)).epsilon(0.05));
    CHECK(cv::mean(out.image)[0] == Approx(cv::mean(step)[0]).epsilon(0.001));  // the kernel keeps light
  }
}

TEST_CASE("degrade: exposure stays within +-15% over 200 frames and uses the range", "[degrade]") {
  const Degrader degrader(only("exposure"), {256, 256});
  const cv::Mat image = flat(200, 256);
  double low = 2.0, high = 0.0, sum = 0.0;
  for (int frame = 1; frame <= 200; ++frame) {
    const Degraded out = degrader.apply(image, frame);
    REQUIRE(out.ok());
    const double gain = out.image.at<std::uint8_t>(100, 100) / 200.0;
    CHECK(gain == Approx(out.exposure_gain).margin(0.5 / 200.0 + 1e-9));
    CHECK(out.exposure_gain >= 0.85);
    CHECK(out.exposure_gain <= 1.15);
    low = std::min(low, out.exposure_gain);
    high = std::max(high, out.exposure_gain);
    sum += out.exposure_gain;
  }
  CHECK(low < 0.87);
  CHECK(high > 1.13);
  CHECK(sum / 200.0 == Approx(1.0).margin(0.02));
}

TEST_CASE("degrade: JPEG changes a smooth image but keeps PSNR above 30 dB", "[degrade]") {
  cv::Mat smooth(512, 512, CV_8UC1);
  for (int v = 0; v < smooth.rows; ++v) {
    for (int u = 0; u < smooth.cols; ++u) {
      smooth.at<std::uint8_t>(v, u) =
          cv::saturate_cast<std::uint8_t>(60.0 + 0.2 * u + 40.0 * std::sin(v / 40.0) * std::cos(u / 60.0));
    }
  }
  const Degraded out = degrade(smooth, only("jpeg"), 1);
  REQUIRE(out.ok());
  CHECK_FALSE(identical(out.image, smooth));
  const double psnr_db = cv::PSNR(out.image, smooth);
  CAPTURE(psnr_db);
  CHECK(psnr_db > 30.0);
  CHECK(psnr_db < 60.0);
}

TEST_CASE("degrade: dust darkens only inside the mirror annulus and a small share of pixels", "[degrade]") {
  const Degrader degrader(only("dust"), {1024, 1024});
  const cv::Mat &transmission = degrader.gain_map();
  REQUIRE(transmission.type() == CV_32FC1);
  int darkened = 0;
  float darkest = 1.0f;
  for (int v = 0; v < 1024; ++v) {
    for (int u = 0; u < 1024; ++u) {
      const float t = transmission.at<float>(v, u);
      if (t >= 1.0f) continue;
      ++darkened;
      darkest = std::min(darkest, t);
      const double r = radius_px(u, v);
      CAPTURE(u, v, r);
      CHECK((r >= 62.0 && r <= 512.0));
    }
  }
  // 12 specks of radius 2-6 px plus a 2 px edge: between 12 x pi x 3^2 and 12 x pi x 8^2 px.
  CHECK(darkened > 300);
  CHECK(darkened < 2500);
  CHECK(darkest >= 0.3f - 1e-6f);  // opacity at most 0.7 (overlaps could go lower; seed 1 has none)
  CHECK(darkest < 0.7f);
  const Degraded out = degrader.apply(flat(200), 5);
  REQUIRE(out.ok());
  const double share = cv::countNonZero(out.image < 200) / (1024.0 * 1024.0);
  CHECK(share > 0.0002);
  CHECK(share < 0.003);
}

TEST_CASE("degrade: every factor together keeps a textured image plausible", "[degrade]") {
  cv::Mat image(1024, 1024, CV_8UC1);
  cv::randu(image, 20, 230);
  cv::GaussianBlur(image, image, {0, 0}, 3.0);
  const Degraded out = degrade(image, DegradationConfig{}, 1);
  REQUIRE(out.ok());
  REQUIRE(out.image.type() == CV_8UC1);
  REQUIRE(out.image.size() == image.size());
  const double psnr_db = cv::PSNR(out.image, image);
  CAPTURE(psnr_db, out.exposure_gain);
  CHECK(psnr_db > 12.0);  // exposure and vignetting alone shift grey levels by up to ~30%
  CHECK(psnr_db < 35.0);  // noise of ~3 DN at least
}

TEST_CASE("degrade: bad input is an error result, not an exception", "[degrade]") {
  const Degrader degrader(DegradationConfig{}, {64, 64});
  CHECK_FALSE(degrader.apply(cv::Mat(), 1).ok());
  CHECK_FALSE(degrader.apply(cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(10)), 1).ok());
  CHECK_FALSE(degrader.apply(cv::Mat(64, 64, CV_16UC1, cv::Scalar(10)), 1).ok());
  const Degraded wrong_size = degrader.apply(flat(10, 32), 1);
  CHECK_THAT(wrong_size.error, Catch::Contains("32x32") && Catch::Contains("64x64"));
  CHECK(wrong_size.image.empty());
  CHECK(degrader.apply(flat(10, 64), 1).ok());
}
