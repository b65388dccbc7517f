#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/pose_graph.hpp"
#include "omnislam/slam/trimmed_icp.hpp"

/// @file
/// Loop closure over the keyframe graph: at each new keyframe, candidates are keyframes far
/// back along the path but within the current pose's drift-grown uncertainty; each is
/// verified by a correlative search (a grid over x, y, yaw scored on the candidate's local
/// submap) and Trimmed ICP, and a loop is accepted only when the fit is good, overlaps, is
/// not degenerate, clearly beats any other hypothesis, and the next keyframe agrees. Plain
/// computation on its caller's thread; its cost per keyframe is bounded by max_candidates
/// (loop_job.hpp packs it as a job for another thread).

namespace omnislam::slam {

struct LoopClosureConfig {
  bool enabled = true;
  /// false: Slam::process runs each keyframe's loop job itself, so a correction lands on
  /// that keyframe's frame (deterministic: replay). true: Slam hands the job out
  /// (Slam::take_loop_job) for its caller to run beside the tracking and give back
  /// (Slam::apply_loop_result) at a later frame (the service: pose latency stays flat).
  bool background = false;
  KeyframeConfig keyframes;
  PoseGraphConfig graph;
  /// Once a confirmed loop closure has tied the robot to the graph, an integrated frame
  /// within keyframe_distance_m of a keyframe at least min_path_gap_m back along the path
  /// that a loop edge joins (a place mapped and matched again by a fit constrained in every
  /// direction: not a plain corridor, where keyframes keep coming so that the loops at its
  /// ends can correct it) is anchored to that keyframe and its scan stored there: no new
  /// keyframe. The pose graph, and with it every later loop search, solve and adoption
  /// of a solved graph, then grows with the area explored, not with the laps driven (and
  /// the stored scans with it: each keyframe holds at most KeyframeConfig::max_scans).
  /// Leaving the mapped places makes a keyframe again (joined to the one revisited last),
  /// and the tie lasts until then. false: every keyframe_distance_m of travel makes a
  /// keyframe, wherever it is.
  bool reuse_keyframes = true;
  /// A candidate lies at least this far back along the path (closer ones are already in
  /// the local map the tracking registers against).
  double min_path_gap_m = 5.0;
  /// Keyframes within this path distance of a keyframe form its submap.
  double submap_path_m = 1.5;
  /// A candidate's keyframe lies within this distance of the current one plus the search
  /// window (scans taken this far apart still share most of what they see).
  double max_candidate_distance_m = 1.5;
  int max_candidates = 3;  ///< verified per keyframe (bounds the cost)
  /// The correlative search window: 3 sigma of the drift grown over the path gap
  /// (KeyframeConfig::drift_per_m, drift_yaw_per_m), clamped to these.
  double max_window_m = 1.0;
  double max_window_rad = 0.1745;   ///< 10 deg
  double grid_resolution_m = 0.05;  ///< of the correlative search (and its scoring grid)
  int max_sample_points = 300;      ///< scored in the correlative search (evenly subsampled)
  /// Acceptance: the correlative score (mean likelihood of the points, 1 = all on the
  /// submap) at least min_score; any other pose more than distinct_m or distinct_rad away,
  /// and any other candidate's hypothesis, below ambiguity_ratio of the best.
  double min_score = 0.5;
  double ambiguity_ratio = 0.85;
  double distinct_m = 0.25;
  double distinct_rad = 0.0873;  ///< 5 deg
  /// Trimmed ICP from the correlative pose: residual RMS, share of points with a submap
  /// point within 0.1 m, and the share of the fit's information along its weakest direction
  /// (a corridor constrains only across itself: share ~0).
  double max_rms_m = 0.03;
  double min_overlap = 0.6;
  double min_weak_direction_share = 0.1;
  /// Two consecutive keyframes' loop hypotheses agree when the map corrections they imply
  /// differ by less than this.
  double agreement_m = 0.1;
  double agreement_rad = 0.035;  ///< 2 deg
  /// Loop edge covariance floor (added to the registration's).
  double loop_floor_xy_m = 0.01;
  double loop_floor_yaw_rad = 0.0087;
  /// A correction that moves no keyframe by more than this keeps the map (it is within
  /// half the map's fusion radius).
  double rebuild_min_shift_m = 0.025;
  /// Background only: a map rebuilt on the worker that lags the tracking by more than this
  /// many integrated scans goes back to the worker to catch up (at most
  /// max_catch_up_rounds times) before it replaces the live map, so the tracking thread
  /// integrates at most a few scans when it takes it.
  int max_catch_up_scans = 2;
  int max_catch_up_rounds = 3;
};

/// Why a loop hypothesis was accepted or not (the first failed check).
enum class LoopStatus {
  kAccepted,
  kNoCandidate,
  kLowScore,
  kAmbiguous,
  kBadFit,
  kSmallOverlap,
  kDegenerate,
};

/// A verified relative pose between two keyframes.
struct LoopMatch {
  LoopStatus status = LoopStatus::kNoCandidate;
  int candidate = -1;
  int current = -1;
  Eigen::Isometry2d T_candidate_current = Eigen::Isometry2d::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  ///< of T_candidate_current, with the floor
  double score = 0.0;                                        ///< correlative, at the best pose
  double second_score = 0.0;                                 ///< the best distinct pose or hypothesis
  TrimmedIcpResult registration;
};

/// Correlative search then Trimmed ICP of `current_points` (current keyframe coordinates)
/// onto `candidate_points` (candidate keyframe coordinates), around `guess`
/// (T_candidate_current) within +-window_m and +-window_rad.
[[nodiscard]] LoopMatch match_keyframes(const Points2 &candidate_points, const Points2 &current_points,
                                        const Eigen::Isometry2d &guess, double window_m, double window_rad,
                                        const LoopClosureConfig &config, const TrimmedIcpConfig &icp);

/// The loop hypotheses of the newest keyframe of `graph`: the best verified candidate's
/// match (status kAccepted) unless none passes or two disagree (kAmbiguous). The drift a
/// candidate's search window allows grows with the path between it and the current
/// keyframe, or, when `last_loop` (the last loop edge added) ties the current region to
/// the old path, with the path from the candidate to that loop's candidate plus the path
/// travelled since that loop, if shorter.
[[nodiscard]] LoopMatch search_loop(const KeyframeGraph &graph, const LoopClosureConfig &config,
                                    const TrimmedIcpConfig &icp,
                                    const std::optional<LoopMatch> &last_loop = {});

/// Whether two loop matches of consecutive keyframes imply the same map correction.
[[nodiscard]] bool agree(const KeyframeGraph &graph, const LoopMatch &earlier, const LoopMatch &later,
                         const LoopClosureConfig &config);

}  // namespace omnislam::slam
