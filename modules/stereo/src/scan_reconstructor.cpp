#include "omnislam/stereo/scan_reconstructor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <tuple>
#include <utility>

#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/vision/texture.hpp"

namespace omnislam::stereo {
namespace {

// The panorama maps of a misaligned rig resample onto the floor (panorama_maps.hpp).
mirror::MirrorConfig with_floor_reference(mirror::MirrorConfig camera, double camera_height_m) {
  camera.reference_depth_mm = camera_height_m * 1000.0;
  return camera;
}

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kDegreeBins = 360;

LobeStats lobe_stats(const LobeWork &work) {
  LobeStats stats;
  stats.canny_px = work.edges.canny_px;
  stats.fragment_px_removed = work.edges.fragment_px_removed;
  stats.low_threshold = work.edges.low_threshold;
  stats.high_threshold = work.edges.high_threshold;
  stats.noise_high_threshold = work.edges.noise_high_threshold;
  stats.horizontal_px = work.selection.horizontal_px;
  stats.runs = work.selection.runs;
  stats.not_local_max = work.selection.not_local_max;
  stats.low_contrast = work.selection.low_contrast;
  stats.candidates = work.selection.selected;
  return stats;
}

// Thesis Filtro: of each degree of azimuth keep only the point nearest the robot. Returns
// how many points were dropped; the survivors come out in azimuth order.
int keep_nearest_per_degree(std::vector<ScanPoint> &points, std::vector<ScanPoint> &scratch) {
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::array<std::size_t, kDegreeBins> nearest;
  nearest.fill(kNone);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto bin = std::min<std::size_t>(
        kDegreeBins - 1, static_cast<std::size_t>(points[i].azimuth_rad / kTwoPi * kDegreeBins));
    if (nearest[bin] == kNone || points[i].range_m < points[nearest[bin]].range_m) nearest[bin] = i;
  }
  scratch.clear();
  for (const std::size_t index : nearest) {
    if (index != kNone) scratch.push_back(points[index]);
  }
  const auto dropped = static_cast<int>(points.size() - scratch.size());
  std::swap(points, scratch);
  return dropped;
}

}  // namespace

ScanReconstructor::ScanReconstructor(const ScanConfig &config)
    : config_(config),
      model_(with_floor_reference(config.camera, config.camera_height_m)),
      unwarper_(model_),
      limits_(derive_disparity_limits(model_, config.camera_height_m, config.stereo.min_range_m,
                                      config.stereo.max_range_m, config.stereo.disparity_margin_px)),
      triangulator_(model_, config.stereo.triangulation),
      floor_geometry_(model_, config.camera_height_m),
      selection_(config.vision.selection),
      inner_detector_(config.vision.canny),
      outer_detector_(config.vision.canny),
      boundary_finder_(config.stereo.floor) {
  if (floor_boundary()) selection_.max_edges_per_column = config.stereo.floor.max_edges_per_column;
  if (config.vision.selection.blackman_smoothing) blackman_ = vision::blackman_kernel(7);
  for (int column = 0; column < config.camera.columns; ++column) {
    const double azimuth =
        std::fmod(std::fmod(mirror::column_azimuth_rad(config.camera, column), kTwoPi) + kTwoPi, kTwoPi);
    column_azimuth_rad_.push_back(azimuth);
    column_cos_.push_back(std::cos(azimuth));
    column_sin_.push_back(std::sin(azimuth));
  }
  matches_.reserve(static_cast<std::size_t>(config.camera.columns) * 4);
  noise_meter_ = vision::ImageNoiseMeter(
      {{config.camera.center_u_px, config.camera.center_v_px},
       static_cast<double>(config.camera.discard_px),
       static_cast<double>(config.camera.discard_px + 2 * config.camera.rows_per_lobe)});
  if (config.vision.canny.auto_thresholds && config.vision.canny.noise_edges_per_panorama > 0.0)
    measure_noise_gain();
}

void ScanReconstructor::measure_noise_gain() {
  constexpr double kDeviation = 20.0;  // grey levels: far above 8-bit rounding, clipped at 6.4 sigma
  cv::Mat normal(config_.camera.image_height_px, config_.camera.image_width_px, CV_32FC1);
  cv::RNG rng(20261207);
  rng.fill(normal, cv::RNG::NORMAL, 128.0, kDeviation);
  cv::Mat noise, panorama;
  normal.convertTo(noise, CV_8UC1);
  for (const auto lobe : {mirror::Lobe::kInner, mirror::Lobe::kOuter}) {
    unwarper_.unwarp(noise, lobe, panorama);
    vision::EdgeDetector &detector = lobe == mirror::Lobe::kInner ? inner_detector_ : outer_detector_;
    std::vector<float> gain = detector.gradient_noise_per_row(panorama);
    const double pixels = static_cast<double>(panorama.rows) * panorama.cols;
    const auto tail = static_cast<float>(
        std::sqrt(2.0 * std::log(std::max(1.0, pixels / config_.vision.canny.noise_edges_per_panorama))) /
        kDeviation);
    for (float &value : gain) value *= tail;
    (lobe == mirror::Lobe::kInner ? inner_noise_gain_ : outer_noise_gain_) = std::move(gain);
  }
}

