#include "scan_truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "omnislam/io/image_file.hpp"

namespace omnislam::test {

std::optional<double> ray_cast_m(const std::vector<io::FloorplanSegment> &segments, double x_m, double y_m,
                                 double heading_rad) {
  const double dx = std::cos(heading_rad), dy = std::sin(heading_rad);
  std::optional<double> best;
  for (const io::FloorplanSegment &s : segments) {
    // Solve origin + t (dx, dy) = p1 + u (p2 - p1) for t > 0, u in [0, 1].
    const double ex = s.x2_m - s.x1_m, ey = s.y2_m - s.y1_m;
    const double denominator = dx * ey - dy * ex;
    if (std::abs(denominator) < 1e-12) continue;
    const double wx = s.x1_m - x_m, wy = s.y1_m - y_m;
    const double t = (wx * ey - wy * ex) / denominator;
    const double u = (wx * dy - wy * dx) / denominator;
    if (t > 0.0 && u >= 0.0 && u <= 1.0 && (!best || t < *best)) best = t;
  }
  return best;
}

double distance_to_segments_m(const std::vector<io::FloorplanSegment> &segments, double x_m, double y_m) {
  double best = std::numeric_limits<double>::infinity();
  for (const io::FloorplanSegment &s : segments) {
    const double ex = s.x2_m - s.x1_m, ey = s.y2_m - s.y1_m;
    const double length2 = ex * ex + ey * ey;
    const double u =
        length2 > 0.0 ? std::clamp(((x_m - s.x1_m) * ex + (y_m - s.y1_m) * ey) / length2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::hypot(s.x1_m + u * ex - x_m, s.y1_m + u * ey - y_m));
  }
  return best;
}

void ScanAccuracy::add(const stereo::LocalScan &scan, const Pose2 &pose,
                       const std::vector<io::FloorplanSegment> &segments) {
  ++frames;
  const double c = std::cos(pose.yaw_rad), s = std::sin(pose.yaw_rad);
  std::vector<bool> degree_has_point(360, false);
  for (const stereo::ScanPoint &p : scan.points) {
    ++points;
    const auto truth = ray_cast_m(segments, pose.x_m, pose.y_m, pose.yaw_rad + p.azimuth_rad);
    if (truth) relative_range_errors.push_back(std::abs(p.range_m - *truth) / *truth);
    const double x = pose.x_m + c * p.x_m - s * p.y_m, y = pose.y_m + s * p.x_m + c * p.y_m;
    if (distance_to_segments_m(segments, x, y) <= segment_tolerance_m) ++points_near_segment;
    const int degree = static_cast<int>(p.azimuth_rad * 180.0 / std::numbers::pi);
    degree_has_point[static_cast<std::size_t>(std::clamp(degree, 0, 359))] = true;
  }
  for (int degree = 0; degree < 360; ++degree) {
    const double azimuth = (degree + 0.5) * std::numbers::pi / 180.0;
    const auto truth = ray_cast_m(segments, pose.x_m, pose.y_m, pose.yaw_rad + azimuth);
    if (!truth || *truth > coverage_range_m) continue;
    ++coverable_degrees;
    if (degree_has_point[static_cast<std::size_t>(degree)]) ++covered_degrees;
  }
  const int free_columns = static_cast<int>(scan.free_range_m.size());
  for (int column = 0; column < free_columns; ++column) {
    ++columns;
    const float free_m = scan.free_range_m[static_cast<std::size_t>(column)];
    if (!std::isfinite(free_m)) continue;
    ++free_known;
    const double azimuth = (column + 0.5) * 2.0 * std::numbers::pi / free_columns;
    const auto truth = ray_cast_m(segments, pose.x_m, pose.y_m, pose.yaw_rad + azimuth);
    if (truth && free_m > *truth + segment_tolerance_m) ++free_beyond_truth;
  }
}

double ScanAccuracy::free_known_share() const {
  return columns > 0 ? static_cast<double>(free_known) / columns : 0.0;
}

double ScanAccuracy::free_overclaim_share() const {
  return free_known > 0 ? static_cast<double>(free_beyond_truth) / free_known : 0.0;
}

double ScanAccuracy::quantile_relative_error(double q) const {
  if (relative_range_errors.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::vector<double> sorted = relative_range_errors;
  const auto index = static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(index), sorted.end());
  return sorted[index];
}

double ScanAccuracy::median_relative_error() const { return quantile_relative_error(0.5); }

double ScanAccuracy::near_segment_share() const {
  return points > 0 ? static_cast<double>(points_near_segment) / points : 0.0;
}

double ScanAccuracy::coverage() const {
  return coverable_degrees > 0 ? static_cast<double>(covered_degrees) / coverable_degrees : 0.0;
}

std::string ScanAccuracy::summary() const {
  char text[400];
  std::snprintf(text, sizeof text,
                "%d frames, %d points (%.1f per frame): median relative range error %.2f%% (p90 %.2f%%), "
                "%.1f%% of points within %.2f m of the floor plan, coverage %.1f%% of %d degrees with a "
                "structure within %.1f m",
                frames, points, frames > 0 ? static_cast<double>(points) / frames : 0.0,
                100.0 * median_relative_error(), 100.0 * quantile_relative_error(0.9),
                100.0 * near_segment_share(), segment_tolerance_m, 100.0 * coverage(), coverable_degrees,
                coverage_range_m);
  std::string out = text;
  if (columns > 0) {
    std::snprintf(text, sizeof text,
                  "; free range known in %.1f%% of columns, beyond the plan in %.1f%% of those",
                  100.0 * free_known_share(), 100.0 * free_overclaim_share());
    out += text;
  }
  return out;
}

TruthDataset load_truth_dataset(const std::filesystem::path &dir) {
  TruthDataset data;
  data.info = io::read_dataset_info(dir);
  const std::vector<io::StampedPose> poses = io::read_tum_file(data.info.groundtruth);
  if (static_cast<int>(poses.size()) < data.info.frames) {
    throw std::runtime_error(data.info.groundtruth.string() + ": fewer poses than frames");
  }
  data.segments = io::read_floorplan_csv(data.info.floorplan);
  for (int frame = 1; frame <= data.info.frames; ++frame) {
    data.images.push_back(io::read_camera_image(data.info.image(frame), data.info.camera));
    const io::StampedPose &pose = poses[static_cast<std::size_t>(frame - 1)];
    data.poses.push_back({pose.x_m, pose.y_m, pose.yaw_rad()});
  }
  return data;
}

}  // namespace omnislam::test
