#pragma once

#include <string>

/// @file
/// omnislamd's own sections of the YAML configuration (read by load_config with the
/// algorithm sections; architecture.md "Service"):
///
/// ```yaml
/// input:    {source: directory | dataset | camera | video, path, device, rate_hz, loops,
///            odometry: dataset | dds | none, odometry_topic, odometry_max_extrapolation_s,
///            odometry_max_gap_s}
/// pipeline: {mode: live | replay, queue_capacity, map_rate_hz, profile_period_s, profile_window}
/// dds:      {enabled, domain_id, config, wait_for_subscribers, wait_timeout_s, initial_pose_topic,
///            tf: {enabled, map_frame, odom_frame, base_frame, publish_odom_to_base,
///                 rate_hz, future_dating_s}}
/// service:  {output_dir, stage_timeout_s}
/// ```

namespace omnislam::io {

struct InputConfig {
  /// dataset: a dataset directory (images, rate and odometry from its dataset.yaml);
  /// directory: images in `path` (sorted by name); camera: cv::VideoCapture(device);
  /// video: cv::VideoCapture(path).
  std::string source = "dataset";
  std::string path;  ///< dataset directory, image directory or video file
  int device = 0;    ///< camera index for source camera
  /// Frames per second to feed the pipeline: < 0 the dataset's own rate (or the
  /// camera's), 0 as fast as possible, > 0 this rate.
  double rate_hz = -1.0;
  /// Play a dataset or directory this many times. A dataset's odometry (with its ground
  /// truth) continues across passes as if the robot drove from the last pose back to the
  /// first (io::loop_seam); without ground truth it jumps back.
  int loops = 1;
  /// Odometry source, matched to frames by timestamp: dataset (its odometry.tum), dds
  /// (nav_msgs Odometry on odometry_topic) or none.
  std::string odometry = "dataset";
  std::string odometry_topic = "rt/odom";
  /// dds odometry: a frame up to this long after the newest sample takes that sample ...
  double odometry_max_extrapolation_s = 0.2;
  /// ... and two samples further apart than this are a gap: frames in a gap have no
  /// odometry (SLAM predicts them from the last motion and keeps them out of the map).
  double odometry_max_gap_s = 0.5;
};

struct PipelineSectionConfig {
  std::string mode = "live";  ///< live: capture drops when the pipeline is full; replay: blocks
  int queue_capacity = 4;
  double map_rate_hz = 1.0;  ///< rt/omnislam/map at most this often (on change)
  double profile_period_s = 1.0;
  int profile_window = 300;  ///< frames in the rolling statistics
};

struct DdsSectionConfig {
  bool enabled = true;
  int domain_id = 0;
  std::string config;            ///< Cyclone XML file; empty: CYCLONEDDS_URI or Cyclone's default
  int wait_for_subscribers = 0;  ///< before starting, wait for this many pose readers ...
  double wait_timeout_s = 10.0;  ///< ... at most this long (then start anyway, with a warning)
  /// geometry_msgs/PoseWithCovarianceStamped in tf.map_frame (RViz's "2D Pose Estimate"):
  /// sets the SLAM pose for the next frame, the map kept. Empty: not subscribed.
  std::string initial_pose_topic = "rt/initialpose";
  /// rt/tf (tf2_msgs/TFMessage), REP-105: map -> odom from each frame's map pose and its
  /// odometry pose, re-sent at rate_hz between frames, stamped future_dating_s ahead (as
  /// slam_toolbox's transform_timeout) so that TF users can look up the data's time.
  struct Tf {
    bool enabled = true;
    std::string map_frame = "map";
    std::string odom_frame = "odom";
    std::string base_frame = "base_link";
    bool publish_odom_to_base = false;  ///< odom -> base_link too (a robot without a base driver's TF)
    double rate_hz = 20.0;
    double future_dating_s = 0.1;
  } tf;
};

struct ServiceConfig {
  InputConfig input;
  PipelineSectionConfig pipeline;
  DdsSectionConfig dds;
  std::string output_dir;  ///< trajectory.tum, profile.csv, map.csv at shutdown; empty: none
  /// A stage busy with one frame for longer is hung: the service stops petting the systemd
  /// watchdog (WatchdogSec), which then restarts it.
  double stage_timeout_s = 5.0;
};

}  // namespace omnislam::io
