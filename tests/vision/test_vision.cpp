#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/vision/edge_detector.hpp"
#include "omnislam/vision/edge_selection.hpp"
#include "omnislam/vision/image_noise.hpp"
#include "omnislam/vision/panorama_unwarper.hpp"
#include "omnislam/vision/ray_subpixel.hpp"
#include "omnislam/vision/texture.hpp"

using omnislam::mirror::Lobe;
using omnislam::mirror::MirrorModel;
using namespace omnislam::vision;

namespace {

const std::string kConventionImage = OMNISLAM_CONVENTION_IMAGE;

// A panorama-sized image: dark below `boundary_row` in every column, light above.
cv::Mat step_panorama(double boundary_row) {
  cv::Mat pano(225, 360, CV_8UC1);
  for (int row = 0; row < pano.rows; ++row) {
    const double light = std::clamp(boundary_row - row + 0.5, 0.0, 1.0);  // area coverage
    pano.row(row).setTo(static_cast<int>(std::lround(90 + 110 * light)));
  }
  return pano;
}

// A steep step, as a wall seen obliquely makes it: in column c the floor (light, below) meets
// a darker band (above) at row boundary(c) = 120 + 2.5 (c - 180), and the step's contrast
// falls off along it (the light at the wall's base fading with distance), so each column's
// neighbours on one side have the stronger edge. Pixels are area-averaged along the column.
double steep_boundary(int column) { return 120.0 + 2.5 * (column - 180); }
cv::Mat steep_step_panorama() {
  cv::Mat pano(225, 360, CV_8UC1, cv::Scalar(60));
  for (int column = 150; column < 211; ++column) {
    const double contrast = 140.0 * std::exp(-(column - 150) / 12.0) + 20.0;
    for (int row = 0; row < pano.rows; ++row) {
      const double floor_share = std::clamp(row + 0.5 - steep_boundary(column), 0.0, 1.0);
      pano.at<std::uint8_t>(row, column) =
          static_cast<std::uint8_t>(std::lround(60.0 + contrast * floor_share));
    }
  }
  return pano;
}

// A panorama's edges, texture and selected candidates, as the scan reconstructor makes them.
struct Selected {
  EdgeImage edges;
  cv::Mat texture;
  ColumnEdges candidates;
};
Selected select_edges(const cv::Mat &pano, const EdgeSelectionConfig &config) {
  Selected selected;
  EdgeDetector().detect(pano, selected.edges);
  make_texture(pano, {}, selected.texture);
  select_nearest_horizontal_edges(selected.edges, selected.texture, config, selected.candidates);
  return selected;
}

}  // namespace

TEST_CASE("unwarp + edges find the convention image's floor-wall boundary at its model rows",
          "[vision][convention]") {
  const MirrorModel model;
  const PanoramaUnwarper unwarper(model);
  const cv::Mat image = cv::imread(kConventionImage, cv::IMREAD_GRAYSCALE);
  REQUIRE(image.rows == 1024);
  EdgeDetector detector;
  EdgeSelectionConfig config;
  // README of the reference: along +x the boundary is at inner row 79.40, outer row 90.45.
  for (const auto &[lobe, expected] : {std::pair{Lobe::kInner, 79.40}, std::pair{Lobe::kOuter, 90.45}}) {
    cv::Mat panorama, texture;
    unwarper.unwarp(image, lobe, panorama);
    REQUIRE(panorama.rows == 225);
    REQUIRE(panorama.cols == 360);
    EdgeImage edges;
    detector.detect(panorama, edges);
    make_texture(panorama, {}, texture);
    ColumnEdges candidates;
    const SelectionStats stats = select_nearest_horizontal_edges(edges, texture, config, candidates);
    CHECK(stats.selected > 300);
    for (int column : {0, 359}) {  // azimuth 0.5 and 359.5 deg: wall x = 3 m, 1 m below
      CAPTURE(column, expected);
      REQUIRE(candidates.column(column).size() == 1);
      CHECK(candidates.column(column)[0].row_subpx == Approx(expected).margin(0.1));
    }
  }
}

