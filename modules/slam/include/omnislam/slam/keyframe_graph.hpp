#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "omnislam/slam/nearest_neighbors.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/pose_graph.hpp"

/// @file
/// Keyframes of a SLAM run and the pose graph over them. A keyframe is an integrated frame
/// taken after the robot travelled keyframe_distance_m or turned keyframe_angle_rad since
/// the last one; it keeps every integrated frame's scan until the next keyframe, in its own
/// coordinates, so the map can be rebuilt from the optimised keyframe poses. Every frame
/// (keyframe or not) is remembered relative to the keyframe it followed, so the whole
/// trajectory follows the graph. Not thread-safe; a copy shares the stored scans (immutable)
/// with the original, so copies may be read on other threads while the original grows.

namespace omnislam::slam {

struct KeyframeConfig {
  double keyframe_distance_m = 0.5;    ///< travel that makes the next integrated frame a keyframe
  double keyframe_angle_rad = 0.3491;  ///< or turn (20 deg)
  /// A sequential edge's covariance is the tracking's own between its two keyframes (the
  /// published walk's terms summed over the frames in between: along a plain corridor the
  /// odometry's, across it the registrations') plus this floor, standard deviations, for
  /// what no frame's estimate sees (the front-end's systematic errors, an exact fit).
  double edge_floor_xy_m = 0.01;
  double edge_floor_yaw_rad = 0.0087;  ///< 0.5 deg
  /// A priori drift of scan-to-map tracking per metre travelled, on top of the floor: the
  /// loop search's window (LoopClosureConfig), not the edges.
  double drift_per_m = 0.03;        ///< position, m per m travelled
  double drift_yaw_per_m = 0.0087;  ///< heading, rad per m travelled (0.5 deg/m)
  /// The scans a keyframe holds at most (its own, the frames that join it, revisits): a
  /// frame that would join a full keyframe is tracked but not integrated, so a place driven
  /// through again and again, or a robot standing still, costs bounded memory and a bounded
  /// share of every map rebuild. 16 views of a place leave a fused map point a quarter of
  /// one view's noise; what the front-end gets wrong the same way every time (a few mm,
  /// docs/frontend.md "Front-end on real floors") more views would not remove.
  int max_scans = 16;
};

struct Keyframe {
  Eigen::Isometry2d T_map_keyframe = Eigen::Isometry2d::Identity();  ///< the graph's current value
  double path_m = 0.0;  ///< distance travelled from the first keyframe
  /// The integrated scans it holds, keyframe coordinates; immutable once stored, shared by
  /// every copy of the graph.
  std::vector<std::shared_ptr<const Points2>> scans_keyframe;
  /// How far its scans may lie from where the map puts them: the mean of the (x, y, yaw)
  /// covariances (map frame, carried to this keyframe's pose) that the run published for the
  /// frames whose scans it holds (the keyframe's own, the frames that joined it, revisits,
  /// each placed by its own tracking). A run localized on this map later adds it to its own
  /// (Slam, localization_only); a loop closure that moves the keyframe since leaves it as it
  /// was, on the safe side.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// A planar pose as three numbers, so that a saved graph reads back bit for bit.
struct PlanarPose {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

/// What a KeyframeGraph needs to continue in another process (io/snapshot.hpp stores it):
/// the keyframes with their scans, the order the scans were integrated in, the pose-graph
/// edges (the nodes are the keyframe poses), and where the path stands. Not the per-frame
/// trajectory: a resumed run starts its own. The scans are shared, immutable, as in the
/// graph, so exporting one from a running graph copies no points.
struct KeyframeGraphState {
  struct SavedKeyframe {
    PlanarPose T_map_keyframe;
    double path_m = 0.0;
    std::vector<std::shared_ptr<const Points2>> scans_keyframe;  ///< keyframe coordinates
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();        ///< Keyframe::covariance
  };
  struct SavedEdge {
    int from = 0;
    int to = 0;
    PlanarPose T_from_to;
    Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
    bool loop = false;
  };
  std::vector<SavedKeyframe> keyframes;
  std::vector<std::pair<int, int>> integration_order;  ///< (keyframe, scan within it)
  std::vector<SavedEdge> edges;
  double path_m = 0.0;    ///< travelled so far
  PlanarPose last_frame;  ///< the last recorded frame's pose (the path continues from it)