LocalScan ScanReconstructor::reconstruct(const cv::Mat &image) {
  LocalScan scan;
  reconstruct(image, scan);
  return scan;
}

void ScanReconstructor::reconstruct(const cv::Mat &image, LocalScan &scan) {
  scan.points.clear();
  scan.stats = {};
  if (!accepts(image)) {
    scan.status = ScanStatus::kBadImage;
    return;
  }
  scan.status = ScanStatus::kOk;
  unwarp(image);      // 1. both lobes -> 225 x 360 panoramas
  detect_edges();     // 2. Canny + removal of tiny fragments
  select_edges();     // 3-4. nearest horizontal edges, local maxima, contrast test
  match();            // 5. DP along every inner/outer column pair
  triangulate(scan);  // 6-7. exact triangulation, cut-offs, one point per degree
}

bool ScanReconstructor::accepts(const cv::Mat &image) const {
  return !image.empty() && image.type() == CV_8UC1 && image.cols == config_.camera.image_width_px &&
         image.rows == config_.camera.image_height_px;
}

void ScanReconstructor::unwarp(const cv::Mat &image) {
  unwarper_.prefetch(image, mirror::Lobe::kInner);
  unwarper_.unwarp(image, mirror::Lobe::kInner, inner_.panorama);
  unwarper_.prefetch(image, mirror::Lobe::kOuter);
  unwarper_.unwarp(image, mirror::Lobe::kOuter, outer_.panorama);
  const double noise_dn = inner_noise_gain_.empty() ? 0.0 : noise_meter_.measure(image);
  inner_.image_noise_dn = noise_dn;
  outer_.image_noise_dn = noise_dn;
}

void ScanReconstructor::detect_edges() {
  for (auto [work, detector, gain] : {std::tuple{&inner_, &inner_detector_, &inner_noise_gain_},
                                      std::tuple{&outer_, &outer_detector_, &outer_noise_gain_}}) {
    noise_floor_.resize(gain->size());
    for (std::size_t row = 0; row < gain->size(); ++row)
      noise_floor_[row] = (*gain)[row] * static_cast<float>(work->image_noise_dn);
    detector->detect(work->panorama, work->edges, noise_floor_);
  }
}

void ScanReconstructor::select_edges() {
  for (LobeWork *work : {&inner_, &outer_}) {
    vision::make_texture(work->panorama, blackman_, work->texture);
    work->selection =
        vision::select_nearest_horizontal_edges(work->edges, work->texture, selection_, work->candidates);
  }
}

void ScanReconstructor::match() {
  matches_.clear();
  match_stats_ = {};
  if (floor_boundary()) {
    boundary_stats_ = boundary_finder_.find(floor_geometry_, inner_.texture, outer_.texture, inner_.edges,
                                            outer_.edges, inner_.candidates, outer_.candidates, limits_,
                                            triangulator_, selection_, boundary_points_, reach_);
    return;
  }
  for (int column = 0; column < inner_.candidates.columns(); ++column) {
    match_column(inner_.candidates.column(column), outer_.candidates.column(column), column, inner_.texture,
                 outer_.texture, limits_, selection_, config_.stereo, matches_, match_stats_);
  }
}

void ScanReconstructor::swap_lobes(LobeWork &inner, LobeWork &outer) noexcept {
  std::swap(inner_, inner);
  std::swap(outer_, outer);
}

void ScanReconstructor::triangulate(LocalScan &scan) {
  scan.stats.inner = lobe_stats(inner_);
  scan.stats.image_noise_dn = static_cast<float>(inner_.image_noise_dn);
  scan.stats.outer = lobe_stats(outer_);
  scan.stats.admissible_pairs = match_stats_.admissible_pairs;
  scan.stats.matched = match_stats_.matched;
  scan.stats.occluded_inner = match_stats_.occluded_inner;
  scan.stats.occluded_outer = match_stats_.occluded_outer;
  if (floor_boundary()) {
    build_boundary_scan(scan);
  } else {
    build_scan(matches_, scan);
  }
}

