#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/floor_geometry.hpp"
#include "omnislam/stereo/floor_twins.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorModel;
using omnislam::stereo::FloorGeometry;

TEST_CASE("floor geometry: the outer row of every floor point agrees with the mirror model",
          "[stereo][floor]") {
  const MirrorModel model;
  for (const double height_m : {0.8, 1.0, 1.3}) {
    const FloorGeometry geometry(model, height_m);
    int seen = 0;
    for (int row = 0; row < geometry.rows(); ++row) {
      const float range_m = geometry.floor_range_m(row);
      if (!std::isfinite(range_m)) continue;
      // The inner lobe sees the floor point at this very row.
      const auto inner = model.project_row(Lobe::kInner, {range_m, -height_m});
      REQUIRE(inner);
      CHECK(*inner == Approx(row).margin(1e-4));
      const auto outer = model.project_row(Lobe::kOuter, {range_m, -height_m});
      if (!outer) continue;
      ++seen;
      CHECK(geometry.floor_outer_row(row) == Approx(*outer).margin(1e-4));
      // Triangulating the pair returns the floor point.
      const auto point = model.triangulate_rows(row, geometry.floor_outer_row(row));
      REQUIRE(point);
      CHECK(point->height_m == Approx(-height_m).margin(1e-3));
    }
    CHECK(seen > 150);
  }
}

TEST_CASE("floor geometry: a vertical surface on the floor is seen at its base's range", "[stereo][floor]") {
  const MirrorModel model;
  const FloorGeometry geometry(model, 1.0);
  int checked = 0;
  for (int base = 60; base < 220; base += 20) {
    const double wall_m = geometry.floor_range_m(base);
    for (int row = base - 40; row < base; row += 5) {
      const float outer = geometry.vertical_outer_row(row, base);
      if (!std::isfinite(outer)) continue;
      const auto point = model.triangulate_rows(row, outer);
      REQUIRE(point);
      CHECK(point->range_m == Approx(wall_m).epsilon(1e-4));
      CHECK(point->height_m > -1.0);  // above the floor
      ++checked;
    }
    // Undefined at or below the base row.
    CHECK(std::isnan(geometry.vertical_outer_row(base, base)));
  }
  CHECK(checked > 40);
}

TEST_CASE(
    "floor geometry: a floor one camera height down is seen below the floor's row, a lower floor between",
    "[stereo][floor]") {
  const MirrorModel model;
  const double height_m = 1.05;
  const FloorGeometry geometry(model, height_m);
  int checked = 0;
  for (int row = 40; row < 220; row += 20) {
    const auto inner_row = static_cast<float>(row);
    const float floor_outer = geometry.floor_outer_row_at(inner_row);
    const float lowest_outer = geometry.lowest_outer_row_at(inner_row);
    if (!std::isfinite(floor_outer) || !std::isfinite(lowest_outer)) continue;
    // The lowest floor's pair triangulates one camera height under the floor.
    const auto lowest = model.triangulate_rows(row, lowest_outer);
    REQUIRE(lowest);
    CHECK(lowest->height_m == Approx(-2.0 * height_m).epsilon(1e-3));
    // A step 0.18 m down along the same inner ray lies between the floor's row and it.
    const auto ray = model.back_project(Lobe::kInner, model.radius_px_of_row(Lobe::kInner, row));
    const double range_m =
        ray.origin.range_m + (ray.origin.height_m + height_m + 0.18) * std::tan(ray.theta_rad);
    const auto step_outer = model.project_row(Lobe::kOuter, {range_m, -height_m - 0.18});
    REQUIRE(step_outer);
    CHECK(*step_outer < floor_outer);
    CHECK(*step_outer > lowest_outer);
    ++checked;
  }
  CHECK(checked >= 6);
}

