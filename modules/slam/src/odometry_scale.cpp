#include "omnislam/slam/odometry_scale.hpp"

#include <cmath>

namespace omnislam::slam {
namespace {

// Segments shorter than this (turning on the spot, standing still) measure nothing.
constexpr double kMinSegmentM = 1e-3;

}  // namespace

double OdometryScale::scale() const {
  if (!config_.enabled) return 1.0;
  const double prior = 1.0 / (config_.prior_sigma * config_.prior_sigma);
  return (prior + weighted_sum_) / (prior + information_);
}

double OdometryScale::sigma() const {
  if (!config_.enabled) return 0.0;
  return 1.0 / std::sqrt(1.0 / (config_.prior_sigma * config_.prior_sigma) + information_);
}

bool OdometryScale::significant() const {
  return config_.enabled && std::abs(scale() - 1.0) > config_.significance_sigmas * sigma();
}

void OdometryScale::add_step(const Eigen::Isometry2d &T_odom_base, const Eigen::Matrix2d &step_covariance) {
  if (reference_) {  // a reference implies the odometry since it (break_chain resets both)
    // The step's noise, from its own start frame into the segment's.
    const Eigen::Matrix2d R = (reference_->T_odom_base.inverse() * *last_odom_).linear();
    segment_covariance_ += R * step_covariance * R.transpose();
  }
  last_odom_ = T_odom_base;
}

void OdometryScale::pin(const Eigen::Isometry2d &T_odom_base, const Eigen::Isometry2d &T_map_base,
                        const Eigen::Matrix2d &position_covariance) {
  if (reference_) {
    // Both displacements in the segment's start frame: the odometry's own, and the one the
    // registrations put between the two pinned poses. Only the component along the
    // odometry's is the distance (a heading error turns the rest).
    const Eigen::Vector2d odometry = (reference_->T_odom_base.inverse() * T_odom_base).translation();
    const Eigen::Vector2d estimated = (reference_->T_map_base.inverse() * T_map_base).translation();
    const Eigen::Matrix2d R_map = reference_->T_map_base.inverse().linear();
    const double distance = odometry.norm();
    if (distance >= kMinSegmentM) {
      const Eigen::Vector2d along = odometry / distance;
      const Eigen::Matrix2d poses =
          R_map * (reference_->covariance + position_covariance) * R_map.transpose();
      const double measured = along.dot(estimated) / distance;
      const double variance = along.dot((segment_covariance_ + poses) * along) / (distance * distance);
      if (std::isfinite(measured) && variance > 0.0 && std::isfinite(variance)) {
        const double deviation = measured - scale(), spread = variance + sigma() * sigma();
        if (deviation * deviation > config_.outlier_sigmas * config_.outlier_sigmas * spread) {
          ++outliers_;
        } else {
          information_ += 1.0 / variance;
          weighted_sum_ += measured / variance;
          ++segments_;
        }
      }
    }
  }
  reference_ = Pinned{T_odom_base, T_map_base, position_covariance};
  segment_covariance_.setZero();
  last_odom_ = T_odom_base;
}

void OdometryScale::restore(double factor, double sigma) {
  break_chain();
  const double prior = 1.0 / (config_.prior_sigma * config_.prior_sigma);
  if (!config_.enabled || !std::isfinite(factor) || !(sigma > 0.0) || !std::isfinite(sigma)) return;
  // scale() = (prior + weighted_sum) / (prior + information), sigma() = (prior + information)^-1/2.
  const double total = 1.0 / (sigma * sigma);
  if (total <= prior) return;
  information_ = total - prior;
  weighted_sum_ = factor * total - prior;
}

void OdometryScale::break_chain() {
  reference_.reset();
  last_odom_.reset();
  segment_covariance_.setZero();
}

}  // namespace omnislam::slam
