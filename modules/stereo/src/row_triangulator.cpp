#include "omnislam/stereo/row_triangulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>

#include <Eigen/Geometry>

namespace omnislam::stereo {
namespace {

constexpr int kStepsPerRow = 32;

std::vector<double> theta_table(const mirror::MirrorModel &model, mirror::Lobe lobe, int rows) {
  std::vector<double> theta(static_cast<std::size_t>((rows + 1) * kStepsPerRow + 1));
  for (std::size_t i = 0; i < theta.size(); ++i) {
    const double row = -1.0 + static_cast<double>(i) / kStepsPerRow;
    theta[i] = model.theta_of_radius_px(lobe, model.radius_px_of_row(lobe, row));
  }
  return theta;
}

}  // namespace

RowTriangulator::RowTriangulator(const mirror::MirrorModel &model, TriangulationMethod method)
    : model_(model),
      method_(method),
      rows_(model.config().rows_per_lobe),
      theta_inner_(theta_table(model, mirror::Lobe::kInner, rows_)),
      theta_outer_(theta_table(model, mirror::Lobe::kOuter, rows_)) {
  if (method == TriangulationMethod::kTable) table_.emplace(model);
  if (!model.config().rig.nominal())
    rig_.emplace(Rig{trace_rays(model, mirror::Lobe::kInner), trace_rays(model, mirror::Lobe::kOuter)});
}

RowTriangulator::RayGrid RowTriangulator::trace_rays(const mirror::MirrorModel &model, mirror::Lobe lobe) {
  const mirror::RigModel rig(model.config());
  const mirror::PanoramaMap map = mirror::make_panorama_map(model, lobe);
  RayGrid grid{map.rows, map.columns, {}};
  grid.rays.resize(map.u_px.size());
  for (std::size_t i = 0; i < grid.rays.size(); ++i) {
    const std::optional<mirror::Ray3> ray = rig.back_project(lobe, {map.u_px[i], map.v_px[i]});
    grid.rays[i].setConstant(std::numeric_limits<float>::quiet_NaN());
    if (ray) grid.rays[i] << ray->origin_m.cast<float>(), ray->direction.cast<float>();
  }
  return grid;
}

std::optional<mirror::Ray3> RowTriangulator::rig_ray(mirror::Lobe lobe, double column, double row) const {
  const RayGrid &grid = lobe == mirror::Lobe::kInner ? rig_->inner : rig_->outer;
  // Bilinear between the four pixels around the position: a ray changes smoothly over a
  // pixel (a floor point 1-2 m away triangulates within 30 um, where tracing the
  // interpolated image position gave 8 um; a row of sub-pixel error is ~10 mm).
  const double wrapped = column - grid.columns * std::floor(column / grid.columns);
  const int left = std::min(static_cast<int>(wrapped), grid.columns - 1);
  const int right = (left + 1) % grid.columns;
  const double across = wrapped - left;
  const int below = std::clamp(static_cast<int>(std::floor(row)), 0, grid.rows - 2);
  const double along = row - below;
  const auto at = [&](int r, int c) {
    return grid.rays[static_cast<std::size_t>(r) * grid.columns + c].cast<double>();
  };
  Eigen::Matrix<double, 6, 1> ray = (1.0 - along) * at(below, left) + along * at(below + 1, left);
  if (across != 0.0)
    ray = (1.0 - across) * ray + across * ((1.0 - along) * at(below, right) + along * at(below + 1, right));
  if (!ray.allFinite()) return std::nullopt;
  return mirror::Ray3{ray.head<3>(), ray.tail<3>().normalized()};
}

std::optional<ColumnPoint> RowTriangulator::triangulate(int column, float inner_row, float outer_row,
                                                        float outer_rows_per_column) const {
  if (!rig_) {
    const std::optional<mirror::MeridianPoint> point = triangulate(inner_row, outer_row);
    if (!point) return std::nullopt;
    return ColumnPoint{point->range_m, point->height_m, 0.0};
  }
  const auto inside = [this](float row) { return row >= -0.5f && row <= static_cast<float>(rows_) - 0.5f; };
  if (!inside(inner_row) || !inside(outer_row)) return std::nullopt;
  const std::optional<mirror::Ray3> inner = rig_ray(mirror::Lobe::kInner, column, inner_row);
  if (!inner) return std::nullopt;
  // The outer edge `shift` columns aside, and how far its ray passes beside the inner ray
  // (signed: the triple product is zero when the two rays are coplanar, i.e. they meet).
  const auto outer_at = [&](double shift) {
    return rig_ray(mirror::Lobe::kOuter, column + shift, outer_row + outer_rows_per_column * shift);
  };
  const auto skew = [&](const mirror::Ray3 &outer) {
    return (outer.origin_m - inner->origin_m).dot(inner->direction.cross(outer.direction));
  };
  std::optional<mirror::Ray3> outer = outer_at(0.0);
  if (!outer) return std::nullopt;
  // Secant steps from the column itself and a probe a quarter column aside. A misaligned
  // rig within the bounds (tilt 1 deg, offset 1 mm) moves a point a small fraction
  // of a column; a search that leaves kMaxShift keeps the column's own outer ray.
  constexpr double kProbe = 0.25, kMaxShift = 3.0, kTolerance = 1e-4;
  constexpr int kMaxSteps = 6;
  double shift = 0.0, value = skew(*outer);
  if (const std::optional<mirror::Ray3> probe = outer_at(kProbe)) {
    double last_shift = kProbe, last_value = skew(*probe);
    std::optional<mirror::Ray3> found;
    for (int step = 0; step < kMaxSteps && value != last_value; ++step) {
      const double next = shift - value * (shift - last_shift) / (value - last_value);
      if (!(std::abs(next) <= kMaxShift)) {
        found.reset();
        break;
      }
      found = outer_at(next);
      if (!found) break;
      last_shift = shift;
      last_value = value;
      shift = next;
      value = skew(*found);
      if (std::abs(shift - last_shift) < kTolerance) break;
    }
    if (found) outer = found;
  }
  const std::optional<mirror::RayIntersection> meet = mirror::RigModel::intersect(*inner, *outer);
  if (!meet) return std::nullopt;
  const Eigen::Vector3d &point = meet->point_m;
  const double azimuth = std::atan2(point.y(), point.x());
  return ColumnPoint{
      std::hypot(point.x(), point.y()), point.z(),
      std::remainder(azimuth - mirror::column_azimuth_rad(model_.config(), column), 2.0 * std::numbers::pi)};
}

double RowTriangulator::theta_of_row(mirror::Lobe lobe, float row) const {
  const std::vector<double> &theta = lobe == mirror::Lobe::kInner ? theta_inner_ : theta_outer_;
  const double position = (static_cast<double>(row) + 1.0) * kStepsPerRow;
  const auto index = static_cast<std::size_t>(position);
  const double fraction = position - static_cast<double>(index);
  return theta[index] + fraction * (theta[index + 1] - theta[index]);
}

std::optional<mirror::MeridianPoint> RowTriangulator::triangulate(float inner_row, float outer_row) const {
  const auto inside = [this](float row) { return row >= -0.5f && row <= static_cast<float>(rows_) - 0.5f; };
  if (!inside(inner_row) || !inside(outer_row)) return std::nullopt;
  if (method_ == TriangulationMethod::kTable) {
    return table_->at(static_cast<int>(std::lround(inner_row)), static_cast<int>(std::lround(outer_row)));
  }
  return model_.triangulate(theta_of_row(mirror::Lobe::kInner, inner_row),
                            theta_of_row(mirror::Lobe::kOuter, outer_row));
}

}  // namespace omnislam::stereo
