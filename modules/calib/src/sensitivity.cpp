#include "omnislam/calib/sensitivity.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/stereo/floor_geometry.hpp"

namespace omnislam::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kCentreStepPx = 1.0;
constexpr double kFocalStep = 0.001;  // 0.1%

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

}  // namespace

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
  return rows;
}

}  // namespace omnislam::calib
