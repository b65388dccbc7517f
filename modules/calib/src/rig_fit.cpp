#include "omnislam/calib/rig_fit.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <limits>

#include "rig_parameters.hpp"

namespace omnislam::calib {
namespace {

using detail::apply;
using detail::kUnit;
using detail::parameters_of;

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
