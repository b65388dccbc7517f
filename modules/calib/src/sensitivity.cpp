#include "omnislam/calib/sensitivity.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include <numbers>

#include "omnislam/calib/rig_fit.hpp"
#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/mirror/rig_model.hpp"
#include "omnislam/stereo/floor_geometry.hpp"

namespace omnislam::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kCentreStepPx = 1.0;
constexpr double kFocalStep = 0.001;  // 0.1%
constexpr double kLevelTiltStepRad = 0.1 * std::numbers::pi / 180.0;

struct Radii {
  double inner_px = kNaN;
  double outer_px = kNaN;
};

// Range errors when the rig images the point at `rig` radii and the configured model reads them.
RangeSensitivity row_for(const std::string &parameter, const std::string &step,
                         const mirror::MirrorModel &model, double camera_height_m,
                         const std::function<Radii(const mirror::MeridianPoint &)> &rig) {
  using mirror::Lobe;
  const stereo::FloorGeometry floor(model, camera_height_m);
  RangeSensitivity row{parameter, step, {}, {}};
  for (std::size_t i = 0; i < kSensitivityRangesM.size(); ++i) {
    const double range_m = kSensitivityRangesM[i];
    const Radii radii = rig({range_m, -camera_height_m});
    const double inner_row = model.row_of_radius_px(Lobe::kInner, radii.inner_px);
    const double outer_row = model.row_of_radius_px(Lobe::kOuter, radii.outer_px);
    row.floor_plane_m[i] = std::abs(floor.floor_range_at(inner_row) - range_m);
    const std::optional<mirror::MeridianPoint> stereo = model.triangulate_rows(inner_row, outer_row);
    row.stereo_m[i] = stereo ? std::abs(stereo->range_m - range_m) : kNaN;
  }
  return row;
}

Radii project(const mirror::MirrorModel &model, const mirror::MeridianPoint &point) {
  return {model.project_radius_px(mirror::Lobe::kInner, point).value_or(kNaN),
          model.project_radius_px(mirror::Lobe::kOuter, point).value_or(kNaN)};
}

constexpr int kAzimuths = 8;
// Steps of the derivatives: a tenth of each parameter's unit of about a pixel's effect.
constexpr std::array<double, kTargetParameters> kRangeSteps{0.1,  0.1, 1e-4, 0.1,  1e-4,
                                                            1e-4, 0.1, 0.1,  1e-4, 1e-4};

// Horizontal ranges read back with `read` from the pixels at which `truth` images `point`.
struct ReadBack {
  double floor_plane_m = kNaN;
  double stereo_m = kNaN;
};
ReadBack read_back(const mirror::RigModel &truth, const mirror::RigModel &read,
                   const Eigen::Vector3d &point) {
  using mirror::Lobe;
  ReadBack out;
  const auto inner_px = truth.project(Lobe::kInner, point);
  const auto outer_px = truth.project(Lobe::kOuter, point);
  if (!inner_px || !outer_px) return out;
  const auto inner = read.back_project(Lobe::kInner, *inner_px);
  const auto outer = read.back_project(Lobe::kOuter, *outer_px);
  if (!inner || !outer) return out;
  if (inner->direction.z() < 0.0) {
    const double t = (point.z() - inner->origin_m.z()) / inner->direction.z();
    out.floor_plane_m = (inner->origin_m + t * inner->direction).head<2>().norm();
  }
  if (const auto met = mirror::RigModel::intersect(*inner, *outer))
    out.stereo_m = met->point_m.head<2>().norm();
  return out;
}

mirror::MirrorConfig stepped(mirror::MirrorConfig config, int parameter, double step) {
  double *values[kTargetParameters] = {&config.center_u_px,
                                       &config.center_v_px,
                                       &config.rig.focal_scale,
                                       &config.rig.mirror_dz_mm,
                                       &config.rig.mirror_tilt_x_rad,
                                       &config.rig.mirror_tilt_y_rad,
                                       &config.rig.mirror_offset_x_mm,
                                       &config.rig.mirror_offset_y_mm,
                                       &config.rig.level_tilt_x_rad,
                                       &config.rig.level_tilt_y_rad};
  *values[parameter] += step;
  return config;
}

}  // namespace

