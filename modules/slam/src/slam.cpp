#include "omnislam/slam/slam.hpp"

#include <Eigen/Eigenvalues>

#include "omnislam/slam/planar_pose.hpp"
#include "omnislam/slam/ray_agreement.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace omnislam::slam {
namespace {

// The misfit test's reference: the scans of the last this many frames the map placed.
constexpr std::size_t kAgreementFrames = 20;
// A misfit's share of crossing points lies this many standard deviations beyond theirs.
constexpr double kMisfitSigmas = 3.0;
// The 99.9% quantile of chi-square with three degrees of freedom (x, y, yaw).
constexpr double kChiSquare999ThreeDof = 16.27;

// Odometry uncertainty of one step, used to grow the covariance of unregistered frames
// (the thesis noise model: 10% of the distance, 1.5 deg of heading).
Eigen::Matrix3d odometry_step_covariance(const Eigen::Isometry2d &step) {
  const double distance = step.translation().norm();
  const double sigma_xy = 0.1 * distance / std::sqrt(3.0);
  const double sigma_yaw =
      std::max(0.1 * std::abs(yaw_rad_of(step)), 1.5 * std::numbers::pi / 180.0) / std::sqrt(3.0);
  return Eigen::Vector3d(sigma_xy * sigma_xy, sigma_xy * sigma_xy, sigma_yaw * sigma_yaw).asDiagonal();
}

// A covariance's size for Welch-Satterthwaite: its position variance.
double position_size(const Eigen::Matrix3d &covariance) { return covariance.topLeftCorner<2, 2>().trace(); }

// One term's share of the Welch-Satterthwaite denominator.
double satterthwaite_share(const Eigen::Matrix3d &term, double dof) {
  const double size = position_size(term);
  return std::isfinite(dof) ? size * size / dof : 0.0;
}

}  // namespace

Eigen::Matrix3d Slam::published_covariance(const FrameEstimate &estimate, const Eigen::Matrix3d &term,
                                           bool on_map) {
  // What the pose's error against the map frame is made of. On a fixed map (localization
  // only) the registration's alone. Otherwise the map the frame registered against was
  // built from the poses before it, whose errors it inherits: the covariance of the last pose
  // integrated into it carried to this pose plus this frame's own (the registration's,
  // cluster-robust), the drift of a chain of registrations. Frames registered on the map
  // without joining it (standing still, or in a place whose keyframe is full) share that
  // map and do not chain: the next one starts again from the map's. A frame placed by the
  // previous scan or by odometry alone (none accepted: the odometry step's) chains from the
  // previous frame. (A loop
  // closure does not shrink it: taking the old keyframe's covariance there was measured
  // overconfident on building-2laps, mean NEES 148, the graph's correction leaving the
  // keyframes along the loop less certain than the one it closed on.)
  //
  // Each registration's covariance is itself an estimate from a few sectors (seven degrees of
  // freedom from eight), so the error follows a t, not a Gaussian, with that covariance as
  // its scale; the walk's degrees of freedom are summed as Welch and Satterthwaite do
  // (terms sized by their position variance; a model's term has infinitely many) and the
  // covariance published is the t's (predictive_covariance): 1.4x after one registration,
  // within 3% of the walk after ten.
  //
  // On a fixed map the pose is the registration's on a map that is itself off by as much as
  // the poses it was built from were: the saved keyframes' covariance where the robot is is
  // added (map_uncertainty_at; measured 2026-12-07, mean NEES of each bundled dataset
  // localized on its own saved map 138-169,950 without it, 0.8-3.7 with it).
  const TrimmedIcpResult &registration = estimate.registration;
  if (estimate.integrated && config_.localization_only) {
    walk_covariance_ = registration.robust_covariance;
    walk_dof_ = registration.covariance_dof;
    return predictive_covariance(walk_covariance_, walk_dof_) + map_uncertainty_at(estimate.T_map_base);
  }
  const WalkAt from = on_map ? map_walk_ : WalkAt{walk_covariance_, previous_.T_map_base, walk_dof_};
  const Eigen::Matrix3d before = carried(from.covariance, from.T_map_base, estimate.T_map_base);
  const double term_dof =
      estimate.integrated ? registration.covariance_dof : std::numeric_limits<double>::infinity();
  const double shares = satterthwaite_share(before, from.dof) + satterthwaite_share(term, term_dof);
  walk_covariance_ = before + term;
  const double size = position_size(walk_covariance_);
  walk_dof_ = shares > 0.0 ? size * size / shares : std::numeric_limits<double>::infinity();
  return predictive_covariance(walk_covariance_, walk_dof_);
}

Eigen::Matrix3d Slam::frame_term(const FrameEstimate &estimate, const Eigen::Isometry2d &step) const {
  return estimate.integrated
             ? estimate.registration.robust_covariance
             : rotated_covariance(odometry_step_covariance(step), previous_.T_map_base.linear());
}

bool Slam::within_correction(const Eigen::Isometry2d &predicted, const Eigen::Isometry2d &estimate) const {
  const Eigen::Isometry2d correction = predicted.inverse() * estimate;
  return correction.translation().norm() <= config_.max_correction_m &&
         std::abs(yaw_rad_of(correction)) <= config_.max_correction_rad;
}

