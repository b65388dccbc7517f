#include "omnislam/io/ground_truth_files.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "number_fields.hpp"

namespace omnislam::io {
namespace {

std::ifstream open(const std::filesystem::path &file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the file");
  return in;
}

std::runtime_error line_error(const std::filesystem::path &file, int line, const std::string &what) {
  return std::runtime_error(file.string() + ":" + std::to_string(line) + ": " + what);
}

}  // namespace

double StampedPose::yaw_rad() const {
  return std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
}

std::vector<StampedPose> read_tum_file(const std::filesystem::path &file) {
  static constexpr std::array<std::string_view, 8> kNames = {"t", "x", "y", "z", "qx", "qy", "qz", "qw"};
  std::ifstream in = open(file);
  std::vector<StampedPose> poses;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const auto fields = detail::split_fields(line, false);
    if (fields.size() != kNames.size()) {
      throw line_error(
          file, number,
          "expected 8 numbers \"t x y z qx qy qz qw\", found " + std::to_string(fields.size()) + " fields");
    }
    std::array<double, 8> v{};
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (const auto error = detail::parse_finite(fields[i], kNames[i], v[i]))
        throw line_error(file, number, *error);
    }
    const StampedPose pose{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
    if (pose.qx * pose.qx + pose.qy * pose.qy + pose.qz * pose.qz + pose.qw * pose.qw < 1e-12)
      throw line_error(file, number, "the quaternion (qx qy qz qw) is zero");
    if (!poses.empty() && pose.t_s < poses.back().t_s) {
      throw line_error(file, number,
                       "time goes backwards: t = " + std::string(fields[0]) +
                           " s after t = " + std::to_string(poses.back().t_s) + " s");
    }
    poses.push_back(pose);
  }
  return poses;
}

std::vector<StampedPose> read_thesis_odometry(const std::filesystem::path &file) {
  constexpr double kPi = 3.14159265358979323846;
  std::ifstream in = open(file);
  std::vector<StampedPose> poses;
  int number = 0;
  long expected = -1;
  double x_m = 0.0, y_m = 0.0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto fields = detail::split_fields(line, false);
    if (expected < 0) {
      if (fields.size() != 1 || detail::parse_integer(fields[0], "frame count", expected) || expected < 0)
        throw line_error(file, number, "expected the frame count");
      continue;
    }
    if (fields.size() != 2) {
      throw line_error(
          file, number,
          "expected \"distance_mm angle_deg\", found " + std::to_string(fields.size()) + " fields");
    }
    double distance_mm = 0.0, angle_deg = 0.0;
    if (auto error = detail::parse_finite(fields[0], "distance_mm", distance_mm))
      throw line_error(file, number, *error);
    if (auto error = detail::parse_finite(fields[1], "angle_deg", angle_deg))
      throw line_error(file, number, *error);
    x_m += distance_mm / 1000.0 * std::cos(angle_deg * kPi / 180.0);
    y_m += distance_mm / 1000.0 * std::sin(angle_deg * kPi / 180.0);
    StampedPose pose;
    pose.t_s = static_cast<double>(poses.size());
    pose.x_m = x_m;
    pose.y_m = y_m;
    poses.push_back(pose);
  }
  if (expected < 0) throw std::runtime_error(file.string() + ": empty file, expected the frame count");
  if (static_cast<long>(poses.size()) != expected) {
    throw std::runtime_error(file.string() + ": line 1 announces " + std::to_string(expected) +
                             " frames but " + std::to_string(poses.size()) + " follow");
  }
  return poses;
}

std::vector<FloorplanSegment> read_floorplan_csv(const std::filesystem::path &file) {
  std::ifstream in = open(file);
  std::vector<FloorplanSegment> segments;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (number == 1 && line.rfind("x1", 0) == 0) continue;  // the header
    const auto fields = detail::split_fields(line, true);
    if (fields.size() != 4) throw line_error(file, number, "expected x1,y1,x2,y2");
    FloorplanSegment s;
    double *values[] = {&s.x1_m, &s.y1_m, &s.x2_m, &s.y2_m};
    static constexpr std::array<std::string_view, 4> kNames = {"x1", "y1", "x2", "y2"};
    for (std::size_t i = 0; i < 4; ++i) {
      if (const auto error = detail::parse_finite(fields[i], kNames[i], *values[i]))
        throw line_error(file, number, *error);
    }
    segments.push_back(s);
  }
  return segments;
}

}  // namespace omnislam::io
