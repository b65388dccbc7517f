#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "omnislam/slam/keyframe_graph.hpp"
#include "omnislam/slam/loop_closure.hpp"
#include "omnislam/slam/loop_job.hpp"
#include "omnislam/slam/nearest_neighbors.hpp"
#include "omnislam/slam/odometry_scale.hpp"
#include "omnislam/slam/point_map.hpp"
#include "omnislam/slam/ray_agreement.hpp"
#include "omnislam/slam/relocalizer.hpp"
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
  /// A correction the odometry noise model makes implausible is rejected: its Mahalanobis
  /// distance under the motion's uncertainty since the last integrated frame (odometry
  /// noise, plus the registration's own residual) beyond the chi-square bound of three
  /// degrees of freedom at 99.9%. Along a plain corridor the scan fits anywhere, and a fit
  /// that undoes a whole step of travel is the corridor, not the robot.
  bool odometry_gate = true;
  /// The same uncertainty as a prior of the registration (slam/trimmed_icp.hpp PosePrior):
  /// where the scan does not constrain the pose, it stays at the odometry's prediction.
  bool odometry_prior = true;
  int min_scan_points = 20;
  /// false: the thesis's SLAM without odometry (sec. 5.2): no motion prediction; the scan
  /// is registered against the map (with kMap) and the last three scans, forward then
  /// reverse, and accepted when Srel exceeds no_odometry_min_srel_percent and the rotation
  /// stays within no_odometry_max_rotation_rad (plus the absolute checks).
  bool use_odometry = true;
  double no_odometry_min_srel_percent = 50.0;
  double no_odometry_max_rotation_rad = 0.0873;
  /// Localization only: frames are registered against the (restored) map as usual, but
  /// nothing is ever integrated, so the map stays exactly as it was loaded.
  bool localization_only = false;
  /// An accepted frame is integrated into the map only when it lies at least this far from
  /// the last integrated one: nearer, an omnidirectional camera sees the same points from
  /// the same place (turning on the spot shows it nothing new), so the frame would add
  /// weight, not information. The map's fusion radius (0.05 m): at 30 Hz a robot standing
  /// still, or creeping, integrates nothing, one driving at 0.5 m/s every third frame. 0:
  /// every accepted frame (the thesis; its images lie 0.15-1 m apart).
  double map_min_step_m = 0.05;
  /// Tracking lost (a kidnapped robot: lifted, pushed or towed with its wheels off the floor,
  /// or odometry that jumped). With odometry and registration against the map, a frame the
  /// map registration rejects is judged: a scan mostly of new territory joins the map as
  /// before (placed by the previous scan). It is a misfit when neither where it is placed
  /// nor where the map registration converged explains it: the previous scan's and its own
  /// rays cross each other's walls, or its rays cross the map's (slam/ray_agreement.hpp).
  /// From a misfit on the robot is in doubt: no frame joins the map, and each frame is also
  /// searched for on the whole map (Relocalizer, `relocalizer`). The doubt ends when the map
  /// registration fits again, when the search confirms a pose where the tracking is, when
  /// the search confirms one elsewhere (where the robot was carried: tracking resumes
  /// there), or when the robot has explored a keyframe's distance with agreeing scans that
  /// nothing on the map resembles. After this many misfits in a row the robot is lost: its
  /// poses are dead reckoning, not published, until the search confirms one. Three, as many
  /// frames as the relocaliser needs to confirm a pose: leaving the tracking takes the same
  /// evidence as re-entering it. 0: never (the thesis: a frame registered against the
  /// previous scan alone is integrated).
  int lost_after_frames = 3;
  RelocalizerConfig relocalizer;
  /// Keyframes, a pose graph over them and loop closure (beyond the thesis). When a loop
  /// closes, the keyframe poses are optimised, the map is rebuilt from them and the current
  /// pose follows the correction.
  LoopClosureConfig loop_closure;
  /// The odometry's distance factor, learnt where the scans pin the position in every
  /// direction (slam/odometry_scale.hpp) and applied to each odometry step: along a plain
  /// corridor, where the prior holds the odometry's position, a wheel reading 3% long would
  /// put the robot 3% of the corridor ahead. Needs odometry_prior (which tells the pinned
  /// frames apart).
  OdometryScaleConfig odometry_scale;
};

/// Which registration was accepted for a frame.
enum class Attempt {
  kNone,
  kFirstFrame,
  kMap,
  kPreviousForward,
  kPreviousReverse,
  kOlderForward,
  kOlderReverse
};