bool Slam::accept(const TrimmedIcpResult &registration, const Eigen::Isometry2d &predicted,
                  const Eigen::Isometry2d &estimate, double srel_limit_percent) const {
  if (!registration.valid) return false;
  if (config_.use_srel_test && registration.srel_percent >= srel_limit_percent) return false;
  if (std::sqrt(registration.final_error_m2) > config_.max_rms_m) return false;
  if (registration.inlier_share < config_.min_inlier_share) return false;
  if (!within_correction(predicted, estimate)) return false;
  if (!config_.odometry_gate || !predicted_by_odometry_) return true;
  const Eigen::Isometry2d correction = predicted.inverse() * estimate;
  Eigen::Matrix3d S = prediction_covariance_;
  S(0, 0) += registration.final_error_m2;
  S(1, 1) += registration.final_error_m2;
  const Eigen::Vector3d e(correction.translation().x(), correction.translation().y(), yaw_rad_of(correction));
  return e.dot(S.ldlt().solve(e)) <= kChiSquare999ThreeDof;
}

bool Slam::accept_without_odometry(const TrimmedIcpResult &registration, const Eigen::Isometry2d &predicted,
                                   const Eigen::Isometry2d &estimate) const {
  if (!registration.valid || registration.srel_percent <= config_.no_odometry_min_srel_percent) return false;
  if (std::sqrt(registration.final_error_m2) > config_.max_rms_m) return false;
  if (registration.inlier_share < config_.min_inlier_share) return false;
  const Eigen::Isometry2d correction = predicted.inverse() * estimate;
  return correction.translation().norm() <= config_.icp.initial_search_radius_m &&
         std::abs(yaw_rad_of(correction)) <= config_.no_odometry_max_rotation_rad;
}

double Slam::registration_reach_m(const Points2 &scan_base) const {
  double farthest_m = 0.0;
  for (const Point2 &p : scan_base) farthest_m = std::max(farthest_m, p.norm());
  const double translation_m =
      config_.use_odometry ? config_.max_correction_m : config_.icp.initial_search_radius_m;
  const double rotation_rad =
      config_.use_odometry ? config_.max_correction_rad : config_.no_odometry_max_rotation_rad;
  return config_.icp.initial_search_radius_m + translation_m + farthest_m * std::abs(rotation_rad) +
         kNormalRadiusM;
}

FrameEstimate Slam::register_scan(const Points2 &scan_base, const Eigen::Isometry2d &predicted,
                                  std::span<const double> range_per_px_m) {
  const double srel_limit = config_.srel_limit_percent + relaxation_percent_;
  auto accepted = [&](const TrimmedIcpResult &r, const Eigen::Isometry2d &pose) {
    return config_.use_odometry ? accept(r, predicted, pose, srel_limit)
                                : accept_without_odometry(r, predicted, pose);
  };
  FrameEstimate estimate;
  estimate.T_map_base = predicted;

  const PosePrior prior{predicted, prediction_covariance_.topLeftCorner<2, 2>()};
  const PosePrior *use_prior = predicted_by_odometry_ && config_.odometry_prior ? &prior : nullptr;
  auto try_forward = [&](const NearestNeighbors &model, Attempt attempt) {
    const TrimmedIcpResult r =
        register_trimmed_icp(model, scan_base, predicted, config_.icp, use_prior, range_per_px_m);
    estimate.registration = r;
    if (!accepted(r, r.T_model_sample)) return false;
    estimate = {r.T_model_sample, true, attempt, r, r.covariance};
    return true;
  };
  // Reverse: an earlier scan registered onto this one, in this scan's frame.
  const NearestNeighbors current(scan_base);
  auto try_reverse = [&](const Points2 &earlier_map, Attempt attempt) {
    const TrimmedIcpResult r = register_trimmed_icp(current, earlier_map, predicted.inverse(), config_.icp);
    estimate.registration = r;
    const Eigen::Isometry2d pose = r.T_model_sample.inverse();
    if (!accepted(r, pose)) return false;
    estimate = {pose, true, attempt, r, r.covariance};
    return true;
  };

  map_fit_.reset();
  if (config_.target == RegistrationTarget::kMap) {
    if (try_forward(map_.index_near(transformed(scan_base, predicted), registration_reach_m(scan_base)),
                    Attempt::kMap))
      return estimate;
    if (estimate.registration.valid) map_fit_ = estimate.registration.T_model_sample;
  }
  // The thesis registers against the previous scan (with odometry), or against each of
  // the last three (without), forward then reverse.
  const std::size_t scans = config_.use_odometry ? 1 : recent_scans_map_.size();
  for (std::size_t i = 0; i < scans && i < recent_scans_map_.size(); ++i) {
    const Points2 &earlier = recent_scans_map_[i];
    if (try_forward(NearestNeighbors(earlier), i == 0 ? Attempt::kPreviousForward : Attempt::kOlderForward) ||
        try_reverse(earlier, i == 0 ? Attempt::kPreviousReverse : Attempt::kOlderReverse)) {
      return estimate;
    }
  }
  return estimate;
}

