#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "omnislam/dds/participant.hpp"
#include "omnislam/grid/occupancy_grid.hpp"
#include "omnislam/pipeline/profiler.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/stereo/local_scan.hpp"

/// @file
/// omnislam's output topics (architecture.md "DDS"): names, ROS 2 types and QoS.

namespace omnislam::dds {

/// Service states of rt/omnislam/status.
enum class ServiceState : std::uint8_t {
  kStarting = 0,
  kRunning = 1,
  kStopping = 2,
  kStopped = 3,
  kFailed = 4,
  kLocalizing = 5  ///< searching for its pose on the saved map: nothing is published until found
};

struct StatusMessage {
  double stamp_s = 0.0;
  ServiceState state = ServiceState::kStarting;
  std::uint64_t frames_in = 0;
  std::uint64_t frames_out = 0;
  std::uint64_t frames_dropped = 0;
  std::string last_error;
};

/// Writers of rt/omnislam/{pose, map, scan, profile, status}. Every method is a
/// non-blocking write of one sample (reliable writers may block briefly when a reader's
/// history is full). Not thread-safe: call from one thread (the pipeline's publish stage),
/// except status(), which the service also calls before start and after join.
/// Stamps are seconds (ROS time: sec + nanosec).
class Publisher {
 public:
  /// Creates the topics and writers; throws std::runtime_error naming the topic on failure.
  explicit Publisher(const Participant &participant);
  Publisher(const Publisher &) = delete;
  Publisher &operator=(const Publisher &) = delete;

  /// geometry_msgs/PoseWithCovarianceStamped in frame "map"; covariance is (x, y, yaw).
  void pose(double stamp_s, const Eigen::Isometry2d &T_map_base, const Eigen::Matrix3d &covariance);
  /// sensor_msgs/PointCloud2 in "map": x, y, z (0) float32 and hits uint32 per point.
  void map(double stamp_s, const std::vector<slam::MapPoint> &points);
  /// sensor_msgs/LaserScan in "base_link": 360 beams of 1 degree from 0, the nearest point
  /// of each; +inf where there is none.
  void scan(double stamp_s, const stereo::LocalScan &scan);
  /// rt/map (nav_msgs/OccupancyGrid) and rt/map_metadata (nav_msgs/MapMetaData), frame "map".
  void grid(double stamp_s, const grid::GridImage &image);
  /// omnislam/StageProfile.
  void profile(double stamp_s, const pipeline::ProfileSnapshot &profile);
  /// omnislam/Status (transient-local: late joiners get the last one).
  void status(const StatusMessage &status);

  /// Waits until rt/omnislam/pose has at least `readers` matched readers; false on timeout.
  [[nodiscard]] bool wait_for_readers(int readers, double timeout_s) const;
  /// Waits until every reliable sample written was acknowledged (before shutting down).
  void flush(double timeout_s) const;

 private:
  std::int32_t pose_ = 0, map_ = 0, scan_ = 0, profile_ = 0, status_ = 0, grid_ = 0, grid_metadata_ = 0;
};

}  // namespace omnislam::dds