struct FrameEstimate {
  Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
  bool integrated = false;  ///< a registration was accepted (tracked; its scan integrated when `mapped`)
  Attempt attempt = Attempt::kNone;
  TrimmedIcpResult registration;                         ///< the accepted one, or the last tried
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< (x, y, yaw) in the map frame
  bool keyframe = false;                                 ///< the frame became a keyframe of the pose graph
  /// The frame revisited a keyframe (LoopClosureConfig::reuse_keyframes): accepted and
  /// anchored to that keyframe (its scan stored there when `mapped`), not a keyframe itself.
  bool revisit = false;
  /// The scan was integrated into the map (and stored in the keyframe graph with loop
  /// closure on). An accepted frame is not: localization only, in an odometry gap, within
  /// map_min_step_m of the last integrated frame, or joining a full keyframe
  /// (KeyframeConfig::max_scans).
  bool mapped = false;
  /// A loop closure corrected the graph (and T_map_base) at this frame: its own keyframe's
  /// (inline loop closure) or a job's result applied just before it (background).
  bool loop_closed = false;
  bool map_rebuilt = false;  ///< ... and the map was rebuilt from the optimised keyframes
  /// A misfit (SlamConfig::lost_after_frames): the scan contradicted the previous scan or
  /// the map, or a misfit came since the map was last matched.
  /// Kept out of the map, and of anything else built from scans at their poses (the
  /// occupancy grid).
  bool unfit = false;
  /// Tracking is lost (SlamConfig::lost_after_frames): this frame's pose is the odometry's
  /// from the last tracked frame, not confirmed; nothing is integrated until a pose is found.
  bool lost = false;
  /// The frame a lost robot was found again at (its pose from the whole-map search).
  bool relocalized = false;
  /// The odometry's distance factor learnt up to this frame, its standard deviation, and
  /// whether it is applied to the odometry (SlamConfig::odometry_scale).
  double odometry_scale = 1.0;
  double odometry_scale_sigma = 0.0;
  bool odometry_scale_applied = false;
  /// This frame's index in Slam::trajectory() (-1: not recorded there, e.g. the frame a
  /// relocalisation confirmed; the trajectory starts afresh at resume()).
  int trajectory_index = -1;
};

/// A saved run's keyframe graph to resume with (Slam::resume).
struct ResumedGraph {
  KeyframeGraphState state;
  /// The resumed pose continues the saved run's tracking (its saved pose taken as is): the
  /// first new keyframe is joined to the saved last one by a sequential edge. false (a pose
  /// found afresh on the map): only loop closure ties the new keyframes to the saved ones.
  bool chained = true;
};

class Slam {
 public:
  explicit Slam(SlamConfig config = {})
      : config_(config),
        map_(config.map),
        keyframes_(config.loop_closure.keyframes),
        odometry_scale_(config.odometry_scale) {}

  /// Processes one local scan (base_link points, metres) with the odometry pose of the
  /// same frame (any fixed odom frame). The first frame defines the map frame, unless the
  /// state was resumed: then the first frame is predicted from the resumed pose.
  ///
  /// A frame without odometry (empty: a gap in the odometry stream) is predicted to keep
  /// the last frame-to-frame motion and registered as usual, but never integrated into the
  /// map (along a corridor a scan fits anywhere). The odometry chain is kept across the
  /// gap: the next frame with odometry is predicted from the last frame that had odometry,
  /// so no motion is counted twice or lost.
  ///
  /// `range_per_px_m`, empty or one per scan point, is how far each point's range moves per
  /// pixel of image error; given, the registration against the map weighs the points by
  /// it (TrimmedIcpConfig::range_weighting_passes).
  [[nodiscard]] FrameEstimate process(const Points2 &scan_base,
                                      const std::optional<Eigen::Isometry2d> &T_odom_base,
                                      std::span<const double> range_per_px_m = {});

