#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <vector>

#include "omnislam/io/config.hpp"
#include "omnislam/io/snapshot.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/slam.hpp"
#include "run_record.hpp"

// omnislamd's saved state: where the snapshot lives, resuming from it at start, and the
// snapshot after a frame that went through the pipeline.
namespace omnislam::app {

/// The saved state cannot be used: a corrupt snapshot under on_corrupt_snapshot: refuse,
/// or localization-only mode without a map. omnislamd exits with code 3 on it.
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// persistence.state_dir, else systemd's $STATE_DIRECTORY (its first entry), joined with
/// state.omnisnap; empty: no persistence.
[[nodiscard]] std::filesystem::path state_file(const io::PersistenceConfig &persistence);

/// The snapshot to resume from (empty: a new map), per config.persistence; logs what
/// happened. Throws StateError when the service must not start.
[[nodiscard]] std::optional<io::Snapshot> resume_state(const io::Config &config,
                                                       const std::filesystem::path &file,
                                                       std::uint64_t config_hash);

/// The snapshot after `frame`: its pose, covariance and odometry, with the map as it was
/// then (points and slam::PointMap::integrations()), the occupancy grid (none when empty)
/// and the keyframe graph (slam::Slam::graph_state; none when it does not describe the map).
[[nodiscard]] io::Snapshot make_snapshot(const FrameRecord &frame, std::vector<slam::MapPoint> points,
                                         int map_integrations, const io::SnapshotCounters &counters,
                                         std::uint64_t config_hash, grid::GridImage grid,
                                         std::optional<slam::KeyframeGraphState> graph);

/// How the service resumes the saved keyframe graph (none in the snapshot: none): chained
/// to the new keyframes, since the saved pose is taken as is and the tracking continues
/// from it (slam::ResumedGraph::chained).
[[nodiscard]] std::optional<slam::ResumedGraph> resumed_graph(const io::Snapshot &snapshot);

}  // namespace omnislam::app
