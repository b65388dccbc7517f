#include "omnislam/io/lut_files.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace omnislam::io {
namespace {

constexpr double kMmPerM = 1000.0;

void write_one(const std::filesystem::path &file, const mirror::TriangulationTable &table,
               double mirror::MeridianPoint::*member) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot open " + file.string() + " for writing");
  char buffer[32];
  for (int inner = 0; inner < table.rows(); ++inner) {
    for (int outer = 0; outer < table.rows(); ++outer) {
      const auto point = table.at(inner, outer);
      if (point) {
        std::snprintf(buffer, sizeof buffer, "%.12g", (*point).*member * kMmPerM);
      } else {
        std::snprintf(buffer, sizeof buffer, "nan");
      }
      if (outer > 0) out << ' ';
      out << buffer;
    }
    out << '\n';
  }
  if (!out.flush()) throw std::runtime_error("write failed: " + file.string());
}

}  // namespace

void write_lut_files(const std::filesystem::path &dir, const mirror::TriangulationTable &table) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw std::runtime_error("cannot create " + dir.string() + ": " + error.message());
  write_one(dir / "rP.txt", table, &mirror::MeridianPoint::range_m);
  write_one(dir / "zP.txt", table, &mirror::MeridianPoint::height_m);
}

LutFile read_lut_file(const std::filesystem::path &file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file.string());
  LutFile lut;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    std::string token;
    int count = 0;
    while (fields >> token) {
      std::size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(token, &used);
      } catch (const std::exception &) {
        used = 0;
      }
      if (used != token.size()) {
        throw std::runtime_error(file.string() + ":" + std::to_string(line_number) + ": not a number: '" +
                                 token + "'");
      }
      lut.values_mm.push_back(value);
      ++count;
    }
    if (lut.size == 0) lut.size = count;
    if (count != lut.size) {
      throw std::runtime_error(file.string() + ":" + std::to_string(line_number) + ": " +
                               std::to_string(count) + " values, expected " + std::to_string(lut.size));
    }
  }
  const auto lines = static_cast<std::size_t>(lut.size);
  if (lut.size == 0 || lut.values_mm.size() != lines * lines) {
    throw std::runtime_error(file.string() + ": expected a square table, got " +
                             std::to_string(lut.values_mm.size()) + " values in rows of " +
                             std::to_string(lut.size));
  }
  return lut;
}

}  // namespace omnislam::io
