#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string_view>
#include <vector>

#include "omnislam/slam/slam.hpp"

// What a replay records per frame, and the files it makes of it.
namespace omnislam::app {

inline constexpr std::array<std::string_view, 7> kStages = {"read",  "unwarp",        "canny", "edges",
                                                            "match", "triangulation", "slam"};

struct FrameRecord {
  double t_s = 0.0;
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  Eigen::Isometry2d T_odom_base = Eigen::Isometry2d::Identity();  ///< the odometry used
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool skipped = false;  ///< the image could not be used
  bool integrated = false;
  slam::Attempt attempt = slam::Attempt::kNone;
  double srel_percent = 0.0;
  int iterations = 0;
  int scan_points = 0;
  std::array<double, kStages.size()> stage_ms{};
};

struct RunRecord {
  std::vector<FrameRecord> frames;
  std::vector<Eigen::Isometry2d> ground_truth;  ///< map frame, empty when unknown
  std::vector<Eigen::Isometry2d> odometry_map;  ///< odometry in the map frame (first pose = identity)
};

}  // namespace omnislam::app