void Slam::resume(std::vector<MapPoint> points, int integrations, const Eigen::Isometry2d &T_map_base,
                  const Eigen::Matrix3d &covariance, const std::optional<Eigen::Isometry2d> &T_odom_base,
                  std::optional<ResumedGraph> graph) {
  // Checked before anything changes: a graph that is not the map's leaves this as it was.
  const bool continue_graph = config_.loop_closure.enabled && graph;
  KeyframeGraph keyframes =
      continue_graph ? resumed_graph(*graph, integrations) : KeyframeGraph(config_.loop_closure.keyframes);
  saved_places_.clear();
  if (graph) {
    for (const KeyframeGraphState::SavedKeyframe &keyframe : graph->state.keyframes)
      saved_places_.emplace_back(planar_pose(keyframe.T_map_keyframe.x_m, keyframe.T_map_keyframe.y_m,
                                             keyframe.T_map_keyframe.yaw_rad),
                                 keyframe.covariance);
  }
  // With the saved graph the restored points are its scans, which a rebuild integrates
  // itself; without it they are a base the graph's corrections do not move.
  restored_points_.reset();
  restored_integrations_ = 0;
  if (config_.loop_closure.enabled && !continue_graph) {
    restored_points_ = std::make_shared<const std::vector<MapPoint>>(points);
    restored_integrations_ = integrations;
  }
  keyframes_ = std::move(keyframes);
  pending_loop_.reset();
  last_loop_.reset();
  search_due_ = false;
  job_out_ = false;
  catch_up_job_.reset();
  tied_ = false;
  last_mapped_.reset();
  ++generation_;
  map_ = PointMap(config_.map, std::move(points), integrations);
  started_ = true;
  anchor_T_odom_base_ = T_odom_base;
  anchor_T_map_base_ = T_map_base;
  odometry_scale_.break_chain();
  // A pose found afresh on the saved map (the graph not chained to it) is as uncertain as the
  // map is there, too; a saved pose taken as is carries its own run's covariance already.
  const Eigen::Matrix3d start =
      graph && !graph->chained ? Eigen::Matrix3d(covariance + map_uncertainty_at(T_map_base)) : covariance;
  previous_ = {T_map_base, true, Attempt::kNone, {}, start};
  walk_covariance_ = start;
  walk_dof_ = std::numeric_limits<double>::infinity();
  since_keyframe_covariance_.setZero();  // the saved pose is taken as is
  anchor_walks_at(T_map_base);
  // Until a scan has been seen, the whole map stands in for the previous local map.
  recent_scans_map_.assign(1, map_.index().points());
  previous_is_scan_ = false;
  relaxation_percent_ = 0.0;
  previous_failed_ = false;
  misfits_ = 0;
  doubt_ = false;
  relocalizer_.reset();
  lost_ = false;
  unplaced_.clear();
}

KeyframeGraph Slam::resumed_graph(const ResumedGraph &graph, int integrations) const {
  // A rebuild integrates the graph's scans instead of the restored points: they must be the same.
  if (graph.state.integrations() != static_cast<std::size_t>(integrations)) {
    throw std::invalid_argument("Slam::resume: the keyframe graph holds " +
                                std::to_string(graph.state.integrations()) + " integrated scans, the map " +
                                std::to_string(integrations));
  }
  return KeyframeGraph(config_.loop_closure.keyframes, graph.state, graph.chained);
}

Eigen::Matrix3d Slam::map_uncertainty_at(const Eigen::Isometry2d &T_map_base) const {
  // The map here holds the scans of every keyframe within a keyframe's spacing (a place
  // passed twice holds both passes'): the mean of their covariances, each carried here; the
  // nearest keyframe's where none is that near.
  const std::pair<Eigen::Isometry2d, Eigen::Matrix3d> *nearest = nullptr;
  double nearest_m2 = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  int near = 0;
  const double reach_m = config_.loop_closure.keyframes.keyframe_distance_m;
  for (const auto &place : saved_places_) {
    const double m2 = (place.first.translation() - T_map_base.translation()).squaredNorm();
    if (m2 < nearest_m2) nearest_m2 = m2, nearest = &place;
    if (m2 <= reach_m * reach_m) {
      sum += carried(place.second, place.first, T_map_base);
      ++near;
    }
  }
  if (near > 0) return sum / near;
  return nearest != nullptr ? carried(nearest->second, nearest->first, T_map_base) : Eigen::Matrix3d::Zero();
}

std::optional<KeyframeGraphState> Slam::graph_state() const {
  // Without loop closure no scan is kept; after a resume without a graph the restored points
  // are in no keyframe. Either way a map rebuilt from the graph would not be this map.
  if (!config_.loop_closure.enabled || restored_points_ ||
      keyframes_.integrations() != static_cast<std::size_t>(map_.integrations()))
    return std::nullopt;
  return keyframes_.state();
}

void Slam::set_pose(const Eigen::Isometry2d &T_map_base, const Eigen::Matrix3d &covariance) {
  // The odometry chain restarts at the next frame: no motion is predicted from before the jump.
  anchor_T_odom_base_.reset();
  anchor_T_map_base_ = T_map_base;
  previous_.T_map_base = T_map_base;
  previous_.covariance = covariance;
  walk_covariance_ = covariance;
  walk_dof_ = std::numeric_limits<double>::infinity();
  uncommitted_covariance_ = covariance;     // the operator's pose is as rough as they say
  since_keyframe_covariance_ = covariance;  // so is its relation to the last keyframe
  anchor_walks_at(T_map_base);
  tied_ = false;         // until a loop closure confirms the jump
  last_mapped_.reset();  // the first frame accepted at the new pose is integrated
  last_step_ = Eigen::Isometry2d::Identity();
  // The scans before the jump sit at the old poses: the whole map stands in for them.
  if (!map_.empty()) recent_scans_map_.assign(1, map_.index().points());
  previous_is_scan_ = false;
  relaxation_percent_ = 0.0;
  previous_failed_ = false;
  misfits_ = 0;  // the operator says where the robot is: not lost
  doubt_ = false;
  relocalizer_.reset();
  lost_ = false;
  unplaced_.clear();  // their poses stay dead-reckoned: the operator's pose is too rough to place them back
  odometry_scale_.break_chain();  // what the factor learnt stays: the same wheels
}

