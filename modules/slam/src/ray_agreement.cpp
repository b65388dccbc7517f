#include "omnislam/slam/ray_agreement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace omnislam::slam {
namespace {

constexpr int kBins = 360;
constexpr double kBinRad = 2.0 * std::numbers::pi / kBins;

int bin_of(double bearing_rad) {
  const int bin = static_cast<int>(std::floor((bearing_rad + std::numbers::pi) / kBinRad));
  return ((bin % kBins) + kBins) % kBins;
}

}  // namespace

RayAgreement ray_agreement(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                           std::span<const Point2> map_points, double margin_m, double point_radius_m) {
  RayAgreement agreement;
  if (scan_base.empty()) return agreement;
  double farthest_m = 0.0;
  for (const Point2 &p : scan_base) farthest_m = std::max(farthest_m, p.norm());
  // The nearest map structure per bearing, within the scan's reach.
  std::array<double, kBins> nearest_m;
  nearest_m.fill(std::numeric_limits<double>::infinity());
  const Eigen::Isometry2d T_base_map = T_map_base.inverse();
  const double reach_m = farthest_m + margin_m;
  for (const Point2 &point : map_points) {
    const Point2 p = T_base_map * point;
    const double range_m = p.norm();
    if (range_m > reach_m || range_m <= point_radius_m) continue;
    const double half_width_rad = std::asin(point_radius_m / range_m);
    const double bearing_rad = std::atan2(p.y(), p.x());
    const int first = bin_of(bearing_rad - half_width_rad), last = bin_of(bearing_rad + half_width_rad);
    for (int bin = first;; bin = (bin + 1) % kBins) {
      nearest_m[static_cast<std::size_t>(bin)] = std::min(nearest_m[static_cast<std::size_t>(bin)], range_m);
      if (bin == last) break;
    }
  }
  for (const Point2 &p : scan_base) {
    const double mapped_m = nearest_m[static_cast<std::size_t>(bin_of(std::atan2(p.y(), p.x())))];
    const double range_m = p.norm();
    if (mapped_m < range_m - margin_m) {
      ++agreement.seen_through;
    } else if (mapped_m <= range_m + margin_m) {
      ++agreement.confirmed;
    } else {
      ++agreement.unseen;
    }
  }
  return agreement;
}

}  // namespace omnislam::slam
