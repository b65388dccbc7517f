#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// Where the two lobes see the floor and a vertical surface standing on it. Both follow
/// from the mirror model and the camera height alone, and are the same in every column
/// (the model is rotationally symmetric), so they are tabulated once per camera.
///
/// - Floor: inner row i looks at the floor point at range floor_range_m(i); the outer lobe
///   sees that point at floor_outer_row(i).
/// - Vertical surface: a surface standing on the floor at the floor range of inner row e
///   (a wall whose base is seen at e) is seen by inner row i < e at some height; the
///   outer lobe sees that point at vertical_outer_row(i, e).
/// - Below the floor: the inner ray of row i, past the floor's level, meets a lower floor
///   at some depth; the outer lobe sees it between floor_outer_row(i) (no depth) and, for a
///   lower floor at most a camera height down, lowest_outer_row(i).
/// Rows are continuous panorama rows (mirror.md sec. 0); NaN marks a point a lobe does not
/// see (or a ray that never meets the floor).

namespace omnislam::stereo {

class FloorGeometry {
 public:
  FloorGeometry(const mirror::MirrorModel &model, double camera_height_m);

  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] double camera_height_m() const { return camera_height_m_; }
  /// Floor range of integer inner row i (m); NaN at or above the horizon.
  [[nodiscard]] float floor_range_m(int inner_row) const { return floor_range_m_[index(inner_row)]; }
  /// Floor range of a fractional inner row (exact, from the mirror model).
  [[nodiscard]] double floor_range_at(double inner_row) const;
  /// Outer row of the floor point of integer inner row i.
  [[nodiscard]] float floor_outer_row(int inner_row) const { return floor_outer_row_[index(inner_row)]; }
  /// The same at a fractional inner row (linear between rows; NaN if either is unseen).
  [[nodiscard]] float floor_outer_row_at(float inner_row) const;
  /// Outer row of the inner ray of row i where it meets a floor one camera height below the
  /// floor (a lower floor at most that deep is seen between it and floor_outer_row), at a
  /// fractional row (linear between rows; NaN if either is unseen).
  [[nodiscard]] float lowest_outer_row_at(float inner_row) const;
  /// Outer row of the point of inner row `row` on the vertical surface whose base is the
  /// floor point of inner row `base_row` (row < base_row; NaN otherwise or when unseen).
  [[nodiscard]] float vertical_outer_row(int row, int base_row) const {
    return vertical_outer_row_[index(base_row) * static_cast<std::size_t>(rows_) + index(row)];
  }
  /// vertical_outer_row(row, base_row) of every row, indexed by row (NaN from base_row on).
  [[nodiscard]] const float *vertical_outer_rows(int base_row) const {
    return vertical_outer_row_.data() + index(base_row) * static_cast<std::size_t>(rows_);
  }
  /// Image radius (px) of a panorama row of each lobe (mirror.md sec. 0).
  [[nodiscard]] float inner_radius_px(float row) const { return inner_radius_offset_px_ - row; }
  [[nodiscard]] float outer_radius_px(float row) const { return outer_radius_offset_px_ - row; }
  /// The same for a fractional base row (linear between the two base rows around it).
  [[nodiscard]] float vertical_outer_row_at(int row, float base_row) const {
    const int below = static_cast<int>(base_row);
    if (row >= below || below + 1 >= rows_) return std::numeric_limits<float>::quiet_NaN();
    const float fraction = base_row - static_cast<float>(below);
    const float a = vertical_outer_row(row, below), b = vertical_outer_row(row, below + 1);
    return a + fraction * (b - a);
  }
  /// The same for a fractional row as well (linear between the two rows around it).
  [[nodiscard]] float vertical_outer_row_subpx(float row, float base_row) const {
    const int below = static_cast<int>(row);
    const float a = vertical_outer_row_at(below, base_row), b = vertical_outer_row_at(below + 1, base_row);
    return std::isfinite(b) ? a + (row - static_cast<float>(below)) * (b - a) : a;
  }

 private:
  [[nodiscard]] static std::size_t index(int row) { return static_cast<std::size_t>(row); }
  /// A per-row table at a fractional inner row (linear between rows; NaN outside them).
  [[nodiscard]] float row_at(const std::vector<float> &per_row, float inner_row) const;

  mirror::MirrorModel model_;
  double camera_height_m_ = 0.0;
  int rows_ = 0;
  float inner_radius_offset_px_ = 0.0f;
  float outer_radius_offset_px_ = 0.0f;
  std::vector<float> floor_range_m_;
  std::vector<float> floor_outer_row_;
  std::vector<float> lowest_outer_row_;
  std::vector<float> vertical_outer_row_;  ///< [base_row][row]
};

}  // namespace omnislam::stereo
