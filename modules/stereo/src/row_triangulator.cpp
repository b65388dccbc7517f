#include "omnislam/stereo/row_triangulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

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
  if (!model.config().rig.nominal()) {
    rig_.emplace(Rig{mirror::RigModel(model.config()), mirror::make_panorama_map(model, mirror::Lobe::kInner),
                     mirror::make_panorama_map(model, mirror::Lobe::kOuter)});
  }
}

std::optional<mirror::Ray3> RowTriangulator::rig_ray(mirror::Lobe lobe, int column, float row) const {
  const mirror::PanoramaMap &map = lobe == mirror::Lobe::kInner ? rig_->inner : rig_->outer;
  if (column < 0 || column >= map.columns) return std::nullopt;
  // The panorama interpolates its integer rows linearly, so a fractional row is the same
  // blend of their image positions.
  const int below = std::clamp(static_cast<int>(std::floor(row)), 0, map.rows - 2);
  const double fraction = static_cast<double>(row) - below;
  const auto at = [&](const std::vector<float> &values, int r) {
    return static_cast<double>(values[static_cast<std::size_t>(r) * map.columns + column]);
  };
  const double u = at(map.u_px, below) + fraction * (at(map.u_px, below + 1) - at(map.u_px, below));
  const double v = at(map.v_px, below) + fraction * (at(map.v_px, below + 1) - at(map.v_px, below));
  return rig_->model.back_project(lobe, {u, v});
}

std::optional<mirror::MeridianPoint> RowTriangulator::triangulate(int column, float inner_row,
                                                                  float outer_row) const {
  if (!rig_) return triangulate(inner_row, outer_row);
  const auto inside = [this](float row) { return row >= -0.5f && row <= static_cast<float>(rows_) - 0.5f; };
  if (!inside(inner_row) || !inside(outer_row)) return std::nullopt;
  const std::optional<mirror::Ray3> inner = rig_ray(mirror::Lobe::kInner, column, inner_row);
  const std::optional<mirror::Ray3> outer = rig_ray(mirror::Lobe::kOuter, column, outer_row);
  if (!inner || !outer) return std::nullopt;
  const std::optional<mirror::RayIntersection> meet = mirror::RigModel::intersect(*inner, *outer);
  if (!meet) return std::nullopt;
  return mirror::MeridianPoint{std::hypot(meet->point_m.x(), meet->point_m.y()), meet->point_m.z()};
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
