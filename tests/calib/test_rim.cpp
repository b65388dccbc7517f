#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "omnislam/calib/circle_fit.hpp"
#include "omnislam/calib/rim.hpp"
#include "omnislam/degrade/degradation.hpp"
#include "omnislam/mirror/mirror_config.hpp"

using omnislam::calib::find_rim;
using omnislam::calib::fit_circle;

namespace {

const std::string kDatasets = OMNISLAM_DEFAULT_DATASETS;

cv::Mat frame(const std::string &dataset, int number) {
  char name[32];
  std::snprintf(name, sizeof name, "/images/%06d.png", number);
  const cv::Mat image = cv::imread(kDatasets + "/" + dataset + name, cv::IMREAD_GRAYSCALE);
  REQUIRE(image.rows == 1024);
  return image;
}

// The rig's axis `du`, `dv` px away from where it was rendered: the whole image moves.
cv::Mat shifted(const cv::Mat &image, double du, double dv) {
  const cv::Matx23d translation(1.0, 0.0, du, 0.0, 1.0, dv);
  cv::Mat out;
  cv::warpAffine(image, out, translation, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
  return out;
}

}  // namespace

TEST_CASE("circle fit: exact points, and points off the circle left out", "[calib][circle]") {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 100; ++i) {
    const double phi = 0.0628 * i;
    points.emplace_back(500.25 + 300.0 * std::cos(phi), 480.75 + 300.0 * std::sin(phi));
  }
  auto fit = fit_circle(points);
  REQUIRE(fit);
  CHECK(fit->centre_px.x() == Approx(500.25).margin(1e-6));
  CHECK(fit->centre_px.y() == Approx(480.75).margin(1e-6));
  CHECK(fit->radius_px == Approx(300.0).margin(1e-6));
  for (int i = 0; i < 20; ++i) points[static_cast<std::size_t>(5 * i)] *= 0.97;  // 20 outliers
  fit = fit_circle(points);
  REQUIRE(fit);
  CHECK(fit->inliers == 80);
  CHECK(fit->centre_px.x() == Approx(500.25).margin(1e-6));
  CHECK(fit->radius_px == Approx(300.0).margin(1e-6));
  CHECK_FALSE(fit_circle(std::vector<Eigen::Vector2d>{{0.0, 0.0}, {1.0, 1.0}}));
}

TEST_CASE("rim method: the centre of rendered frames, moved by known amounts, within 0.15 px",
          "[calib][rim][dataset]") {
  const omnislam::mirror::MirrorConfig camera;  // the designed centre, 511.5
  // Different rooms and floors, noise-free and with every camera factor (the dust specks
  // sit on the mirror, the vignetting darkens the rim).
  const omnislam::degrade::Degrader degrader({}, cv::Size(1024, 1024));
  for (const auto &[dataset, number] : {std::pair{"sim-room-37-real", 1}, std::pair{"office-real", 20},
                                        std::pair{"l-room-1lap-real", 40}, std::pair{"sim-room-37", 5}}) {
    for (const auto &[du, dv] : {std::pair{0.0, 0.0}, std::pair{1.2, -0.8}, std::pair{-4.3, 2.6},
                                 std::pair{3.0, 4.0}, std::pair{-0.35, -4.9}}) {
      for (const bool degraded : {false, true}) {
        cv::Mat image = shifted(frame(dataset, number), du, dv);
        if (degraded) image = degrader.apply(image, number).image;
        const auto estimate = find_rim(image, camera);
        CAPTURE(dataset, du, dv, degraded, estimate.error);
        REQUIRE(estimate.ok());
        CHECK(estimate.rim);
        CHECK(estimate.central);
        CHECK(estimate.centre_px.x() == Approx(511.5 + du).margin(0.15));
        CHECK(estimate.centre_px.y() == Approx(511.5 + dv).margin(0.15));
        CHECK(estimate.centre_sigma_px.maxCoeff() < 0.15);
      }
    }
  }
}