TEST_CASE("floor boundary on the convention image: one point per column at most, free ranges",
          "[stereo][floor]") {
  const cv::Mat image = cv::imread(OMNISLAM_CONVENTION_IMAGE, cv::IMREAD_GRAYSCALE);
  REQUIRE_FALSE(image.empty());
  omnislam::stereo::ScanReconstructor reconstructor;
  const omnislam::stereo::LocalScan scan = reconstructor.reconstruct(image);
  REQUIRE(scan.status == omnislam::stereo::ScanStatus::kOk);
  REQUIRE(scan.free_range_m.size() == 360u);
  CHECK(scan.points.size() > 100u);
  CHECK(scan.points.size() <= 360u);
  int contacts = 0;
  for (const auto &point : scan.points) {
    const auto column = static_cast<std::size_t>(point.azimuth_rad * 180.0 / M_PI);
    const float free_m = scan.free_range_m[column];
    // A floor contact: the floor was seen up to it. An edge above the floor: only as far as
    // the floor was seen in front of it, if at all.
    if (!point.elevated) {
      REQUIRE(std::isfinite(free_m));
      ++contacts;
    }
    if (std::isfinite(free_m)) CHECK(free_m <= point.range_m + 1e-6);  // never free beyond the boundary
  }
  CHECK(contacts > 100);

  // The thesis's selection stays available and gives no free ranges.
  omnislam::stereo::ScanConfig thesis;
  thesis.stereo.boundary = omnislam::stereo::BoundaryMethod::kNearestEdge;
  omnislam::stereo::ScanReconstructor nearest(thesis);
  const omnislam::stereo::LocalScan nearest_scan = nearest.reconstruct(image);
  CHECK(nearest_scan.free_range_m.empty());
  CHECK(nearest_scan.points.size() > 100u);
}

TEST_CASE("floor contacts with unambiguous twins lie on the floor by stereo", "[stereo][floor][level]") {
  const cv::Mat image = cv::imread(OMNISLAM_CONVENTION_IMAGE, cv::IMREAD_GRAYSCALE);
  REQUIRE_FALSE(image.empty());
  omnislam::stereo::ScanReconstructor reconstructor;
  const omnislam::stereo::LocalScan scan = reconstructor.reconstruct(image);
  REQUIRE(scan.status == omnislam::stereo::ScanStatus::kOk);
  constexpr double kDegree = M_PI / 180.0;
  const auto contacts = omnislam::stereo::unambiguous_floor_contacts(reconstructor, scan, 1.0 * kDegree);
  CHECK(contacts.size() > 50u);
  // Stereo puts them on the floor 1 m down (walls 3 m away: ~13 mm of height error each).
  std::vector<double> errors;
  for (const Eigen::Vector3d &p : contacts) errors.push_back(p.z() + 1.0);
  const auto middle = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
  std::nth_element(errors.begin(), middle, errors.end());
  const double median = *middle;
  for (double &e : errors) e = std::abs(e - median);
  std::nth_element(errors.begin(), middle, errors.end());
  CAPTURE(contacts.size(), median, *middle);
  CHECK(std::abs(median) < 0.01);  // measured +4.6 mm
  CHECK(*middle < 0.02);           // measured 6.9 mm
}

TEST_CASE("a frame of pure sensor noise gives no scan, and the convention image keeps its walls under noise",
          "[stereo][floor][noise]") {
  cv::Mat normal(1024, 1024, CV_32FC1), noise;
  cv::RNG rng(29);
  rng.fill(normal, cv::RNG::NORMAL, 128.0, 10.0);
  normal.convertTo(noise, CV_8UC1);
  omnislam::stereo::ScanReconstructor reconstructor;
  const omnislam::stereo::LocalScan nothing = reconstructor.reconstruct(noise);
  CHECK(nothing.stats.image_noise_dn == Approx(10.0).epsilon(0.1));
  // 263 floor contacts when Canny's thresholds ignored the noise.
  CHECK(nothing.points.empty());
  CHECK(nothing.stats.inner.noise_high_threshold > nothing.stats.inner.high_threshold);

  const cv::Mat image = cv::imread(OMNISLAM_CONVENTION_IMAGE, cv::IMREAD_GRAYSCALE);
  REQUIRE_FALSE(image.empty());
  const omnislam::stereo::LocalScan clean = reconstructor.reconstruct(image);
  CHECK(clean.stats.image_noise_dn < 1.0f);
  CHECK(clean.stats.inner.noise_high_threshold == 0.0);  // the image's own thresholds stand
  cv::Mat noisy_float, noisy;
  image.convertTo(noisy_float, CV_32FC1);
  rng.fill(normal, cv::RNG::NORMAL, 0.0, 10.0);
  noisy_float += normal;
  noisy_float.convertTo(noisy, CV_8UC1);
  const omnislam::stereo::LocalScan walls = reconstructor.reconstruct(noisy);
  INFO("points: clean " << clean.points.size() << ", noisy " << walls.points.size());
  CHECK(walls.points.size() > clean.points.size() / 2);
}
