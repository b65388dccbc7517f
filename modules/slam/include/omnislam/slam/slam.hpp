#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "omnislam/slam/nearest_neighbors.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/trimmed_icp.hpp"

/// @file
/// SLAM with odometry (thesis sec. 5.3, fig. 5.3): each local scan is registered with
/// Trimmed ICP starting from the odometry prediction, accepted or not, and integrated into
/// the point map. Not thread-safe: one instance per pipeline, fed frames in order.

namespace omnislam::slam {

/// What a scan is registered against first.
enum class RegistrationTarget {
  kPreviousScan,  ///< the thesis: the previous local map, then the reverse registration
  kMap,           ///< the global map first (less drift), then the thesis's two attempts
};

struct SlamConfig {
  TrimmedIcpConfig icp;
  PointMapConfig map;
  RegistrationTarget target = RegistrationTarget::kMap;
  /// Thesis acceptance: Srel below the limit plus the relaxation accumulated by failures.
  bool use_srel_test = false;
  double srel_limit_percent = 30.0;
  double srel_relax_percent = 10.0;
  /// Thesis UsaOpcional: after a failure, refine the next accepted pose against the map
  /// (accepted if Srel < 50%). Only meaningful with kPreviousScan.
  bool optional_map_correction = true;
  /// Absolute checks (beyond the thesis): a registration that neither fits nor overlaps is
  /// rejected even when Srel is small.
  double max_rms_m = 0.04;
  double min_inlier_share = 0.7;
  /// A correction of the odometry prediction beyond these is implausible.
  double max_correction_m = 0.3;
  double max_correction_rad = 0.1745;
  int min_scan_points = 20;
};

/// Which registration was accepted for a frame.
enum class Attempt { kNone, kFirstFrame, kMap, kPreviousForward, kPreviousReverse };

struct FrameEstimate {
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  bool integrated = false;
  Attempt attempt = Attempt::kNone;
  TrimmedIcpResult registration;                         ///< the accepted one, or the last tried
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< (x, y, yaw) in the map frame
};

class Slam {
 public:
  explicit Slam(SlamConfig config = {}) : config_(config), map_(config.map) {}

  /// Processes one local scan (base_link points, metres) with the odometry pose of the
  /// same frame (any fixed odom frame). The first frame defines the map frame.
  [[nodiscard]] FrameEstimate process(const Points2 &scan_base, const Eigen::Isometry2d &T_odom_base);

  [[nodiscard]] const PointMap &map() const { return map_; }

 private:
  [[nodiscard]] bool accept(const TrimmedIcpResult &registration, const Eigen::Isometry2d &predicted,
                            const Eigen::Isometry2d &estimate, double srel_limit_percent) const;
  [[nodiscard]] FrameEstimate register_scan(const Points2 &scan_base, const Eigen::Isometry2d &predicted);

  SlamConfig config_;
  PointMap map_;
  std::optional<Eigen::Isometry2d> previous_T_odom_base_;
  FrameEstimate previous_;
  Points2 previous_scan_map_;  ///< the previous scan at its estimated (or propagated) pose
  double relaxation_percent_ = 0.0;
  bool previous_failed_ = false;
};

}  // namespace omnislam::slam