  /// Continues from a saved state (map points with their integration count, and the last
  /// pose with its (x, y, yaw) covariance) instead of starting a new map. With the saved
  /// frame's odometry pose, the next frame is predicted from the odometry motion since
  /// (the odometry frame must be the same: a dataset, a base driver that kept running);
  /// without it, the robot is taken not to have moved. Either way the next frame is
  /// registered against the restored map.
  ///
  /// With the saved run's keyframe graph (whose scans are exactly the map's: as many
  /// integrations as `integrations`, else std::invalid_argument) and loop closure on, the
  /// graph continues: new keyframes join it, loop closure can close loops against the saved
  /// keyframes, and a loop's rebuilt map is made from all of them. Without one, the restored
  /// points are a fixed base that the graph of the new keyframes is added to. On a fixed map
  /// (localization_only) the graph's keyframe covariances say how far the map may be off
  /// where the robot is, and every published covariance adds the nearest's (map_uncertainty_at).
  void resume(std::vector<MapPoint> points, int integrations, const Eigen::Isometry2d &T_map_base,
              const Eigen::Matrix3d &covariance, const std::optional<Eigen::Isometry2d> &T_odom_base = {},
              std::optional<ResumedGraph> graph = {});

  /// How far the saved map may lie from the truth at `T_map_base`, as a covariance of a pose
  /// registered on it there: the mean covariance of the saved keyframes within
  /// keyframe_distance_m (else of the nearest one), each carried to `T_map_base` (a
  /// keyframe's heading error swings the map by the lever arm). Zero without a saved
  /// graph, or with one from a snapshot older than version 6 (which carries no covariances).
  [[nodiscard]] Eigen::Matrix3d map_uncertainty_at(const Eigen::Isometry2d &T_map_base) const;

  /// The keyframe graph to save with the map, when it describes the map (every map
  /// integration is one of its scans): not with loop closure off, nor after a resume
  /// without a graph (the restored points belong to no keyframe).
  [[nodiscard]] std::optional<KeyframeGraphState> graph_state() const;

  /// An operator's pose (rt/initialpose): the next frame is predicted at `T_map_base`
  /// (the robot taken not to have moved since) and registered against the whole map, which
  /// is kept. Before the first frame it places the new map's first scan there instead of at
  /// the origin.
  void set_pose(const Eigen::Isometry2d &T_map_base, const Eigen::Matrix3d &covariance);

  [[nodiscard]] const PointMap &map() const { return map_; }
  /// The odometry's distance factor as learnt so far (SlamConfig::odometry_scale).
  [[nodiscard]] const OdometryScale &odometry_scale() const { return odometry_scale_; }
  /// Starts from the factor an earlier run of the same robot learnt (OdometryScale::restore).
  void restore_odometry_scale(double factor, double sigma) { odometry_scale_.restore(factor, sigma); }
  /// Every processed frame's pose following the optimised pose graph (its keyframe's pose
  /// composed with where the frame was relative to it); without loop closure, the poses
  /// as they were estimated.
  [[nodiscard]] std::vector<Eigen::Isometry2d> trajectory() const { return keyframes_.trajectory(); }
  [[nodiscard]] const KeyframeGraph &keyframes() const { return keyframes_; }
  [[nodiscard]] int loop_closures() const { return loop_closures_; }
  /// Tracking is lost: frames are searched for on the whole map.
  [[nodiscard]] bool lost() const { return lost_; }

  /// With loop_closure.background: the loop job of the newest keyframe, once a keyframe was
  /// made and no job is out (at most one at a time: keyframes made while one is out are
  /// searched as one, the newest, after its result came back); otherwise nullopt. The job
  /// shares the stored scans and may be run on any thread (run_loop_job).
  [[nodiscard]] std::optional<LoopJob> take_loop_job();
  /// Takes the result of the job that is out, between two process() calls. A rebuilt map
  /// that lags the tracking by more than loop_closure.max_catch_up_scans goes back out as
  /// a catch-up job (take_loop_job; the job stays out) instead. Otherwise: a confirmed
  /// loop's optimised graph (with the keyframes made since moved by the correction of the
  /// job's newest one), the rebuilt map caught up with the scans integrated since, and the
  /// live pose, the odometry anchor and the recent scans moved by the same correction, so
  /// the next frame is predicted and registered in the corrected map. The next estimate
  /// reports loop_closed / map_rebuilt. A result from before a resume() is ignored.
  void apply_loop_result(LoopResult result);
  /// A job was taken and its result not applied yet.
  [[nodiscard]] bool loop_job_out() const { return job_out_; }

