#include "omnislam/io/run_files.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "number_fields.hpp"

namespace omnislam::io {
namespace {

std::ofstream open_for_writing(const std::filesystem::path &file) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cannot open " + file.string() + " for writing");
  return out;
}

void finish(std::ofstream &out, const std::filesystem::path &file) {
  if (!out.flush()) throw std::runtime_error("write failed: " + file.string());
}

}  // namespace

void write_tum_file(const std::filesystem::path &file, const std::vector<StampedPose> &poses) {
  std::ofstream out = open_for_writing(file);
  out << "# t x y z qx qy qz qw (base_link in map, metres)\n";
  char line[256];
  for (const StampedPose &p : poses) {
    std::snprintf(line, sizeof line, "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.t_s, p.x_m, p.y_m, p.z_m,
                  p.qx, p.qy, p.qz, p.qw);
    out << line;
  }
  finish(out, file);
}

void write_map_csv(const std::filesystem::path &file, const std::vector<MapPointRecord> &points) {
  std::ofstream out = open_for_writing(file);
  out << "x,y,hits\n";
  char line[96];
  for (const MapPointRecord &p : points) {
    std::snprintf(line, sizeof line, "%.6f,%.6f,%d\n", p.x_m, p.y_m, p.hits);
    out << line;
  }
  finish(out, file);
}

void write_map_ply(const std::filesystem::path &file, const std::vector<MapPointRecord> &points) {
  std::ofstream out = open_for_writing(file);
  out << "ply\nformat ascii 1.0\ncomment omnislam map, metres, map frame\nelement vertex " << points.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty int hits\nend_header\n";
  char line[96];
  for (const MapPointRecord &p : points) {
    std::snprintf(line, sizeof line, "%.6f %.6f 0 %d\n", p.x_m, p.y_m, p.hits);
    out << line;
  }
  finish(out, file);
}

std::vector<MapPointRecord> read_map_csv(const std::filesystem::path &file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file.string());
  std::vector<MapPointRecord> points;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 || line.find_first_not_of(" \t\r") == std::string::npos) continue;  // header
    const auto where = file.string() + ":" + std::to_string(number) + ": ";
    const auto fields = detail::split_fields(line, true);
    if (fields.size() != 3) throw std::runtime_error(where + "expected x,y,hits, got '" + line + "'");
    MapPointRecord p;
    long hits = 0;
    if (auto error = detail::parse_finite(fields[0], "x", p.x_m)) throw std::runtime_error(where + *error);
    if (auto error = detail::parse_finite(fields[1], "y", p.y_m)) throw std::runtime_error(where + *error);
    if (auto error = detail::parse_integer(fields[2], "hits", hits)) throw std::runtime_error(where + *error);
    if (hits < 1 || hits > 1000000000) throw std::runtime_error(where + "'hits' must be in 1..1e9");
    p.hits = static_cast<int>(hits);
    points.push_back(p);
  }
  return points;
}

std::vector<CovarianceRecord> read_covariance_csv(const std::filesystem::path &file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file.string());
  std::vector<CovarianceRecord> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 || line.find_first_not_of(" \t\r") == std::string::npos) continue;  // header
    const auto where = file.string() + ":" + std::to_string(number) + ": ";
    const auto fields = detail::split_fields(line, true);
    if (fields.size() != 8)
      throw std::runtime_error(where + "expected frame,t and 6 covariance terms, got '" + line + "'");
    CovarianceRecord row;
    long frame = 0;
    if (auto error = detail::parse_integer(fields[0], "frame", frame))
      throw std::runtime_error(where + *error);
    if (auto error = detail::parse_finite(fields[1], "t", row.t_s)) throw std::runtime_error(where + *error);
    static constexpr const char *kNames[] = {"xx_m2",      "xy_m2",      "yy_m2",
                                             "xyaw_m_rad", "yyaw_m_rad", "yawyaw_rad2"};
    double terms[6] = {};
    for (int k = 0; k < 6; ++k) {
      if (auto error = detail::parse_finite(fields[static_cast<std::size_t>(k) + 2], kNames[k], terms[k]))
        throw std::runtime_error(where + *error);
    }
    row.frame = static_cast<int>(frame);
    row.covariance << terms[0], terms[1], terms[3], terms[1], terms[2], terms[4], terms[3], terms[4],
        terms[5];
    rows.push_back(row);
  }
  return rows;
}

void write_text_file(const std::filesystem::path &file, const std::string &text) {
  std::ofstream out = open_for_writing(file);
  out << text;
  finish(out, file);
}

}  // namespace omnislam::io
