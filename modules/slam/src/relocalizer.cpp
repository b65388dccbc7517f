#include "omnislam/slam/relocalizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {

namespace {

CorrelativeMatcherConfig coarse(double resolution_m) {
  CorrelativeMatcherConfig config;
  config.resolution_m = config.sigma_m = config.scan_voxel_m = resolution_m;
  return config;
}

}  // namespace

Relocalizer::Relocalizer(const Points2 &map_points, RelocalizerConfig config)
    : config_(config),
      matcher_(map_points, config.matcher),
      search_matcher_(map_points, coarse(config.search_resolution_m)),
      map_index_(map_points) {}

void Relocalizer::reset() {
  hypotheses_.clear();
  last_T_odom_base_.reset();
  localized_.reset();
}

bool Relocalizer::same_pose(const Eigen::Isometry2d &a, const Eigen::Isometry2d &b) const {
  return (a.translation() - b.translation()).norm() <= config_.distinct_m &&
         std::abs(std::remainder(yaw_rad_of(a) - yaw_rad_of(b), 2.0 * std::numbers::pi)) <=
             config_.distinct_rad;
}

double Relocalizer::log_likelihood(const Points2 &thinned, const Eigen::Isometry2d &T_map_base) const {
  const double reach_m = 2.0 * matcher_.config().sigma_m;
  const auto explained =
      static_cast<double>(std::count_if(thinned.begin(), thinned.end(), [&](const Point2 &p) {
        return map_index_.nearest(T_map_base * p, reach_m).has_value();
      }));
  return config_.point_correlation * (static_cast<double>(thinned.size()) - explained) *
         std::log(config_.outlier_share);
}

bool Relocalizer::admissible(double score, double best_score) const {
  return score >= config_.min_score && score >= config_.relative_score * best_score;
}

double Relocalizer::decision_margin(std::size_t competitors) const {
  return std::log((1.0 - config_.error_rate) / config_.error_rate) +
         std::log(static_cast<double>(std::max<std::size_t>(competitors, 1)));
}

std::optional<TrimmedIcpResult> Relocalizer::refine(const Points2 &scan_base,
                                                    const Eigen::Isometry2d &guess) const {
  const TrimmedIcpResult fit = register_trimmed_icp(map_index_, scan_base, guess, config_.icp);
  if (!fit.valid || std::sqrt(fit.final_error_m2) > config_.max_rms_m ||
      fit.inlier_share < config_.min_inlier_share)
    return std::nullopt;
  return fit;
}

std::vector<Relocalizer::Hypothesis> Relocalizer::rivals(const Points2 &scan_base, const Points2 &thinned,
                                                         const std::vector<PoseCandidate> &candidates,
                                                         double candidates_best, const Hypothesis &survivor,
                                                         double margin) const {
  const double own = log_likelihood(thinned, survivor.T_map_base);
  std::vector<Hypothesis> found;
  const auto known = [&](const Eigen::Isometry2d &pose) {
    return same_pose(pose, survivor.T_map_base) ||
           std::any_of(found.begin(), found.end(),
                       [&](const Hypothesis &h) { return same_pose(h.T_map_base, pose); });
  };
  for (const PoseCandidate &candidate : candidates) {
    if (known(candidate.T_map_base)) continue;
    const auto refined = refine(scan_base, candidate.T_map_base);
    if (!refined || known(refined->T_model_sample)) continue;
    const double score = matcher_.score(scan_base, refined->T_model_sample);
    if (!admissible(score, candidates_best)) continue;
    const double behind = own - log_likelihood(thinned, refined->T_model_sample);
    if (behind > margin) continue;
    found.push_back(
        {refined->T_model_sample, predictive_covariance(*refined), score, std::max(behind, 0.0), 1});
  }
  return found;
}