void Slam::anchor_walks_at(const Eigen::Isometry2d &T_map_base) {
  map_walk_ = {walk_covariance_, T_map_base, walk_dof_};
  map_since_keyframe_ = {since_keyframe_covariance_, T_map_base};
}

void Slam::set_anchor(const Eigen::Isometry2d &T_odom_base, const Eigen::Isometry2d &T_map_base) {
  anchor_T_odom_base_ = T_odom_base;
  anchor_T_map_base_ = T_map_base;
}

FrameEstimate Slam::seed_map(const Points2 &scan_base) {
  // A new map starts at the current pose: the identity on a fresh start, so the first
  // frame defines the map frame (REP-105 map = first pose).
  previous_ = {previous_.T_map_base, true, Attempt::kFirstFrame, {}, previous_.covariance};
  recent_scans_map_.assign(1, transformed(scan_base, previous_.T_map_base));
  map_.integrate(recent_scans_map_.front());
  previous_.mapped = true;
  last_mapped_ = previous_.T_map_base;
  anchor_walks_at(previous_.T_map_base);
  if (config_.loop_closure.enabled) {
    previous_.keyframe = keyframes_.add_integrated(scan_base, previous_.T_map_base, previous_.covariance);
    keyframes_.add_scan_covariance(previous_.covariance, previous_.T_map_base);
  } else {
    keyframes_.add_pose(previous_.T_map_base);
  }
  previous_.trajectory_index = keyframes_.frame_count() - 1;
  return previous_;
}

Eigen::Isometry2d Slam::update_graph(const Points2 &scan_base, FrameEstimate &estimate) {
  estimate.keyframe = keyframes_.add_integrated(scan_base, estimate.T_map_base, since_keyframe_covariance_);
  if (!estimate.keyframe) return estimate.T_map_base;
  since_keyframe_covariance_.setZero();
  tied_ = false;  // new trail: a loop closure must tie it again before places are revisited
  search_due_ = true;
  if (config_.loop_closure.background) return estimate.T_map_base;  // the caller runs the job
  search_due_ = false;
  const Eigen::Isometry2d T_corrected_tracked = take_result(run_loop_job(make_loop_job()));
  estimate.loop_closed = closed_since_frame_;
  estimate.map_rebuilt = rebuilt_since_frame_;
  closed_since_frame_ = rebuilt_since_frame_ = false;
  if (!estimate.loop_closed) return estimate.T_map_base;
  for (Points2 &scan : recent_scans_map_) scan = transformed(scan, T_corrected_tracked);
  return keyframes_.keyframes().back().T_map_keyframe;  // this frame is that keyframe
}

LoopJob Slam::make_loop_job() const {
  LoopJob job;
  job.generation = generation_;
  job.graph = keyframes_.without_trajectory();
  job.edges = keyframes_.graph().edges().size();
  job.pending = pending_loop_;
  job.last_loop = last_loop_;
  job.restored_points = restored_points_;
  job.restored_integrations = restored_integrations_;
  job.config = config_.loop_closure;
  job.icp = config_.icp;
  job.map = config_.map;
  return job;
}

Eigen::Isometry2d Slam::take_result(LoopResult result) {
  const LoopMatch &match = result.match;
  if (match.status != LoopStatus::kAccepted) {
    pending_loop_.reset();
    return Eigen::Isometry2d::Identity();
  }
  pending_loop_ = match;
  if (!result.confirmed || !result.solved) return Eigen::Isometry2d::Identity();
  last_loop_ = match;
  ++loop_closures_;
  closed_since_frame_ = true;
  tied_ = true;
  const Eigen::Isometry2d T_corrected_tracked = keyframes_.adopt(*result.solved, result.copied_edges);
  if (result.map) {
    // The rebuilt map holds the scans up to the job; those integrated since follow.
    keyframes_.integrate_since(*result.map, result.map_integrations);
    map_ = std::move(*result.map);
    rebuilt_since_frame_ = true;
  }
  return T_corrected_tracked;
}

std::optional<LoopJob> Slam::take_loop_job() {
  if (catch_up_job_) {
    std::optional<LoopJob> job = std::move(catch_up_job_);
    catch_up_job_.reset();
    return job;
  }
  if (!config_.loop_closure.background || !search_due_ || job_out_) return std::nullopt;
  search_due_ = false;
  job_out_ = true;
  return make_loop_job();
}

void Slam::apply_loop_result(LoopResult result) {
  if (result.generation != generation_) return;  // made before a resume: another graph
  const LoopClosureConfig &loops = config_.loop_closure;
  if (result.map && result.solved && result.catch_up_rounds < loops.max_catch_up_rounds &&
      keyframes_.integrations() >
          result.map_integrations + static_cast<std::size_t>(loops.max_catch_up_scans)) {
    // The worker integrates the scans tracked meanwhile, at their corrected poses.
    LoopJob job;
    job.generation = generation_;
    job.scans_since = keyframes_.scans_since(result.map_integrations, *result.solved);
    job.catch_up = std::make_shared<LoopResult>(std::move(result));
    catch_up_job_ = std::move(job);
    return;
  }
  job_out_ = false;
  const Eigen::Isometry2d T_corrected_tracked = take_result(std::move(result));
  if (!closed_since_frame_) return;
  if (relocalizer_ && rebuilt_since_frame_) search_map();  // the search follows the corrected map
  // The tracking state follows the correction: the next frame is predicted from the
  // corrected pose and registered against the corrected map.
  previous_.T_map_base = orthonormalized(T_corrected_tracked * previous_.T_map_base);
  anchor_T_map_base_ = orthonormalized(T_corrected_tracked * anchor_T_map_base_);
  if (last_mapped_) last_mapped_ = orthonormalized(T_corrected_tracked * *last_mapped_);
  for (WalkAt *walk : {&map_walk_, &map_since_keyframe_})
    walk->T_map_base = orthonormalized(T_corrected_tracked * walk->T_map_base);
  for (Points2 &scan : recent_scans_map_) scan = transformed(scan, T_corrected_tracked);
}