  /// Integrated scans (integration_order's size).
  [[nodiscard]] std::size_t integrations() const { return integration_order.size(); }
};

/// What makes `state` unusable as a KeyframeGraph, or an empty string: non-finite values,
/// negative or decreasing path lengths, a null scan, edge nodes out of range or equal, an
/// information matrix that is not symmetric positive definite, an integration order that
/// does not name every stored scan exactly once, a keyframe covariance that is not symmetric
/// positive semi-definite.
[[nodiscard]] std::string keyframe_graph_state_error(const KeyframeGraphState &state);

/// A stored scan and the pose it is integrated at.
struct PlacedScan {
  std::shared_ptr<const Points2> scan_keyframe;  ///< keyframe coordinates, shared with the graph
  Eigen::Isometry2d T_map_keyframe = Eigen::Isometry2d::Identity();
};

class KeyframeGraph {
 public:
  explicit KeyframeGraph(KeyframeConfig config = {}) : config_(config) {}
  /// Continues a saved graph (std::invalid_argument when keyframe_graph_state_error finds
  /// a fault). `chained`: the next keyframe is joined to the saved last one by a
  /// sequential edge, as if the run had not stopped (the saved pose taken as is); false
  /// (the pose found afresh, e.g. by relocalisation): the next integrated frame starts a
  /// keyframe with no edge to the saved ones, which only loop closure then ties.
  KeyframeGraph(KeyframeConfig config, const KeyframeGraphState &state, bool chained);

  /// The state to save (keyframes, scans shared, integration order, edges, path).
  [[nodiscard]] KeyframeGraphState state() const;

  /// Records an integrated frame at `T_map_base` with its scan (base_link); it becomes a
  /// keyframe when far enough from the keyframe the frames are anchored to (the last one,
  /// or the one last revisited), joined to it by a sequential edge whose covariance is
  /// `tracked_covariance` (map frame: the tracking's uncertainty of this pose relative to
  /// that keyframe) plus the floor. Returns whether it did.
  bool add_integrated(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                      const Eigen::Matrix3d &tracked_covariance);
  /// Counts the published covariance of the frame whose scan was stored last (at
  /// `T_map_base`, map frame) into the covariance of the keyframe that holds the scan
  /// (Keyframe::covariance, a mean over its scans). Nothing when no scan is stored.
  void add_scan_covariance(const Eigen::Matrix3d &covariance, const Eigen::Isometry2d &T_map_base);
  /// Records a frame that was not integrated (only its pose, relative to the keyframe the
  /// frames are anchored to: the last one, or the one revisited).
  void add_pose(const Eigen::Isometry2d &T_map_base);
  /// Places the already recorded frame `frame` (a trajectory() index) at `T_map_base`,
  /// anchored to the keyframe frames are anchored to now: a pose known only afterwards (the
  /// frames of a lost stretch, placed back from where the robot was found). Out of range:
  /// std::out_of_range.
  void place_frame(int frame, const Eigen::Isometry2d &T_map_base);
  /// Whether a frame integrated at `T_map_base` would become a keyframe (add_integrated).
  [[nodiscard]] bool makes_keyframe(const Eigen::Isometry2d &T_map_base) const;
  /// Whether a frame at `T_map_base` has room to be integrated: it would make a keyframe, or
  /// the keyframe it would join (`revisit` when >= 0, else the last) holds fewer than
  /// max_scans scans.
  [[nodiscard]] bool has_room(const Eigen::Isometry2d &T_map_base, int revisit) const;

  /// The keyframe a frame at `T_map_base` revisits: the nearest within keyframe_distance_m
  /// that lies at least `min_path_gap_m` back along the path (a place mapped before, not the
  /// trail just laid) and that a loop edge joins (matched by a fit constrained in every
  /// direction), or -1.
  [[nodiscard]] int revisited(const Eigen::Isometry2d &T_map_base, double min_path_gap_m) const;
  /// The keyframe nearest `T_map_base` in position, or -1 when there is none.
  [[nodiscard]] int nearest(const Eigen::Isometry2d &T_map_base) const;
  /// Records an integrated frame in a place the graph already holds: anchored to keyframe
  /// `keyframe` (its pose relative to it, so it follows the graph) and its scan (base_link)
  /// stored there, no new keyframe. The next keyframe is joined to `keyframe` by its
  /// sequential edge.
  void add_revisit(int keyframe, const Points2 &scan_base, const Eigen::Isometry2d &T_map_base);
  /// The same for a frame that is not integrated (its keyframe is full): only its pose,
  /// anchored to `keyframe`.
  void add_revisit(int keyframe, const Eigen::Isometry2d &T_map_base);

  /// Adds a loop edge: keyframe `current` seen at T_candidate_current from `candidate`.
  void add_loop(int candidate, int current, const Eigen::Isometry2d &T_candidate_current,
                const Eigen::Matrix3d &covariance);
  /// Whether keyframe `current` already has a loop edge.
  [[nodiscard]] bool has_loop(int current) const;
  /// Solves the graph (warm start from the current keyframe poses) and takes its poses.
  /// Returns the solver's report and the largest keyframe displacement it made.
  struct Correction {
    PoseGraphResult solve;
    double max_shift_m = 0.0;
  };
  Correction optimize(const PoseGraphConfig &config);

