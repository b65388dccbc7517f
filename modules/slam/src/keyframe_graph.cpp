#include "omnislam/slam/keyframe_graph.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

// How the optimisation moved the newest keyframe of a copy of the first `copied` keyframes.
Eigen::Isometry2d newest_correction(const std::vector<Keyframe> &solved, const std::vector<Keyframe> &live,
                                    std::size_t copied) {
  if (copied == 0) return Eigen::Isometry2d::Identity();
  return solved[copied - 1].T_map_keyframe * live[copied - 1].T_map_keyframe.inverse();
}

// Keyframe k's pose once `solved` is adopted: its optimised pose, or for a keyframe made
// since the copy, its tracked pose moved like the copy's newest keyframe (re-made a
// rotation: repeated corrections would otherwise compound the rounding, planar_pose.hpp).
Eigen::Isometry2d corrected_pose(std::size_t k, std::size_t copied, const std::vector<Keyframe> &solved,
                                 const std::vector<Keyframe> &live,
                                 const Eigen::Isometry2d &T_corrected_tracked) {
  return k < copied ? solved[k].T_map_keyframe
                    : orthonormalized(T_corrected_tracked * live[k].T_map_keyframe);
}

PlanarPose planar_of(const Eigen::Isometry2d &T) {
  return {T.translation().x(), T.translation().y(), yaw_rad_of(T)};
}

Eigen::Isometry2d isometry_of(const PlanarPose &pose) {
  return planar_pose(pose.x_m, pose.y_m, pose.yaw_rad);
}

bool finite(const PlanarPose &pose) {
  return std::isfinite(pose.x_m) && std::isfinite(pose.y_m) && std::isfinite(pose.yaw_rad);
}

// A pose graph edge's information must whiten its residual (a Cholesky factor exists):
// symmetric (up to the rounding of a covariance's inverse) and positive definite.
bool usable_information(const Eigen::Matrix3d &information) {
  if (!information.allFinite()) return false;
  if ((information - information.transpose()).cwiseAbs().maxCoeff() >
      1e-9 * information.cwiseAbs().maxCoeff())
    return false;
  return Eigen::LLT<Eigen::Matrix3d>(information).info() == Eigen::Success;
}

// A covariance: finite, symmetric, no negative variance in any direction (zero is allowed:
// the first keyframe defines the map frame).
bool usable_covariance(const Eigen::Matrix3d &covariance) {
  if (!covariance.allFinite()) return false;
  const double scale = covariance.cwiseAbs().maxCoeff();
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance, Eigen::EigenvaluesOnly)
             .eigenvalues()
             .minCoeff() >= -1e-9 * scale;
}

std::string keyframe_error(const KeyframeGraphState::SavedKeyframe &keyframe, std::size_t k,
                           double previous_path_m) {
  const std::string which = "keyframe " + std::to_string(k);
  if (!finite(keyframe.T_map_keyframe)) return which + ": pose is not finite";
  if (!std::isfinite(keyframe.path_m) || keyframe.path_m < previous_path_m)
    return which + ": path_m " + std::to_string(keyframe.path_m) +
           " is not finite or below the previous "
           "keyframe's " +
           std::to_string(previous_path_m);
  for (std::size_t i = 0; i < keyframe.scans_keyframe.size(); ++i) {
    const std::shared_ptr<const Points2> &scan = keyframe.scans_keyframe[i];
    if (!scan) return which + ": scan " + std::to_string(i) + " is missing";
    for (const Point2 &p : *scan)
      if (!p.allFinite()) return which + ": scan " + std::to_string(i) + " has a non-finite point";
  }
  if (!usable_covariance(keyframe.covariance))
    return which + ": covariance is not symmetric positive semi-definite";
  return {};
}

std::string edge_error(const KeyframeGraphState::SavedEdge &edge, std::size_t e, std::size_t keyframes) {
  const std::string which = "edge " + std::to_string(e);
  const auto in_range = [&](int node) { return node >= 0 && static_cast<std::size_t>(node) < keyframes; };
  if (!in_range(edge.from) || !in_range(edge.to) || edge.from == edge.to) {
    return which + " joins keyframes " + std::to_string(edge.from) + " and " + std::to_string(edge.to) +
           " (" + std::to_string(keyframes) + " keyframes)";
  }
  if (!finite(edge.T_from_to)) return which + ": relative pose is not finite";
  if (!usable_information(edge.information))
    return which + ": information is not symmetric positive definite";
  return {};
}

