#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "omnislam/grid/occupancy_grid.hpp"
#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/point_map.hpp"

/// @file
/// Snapshots of the SLAM state (map, pose, counters, configuration hash) that a service
/// writes periodically into its state directory and resumes from after a restart.
///
/// File format, version 7 (all integers and doubles little-endian):
/// ```
/// offset  size  field
///  0       8    magic "OMNISNAP"
///  8       4    u32 format version (7)
/// 12       8    u64 payload size in bytes
/// 20       4    u32 CRC-32 (zlib) of bytes 8..19 followed by the payload
/// 24       -    payload: u64 config_hash, f64 t_s, f64 x_m, f64 y_m, f64 yaw_rad,
///               9 x f64 covariance (row-major, x y yaw), u64 frames, u64 integrated,
///               u64 not_integrated, u64 skipped, u64 dropped, i64 map_integrations,
///               u64 has_odometry (0 or 1), f64 odom x_m, f64 odom y_m, f64 odom yaw_rad,
///               u64 point count, then per point f64 x_m, f64 y_m, i32 hits, i32 first_seen,
///               u64 has_grid (0 or 1), and when 1: i32 width, i32 height, f64 resolution_m,
///               f64 origin x_m, f64 origin y_m, width x height i8 cells (-1, 0, 100; the
///               layout of grid::GridImage), width x height u8 above-floor flags (0, 1;
///               grid::GridImage::above_floor),
///               u64 has_graph (0 or 1), and when 1 the keyframe graph
///               (slam::KeyframeGraphState): f64 path_m, f64 last frame x_m, y_m, yaw_rad,
///               u64 keyframe count, per keyframe f64 x_m, f64 y_m, f64 yaw_rad, f64 path_m,
///               9 x f64 covariance (row-major, x y yaw; slam::Keyframe::covariance), u64 scan count, per
///               scan u64 point count and per point f64 x_m, f64 y_m (keyframe coordinates); u64 integration
///               count, per integration u32 keyframe, u32 scan (within the keyframe); u64 edge count, per
///               edge u32 from, u32 to, u64 loop (0 or 1), f64 x_m, f64 y_m, f64 yaw_rad (pose of `to` in
///               `from`), 9 x f64 information (row-major, x y yaw),
///               u64 has_odometry_scale (0 or 1), f64 factor, f64 sigma (the odometry's
///               distance factor the run had learnt, slam::OdometryScale; 1 and 0 when 0)
/// ```
/// Version 6 is version 7 without the odometry's distance factor, version 5 version 6
/// without the keyframes' covariances, version 4 version 5 without the
/// grid's above-floor flags, version 3 version 4 without
/// the graph section, version 2 version 3 without the grid section, version 1 version 2
/// without the four odometry fields; all are still read (their keyframes' covariances are
/// zero: a run localized on such a map publishes its registrations' alone; before version 7
/// their `odometry_scale`, before version 5 their grid's `above_floor`, before version 4
/// their `graph`, and before version 3 their `grid`, are empty).