TEST_CASE("rim method: a black image, a featureless one and a wrong type say why", "[calib][rim]") {
  const omnislam::mirror::MirrorConfig camera;
  const cv::Mat black(1024, 1024, CV_8UC1, cv::Scalar(0));
  CHECK_FALSE(find_rim(black, camera).ok());
  CHECK(find_rim(black, camera).error.find("no mirror rim") != std::string::npos);
  const cv::Mat grey(1024, 1024, CV_8UC1, cv::Scalar(128));
  CHECK_FALSE(find_rim(grey, camera).ok());
  cv::Mat noise(1024, 1024, CV_8UC1);
  cv::randu(noise, 0, 256);
  CHECK_FALSE(find_rim(noise, camera).ok());
  CHECK_FALSE(find_rim(cv::Mat(1024, 1024, CV_8UC3, cv::Scalar(0, 0, 0)), camera).ok());
  CHECK_FALSE(find_rim(cv::Mat(), camera).ok());
}

// datasets/sim-room-37-rig: the mirror tilted 0.8 / -0.5 deg and offset 0.7 / -0.4 mm, the
// optical axis at (514.0, 509.5). Its rim and central disc are ~12 and ~14 px off that axis
// (measured fits: (508.38, 487.50) and (524.90, 506.08)); the configured rig predicts them.
TEST_CASE("rim method on a tilted and offset mirror: the circles where the rig puts them, the axis recovered",
          "[calib][rim][rig]") {
  omnislam::mirror::MirrorConfig camera;
  camera.rig.focal_scale = 1.008;
  camera.rig.mirror_dz_mm = 2.5;
  camera.rig.mirror_tilt_x_rad = 0.8 * std::numbers::pi / 180.0;
  camera.rig.mirror_tilt_y_rad = -0.5 * std::numbers::pi / 180.0;
  camera.rig.mirror_offset_x_mm = 0.7;
  camera.rig.mirror_offset_y_mm = -0.4;
  const cv::Mat image = frame("sim-room-37-rig", 1);
  for (const double u : {514.0, 511.5}) {  // the true centre configured, and 3.2 px off it
    camera.center_u_px = u;
    camera.center_v_px = u == 514.0 ? 509.5 : 511.5;
    CAPTURE(camera.center_u_px, camera.center_v_px);
    const auto estimate = find_rim(image, camera);
    REQUIRE(estimate.ok());
    REQUIRE(estimate.rim);
    REQUIRE(estimate.central);
    CHECK(std::abs(estimate.centre_px.x() - 514.0) < 0.05);
    CHECK(std::abs(estimate.centre_px.y() - 509.5) < 0.05);
  }
  camera.center_u_px = 514.0, camera.center_v_px = 509.5;
  const auto predicted = omnislam::calib::predict_rim(camera);
  const auto estimate = find_rim(image, camera);
  CHECK((estimate.rim->centre_px - predicted.rim_centre_px).norm() < 0.05);
  CHECK((estimate.central->centre_px - predicted.central_centre_px).norm() < 0.05);
  CHECK((predicted.rim_centre_px - Eigen::Vector2d(514.0, 509.5)).norm() > 10.0);
  // Read as a designed rig, the same image gives the circles' mean: far from the axis.
  const auto designed = find_rim(image, omnislam::mirror::MirrorConfig{});
  REQUIRE(designed.ok());
  CHECK((designed.centre_px - Eigen::Vector2d(514.0, 509.5)).norm() > 5.0);
}

TEST_CASE("rim prediction of a designed rig is the configured centre", "[calib][rim][rig]") {
  omnislam::mirror::MirrorConfig camera;
  camera.center_u_px = 500.25;
  const auto predicted = omnislam::calib::predict_rim(camera);
  CHECK(predicted.rim_centre_px == Eigen::Vector2d(500.25, 511.5));
  CHECK(predicted.central_centre_px == Eigen::Vector2d(500.25, 511.5));
  camera.rig.focal_scale = 1.0 + 1e-12;  // the traced path, same answer
  const auto traced = omnislam::calib::predict_rim(camera);
  CHECK((traced.rim_centre_px - Eigen::Vector2d(500.25, 511.5)).norm() < 1e-6);
  CHECK(traced.rim_radius_px == Approx(512.0).epsilon(1e-9));
  CHECK((traced.central_centre_px - Eigen::Vector2d(500.25, 511.5)).norm() < 1e-6);
  CHECK(traced.central_radius_px == Approx(62.0).epsilon(1e-9));
}
