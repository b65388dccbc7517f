#include "omnislam/slam/loop_job.hpp"

#include "omnislam/slam/planar_pose.hpp"

#include <utility>

namespace omnislam::slam {

LoopResult run_loop_job(LoopJob job) {
  if (job.catch_up) {
    LoopResult result = std::move(*job.catch_up);
    for (const PlacedScan &placed : job.scans_since)
      result.map->integrate(transformed(*placed.scan_keyframe, placed.T_map_keyframe));
    result.map_integrations += job.scans_since.size();
    ++result.catch_up_rounds;
    return result;
  }
  LoopResult result;
  result.generation = job.generation;
  result.copied_edges = job.edges;
  KeyframeGraph &graph = job.graph;
  const LoopClosureConfig &loops = job.config;
  // A loop hypothesis is verified at this keyframe, and used only when the previous
  // searched keyframe's agrees with it (one match can be fooled; two in a row rarely are).
  result.match = search_loop(graph, loops, job.icp, job.last_loop);
  const LoopMatch &match = result.match;
  if (match.status != LoopStatus::kAccepted) return result;
  const std::optional<LoopMatch> &pending = job.pending;
  result.confirmed = pending && pending->current < match.current && agree(graph, *pending, match, loops);
  if (!result.confirmed) return result;
  if (!graph.has_loop(pending->current))
    graph.add_loop(pending->candidate, pending->current, pending->T_candidate_current, pending->covariance);
  graph.add_loop(match.candidate, match.current, match.T_candidate_current, match.covariance);

  // Optimise (warm start: the graph holds the tracking's estimate), and rebuild the map
  // from the corrected keyframes when they moved beyond the map's fusion.
  result.correction = graph.optimize(loops.graph);
  if (result.correction.max_shift_m > loops.rebuild_min_shift_m) {
    const std::vector<MapPoint> none;
    result.map = graph.rebuilt_map(job.map, job.restored_points ? *job.restored_points : none,
                                   job.restored_integrations);
    result.map_integrations = graph.integrations();
  }
  result.solved = std::move(graph);
  return result;
}

}  // namespace omnislam::slam
