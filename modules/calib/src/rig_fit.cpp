#include "omnislam/calib/rig_fit.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <limits>

namespace omnislam::calib {
namespace {

// Parameters in units of similar effect (about a pixel each): px, px, 1e-3 of focal length,
// mm, mrad, mrad, mm, mm. Near-equal scales keep the trust region round.
constexpr std::array<double, kRigParameters> kUnit{1.0, 1.0, 1e-3, 1.0, 1e-3, 1e-3, 1.0, 1.0};

mirror::MirrorConfig apply(mirror::MirrorConfig config, const double *p) {
  config.center_u_px = p[kCenterU] * kUnit[kCenterU];
  config.center_v_px = p[kCenterV] * kUnit[kCenterV];
  config.rig.focal_scale = p[kFocalScale] * kUnit[kFocalScale];
  config.rig.mirror_dz_mm = p[kMirrorDz] * kUnit[kMirrorDz];
  config.rig.mirror_tilt_x_rad = p[kTiltX] * kUnit[kTiltX];
  config.rig.mirror_tilt_y_rad = p[kTiltY] * kUnit[kTiltY];
  config.rig.mirror_offset_x_mm = p[kOffsetX] * kUnit[kOffsetX];
  config.rig.mirror_offset_y_mm = p[kOffsetY] * kUnit[kOffsetY];
  return config;
}

std::array<double, kRigParameters> parameters_of(const mirror::MirrorConfig &config) {
  std::array<double, kRigParameters> p{config.center_u_px,
                                       config.center_v_px,
                                       config.rig.focal_scale,
                                       config.rig.mirror_dz_mm,
                                       config.rig.mirror_tilt_x_rad,
                                       config.rig.mirror_tilt_y_rad,
                                       config.rig.mirror_offset_x_mm,
                                       config.rig.mirror_offset_y_mm};
  for (int i = 0; i < kRigParameters; ++i) p[i] /= kUnit[i];
  return p;
}

// Reprojection error of one observation. The model is traced (RigModel::project iterates),
// so the derivatives are numerical.
struct Reprojection {
  mirror::MirrorConfig base;
  RigObservation observation;

  bool operator()(const double *p, double *residual) const {
    const mirror::RigModel rig(apply(base, p));
    const std::optional<mirror::Pixel> pixel = rig.project(observation.lobe, observation.point_m);
    if (!pixel) return false;
    residual[0] = pixel->u_px - observation.pixel.u_px;
    residual[1] = pixel->v_px - observation.pixel.v_px;
    return true;
  }
};

}  // namespace

RigFitResult fit_rig(const mirror::MirrorConfig &initial, const std::vector<RigObservation> &observations,
                     const RigFitConfig &config) {
  RigFitResult result;
  result.camera = initial;
  result.sigma.fill(std::numeric_limits<double>::quiet_NaN());
  result.observations = static_cast<int>(observations.size());
  int inner = 0;
  for (const RigObservation &observation : observations)
    inner += observation.lobe == mirror::Lobe::kInner ? 1 : 0;
  const int outer = result.observations - inner;
  if (inner <= kRigParameters || outer <= kRigParameters) {
    result.message = "too few observations: need more than 8 in each lobe";
    return result;
  }
  std::array<double, kRigParameters> p = parameters_of(initial);
  ceres::Problem problem;
  for (const RigObservation &observation : observations) {
    problem.AddResidualBlock(
        new ceres::NumericDiffCostFunction<Reprojection, ceres::CENTRAL, 2, kRigParameters>(
            new Reprojection{initial, observation}),
        nullptr, p.data());
  }
  ceres::Solver::Options options;
  options.max_num_iterations = config.max_iterations;
  options.linear_solver_type = ceres::DENSE_QR;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.message = summary.BriefReport();
  result.camera = apply(initial, p.data());
  const int residuals = 2 * result.observations;
  result.rms_px = std::sqrt(2.0 * summary.final_cost / residuals);
  if (!result.converged) return result;

  ceres::Covariance::Options covariance_options;
  ceres::Covariance covariance(covariance_options);
  const std::vector<std::pair<const double *, const double *>> blocks{{p.data(), p.data()}};
  if (!covariance.Compute(blocks, &problem)) {
    result.message += "; covariance: not estimable (degenerate observations)";
    return result;
  }
  Eigen::Matrix<double, kRigParameters, kRigParameters, Eigen::RowMajor> c;
  covariance.GetCovarianceBlock(p.data(), p.data(), c.data());
  // Ceres's covariance assumes unit residual variance; scale by the fitted one.
  const double variance = 2.0 * summary.final_cost / (residuals - kRigParameters);
  for (int i = 0; i < kRigParameters; ++i) result.sigma[i] = std::sqrt(c(i, i) * variance) * kUnit[i];
  return result;
}

}  // namespace omnislam::calib