RangeUncertainty range_uncertainty(
    const mirror::MirrorConfig &camera,
    const Eigen::Matrix<double, kTargetParameters, kTargetParameters> &covariance, double camera_height_m) {
  const mirror::RigModel read(camera);
  std::vector<mirror::RigModel> perturbed;
  for (int i = 0; i < kTargetParameters; ++i) perturbed.emplace_back(stepped(camera, i, kRangeSteps[i]));
  RangeUncertainty out;
  for (std::size_t r = 0; r < kSensitivityRangesM.size(); ++r) {
    double floor_sum = 0.0, stereo_sum = 0.0;
    for (int a = 0; a < kAzimuths; ++a) {
      const double phi = 2.0 * std::numbers::pi * (a + 0.5) / kAzimuths;
      const Eigen::Vector3d point(kSensitivityRangesM[r] * std::cos(phi),
                                  kSensitivityRangesM[r] * std::sin(phi), -camera_height_m);
      const ReadBack base = read_back(read, read, point);
      Eigen::Matrix<double, 1, kTargetParameters> d_floor, d_stereo;
      for (int i = 0; i < kTargetParameters; ++i) {
        const ReadBack moved = read_back(perturbed[static_cast<std::size_t>(i)], read, point);
        d_floor(i) = (moved.floor_plane_m - base.floor_plane_m) / kRangeSteps[i];
        d_stereo(i) = (moved.stereo_m - base.stereo_m) / kRangeSteps[i];
      }
      floor_sum += (d_floor * covariance * d_floor.transpose())(0, 0);
      stereo_sum += (d_stereo * covariance * d_stereo.transpose())(0, 0);
    }
    out.floor_plane_m[r] = std::sqrt(floor_sum / kAzimuths);
    out.stereo_m[r] = std::sqrt(stereo_sum / kAzimuths);
  }
  return out;
}

std::vector<RangeSensitivity> range_sensitivity(const mirror::MirrorConfig &camera, double camera_height_m) {
  const mirror::MirrorModel model(camera);
  std::vector<RangeSensitivity> rows;
  // The centre off by one pixel along the point's azimuth: both of its radii read one pixel
  // short (the worst azimuth; across it, the error vanishes).
  rows.push_back(
      row_for("image centre", "1 px", model, camera_height_m, [&](const mirror::MeridianPoint &point) {
        const Radii radii = project(model, point);
        return Radii{radii.inner_px - kCentreStepPx, radii.outer_px - kCentreStepPx};
      }));
  mirror::MirrorConfig longer = camera;
  longer.focal_mm *= 1.0 + kFocalStep;
  const mirror::MirrorModel rig(longer);
  rows.push_back(row_for("focal length", "0.1%", model, camera_height_m,
                         [&](const mirror::MeridianPoint &point) { return project(rig, point); }));
  // The whole rig turned 0.1 deg off level about the camera x axis, read as level: a floor
  // point along the camera y axis (the worst azimuth), imaged by the tilted rig.
  mirror::MirrorConfig tilted = camera;
  tilted.rig.level_tilt_x_rad += kLevelTiltStepRad;
  const mirror::RigModel truth(tilted), read(camera);
  RangeSensitivity level{"level tilt", "0.1 deg", {}, {}};
  for (std::size_t i = 0; i < kSensitivityRangesM.size(); ++i) {
    const double range_m = kSensitivityRangesM[i];
    const ReadBack back = read_back(truth, read, Eigen::Vector3d(0.0, range_m, -camera_height_m));
    level.floor_plane_m[i] = std::abs(back.floor_plane_m - range_m);
    level.stereo_m[i] = std::abs(back.stereo_m - range_m);
  }
  rows.push_back(level);
  return rows;
}

}  // namespace omnislam::calib
