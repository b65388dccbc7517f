#pragma once

#include <Eigen/Geometry>
#include <optional>

/// @file
/// How far the wheel odometry over- or under-reads distance, learnt from the scans. A wheel's
/// effective radius is rarely its nominal one (a tyre's wear, load or pressure, a carpet's
/// pile): the odometry then reads every distance a few per cent long or short. In a room the
/// scans correct each step, but along a plain corridor only the odometry tells how far the
/// robot went, and a loop whose corridors are all read long by the same factor closes without
/// showing it. Between two frames whose position the scans pin in every direction, the
/// distance the registrations put between them against the odometry's measures that factor;
/// the estimate is the weighted mean of those measurements (each weighed by its variance
/// from the odometry noise model and the two registrations) with a prior at 1. Algorithm
/// only: the SLAM feeds it (Slam::learn_odometry_scale) and applies it to each step.

namespace omnislam::slam {

struct OdometryScaleConfig {
  /// Estimate the factor and scale each odometry step's translation by it.
  bool enabled = true;
  /// The prior: a factor of 1 with this standard deviation. Wheel radii and tyre wear keep
  /// an odometry's distance within a few per cent of the truth.
  double prior_sigma = 0.05;
  /// The factor is applied once it differs from 1 by more than this many of its standard
  /// deviations (a two-sided test at 95%): an odometry that reads true is left exactly as it
  /// is, whatever its random error made the estimate wander meanwhile.
  double significance_sigmas = 2.0;
  /// A measurement this many standard deviations from the estimate (its own variance and the
  /// estimate's) is a registration gone wrong, not evidence: it is left out.
  double outlier_sigmas = 3.0;
};

class OdometryScale {
 public:
  explicit OdometryScale(OdometryScaleConfig config = {}) : config_(config) {}

  /// The factor to multiply an odometry translation by (1 when disabled) and its standard
  /// deviation (0 when disabled).
  [[nodiscard]] double scale() const;
  [[nodiscard]] double sigma() const;
  /// The factor applied to the odometry, and its standard deviation: scale() and sigma()
  /// once significant (OdometryScaleConfig::significance_sigmas), else 1 and 0.
  [[nodiscard]] double applied() const { return significant() ? scale() : 1.0; }
  [[nodiscard]] double applied_sigma() const { return significant() ? sigma() : 0.0; }
  [[nodiscard]] bool significant() const;
  /// Measurements taken into the estimate, and those left out as outliers.
  [[nodiscard]] int segments() const { return segments_; }
  [[nodiscard]] int outliers() const { return outliers_; }

  /// A frame with odometry (T_odom_base, raw as the odometry reports it); `step_covariance`
  /// is the position covariance of its step since the last frame with odometry, in that
  /// frame's base frame (the odometry noise model's).
  void add_step(const Eigen::Isometry2d &T_odom_base, const Eigen::Matrix2d &step_covariance);
  /// The same frame is pinned by its scan in every direction, at T_map_base with this
  /// position covariance (map frame): it closes the segment since the last pinned frame
  /// (a measurement) and starts the next.
  void pin(const Eigen::Isometry2d &T_odom_base, const Eigen::Isometry2d &T_map_base,
           const Eigen::Matrix2d &position_covariance);
  /// Continues from what an earlier run of the same wheels learnt (a snapshot): the estimate
  /// `factor` with standard deviation `sigma` becomes this one's, as if its measurements had
  /// been taken here (a sigma at or above the prior's adds nothing). The chain starts afresh.
  void restore(double factor, double sigma);
  /// The odometry chain broke (a gap, a lost or carried robot, a pose set from outside) or
  /// the pinned poses moved (a loop closure): the next pinned frame starts a segment afresh.
  void break_chain();

 private:
  struct Pinned {
    Eigen::Isometry2d T_odom_base;
    Eigen::Isometry2d T_map_base;
    Eigen::Matrix2d covariance;  ///< position, map frame
  };

  OdometryScaleConfig config_;
  std::optional<Pinned> reference_;                               ///< the segment's start
  std::optional<Eigen::Isometry2d> last_odom_;                    ///< the last frame with odometry
  Eigen::Matrix2d segment_covariance_ = Eigen::Matrix2d::Zero();  ///< odometry noise since, reference frame
  double information_ = 0.0;                                      ///< sum of the measurements' 1 / variance
  double weighted_sum_ = 0.0;                                     ///< sum of measurement / variance
  int segments_ = 0;
  int outliers_ = 0;
};

}  // namespace omnislam::slam
