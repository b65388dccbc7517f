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

/// A point triangulated from the rows of one panorama column.
struct ColumnPoint {
  double range_m = 0.0;   ///< from the camera axis
  double height_m = 0.0;  ///< relative to the pinhole
  /// The point's azimuth less the column's: 0 on a designed rig, whose two lobes' columns
  /// show the same vertical half-plane; on a misaligned rig a point off the floor lies
  /// slightly beside its column's designed ray.
  double azimuth_shift_rad = 0.0;
};

/// Precomputes, once, the elevation of every 1/32 row of both lobes (linear interpolation
/// between them is exact to ~1e-7 rad) and, for kTable, the 225x225 table. Const and
/// thread-safe after construction.
class RowTriangulator {
 public:
  RowTriangulator(const mirror::MirrorModel &model, TriangulationMethod method);

  /// Intersection of the rays of the two rows; nullopt when they do not meet in front of
  /// both foci or a row is outside the panorama.
  [[nodiscard]] std::optional<mirror::MeridianPoint> triangulate(float inner_row, float outer_row) const;

  /// The same for the rows of panorama column `column`. For a nominal rig it is exactly
  /// triangulate(inner_row, outer_row). For a misaligned rig (config.rig not nominal;
  /// issue 12) the panoramas agree on the floor only: off the floor the point the inner
  /// pixel sees lies in the outer panorama a fraction of a column aside, on the epipolar
  /// curve of the inner ray. The outer edge is followed there along its own slope in the
  /// panorama (`outer_rows_per_column`, d row / d column along the edge; 0 takes it as
  /// level) to the column where its ray meets the inner ray (a secant search on the rays'
  /// coplanarity), and the rays' closest point gives range, height and the azimuth shift.
  /// The rays are the general model's at every panorama pixel, traced once at
  /// construction, interpolated between rows and columns. Both methods then use this path.
  [[nodiscard]] std::optional<ColumnPoint> triangulate(int column, float inner_row, float outer_row,
                                                       float outer_rows_per_column = 0.0f) const;

  /// Elevation (rad, from the nadir) of a fractional row, interpolated in the table.
  [[nodiscard]] double theta_of_row(mirror::Lobe lobe, float row) const;

 private:
  mirror::MirrorModel model_;
  TriangulationMethod method_;
  int rows_ = 0;
  std::vector<double> theta_inner_;  ///< at rows -1, -1 + 1/32, ..., rows
  std::vector<double> theta_outer_;
  std::optional<mirror::TriangulationTable> table_;

  /// Only for a misaligned rig: each lobe's world ray (origin, direction; NaN where the
  /// lobe is missed) at every panorama pixel, row-major.
  struct RayGrid {
    int rows = 0;
    int columns = 0;
    std::vector<Eigen::Matrix<float, 6, 1>> rays;
  };
  struct Rig {
    RayGrid inner;
    RayGrid outer;
  };
  std::optional<Rig> rig_;
  static RayGrid trace_rays(const mirror::MirrorModel &model, mirror::Lobe lobe);
  /// The ray of a fractional panorama position of a misaligned rig.
  [[nodiscard]] std::optional<mirror::Ray3> rig_ray(mirror::Lobe lobe, double column, double row) const;
};

}  // namespace omnislam::stereo