 private:
  [[nodiscard]] bool accept(const TrimmedIcpResult &registration, const Eigen::Isometry2d &predicted,
                            const Eigen::Isometry2d &estimate, double srel_limit_percent) const;
  /// The covariance published with `estimate`, `term` what the frame adds (frame_term);
  /// advances the random walk it is made of (walk_covariance_) to this frame: from the map's
  /// (map_walk_) when `on_map` (registered on the map as it stands), else from the previous
  /// frame's.
  [[nodiscard]] Eigen::Matrix3d published_covariance(const FrameEstimate &estimate,
                                                     const Eigen::Matrix3d &term, bool on_map);
  /// What `estimate` adds to the uncertainty of the tracking: its registration's
  /// cluster-robust covariance, or the odometry step's when it was not integrated.
  [[nodiscard]] Eigen::Matrix3d frame_term(const FrameEstimate &estimate,
                                           const Eigen::Isometry2d &step) const;
  [[nodiscard]] FrameEstimate register_scan(const Points2 &scan_base, const Eigen::Isometry2d &predicted,
                                            std::span<const double> range_per_px_m);
  /// How far beyond a scan at its predicted pose the map must be indexed for a registration
  /// to see all it would see in the whole map: the first search radius, the largest
  /// correction accepted (its translation, and its rotation swinging the scan's farthest
  /// point), and the neighbourhood of a paired point's normal.
  [[nodiscard]] double registration_reach_m(const Points2 &scan_base) const;
  void set_anchor(const Eigen::Isometry2d &T_odom_base, const Eigen::Isometry2d &T_map_base);
  [[nodiscard]] FrameEstimate seed_map(const Points2 &scan_base);
  /// Judges a frame the map registration rejected (SlamConfig::lost_after_frames: false when
  /// it is off): counts misfits in a row, and returns whether the robot is in doubt (the
  /// frame must stay out of the map).
  [[nodiscard]] bool count_misfit(const Points2 &scan_base, const FrameEstimate &estimate,
                                  const Eigen::Isometry2d &predicted);
  /// At the misfit test's margins (count_misfit): the scan at `T_map_base` against the
  /// previous scan, each one's rays against the other's structure (forward: the scan's), and
  /// the scan against `map_points`.
  struct Agreements {
    RayAgreement forward;
    RayAgreement backward;
  };
  [[nodiscard]] Agreements agreement_with_previous(const Points2 &scan_base,
                                                   const Eigen::Isometry2d &T_map_base) const;
  [[nodiscard]] RayAgreement agreement_with(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                            std::span<const Point2> map_points) const;
  /// Records how much the scan of a frame the map registration placed and the previous scan
  /// contradict each other, and the scan and the map around it (the references count_misfit
  /// judges by).
  void record_agreement(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base);
  /// The two references: scans against the previous scan, or against the map.
  enum class Reference { kPreviousScan, kMap };
  /// Whether `agreement` shows more of a scan crossing structure than the scans of this run
  /// do where the robot is (agreement_history_, against the same reference), and more than
  /// the relocaliser's outlier share.
  [[nodiscard]] bool contradicts(const RayAgreement &agreement, Reference reference) const;
  /// Starts (or, on a corrected map, restarts) the search of the whole map for the robot.
  void search_map();
  /// Whether the scan breaks with the previous frame's where the odometry puts it: it does
  /// not register onto that scan within a frame's largest accepted correction and residual
  /// (a carrying; also a view blocked right in front of the camera, where searching the
  /// whole map is the safe reading). A doorway's parallax does not: the scans still fit.
  [[nodiscard]] bool breaks_with_previous(const Points2 &scan_base, const Eigen::Isometry2d &predicted) const;
  /// One frame of the search (in doubt or lost): the whole map once the robot may have been
  /// carried (broke_with_previous_), else the poses dead reckoning can have reached from the last
  /// tracked one: the published uncertainty grown by this step, to chi-square 99.9% with
  /// three degrees of freedom, and never less than a frame's largest accepted correction.
  [[nodiscard]] LocalizationResult search_step(const Points2 &scan_base,
                                               const std::optional<Eigen::Isometry2d> &T_odom_base,
                                               const Eigen::Isometry2d &predicted,
                                               const Eigen::Isometry2d &step);
  /// A lost frame: searched for on the map; when found, tracking resumes there.
  [[nodiscard]] FrameEstimate search_lost(const Points2 &scan_base,
                                          const std::optional<Eigen::Isometry2d> &T_odom_base,
                                          const Eigen::Isometry2d &predicted, const Eigen::Isometry2d &step);
  /// A pose the search confirmed (in doubt or lost): tracking resumes there.
  [[nodiscard]] FrameEstimate found_again(const Points2 &scan_base,
                                          const std::optional<Eigen::Isometry2d> &T_odom_base,
                                          const LocalizationResult &found);
  /// What every frame ends with: its place in the trajectory (unless the graph recorded it),
  /// the loop flags, and the state the next frame is predicted from.
  /// Feeds the frame to the odometry's distance factor (SlamConfig::odometry_scale).
  void learn_odometry_scale(const FrameEstimate &estimate,
                            const std::optional<Eigen::Isometry2d> &T_odom_base);
  [[nodiscard]] FrameEstimate finish_frame(FrameEstimate estimate, const Points2 &scan_base,
                                           const std::optional<Eigen::Isometry2d> &T_odom_base,
                                           bool in_graph);
  /// Whether `estimate` lies within the largest correction a frame may take from `predicted`
  /// (SlamConfig::max_correction_m, max_correction_rad).
  [[nodiscard]] bool within_correction(const Eigen::Isometry2d &predicted,
                                       const Eigen::Isometry2d &estimate) const;
  [[nodiscard]] bool accept_without_odometry(const TrimmedIcpResult &registration,
                                             const Eigen::Isometry2d &predicted,
                                             const Eigen::Isometry2d &estimate) const;

