#include "omnislam/io/run_files.hpp"

#include <cstdio>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

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

// Throws std::runtime_error with the row's file:line prefixed to the message.
using Fail = std::function<void(const std::string &)>;

// Calls parse(fields, fail) for every row of a CSV file with a header line (blank lines
// skipped); a row without `field_count` fields fails naming what was expected.
template <typename Parse>
void for_each_csv_row(const std::filesystem::path &file, std::size_t field_count, const char *expected,
                      Parse &&parse) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open " + file.string());
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 || line.find_first_not_of(" \t\r") == std::string::npos) continue;  // header
    const std::string where = file.string() + ":" + std::to_string(number) + ": ";
    const Fail fail = [&where](const std::string &message) { throw std::runtime_error(where + message); };
    const auto fields = detail::split_fields(line, true);
    if (fields.size() != field_count) fail(std::string("expected ") + expected + ", got '" + line + "'");
    parse(fields, fail);
  }
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

void write_covariance_csv(const std::filesystem::path &file, const std::vector<CovarianceRecord> &rows) {
  std::ofstream out = open_for_writing(file);
  out << "frame,t,xx_m2,xy_m2,yy_m2,xyaw_m_rad,yyaw_m_rad,yawyaw_rad2\n";
  char line[256];
  for (const CovarianceRecord &row : rows) {
    const Eigen::Matrix3d &c = row.covariance;
    std::snprintf(line, sizeof line, "%d,%.6f,%.6e,%.6e,%.6e,%.6e,%.6e,%.6e\n", row.frame, row.t_s, c(0, 0),
                  c(0, 1), c(1, 1), c(0, 2), c(1, 2), c(2, 2));
    out << line;
  }
  finish(out, file);
}

std::vector<MapPointRecord> read_map_csv(const std::filesystem::path &file) {
  std::vector<MapPointRecord> points;
  for_each_csv_row(file, 3, "x,y,hits", [&](const std::vector<std::string_view> &fields, const Fail &fail) {
    MapPointRecord p;
    long hits = 0;
    if (auto error = detail::parse_finite(fields[0], "x", p.x_m)) fail(*error);
    if (auto error = detail::parse_finite(fields[1], "y", p.y_m)) fail(*error);
    if (auto error = detail::parse_integer(fields[2], "hits", hits)) fail(*error);
    if (hits < 1 || hits > 1000000000) fail("'hits' must be in 1..1e9");
    p.hits = static_cast<int>(hits);
    points.push_back(p);
  });
  return points;
}

std::vector<CovarianceRecord> read_covariance_csv(const std::filesystem::path &file) {
  static constexpr const char *kTerms[] = {"xx_m2",      "xy_m2",      "yy_m2",
                                           "xyaw_m_rad", "yyaw_m_rad", "yawyaw_rad2"};
  std::vector<CovarianceRecord> rows;
  for_each_csv_row(file, 8, "frame,t and 6 covariance terms",
                   [&](const std::vector<std::string_view> &fields, const Fail &fail) {
                     CovarianceRecord row;
                     long frame = 0;
                     if (auto error = detail::parse_integer(fields[0], "frame", frame)) fail(*error);
                     if (auto error = detail::parse_finite(fields[1], "t", row.t_s)) fail(*error);
                     double terms[6] = {};
                     for (std::size_t k = 0; k < 6; ++k) {
                       if (auto error = detail::parse_finite(fields[k + 2], kTerms[k], terms[k]))
                         fail(*error);
                     }
                     row.frame = static_cast<int>(frame);
                     row.covariance << terms[0], terms[1], terms[3], terms[1], terms[2], terms[4], terms[3],
                         terms[4], terms[5];
                     rows.push_back(row);
                   });
  return rows;
}

void write_text_file(const std::filesystem::path &file, const std::string &text) {
  std::ofstream out = open_for_writing(file);
  out << text;
  finish(out, file);
}

}  // namespace omnislam::io
