#pragma once

#include <filesystem>

#include "omnislam/grid/occupancy_grid.hpp"

/// @file
/// Occupancy grids as nav2_map_server reads them: a PGM (P5) image and a YAML file (image,
/// mode, resolution, origin, negate, occupied_thresh, free_thresh).

namespace omnislam::io {

/// Writes `yaml_file` and, beside it, the PGM of the same stem: occupied cells 0, free 254,
/// unknown 205, the top row the grid's highest y; mode trinary, negate 0,
/// occupied_thresh 0.65 and free_thresh 0.196, so that map_server's trinary rule
/// (occupied above occupied_thresh, free below free_thresh, both on 1 - shade) gives back
/// every cell (with nav2's own default free_thresh of 0.25, 205 would read as free).
/// Throws std::runtime_error naming the file that cannot be written or an empty grid.
void write_nav2_map(const std::filesystem::path &yaml_file, const grid::GridImage &image);

}  // namespace omnislam::io
