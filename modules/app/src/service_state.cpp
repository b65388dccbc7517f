#include "service_state.hpp"

#include <spdlog/spdlog.h>

#include <cstdlib>
#include <string>
#include <utility>

namespace omnislam::app {

std::filesystem::path state_file(const io::PersistenceConfig &persistence) {
  std::string dir = persistence.state_dir;
  if (dir.empty()) {
    const char *from_systemd = std::getenv("STATE_DIRECTORY");
    if (from_systemd != nullptr)
      dir = std::string(from_systemd).substr(0, std::string(from_systemd).find(':'));
  }
  return dir.empty() ? std::filesystem::path() : std::filesystem::path(dir) / "state.omnisnap";
}

std::optional<io::Snapshot> resume_state(const io::Config &config, const std::filesystem::path &file,
                                         std::uint64_t config_hash) {
  std::optional<io::Snapshot> snapshot;
  if (!file.empty() && config.persistence.resume) {
    const auto policy = config.persistence.refuse_corrupt_snapshot ? io::CorruptSnapshotPolicy::kRefuse
                                                                   : io::CorruptSnapshotPolicy::kStartFresh;
    io::ResumeResult resumed;
    try {
      resumed = io::resume_from_snapshot(file, policy);
    } catch (const io::SnapshotError &error) {
      throw StateError(error.what());
    }
    if (resumed.moved_aside_to.empty()) {
      spdlog::info("{}", resumed.message);
    } else {
      spdlog::error("{}", resumed.message);
    }
    snapshot = std::move(resumed.snapshot);
  }
  if (snapshot && snapshot->config_hash != config_hash) {
    spdlog::warn(
        "the snapshot's map was built under another configuration (hash {:016x}, now {:016x}); "
        "continuing with it",
        snapshot->config_hash, config_hash);
  }
  if (config.slam.localization_only && !snapshot) {
    throw StateError("slam.localization_only needs a saved map, and there is none" +
                     (file.empty() ? std::string(" (no persistence.state_dir or STATE_DIRECTORY)")
                                   : " at " + file.string()) +
                     ": map first, or place one with `omnislam map save RUN_DIR " +
                     (file.empty() ? std::string("STATE_DIR/state.omnisnap") : file.string()) + "`");
  }
  return snapshot;
}

io::Snapshot make_snapshot(const FrameRecord &frame, std::vector<slam::MapPoint> points, int map_integrations,
                           const io::SnapshotCounters &counters, std::uint64_t config_hash,
                           grid::GridImage grid, std::optional<slam::KeyframeGraphState> graph) {
  io::Snapshot s;
  s.config_hash = config_hash;
  s.t_s = frame.t_s;
  s.T_map_base = frame.T_map_base;
  s.covariance = frame.covariance;
  if (frame.has_odometry) s.T_odom_base = frame.T_odom_base;
  s.counters = counters;
  s.map_integrations = map_integrations;
  s.points = std::move(points);
  if (grid.width > 0) s.grid = std::move(grid);
  s.graph = std::move(graph);
  if (frame.odometry_scale_sigma > 0.0) s.odometry_scale = {frame.odometry_scale, frame.odometry_scale_sigma};
  return s;
}

std::optional<slam::ResumedGraph> resumed_graph(const io::Snapshot &snapshot) {
  if (!snapshot.graph) return std::nullopt;
  return slam::ResumedGraph{*snapshot.graph, true};
}

}  // namespace omnislam::app
