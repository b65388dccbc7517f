#include "omnislam/stereo/floor_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace omnislam::stereo {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

float row_or_nan(const std::optional<double> &row) { return row ? static_cast<float>(*row) : kNaN; }

// Range from the axis where `ray` comes down to `height_m` (relative to the pinhole).
double range_at_height(const mirror::MeridianRay &ray, double height_m) {
  return ray.origin.range_m + (ray.origin.height_m - height_m) * std::tan(ray.theta_rad);
}

}  // namespace

FloorGeometry::FloorGeometry(const mirror::MirrorModel &model, double camera_height_m)
    : model_(model),
      camera_height_m_(camera_height_m),
      rows_(model.config().rows_per_lobe),
      inner_radius_offset_px_(static_cast<float>(model.radius_px_of_row(mirror::Lobe::kInner, 0.0))),
      outer_radius_offset_px_(static_cast<float>(model.radius_px_of_row(mirror::Lobe::kOuter, 0.0))) {
  using mirror::Lobe;
  const auto rows = static_cast<std::size_t>(rows_);
  floor_range_m_.assign(rows, kNaN);
  floor_outer_row_.assign(rows, kNaN);
  lowest_outer_row_.assign(rows, kNaN);
  vertical_outer_row_.assign(rows * rows, kNaN);
  std::vector<mirror::MeridianRay> rays;
  for (int row = 0; row < rows_; ++row) {
    rays.push_back(model.back_project(Lobe::kInner, model.radius_px_of_row(Lobe::kInner, row)));
    const double range_m = floor_range_at(row);
    if (!std::isfinite(range_m)) continue;
    floor_range_m_[index(row)] = static_cast<float>(range_m);
    floor_outer_row_[index(row)] = row_or_nan(model.project_row(Lobe::kOuter, {range_m, -camera_height_m}));
    const double lowest_m = -2.0 * camera_height_m;  // a floor one camera height down
    lowest_outer_row_[index(row)] =
        row_or_nan(model.project_row(Lobe::kOuter, {range_at_height(rays.back(), lowest_m), lowest_m}));
  }
  for (int base = 0; base < rows_; ++base) {
    const double wall_m = floor_range_m_[index(base)];
    if (!std::isfinite(wall_m)) continue;
    for (int row = 0; row < base; ++row) {
      const mirror::MeridianRay &ray = rays[index(row)];
      // Inner ray of `row` meets the cylinder range = wall_m (thesis eq. 2-2).
      const double height_m = ray.origin.height_m - (wall_m - ray.origin.range_m) / std::tan(ray.theta_rad);
      vertical_outer_row_[index(base) * rows + index(row)] =
          row_or_nan(model.project_row(Lobe::kOuter, {wall_m, height_m}));
    }
  }
}

float FloorGeometry::row_at(const std::vector<float> &per_row, float inner_row) const {
  if (!(inner_row >= 0.0f) || inner_row > static_cast<float>(rows_ - 1)) return kNaN;
  const int below = std::min(rows_ - 2, static_cast<int>(inner_row));
  const float fraction = inner_row - static_cast<float>(below);
  return per_row[index(below)] + fraction * (per_row[index(below + 1)] - per_row[index(below)]);
}

float FloorGeometry::floor_outer_row_at(float inner_row) const { return row_at(floor_outer_row_, inner_row); }

float FloorGeometry::lowest_outer_row_at(float inner_row) const {
  return row_at(lowest_outer_row_, inner_row);
}

double FloorGeometry::floor_range_at(double inner_row) const {
  using mirror::Lobe;
  const mirror::MeridianRay ray =
      model_.back_project(Lobe::kInner, model_.radius_px_of_row(Lobe::kInner, inner_row));
  if (!(ray.theta_rad < std::numbers::pi / 2.0)) return std::numeric_limits<double>::quiet_NaN();
  return range_at_height(ray, -camera_height_m_);
}

}  // namespace omnislam::stereo
