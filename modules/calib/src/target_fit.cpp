#include "omnislam/calib/target_fit.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <utility>

#include "finite_difference.hpp"
#include "rig_parameters.hpp"
#include "target_pose.hpp"

namespace omnislam::calib {
namespace {

using detail::apply;
using detail::kUnit;
using detail::parameters_of;
using detail::Pose;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Finite-difference steps: a thousandth of each rig parameter's unit (about a thousandth
// of a pixel each), a microradian and a micrometre of a pose.
const std::vector<double> kRigSteps(kRigParameters, 1e-3);
const std::vector<double> kPoseSteps(6, 1e-6);
const std::vector<double> kPlaneSteps(3, 1e-6);
const std::vector<double> kHeightSteps(1, 1e-6);
const std::vector<double> kLevelSteps(2, 1e-3);  // microradians (the block is in mrad)

// The rig's level tilt block (mrad, RigConfig::level_tilt_*) as the rotation taking camera
// coordinates to level ones.
Eigen::Matrix3d level_rotation(const double *level_mrad) {
  return mirror::tilt_rotation(level_mrad[0] * 1e-3, level_mrad[1] * 1e-3);
}

// Where a board point is in the camera frame, from the pose's parameter blocks.
using Placement =
    std::function<Eigen::Vector3d(const double *const *pose_blocks, const Eigen::Vector3d &board_m)>;

// A corner's reprojection error in pixels times `*weight` (1 / the corners' standard
// deviation once it is known, so that the rim's residuals, in their sigmas, weigh right).
ceres::CostFunction *corner_cost(const mirror::MirrorConfig &base, const TargetGeometry &target,
                                 const TargetCorner &corner, const double *weight,
                                 std::vector<std::vector<double>> pose_steps, Placement place) {
  const Eigen::Vector3d board_m = target.corner_m(corner.index);
  pose_steps.insert(pose_steps.begin(), kRigSteps);
  return new detail::FiniteDifferenceCost(2, std::move(pose_steps),
                                          [=](const double *const *parameters, double *residual) {
                                            const mirror::RigModel rig(apply(base, parameters[0]));
                                            const std::optional<mirror::Pixel> projected =
                                                rig.project(corner.lobe, place(parameters + 1, board_m));
                                            if (!projected) return false;
                                            residual[0] = *weight * (projected->u_px - corner.pixel.u_px);
                                            residual[1] = *weight * (projected->v_px - corner.pixel.v_px);
                                            return true;
                                          });
}

ceres::CostFunction *held_corner_cost(const mirror::MirrorConfig &base, const TargetGeometry &target,
                                      const TargetCorner &corner, const double *weight) {
  return corner_cost(base, target, corner, weight, {kPoseSteps},
                     [](const double *const *pose, const Eigen::Vector3d &board_m) {
                       return detail::to_camera(pose[0], board_m);
                     });
}

// A board on the floor: placed in the level frame (the floor is z = floor_z there), then
// turned into the camera frame by the rig's level tilt (the last block).
ceres::CostFunction *floor_corner_cost(const mirror::MirrorConfig &base, const TargetGeometry &target,
                                       const TargetCorner &corner, const double *weight, bool face_up) {
  return corner_cost(base, target, corner, weight, {kPlaneSteps, kHeightSteps, kLevelSteps},
                     [face_up](const double *const *pose, const Eigen::Vector3d &board_m) {
                       return Eigen::Vector3d(level_rotation(pose[2]).transpose() *
                                              detail::floor_to_camera(pose[0], pose[1][0], face_up, board_m));
                     });
}

// A rim circle's fitted centre against where the rig puts it, in its standard deviations.
ceres::CostFunction *rim_cost(const mirror::MirrorConfig &base, bool outer_rim,
                              const Eigen::Vector2d &centre_px, const Eigen::Vector2d &sigma_px) {
  return new detail::FiniteDifferenceCost(
      2, {kRigSteps}, [=](const double *const *parameters, double *residual) {
        const RimPrediction predicted = predict_rim(apply(base, parameters[0]));
        const Eigen::Vector2d at = outer_rim ? predicted.rim_centre_px : predicted.central_centre_px;
        residual[0] = (at.x() - centre_px.x()) / sigma_px.x();
        residual[1] = (at.y() - centre_px.y()) / sigma_px.y();
        return true;
      });
}

ceres::Solver::Options solver_options(int max_iterations) {
  ceres::Solver::Options options;
  options.max_num_iterations = max_iterations;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  return options;
}

// A view's starting pose: from the inner lobe, then refined on all its corners with the
// rig held.
std::optional<Pose> initial_pose(const mirror::MirrorConfig &camera, const TargetGeometry &target,
                                 const TargetView &view, int min_corners, std::string &error) {
  std::optional<Pose> pose = detail::pose_from_inner_lobe(camera, target, view, min_corners, error);
  if (!pose) return std::nullopt;
  std::array<double, kRigParameters> p = parameters_of(camera);
  const double weight = 1.0;
  ceres::Problem problem;
  for (const TargetCorner &corner : view.corners)
    problem.AddResidualBlock(held_corner_cost(camera, target, corner, &weight), nullptr, p.data(),
                             pose->data());
  problem.SetParameterBlockConstant(p.data());
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(50), &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    error = "the board's pose did not converge: " + summary.BriefReport();
    return std::nullopt;
  }
  return pose;
}

// One used view: its pose (a held board: all six; a board on the floor: yaw, x, y in the
// first three, with the shared floor height) and its corners.
struct PlacedView {
  bool on_floor = false;
  bool face_up = true;
  Pose pose{};
  std::vector<TargetCorner> corners;
};

// The joint problem: the rig (its level tilt apart), every pose, the floor's height, the
// rim circles.
struct JointProblem {
  std::array<double, kRigParameters> rig{};
  std::array<double, 2> level_mrad{};  // the rig's level tilt; its boards on the floor fix it
  bool fit_level = true;
  std::vector<PlacedView> views;
  double floor_z_m = kNaN;
  double weight = 1.0;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> corner_blocks;
  std::vector<std::pair<std::size_t, std::size_t>> corner_of_block;  // (view, corner)
  int rim_blocks = 0;

