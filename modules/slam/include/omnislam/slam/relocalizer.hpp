#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "omnislam/slam/correlative_matcher.hpp"
#include "omnislam/slam/nearest_neighbors.hpp"
#include "omnislam/slam/trimmed_icp.hpp"

/// @file
/// Global relocalisation on a saved map: the robot's pose found from its scans alone (no
/// start pose, or a rough one as a search window), and confirmed over several frames before
/// it is reported. Every frame, the whole map (or the window) is searched by correlative
/// matching; each pose that explains the scan nearly as well as the best one is a
/// hypothesis, refined by Trimmed ICP and carried to the next frame by odometry (two that the
/// refinement brings to one place are one hypothesis from then on). A pose is
/// reported only when one hypothesis alone has survived confirm_frames frames and no other
/// candidate of the frame, refined, explains the scan nearly as well: in a symmetric room
/// two hypotheses survive forever, and the robot is never localized on the wrong one of
/// them. Not thread-safe: one instance, fed frames in order.

namespace omnislam::slam {

struct RelocalizerConfig {
  /// Scores and likelihoods of hypotheses (the map's 0.05 m fusion scale).
  CorrelativeMatcherConfig matcher;
  /// The whole-map search runs on a grid twice as coarse (cell, fall-off and scan thinning
  /// 0.1 m: a quarter of the cells, half the yaws); Trimmed ICP brings its candidates to the
  /// map's precision.
  double search_resolution_m = 0.1;
  TrimmedIcpConfig icp;
  /// The search's candidates: a mean point score of at least min_score (the scan mostly on
  /// the map's structure) and relative_score of the frame's best.
  double min_score = 0.5;
  double relative_score = 0.8;
  /// Hypotheses then compete on their likelihood, summed over the frames they were tracked:
  /// each scan point (thinned to the matcher's voxel) is on the map's structure or, with
  /// probability outlier_share, not (the front-end's wrong points and what changed since the
  /// map: 5-10% of a scan, measured); neighbouring points share errors, so a frame's sum
  /// counts point_correlation of its points. A hypothesis falls behind the best by more than
  /// ln((1 - error_rate) / error_rate) + ln(hypotheses and candidates in play) and is
  /// dropped (Wald's test at error_rate for the frame as a whole; decision_margin()).
  double outlier_share = 0.1;
  double point_correlation = 0.5;
  double error_rate = 0.01;
  /// Poses closer than this are the same hypothesis.
  double distinct_m = 0.5;
  double distinct_rad = 0.35;
  /// A refinement is accepted when it fits (as in the SLAM) and explains the scan: at most
  /// twice outlier_share of its points farther than 0.1 m from the map (true poses on the
  /// bundled rooms, every camera factor on: 92-99% within; the sim room's end placed in the
  /// office's map: 71-75%). The SLAM's 0.7 is for consecutive frames, not for a whole map.
  double max_rms_m = 0.04;
  double min_inlier_share = 0.8;
  /// Frames the sole surviving hypothesis must have been tracked for.
  int confirm_frames = 3;
  int min_scan_points = 20;
};

enum class LocalizationState { kSearching, kLocalized };

struct LocalizationResult {
  LocalizationState state = LocalizationState::kSearching;
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();  ///< when localized
  /// Of the last refinement (x, y, yaw): its cluster-robust estimate as the t's covariance for
  /// the estimate's degrees of freedom (slam/trimmed_icp.hpp predictive_covariance).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int hypotheses = 0;       ///< alive after this frame
  double best_score = 0.0;  ///< of the frame's best hypothesis
  int searched_poses = 0;   ///< candidates the correlative search returned
};

class Relocalizer {
 public:
  explicit Relocalizer(const Points2 &map_points, RelocalizerConfig config = {});

  /// One frame: its scan (base_link, metres) and odometry pose (empty: none; the robot is
  /// then taken to stand still since the last frame, and hypotheses rely on the search).
  /// With a window, only poses inside it are searched (a rough pose with its uncertainty).
  [[nodiscard]] LocalizationResult process(const Points2 &scan_base,
                                           const std::optional<Eigen::Isometry2d> &T_odom_base,
                                           const std::optional<SearchWindow> &window = {});

  /// Forgets every hypothesis (a new search from the next frame).
  void reset();

 private:
  struct Hypothesis {
    Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    double score = 0.0;
    double deficit = 0.0;  ///< summed log-likelihood behind the best hypothesis (>= 0)
    int frames = 0;        ///< consecutive frames it was confirmed in
  };
  /// Log-likelihood of the (thinned) scan at a refined pose, times point_correlation: each
  /// point is explained (a map point within 2 sigma of the matcher, the 0.1 m the refinement
  /// counts too) or an outlier (probability outlier_share). Hypotheses are weighed by which
  /// points they explain, not by how closely: two corridors that explain every point differ
  /// only by sub-sigma fit quality, and the grid's bilinear score (off by up to ~20% with
  /// where the map's points fall between cells) turned that noise into evidence, enough to
  /// drop the true pose beside a wrong corridor in three frames.
  /// `thinned`: the scan as matcher_.thinned() gives it (once per frame).
  [[nodiscard]] double log_likelihood(const Points2 &thinned, const Eigen::Isometry2d &T_map_base) const;
  /// ICP from `guess` against the map; nullopt when the fit is rejected.
  [[nodiscard]] std::optional<TrimmedIcpResult> refine(const Points2 &scan_base,
                                                       const Eigen::Isometry2d &guess) const;
  [[nodiscard]] bool same_pose(const Eigen::Isometry2d &a, const Eigen::Isometry2d &b) const;
  /// A refined pose's score qualifies it as a hypothesis: min_score, and relative_score of
  /// the frame's best search candidate.
  [[nodiscard]] bool admissible(double score, double best_score) const;
  /// Log-likelihood by which a hypothesis may trail the best before it is dropped: Wald's
  /// ln((1 - error_rate) / error_rate), plus ln(competitors). The true pose is dropped when
  /// any one of the frame's other poses gets that far ahead of it by chance; with N of them
  /// in play each must be held to error_rate / N for the frame to keep error_rate
  /// (Bonferroni). A corridor offers dozens of alike poses, a room a handful.
  [[nodiscard]] double decision_margin(std::size_t competitors) const;
  /// Before `survivor` is reported: every candidate of the frame at another place, refined,
  /// that explains the scan within `margin` of it (as new hypotheses, each behind by what
  /// this frame says).
  [[nodiscard]] std::vector<Hypothesis> rivals(const Points2 &scan_base, const Points2 &thinned,
                                               const std::vector<PoseCandidate> &candidates,
                                               double candidates_best, const Hypothesis &survivor,
                                               double margin) const;

  RelocalizerConfig config_;
  CorrelativeMatcher matcher_;
  CorrelativeMatcher search_matcher_;
  NearestNeighbors map_index_;
  std::vector<Hypothesis> hypotheses_;
  std::optional<Eigen::Isometry2d> last_T_odom_base_;
  std::optional<Hypothesis> localized_;
};

}  // namespace omnislam::slam
