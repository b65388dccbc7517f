#pragma once

#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/slam.hpp"
#include "omnislam/stereo/local_scan.hpp"
#include "omnislam/stereo/scan_reconstructor.hpp"

/// @file
/// The one frame type that flows through the pipeline (architecture.md "Pipeline"), owned
/// by exactly one stage at a time and handed on by std::unique_ptr.

namespace omnislam::pipeline {

using Clock = std::chrono::steady_clock;

/// Timed steps, in pipeline order (the columns of profile.csv and the thesis's timelog).
inline constexpr std::array<std::string_view, 7> kStages = {"read",  "unwarp",        "canny", "edges",
                                                            "match", "triangulation", "slam"};
enum Step : std::size_t { kRead, kUnwarp, kCanny, kEdges, kMatch, kTriangulation, kSlam };

/// The queues, named after the stage that consumes them.
inline constexpr std::array<std::string_view, 4> kQueues = {"frontend", "stereo", "slam", "publish"};

/// Where a frame's time went. Milliseconds of the steady clock.
struct FrameTimings {
  std::array<double, kStages.size()> stage_ms{};
  std::array<double, kQueues.size()> wait_ms{};   ///< time spent in each queue (blocked push included)
  std::array<int, kQueues.size()> queue_depth{};  ///< frames left in each queue when this one was taken
  double latency_ms = 0.0;                        ///< from capture (image in memory) to the sinks
};

struct Frame {
  std::uint64_t sequence = 0;  ///< 1-based, counting every captured frame (dropped ones too)
  double stamp_s = 0.0;        ///< capture time: dataset time in replay, system clock when live
  Clock::time_point captured;  ///< steady clock when the image was in memory
  Clock::time_point enqueued;  ///< steady clock when it was last offered to a queue

  Eigen::Isometry2d T_odom_base = Eigen::Isometry2d::Identity();  ///< odometry at stamp_s
  bool has_odometry = false;
  /// Frames dropped by capture just before this one (live mode). Their motion is not
  /// lost: odometry is an absolute pose, so this frame's pose composes all of it.
  std::uint32_t dropped_before = 0;

  /// An operator's pose (rt/initialpose) to apply before this frame (slam::Slam::set_pose).
  /// Capture carries it over to the next frame when this one is dropped.
  struct PoseReset {
    Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  };
  std::optional<PoseReset> pose_reset;

  cv::Mat image;      ///< CV_8UC1 of the camera size; released after the front-end
  std::string error;  ///< non-empty: the image was unusable and the frame is skipped

  stereo::LobeWork inner;  ///< front-end results handed to the stereo stage
  stereo::LobeWork outer;
  stereo::LocalScan scan;        ///< base_link, metres
  slam::FrameEstimate estimate;  ///< pose in the map frame
  /// false while the pipeline still searches for its pose on a saved map (Pipeline::relocalize):
  /// the frame has no pose.
  bool localized = true;
  /// The map after this frame, when the pipeline was asked for snapshots and it changed,
  /// or when state_due.
  std::shared_ptr<const std::vector<slam::MapPoint>> map;
  int map_integrations = 0;  ///< slam::PointMap::integrations() of `map`
  bool state_due = false;    ///< map is attached for a state snapshot (PipelineConfig::state_period_s)
  /// With state_due: the keyframe graph of the same state (slam::Slam::graph_state), when
  /// it describes the map; its scans are shared with the SLAM, not copied.
  std::shared_ptr<const slam::KeyframeGraphState> graph;
  /// When a loop closure moved the map (estimate.map_rebuilt): every frame's corrected pose
  /// (slam::Slam::trajectory(), indexed by FrameEstimate::trajectory_index), for what was
  /// built from the poses as they were published (the occupancy grid).
  std::shared_ptr<const std::vector<Eigen::Isometry2d>> trajectory;

  FrameTimings timings;

  [[nodiscard]] bool skipped() const { return !error.empty(); }
};

using FramePtr = std::unique_ptr<Frame>;

/// Milliseconds between two steady-clock instants.
[[nodiscard]] inline double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

}  // namespace omnislam::pipeline
