#include "omnislam/mirror/panorama_maps.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>

namespace omnislam::mirror {

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
