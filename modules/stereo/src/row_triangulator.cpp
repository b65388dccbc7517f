#include "omnislam/stereo/row_triangulator.hpp"

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