FrameEstimate Slam::process(const Points2 &scan_base, const std::optional<Eigen::Isometry2d> &T_odom_base,
                            std::span<const double> range_per_px_m) {
  const bool first = !started_;
  started_ = true;
  if (first && map_.empty() && !config_.localization_only) {
    FrameEstimate estimate = seed_map(scan_base);
    if (T_odom_base) set_anchor(*T_odom_base, estimate.T_map_base);
    return estimate;
  }
  // The odometry motion since the anchor (the previous frame unless odometry had a gap).
  // Without odometry the robot is predicted to keep the last frame-to-frame motion.
  Eigen::Isometry2d step = Eigen::Isometry2d::Identity();
  Eigen::Isometry2d from = previous_.T_map_base;
  Eigen::Matrix3d scale_covariance = Eigen::Matrix3d::Zero();
  if (config_.use_odometry) {
    if (!T_odom_base) {
      step = last_step_;
    } else if (anchor_T_odom_base_) {
      step = anchor_T_odom_base_->inverse() * *T_odom_base;
      from = anchor_T_map_base_;
      // The odometry's distance read with the factor learnt so far, and that factor's own
      // uncertainty along the step (map frame).
      const Eigen::Vector2d along = from.linear() * step.translation();
      const double sigma = odometry_scale_.applied_sigma();
      scale_covariance.topLeftCorner<2, 2>() = sigma * sigma * along * along.transpose();
      step.translation() *= odometry_scale_.applied();
    }
  }
  const Eigen::Isometry2d predicted = from * step;
  prediction_covariance_ = uncommitted_covariance_ + odometry_step_covariance(step) + scale_covariance;
  // In an odometry gap the motion is a guess (the last one kept up): neither a prior nor a
  // reason to reject a correction.
  predicted_by_odometry_ = config_.use_odometry && T_odom_base.has_value();

  if (lost_) return search_lost(scan_base, T_odom_base, predicted, step);

  FrameEstimate estimate;
  estimate.T_map_base = predicted;
  if (static_cast<int>(scan_base.size()) >= config_.min_scan_points)
    estimate = register_scan(scan_base, predicted, range_per_px_m);

  if (estimate.integrated && previous_failed_ && config_.optional_map_correction &&
      config_.target == RegistrationTarget::kPreviousScan) {
    const TrimmedIcpResult refined = register_trimmed_icp(
        map_.index_near(transformed(scan_base, estimate.T_map_base), registration_reach_m(scan_base)),
        scan_base, estimate.T_map_base, config_.icp);
    if (accept(refined, predicted, refined.T_model_sample, 50.0))
      estimate.T_map_base = refined.T_model_sample;
  }

  // A scan that contradicts the map or the previous scan is not added to the map, nor any
  // after it until the map is matched again: after a kidnapping they sit at the wrong pose.
  estimate.unfit = count_misfit(scan_base, estimate, predicted);
  bool in_graph = false;  // recorded as an integrated frame of the keyframe graph
  const std::size_t stored_scans = keyframes_.integrations();  // scans the graph held before this frame
  uncommitted_covariance_ = estimate.integrated ? Eigen::Matrix3d::Zero() : prediction_covariance_;
  // The tracking's uncertainty of this pose relative to the last keyframe: the same terms
  // as the published walk's, summed from that keyframe on (the next sequential edge's), from
  // the map's where the frame registered on it.
  const Eigen::Matrix3d term = frame_term(estimate, step);
  const bool on_map = estimate.integrated && estimate.attempt == Attempt::kMap;
  const WalkAt since_from =
      on_map ? map_since_keyframe_ : WalkAt{since_keyframe_covariance_, previous_.T_map_base};
  since_keyframe_covariance_ =
      carried(since_from.covariance, since_from.T_map_base, estimate.T_map_base) + term;
  if (estimate.integrated) {
    relaxation_percent_ = 0.0;
    // A frame without odometry is registered but never changes the map: along a corridor
    // the scan fits anywhere, and only odometry tells where.
    const bool odometry_gap = config_.use_odometry && !T_odom_base;
    if (!config_.localization_only && !odometry_gap && !estimate.unfit) {
      const LoopClosureConfig &loops = config_.loop_closure;
      const int revisited = loops.enabled && loops.reuse_keyframes && tied_
                                ? keyframes_.revisited(estimate.T_map_base, loops.min_path_gap_m)
                                : -1;
      estimate.mapped =
          (!last_mapped_ || (estimate.T_map_base.translation() - last_mapped_->translation()).norm() >=
                                config_.map_min_step_m) &&
          (!loops.enabled || keyframes_.has_room(estimate.T_map_base, revisited));
      if (estimate.mapped) map_.integrate(transformed(scan_base, estimate.T_map_base));
      if (revisited >= 0) {
        // A mapped place: the frame follows the keyframe it revisits, and its relation to
        // that keyframe is this registration's (the map there holds the keyframe's scans).
        // Its scan still refines the map (fused points average over every visit: on six
        // laps of the synthetic L-room, seeds 1-6, the first lap's map alone left the later
        // laps' worst frame 40 mm off on average, the refined map 29 mm), up to max_scans.
        if (estimate.mapped) {
          keyframes_.add_revisit(revisited, scan_base, estimate.T_map_base);
        } else {
          keyframes_.add_revisit(revisited, estimate.T_map_base);
        }
        since_keyframe_covariance_ = term;
        estimate.revisit = in_graph = true;
      } else if (loops.enabled && estimate.mapped) {
        estimate.T_map_base = update_graph(scan_base, estimate);
        in_graph = true;
      }
      if (estimate.mapped) last_mapped_ = estimate.T_map_base;
    }
  } else {
    relaxation_percent_ += config_.srel_relax_percent;
  }
  // In doubt the whole map is searched too: a pose it confirms ends the doubt, where the
  // tracking is or elsewhere (where the robot was carried: found before it was even declared
  // lost), and tracking goes on from it. Where nothing on the map looks like the scans (no
  // hypothesis) while they agree with each other, the robot is exploring: after a keyframe's
  // distance of that the map takes frames again.
  if (!doubt_) {
    relocalizer_.reset();
  } else {
    if (!relocalizer_) {
      walk_before_lost_ = walk_covariance_;
      walk_dof_before_lost_ = walk_dof_;
      search_map();
      unmatched_m_ = 0.0;
      broke_with_previous_ = false;
    }
    const LocalizationResult found = search_step(scan_base, T_odom_base, predicted, step);
    if (found.state == LocalizationState::kLocalized) {
      // Confirmed on the map: where the tracking is (which drifted meanwhile, placed by
      // scan-to-scan registration alone) or elsewhere (carried there).
      return found_again(scan_base, T_odom_base, found);
    } else if (misfits_ >= config_.lost_after_frames) {
      lost_ = true;
      estimate.lost = true;
    } else if (misfits_ == 0 && found.hypotheses == 0) {
      unmatched_m_ += step.translation().norm();
      if (unmatched_m_ >= config_.loop_closure.keyframes.keyframe_distance_m) doubt_ = false;
    } else {
      unmatched_m_ = 0.0;
    }
    if (!doubt_) relocalizer_.reset();
  }
  estimate.covariance = published_covariance(estimate, term, on_map);
  if (keyframes_.integrations() > stored_scans)
    keyframes_.add_scan_covariance(estimate.covariance, estimate.T_map_base);
  if (estimate.mapped) map_walk_ = {walk_covariance_, estimate.T_map_base, walk_dof_};
  if (estimate.mapped || estimate.revisit)
    map_since_keyframe_ = {since_keyframe_covariance_, estimate.T_map_base};
  return finish_frame(estimate, scan_base, T_odom_base, in_graph);
}

