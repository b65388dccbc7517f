#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

/// @file
/// A 2D pose graph (nodes x, y, yaw in the map frame; edges measured relative poses with
/// an information matrix) solved by Ceres: yaw on an angle manifold, sparse Cholesky,
/// started from the nodes' current values (a warm start). Loop edges are under a robust
/// (Cauchy) loss; after a solve, loop edges whose whitened residual fails a chi-square
/// test are removed and the graph is solved again. The first node is held fixed (it is
/// the map frame). Not thread-safe; no allocation beyond the graph itself.

namespace omnislam::slam {

struct PoseGraphConfig {
  /// Chi-square bound (3 degrees of freedom) on a loop edge's squared whitened residual at
  /// the solution; 11.34 is the 99% quantile: a true loop edge fails it once in a hundred.
  double loop_chi2_limit = 11.34;
  /// Scale of the Cauchy loss on loop edges, in whitened units (sigma): residuals beyond
  /// it are progressively discounted, so a false edge pulls little before it is removed.
  double loop_loss_scale = 1.0;
  int max_iterations = 100;
  /// Solve/remove rounds at most (each removes the loop edges that fail the test).
  int max_rounds = 5;
};

struct PoseGraphEdge {
  int from = 0;
  int to = 0;
  Eigen::Isometry2d T_from_to = Eigen::Isometry2d::Identity();  ///< measured pose of `to` in `from`
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();    ///< of (x, y, yaw) of T_from_to
  bool loop = false;                                            ///< robust loss and chi-square test
};

struct PoseGraphResult {
  bool converged = false;  ///< the last solve reported convergence
  int iterations = 0;      ///< solver iterations over all rounds
  int rounds = 0;          ///< solves
  int rejected_loops = 0;  ///< loop edges removed by the chi-square test
  double final_cost = 0.0;
};

class PoseGraph {
 public:
  /// Adds a node at `T_map_node` (its initial value); returns its index.
  int add_node(const Eigen::Isometry2d &T_map_node);
  /// Adds an edge between existing nodes.
  void add_edge(const PoseGraphEdge &edge);

  /// Optimises every node but the first, starting from the current values; removes loop
  /// edges the solution rejects and solves again. A graph of fewer than two nodes is left
  /// as it is (converged).
  PoseGraphResult optimize(const PoseGraphConfig &config = {});

  [[nodiscard]] int size() const { return static_cast<int>(nodes_.size()); }
  [[nodiscard]] Eigen::Isometry2d pose(int node) const;
  void set_pose(int node, const Eigen::Isometry2d &T_map_node);
  [[nodiscard]] const std::vector<PoseGraphEdge> &edges() const { return edges_; }
  /// Squared whitened residual of `edge` at the current node values.
  [[nodiscard]] double chi2(const PoseGraphEdge &edge) const;

 private:
  struct Node {
    double xy[2];
    double yaw;
  };
  std::vector<Node> nodes_;
  std::vector<PoseGraphEdge> edges_;
};

}  // namespace omnislam::slam