  /// Adds an integrated frame to the keyframe graph; at a new keyframe, unless loop closure
  /// runs in the background, runs its loop job (search, and when a loop is confirmed,
  /// optimisation and map rebuild). Returns the frame's pose after any correction.
  [[nodiscard]] Eigen::Isometry2d update_graph(const Points2 &scan_base, FrameEstimate &estimate);
  [[nodiscard]] LoopJob make_loop_job() const;
  /// The graph resume() continues: `graph`, checked to hold the map's `integrations`.
  [[nodiscard]] KeyframeGraph resumed_graph(const ResumedGraph &graph, int integrations) const;
  /// Applies a job's result to the graph and the map; returns the correction of the live
  /// pose (T_corrected_tracked: identity when no loop was confirmed).
  [[nodiscard]] Eigen::Isometry2d take_result(LoopResult result);

  SlamConfig config_;
  PointMap map_;
  KeyframeGraph keyframes_;
  OdometryScale odometry_scale_;
  std::optional<LoopMatch> pending_loop_;  ///< the previous keyframe's verified loop, to be confirmed
  std::optional<LoopMatch> last_loop_;     ///< the last loop edge added (narrows the next search)
  int loop_closures_ = 0;
  bool search_due_ = false;              ///< a keyframe was made since the last job was taken
  bool job_out_ = false;                 ///< a job was taken, its result not applied yet
  std::optional<LoopJob> catch_up_job_;  ///< a result's map to catch up on the worker
  std::uint64_t generation_ = 0;         ///< counts resumes: older jobs' results are ignored
  bool closed_since_frame_ = false;      ///< a result closed a loop since the last frame
  bool rebuilt_since_frame_ = false;     ///< ... and rebuilt the map
  /// A confirmed loop closure tied the robot to the graph and no keyframe was made since:
  /// frames in mapped places revisit keyframes (LoopClosureConfig::reuse_keyframes).
  bool tied_ = false;
  /// A resumed map: the base every rebuild starts from (shared with the jobs).
  std::shared_ptr<const std::vector<MapPoint>> restored_points_;
  int restored_integrations_ = 0;
  bool started_ = false;
  /// The last frame that had odometry: its odometry pose and its estimate. Predictions
  /// compose the odometry motion since onto it.
  std::optional<Eigen::Isometry2d> anchor_T_odom_base_;
  Eigen::Isometry2d anchor_T_map_base_ = Eigen::Isometry2d::Identity();
  FrameEstimate previous_;
  Eigen::Isometry2d last_step_ = Eigen::Isometry2d::Identity();  ///< previous_ relative to the frame before
  std::deque<Points2> recent_scans_map_;  ///< newest first: the last scans at their estimated poses
  double relaxation_percent_ = 0.0;
  /// Uncertainty of the motion predicted for the current frame: the odometry steps since
  /// the last integrated frame (or an operator's pose), in the odometry_gate.
  Eigen::Matrix3d prediction_covariance_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d uncommitted_covariance_ = Eigen::Matrix3d::Zero();
  /// The random walk behind the published covariance: the sum of its terms as estimated, and
  /// the sum's degrees of freedom (Welch-Satterthwaite; infinite while every term comes from
  /// a model: odometry, an operator's or a saved pose).
  Eigen::Matrix3d walk_covariance_ = Eigen::Matrix3d::Zero();
  double walk_dof_ = std::numeric_limits<double>::infinity();
  /// The walk's terms since the last keyframe (map frame): the tracking's uncertainty of
  /// the current pose relative to that keyframe, the next sequential edge's covariance.
  Eigen::Matrix3d since_keyframe_covariance_ = Eigen::Matrix3d::Zero();
  /// A walk as it stood at one pose (with its degrees of freedom where they are kept).
  struct WalkAt {
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    Eigen::Isometry2d T_map_base = Eigen::Isometry2d::Identity();
    double dof = std::numeric_limits<double>::infinity();
  };
  /// The map's own uncertainty: the published walk of the last frame integrated into it (or
  /// of an operator's, a saved or a found pose). A frame registered on the map inherits it,
  /// not the walk of the frames since: those registered on the same map, their errors do
  /// not add up (a robot standing still for an hour is no less certain than after a second).
  WalkAt map_walk_;
  /// The same for since_keyframe_covariance_: its value at the last frame that joined the
  /// map or a keyframe's place (a revisit).
  WalkAt map_since_keyframe_;
  /// Both taken from the current walk and since_keyframe_covariance_, at `T_map_base`: the
  /// map is as certain as this pose (a fresh map, an operator's or a saved pose).
  void anchor_walks_at(const Eigen::Isometry2d &T_map_base);
  bool predicted_by_odometry_ = false;  ///< the current frame's prediction came from odometry
  /// The last integrated frame's pose (moved by corrections as the tracking is), or none:
  /// the next accepted frame is integrated (map_min_step_m).
  std::optional<Eigen::Isometry2d> last_mapped_;
  bool previous_failed_ = false;
  bool previous_is_scan_ =
      false;         ///< recent_scans_map_'s front is the previous frame's scan (not the whole map)
  int misfits_ = 0;  ///< misfit frames in a row
  /// How much consecutive scans cross each other's structure where the map registration
  /// placed them, and how much a scan crosses the map's, over the last frames it did (per
  /// frame: seen through, and seen through or confirmed; both ways summed for the scans): the
  /// front-end's wrong points on this floor, and those the map has gathered as well.
  struct Share {
    int seen_through = 0;
    int informative = 0;
  };
  struct AgreementTally {
    Share previous_scan;  ///< both ways summed
    Share map;
    [[nodiscard]] const Share &against(Reference reference) const {
      return reference == Reference::kMap ? map : previous_scan;
    }
  };
  std::deque<AgreementTally> agreement_history_;
  bool doubt_ = false;        ///< a misfit came since the map was last matched: nothing joins the map
  double unmatched_m_ = 0.0;  ///< travelled in doubt with agreeing scans that the map search does not place
  /// Where the frame's registration against the map converged when it was rejected.
  std::optional<Eigen::Isometry2d> map_fit_;
  /// In doubt or lost: the search over the map as it was when the doubt began.
  std::unique_ptr<Relocalizer> relocalizer_;
  bool lost_ = false;
  /// Since the doubt began, a scan broke with the one before it where the odometry put it
  /// (or a frame came without odometry): the robot may have been carried anywhere, and the
  /// whole map is searched. Until then the search keeps to where dead reckoning can have
  /// taken it: a place the map has not seen can look like one it has (a corridor like
  /// another), and only the track tells them apart.
  bool broke_with_previous_ = false;
  /// The frames since the doubt began (in doubt, then lost) that had odometry: their
  /// trajectory index and odometry pose. Dead-reckoned from before the carrying while they
  /// happen; when the search finds the robot, placed back from the found pose by their
  /// odometry (continuous since the carrying, which it did not see).
  std::vector<std::pair<int, Eigen::Isometry2d>> unplaced_;
  /// The published walk when the doubt began: a pose found on the map inherits it.
  Eigen::Matrix3d walk_before_lost_ = Eigen::Matrix3d::Zero();
  double walk_dof_before_lost_ = std::numeric_limits<double>::infinity();
  /// The resumed graph's keyframes (pose, covariance): the saved map's uncertainty by place.
  std::vector<std::pair<Eigen::Isometry2d, Eigen::Matrix3d>> saved_places_;
};

}  // namespace omnislam::slam
