#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "omnislam/pipeline/frame.hpp"
#include "omnislam/slam/slam.hpp"

// What a replay records per frame, and the files it makes of it.
namespace omnislam::app {

using pipeline::kQueues;
using pipeline::kStages;

struct FrameRecord {
  double t_s = 0.0;
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  Eigen::Isometry2d T_odom_base = Eigen::Isometry2d::Identity();  ///< the odometry used
  bool has_odometry = true;  ///< false: odometry had a gap at this frame (T_odom_base is meaningless)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool skipped = false;  ///< the image could not be used
  bool integrated = false;
  bool localized = true;     ///< false: still searching for its pose on a saved map (no pose)
  bool lost = false;         ///< the tracking was lost: a dead-reckoned pose (slam::FrameEstimate::lost)
  bool relocalized = false;  ///< a lost robot was found again at this frame
  bool keyframe = false;     ///< became a keyframe of the pose graph
  bool revisit = false;      ///< revisited a keyframe: accepted, anchored to it, no new keyframe
  bool mapped = false;       ///< its scan was integrated into the map (slam::FrameEstimate::mapped)
  bool loop_closed = false;  ///< a loop closure corrected the graph at this frame
  slam::Attempt attempt = slam::Attempt::kNone;
  double odometry_scale = 1.0;  ///< the odometry's distance factor learnt so far (slam::FrameEstimate)
  double odometry_scale_sigma = 0.0;
  bool odometry_scale_applied = false;
  double srel_percent = 0.0;
  int iterations = 0;
  int scan_points = 0;
  std::array<double, kStages.size()> stage_ms{};
  std::array<double, kQueues.size()> wait_ms{};  ///< time in each pipeline queue
  std::array<int, kQueues.size()> queue_depth{};
  double latency_ms = 0.0;  ///< capture -> pose handed to the outputs
  int dropped_before = 0;   ///< frames dropped by capture just before this one (live mode)
};

struct RunRecord {
  std::vector<FrameRecord> frames;
  std::vector<Eigen::Isometry2d> ground_truth;  ///< map frame, empty when unknown
  std::vector<Eigen::Isometry2d> odometry_map;  ///< odometry in the map frame (first pose = identity)
  std::string degradation_factors = "none";     ///< image degradation applied on the fly (replay --degrade)
  std::uint64_t degradation_seed = 0;
  bool localizing = false;  ///< started on a saved map from an unknown pose (replay --localize)
};

}  // namespace omnislam::app
