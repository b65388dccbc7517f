#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Relocalisation on the saved map of a bundled dataset (tests and benchmarks only): the
/// map a replay builds (SLAM over every frame, the first frame's pose defines the map
/// frame), then a fresh relocaliser started at every frame in turn with no pose.

namespace omnislam::test {

struct LocalizationRun {
  std::vector<slam::Points2> scans;         ///< base_link, per frame
  std::vector<Eigen::Isometry2d> odometry;  ///< the dataset's noisy odometry
  /// Each frame's pose in the saved map, as the mapping run left it (its optimised
  /// trajectory): where a relocaliser should put the frame. On a room it is within a few mm
  /// of the truth; on a building floor the map itself is bent by up to ~0.15 m.
  std::vector<Eigen::Isometry2d> mapped;
  slam::Points2 map;  ///< the map after the whole run
};

/// Front-end and SLAM over every frame of the dataset in `dir` (throws naming a missing file).
[[nodiscard]] LocalizationRun build_localization_run(const std::filesystem::path &dir);

struct RelocalizationOutcome {
  int starts = 0;
  int localized = 0;
  int correct = 0;             ///< localized within 50 mm and 1 deg of the frame's pose in the map
  int wrong = 0;               ///< localized anywhere else
  int frames_needed = 0;       ///< summed over the localized starts (the confirming frame included)
  double worst_error_m = 0.0;  ///< of the correct ones
  double worst_error_deg = 0.0;
  std::vector<double> frame_ms;  ///< time of every relocaliser frame before localization
  std::vector<int> missed;       ///< the starts (1-based frames) not localized within max_frames
};

/// Starts a fresh relocaliser at every frame that has `max_frames` frames after it, and feeds
/// it those frames until it reports a pose.
[[nodiscard]] RelocalizationOutcome relocalize_from_every_frame(const LocalizationRun &run, int max_frames);

/// The same for the starts at frames [first, last) only (0-based).
[[nodiscard]] RelocalizationOutcome relocalize_from_frames(const LocalizationRun &run, int max_frames,
                                                           int first, int last);

}  // namespace omnislam::test
