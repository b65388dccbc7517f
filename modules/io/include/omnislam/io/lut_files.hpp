#pragma once

#include <filesystem>

#include "omnislam/mirror/triangulation_table.hpp"

/// @file
/// The thesis's triangulation table files rP.txt and zP.txt (annex A1.3; architecture.md
/// "Command line"): one line per inner row, one whitespace-separated value per outer row,
/// millimetres with 12 significant digits, `nan` where the rays do not meet.

namespace omnislam::io {

/// Writes DIR/rP.txt and DIR/zP.txt, creating DIR if needed. Throws std::runtime_error
/// naming the file on any I/O failure.
void write_lut_files(const std::filesystem::path &dir, const mirror::TriangulationTable &table);

/// A square table of millimetre values as read from one of the files (NaN kept).
struct LutFile {
  int size = 0;
  std::vector<double> values_mm;  ///< size * size, row-major [inner][outer]
  [[nodiscard]] double at(int inner_row, int outer_row) const {
    return values_mm[static_cast<std::size_t>(inner_row) * static_cast<std::size_t>(size) +
                     static_cast<std::size_t>(outer_row)];
  }
};

/// Reads rP.txt or zP.txt. Throws std::runtime_error naming the file and line when the
/// file is missing, a value does not parse, or the table is not square.
[[nodiscard]] LutFile read_lut_file(const std::filesystem::path &file);

}  // namespace omnislam::io
