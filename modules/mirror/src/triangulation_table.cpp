#include "omnislam/mirror/triangulation_table.hpp"

namespace omnislam::mirror {

TriangulationTable::TriangulationTable(const MirrorModel &model)
    : rows_(model.config().rows_per_lobe),
      entries_(static_cast<std::size_t>(rows_) * static_cast<std::size_t>(rows_)) {
  for (int inner = 0; inner < rows_; ++inner) {
    for (int outer = 0; outer < rows_; ++outer) {
      auto &entry = entries_[static_cast<std::size_t>(inner) * rows_ + outer];
      entry = model.triangulate_rows(inner, outer);
      if (entry) ++valid_count_;
    }
  }
}

std::optional<MeridianPoint> TriangulationTable::at(int inner_row, int outer_row) const {
  if (inner_row < 0 || outer_row < 0 || inner_row >= rows_ || outer_row >= rows_) return std::nullopt;
  return entries_[static_cast<std::size_t>(inner_row) * rows_ + outer_row];
}

}  // namespace omnislam::mirror