// Every stored scan named once by the integration order, so a rebuilt map holds each once.
std::string integration_order_error(const KeyframeGraphState &state) {
  std::vector<std::vector<bool>> seen;
  std::size_t scans = 0;
  for (const auto &keyframe : state.keyframes) {
    seen.emplace_back(keyframe.scans_keyframe.size(), false);
    scans += keyframe.scans_keyframe.size();
  }
  if (state.integration_order.size() != scans) {
    return "the integration order names " + std::to_string(state.integration_order.size()) +
           " scans, the keyframes hold " + std::to_string(scans);
  }
  for (std::size_t i = 0; i < state.integration_order.size(); ++i) {
    const auto [k, scan] = state.integration_order[i];
    const bool valid = k >= 0 && static_cast<std::size_t>(k) < seen.size() && scan >= 0 &&
                       static_cast<std::size_t>(scan) < seen[static_cast<std::size_t>(k)].size();
    if (!valid || seen[static_cast<std::size_t>(k)][static_cast<std::size_t>(scan)]) {
      return "integration " + std::to_string(i) + " names scan " + std::to_string(scan) + " of keyframe " +
             std::to_string(k) + (valid ? ", named before" : ", which does not exist");
    }
    seen[static_cast<std::size_t>(k)][static_cast<std::size_t>(scan)] = true;
  }
  return {};
}

}  // namespace

std::string keyframe_graph_state_error(const KeyframeGraphState &state) {
  double path_m = 0.0;
  for (std::size_t k = 0; k < state.keyframes.size(); ++k) {
    if (std::string error = keyframe_error(state.keyframes[k], k, path_m); !error.empty()) return error;
    path_m = state.keyframes[k].path_m;
  }
  for (std::size_t e = 0; e < state.edges.size(); ++e)
    if (std::string error = edge_error(state.edges[e], e, state.keyframes.size()); !error.empty())
      return error;
  if (std::string error = integration_order_error(state); !error.empty()) return error;
  if (!std::isfinite(state.path_m) || state.path_m < path_m)
    return "path_m " + std::to_string(state.path_m) + " is not finite or below the last keyframe's";
  if (!finite(state.last_frame)) return "the last frame's pose is not finite";
  return {};
}

KeyframeGraph::KeyframeGraph(KeyframeConfig config, const KeyframeGraphState &state, bool chained)
    : config_(config), path_m_(state.path_m), last_frame_(isometry_of(state.last_frame)), chained_(chained) {
  if (std::string error = keyframe_graph_state_error(state); !error.empty())
    throw std::invalid_argument("keyframe graph state: " + error);
  for (const KeyframeGraphState::SavedKeyframe &saved : state.keyframes) {
    keyframes_.push_back(
        {isometry_of(saved.T_map_keyframe), saved.path_m, saved.scans_keyframe, saved.covariance});
    graph_.add_node(keyframes_.back().T_map_keyframe);
  }
  for (const KeyframeGraphState::SavedEdge &edge : state.edges)
    graph_.add_edge({edge.from, edge.to, isometry_of(edge.T_from_to), edge.information, edge.loop});
  integration_order_ = state.integration_order;
  mark_matched();
  // The saved run was revisiting when its last frame lies beyond a keyframe's reach of the
  // last keyframe but within that of a matched one (a snapshot does not name the anchor).
  anchor_ = last();
  if (anchor_ >= 0 && (keyframes_.back().T_map_keyframe.translation() - last_frame_.translation()).norm() >=
                          config_.keyframe_distance_m) {
    if (const int revisited = this->revisited(last_frame_, 0.0); revisited >= 0) anchor_ = revisited;
  }
}

KeyframeGraphState KeyframeGraph::state() const {
  KeyframeGraphState state;
  for (const Keyframe &keyframe : keyframes_)
    state.keyframes.push_back(
        {planar_of(keyframe.T_map_keyframe), keyframe.path_m, keyframe.scans_keyframe, keyframe.covariance});
  for (const PoseGraphEdge &edge : graph_.edges())
    state.edges.push_back({edge.from, edge.to, planar_of(edge.T_from_to), edge.information, edge.loop});
  state.integration_order = integration_order_;
  state.path_m = path_m_;
  state.last_frame = planar_of(last_frame_);
  return state;
}