LocalizationResult Relocalizer::process(const Points2 &scan_base,
                                        const std::optional<Eigen::Isometry2d> &T_odom_base,
                                        const std::optional<SearchWindow> &window) {
  // 1. Carry every hypothesis by the odometry motion since the last frame.
  Eigen::Isometry2d motion = Eigen::Isometry2d::Identity();
  if (T_odom_base && last_T_odom_base_) motion = last_T_odom_base_->inverse() * *T_odom_base;
  if (T_odom_base) last_T_odom_base_ = T_odom_base;
  for (Hypothesis &hypothesis : hypotheses_) hypothesis.T_map_base = hypothesis.T_map_base * motion;

  LocalizationResult result;
  if (localized_) {
    // Tracking: refined where the scan fits, else carried by odometry.
    localized_->T_map_base = localized_->T_map_base * motion;
    if (static_cast<int>(scan_base.size()) >= config_.min_scan_points) {
      if (const auto refined = refine(scan_base, localized_->T_map_base)) {
        localized_->T_map_base = refined->T_model_sample;
        localized_->covariance = predictive_covariance(*refined);
      }
    }
    result.state = LocalizationState::kLocalized;
    result.T_map_base = localized_->T_map_base;
    result.covariance = localized_->covariance;
    result.hypotheses = 1;
    result.best_score = matcher_.score(scan_base, localized_->T_map_base);
    return result;
  }
  if (static_cast<int>(scan_base.size()) < config_.min_scan_points) {
    result.hypotheses = static_cast<int>(hypotheses_.size());
    return result;
  }

  // 2. Search the map (or the window) for every pose that explains the scan nearly as well
  //    as the best.
  const std::vector<PoseCandidate> candidates = search_matcher_.search(
      scan_base, config_.min_score, config_.relative_score, config_.distinct_m, config_.distinct_rad, window);
  result.searched_poses = static_cast<int>(candidates.size());
  double candidates_best = 0.0;
  for (const PoseCandidate &candidate : candidates)
    candidates_best = std::max(candidates_best, candidate.score);
  double best = candidates_best;                        // ... and of the hypotheses kept (reported)
  const Points2 thinned = matcher_.thinned(scan_base);  // what the likelihoods count

  // 3. A tracked hypothesis survives where its refined pose still explains the scan. Two
  //    that the refinement brings to one place (along a corridor, where ICP slides) are one
  //    hypothesis from then on: the one with the better record (visited first) stays.
  std::stable_sort(hypotheses_.begin(), hypotheses_.end(),
                   [](const Hypothesis &a, const Hypothesis &b) { return a.deficit < b.deficit; });
  std::vector<Hypothesis> alive;
  std::vector<double> frame_log_likelihood;
  for (Hypothesis hypothesis : hypotheses_) {
    const auto refined = refine(scan_base, hypothesis.T_map_base);
    if (!refined) continue;
    if (std::any_of(alive.begin(), alive.end(), [&](const Hypothesis &kept) {
          return same_pose(kept.T_map_base, refined->T_model_sample);
        }))
      continue;
    hypothesis.T_map_base = refined->T_model_sample;
    hypothesis.covariance = predictive_covariance(*refined);
    hypothesis.score = matcher_.score(scan_base, hypothesis.T_map_base);
    if (hypothesis.score < config_.min_score) continue;
    ++hypothesis.frames;
    alive.push_back(hypothesis);
    frame_log_likelihood.push_back(log_likelihood(thinned, hypothesis.T_map_base));
  }
  // 4. Every other candidate is a new hypothesis, with no history, unless the coarse grid
  //    already puts it out of the running (no refinement for those: in a building of alike
  //    rooms most candidates are). A candidate at a hypothesis's place is that hypothesis:
  //    it moves there when that explains the scan better (a hypothesis carried along a
  //    corridor slides where the scan cannot hold it; the search finds the place again).
  const double margin = decision_margin(candidates.size() + hypotheses_.size());
  std::vector<double> coarse_log_likelihood;
  double coarse_best = -std::numeric_limits<double>::infinity();
  for (const PoseCandidate &candidate : candidates) {
    coarse_log_likelihood.push_back(
        config_.point_correlation *
        search_matcher_.log_likelihood(scan_base, candidate.T_map_base, config_.outlier_share));
    coarse_best = std::max(coarse_best, coarse_log_likelihood.back());
  }
  const std::size_t tracked = alive.size();
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const PoseCandidate &candidate = candidates[c];
    if (coarse_best - coarse_log_likelihood[c] > margin) continue;
    const auto refined = refine(scan_base, candidate.T_map_base);
    if (!refined) continue;
    const Eigen::Isometry2d &pose = refined->T_model_sample;
    const double score = matcher_.score(scan_base, pose);
    const double likelihood = log_likelihood(thinned, pose);
    const auto known = std::find_if(alive.begin(), alive.end(), [&](const Hypothesis &h) {
      return same_pose(h.T_map_base, pose) || same_pose(h.T_map_base, candidate.T_map_base);
    });
    if (known != alive.end()) {
      const auto i = static_cast<std::size_t>(known - alive.begin());
      if (likelihood > frame_log_likelihood[i] ||
          (likelihood == frame_log_likelihood[i] && score > known->score)) {
        known->T_map_base = pose;
        known->covariance = predictive_covariance(*refined);
        known->score = score;
        frame_log_likelihood[i] = likelihood;
      }
      continue;
    }
    if (!admissible(score, candidates_best)) continue;
    alive.push_back({pose, predictive_covariance(*refined), score, 0.0, 1});
    frame_log_likelihood.push_back(likelihood);
  }
  // Each hypothesis falls behind the frame's best by what this frame says (a new one: by
  // this frame alone); the leader is at zero, and who trails by the decision margin is out.
  double frame_best = -std::numeric_limits<double>::infinity();
  for (const double l : frame_log_likelihood) frame_best = std::max(frame_best, l);
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < alive.size(); ++i) {
    alive[i].deficit = (i < tracked ? alive[i].deficit : 0.0) + frame_best - frame_log_likelihood[i];
    least = std::min(least, alive[i].deficit);
  }
  hypotheses_.clear();
  for (Hypothesis &hypothesis : alive) {
    hypothesis.deficit -= least;
    best = std::max(best, hypothesis.score);
    if (hypothesis.deficit <= margin) hypotheses_.push_back(hypothesis);
  }

  // 5. Localized when one hypothesis alone has held for confirm_frames frames, and no
  //    other pose explains this frame's scan within the margin: the coarse grid above
  //    left candidates unrefined, among them at times the true pose beside a wrong
  //    corridor; before a pose is reported they are all refined. Those that pass join
  //    as hypotheses, and the confirmation waits.
  const auto confirmable = [&] {
    return hypotheses_.size() == 1 && hypotheses_.front().frames >= config_.confirm_frames;
  };
  if (confirmable()) {
    for (Hypothesis &rival :
         rivals(scan_base, thinned, candidates, candidates_best, hypotheses_.front(), margin))
      hypotheses_.push_back(rival);
  }
  result.hypotheses = static_cast<int>(hypotheses_.size());
  result.best_score = best;
  if (confirmable()) {
    localized_ = hypotheses_.front();
    result.state = LocalizationState::kLocalized;
    result.T_map_base = localized_->T_map_base;
    result.covariance = localized_->covariance;
  }
  return result;
}

}  // namespace omnislam::slam