  /// The scans of the keyframes whose path position lies within `path_radius_m` of
  /// keyframe `center`'s (and not beyond `max_path_m`), in `center`'s coordinates.
  [[nodiscard]] Points2 submap(int center, double path_radius_m, double max_path_m) const;
  /// A new map of `base` (restored points, may be empty) plus every stored scan at its
  /// keyframe's current pose, integrated in the order they were first integrated.
  [[nodiscard]] PointMap rebuilt_map(const PointMapConfig &config, const std::vector<MapPoint> &base,
                                     int base_integrations) const;

  /// A copy for a loop search on another thread: keyframes (their scans shared, not
  /// copied), pose graph and integration order, without the per-frame trajectory.
  [[nodiscard]] KeyframeGraph without_trajectory() const;
  /// Takes the poses and edges of `solved`, a copy of this graph made when it had
  /// `copied_edges` edges and then given loop edges and optimised. Keyframes and edges
  /// added here since the copy stay; the new keyframes move with the copy's newest
  /// keyframe. Returns the correction of the keyframe new frames are anchored to
  /// (T_corrected_tracked, map frame): the copy's newest keyframe's, unless an older
  /// keyframe is being revisited.
  Eigen::Isometry2d adopt(const KeyframeGraph &solved, std::size_t copied_edges);
  /// The stored scans from the `first`-th integrated one on, each with the pose it would
  /// have once `solved` (as for adopt) is adopted.
  [[nodiscard]] std::vector<PlacedScan> scans_since(std::size_t first, const KeyframeGraph &solved) const;
  /// Integrates into `map` the stored scans from the `first`-th integrated one on, at their
  /// keyframes' current poses (a map rebuilt from a copy, caught up with this graph).
  void integrate_since(PointMap &map, std::size_t first) const;
  /// Integrated scans recorded so far.
  [[nodiscard]] std::size_t integrations() const { return integration_order_.size(); }

  /// Every recorded frame's pose following its keyframe's current pose (frames before the
  /// first keyframe keep the pose they were recorded with).
  [[nodiscard]] std::vector<Eigen::Isometry2d> trajectory() const;

  [[nodiscard]] const std::vector<Keyframe> &keyframes() const { return keyframes_; }
  /// How many frames are recorded (trajectory()'s size).
  [[nodiscard]] int frame_count() const { return static_cast<int>(frames_.size()); }
  [[nodiscard]] int last() const { return static_cast<int>(keyframes_.size()) - 1; }
  /// The keyframe new frames are anchored to (-1 before the first).
  [[nodiscard]] int anchor_keyframe() const { return anchor_; }
  [[nodiscard]] const PoseGraph &graph() const { return graph_; }
  [[nodiscard]] const KeyframeConfig &config() const { return config_; }

 private:
  struct FrameAnchor {
    int keyframe = -1;  ///< -1: before any keyframe, T is then in the map frame
    Eigen::Isometry2d T_keyframe_base = Eigen::Isometry2d::Identity();
  };
  [[nodiscard]] FrameAnchor anchor(const Eigen::Isometry2d &T_map_base) const;
  /// Stores the last recorded frame's scan in the keyframe it is anchored to.
  void store_scan(const Points2 &scan_base);
  /// Recomputes matched_ from the pose graph's loop edges (after a solve or an adoption,
  /// which may have removed some).
  void mark_matched();

  KeyframeConfig config_;
  std::vector<Keyframe> keyframes_;
  std::vector<FrameAnchor> frames_;
  /// Order of integration: (keyframe, scan index within it), to rebuild the map as it grew.
  std::vector<std::pair<int, int>> integration_order_;
  PoseGraph graph_;
  double path_m_ = 0.0;  ///< travelled so far, summed frame to frame
  Eigen::Isometry2d last_frame_ = Eigen::Isometry2d::Identity();
  /// The keyframe frames are anchored to and the next keyframe's sequential edge starts
  /// from: the last keyframe, or the old one a revisiting frame was anchored to.
  int anchor_ = -1;
  /// Per keyframe: a loop edge joins it (revisited() takes only these), kept up to date as
  /// loop edges come and go, so the per-frame test does not walk the edges.
  std::vector<char> matched_;
  /// false after a resume whose pose does not continue the saved tracking: the next
  /// integrated frame is a keyframe without a sequential edge.
  bool chained_ = true;
};

}  // namespace omnislam::slam