TEST_CASE("the prefetch covers every pixel a lobe's samples read, and only the lobe's part of the frame",
          "[vision][unwarp]") {
  omnislam::mirror::MirrorConfig off_centre;  // the outer lobe's rim crosses the image border
  off_centre.center_u_px = 470.0;
  off_centre.center_v_px = 545.25;
  for (const auto &config : {omnislam::mirror::MirrorConfig{}, off_centre}) {
    const MirrorModel model(config);
    const PanoramaUnwarper unwarper(model);
    for (const Lobe lobe : {Lobe::kInner, Lobe::kOuter}) {
      const omnislam::mirror::PanoramaMap map = omnislam::mirror::make_panorama_map(model, lobe);
      const cv::Mat u(map.rows, map.columns, CV_32FC1, const_cast<float *>(map.u_px.data()));
      const cv::Mat v(map.rows, map.columns, CV_32FC1, const_cast<float *>(map.v_px.data()));
      cv::Mat xy, fraction;
      cv::convertMaps(u, v, xy, fraction, CV_16SC2);
      cv::Mat covered(config.image_height_px, config.image_width_px, CV_8UC1, cv::Scalar(0));
      for (const PanoramaUnwarper::Span &span : unwarper.spans(lobe)) {
        REQUIRE(span.row >= 0);
        REQUIRE(span.row < covered.rows);
        REQUIRE(span.first >= 0);
        REQUIRE(span.first <= span.last);
        REQUIRE(span.last < covered.cols);
        covered.row(span.row).colRange(span.first, span.last + 1).setTo(1);
      }
      int missed = 0;
      for (int row = 0; row < xy.rows; ++row) {
        for (int column = 0; column < xy.cols; ++column) {
          const cv::Vec2s position = xy.at<cv::Vec2s>(row, column);
          for (int dy = 0; dy <= 1; ++dy) {
            for (int dx = 0; dx <= 1; ++dx) {
              const int x = position[0] + dx, y = position[1] + dy;
              if (x >= 0 && x < covered.cols && y >= 0 && y < covered.rows)
                missed += static_cast<int>(covered.at<std::uint8_t>(y, x) == 0);
            }
          }
        }
      }
      CHECK(missed == 0);
      // The inner lobe reads a disk, the outer lobe a ring: neither needs the whole frame.
      CHECK(cv::countNonZero(covered) < covered.total() * (lobe == Lobe::kInner ? 0.4 : 0.8));
    }
  }
}

TEST_CASE("Canny thresholds: automatic choice has a floor, fixed ones are used as given", "[vision][canny]") {
  const cv::Mat pano = step_panorama(100.3);
  EdgeImage automatic, fixed;
  EdgeDetector(CannyConfig{}).detect(pano, automatic);
  CHECK(automatic.high_threshold == Approx(24.0));  // uniform rows: the quantile is ~0
  CHECK(automatic.low_threshold == Approx(0.4 * 24.0));
  CHECK(automatic.canny_px >= 360);  // the step, across every column
  CannyConfig config;
  config.auto_thresholds = false;
  config.high_threshold = 5000.0;
  config.low_threshold = 4000.0;
  EdgeDetector(config).detect(pano, fixed);
  CHECK(fixed.high_threshold == 5000.0);
  CHECK(fixed.canny_px == 0);
}

