#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/loop_closure.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/trimmed_icp.hpp"

/// @file
/// Loop closure as a self-contained job, so that it can run beside the tracking: at a new
/// keyframe Slam hands out a LoopJob (a copy of the keyframe graph whose scans are shared,
/// immutable, with everything the search, the confirmation, the solve and the map rebuild
/// need); run_loop_job() computes its LoopResult on any thread; Slam takes the result at a
/// later frame (Slam::apply_loop_result). Run inline, at the keyframe, it gives what the
/// synchronous loop closure gave.

namespace omnislam::slam {

struct LoopResult;

struct LoopJob {
  std::uint64_t generation = 0;  ///< Slam's, so a result from before a resume is ignored
  /// The graph when the job was made (without the per-frame trajectory); its newest
  /// keyframe is the one searched.
  KeyframeGraph graph;
  std::size_t edges = 0;  ///< graph's edges then: later ones are the caller's
  /// The previous searched keyframe's accepted loop (to be confirmed by this one), and the
  /// last loop edge added (narrows the search windows).
  std::optional<LoopMatch> pending;
  std::optional<LoopMatch> last_loop;
  /// A resumed map: the base a rebuild starts from (may be null).
  std::shared_ptr<const std::vector<MapPoint>> restored_points;
  int restored_integrations = 0;
  LoopClosureConfig config;
  TrimmedIcpConfig icp;
  PointMapConfig map;
  /// A catch-up job instead of a search: the result whose rebuilt map lags the tracking,
  /// and the scans integrated since, at their corrected poses, to integrate into it.
  std::shared_ptr<LoopResult> catch_up;
  std::vector<PlacedScan> scans_since;
};

struct LoopResult {
  std::uint64_t generation = 0;
  std::size_t copied_edges = 0;  ///< LoopJob::edges
  LoopMatch match;               ///< the searched keyframe's hypothesis (status says why not)
  /// Two consecutive searched keyframes agree: both loop edges were added and `solved`
  /// holds the optimised graph.
  bool confirmed = false;
  std::optional<KeyframeGraph> solved;
  KeyframeGraph::Correction correction;
  /// The map rebuilt from the optimised keyframes, when the correction moved one by more
  /// than rebuild_min_shift_m; it holds the graph's first map_integrations scans.
  std::optional<PointMap> map;
  std::size_t map_integrations = 0;
  int catch_up_rounds = 0;  ///< catch-up jobs this result went through
};

/// Searches a loop at the job's newest keyframe, confirms it against `pending` (the loops
/// of two consecutive searched keyframes must imply the same correction), and when
/// confirmed adds both loop edges, optimises the graph and, after a large enough
/// correction, rebuilds the map. A catch-up job instead integrates its scans into its
/// result's map. Pure computation on the caller's thread.
[[nodiscard]] LoopResult run_loop_job(LoopJob job);

}  // namespace omnislam::slam
