#include "omnislam/slam/keyframe_graph.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

// A (x, y, yaw) covariance given in the map frame, expressed in a frame turned by R.
Eigen::Matrix3d in_frame(const Eigen::Matrix3d &covariance_map, const Eigen::Matrix2d &R_map_frame) {
  Eigen::Matrix3d rotate = Eigen::Matrix3d::Identity();
  rotate.topLeftCorner<2, 2>() = R_map_frame.transpose();
  return rotate * covariance_map * rotate.transpose();
}

}  // namespace

KeyframeGraph::FrameAnchor KeyframeGraph::anchor(const Eigen::Isometry2d &T_map_base) const {
  if (keyframes_.empty()) return {-1, T_map_base};
  return {last(), keyframes_.back().T_map_keyframe.inverse() * T_map_base};
}

void KeyframeGraph::add_pose(const Eigen::Isometry2d &T_map_base) {
  frames_.push_back(anchor(T_map_base));
  if (!keyframes_.empty()) path_m_ += (T_map_base.translation() - last_frame_.translation()).norm();
  last_frame_ = T_map_base;
}

bool KeyframeGraph::add_integrated(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                   const Eigen::Matrix3d &registration_covariance) {
  if (!keyframes_.empty()) path_m_ += (T_map_base.translation() - last_frame_.translation()).norm();
  last_frame_ = T_map_base;
  bool is_keyframe = keyframes_.empty();
  if (!is_keyframe) {
    const Eigen::Isometry2d step = keyframes_.back().T_map_keyframe.inverse() * T_map_base;
    is_keyframe = step.translation().norm() >= config_.keyframe_distance_m ||
                  std::abs(yaw_rad_of(step)) >= config_.keyframe_angle_rad;
  }
  if (is_keyframe) {
    const int node = graph_.add_node(T_map_base);
    if (node > 0) {
      // The sequential edge: the relative pose the tracking produced, with the
      // registration's covariance plus the drift the tracking can accumulate over it.
      const Keyframe &previous = keyframes_.back();
      const Eigen::Isometry2d T_previous_current = previous.T_map_keyframe.inverse() * T_map_base;
      const double travelled_m = path_m_ - previous.path_m;
      const double sigma_xy = config_.edge_floor_xy_m + config_.drift_per_m * travelled_m;
      const double sigma_yaw = config_.edge_floor_yaw_rad + config_.drift_yaw_per_m * travelled_m;
      const Eigen::Matrix3d covariance =
          in_frame(registration_covariance, previous.T_map_keyframe.linear()) +
          Eigen::Vector3d(sigma_xy * sigma_xy, sigma_xy * sigma_xy, sigma_yaw * sigma_yaw)
              .asDiagonal()
              .toDenseMatrix();
      graph_.add_edge({node - 1, node, T_previous_current, covariance.inverse(), false});
    }
    keyframes_.push_back({T_map_base, path_m_, {}});
  }
  frames_.push_back(anchor(T_map_base));
  keyframes_.back().scans_keyframe.push_back(
      std::make_shared<const Points2>(transformed(scan_base, frames_.back().T_keyframe_base)));
  integration_order_.emplace_back(last(), static_cast<int>(keyframes_.back().scans_keyframe.size()) - 1);
  return is_keyframe;
}

void KeyframeGraph::add_loop(int candidate, int current, const Eigen::Isometry2d &T_candidate_current,
                             const Eigen::Matrix3d &covariance) {
  graph_.add_edge({candidate, current, T_candidate_current, covariance.inverse(), true});
}

bool KeyframeGraph::has_loop(int current) const {
  return std::any_of(graph_.edges().begin(), graph_.edges().end(),
                     [&](const PoseGraphEdge &edge) { return edge.loop && edge.to == current; });
}

KeyframeGraph::Correction KeyframeGraph::optimize(const PoseGraphConfig &config) {
  Correction correction;
  correction.solve = graph_.optimize(config);
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
  return copy;
}

std::vector<PlacedScan> KeyframeGraph::scans_since(std::size_t first, const KeyframeGraph &solved) const {
  const std::size_t copied = std::min(solved.keyframes_.size(), keyframes_.size());
  const Eigen::Isometry2d T_corrected_tracked =
      copied == 0
          ? Eigen::Isometry2d::Identity()
          : solved.keyframes_[copied - 1].T_map_keyframe * keyframes_[copied - 1].T_map_keyframe.inverse();
  std::vector<PlacedScan> scans;
  for (std::size_t i = first; i < integration_order_.size(); ++i) {
    const auto k = static_cast<std::size_t>(integration_order_[i].first);
    const Eigen::Isometry2d pose =
        k < copied ? solved.keyframes_[k].T_map_keyframe : T_corrected_tracked * keyframes_[k].T_map_keyframe;
    scans.push_back(
        {keyframes_[k].scans_keyframe[static_cast<std::size_t>(integration_order_[i].second)], pose});
  }
  return scans;
}

Eigen::Isometry2d KeyframeGraph::adopt(const KeyframeGraph &solved, std::size_t copied_edges) {
  const std::size_t copied = solved.keyframes_.size();
  if (copied == 0 || copied > keyframes_.size()) return Eigen::Isometry2d::Identity();
  const Eigen::Isometry2d T_corrected_tracked =
      solved.keyframes_[copied - 1].T_map_keyframe * keyframes_[copied - 1].T_map_keyframe.inverse();
  for (std::size_t k = 0; k < keyframes_.size(); ++k) {
    Eigen::Isometry2d &pose = keyframes_[k].T_map_keyframe;
    pose = k < copied ? solved.keyframes_[k].T_map_keyframe : T_corrected_tracked * pose;
  }
  // The solved graph (its loop edges, without those it rejected), then what was added here
  // since the copy: the new keyframes' nodes and their sequential edges.
  PoseGraph graph = solved.graph_;
  for (std::size_t k = copied; k < keyframes_.size(); ++k) graph.add_node(keyframes_[k].T_map_keyframe);
  for (std::size_t e = copied_edges; e < graph_.edges().size(); ++e) graph.add_edge(graph_.edges()[e]);
  graph_ = std::move(graph);
  return T_corrected_tracked;
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