  [[nodiscard]] int unknowns() const {
    const bool floor = !std::isnan(floor_z_m);
    int count = kRigParameters + (floor ? 1 : 0) + (floor && fit_level ? 2 : 0);
    for (const PlacedView &view : views) count += view.on_floor ? 3 : 6;
    return count;
  }
};

void build(JointProblem &joint, const mirror::MirrorConfig &base, const TargetGeometry &target,
           const RimCircles &rim, const TargetFitConfig &config) {
  joint.problem = std::make_unique<ceres::Problem>();
  joint.corner_blocks.clear();
  joint.corner_of_block.clear();
  joint.rim_blocks = 0;
  for (std::size_t v = 0; v < joint.views.size(); ++v) {
    PlacedView &view = joint.views[v];
    for (std::size_t c = 0; c < view.corners.size(); ++c) {
      const TargetCorner &corner = view.corners[c];
      const ceres::ResidualBlockId block =
          view.on_floor
              ? joint.problem->AddResidualBlock(
                    floor_corner_cost(base, target, corner, &joint.weight, view.face_up), nullptr,
                    joint.rig.data(), view.pose.data(), &joint.floor_z_m, joint.level_mrad.data())
              : joint.problem->AddResidualBlock(held_corner_cost(base, target, corner, &joint.weight),
                                                nullptr, joint.rig.data(), view.pose.data());
      joint.corner_blocks.push_back(block);
      joint.corner_of_block.emplace_back(v, c);
    }
  }
  const auto add_rim = [&](const std::optional<CircleFit> &circle, bool outer_rim) {
    if (!circle) return;
    const Eigen::Vector2d sigma = circle->centre_sigma_px.cwiseMax(config.min_rim_sigma_px);
    joint.problem->AddResidualBlock(rim_cost(base, outer_rim, circle->centre_px, sigma), nullptr,
                                    joint.rig.data());
    ++joint.rim_blocks;
  };
  add_rim(rim.rim, true);
  add_rim(rim.central, false);
  if (!joint.fit_level && joint.problem->HasParameterBlock(joint.level_mrad.data()))
    joint.problem->SetParameterBlockConstant(joint.level_mrad.data());
}

// Each corner's reprojection error in pixels (NaN where it does not project), in the
// order of joint.corner_blocks.
std::vector<double> corner_errors_px(const JointProblem &joint) {
  std::vector<double> errors;
  for (const ceres::ResidualBlockId block : joint.corner_blocks) {
    double residual[2];
    const bool ok = joint.problem->EvaluateResidualBlock(block, false, nullptr, residual, nullptr);
    errors.push_back(ok ? std::hypot(residual[0], residual[1]) / joint.weight : kNaN);
  }
  return errors;
}

double sum_of_squares(const std::vector<double> &values) {
  double sum = 0.0;
  for (const double value : values) sum += value * value;
  return sum;
}

double rim_residual_rms(const JointProblem &joint) {
  if (joint.rim_blocks == 0) return kNaN;
  std::vector<ceres::ResidualBlockId> all;
  joint.problem->GetResidualBlocks(&all);
  double sum = 0.0;
  for (const ceres::ResidualBlockId block : all) {
    if (std::find(joint.corner_blocks.begin(), joint.corner_blocks.end(), block) != joint.corner_blocks.end())
      continue;
    double residual[2];
    joint.problem->EvaluateResidualBlock(block, false, nullptr, residual, nullptr);
    sum += residual[0] * residual[0] + residual[1] * residual[1];
  }
  return std::sqrt(sum / (2.0 * joint.rim_blocks));
}

bool solve(JointProblem &joint, int max_iterations, TargetFitResult &result, double *cost = nullptr) {
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(max_iterations), joint.problem.get(), &summary);
  result.iterations += static_cast<int>(summary.iterations.size());
  result.message = summary.BriefReport();
  if (cost != nullptr) *cost = summary.final_cost;
  return summary.termination_type == ceres::CONVERGENCE;
}

