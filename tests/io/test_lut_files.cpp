#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "omnislam/io/lut_files.hpp"

namespace fs = std::filesystem;
using omnislam::io::LutFile;

namespace {

fs::path scratch_dir(const std::string &name) {
  const fs::path dir = fs::temp_directory_path() / ("omnislam-test-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void check_against_mirror_md(const fs::path &dir) {
  const LutFile rp = omnislam::io::read_lut_file(dir / "rP.txt");
  const LutFile zp = omnislam::io::read_lut_file(dir / "zP.txt");
  REQUIRE(rp.size == 225);
  REQUIRE(zp.size == 225);
  CHECK(rp.at(45, 60) == Approx(2514.909).margin(1.5e-3));
  CHECK(zp.at(45, 60) == Approx(-386.693).margin(1.5e-3));
  CHECK(rp.at(0, 0) == Approx(133309.880).margin(1.5e-3));
  CHECK(zp.at(150, 160) == Approx(-1419.175).margin(1.5e-3));
  CHECK(rp.at(200, 224) == Approx(284.373).margin(1.5e-3));
  CHECK(std::isnan(rp.at(112, 112)));
  CHECK(std::isnan(zp.at(112, 112)));
  int valid = 0;
  for (double v : rp.values_mm) valid += std::isnan(v) ? 0 : 1;
  CHECK(valid == 25162);

  // The file holds enough digits to agree with the model to 1e-10 relative.
  const omnislam::mirror::MirrorModel model;
  const omnislam::mirror::TriangulationTable table(model);
  for (int inner = 0; inner < 225; inner += 7) {
    for (int outer = 0; outer < 225; outer += 5) {
      const auto point = table.at(inner, outer);
      if (!point) {
        REQUIRE(std::isnan(rp.at(inner, outer)));
        continue;
      }
      REQUIRE(rp.at(inner, outer) == Approx(point->range_m * 1e3).epsilon(1e-10));
      REQUIRE(zp.at(inner, outer) == Approx(point->height_m * 1e3).epsilon(1e-10));
    }
  }
}

}  // namespace

TEST_CASE("LUT files: written in the thesis format and read back", "[io][lut]") {
  const fs::path dir = scratch_dir("lut");
  const omnislam::mirror::MirrorModel model;
  omnislam::io::write_lut_files(dir, omnislam::mirror::TriangulationTable(model));
  std::ifstream in(dir / "rP.txt");
  int lines = 0;
  for (std::string line; std::getline(in, line);) ++lines;
  CHECK(lines == 225);
  check_against_mirror_md(dir);
  fs::remove_all(dir);
}

TEST_CASE("LUT files: a malformed file names the file and line", "[io][lut]") {
  const fs::path dir = scratch_dir("lut-bad");
  {
    std::ofstream out(dir / "rP.txt");
    out << "1 2 3\n4 x 6\n7 8 9\n";
  }
  CHECK_THROWS_WITH(omnislam::io::read_lut_file(dir / "rP.txt"),
                    Catch::Contains("rP.txt:2") && Catch::Contains("'x'"));
  {
    std::ofstream out(dir / "zP.txt");
    out << "1 2 3\n4 5\n";
  }
  CHECK_THROWS_WITH(omnislam::io::read_lut_file(dir / "zP.txt"), Catch::Contains("zP.txt:2"));
  CHECK_THROWS_WITH(omnislam::io::read_lut_file(dir / "missing.txt"), Catch::Contains("missing.txt"));
  fs::remove_all(dir);
}

TEST_CASE("LUT files written by the omnislam CLI", "[.][cli]") {
  const char *dir = std::getenv("OMNISLAM_LUT_DIR");
  REQUIRE(dir != nullptr);
  check_against_mirror_md(dir);
}