double ScanReconstructor::stereo_range_per_px(int column, float inner_row, float outer_row,
                                              double range_m) const {
  // Range moved by one pixel of `row`, from the rows half a pixel either side.
  auto per_px = [&](auto &&range_at, float row) {
    const std::optional<double> below = range_at(row - 0.5f), above = range_at(row + 0.5f);
    if (below && above) return *above - *below;
    if (below) return 2.0 * (range_m - *below);
    if (above) return 2.0 * (*above - range_m);
    return std::numeric_limits<double>::infinity();
  };
  auto range_of = [](const std::optional<ColumnPoint> &point) {
    return point ? std::optional<double>(point->range_m) : std::nullopt;
  };
  const double inner = per_px(
      [&](float row) { return range_of(triangulator_.triangulate(column, row, outer_row)); }, inner_row);
  const double outer = per_px(
      [&](float row) { return range_of(triangulator_.triangulate(column, inner_row, row)); }, outer_row);
  return std::hypot(inner, outer);
}

double ScanReconstructor::floor_range_per_px(float inner_row) const {
  return std::abs(floor_geometry_.floor_range_at(inner_row + 0.5) -
                  floor_geometry_.floor_range_at(inner_row - 0.5));
}

void ScanReconstructor::add_point(int column, double range_m, double height_m, double azimuth_shift_rad,
                                  float inner_row, float outer_row, bool floor_ranged, bool elevated,
                                  LocalScan &scan) {
  if (range_m < config_.stereo.near_cutoff_m || range_m > config_.stereo.far_cutoff_m) {
    ++scan.stats.outside_cutoffs;
    return;
  }
  const double range_per_px_m = floor_ranged ? floor_range_per_px(inner_row)
                                             : stereo_range_per_px(column, inner_row, outer_row, range_m);
  const auto c = static_cast<std::size_t>(column);
  double azimuth = column_azimuth_rad_[c], cos_azimuth = column_cos_[c], sin_azimuth = column_sin_[c];
  if (azimuth_shift_rad != 0.0) {
    azimuth = std::fmod(azimuth + azimuth_shift_rad + kTwoPi, kTwoPi);
    cos_azimuth = std::cos(azimuth);
    sin_azimuth = std::sin(azimuth);
  }
  scan.points.push_back({azimuth, range_m, range_m * cos_azimuth, range_m * sin_azimuth,
                         config_.camera_height_m + height_m, inner_row, outer_row, column,
                         static_cast<float>(range_per_px_m), floor_ranged, elevated});
}

void ScanReconstructor::build_boundary_scan(LocalScan &scan) {
  scan.points.clear();
  scan.stats.matched = static_cast<int>(boundary_points_.size());
  scan.stats.floor_texture_edges = boundary_stats_.floor_texture;
  scan.stats.floor_contacts = boundary_stats_.floor_contacts;
  scan.stats.undecided = boundary_stats_.undecided;
  scan.stats.elevated = boundary_stats_.elevated;
  scan.stats.unexplained = boundary_stats_.unexplained;
  scan.stats.noise_scale = boundary_stats_.noise_scale;
  scan.stats.twin_spread_px = boundary_stats_.twin_spread_px;
  for (const BoundaryPoint &point : boundary_points_) {
    add_point(point.column, point.range_m, point.height_m, point.azimuth_shift_rad, point.inner_row,
              point.outer_row, point.floor_ranged, point.elevated, scan);
  }
  // One boundary per column already; the per-degree filter matters only for finer panoramas.
  if (config_.stereo.one_point_per_degree)
    scan.stats.filtered_out = keep_nearest_per_degree(scan.points, filtered_);
  scan.stats.points = static_cast<int>(scan.points.size());
  scan.free_range_m = reach_.free_m;
  scan.drop_range_m = reach_.drop_m;
  scan.drop_lower_range_m = reach_.lower_m;
  scan.stats.drops = boundary_stats_.drops;
}

void ScanReconstructor::build_scan(const std::vector<RowMatch> &matches, LocalScan &scan) {
  const StereoConfig &stereo = config_.stereo;
  scan.points.clear();
  scan.free_range_m.clear();
  scan.drop_range_m.clear();
  scan.drop_lower_range_m.clear();
  for (const RowMatch &match : matches) {
    const auto point = triangulator_.triangulate(match.column, match.inner_row, match.outer_row);
    if (!point) {
      ++scan.stats.no_intersection;
      continue;
    }
    add_point(match.column, point->range_m, point->height_m, point->azimuth_shift_rad, match.inner_row,
              match.outer_row, false, false, scan);
  }
  if (stereo.one_point_per_degree) scan.stats.filtered_out = keep_nearest_per_degree(scan.points, filtered_);
  scan.stats.points = static_cast<int>(scan.points.size());
}

}  // namespace omnislam::stereo