TEST_CASE("edges are cv::Canny's (L2) on a textured, noisy panorama and on the convention image",
          "[vision][canny]") {
  cv::Mat textured(225, 360, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(textured, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(textured, textured, cv::Size(5, 5), 1.5);  // tile-sized blobs, not pure noise
  cv::Mat noise(textured.size(), CV_8UC1);
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  cv::add(textured, noise, textured);
  cv::rectangle(textured, cv::Rect(0, 120, 360, 105), cv::Scalar(40), cv::FILLED);  // a long step
  cv::Mat convention;
  PanoramaUnwarper(MirrorModel{})
      .unwarp(cv::imread(kConventionImage, cv::IMREAD_GRAYSCALE), Lobe::kInner, convention);
  CannyConfig config;
  config.min_fragment_px = 0;  // Canny's own output
  for (const cv::Mat &panorama : {textured, convention}) {
    EdgeImage edges;
    EdgeDetector(config).detect(panorama, edges);
    cv::Mat expected, differ;
    cv::Canny(edges.grad_col, edges.grad_row, expected, edges.low_threshold, edges.high_threshold, true);
    cv::compare(expected, edges.edges, differ, cv::CMP_NE);
    CHECK(cv::countNonZero(expected) > 1000);
    CHECK(edges.canny_px == cv::countNonZero(expected));
    CHECK(cv::countNonZero(differ) == 0);
  }
}

TEST_CASE("tiny edge fragments are removed, long edges kept", "[vision][canny]") {
  cv::Mat pano(225, 360, CV_8UC1, cv::Scalar(100));
  cv::rectangle(pano, cv::Rect(50, 100, 2, 2), cv::Scalar(220), cv::FILLED);   // a speck
  cv::rectangle(pano, cv::Rect(0, 150, 360, 75), cv::Scalar(30), cv::FILLED);  // a long step
  CannyConfig config;
  config.min_fragment_px = 20;
  EdgeImage edges;
  EdgeDetector(config).detect(pano, edges);
  CHECK(edges.fragment_px_removed > 0);
  CHECK(cv::countNonZero(edges.edges(cv::Rect(40, 90, 25, 25))) == 0);
  CHECK(cv::countNonZero(edges.edges.row(149)) + cv::countNonZero(edges.edges.row(150)) >= 300);
}

TEST_CASE("fragment removal drops exactly the 8-connected Canny components below the size",
          "[vision][canny]") {
  cv::Mat textured(225, 360, CV_8UC1);
  cv::RNG rng(11);
  rng.fill(textured, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(textured, textured, cv::Size(5, 5), 1.5);
  cv::Mat noise(textured.size(), CV_8UC1);
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  cv::add(textured, noise, textured);
  CannyConfig config;
  config.min_fragment_px = 0;
  EdgeImage all;
  EdgeDetector(config).detect(textured, all);
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(all.edges, labels, stats, centroids, 8, CV_32S);
  for (const int min_size : {2, 6, 20}) {
    cv::Mat expected = cv::Mat::zeros(all.edges.size(), CV_8UC1);
    int removed = 0, fragments = 0;
    for (int label = 1; label < count; ++label) {
      const int area = stats.at<int>(label, cv::CC_STAT_AREA);
      if (area >= min_size) {
        expected.setTo(255, labels == label);
      } else {
        removed += area;
        ++fragments;
      }
    }
    config.min_fragment_px = min_size;
    EdgeImage kept;
    EdgeDetector(config).detect(textured, kept);
    cv::Mat differ;
    cv::compare(expected, kept.edges, differ, cv::CMP_NE);
    CHECK(fragments > 0);
    CHECK(cv::countNonZero(differ) == 0);
    CHECK(kept.canny_px == all.canny_px);
    CHECK(kept.fragment_px_removed == removed);
  }
}

TEST_CASE("edge selection: horizontal only, nearest (bottom) first, capped per column",
          "[vision][selection]") {
  cv::Mat pano(225, 360, CV_8UC1, cv::Scalar(60));
  for (int band = 0; band < 5; ++band) {  // horizontal steps at rows 40, 70, ..., 160
    cv::rectangle(pano, cv::Rect(0, 40 + 30 * band, 180, 15), cv::Scalar(200), cv::FILLED);
  }
  cv::rectangle(pano, cv::Rect(270, 0, 90, 225), cv::Scalar(200), cv::FILLED);  // vertical step at column 270
  EdgeSelectionConfig config;
  config.max_edges_per_column = 3;
  const ColumnEdges candidates = select_edges(pano, config).candidates;
  const auto column = candidates.column(90);
  REQUIRE(column.size() == 3);
  // Bottom-up: the lower boundary of the lowest band (row 174.5 between 174 and 175), ...
  CHECK(column[0].row_subpx == Approx(174.5).margin(0.35));
  CHECK(column[1].row_subpx == Approx(159.5).margin(0.35));
  CHECK(column[2].row_subpx == Approx(144.5).margin(0.35));
  CHECK(column[0].row > column[1].row);
  for (int c = 265; c < 275; ++c) CHECK(candidates.column(c).empty());  // the vertical edge is dropped
  CHECK(candidates.column(220).empty());                                // uniform: nothing
}

TEST_CASE("relative contrast test rejects faint steps", "[vision][selection]") {
  cv::Mat faint(225, 360, CV_8UC1, cv::Scalar(200));
  faint.rowRange(0, 100).setTo(cv::Scalar(215));  // (215 - 200) / ~207 = 7% < 15%
  EdgeImage edges;
  CannyConfig canny;
  canny.auto_thresholds = false;
  canny.high_threshold = 10.0;
  canny.low_threshold = 5.0;
  EdgeDetector(canny).detect(faint, edges);
  cv::Mat texture;
  make_texture(faint, {}, texture);
  ColumnEdges candidates;
  const SelectionStats stats =
      select_nearest_horizontal_edges(edges, texture, EdgeSelectionConfig{}, candidates);
  CHECK(stats.runs >= 360);
  CHECK(stats.low_contrast == stats.runs - stats.not_local_max);
  CHECK(stats.selected == 0);
  CHECK(relative_contrast(texture, 100, 5, 3, 1) == Approx(15.0 / (200.0 + 15.0 * 9.0 / 21.0)).epsilon(1e-3));
}

TEST_CASE("Blackman kernel: 7 taps, symmetric, normalised", "[vision][texture]") {
  const cv::Mat kernel = blackman_kernel(7);
  REQUIRE(kernel.total() == 7u);
  CHECK(cv::sum(kernel)[0] == Approx(1.0));
  CHECK(kernel.at<float>(0) == Approx(0.0).margin(1e-6));
  CHECK(kernel.at<float>(1) == Approx(kernel.at<float>(5)));
  CHECK(kernel.at<float>(3) > kernel.at<float>(2));
  cv::Mat flat(225, 360, CV_8UC1, cv::Scalar(255)), texture;
  make_texture(flat, kernel, texture);
  CHECK(texture.type() == CV_32FC1);
  CHECK(texture.at<float>(100, 100) == Approx(1.0f));
}

TEST_CASE(
    "an edge's row along its ray: a steep edge whose contrast changes along it is found where it crosses",
    "[vision][selection]") {
  EdgeSelectionConfig config;
  config.min_relative_contrast = 0.0;
  const auto [edges, texture, candidates] = select_edges(steep_step_panorama(), config);
  double canny_error = 0.0, ray_error = 0.0;
  int found = 0;
  for (int column = 160; column <= 200; ++column) {
    const double truth = steep_boundary(column);
    for (const EdgePoint &edge : candidates.column(column)) {
      if (std::abs(edge.row - truth) > 2.0) continue;
      const float ray = ray_subpixel_row(texture, edges, edge, column, 1.0);
      CHECK(ray == Approx(truth).margin(0.1));
      CHECK(ray_subpixel_row(texture, edges, edge, column, 0.0) ==
            edge.row_subpx);  // off: the edge's own row
      canny_error += std::abs(edge.row_subpx - truth);
      ray_error += std::abs(ray - truth);
      ++found;
    }
  }
  REQUIRE(found >= 30);
  // Canny's gradient mixes the neighbouring columns' rows, weighted by their contrast.
  CHECK(canny_error / found > 0.15);
  CHECK(ray_error / found < 0.05);
}

namespace {

// A frame-sized scene with plenty of structure: tiles of random grey with sharp edges, a
// shading ramp across the frame and a few bright lines, inside the mirror's annulus.
cv::Mat structured_frame() {
  cv::Mat frame(1024, 1024, CV_8UC1);
  cv::RNG rng(7);
  for (int y = 0; y < frame.rows; y += 48)
    for (int x = 0; x < frame.cols; x += 64)
      frame(cv::Rect(x, y, std::min(64, frame.cols - x), std::min(48, frame.rows - y)))
          .setTo(rng.uniform(40, 200));
  cv::Mat ramp(frame.size(), CV_8UC1);
  for (int y = 0; y < frame.rows; ++y) ramp.row(y).setTo(y / 32);
  frame += ramp;
  for (int k = 0; k < 20; ++k)
    cv::line(frame, {rng.uniform(0, 1024), rng.uniform(0, 1024)},
             {rng.uniform(0, 1024), rng.uniform(0, 1024)}, cv::Scalar(230), 2, cv::LINE_AA);
  return frame;
}

cv::Mat with_noise(const cv::Mat &frame, double deviation, std::uint64_t seed) {
  cv::Mat noise(frame.size(), CV_32FC1), noisy;
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, deviation);
  frame.convertTo(noisy, CV_32FC1);
  noisy += noise;
  noisy.convertTo(noisy, CV_8UC1);
  return noisy;
}

}  // namespace

TEST_CASE("image noise: a frame's noise deviation, whatever its edges, texture and shading",
          "[vision][noise]") {
  const cv::Mat scene = structured_frame();
  const ImageAnnulus annulus;
  // Noise-free: the edges, tiles and ramp alone read as (almost) no noise.
  CHECK(ImageNoiseMeter(annulus).measure(scene) < 0.6);
  for (const double deviation : {2.0, 5.0, 10.0, 20.0}) {
    INFO("noise deviation " << deviation);
    const double estimate = ImageNoiseMeter(annulus).measure(with_noise(scene, deviation, 11));
    CHECK(estimate == Approx(deviation).epsilon(0.1).margin(0.3));  // 8-bit rounding adds 0.29
  }
  // Only the annulus counts: noise outside it does not, inside it does.
  cv::Mat outside = scene.clone();
  cv::Mat noisy = with_noise(scene, 20.0, 3);
  cv::Mat ring_mask(scene.size(), CV_8UC1, cv::Scalar(255));
  cv::circle(ring_mask, {512, 512}, 500, cv::Scalar(0), cv::FILLED);
  noisy.copyTo(outside, ring_mask);
  CHECK(ImageNoiseMeter(annulus).measure(outside) < 0.6);
  CHECK(ImageNoiseMeter(annulus).measure(cv::Mat::zeros(1024, 1024, CV_8UC1)) == 0.0);
  CHECK(ImageNoiseMeter({{511.5, 511.5}, 0.0, 0.0}).measure(noisy) == 0.0);  // an empty annulus
}

TEST_CASE("Canny's noise floor: a row's high threshold rises to what the noise reaches there",
          "[vision][canny][noise]") {
  // A panorama of pure noise (deviation 10) over a step of 60 grey levels at row 150.
  cv::Mat pano = step_panorama(150.0);
  cv::Mat noise(pano.size(), CV_32FC1), noisy;
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 10.0);
  pano.convertTo(noisy, CV_32FC1);
  noisy += noise;
  noisy.convertTo(noisy, CV_8UC1);

  EdgeDetector detector;
  // The gain per grey level of noise, from a panorama of pure noise of deviation 20.
  cv::Mat unit(pano.size(), CV_32FC1), unit8;
  rng.fill(unit, cv::RNG::NORMAL, 128.0, 20.0);
  unit.convertTo(unit8, CV_8UC1);
  const std::vector<float> scale = detector.gradient_noise_per_row(unit8);
  REQUIRE(scale.size() == static_cast<std::size_t>(pano.rows));
  // A Rayleigh scale per row, the same in every row of a panorama of white noise, and in
  // proportion to the noise's deviation.
  std::vector<float> sorted = scale;
  std::sort(sorted.begin(), sorted.end());
  const float median = sorted[sorted.size() / 2];
  for (std::size_t row = 5; row + 5 < scale.size(); ++row)  // the smoothing replicates the border rows
    CHECK(scale[row] == Approx(median).epsilon(0.15));      // a median of 1,800 samples
  cv::Mat half8;
  unit8.convertTo(half8, CV_8UC1, 0.5, 64.0);  // deviation 10
  const std::vector<float> half_scale = detector.gradient_noise_per_row(half8);
  CHECK(half_scale[100] == Approx(scale[100] / 2.0f).epsilon(0.1));

  const float tail = std::sqrt(2.0f * std::log(static_cast<float>(pano.total())));  // one pixel per panorama
  std::vector<float> floor(scale.size());
  for (std::size_t row = 0; row < floor.size(); ++row) floor[row] = scale[row] / 20.0f * 10.0f * tail;

  EdgeImage plain, floored;
  detector.detect(noisy, plain);
  detector.detect(noisy, floored, floor);
  const auto edges_off_the_step = [](const EdgeImage &edges) {
    int count = 0;
    for (int row = 0; row < edges.edges.rows; ++row)
      if (std::abs(row - 150) > 3) count += cv::countNonZero(edges.edges.row(row));
    return count;
  };
  INFO("noise edges without the floor " << edges_off_the_step(plain) << ", with it "
                                        << edges_off_the_step(floored));
  CHECK(edges_off_the_step(plain) > 500);
  CHECK(edges_off_the_step(floored) < 100);
  CHECK(floored.noise_high_threshold > floored.high_threshold);
  // The step stands out of the noise: still found in nearly every column.
  CHECK(cv::countNonZero(floored.edges.rowRange(147, 154)) > 0.95 * pano.cols);
  // Fixed thresholds ignore the floor.
  CannyConfig fixed;
  fixed.auto_thresholds = false;
  EdgeDetector fixed_detector(fixed);
  EdgeImage as_given;
  fixed_detector.detect(noisy, as_given, floor);
  CHECK(as_given.high_threshold == fixed.high_threshold);
  CHECK(as_given.noise_high_threshold == 0.0);
}
