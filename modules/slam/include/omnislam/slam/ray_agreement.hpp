#pragma once

#include <Eigen/Geometry>
#include <span>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Whether a scan at a pose agrees with a map along its rays: each scan point is what its
/// ray met first, so the ray crossed free floor up to it. A map point on the ray well short
/// of the scan point is structure the ray would have met: the scan sees through the map
/// there, which no true pose can (the map's walls stand where they were mapped). A map
/// point at the scan point's range confirms it; none at all along the ray is a part the map
/// has not seen (new territory). Telling the two apart is what separates a robot exploring
/// (a scan mostly new, the rest agreeing) from a robot that is not where it believes (a
/// scan that crosses the map's walls).

namespace omnislam::slam {

struct RayAgreement {
  int confirmed = 0;     ///< scan points with map structure at their range along the ray
  int seen_through = 0;  ///< scan points whose ray crosses map structure well short of them
  int unseen = 0;        ///< scan points whose ray meets no map structure up to them

  /// More of the scan sees through the map than wrong points explain: of the points the map
  /// says something about (confirmed or seen through), a greater share than `outlier_share`
  /// (the front-end's wrong points and what changed since the map) crosses mapped structure.
  /// Along a corridor a wrong pose still agrees with both side walls; only the rays to what
  /// differs (an end wall, a box) see through, so the share, not a majority, decides.
  [[nodiscard]] bool contradicts(double outlier_share) const {
    return seen_through > outlier_share * (confirmed + seen_through);
  }
};

/// Compares the scan (base_link) at `T_map_base` with the map points along its rays, one
/// bearing bin per degree. A map point covers the bins its `point_radius_m` spans at its
/// range (half the map's spacing: a ray passing a wall's end or a box's corner must not
/// count as crossing it); a scan point is confirmed when the nearest map structure in its
/// bin lies within `margin_m` of its range, seen through when it lies nearer than that.
[[nodiscard]] RayAgreement ray_agreement(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                         std::span<const Point2> map_points, double margin_m,
                                         double point_radius_m);

}  // namespace omnislam::slam
