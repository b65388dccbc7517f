#include "omnislam/io/ground_truth_files.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

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
  std::ifstream in = open(file);
  std::vector<StampedPose> poses;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    StampedPose pose;
    if (!(fields >> pose.t_s >> pose.x_m >> pose.y_m >> pose.z_m >> pose.qx >> pose.qy >> pose.qz >>
          pose.qw)) {
      throw line_error(file, number, "expected 8 numbers \"t x y z qx qy qz qw\"");
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
    std::istringstream fields(line);
    if (expected < 0) {
      if (!(fields >> expected) || expected < 0) throw line_error(file, number, "expected the frame count");
      continue;
    }
    double distance_mm = 0.0, angle_deg = 0.0;
    std::string rest;
    if (!(fields >> distance_mm >> angle_deg) || (fields >> rest) || !std::isfinite(distance_mm) ||
        !std::isfinite(angle_deg)) {
      throw line_error(file, number, "expected \"distance_mm angle_deg\"");
    }
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
    for (char &c : line) c = c == ',' ? ' ' : c;
    std::istringstream fields(line);
    FloorplanSegment s;
    if (!(fields >> s.x1_m >> s.y1_m >> s.x2_m >> s.y2_m))
      throw line_error(file, number, "expected x1,y1,x2,y2");
    segments.push_back(s);
  }
  return segments;
}

}  // namespace omnislam::io
