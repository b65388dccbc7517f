#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "omnislam/stereo/scan_reconstructor.hpp"

using namespace omnislam::stereo;

namespace {

const std::string kConventionImage = OMNISLAM_CONVENTION_IMAGE;
constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace

TEST_CASE("the convention image gives the x = +3 m wall at its true range", "[stereo][scan][convention]") {
  ScanReconstructor reconstructor;
  const cv::Mat image = cv::imread(kConventionImage, cv::IMREAD_GRAYSCALE);
  const LocalScan scan = reconstructor.reconstruct(image);
  REQUIRE(scan.status == ScanStatus::kOk);
  CHECK(scan.stats.points > 250);  // of 360 degrees; the blue cube is nearly invisible in grey
  CHECK(scan.stats.points == static_cast<int>(scan.points.size()));
  CHECK(scan.stats.matched >= scan.stats.points);
  CHECK(scan.stats.inner.candidates >= scan.stats.matched);
  int wall_points = 0;
  for (const ScanPoint &p : scan.points) {
    // Azimuths -8..8 deg see only the wall x = 3 (the red cube starts at 13 deg).
    const double azimuth = std::remainder(p.azimuth_rad, 2.0 * std::numbers::pi);
    if (std::abs(azimuth) > 8.0 * kDeg) continue;
    ++wall_points;
    CAPTURE(azimuth / kDeg, p.range_m, p.inner_row, p.outer_row);
    CHECK(p.x_m == Approx(3.0).margin(0.06));  // 2% at 3 m
    CHECK(p.z_m == Approx(0.0).margin(0.03));  // the floor contact
    CHECK(p.y_m == Approx(p.range_m * std::sin(azimuth)).margin(1e-9));
    const double wall_range_m = 3.0 / std::cos(azimuth);
    const auto inner =
        reconstructor.model().project_row(omnislam::mirror::Lobe::kInner, {wall_range_m, -1.0});
    const auto outer =
        reconstructor.model().project_row(omnislam::mirror::Lobe::kOuter, {wall_range_m, -1.0});
    REQUIRE(inner);
    REQUIRE(outer);
    CHECK(p.inner_row == Approx(*inner).margin(0.15));
    CHECK(p.outer_row - p.inner_row == Approx(*outer - *inner).margin(0.2));
  }
  CHECK(wall_points == 16);
}

TEST_CASE("the red cube's front face is found at x = 1.3 m", "[stereo][scan][convention]") {
  ScanReconstructor reconstructor;
  const LocalScan scan = reconstructor.reconstruct(cv::imread(kConventionImage, cv::IMREAD_GRAYSCALE));
  int cube_points = 0;
  for (const ScanPoint &p : scan.points) {
    const double azimuth_deg = p.azimuth_rad / kDeg;
    if (azimuth_deg < 15.0 || azimuth_deg > 26.0) continue;  // front face x = 1.3, y in 0.35..0.63
    ++cube_points;
    CAPTURE(azimuth_deg, p.range_m, p.z_m);
    CHECK(p.x_m == Approx(1.3).margin(0.04));
  }
  CHECK(cube_points >= 9);
}

TEST_CASE("integer rows and the thesis table are less accurate than sub-pixel + exact", "[stereo][scan]") {
  const cv::Mat image = cv::imread(kConventionImage, cv::IMREAD_GRAYSCALE);
  const auto wall_error = [&image](SubpixelMethod subpixel, TriangulationMethod triangulation) {
    ScanConfig config;  // the DP stereo path: the floor boundary ranges by the floor plane
    config.stereo.boundary = omnislam::stereo::BoundaryMethod::kNearestEdge;
    config.stereo.subpixel = subpixel;
    config.stereo.triangulation = triangulation;
    ScanReconstructor reconstructor(config);
    double sum = 0.0;
    int count = 0;
    for (const ScanPoint &p : reconstructor.reconstruct(image).points) {
      if (std::abs(std::remainder(p.azimuth_rad, 2.0 * std::numbers::pi)) > 8.0 * kDeg) continue;
      sum += std::abs(p.x_m - 3.0);
      ++count;
    }
    return count > 0 ? sum / count : 1e9;
  };
  const double subpixel = wall_error(SubpixelMethod::kEdgePeak, TriangulationMethod::kExact);
  const double integer = wall_error(SubpixelMethod::kNone, TriangulationMethod::kExact);
  const double table = wall_error(SubpixelMethod::kNone, TriangulationMethod::kTable);
  CHECK(subpixel < 0.03);
  CHECK(integer > subpixel);
  CHECK(table == Approx(integer).margin(1e-6));  // both read the same integer rows
}

TEST_CASE("bad images are reported, not thrown", "[stereo][scan]") {
  ScanReconstructor reconstructor;
  CHECK(reconstructor.reconstruct(cv::Mat()).status == ScanStatus::kBadImage);
  CHECK(reconstructor.reconstruct(cv::Mat(512, 512, CV_8UC1, cv::Scalar(0))).status == ScanStatus::kBadImage);
  CHECK(reconstructor.reconstruct(cv::Mat(1024, 1024, CV_8UC3, cv::Scalar(0))).status ==
        ScanStatus::kBadImage);
  const LocalScan black = reconstructor.reconstruct(cv::Mat(1024, 1024, CV_8UC1, cv::Scalar(0)));
  CHECK(black.status == ScanStatus::kOk);
  CHECK(black.points.empty());
}
