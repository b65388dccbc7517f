#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/io/ground_truth_files.hpp"
#include "omnislam/stereo/local_scan.hpp"

/// @file
/// Ground truth for local scans (tests and benchmarks only): ray casting against the
/// floor-plan segments and the three accuracy figures of the stereo issue.

namespace omnislam::test {

/// base_link pose in the map frame.
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

/// Distance along the ray from (x, y) in direction `heading_rad` to the first segment it
/// meets, or nullopt when it meets none.
[[nodiscard]] std::optional<double> ray_cast_m(const std::vector<io::FloorplanSegment> &segments, double x_m,
                                               double y_m, double heading_rad);

/// Distance from (x, y) to the nearest segment (infinity without segments).
[[nodiscard]] double distance_to_segments_m(const std::vector<io::FloorplanSegment> &segments, double x_m,
                                            double y_m);

/// Accumulates the figures over many scans.
struct ScanAccuracy {
  double segment_tolerance_m = 0.1;  ///< a point is "on the plan" within this distance
  double coverage_range_m = 2.5;     ///< degrees whose ray meets a structure this near count

  std::vector<double> relative_range_errors;  ///< |range - ray cast| / ray cast, per point
  int points = 0;
  int points_near_segment = 0;
  int coverable_degrees = 0;
  int covered_degrees = 0;
  // Free range per column (floor-boundary scans): columns with one, and of those the ones
  // claiming free floor more than segment_tolerance_m beyond the first structure.
  int columns = 0;
  int free_known = 0;
  int free_beyond_truth = 0;
  int frames = 0;

  void add(const stereo::LocalScan &scan, const Pose2 &pose,
           const std::vector<io::FloorplanSegment> &segments);

  [[nodiscard]] double median_relative_error() const;
  [[nodiscard]] double quantile_relative_error(double q) const;
  [[nodiscard]] double near_segment_share() const;
  [[nodiscard]] double coverage() const;
  [[nodiscard]] double free_known_share() const;
  [[nodiscard]] double free_overclaim_share() const;
  [[nodiscard]] std::string summary() const;
};

/// A dataset held in memory: grey images, true poses per frame, floor plan.
struct TruthDataset {
  io::DatasetInfo info;
  std::vector<cv::Mat> images;
  std::vector<Pose2> poses;
  std::vector<io::FloorplanSegment> segments;
};

/// Loads every frame (throws std::runtime_error naming the file when something is missing).
[[nodiscard]] TruthDataset load_truth_dataset(const std::filesystem::path &dir);

}  // namespace omnislam::test
