#pragma once

#include <filesystem>
#include <vector>

#include "omnislam/io/dataset.hpp"
#include "omnislam/slam/point_map.hpp"
#include "run_record.hpp"

// Writes a run's output directory (architecture.md `omnislam replay`): trajectory.tum,
// map.csv, map.ply, profile.csv, summary.json and the thesis's files.
namespace omnislam::app {

class OutputWriter {
 public:
  /// Creates the directory; throws std::runtime_error naming it if that fails.
  explicit OutputWriter(std::filesystem::path dir);

  /// mapaN.txt: the global map after image N (thesis format: x y count, millimetres).
  void write_thesis_map(int frame, const std::vector<slam::MapPoint> &points) const;

  /// Everything else, once the run is over. `optimised` is every frame's final pose
  /// (slam::Slam::trajectory(); trajectory.tum); the frames' poses as they were published go
  /// to trajectory_online.tum, with covariance.csv. An `optimised` of another length than
  /// the frames (no pose graph) makes the two trajectories equal.
  void write_all(const RunRecord &run, const slam::PointMap &map, const io::DatasetInfo &info,
                 const std::vector<Eigen::Isometry2d> &optimised = {}) const;

 private:
  std::filesystem::path dir_;
};

}  // namespace omnislam::app