bool Slam::count_misfit(const Points2 &scan_base, const FrameEstimate &estimate,
                        const Eigen::Isometry2d &predicted) {
  if (config_.lost_after_frames <= 0 || !config_.use_odometry || config_.target != RegistrationTarget::kMap)
    return false;
  if (estimate.integrated && estimate.attempt == Attempt::kMap) {
    misfits_ = 0;
    doubt_ = false;
    record_agreement(scan_base, estimate.T_map_base);
    return false;
  }
  // No judgement without a scan to judge or an odometry pose to judge it at (a gap's guess),
  // nor before the run's scans have shown how much they disagree where the robot is (until
  // the map registration first places a frame: on a floor where the front-end errs more
  // than on the bundled ones, the first frames' disagreement is that, not a carrying).
  if (!predicted_by_odometry_ || static_cast<int>(scan_base.size()) < config_.min_scan_points ||
      recent_scans_map_.empty() || agreement_history_.empty())
    return doubt_;
  // The registration against the map failed. Exploring, the scan is mostly new territory:
  // the previous scan places it, and it joins the map as in the thesis. It does not when it
  // contradicts the previous scan where the odometry puts it (the view changed as no
  // motion of the robot can change it: carried off, or something right in front of the
  // camera), when its rays cross the map's walls where it is placed, or when a misfit came
  // since the map was last matched (the scans since sit at the same wrong pose). Two scans
  // contradict when the rays of either cross the other's structure (slam/ray_agreement.hpp):
  // one way alone misses a carrying into a narrower place, whose near walls stand in the
  // other's free space but hide nothing of it. A scan point within two fusion radii of
  // structure is on it (the 0.1 m the relocaliser counts), a point stands for half a fusion
  // radius either side (the map's spacing; agreement_with()), and the scans' wrong points
  // are what the scans of this run show where the map placed them (contradicts()).
  const Points2 map_points = positions_of(map_.points());
  auto consistent = [&](const Eigen::Isometry2d &T_map_base) {
    if (!within_correction(predicted, T_map_base)) return false;
    // A previous scan that was itself a misfit is no reference (taken from where no scan
    // agrees, or from inside a box in a synthetic test), nor is the whole map that stands in
    // for it after an operator's pose or a resume: the map alone judges.
    if (misfits_ == 0 && previous_is_scan_) {
      const Agreements previous = agreement_with_previous(scan_base, T_map_base);
      if (contradicts(previous.forward, Reference::kPreviousScan) ||
          contradicts(previous.backward, Reference::kPreviousScan))
        return false;
    }
    return !contradicts(agreement_with(scan_base, T_map_base, map_points), Reference::kMap);
  };
  const bool explained = consistent(estimate.T_map_base) || (map_fit_ && consistent(*map_fit_));

  misfits_ = explained ? 0 : misfits_ + 1;
  doubt_ = doubt_ || !explained;
  return doubt_;
}

