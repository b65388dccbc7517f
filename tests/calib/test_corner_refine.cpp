#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "corner_refine.hpp"

using omnislam::calib::detail::refine_corner;

namespace {

// A chessboard imaged through the affine map pixel = corner + axes * (board squares),
// box-filtered over each pixel (8 x 8 samples: a rendered, antialiased image), blurred and
// noisy, 8-bit.
cv::Mat board_image(const Eigen::Vector2d &corner_px, const Eigen::Matrix2d &axes_px, double blur_px,
                    double noise_grey, unsigned seed) {
  const Eigen::Matrix2d to_board = axes_px.inverse();
  cv::Mat image(64, 64, CV_64F);
  constexpr int kSub = 8;
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      double sum = 0.0;
      for (int i = 0; i < kSub; ++i) {
        for (int j = 0; j < kSub; ++j) {
          const Eigen::Vector2d at(u - 0.5 + (j + 0.5) / kSub, v - 0.5 + (i + 0.5) / kSub);
          const Eigen::Vector2d board = to_board * (at - corner_px);
          const auto parity = static_cast<long>(std::floor(board.x()) + std::floor(board.y())) & 1L;
          sum += parity != 0 ? 40.0 : 200.0;
        }
      }
      image.at<double>(v, u) = sum / (kSub * kSub);
    }
  }
  if (blur_px > 0.0) cv::GaussianBlur(image, image, cv::Size(0, 0), blur_px);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, noise_grey);
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) image.at<double>(v, u) += noise(random);
  cv::Mat grey;
  image.convertTo(grey, CV_8U);
  return grey;
}

}  // namespace

TEST_CASE("corner refinement: a squeezed, sheared, blurred and noisy corner to a few hundredths of a pixel",
          "[calib][target][refine]") {
  // Squares as the outer lobe shows a board on the floor (~4-5 px one way, ~12-18 the
  // other, slanted) and as the inner lobe shows a held one.
  const Eigen::Matrix2d squeezed = (Eigen::Matrix2d() << 14.0, -1.5, 3.0, 4.5).finished();
  const Eigen::Matrix2d square = (Eigen::Matrix2d() << 11.0, -3.0, 2.5, 10.0).finished();
  const Eigen::Vector2d truth(31.37, 30.81);
  int case_index = 0;
  for (const Eigen::Matrix2d &axes : {squeezed, square}) {
    for (const double blur_px : {0.0, 0.6}) {
      const cv::Mat image = board_image(truth, axes, blur_px, 2.0, static_cast<unsigned>(++case_index));
      // The detector's corner a few tenths off, and the axes from its neighbours a little off.
      const Eigen::Matrix2d rough_axes = axes * Eigen::Rotation2Dd(0.05).toRotationMatrix();
      const auto refined = refine_corner(image, truth + Eigen::Vector2d(0.3, -0.2), rough_axes);
      CAPTURE(case_index, blur_px);
      REQUIRE(refined);
      // Measured: 0.004-0.017 px.
      CHECK((*refined - truth).norm() < 0.03);
    }
  }
}

TEST_CASE("corner refinement: no corner to fit is said, not invented", "[calib][target][refine]") {
  const Eigen::Matrix2d axes = (Eigen::Matrix2d() << 11.0, 0.0, 0.0, 10.0).finished();
  const cv::Mat flat(64, 64, CV_8UC1, cv::Scalar(128));
  CHECK_FALSE(refine_corner(flat, {31.0, 31.0}, axes));
  const cv::Mat image = board_image({31.37, 30.81}, axes, 0.5, 1.0, 7);
  CHECK_FALSE(refine_corner(image, {2.0, 31.0}, axes));  // the window leaves the image
  const Eigen::Matrix2d tiny = (Eigen::Matrix2d() << 2.0, 0.0, 0.0, 2.0).finished();
  CHECK_FALSE(refine_corner(image, {31.37, 30.81}, tiny));  // too few pixels
  CHECK_FALSE(refine_corner(image, {31.0, 31.0}, Eigen::Matrix2d::Zero()));
  CHECK_FALSE(refine_corner(cv::Mat(), {31.0, 31.0}, axes));
}
