#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// The thesis's triangulation lookup table (annex A1.3): for every pair (inner row, outer
/// row) of integer panorama rows, the point where the two rays meet.

namespace omnislam::mirror {

class TriangulationTable {
 public:
  /// Computes rows_per_lobe^2 entries once (about 50k closed-form triangulations).
  explicit TriangulationTable(const MirrorModel &model);

  [[nodiscard]] int rows() const { return rows_; }

  /// The point for integer rows, or nullopt where the rays do not meet (NaN in the files)
  /// or a row is out of [0, rows).
  [[nodiscard]] std::optional<MeridianPoint> at(int inner_row, int outer_row) const;

  [[nodiscard]] std::size_t valid_count() const { return valid_count_; }

 private:
  int rows_ = 0;
  std::size_t valid_count_ = 0;
  std::vector<std::optional<MeridianPoint>> entries_;  ///< row-major, [inner][outer]
};

}  // namespace omnislam::mirror
