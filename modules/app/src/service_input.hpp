#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "omnislam/dds/initial_pose_reader.hpp"
#include "omnislam/dds/odometry_reader.hpp"
#include "omnislam/io/config.hpp"
#include "omnislam/pipeline/pipeline.hpp"

// omnislamd's inputs (config `input:`): frames from a dataset, an image directory, a
// camera or a video, with odometry from the dataset, DDS (rt/odom) or none.
namespace omnislam::app {

struct ServiceInput {
  pipeline::FrameSource source;
  double rate_hz = 0.0;  ///< pacing for the pipeline's capture stage (0: the source paces itself)
  std::string description;
};

/// Builds the source. `config.scan.camera` is updated from a dataset's own camera.
/// `odometry` is used (on the capture thread only) when input.odometry is dds. A dataset
/// starts after `resume_after_s` (the time of the snapshot the service resumed from);
/// live sources are stamped with the clock and need no such cut.
/// Throws std::runtime_error naming the path or device that cannot be opened.
[[nodiscard]] ServiceInput make_service_input(io::Config &config,
                                              std::shared_ptr<dds::OdometryReader> odometry,
                                              double resume_after_s);

/// What became of rt/initialpose samples; written by the capture thread, read by any.
struct InitialPoseCounts {
  std::atomic<std::uint64_t> applied{0};
  std::atomic<std::uint64_t> rejected{0};  ///< another frame_id (non-finite ones: the reader's count)
  [[nodiscard]] std::string last_error() const {
    const std::lock_guard lock(mutex_);
    return last_error_;
  }
  void reject(std::string reason) {
    rejected.fetch_add(1, std::memory_order_relaxed);
    const std::lock_guard lock(mutex_);
    last_error_ = std::move(reason);
  }

 private:
  mutable std::mutex mutex_;
  std::string last_error_;
};

/// `source` with rt/initialpose: before each frame is handed on, the reader is polled (on
/// the capture thread) and a pose in `map_frame` is attached to the frame
/// (pipeline::Frame::pose_reset: SLAM applies it before that frame); a pose in another
/// frame is logged, counted and left out.
[[nodiscard]] pipeline::FrameSource with_initial_pose(pipeline::FrameSource source,
                                                      std::shared_ptr<dds::InitialPoseReader> reader,
                                                      std::string map_frame,
                                                      std::shared_ptr<InitialPoseCounts> counts);

}  // namespace omnislam::app