// Whether the level tilt the boards on the floor show is worth its two parameters: the fit
// with it free against the fit with it held at the configured value, by Akaike's criterion
// (chi-square down by more than 2 per parameter). A rig that is level within what the
// boards can tell gets the configured tilt instead of a noisy estimate of it: the tilt is
// nearly interchangeable with the image centre (the file's note), so a free tilt costs
// range accuracy when there is none to find. Keeps the better of the two in `joint`.
void choose_level(JointProblem &joint, const mirror::MirrorConfig &base, const TargetGeometry &target,
                  const RimCircles &rim, const TargetFitConfig &config,
                  const std::array<double, 2> &configured, double free_cost, TargetFitResult &result) {
  const std::array<double, kRigParameters> rig = joint.rig;
  const std::array<double, 2> level = joint.level_mrad;
  const std::vector<PlacedView> views = joint.views;
  const double floor_z_m = joint.floor_z_m;
  const std::string message = result.message;
  joint.level_mrad = configured;
  joint.fit_level = false;
  build(joint, base, target, rim, config);
  double held_cost = 0.0;
  const bool converged = solve(joint, config.max_iterations, result, &held_cost);
  // Ceres's cost is half the sum of squares, the residuals are in their sigmas.
  result.level_chi2 = 2.0 * (held_cost - free_cost);
  if (converged && result.level_chi2 <= 2.0 * 2.0) return;
  joint.rig = rig;
  joint.level_mrad = level;
  joint.views = views;
  joint.floor_z_m = floor_z_m;
  joint.fit_level = true;
  build(joint, base, target, rim, config);
  result.message = message;
}

// The rig's (and the floor's) standard deviations: every residual is in its own standard
// deviations once the corners' weight is set, so the covariance needs no further scaling.
bool covariance_of(JointProblem &joint, TargetFitResult &result) {
  // Ceres's default (sparse QR): its dense SVD path runs Eigen's BDCSVD inside libceres,
  // whose allocations then mix with this build's Eigen instantiations (AddressSanitizer:
  // bad free). A rank-deficient fit is reported as not estimable either way.
  ceres::Covariance::Options options;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double *, const double *>> blocks{{joint.rig.data(), joint.rig.data()}};
  const bool floor = !std::isnan(joint.floor_z_m);
  const bool level = floor && joint.fit_level;
  if (floor) blocks.emplace_back(&joint.floor_z_m, &joint.floor_z_m);
  if (level) {
    blocks.emplace_back(joint.level_mrad.data(), joint.level_mrad.data());
    blocks.emplace_back(joint.rig.data(), joint.level_mrad.data());
  }
  if (!covariance.Compute(blocks, joint.problem.get())) return false;
  // Units of the joint covariance: the rig's (kUnit), then the level tilt's mrad.
  Eigen::Matrix<double, kTargetParameters, kTargetParameters> c =
      Eigen::Matrix<double, kTargetParameters, kTargetParameters>::Zero();
  Eigen::Matrix<double, kRigParameters, kRigParameters, Eigen::RowMajor> rig;
  covariance.GetCovarianceBlock(joint.rig.data(), joint.rig.data(), rig.data());
  c.topLeftCorner<kRigParameters, kRigParameters>() = rig;
  if (level) {
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> tilt;
    Eigen::Matrix<double, kRigParameters, 2, Eigen::RowMajor> cross;
    covariance.GetCovarianceBlock(joint.level_mrad.data(), joint.level_mrad.data(), tilt.data());
    covariance.GetCovarianceBlock(joint.rig.data(), joint.level_mrad.data(), cross.data());
    c.bottomRightCorner<2, 2>() = tilt;
    c.topRightCorner<kRigParameters, 2>() = cross;
    c.bottomLeftCorner<2, kRigParameters>() = cross.transpose();
  }
  std::array<double, kTargetParameters> unit{};
  std::copy(kUnit.begin(), kUnit.end(), unit.begin());
  unit[kLevelX] = unit[kLevelY] = 1e-3;
  for (int i = 0; i < kTargetParameters; ++i) {
    result.sigma[i] = (i < kRigParameters || level) ? std::sqrt(c(i, i)) * unit[i] : 0.0;
    for (int j = 0; j < kTargetParameters; ++j) result.covariance(i, j) = c(i, j) * unit[i] * unit[j];
  }
  if (floor) {
    double variance = 0.0;
    covariance.GetCovarianceBlock(&joint.floor_z_m, &joint.floor_z_m, &variance);
    result.camera_height_sigma_m = std::sqrt(variance);
  }
  return true;
}