namespace omnislam::io {

inline constexpr std::uint32_t kSnapshotVersion = 7;

/// A snapshot that cannot be used: missing, truncated, of another version, failing its
/// checksum, or holding impossible values. The message names the file.
class SnapshotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SnapshotCounters {
  std::uint64_t frames = 0;          ///< frames processed since the map was started
  std::uint64_t integrated = 0;      ///< frames whose registration was accepted
  std::uint64_t not_integrated = 0;  ///< frames that followed odometry
  std::uint64_t skipped = 0;         ///< frames whose image could not be used
  std::uint64_t dropped = 0;         ///< frames dropped by the live pipeline
};

/// The odometry's distance factor a run learnt (slam::OdometryScale: scale(), sigma()).
struct SnapshotOdometryScale {
  double factor = 1.0;
  double sigma = 0.0;
};

struct Snapshot {
  std::uint32_t version = kSnapshotVersion;  ///< of the file it was read from (written: always the newest)
  std::uint64_t config_hash = 0;             ///< config_file_hash() of the configuration that built the map
  double t_s = 0.0;                          ///< capture time of the last frame in the snapshot
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();  ///< last pose (planar)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();          ///< of (x, y, yaw), map frame
  /// The odometry pose of the last frame, when it had one: a resumed run whose odometry
  /// keeps its frame (a dataset, a base driver that kept running) predicts its first frame
  /// from it instead of assuming the robot stood still.
  std::optional<Eigen::Isometry2d> T_odom_base;
  SnapshotCounters counters;
  int map_integrations = 0;  ///< slam::PointMap::integrations() (the age reference of first_seen)
  std::vector<slam::MapPoint> points;
  /// The trinary occupancy grid (free space included) of the same state, when the writer
  /// had one (version 3), with what stood above the floor (version 5); a resumed service
  /// starts its grid from it (grid::OccupancyGrid::seed).
  std::optional<grid::GridImage> grid;
  /// The keyframe graph the map was built from, when the writer's graph described the map
  /// (version 4; slam::Slam::graph_state): a resumed run continues it and can close loops
  /// against its keyframes. Its integrations() equal map_integrations.
  std::optional<slam::KeyframeGraphState> graph;
  /// What the run had learnt of its odometry's distance factor (version 7): the same wheels
  /// resumed start from it (slam::Slam::restore_odometry_scale) instead of from 1.
  std::optional<SnapshotOdometryScale> odometry_scale;
};

/// The bytes of the file format above.
[[nodiscard]] std::vector<std::uint8_t> encode_snapshot(const Snapshot &snapshot);

/// Parses the file format; `name` is used in error messages. Throws SnapshotError on a
/// truncated or oversized buffer, a bad magic, checksum or version, or a non-finite or
/// impossible value (hits < 1, first_seen outside 0..map_integrations, a keyframe graph
/// that slam::keyframe_graph_state_error rejects or whose integrations are not
/// map_integrations).
[[nodiscard]] Snapshot decode_snapshot(std::span<const std::uint8_t> bytes, const std::string &name);

/// Writes `snapshot` so that `file` always holds either the previous or the new complete
/// snapshot, even across a crash or power loss: a temporary file in the same directory,
/// fsync, rename over `file`, fsync of the directory. Throws std::runtime_error naming the
/// file and the failing system call.
void write_snapshot(const std::filesystem::path &file, const Snapshot &snapshot);

/// Reads and checks a snapshot file. Throws SnapshotError (see decode_snapshot), also when
/// the file cannot be read.
[[nodiscard]] Snapshot read_snapshot(const std::filesystem::path &file);

/// Renames `file` to `file`.corrupt-N with the smallest N not yet taken, keeping it for
/// inspection; returns the new path. Throws std::runtime_error when the rename fails.
std::filesystem::path move_aside(const std::filesystem::path &file);

/// What to do when the snapshot to resume from is corrupt.
enum class CorruptSnapshotPolicy {
  kStartFresh,  ///< move it aside and start a new map
  kRefuse,      ///< throw: an operator decides
};

struct ResumeResult {
  std::optional<Snapshot> snapshot;      ///< empty: start a new map
  std::string message;                   ///< what happened, for the log
  std::filesystem::path moved_aside_to;  ///< where a corrupt snapshot went, if it did
};

/// Resumes from `file` if it exists. A missing file starts fresh; a corrupt one is moved
/// aside and starts fresh, or (kRefuse) throws SnapshotError and stays where it is.
[[nodiscard]] ResumeResult resume_from_snapshot(const std::filesystem::path &file,
                                                CorruptSnapshotPolicy policy);

/// FNV-1a 64-bit hash of a configuration file's bytes (0 for an empty path), stored in
/// snapshots so a resume under a changed configuration can be noticed.
[[nodiscard]] std::uint64_t config_file_hash(const std::filesystem::path &file);

}  // namespace omnislam::io
