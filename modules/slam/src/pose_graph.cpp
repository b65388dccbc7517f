#include "omnislam/slam/pose_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

// An angle wrapped into [-pi, pi), written for Ceres jets too.
template <typename T>
T wrapped(const T &angle_rad) {
  const T two_pi(2.0 * std::numbers::pi);
  return angle_rad - two_pi * ceres::floor((angle_rad + T(std::numbers::pi)) / two_pi);
}

// Yaw lives on the circle: a step is added and wrapped, a difference is wrapped, so the
// solver never sees the 2 pi jump.
struct AngleManifold {
  template <typename T>
  bool Plus(const T *yaw, const T *delta, T *yaw_plus_delta) const {
    *yaw_plus_delta = wrapped(*yaw + *delta);
    return true;
  }
  template <typename T>
  bool Minus(const T *yaw_b, const T *yaw_a, T *b_minus_a) const {
    *b_minus_a = wrapped(*yaw_b - *yaw_a);
    return true;
  }
};

// The residual of a relative-pose measurement: the pose of node b in node a's frame minus
// the measured one (position in a's frame, wrapped yaw), whitened by sqrt(information).
struct RelativePoseError {
  RelativePoseError(const Eigen::Isometry2d &T_a_b, const Eigen::Matrix3d &information)
      : measured_xy(T_a_b.translation()), measured_yaw(yaw_rad_of(T_a_b)) {
    // information = L L^T (Cholesky), so r^T information r = |L^T r|^2.
    sqrt_information = Eigen::LLT<Eigen::Matrix3d>(information).matrixU();
  }

  template <typename T>
  bool operator()(const T *a_xy, const T *a_yaw, const T *b_xy, const T *b_yaw, T *residual) const {
    const T c = ceres::cos(*a_yaw), s = ceres::sin(*a_yaw);
    const T dx = b_xy[0] - a_xy[0], dy = b_xy[1] - a_xy[1];
    Eigen::Matrix<T, 3, 1> r;
    r(0) = c * dx + s * dy - T(measured_xy.x());
    r(1) = -s * dx + c * dy - T(measured_xy.y());
    r(2) = wrapped(*b_yaw - *a_yaw - T(measured_yaw));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> whitened(residual);
    whitened = sqrt_information.cast<T>() * r;
    return true;
  }

  Eigen::Vector2d measured_xy;
  double measured_yaw;
  Eigen::Matrix3d sqrt_information;
};

ceres::Solver::Options solver_options(const PoseGraphConfig &config) {
  ceres::Solver::Options options;
  options.max_num_iterations = config.max_iterations;
  options.num_threads = 1;  // slam/ runs on its caller's thread
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
    options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  } else if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)) {
    options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  } else {
    options.linear_solver_type = ceres::DENSE_QR;
  }
  return options;
}

}  // namespace

int PoseGraph::add_node(const Eigen::Isometry2d &T_map_node) {
  nodes_.push_back({{T_map_node.translation().x(), T_map_node.translation().y()}, yaw_rad_of(T_map_node)});
  return size() - 1;
}

void PoseGraph::add_edge(const PoseGraphEdge &edge) { edges_.push_back(edge); }

Eigen::Isometry2d PoseGraph::pose(int node) const {
  const Node &n = nodes_[static_cast<std::size_t>(node)];
  return planar_pose(n.xy[0], n.xy[1], n.yaw);
}

void PoseGraph::set_pose(int node, const Eigen::Isometry2d &T_map_node) {
  nodes_[static_cast<std::size_t>(node)] = {{T_map_node.translation().x(), T_map_node.translation().y()},
                                            yaw_rad_of(T_map_node)};
}

double PoseGraph::chi2(const PoseGraphEdge &edge) const {
  const Node &a = nodes_[static_cast<std::size_t>(edge.from)];
  const Node &b = nodes_[static_cast<std::size_t>(edge.to)];
  double residual[3];
  RelativePoseError(edge.T_from_to, edge.information)(a.xy, &a.yaw, b.xy, &b.yaw, residual);
  return residual[0] * residual[0] + residual[1] * residual[1] + residual[2] * residual[2];
}

PoseGraphResult PoseGraph::optimize(const PoseGraphConfig &config) {
  PoseGraphResult result;
  if (nodes_.size() < 2) {
    result.converged = true;
    return result;
  }
  const ceres::Solver::Options options = solver_options(config);
  while (result.rounds < config.max_rounds) {
    ceres::Problem problem;
    for (Node &node : nodes_) {
      problem.AddParameterBlock(node.xy, 2);
      problem.AddParameterBlock(&node.yaw, 1, new ceres::AutoDiffManifold<AngleManifold, 1, 1>);
    }
    // Graduated robustness: a Cauchy loss at its final scale, started from a warm start
    // where a true loop edge is still far off (chi2 in the thousands), would leave that edge
    // in the flat tail of the loss, a local minimum. The scale starts at the largest loop
    // residual and shrinks fourfold per solve to loop_loss_scale, so true edges are pulled
    // in first and only edges the rest of the graph contradicts end up discounted.
    double largest_chi2 = 0.0;
    std::vector<ceres::LossFunctionWrapper *> losses;
    for (const PoseGraphEdge &edge : edges_) {
      Node &a = nodes_[static_cast<std::size_t>(edge.from)];
      Node &b = nodes_[static_cast<std::size_t>(edge.to)];
      auto *cost = new ceres::AutoDiffCostFunction<RelativePoseError, 3, 2, 1, 2, 1>(
          new RelativePoseError(edge.T_from_to, edge.information));
      ceres::LossFunctionWrapper *loss = nullptr;
      if (edge.loop) {
        loss = new ceres::LossFunctionWrapper(new ceres::CauchyLoss(config.loop_loss_scale),
                                              ceres::TAKE_OWNERSHIP);
        losses.push_back(loss);
        largest_chi2 = std::max(largest_chi2, chi2(edge));
      }
      problem.AddResidualBlock(cost, loss, a.xy, &a.yaw, b.xy, &b.yaw);
    }
    problem.SetParameterBlockConstant(nodes_.front().xy);
    problem.SetParameterBlockConstant(&nodes_.front().yaw);

    double scale = std::max(std::sqrt(largest_chi2), config.loop_loss_scale);
    for (;;) {
      for (ceres::LossFunctionWrapper *loss : losses)
        loss->Reset(new ceres::CauchyLoss(scale), ceres::TAKE_OWNERSHIP);
      ceres::Solver::Summary summary;
      ceres::Solve(options, &problem, &summary);
      result.iterations += static_cast<int>(summary.iterations.size());
      result.converged = summary.termination_type == ceres::CONVERGENCE;
      result.final_cost = summary.final_cost;
      if (scale <= config.loop_loss_scale) break;
      scale = std::max(scale / 4.0, config.loop_loss_scale);
    }
    ++result.rounds;

    // Loop edges the solution cannot explain are outliers (false loop closures): drop them
    // and solve again without their pull.
    const auto before = edges_.size();
    std::erase_if(
        edges_, [&](const PoseGraphEdge &edge) { return edge.loop && chi2(edge) > config.loop_chi2_limit; });
    const auto removed = static_cast<int>(before - edges_.size());
    result.rejected_loops += removed;
    if (removed == 0) break;
  }
  return result;
}

}  // namespace omnislam::slam