KeyframeGraph::FrameAnchor KeyframeGraph::anchor(const Eigen::Isometry2d &T_map_base) const {
  if (anchor_ < 0) return {-1, T_map_base};
  return {anchor_, keyframes_[static_cast<std::size_t>(anchor_)].T_map_keyframe.inverse() * T_map_base};
}

void KeyframeGraph::add_scan_covariance(const Eigen::Matrix3d &covariance,
                                        const Eigen::Isometry2d &T_map_base) {
  if (integration_order_.empty()) return;
  Keyframe &keyframe = keyframes_[static_cast<std::size_t>(integration_order_.back().first)];
  // Carried from the frame to the keyframe (the frame's heading error swings its scan about
  // the frame, not the keyframe), then into the running mean over the keyframe's scans.
  const double scans = static_cast<double>(keyframe.scans_keyframe.size());
  keyframe.covariance +=
      (carried(covariance, T_map_base, keyframe.T_map_keyframe) - keyframe.covariance) / scans;
}

void KeyframeGraph::add_pose(const Eigen::Isometry2d &T_map_base) {
  frames_.push_back(anchor(T_map_base));
  if (!keyframes_.empty()) path_m_ += (T_map_base.translation() - last_frame_.translation()).norm();
  last_frame_ = T_map_base;
}

void KeyframeGraph::place_frame(int frame, const Eigen::Isometry2d &T_map_base) {
  frames_.at(static_cast<std::size_t>(frame)) = anchor(T_map_base);
}

int KeyframeGraph::revisited(const Eigen::Isometry2d &T_map_base, double min_path_gap_m) const {
  // Only places a loop edge joins: each was matched against another visit's scans by a fit
  // constrained in every direction (the loop search refuses a plain corridor's).
  int nearest = -1;
  double nearest_m = config_.keyframe_distance_m;
  for (int k = 0; k <= last(); ++k) {
    const Keyframe &keyframe = keyframes_[static_cast<std::size_t>(k)];
    if (path_m_ - keyframe.path_m < min_path_gap_m) break;  // path_m grows with k
    if (!matched_[static_cast<std::size_t>(k)]) continue;
    const double distance_m = (keyframe.T_map_keyframe.translation() - T_map_base.translation()).norm();
    if (distance_m < nearest_m) {
      nearest = k;
      nearest_m = distance_m;
    }
  }
  return nearest;
}

int KeyframeGraph::nearest(const Eigen::Isometry2d &T_map_base) const {
  int nearest = -1;
  double nearest_m = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= last(); ++k) {
    const double distance_m =
        (keyframes_[static_cast<std::size_t>(k)].T_map_keyframe.translation() - T_map_base.translation())
            .norm();
    if (distance_m < nearest_m) {
      nearest = k;
      nearest_m = distance_m;
    }
  }
  return nearest;
}

void KeyframeGraph::add_revisit(int keyframe, const Points2 &scan_base, const Eigen::Isometry2d &T_map_base) {
  add_revisit(keyframe, T_map_base);
  store_scan(scan_base);
}

void KeyframeGraph::add_revisit(int keyframe, const Eigen::Isometry2d &T_map_base) {
  if (keyframe < 0 || keyframe > last())
    throw std::out_of_range("KeyframeGraph::add_revisit: keyframe " + std::to_string(keyframe) + " of " +
                            std::to_string(keyframes_.size()));
  path_m_ += (T_map_base.translation() - last_frame_.translation()).norm();
  last_frame_ = T_map_base;
  anchor_ = keyframe;
  frames_.push_back(anchor(T_map_base));
}

bool KeyframeGraph::makes_keyframe(const Eigen::Isometry2d &T_map_base) const {
  // After a resume that does not continue the saved tracking, the first integrated frame
  // starts a keyframe of its own: its scan belongs to none of the saved keyframes.
  if (keyframes_.empty() || !chained_) return true;
  const Eigen::Isometry2d step =
      keyframes_[static_cast<std::size_t>(anchor_)].T_map_keyframe.inverse() * T_map_base;
  return step.translation().norm() >= config_.keyframe_distance_m ||
         std::abs(yaw_rad_of(step)) >= config_.keyframe_angle_rad;
}

