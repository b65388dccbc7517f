#pragma once

#include <optional>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"
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

  /// Elevation (rad, from the nadir) of a fractional row, interpolated in the table.
  [[nodiscard]] double theta_of_row(mirror::Lobe lobe, float row) const;

 private:
  mirror::MirrorModel model_;
  TriangulationMethod method_;
  int rows_ = 0;
  std::vector<double> theta_inner_;  ///< at rows -1, -1 + 1/32, ..., rows
  std::vector<double> theta_outer_;
  std::optional<mirror::TriangulationTable> table_;
};

}  // namespace omnislam::stereo
