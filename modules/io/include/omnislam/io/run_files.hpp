#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "omnislam/io/ground_truth_files.hpp"

/// @file
/// Files a run writes into its output directory (architecture.md `omnislam replay`).
/// Every writer throws std::runtime_error naming the file when it cannot write.

namespace omnislam::io {

/// TUM trajectory, full precision, with a header comment.
void write_tum_file(const std::filesystem::path &file, const std::vector<StampedPose> &poses);

struct MapPointRecord {
  double x_m = 0.0;
  double y_m = 0.0;
  int hits = 0;
};

/// map.csv: header `x,y,hits`, metres, map frame.
void write_map_csv(const std::filesystem::path &file, const std::vector<MapPointRecord> &points);

/// map.ply: ASCII PLY with float x, y, z (z = 0) and an int property `hits`.
void write_map_ply(const std::filesystem::path &file, const std::vector<MapPointRecord> &points);

/// Reads map.csv back (for `omnislam evaluate`); errors name file:line.
[[nodiscard]] std::vector<MapPointRecord> read_map_csv(const std::filesystem::path &file);

/// One row of a run's covariance.csv: a frame's (x, y, yaw) covariance in the map frame.
struct CovarianceRecord {
  int frame = 0;
  double t_s = 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// covariance.csv: header `frame,t,xx_m2,xy_m2,yy_m2,xyaw_m_rad,yyaw_m_rad,yawyaw_rad2`,
/// one row per frame (the six distinct terms of the symmetric matrix).
void write_covariance_csv(const std::filesystem::path &file, const std::vector<CovarianceRecord> &rows);

/// Reads covariance.csv back; throws std::runtime_error naming the file and line of a bad row.
[[nodiscard]] std::vector<CovarianceRecord> read_covariance_csv(const std::filesystem::path &file);

/// Writes `text` to `file` (creating or replacing it).
void write_text_file(const std::filesystem::path &file, const std::string &text);

}  // namespace omnislam::io
