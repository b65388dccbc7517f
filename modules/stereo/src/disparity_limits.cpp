#include "omnislam/stereo/disparity_limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace omnislam::stereo {
namespace {

constexpr int kSamplesPerRay = 64;

DisparityBand band_of_inner_row(const mirror::MirrorModel &model, int inner_row, double camera_height_m,
                                double min_range_m, double max_range_m) {
  using mirror::Lobe;
  const mirror::MeridianRay ray =
      model.back_project(Lobe::kInner, model.radius_px_of_row(Lobe::kInner, inner_row));
  const double tan_theta = std::tan(ray.theta_rad);
  // The inner ray meets the floor (height -camera_height_m) at this range; beyond it the
  // ray is underground. Rays at or above the horizon never meet it.
  const double floor_range_m = ray.theta_rad < std::numbers::pi / 2.0
                                   ? ray.origin.range_m + (ray.origin.height_m + camera_height_m) * tan_theta
                                   : std::numeric_limits<double>::infinity();
  const double far_m = std::min(max_range_m, floor_range_m);
  DisparityBand band{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()};
  if (!(far_m > min_range_m)) return {};
  // d is monotonic along an inner ray (mirror.md sec. 8), but sampling keeps this
  // independent of that and of the visibility clipping at both ends.
  for (int i = 0; i <= kSamplesPerRay; ++i) {
    const double range_m = min_range_m + (far_m - min_range_m) * i / kSamplesPerRay;
    const double height_m = ray.origin.height_m - (range_m - ray.origin.range_m) / tan_theta;
    const auto outer_row = model.project_row(Lobe::kOuter, {range_m, height_m});
    if (!outer_row) continue;
    const auto disparity = static_cast<float>(*outer_row - inner_row);
    band.min_px = std::min(band.min_px, disparity);
    band.max_px = std::max(band.max_px, disparity);
  }
  return band.max_px >= band.min_px ? band : DisparityBand{};
}

}  // namespace

DisparityLimits derive_disparity_limits(const mirror::MirrorModel &model, double camera_height_m,
                                        double min_range_m, double max_range_m, double margin_px) {
  DisparityLimits limits;
  const int rows = model.config().rows_per_lobe;
  limits.per_inner_row.resize(static_cast<std::size_t>(rows));
  limits.min_px = std::numeric_limits<float>::max();
  limits.max_px = std::numeric_limits<float>::lowest();
  const auto margin = static_cast<float>(margin_px);
  for (int row = 0; row < rows; ++row) {
    DisparityBand band = band_of_inner_row(model, row, camera_height_m, min_range_m, max_range_m);
    if (band.max_px < band.min_px) continue;
    band.min_px -= margin;
    band.max_px += margin;
    limits.per_inner_row[static_cast<std::size_t>(row)] = band;
    limits.min_px = std::min(limits.min_px, band.min_px);
    limits.max_px = std::max(limits.max_px, band.max_px);
  }
  if (limits.max_px < limits.min_px) limits.min_px = limits.max_px = 0.0f;
  return limits;
}

}  // namespace omnislam::stereo
