#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "omnislam/degrade/degradation.hpp"
#include "omnislam/io/dataset.hpp"
#include "omnislam/pipeline/pipeline.hpp"

// Frames of a dataset directory for the pipeline's capture stage.
namespace omnislam::app {

struct DatasetSourceOptions {
  int loops = 1;  ///< play the dataset this many times (stamps keep increasing)
  /// What moves one pass's odometry onto the next's (io::loop_seam): the identity jumps
  /// back to the first frame's odometry.
  Eigen::Isometry2d seam = Eigen::Isometry2d::Identity();
  /// Frames stamped at or before this are passed over unread (a service resuming the
  /// dataset from a snapshot taken at this time).
  double after_s = -std::numeric_limits<double>::infinity();
  /// Called (on the capture thread) for an image that cannot be used; the frame goes on
  /// as skipped, so SLAM still gets its odometry.
  std::function<void(int frame, const std::string &error)> on_skip;
  /// When set, each image is degraded as its 1-based dataset frame number right after it is
  /// read (so a degraded copy on disk and this give the same bytes).
  std::shared_ptr<const degrade::Degrader> degrader;
};

/// Frame i (1-based) of the dataset: stamp (i - 1) / rate_hz, odometry[i - 1] (odometry
/// poses of the dataset's frames, any fixed odom frame; on later passes moved by
/// options.seam once per pass), the image read and checked
/// against `camera`, then degraded when options.degrader is set.
[[nodiscard]] pipeline::FrameSource dataset_source(const io::DatasetInfo &info,
                                                   std::vector<Eigen::Isometry2d> odometry,
                                                   const mirror::MirrorConfig &camera,
                                                   DatasetSourceOptions options = {});

/// The same from images decoded beforehand (benchmarks): no file access while running.
[[nodiscard]] pipeline::FrameSource memory_source(std::vector<cv::Mat> images,
                                                  std::vector<Eigen::Isometry2d> odometry, double rate_hz,
                                                  int loops);

}  // namespace omnislam::app