Slam::Agreements Slam::agreement_with_previous(const Points2 &scan_base,
                                               const Eigen::Isometry2d &T_map_base) const {
  const Points2 &previous_map = recent_scans_map_.front();
  return {agreement_with(scan_base, T_map_base, previous_map),
          agreement_with(transformed(previous_map, previous_.T_map_base.inverse()), previous_.T_map_base,
                         transformed(scan_base, T_map_base))};
}

RayAgreement Slam::agreement_with(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                  std::span<const Point2> map_points) const {
  return ray_agreement(scan_base, T_map_base, map_points, 2.0 * config_.map.fusion_radius_m,
                       0.5 * config_.map.fusion_radius_m);
}

void Slam::record_agreement(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base) {
  if (!previous_is_scan_ || recent_scans_map_.empty()) return;
  const Agreements previous = agreement_with_previous(scan_base, T_map_base);
  // The map around the scan: the registration's own index (bounded, whatever the map's size).
  const RayAgreement on_map = agreement_with(scan_base, T_map_base, map_.index().points());
  const RayAgreement &forward = previous.forward, &backward = previous.backward;
  agreement_history_.push_front(
      {{forward.seen_through + backward.seen_through,
        forward.seen_through + forward.confirmed + backward.seen_through + backward.confirmed},
       {on_map.seen_through, on_map.seen_through + on_map.confirmed}});
  if (agreement_history_.size() > kAgreementFrames) agreement_history_.pop_back();
}

bool Slam::contradicts(const RayAgreement &agreement, Reference reference) const {
  // The share of a scan that crosses structure where the robot is, pooled over the recent
  // frames the map placed; a frame's share scatters about it binomially, its points counted
  // at the relocaliser's correlation (neighbours share errors). A misfit lies beyond three
  // standard deviations of that, and beyond the relocaliser's outlier share. Against the map
  // the share is the map's own: it also holds the wrong points of every scan it fused.
  double seen = 0.0, informative = 0.0;
  for (const AgreementTally &tally : agreement_history_) {
    seen += tally.against(reference).seen_through;
    informative += tally.against(reference).informative;
  }
  const double n = agreement.confirmed + agreement.seen_through;
  if (n <= 0.0) return false;
  const double share = informative > 0.0 ? seen / informative : 0.0;
  const double effective = std::max(1.0, n * config_.relocalizer.point_correlation);
  const double tolerance = std::max(config_.relocalizer.outlier_share,
                                    share + kMisfitSigmas * std::sqrt(share * (1.0 - share) / effective));
  return agreement.seen_through > tolerance * n;
}

void Slam::search_map() {
  relocalizer_ = std::make_unique<Relocalizer>(positions_of(map_.points()), config_.relocalizer);
}

bool Slam::breaks_with_previous(const Points2 &scan_base, const Eigen::Isometry2d &predicted) const {
  if (!predicted_by_odometry_ || !previous_is_scan_ || recent_scans_map_.empty()) return true;
  const TrimmedIcpResult fit =
      register_trimmed_icp(NearestNeighbors(recent_scans_map_.front()), scan_base, predicted, config_.icp);
  return !fit.valid || !within_correction(predicted, fit.T_model_sample) ||
         std::sqrt(fit.final_error_m2) > config_.max_rms_m;
}

LocalizationResult Slam::search_step(const Points2 &scan_base,
                                     const std::optional<Eigen::Isometry2d> &T_odom_base,
                                     const Eigen::Isometry2d &predicted, const Eigen::Isometry2d &step) {
  broke_with_previous_ = broke_with_previous_ || breaks_with_previous(scan_base, predicted);
  if (broke_with_previous_) return relocalizer_->process(scan_base, T_odom_base);
  // This frame as published when nothing places it: the walk carried here plus the step's.
  const Eigen::Matrix3d grown = predictive_covariance(
      carried(walk_covariance_, previous_.T_map_base, predicted) + frame_term(FrameEstimate{}, step),
      walk_dof_);
  const double position_variance =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(grown.topLeftCorner<2, 2>()).eigenvalues().maxCoeff();
  SearchWindow window;
  window.T_map_base = predicted;
  window.radius_m = std::max(std::sqrt(kChiSquare999ThreeDof * position_variance), config_.max_correction_m);
  window.half_angle_rad = std::min(
      std::numbers::pi, std::max(std::sqrt(kChiSquare999ThreeDof * grown(2, 2)), config_.max_correction_rad));
  return relocalizer_->process(scan_base, T_odom_base, window);
}

FrameEstimate Slam::search_lost(const Points2 &scan_base, const std::optional<Eigen::Isometry2d> &T_odom_base,
                                const Eigen::Isometry2d &predicted, const Eigen::Isometry2d &step) {
  FrameEstimate estimate;
  estimate.T_map_base = predicted;  // dead reckoning from the last tracked frame
  estimate.lost = true;
  const LocalizationResult found = search_step(scan_base, T_odom_base, predicted, step);
  if (found.state == LocalizationState::kLocalized) return found_again(scan_base, T_odom_base, found);
  estimate.covariance = published_covariance(estimate, frame_term(estimate, step), false);
  return finish_frame(estimate, scan_base, T_odom_base, false);
}

