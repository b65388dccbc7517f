#include "omnislam/io/grid_files.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace omnislam::io {
namespace {

constexpr unsigned char kOccupiedShade = 0;
constexpr unsigned char kFreeShade = 254;
constexpr unsigned char kUnknownShade = 205;

}  // namespace

void write_nav2_map(const std::filesystem::path &yaml_file, const grid::GridImage &image) {
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(yaml_file.string() + ": the grid is empty");
  std::filesystem::path pgm_file = yaml_file;
  pgm_file.replace_extension(".pgm");
  {
    std::ofstream pgm(pgm_file, std::ios::binary);
    pgm << "P5\n" << image.width << ' ' << image.height << "\n255\n";
    std::vector<unsigned char> row(static_cast<std::size_t>(image.width));
    for (int r = 0; r < image.height; ++r) {
      const int y = image.height - 1 - r;  // the image's top row is the grid's highest y
      for (int x = 0; x < image.width; ++x) {
        const std::int8_t cell =
            image.cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                        static_cast<std::size_t>(x)];
        row[static_cast<std::size_t>(x)] =
            cell == 100 ? kOccupiedShade : (cell == 0 ? kFreeShade : kUnknownShade);
      }
      pgm.write(reinterpret_cast<const char *>(row.data()), static_cast<std::streamsize>(row.size()));
    }
    if (!pgm) throw std::runtime_error(pgm_file.string() + ": cannot write");
  }
  std::ofstream yaml(yaml_file);
  char origin[96];
  std::snprintf(origin, sizeof origin, "[%.6f, %.6f, 0.0]", image.origin_m.x(), image.origin_m.y());
  yaml << "image: " << pgm_file.filename().string() << "\n"
       << "mode: trinary\n"
       << "resolution: " << image.resolution_m << "\n"
       << "origin: " << origin << "\n"
       << "negate: 0\n"
       << "occupied_thresh: 0.65\n"
       << "free_thresh: 0.196\n";
  if (!yaml) throw std::runtime_error(yaml_file.string() + ": cannot write");
}

}  // namespace omnislam::io
