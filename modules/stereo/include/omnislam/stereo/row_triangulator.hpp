#pragma once

#include <optional>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"
#include "omnislam/mirror/panorama_maps.hpp"
#include "omnislam/mirror/rig_model.hpp"
#include "omnislam/mirror/triangulation_table.hpp"
#include "omnislam/stereo/stereo_config.hpp"

/// @file
/// Panorama rows -> point in the meridian half-plane (thesis sec. 3 step 6). Two methods:
/// the exact model at fractional rows (mirror.md sec. 6; integer rows cost 29-102 mm median
/// range error at 1-4 m, sec. 9) and, for comparison, the thesis's integer lookup table.

namespace omnislam::stereo {

/// Precomputes, once, the elevation of every 1/32 row of both lobes (linear interpolation
/// between them is exact to ~1e-7 rad) and, for kTable, the 225x225 table. Const and
/// thread-safe after construction.
class RowTriangulator {
 public:
  RowTriangulator(const mirror::MirrorModel &model, TriangulationMethod method);

  /// Intersection of the rays of the two rows; nullopt when they do not meet in front of
  /// both foci or a row is outside the panorama.
  [[nodiscard]] std::optional<mirror::MeridianPoint> triangulate(float inner_row, float outer_row) const;

  /// The same for the rows of panorama column `column`. For a misaligned rig
  /// (config.rig not nominal; issue 12) the rows are taken back to image positions through
  /// the panorama maps (linear between integer rows), the two pixels back-projected by
  /// the general model and the rays' closest point returned as (range from the camera
  /// axis, height); both methods then use this path. For a nominal rig it is exactly
  /// triangulate(inner_row, outer_row).
  [[nodiscard]] std::optional<mirror::MeridianPoint> triangulate(int column, float inner_row,
                                                                 float outer_row) const;

  /// Elevation (rad, from the nadir) of a fractional row, interpolated in the table.
  [[nodiscard]] double theta_of_row(mirror::Lobe lobe, float row) const;

 private:
  mirror::MirrorModel model_;
  TriangulationMethod method_;
  int rows_ = 0;
  std::vector<double> theta_inner_;  ///< at rows -1, -1 + 1/32, ..., rows
  std::vector<double> theta_outer_;
  std::optional<mirror::TriangulationTable> table_;

  /// Only for a misaligned rig: the general model and the panorama maps.
  struct Rig {
    mirror::RigModel model;
    mirror::PanoramaMap inner;
    mirror::PanoramaMap outer;
  };
  std::optional<Rig> rig_;
  [[nodiscard]] std::optional<mirror::Ray3> rig_ray(mirror::Lobe lobe, int column, float row) const;
};

}  // namespace omnislam::stereo
