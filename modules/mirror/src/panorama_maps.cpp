#include "omnislam/mirror/panorama_maps.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>

#include "omnislam/mirror/rig_model.hpp"

namespace omnislam::mirror {
namespace {

constexpr double kMmPerM = 1000.0;
constexpr double kFarthestReferenceMm = 20000.0;  // rays at or near the horizon: a point this far
constexpr float kOutsidePx = -10.0f;              // samples black (cv::remap, constant border)
// The designed rig samples its extreme rows half a pixel inside the annulus; a quarter pixel
// keeps every row of a designed (or barely misaligned) rig and only drops rows a moved
// mirror really takes off the lobe.
constexpr double kLobeMarginPx = 0.25;

// A misaligned rig: the panorama pixel keeps the designed ray of its row and column; it
// samples the image where the real rig sees that ray's point on the reference surface
// (the floor), so floor points keep their designed rows and the columns stay epipolar.
void fill_rig_map(const MirrorModel &model, Lobe lobe, PanoramaMap &map) {
  const MirrorConfig &config = model.config();
  const RigModel rig(config);
  for (int row = 0; row < map.rows; ++row) {
    const MeridianRay ray = model.back_project(lobe, model.radius_px_of_row(lobe, row));
    const double down = std::cos(ray.theta_rad);
    const double depth_mm = ray.origin.height_m * kMmPerM + config.reference_depth_mm;
    const double along_mm = down > depth_mm / kFarthestReferenceMm ? depth_mm / down : kFarthestReferenceMm;
    const double range_mm = ray.origin.range_m * kMmPerM + along_mm * std::sin(ray.theta_rad);
    const double height_mm = ray.origin.height_m * kMmPerM - along_mm * down;
    for (int column = 0; column < map.columns; ++column) {
      const double phi = column_azimuth_rad(config, column);
      const Eigen::Vector3d point_m(range_mm * std::cos(phi) / kMmPerM, range_mm * std::sin(phi) / kMmPerM,
                                    height_mm / kMmPerM);
      const std::optional<Pixel> pixel = rig.project(lobe, point_m);
      const std::size_t index = static_cast<std::size_t>(row) * map.columns + column;
      const bool on_lobe = pixel && rig.sees_lobe(lobe, *pixel, kLobeMarginPx);
      map.u_px[index] = on_lobe ? static_cast<float>(pixel->u_px) : kOutsidePx;
      map.v_px[index] = on_lobe ? static_cast<float>(pixel->v_px) : kOutsidePx;
    }
  }
  // Rows the lobe does not reach (at the split and the rim when the mirror has moved)
  // repeat the nearest row it does: a constant band has no edges, where black or the other
  // lobe would put a false one at the lobe's border.
  for (int column = 0; column < map.columns; ++column) {
    const auto index = [&](int row) { return static_cast<std::size_t>(row) * map.columns + column; };
    const auto valid = [&](int row) { return map.u_px[index(row)] != kOutsidePx; };
    int first = 0, last = map.rows - 1;
    while (first < map.rows && !valid(first)) ++first;
    while (last >= 0 && !valid(last)) --last;
    if (first > last) continue;
    for (int row = 0; row < map.rows; ++row) {
      const int source = row < first ? first : (row > last ? last : row);
      if (source == row) continue;
      map.u_px[index(row)] = map.u_px[index(source)];
      map.v_px[index(row)] = map.v_px[index(source)];
    }
  }
}

}  // namespace

double column_azimuth_rad(const MirrorConfig &config, double column) {
  const double step_deg = 360.0 / config.columns;
  return ((column + 0.5) * step_deg + config.azimuth_offset_deg) * std::numbers::pi / 180.0;
}

PanoramaMap make_panorama_map(const MirrorModel &model, Lobe lobe) {
  const MirrorConfig &config = model.config();
  PanoramaMap map;
  map.rows = config.rows_per_lobe;
  map.columns = config.columns;
  const std::size_t size = static_cast<std::size_t>(map.rows) * static_cast<std::size_t>(map.columns);
  map.u_px.resize(size);
  map.v_px.resize(size);
  if (!config.rig.nominal()) {
    fill_rig_map(model, lobe, map);
    return map;
  }
  for (int column = 0; column < map.columns; ++column) {
    const double phi = column_azimuth_rad(config, column);
    const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
    for (int row = 0; row < map.rows; ++row) {
      const double radius = model.radius_px_of_row(lobe, row);
      const std::size_t index = static_cast<std::size_t>(row) * map.columns + column;
      map.u_px[index] = static_cast<float>(config.center_u_px + radius * cos_phi);
      map.v_px[index] = static_cast<float>(config.center_v_px + radius * sin_phi);
    }
  }
  return map;
}

}  // namespace omnislam::mirror