// Turns the views marked by `lay` into boards on the floor, from their current poses: yaw
// from the board's x, the floor's height (if not yet known) the median of theirs.
void lay_on_floor(JointProblem &joint, const std::vector<bool> &lay) {
  std::vector<double> heights;
  for (std::size_t v = 0; v < joint.views.size(); ++v) {
    PlacedView &view = joint.views[v];
    if (!lay[v] || view.on_floor) continue;
    const Eigen::Isometry3d T = level_rotation(joint.level_mrad.data()) * detail::isometry_of(view.pose);
    view.on_floor = true;
    view.face_up = T.linear()(2, 2) > 0.0;
    view.pose = {std::atan2(T.linear()(1, 0), T.linear()(0, 0)),
                 T.translation().x(),
                 T.translation().y(),
                 0.0,
                 0.0,
                 0.0};
    heights.push_back(T.translation().z());
  }
  if (!heights.empty() && std::isnan(joint.floor_z_m)) {
    std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
    joint.floor_z_m = heights[heights.size() / 2];
  }
}

// The held views whose fitted pose lies level and near the configured floor.
std::vector<bool> found_on_floor(const JointProblem &joint, const TargetFitConfig &config) {
  std::vector<bool> lay(joint.views.size(), false);
  for (std::size_t v = 0; v < joint.views.size(); ++v) {
    if (joint.views[v].on_floor) continue;
    const Eigen::Isometry3d T =
        level_rotation(joint.level_mrad.data()) * detail::isometry_of(joint.views[v].pose);
    const bool level =
        std::abs(T.linear()(2, 2)) > std::cos(config.floor_level_deg * std::numbers::pi / 180.0);
    lay[v] = level && std::abs(T.translation().z() + config.floor_height_m) < config.floor_tolerance_m;
  }
  return lay;
}

// Every view's start (the views flagged on the floor in their constrained form).
void start_views(JointProblem &joint, const mirror::MirrorConfig &initial, const TargetGeometry &target,
                 const std::vector<TargetView> &views, const TargetFitConfig &config,
                 TargetFitResult &result) {
  std::vector<bool> lay;
  for (std::size_t v = 0; v < views.size(); ++v) {
    std::string error;
    const std::optional<Pose> pose = initial_pose(initial, target, views[v], config.min_corners, error);
    if (!pose) {
      result.rejected_views.push_back(static_cast<int>(v));
      result.view_errors.push_back(error);
      continue;
    }
    result.used_views.push_back(static_cast<int>(v));
    joint.views.push_back({false, true, *pose, views[v].corners});
    lay.push_back(views[v].on_floor);
  }
  lay_on_floor(joint, lay);
}

// Drops the corners farther than `outlier_px` from their projection; returns how many.
int drop_outliers(JointProblem &joint, double outlier_px) {
  const std::vector<double> errors = corner_errors_px(joint);
  std::vector<std::vector<TargetCorner>> kept(joint.views.size());
  int dropped = 0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const auto [v, c] = joint.corner_of_block[i];
    if (errors[i] <= outlier_px)
      kept[v].push_back(joint.views[v].corners[c]);
    else
      ++dropped;
  }
  for (std::size_t v = 0; v < joint.views.size(); ++v) joint.views[v].corners = std::move(kept[v]);
  return dropped;
}

