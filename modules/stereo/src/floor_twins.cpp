#include "omnislam/stereo/floor_twins.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "omnislam/mirror/panorama_maps.hpp"

namespace omnislam::stereo {
namespace {

int polarity(const vision::EdgeImage &edges, int row, int column) {
  return edges.grad_row.at<std::int16_t>(row, column) >= 0 ? 1 : -1;
}

// The outer row of the point on the inner ray of `inner_row` at `height_m` (nullopt where the
// outer lobe does not see it).
std::optional<double> outer_row_at_height(const mirror::MirrorModel &model, double inner_row,
                                          double height_m) {
  const mirror::MeridianRay ray =
      model.back_project(mirror::Lobe::kInner, model.radius_px_of_row(mirror::Lobe::kInner, inner_row));
  const double down = ray.origin.height_m - height_m;
  if (!(down > 0.0)) return std::nullopt;
  const mirror::MeridianPoint point{ray.origin.range_m + down * std::tan(ray.theta_rad), height_m};
  return model.project_row(mirror::Lobe::kOuter, point);
}

}  // namespace

std::vector<Eigen::Vector3d> unambiguous_floor_contacts(const ScanReconstructor &reconstructor,
                                                        const LocalScan &scan, double max_tilt_rad) {
  const mirror::MirrorModel &model = reconstructor.model();
  const double floor_m = -reconstructor.config().camera_height_m;
  const LobeWork &inner = reconstructor.inner();
  const LobeWork &outer = reconstructor.outer();
  const int capacity = reconstructor.config().stereo.floor.max_edges_per_column;
  std::vector<Eigen::Vector3d> contacts;
  for (const ScanPoint &p : scan.points) {
    if (p.elevated) continue;
    // The inner edge the contact lies on (its ray-refined row is within a row of it).
    const auto inner_column = inner.candidates.column(p.column);
    const auto edge =
        std::min_element(inner_column.begin(), inner_column.end(), [&](const auto &a, const auto &b) {
          return std::abs(a.row_subpx - p.inner_row) < std::abs(b.row_subpx - p.inner_row);
        });
    if (edge == inner_column.end()) continue;
    const int sign = polarity(inner.edges, edge->row, p.column);
    // Where the floor puts the twin, tilted either way by the largest tilt allowed.
    const double reach_m = p.range_m * std::tan(max_tilt_rad);
    const std::optional<double> low = outer_row_at_height(model, p.inner_row, floor_m - reach_m);
    const std::optional<double> high = outer_row_at_height(model, p.inner_row, floor_m + reach_m);
    if (!low || !high) continue;
    const double first = std::min(*low, *high), last = std::max(*low, *high);
    // The candidates run from the robot outwards (rows falling) up to the column's capacity:
    // a full column that stops inside the window may hide a second edge there.
    const auto outer_column = outer.candidates.column(p.column);
    if (static_cast<int>(outer_column.size()) >= capacity && !outer_column.empty() &&
        outer_column.back().row_subpx > first)
      continue;
    const vision::EdgePoint *twin = nullptr;
    int found = 0;
    for (const vision::EdgePoint &candidate : outer_column) {
      if (candidate.row_subpx < first || candidate.row_subpx > last) continue;
      if (polarity(outer.edges, candidate.row, p.column) != sign) continue;
      twin = &candidate;
      ++found;
    }
    if (found != 1) continue;
    const std::optional<ColumnPoint> point =
        reconstructor.triangulator().triangulate(p.column, p.inner_row, twin->row_subpx);
    if (!point) continue;
    const double azimuth = mirror::column_azimuth_rad(model.config(), p.column) + point->azimuth_shift_rad;
    contacts.emplace_back(point->range_m * std::cos(azimuth), point->range_m * std::sin(azimuth),
                          point->height_m);
  }
  return contacts;
}

}  // namespace omnislam::stereo