bool KeyframeGraph::has_room(const Eigen::Isometry2d &T_map_base, int revisit) const {
  if (revisit < 0 && makes_keyframe(T_map_base)) return true;
  const Keyframe &joined = keyframes_[static_cast<std::size_t>(revisit >= 0 ? revisit : last())];
  return joined.scans_keyframe.size() < static_cast<std::size_t>(config_.max_scans);
}

void KeyframeGraph::mark_matched() {
  matched_.assign(keyframes_.size(), 0);
  for (const PoseGraphEdge &edge : graph_.edges()) {
    if (!edge.loop) continue;
    matched_[static_cast<std::size_t>(edge.from)] = 1;
    matched_[static_cast<std::size_t>(edge.to)] = 1;
  }
}

void KeyframeGraph::store_scan(const Points2 &scan_base) {
  Keyframe &keyframe = keyframes_[static_cast<std::size_t>(anchor_)];
  keyframe.scans_keyframe.push_back(
      std::make_shared<const Points2>(transformed(scan_base, frames_.back().T_keyframe_base)));
  integration_order_.emplace_back(anchor_, static_cast<int>(keyframe.scans_keyframe.size()) - 1);
}

bool KeyframeGraph::add_integrated(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                   const Eigen::Matrix3d &tracked_covariance) {
  if (!keyframes_.empty()) path_m_ += (T_map_base.translation() - last_frame_.translation()).norm();
  last_frame_ = T_map_base;
  const bool is_keyframe = makes_keyframe(T_map_base);
  if (is_keyframe) {
    const int node = graph_.add_node(T_map_base);
    if (node > 0 && chained_) {
      // The sequential edge: the relative pose the tracking produced, with the
      // tracking's covariance over it plus the floor.
      const Keyframe &previous = keyframes_[static_cast<std::size_t>(anchor_)];
      const Eigen::Isometry2d T_previous_current = previous.T_map_keyframe.inverse() * T_map_base;
      const Eigen::Vector3d floor(config_.edge_floor_xy_m, config_.edge_floor_xy_m,
                                  config_.edge_floor_yaw_rad);
      const Eigen::Matrix3d covariance =
          rotated_covariance(tracked_covariance, previous.T_map_keyframe.linear().transpose()) +
          Eigen::Matrix3d(floor.cwiseAbs2().asDiagonal());
      graph_.add_edge({anchor_, node, T_previous_current, covariance.inverse(), false});
    }
    keyframes_.push_back({T_map_base, path_m_, {}});
    matched_.push_back(0);
    chained_ = true;
  }
  // An integrated frame lays new trail: it belongs to the last keyframe.
  anchor_ = last();
  frames_.push_back(anchor(T_map_base));
  store_scan(scan_base);
  return is_keyframe;
}

void KeyframeGraph::add_loop(int candidate, int current, const Eigen::Isometry2d &T_candidate_current,
                             const Eigen::Matrix3d &covariance) {
  graph_.add_edge({candidate, current, T_candidate_current, covariance.inverse(), true});
  matched_[static_cast<std::size_t>(candidate)] = matched_[static_cast<std::size_t>(current)] = 1;
}

bool KeyframeGraph::has_loop(int current) const {
  return std::any_of(graph_.edges().begin(), graph_.edges().end(),
                     [&](const PoseGraphEdge &edge) { return edge.loop && edge.to == current; });
}

KeyframeGraph::Correction KeyframeGraph::optimize(const PoseGraphConfig &config) {
  Correction correction;
  correction.solve = graph_.optimize(config);
  mark_matched();  // the solve may have removed loop edges
  for (int k = 0; k <= last(); ++k) {
    Keyframe &keyframe = keyframes_[static_cast<std::size_t>(k)];
    const Eigen::Isometry2d optimised = graph_.pose(k);
    correction.max_shift_m = std::max(
        correction.max_shift_m, (optimised.translation() - keyframe.T_map_keyframe.translation()).norm());
    keyframe.T_map_keyframe = optimised;
  }
  return correction;
}

Points2 KeyframeGraph::submap(int center, double path_radius_m, double max_path_m) const {
  const Keyframe &middle = keyframes_[static_cast<std::size_t>(center)];
  const Eigen::Isometry2d T_center_map = middle.T_map_keyframe.inverse();
  Points2 points;
  for (const Keyframe &keyframe : keyframes_) {
    if (std::abs(keyframe.path_m - middle.path_m) > path_radius_m || keyframe.path_m > max_path_m) continue;
    const Eigen::Isometry2d T_center_keyframe = T_center_map * keyframe.T_map_keyframe;
    for (const auto &scan : keyframe.scans_keyframe)
      for (const Point2 &p : *scan) points.push_back(T_center_keyframe * p);
  }
  return points;
}

