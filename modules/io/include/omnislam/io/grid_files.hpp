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

/// Reads a map as nav2_map_server loads it in trinary mode: each pixel's shade v (0..255)
/// gives p = (255 - v) / 255, or v / 255 with negate 1; p > occupied_thresh is occupied
/// (100), p < free_thresh free (0), anything else unknown (-1). The image path is relative
/// to the YAML file's folder; the image's top row is the grid's highest y.
/// Throws std::runtime_error naming the file and the key or problem (missing key, a mode
/// other than trinary, an unreadable image).
[[nodiscard]] grid::GridImage read_nav2_map(const std::filesystem::path &yaml_file);

}  // namespace omnislam::io
