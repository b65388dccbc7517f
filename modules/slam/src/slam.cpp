#include "omnislam/slam/slam.hpp"

#include <cmath>
#include <numbers>

namespace omnislam::slam {
namespace {

Points2 transformed(const Points2 &points, const Eigen::Isometry2d &T) {
  Points2 out;
  out.reserve(points.size());
  for (const Point2 &p : points) out.push_back(T * p);
  return out;
}

double yaw_of(const Eigen::Isometry2d &T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

// Odometry uncertainty of one step, used to grow the covariance of unregistered frames
// (the thesis noise model: 10% of the distance, 1.5 deg of heading).
Eigen::Matrix3d odometry_step_covariance(const Eigen::Isometry2d &step) {
  const double distance = step.translation().norm();
  const double sigma_xy = 0.1 * distance / std::sqrt(3.0);
  const double sigma_yaw =
      std::max(0.1 * std::abs(yaw_of(step)), 1.5 * std::numbers::pi / 180.0) / std::sqrt(3.0);
  return Eigen::Vector3d(sigma_xy * sigma_xy, sigma_xy * sigma_xy, sigma_yaw * sigma_yaw).asDiagonal();
}

}  // namespace

bool Slam::accept(const TrimmedIcpResult &registration, const Eigen::Isometry2d &predicted,
                  const Eigen::Isometry2d &estimate, double srel_limit_percent) const {
  if (!registration.valid) return false;
  if (config_.use_srel_test && registration.srel_percent >= srel_limit_percent) return false;
  if (std::sqrt(registration.final_error_m2) > config_.max_rms_m) return false;
  if (registration.inlier_share < config_.min_inlier_share) return false;
  const Eigen::Isometry2d correction = predicted.inverse() * estimate;
  return correction.translation().norm() <= config_.max_correction_m &&
         std::abs(yaw_of(correction)) <= config_.max_correction_rad;
}

FrameEstimate Slam::register_scan(const Points2 &scan_base, const Eigen::Isometry2d &predicted) {
  const double srel_limit = config_.srel_limit_percent + relaxation_percent_;
  FrameEstimate estimate;
  estimate.T_map_base = predicted;

  auto try_forward = [&](const NearestNeighbors &model, Attempt attempt) {
    const TrimmedIcpResult r = register_trimmed_icp(model, scan_base, predicted, config_.icp);
    estimate.registration = r;
    if (!accept(r, predicted, r.T_model_sample, srel_limit)) return false;
    estimate = {r.T_model_sample, true, attempt, r, r.covariance};
    return true;
  };

  if (config_.target == RegistrationTarget::kMap && try_forward(map_.index(), Attempt::kMap)) return estimate;

  const NearestNeighbors previous(previous_scan_map_);
  if (try_forward(previous, Attempt::kPreviousForward)) return estimate;

  // Reverse: the previous scan registered onto this one, in this scan's frame.
  const NearestNeighbors current(scan_base);
  const TrimmedIcpResult reverse =
      register_trimmed_icp(current, previous_scan_map_, predicted.inverse(), config_.icp);
  estimate.registration = reverse;
  const Eigen::Isometry2d reverse_pose = reverse.T_model_sample.inverse();
  if (accept(reverse, predicted, reverse_pose, srel_limit)) {
    estimate = {reverse_pose, true, Attempt::kPreviousReverse, reverse, reverse.covariance};
  }
  return estimate;
}

FrameEstimate Slam::process(const Points2 &scan_base, const Eigen::Isometry2d &T_odom_base) {
  if (!previous_T_odom_base_) {
    // The first frame defines the map frame (REP-105 map = first pose).
    previous_T_odom_base_ = T_odom_base;
    previous_ = {Eigen::Isometry2d::Identity(), true, Attempt::kFirstFrame, {}, Eigen::Matrix3d::Zero()};
    previous_scan_map_ = scan_base;
    map_.integrate(scan_base);
    return previous_;
  }
  const Eigen::Isometry2d step = previous_T_odom_base_->inverse() * T_odom_base;
  previous_T_odom_base_ = T_odom_base;
  const Eigen::Isometry2d predicted = previous_.T_map_base * step;

  FrameEstimate estimate;
  estimate.T_map_base = predicted;
  if (static_cast<int>(scan_base.size()) >= config_.min_scan_points)
    estimate = register_scan(scan_base, predicted);

  if (estimate.integrated && previous_failed_ && config_.optional_map_correction &&
      config_.target == RegistrationTarget::kPreviousScan) {
    const TrimmedIcpResult refined =
        register_trimmed_icp(map_.index(), scan_base, estimate.T_map_base, config_.icp);
    if (accept(refined, predicted, refined.T_model_sample, 50.0))
      estimate.T_map_base = refined.T_model_sample;
  }

  if (estimate.integrated) {
    relaxation_percent_ = 0.0;
    map_.integrate(transformed(scan_base, estimate.T_map_base));
  } else {
    relaxation_percent_ += config_.srel_relax_percent;
    const Eigen::Matrix2d R = previous_.T_map_base.linear();
    Eigen::Matrix3d rotate = Eigen::Matrix3d::Identity();
    rotate.topLeftCorner<2, 2>() = R;
    estimate.covariance = previous_.covariance + rotate * odometry_step_covariance(step) * rotate.transpose();
  }
  previous_failed_ = !estimate.integrated;
  // Thesis fig. 5.3: second_last = last every iteration, integrated or not.
  previous_scan_map_ = transformed(scan_base, estimate.T_map_base);
  previous_ = estimate;
  return estimate;
}

}  // namespace omnislam::slam