FrameEstimate Slam::found_again(const Points2 &scan_base, const std::optional<Eigen::Isometry2d> &T_odom_base,
                                const LocalizationResult &found) {
  // Tracking resumes at the confirmed pose, on the map as it is.
  relocalizer_.reset();
  lost_ = false;
  doubt_ = false;
  misfits_ = 0;
  FrameEstimate estimate;
  estimate.T_map_base = found.T_map_base;
  estimate.relocalized = estimate.integrated = true;
  estimate.attempt = Attempt::kMap;
  // The map here was built from poses as uncertain as the track was when the doubt began (the
  // walk never shrinks), and this pose adds the registration's own error to it.
  walk_covariance_ = walk_before_lost_ + found.covariance;
  walk_dof_ = walk_dof_before_lost_;
  estimate.covariance = predictive_covariance(walk_covariance_, walk_dof_);
  if (config_.localization_only) estimate.covariance += map_uncertainty_at(found.T_map_base);
  map_walk_ = {walk_before_lost_, found.T_map_base,
               walk_dof_before_lost_};  // the next frames register there too
  uncommitted_covariance_.setZero();
  since_keyframe_covariance_ = found.covariance;  // a registration against the keyframe's part of the map
  map_since_keyframe_ = {since_keyframe_covariance_, found.T_map_base};
  tied_ = false;         // until a loop closure ties the new trail
  last_mapped_.reset();  // the next frame that fits the map is integrated
  relaxation_percent_ = 0.0;
  bool in_graph = false;
  if (config_.loop_closure.enabled) {
    // Anchored to the nearest keyframe: the next keyframe's sequential edge starts there,
    // not at the keyframe the robot was carried away from.
    if (const int keyframe = keyframes_.nearest(found.T_map_base); keyframe >= 0) {
      keyframes_.add_revisit(keyframe, found.T_map_base);
      in_graph = true;
    }
  }
  // The frames since the doubt began, placed back from here by their odometry: it saw the
  // robot's own motion since the carrying, only not the carrying itself.
  if (T_odom_base) {
    for (const auto &[frame, T_odom_frame] : unplaced_)
      keyframes_.place_frame(frame,
                             orthonormalized(found.T_map_base * T_odom_base->inverse() * T_odom_frame));
  }
  unplaced_.clear();
  // The scans before the jump sit at the old poses: the whole map stands in for them.
  recent_scans_map_.assign(1, map_.index().points());
  estimate = finish_frame(estimate, scan_base, T_odom_base, in_graph);
  last_step_ = Eigen::Isometry2d::Identity();  // no motion is extrapolated across the jump
  return estimate;
}

void Slam::learn_odometry_scale(const FrameEstimate &estimate,
                                const std::optional<Eigen::Isometry2d> &T_odom_base) {
  if (!config_.odometry_scale.enabled || !config_.use_odometry || !config_.odometry_prior) return;
  // A gap, a lost or carried robot, a pose found by the search, or a loop closure that moved
  // the poses: the odometry since the last pinned frame no longer joins two comparable poses.
  if (!T_odom_base || !predicted_by_odometry_ || estimate.lost || estimate.unfit || estimate.relocalized ||
      estimate.loop_closed) {
    odometry_scale_.break_chain();
    return;
  }
  const Eigen::Isometry2d raw_step = anchor_T_odom_base_
                                         ? Eigen::Isometry2d(anchor_T_odom_base_->inverse() * *T_odom_base)
                                         : Eigen::Isometry2d::Identity();
  odometry_scale_.add_step(*T_odom_base, odometry_step_covariance(raw_step).topLeftCorner<2, 2>());
  // Pinned: placed on the map by its scan in both directions (where the pairs leave one to
  // the prior, along a corridor, the position is the odometry's own and measures nothing).
  const TrimmedIcpResult &registration = estimate.registration;
  if (estimate.integrated && estimate.attempt == Attempt::kMap && registration.unconstrained_directions == 0)
    odometry_scale_.pin(*T_odom_base, estimate.T_map_base,
                        predictive_covariance(registration).topLeftCorner<2, 2>());
}

FrameEstimate Slam::finish_frame(FrameEstimate estimate, const Points2 &scan_base,
                                 const std::optional<Eigen::Isometry2d> &T_odom_base, bool in_graph) {
  if (!in_graph) keyframes_.add_pose(estimate.T_map_base);
  estimate.trajectory_index = keyframes_.frame_count() - 1;
  if (!estimate.unfit && !estimate.lost) {
    unplaced_.clear();  // tracked (the doubt, if any, ended where the tracking is)
  } else if (T_odom_base) {
    unplaced_.emplace_back(estimate.trajectory_index, *T_odom_base);
  }
  // A background job's result applied before this frame.
  estimate.loop_closed = estimate.loop_closed || closed_since_frame_;
  estimate.map_rebuilt = estimate.map_rebuilt || rebuilt_since_frame_;
  closed_since_frame_ = rebuilt_since_frame_ = false;
  previous_failed_ = !estimate.integrated;
  learn_odometry_scale(estimate, T_odom_base);
  estimate.odometry_scale = odometry_scale_.scale();
  estimate.odometry_scale_sigma = odometry_scale_.sigma();
  estimate.odometry_scale_applied = odometry_scale_.significant();
  if (T_odom_base) set_anchor(*T_odom_base, estimate.T_map_base);
  // Extrapolated through gaps, re-made a rotation: the inverse transposes (planar_pose.hpp).
  last_step_ = orthonormalized(previous_.T_map_base.inverse() * estimate.T_map_base);
  // Thesis fig. 5.3: second_last = last every iteration, integrated or not.
  recent_scans_map_.push_front(transformed(scan_base, estimate.T_map_base));
  previous_is_scan_ = true;
  if (recent_scans_map_.size() > 3) recent_scans_map_.pop_back();
  previous_ = estimate;
  return estimate;
}

}  // namespace omnislam::slam
