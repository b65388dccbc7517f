#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "omnislam/io/grid_files.hpp"

namespace fs = std::filesystem;
using omnislam::grid::GridImage;

namespace {

fs::path scratch(const std::string &name) {
  const fs::path dir = fs::temp_directory_path() / "omnislam-test-grid-files" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string text(const fs::path &file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

GridImage example() {
  GridImage g;
  g.width = 5;
  g.height = 4;
  g.resolution_m = 0.05;
  g.origin_m = {-2.35, 1.1};
  for (int i = 0; i < g.width * g.height; ++i) g.cells.push_back(i % 4 == 0 ? 100 : (i % 4 == 1 ? -1 : 0));
  g.cells[static_cast<std::size_t>(g.width * (g.height - 1))] = 100;  // a top-left marker
  return g;
}

}  // namespace

TEST_CASE("nav2 map files: read back by map_server's trinary rules, cell for cell and byte for byte",
          "[io][grid]") {
  const fs::path dir = scratch("roundtrip");
  const GridImage written = example();
  omnislam::io::write_nav2_map(dir / "map.yaml", written);
  // The image's top row is the grid's highest y: its first pixel is the marker (shade 0).
  const std::string pgm = text(dir / "map.pgm");
  CHECK(pgm.rfind("P5\n5 4\n255\n", 0) == 0);
  CHECK(static_cast<unsigned char>(pgm[11]) == 0);
  CHECK(static_cast<unsigned char>(pgm[13]) == 205);

  const GridImage read = omnislam::io::read_nav2_map(dir / "map.yaml");
  CHECK(read.width == 5);
  CHECK(read.height == 4);
  CHECK(read.resolution_m == 0.05);
  CHECK(read.origin_m.isApprox(written.origin_m, 1e-12));
  CHECK(read.cells == written.cells);

  fs::create_directories(dir / "again");
  omnislam::io::write_nav2_map(dir / "again" / "map.yaml", read);
  CHECK(text(dir / "again" / "map.yaml") == text(dir / "map.yaml"));
  CHECK(text(dir / "again" / "map.pgm") == pgm);
}

TEST_CASE("nav2 map files: negate, thresholds, and bad files named", "[io][grid]") {
  const fs::path dir = scratch("rules");
  omnislam::io::write_nav2_map(dir / "map.yaml", example());
  // negate 1 reads a shade as p = v / 255: 254 (free) becomes occupied, 0 free, 205 (0.80) unknown.
  std::ofstream(dir / "negated.yaml")
      << "image: map.pgm\nmode: trinary\nresolution: 0.05\n"
         "origin: [0, 0, 0]\nnegate: 1\noccupied_thresh: 0.9\nfree_thresh: 0.1\n";
  const GridImage negated = omnislam::io::read_nav2_map(dir / "negated.yaml");
  const GridImage plain = example();
  for (std::size_t i = 0; i < plain.cells.size(); ++i) {
    const std::int8_t expected = plain.cells[i] == 0 ? 100 : (plain.cells[i] == 100 ? 0 : -1);
    CHECK(negated.cells[i] == expected);
  }

  std::ofstream(dir / "no-origin.yaml") << "image: map.pgm\nresolution: 0.05\nnegate: 0\n"
                                           "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
  CHECK_THROWS_WITH(omnislam::io::read_nav2_map(dir / "no-origin.yaml"),
                    Catch::EndsWith("no-origin.yaml: missing key origin"));
  std::ofstream(dir / "scale.yaml") << "image: map.pgm\nmode: scale\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                       "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  CHECK_THROWS_WITH(omnislam::io::read_nav2_map(dir / "scale.yaml"),
                    Catch::EndsWith("scale.yaml: mode scale (only trinary maps are read)"));
  std::ofstream(dir / "no-image.yaml") << "image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"
                                          "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  CHECK_THROWS_WITH(omnislam::io::read_nav2_map(dir / "no-image.yaml"),
                    Catch::EndsWith("missing.pgm: not a readable image"));
  CHECK_THROWS_WITH(omnislam::io::read_nav2_map(dir / "absent.yaml"),
                    Catch::EndsWith("absent.yaml: cannot open the map file"));
}