void fill_result(const JointProblem &joint, const mirror::MirrorConfig &initial, TargetFitResult &result) {
  result.camera = apply(initial, joint.rig.data());
  result.camera.rig.level_tilt_x_rad = joint.level_mrad[0] * 1e-3;
  result.camera.rig.level_tilt_y_rad = joint.level_mrad[1] * 1e-3;
  result.rms_px = std::sqrt(sum_of_squares(corner_errors_px(joint)) / (2.0 * result.corners));
  result.rim_rms_sigma = rim_residual_rms(joint);
  result.camera_height_m = -joint.floor_z_m;
  for (const PlacedView &view : joint.views) {
    result.on_floor.push_back(view.on_floor);
    result.T_camera_board.push_back(
        view.on_floor
            ? Eigen::Isometry3d(level_rotation(joint.level_mrad.data()).transpose() *
                                detail::floor_isometry(view.pose.data(), joint.floor_z_m, view.face_up))
            : detail::isometry_of(view.pose));
  }
}

}  // namespace

Eigen::Vector3d TargetGeometry::corner_m(int index) const {
  return Eigen::Vector3d((index % corners_x()) * square_m, (index / corners_x()) * square_m, 0.0);
}

TargetFitResult fit_target(const mirror::MirrorConfig &initial, const TargetGeometry &target,
                           const std::vector<TargetView> &views, const RimCircles &rim,
                           const TargetFitConfig &config) {
  TargetFitResult result;
  result.camera = initial;
  result.sigma.fill(kNaN);
  JointProblem joint;
  joint.rig = parameters_of(initial);
  const std::array<double, 2> configured_level_mrad{initial.rig.level_tilt_x_rad * 1e3,
                                                    initial.rig.level_tilt_y_rad * 1e3};
  joint.level_mrad = configured_level_mrad;
  joint.fit_level = config.fit_level;
  // Inside the fit the rig projects from its own (camera) frame: boards held anywhere are
  // placed there, boards on the floor are turned into it by the level block.
  mirror::MirrorConfig base = initial;
  base.rig.level_tilt_x_rad = base.rig.level_tilt_y_rad = 0.0;
  start_views(joint, base, target, views, config, result);
  result.views_used = static_cast<int>(joint.views.size());
  if (result.views_used < 2) {
    result.message = "too few usable views: " + std::to_string(result.views_used) + " of " +
                     std::to_string(views.size()) + ", need 2";
    return result;
  }
  build(joint, base, target, rim, config);
  solve(joint, config.max_iterations, result);
  // The boards found lying on the floor (their first poses, from the configured rig, are
  // too rough to tell) become boards on the floor.
  if (!std::isnan(config.floor_height_m)) {
    const std::vector<bool> lay = found_on_floor(joint, config);
    if (std::find(lay.begin(), lay.end(), true) != lay.end()) {
      lay_on_floor(joint, lay);
      build(joint, base, target, rim, config);
      solve(joint, config.max_iterations, result);
    }
  }
  // Drop the corners that do not fit (a corner on the wrong square) and fit again.
  result.outliers = drop_outliers(joint, config.outlier_px);
  build(joint, base, target, rim, config);
  result.corners = static_cast<int>(joint.corner_blocks.size());
  if (2 * result.corners <= joint.unknowns()) {
    result.message = "too few corners: " + std::to_string(result.corners);
    return result;
  }
  // Weigh the corners by their standard deviation (from the residual), then fit again so the
  // rim's residuals, in their own sigmas, count as much as they should.
  const double corner_sigma_px =
      std::sqrt(sum_of_squares(corner_errors_px(joint)) / (2.0 * result.corners - joint.unknowns()));
  joint.weight = 1.0 / std::max(corner_sigma_px, 1e-6);
  double cost = 0.0;
  result.converged = solve(joint, config.max_iterations, result, &cost);
  if (result.converged && joint.fit_level && !std::isnan(joint.floor_z_m)) {
    choose_level(joint, base, target, rim, config, configured_level_mrad, cost, result);
  }
  result.level_fitted = joint.fit_level && !std::isnan(joint.floor_z_m);
  fill_result(joint, base, result);
  if (result.converged && !covariance_of(joint, result))
    result.message += "; covariance: not estimable (degenerate views)";
  return result;
}

}  // namespace omnislam::calib
