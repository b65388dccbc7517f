#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <span>

#include "omnislam/slam/nearest_neighbors.hpp"

/// @file
/// Trimmed ICP in 2D (Chetverikov et al. 2002; thesis sec. 5.1): registers a moving
/// "sample" point set onto a static "model" set, trimming to the best `overlap` share of
/// the pairs at every iteration.

namespace omnislam::slam {

/// Error metric of the pairs.
enum class IcpMetric {
  kPointToPoint,  ///< the thesis: Horn's closed form on point pairs (optionally with scale)
  kPointToLine,   ///< Gauss-Newton on the distance to the model's local line: no bias from
                  ///< the two scans sampling a wall at different places, and faster convergence
};

struct TrimmedIcpConfig {
  IcpMetric metric = IcpMetric::kPointToLine;
  double initial_search_radius_m = 0.5;  ///< dmax of the first iteration (thesis: 500 mm)
  double min_search_radius_m = 0.02;     ///< floor for the shrinking dmax
  double overlap = 0.7;                  ///< xi: share of sample points kept (thesis: 0.7)
  int max_iterations = 30;               ///< thesis results chapter
  double target_error_m2 = 1e-8;         ///< stop when the trimmed mean squared distance reaches it
  double min_relative_change = 1e-4;     ///< stop when e changes less than this between iterations
  bool estimate_scale = false;           ///< point-to-point only: also estimate a scale (thesis)
  bool keep_global_minimum = true;       ///< return the best iterate if the last is > 10% worse
  /// Bearing sectors of the sample frame whose pairs' residuals robust_covariance treats as
  /// possibly correlated (one cluster each); 45 deg is about one wall seen from inside a room.
  int covariance_sectors = 8;
  /// Reweighting passes when the sample's range errors per pixel are given (point-to-line
  /// only): after a plain fit, the pairs' squared residuals are modelled as s0^2 + k b^2,
  /// with b the point's range per pixel projected on the model normal, the two variances
  /// fitted to the pairs themselves; the fit is repeated with each pair weighted by
  /// s0^2 / (s0^2 + k b^2). A point ranged by stereo at 3 m moves ~8x further per pixel
  /// than a floor contact there, and far points further than near ones. 0: unweighted.
  int range_weighting_passes = 2;
  /// Degrees of freedom nu of a Student-t law of the residuals in those passes: each pair's
  /// weight is further multiplied by (nu + 1) / (nu + r^2 / sigma^2), r its residual and
  /// sigma^2 = s0^2 + k b^2 its variance under the fitted model, so a pair far off that law
  /// (a floor contact ranged from a skirting board's top, 8% long, whose small b would give
  /// it a large weight) pulls the fit little. The covariance leaves this factor out (it
  /// reweighs residuals, it adds no information) but takes the t fit's efficiency over least
  /// squares, (nu + 3) (nu - 2) / ((nu + 1) nu) of the residual variance (nu > 2). 4: Lange,
  /// Little & Taylor's (1989) robust default; 0: Gaussian residuals (the behaviour before).
  double residual_tail_dof = 4.0;
  /// With a pose prior (point-to-line only): a direction of the motion that the pairs pin
  /// with less information than this many pairs whose normals lie along it (the smaller
  /// eigenvalue of sum w n n^T, in pairs) is left to the prior, and the returned covariance
  /// takes the prior's variance there. Along a plain corridor every normal lies across it,
  /// and a degree of tilt in a few of them (a wall bent by its scan's errors, a skirting
  /// board's top beside its base) would otherwise place the robot along the corridor by the
  /// walls' millimetre residuals divided by that tilt, overruling the odometry. 3: as many
  /// pairs as a planar pose has parameters (fewer never determine one). 0: off.
  double min_constraining_pairs = 3.0;
};

struct TrimmedIcpResult {
  Eigen::Isometry2d T_model_sample = Eigen::Isometry2d::Identity();  ///< applied to sample points
  double scale = 1.0;                                                ///< 1 unless estimate_scale
  bool valid = false;      ///< false when too few pairs were ever found
  bool converged = false;  ///< stopped by a criterion, not by the iteration cap
  int iterations = 0;
  double first_error_m2 = 0.0;  ///< e of the first iteration (trimmed mean squared residual)
  double final_error_m2 = 0.0;  ///< e at the returned transform
  double srel_percent = 0.0;    ///< 100 (e_first - e_final) / e_first (thesis "Srel")
  std::size_t sample_points = 0;
  std::size_t kept_pairs = 0;  ///< trimmed pairs at the returned transform
  double inlier_share = 0.0;   ///< share of sample points with a model point within 0.1 m at the end
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< (x, y, yaw) of T_model_sample, from the residual
  /// The same, robust to residuals that are not independent: a cluster-robust (sandwich)
  /// estimate with the pairs grouped by the sample point's bearing. A front-end's errors are
  /// shared by neighbouring points (one wall's range bias, a lobe's sub-pixel placement), so
  /// sigma^2 (J^T J)^-1 above, which treats every pair as an independent measurement, is
  /// smaller than the error the fit actually makes. Never smaller than `covariance`.
  Eigen::Matrix3d robust_covariance = Eigen::Matrix3d::Zero();
  /// Degrees of freedom of robust_covariance as an estimate of the error's covariance: the
  /// sectors that held pairs less one (their scores sum to zero at the fit), or the pairs
  /// less three where the independent estimate stands in. Eight sectors give seven: the
  /// estimate itself is uncertain (predictive_covariance).
  double covariance_dof = 0.0;
  /// The range-noise model of the last reweighting pass, k / s0^2 in (px/m)^2: a pair's
  /// weight was 1 / (1 + range_noise_ratio b^2). 0 when the fit was unweighted.
  double range_noise_ratio = 0.0;
  /// Directions of the translation left to the prior (TrimmedIcpConfig::min_constraining_pairs):
  /// 0, 1 (a corridor) or 2.
  int unconstrained_directions = 0;
};

/// Fewest degrees of freedom predictive_covariance assumes (a t with fewer has no variance).
inline constexpr double kMinPredictiveDof = 3.0;

/// The covariance of the error when `estimate` is itself estimated with `dof` degrees of
/// freedom: the error then follows a multivariate t with that scale matrix, whose covariance
/// is dof / (dof - 2) times it (3x with 3 dof, 1.4x with 7, 1.03x with 70; unchanged for
/// infinite dof, a covariance known from a model). dof is taken as at least kMinPredictiveDof.
[[nodiscard]] Eigen::Matrix3d predictive_covariance(const Eigen::Matrix3d &estimate, double dof);

/// A registration's robust_covariance as the t's, for its covariance_dof.
[[nodiscard]] inline Eigen::Matrix3d predictive_covariance(const TrimmedIcpResult &registration) {
  return predictive_covariance(registration.robust_covariance, registration.covariance_dof);
}

/// A Gaussian prior on the registered position (an odometry prediction): where the pairs do
/// not constrain it (along a plain corridor) it holds the position; elsewhere the pairs,
/// weighted by their residual variance, outweigh it. Position only: the heading is what
/// scans constrain best (every wall gives it), the position along a corridor what they may
/// not. Point-to-line only.
struct PosePrior {
  Eigen::Isometry2d T_model_sample = Eigen::Isometry2d::Identity();
  Eigen::Matrix2d translation_covariance = Eigen::Matrix2d::Identity();  ///< of the sample frame's origin
};

/// Registers `sample` onto `model`, starting from `initial_guess`. Degenerate inputs
/// (empty sets, fewer than 3 pairs) return valid = false with the initial guess.
/// `sample_range_per_px_m`, empty or one per sample point, is how far each point's range
/// moves per pixel of image error (stereo::ScanPoint::range_per_px_m); given, the pairs are
/// weighted by it (TrimmedIcpConfig::range_weighting_passes). final_error_m2, srel_percent,
/// kept_pairs and inlier_share stay unweighted measures of the returned transform.
[[nodiscard]] TrimmedIcpResult register_trimmed_icp(const NearestNeighbors &model, const Points2 &sample,
                                                    const Eigen::Isometry2d &initial_guess,
                                                    const TrimmedIcpConfig &config = {},
                                                    const PosePrior *prior = nullptr,
                                                    std::span<const double> sample_range_per_px_m = {});

}  // namespace omnislam::slam