PointMap KeyframeGraph::rebuilt_map(const PointMapConfig &config, const std::vector<MapPoint> &base,
                                    int base_integrations) const {
  PointMap map = base.empty() ? PointMap(config) : PointMap(config, base, base_integrations);
  integrate_since(map, 0);
  return map;
}

void KeyframeGraph::integrate_since(PointMap &map, std::size_t first) const {
  for (std::size_t i = first; i < integration_order_.size(); ++i) {
    const auto &[k, scan] = integration_order_[i];
    const Keyframe &keyframe = keyframes_[static_cast<std::size_t>(k)];
    map.integrate(
        transformed(*keyframe.scans_keyframe[static_cast<std::size_t>(scan)], keyframe.T_map_keyframe));
  }
}

KeyframeGraph KeyframeGraph::without_trajectory() const {
  KeyframeGraph copy(config_);
  copy.keyframes_ = keyframes_;
  copy.integration_order_ = integration_order_;
  copy.graph_ = graph_;
  copy.path_m_ = path_m_;
  copy.last_frame_ = last_frame_;
  copy.chained_ = chained_;
  copy.anchor_ = anchor_;
  copy.matched_ = matched_;
  return copy;
}

std::vector<PlacedScan> KeyframeGraph::scans_since(std::size_t first, const KeyframeGraph &solved) const {
  const std::size_t copied = std::min(solved.keyframes_.size(), keyframes_.size());
  const Eigen::Isometry2d T_corrected_tracked = newest_correction(solved.keyframes_, keyframes_, copied);
  std::vector<PlacedScan> scans;
  for (std::size_t i = first; i < integration_order_.size(); ++i) {
    const auto k = static_cast<std::size_t>(integration_order_[i].first);
    scans.push_back({keyframes_[k].scans_keyframe[static_cast<std::size_t>(integration_order_[i].second)],
                     corrected_pose(k, copied, solved.keyframes_, keyframes_, T_corrected_tracked)});
  }
  return scans;
}

Eigen::Isometry2d KeyframeGraph::adopt(const KeyframeGraph &solved, std::size_t copied_edges) {
  const std::size_t copied = solved.keyframes_.size();
  if (copied == 0 || copied > keyframes_.size()) return Eigen::Isometry2d::Identity();
  const Eigen::Isometry2d T_corrected_tracked = newest_correction(solved.keyframes_, keyframes_, copied);
  // The live pose follows the keyframe it is tracked against: the newest (or one made since
  // the copy, which moves with it), or an older one it revisits, which moves as solved.
  const auto anchor = static_cast<std::size_t>(anchor_);
  const Eigen::Isometry2d T_anchor_corrected =
      anchor_ >= 0 && anchor + 1 < copied ? orthonormalized(solved.keyframes_[anchor].T_map_keyframe *
                                                            keyframes_[anchor].T_map_keyframe.inverse())
                                          : T_corrected_tracked;
  for (std::size_t k = 0; k < keyframes_.size(); ++k)
    keyframes_[k].T_map_keyframe =
        corrected_pose(k, copied, solved.keyframes_, keyframes_, T_corrected_tracked);
  // The solved graph (its loop edges, without those it rejected), then what was added here
  // since the copy: the new keyframes' nodes and their sequential edges.
  PoseGraph graph = solved.graph_;
  for (std::size_t k = copied; k < keyframes_.size(); ++k) graph.add_node(keyframes_[k].T_map_keyframe);
  for (std::size_t e = copied_edges; e < graph_.edges().size(); ++e) graph.add_edge(graph_.edges()[e]);
  graph_ = std::move(graph);
  mark_matched();
  return T_anchor_corrected;
}

std::vector<Eigen::Isometry2d> KeyframeGraph::trajectory() const {
  std::vector<Eigen::Isometry2d> poses;
  poses.reserve(frames_.size());
  for (const FrameAnchor &frame : frames_) {
    poses.push_back(frame.keyframe < 0 ? frame.T_keyframe_base
                                       : keyframes_[static_cast<std::size_t>(frame.keyframe)].T_map_keyframe *
                                             frame.T_keyframe_base);
  }
  return poses;
}

}  // namespace omnislam::slam
