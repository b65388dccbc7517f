#include "corner_refine.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace omnislam::calib::detail {
namespace {

struct Sample {
  double u, v, grey;
};

// erf(d1 / (sqrt(2) sigma)) erf(d2 / (sqrt(2) sigma)) at (u, v): the corner's shape, which
// the grey levels follow up to (m, k) (corner_refine.hpp). Parameters: corner (u, v), edge
// directions (rad), sigma (px).
template <typename T>
T corner_shape(double u, double v, const T *corner, const T *direction, const T &sigma) {
  using std::cos, std::erf, std::sin;
  const T du = T(u) - corner[0], dv = T(v) - corner[1];
  const T d1 = -sin(direction[0]) * du + cos(direction[0]) * dv;
  const T d2 = -sin(direction[1]) * du + cos(direction[1]) * dv;
  const T scale = sigma * T(std::numbers::sqrt2);
  return erf(d1 / scale) * erf(d2 / scale);
}

// The blurred image of a corner at each sample, minus its grey level; `level` is (m, k).
class CornerModel {
 public:
  explicit CornerModel(std::vector<Sample> samples) : samples_(std::move(samples)) {}

  template <typename T>
  bool operator()(const T *corner, const T *direction, const T *level, const T *sigma, T *residual) const {
    for (std::size_t i = 0; i < samples_.size(); ++i) {
      const Sample &s = samples_[i];
      residual[i] = level[0] + level[1] * corner_shape(s.u, s.v, corner, direction, sigma[0]) - T(s.grey);
    }
    return true;
  }

 private:
  std::vector<Sample> samples_;
};

// The pixels within `window` squares of the corner along both board axes.
std::vector<Sample> window_samples(const cv::Mat &image, const Eigen::Vector2d &corner_px,
                                   const Eigen::Matrix2d &axes_px, double window) {
  const Eigen::Matrix2d to_board = axes_px.inverse();
  const Eigen::Vector2d reach = axes_px.cwiseAbs() * Eigen::Vector2d::Constant(window);
  const int u0 = static_cast<int>(std::floor(corner_px.x() - reach.x()));
  const int u1 = static_cast<int>(std::ceil(corner_px.x() + reach.x()));
  const int v0 = static_cast<int>(std::floor(corner_px.y() - reach.y()));
  const int v1 = static_cast<int>(std::ceil(corner_px.y() + reach.y()));
  if (u0 < 0 || v0 < 0 || u1 >= image.cols || v1 >= image.rows) return {};
  std::vector<Sample> samples;
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const Eigen::Vector2d board = to_board * (Eigen::Vector2d(u, v) - corner_px);
      if (board.cwiseAbs().maxCoeff() > window) continue;
      samples.push_back(
          {static_cast<double>(u), static_cast<double>(v), static_cast<double>(image.at<uchar>(v, u))});
    }
  }
  return samples;
}

}  // namespace

std::optional<Eigen::Vector2d> refine_corner(const cv::Mat &image, const Eigen::Vector2d &corner_px,
                                             const Eigen::Matrix2d &axes_px,
                                             const CornerRefineConfig &config) {
  if (image.empty() || image.type() != CV_8UC1 || std::abs(axes_px.determinant()) < 1e-6) return std::nullopt;
  std::vector<Sample> samples = window_samples(image, corner_px, axes_px, config.window);
  if (static_cast<int>(samples.size()) < config.min_pixels) return std::nullopt;

  double corner[2] = {corner_px.x(), corner_px.y()};
  double direction[2] = {std::atan2(axes_px(1, 0), axes_px(0, 0)), std::atan2(axes_px(1, 1), axes_px(0, 1))};
  double sigma[1] = {0.7};  // a pixel's box and a little defocus
  // (m, k) by linear least squares on the start geometry (so k starts with the sign of the
  // corner's squares).
  Eigen::MatrixXd design(samples.size(), 2);
  Eigen::VectorXd grey(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    design(static_cast<Eigen::Index>(i), 0) = 1.0;
    design(static_cast<Eigen::Index>(i), 1) =
        corner_shape(samples[i].u, samples[i].v, corner, direction, sigma[0]);
    grey(static_cast<Eigen::Index>(i)) = samples[i].grey;
  }
  const Eigen::Vector2d start = design.colPivHouseholderQr().solve(grey);
  double level[2] = {start.x(), start.y()};
  const double contrast = std::abs(level[1]);
  if (!(contrast > 1.0)) return std::nullopt;  // grey levels: no corner to fit

  const auto residuals = static_cast<int>(samples.size());
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<CornerModel, ceres::DYNAMIC, 2, 2, 2, 1>(
                               new CornerModel(std::move(samples)), residuals),
                           nullptr, corner, direction, level, sigma);
  problem.SetParameterLowerBound(sigma, 0, 0.2);
  problem.SetParameterUpperBound(sigma, 0, 3.0);
  ceres::Solver::Options options;
  options.max_num_iterations = config.max_iterations;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (summary.termination_type != ceres::CONVERGENCE) return std::nullopt;

  // Still this corner: within its own quarter squares of where the detector put it.
  const Eigen::Vector2d refined(corner[0], corner[1]);
  const Eigen::Vector2d moved_squares = axes_px.inverse() * (refined - corner_px);
  if (moved_squares.cwiseAbs().maxCoeff() > 0.25 || std::abs(level[1]) < 0.5 * contrast) return std::nullopt;
  return refined;
}

}  // namespace omnislam::calib::detail
