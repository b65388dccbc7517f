#include "omnislam/slam/loop_closure.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_set>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

// A likelihood field over the candidate's submap: each cell holds exp(-d^2 / 2 sigma^2)
// of its distance d to the nearest submap point (sigma = one cell), so a pose's score is
// the mean over the scan's points (Olson 2009, correlative scan matching).
class ScoreGrid {
 public:
  ScoreGrid(const Points2 &points, double resolution_m, double margin_m) : resolution_m_(resolution_m) {
    Point2 low = Point2::Constant(std::numeric_limits<double>::infinity());
    Point2 high = -low;
    for (const Point2 &p : points) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
    origin_ = low.array() - margin_m;
    width_ = static_cast<int>(std::ceil((high.x() - low.x() + 2.0 * margin_m) / resolution_m)) + 1;
    height_ = static_cast<int>(std::ceil((high.y() - low.y() + 2.0 * margin_m) / resolution_m)) + 1;
    values_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0.0f);
    constexpr int kReach = 3;  // cells: the likelihood is negligible (< 1%) beyond 3 sigma
    for (const Point2 &p : points) {
      const int cx = cell(p.x() - origin_.x()), cy = cell(p.y() - origin_.y());
      for (int y = std::max(cy - kReach, 0); y <= std::min(cy + kReach, height_ - 1); ++y) {
        for (int x = std::max(cx - kReach, 0); x <= std::min(cx + kReach, width_ - 1); ++x) {
          const Point2 centre = origin_ + resolution_m * Point2(x, y);
          const double d2 = (centre - p).squaredNorm() / (resolution_m * resolution_m);
          float &value = values_[index(x, y)];
          value = std::max(value, static_cast<float>(std::exp(-0.5 * d2)));
        }
      }
    }
  }

  /// The grid whose cell (x, y) holds the largest value of this one's cells x..x+block-1,
  /// y..y+block-1: summed over a scan's points it bounds the score of every pose whose
  /// offset lies in that block of cells (Olson 2009's multi-resolution bound).
  [[nodiscard]] ScoreGrid pooled(int block) const {
    ScoreGrid out = *this;
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        float value = 0.0f;
        for (int dy = 0; dy < block && y + dy < height_; ++dy)
          for (int dx = 0; dx < block && x + dx < width_; ++dx)
            value = std::max(value, values_[index(x + dx, y + dy)]);
        out.values_[index(x, y)] = value;
      }
    }
    return out;
  }

  /// The cell of a point (may lie outside the grid).
  [[nodiscard]] Eigen::Vector2i cell_of(const Point2 &p) const {
    return {cell(p.x() - origin_.x()), cell(p.y() - origin_.y())};
  }
  /// The value of a cell; 0 outside the grid.
  [[nodiscard]] double at(int x, int y) const {
    if (static_cast<unsigned>(x) >= static_cast<unsigned>(width_) ||
        static_cast<unsigned>(y) >= static_cast<unsigned>(height_))
      return 0.0;
    return values_[index(x, y)];
  }

 private:
  [[nodiscard]] int cell(double offset_m) const {
    return static_cast<int>(std::floor(offset_m / resolution_m_ + 0.5));
  }
  [[nodiscard]] std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }

  double resolution_m_;
  Point2 origin_;
  int width_ = 0;
  int height_ = 0;
  std::vector<float> values_;
};

// One point per cell_m square (the first one): overlapping scans of a submap see the same
// walls many times, and the match needs each wall once.
Points2 voxel_filtered(const Points2 &points, double cell_m) {
  std::unordered_set<std::uint64_t> seen;
  Points2 kept;
  for (const Point2 &p : points) {
    const auto x = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(p.x() / cell_m)));
    const auto y = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(p.y() / cell_m)));
    if (seen.insert((static_cast<std::uint64_t>(x) << 32) | y).second) kept.push_back(p);
  }
  return kept;
}

Points2 subsampled(const Points2 &points, int max_points) {
  if (static_cast<int>(points.size()) <= max_points) return points;
  Points2 out;
  const double step = static_cast<double>(points.size()) / max_points;
  for (int i = 0; i < max_points; ++i) out.push_back(points[static_cast<std::size_t>(i * step)]);
  return out;
}

bool distinct(const Eigen::Isometry2d &a, const Eigen::Isometry2d &b, double distance_m, double angle_rad) {
  const Eigen::Isometry2d d = a.inverse() * b;
  return d.translation().norm() > distance_m || std::abs(yaw_rad_of(d)) > angle_rad;
}

// Share of the fit's position information along its weakest direction: the smallest
// eigenvalue of the marginal (x, y) information J^T J per pair. Unit normals give a trace
// of one per pair, so a corridor (all normals across it) scores ~0 and a corner ~0.5.
double weak_direction_share(const TrimmedIcpResult &r) {
  if (r.kept_pairs == 0) return 0.0;
  const double sigma2 = std::max(r.final_error_m2, 1e-8);  // as trimmed_icp's covariance
  const Eigen::Matrix2d covariance_xy = r.covariance.topLeftCorner<2, 2>();
  if (!(std::abs(covariance_xy.determinant()) > 0.0)) return 0.0;
  const Eigen::Matrix2d information_xy = sigma2 * covariance_xy.inverse();
  const double weakest =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(information_xy).eigenvalues().minCoeff();
  return weakest / static_cast<double>(r.kept_pairs);
}

}  // namespace

LoopMatch match_keyframes(const Points2 &candidate_scans, const Points2 &current_scans,
                          const Eigen::Isometry2d &guess, double window_m, double window_rad,
                          const LoopClosureConfig &config, const TrimmedIcpConfig &icp) {
  LoopMatch match;
  // Half a grid cell keeps the walls' shape for ICP at a cost that follows the submap's
  // extent, not how many scans overlap in it.
  const Points2 candidate_points = voxel_filtered(candidate_scans, 0.5 * config.grid_resolution_m);
  const Points2 current_points = voxel_filtered(current_scans, 0.5 * config.grid_resolution_m);
  if (candidate_points.size() < 3 || current_points.size() < 3) return match;

  // Coarse: every pose of the grid (yaw about the current keyframe, then x, y in the
  // candidate's frame) scored on the likelihood field.
  const double resolution = config.grid_resolution_m;
  const ScoreGrid grid(candidate_points, resolution, window_m + resolution);
  const Points2 sample = subsampled(current_points, config.max_sample_points);
  double farthest_m = 1.0;
  for (const Point2 &p : sample) farthest_m = std::max(farthest_m, p.norm());
  const double yaw_step = resolution / farthest_m;  // the farthest point moves one cell
  const int yaw_steps = static_cast<int>(std::ceil(window_rad / yaw_step));
  const int xy_steps = static_cast<int>(std::ceil(window_m / resolution));
  const double guess_yaw = yaw_rad_of(guess);
  const int side = 2 * xy_steps + 1;
  // Scores indexed [yaw][y][x]; per yaw the points' cells are found once, and a shift of
  // the pose by whole cells is a shift of those indices.
  // Branch and bound over blocks of kBlock x kBlock offsets: a block's bound (the pooled
  // grid) is computed for every yaw, and its poses are scored only while the bound could
  // still beat the best score found or reach ambiguity_ratio of it. A pose never scored
  // (-1) is thus below both, and cannot change the best pose or the ambiguity test.
  constexpr int kBlock = 4;
  const ScoreGrid bound_grid = grid.pooled(kBlock);
  const int blocks = (side + kBlock - 1) / kBlock;
  std::vector<float> scores(static_cast<std::size_t>((2 * yaw_steps + 1) * side * side), -1.0f);
  std::vector<std::vector<Eigen::Vector2i>> cells(static_cast<std::size_t>(2 * yaw_steps + 1));
  auto at = [&](int a, int iy, int ix) -> float & {
    return scores[static_cast<std::size_t>(((a + yaw_steps) * side + iy + xy_steps) * side + ix + xy_steps)];
  };
  struct Block {
    float bound;
    int a, by, bx;
  };
  std::vector<Block> bounds;
  const double n = static_cast<double>(sample.size());
  for (int a = -yaw_steps; a <= yaw_steps; ++a) {
    const Eigen::Rotation2Dd R(guess_yaw + a * yaw_step);
    std::vector<Eigen::Vector2i> &turned = cells[static_cast<std::size_t>(a + yaw_steps)];
    for (const Point2 &p : sample) turned.push_back(grid.cell_of(R * p + guess.translation()));
    for (int by = 0; by < blocks; ++by) {
      for (int bx = 0; bx < blocks; ++bx) {
        double sum = 0.0;
        for (const Eigen::Vector2i &c : turned)
          sum += bound_grid.at(c.x() - xy_steps + bx * kBlock, c.y() - xy_steps + by * kBlock);
        bounds.push_back({static_cast<float>(sum / n), a, by, bx});
      }
    }
  }
  std::sort(bounds.begin(), bounds.end(), [](const Block &l, const Block &r) { return l.bound > r.bound; });
  double best_so_far = 0.0;
  for (const Block &b : bounds) {
    if (b.bound < config.ambiguity_ratio * best_so_far) break;
    const std::vector<Eigen::Vector2i> &turned = cells[static_cast<std::size_t>(b.a + yaw_steps)];
    for (int iy = -xy_steps + b.by * kBlock; iy < -xy_steps + (b.by + 1) * kBlock && iy <= xy_steps; ++iy) {
      for (int ix = -xy_steps + b.bx * kBlock; ix < -xy_steps + (b.bx + 1) * kBlock && ix <= xy_steps; ++ix) {
        double sum = 0.0;
        for (const Eigen::Vector2i &c : turned) sum += grid.at(c.x() + ix, c.y() + iy);
        at(b.a, iy, ix) = static_cast<float>(sum / n);
        best_so_far = std::max(best_so_far, sum / n);
      }
    }
  }
  const auto best_at = std::max_element(scores.begin(), scores.end()) - scores.begin();
  const int best_ix = static_cast<int>(best_at % side) - xy_steps;
  const int best_iy = static_cast<int>((best_at / side) % side) - xy_steps;
  const int best_a = static_cast<int>(best_at / (side * side)) - yaw_steps;
  match.score = scores[static_cast<std::size_t>(best_at)];
  // The best pose more than distinct_m or distinct_rad away from the best one.
  for (int a = -yaw_steps; a <= yaw_steps; ++a) {
    const bool turned_away = std::abs(a - best_a) * yaw_step > config.distinct_rad;
    for (int iy = -xy_steps; iy <= xy_steps; ++iy) {
      for (int ix = -xy_steps; ix <= xy_steps; ++ix) {
        if (turned_away || std::hypot(ix - best_ix, iy - best_iy) * resolution > config.distinct_m)
          match.second_score = std::max(match.second_score, static_cast<double>(at(a, iy, ix)));
      }
    }
  }
  const Eigen::Isometry2d coarse =
      planar_pose(guess.translation().x() + best_ix * resolution,
                  guess.translation().y() + best_iy * resolution, guess_yaw + best_a * yaw_step);
  match.T_candidate_current = coarse;
  if (match.score < config.min_score) {
    match.status = LoopStatus::kLowScore;
    return match;
  }
  if (match.second_score >= config.ambiguity_ratio * match.score) {
    match.status = LoopStatus::kAmbiguous;
    return match;
  }

  // Fine: the project's Trimmed ICP from the coarse pose, then the acceptance checks.
  const NearestNeighbors model(candidate_points);
  match.registration = register_trimmed_icp(model, current_points, coarse, icp);
  const TrimmedIcpResult &r = match.registration;
  match.T_candidate_current = r.T_model_sample;
  if (!r.valid || std::sqrt(r.final_error_m2) > config.max_rms_m ||
      distinct(coarse, r.T_model_sample, config.distinct_m, config.distinct_rad)) {
    match.status = LoopStatus::kBadFit;
  } else if (r.inlier_share < config.min_overlap) {
    match.status = LoopStatus::kSmallOverlap;
  } else if (weak_direction_share(r) < config.min_weak_direction_share) {
    match.status = LoopStatus::kDegenerate;
  } else {
    match.status = LoopStatus::kAccepted;
  }
  const Eigen::Vector3d floor(config.loop_floor_xy_m * config.loop_floor_xy_m,
                              config.loop_floor_xy_m * config.loop_floor_xy_m,
                              config.loop_floor_yaw_rad * config.loop_floor_yaw_rad);
  match.covariance = r.covariance + Eigen::Matrix3d(floor.asDiagonal());
  return match;
}

LoopMatch search_loop(const KeyframeGraph &graph, const LoopClosureConfig &config,
                      const TrimmedIcpConfig &icp, const std::optional<LoopMatch> &last_loop) {
  LoopMatch none;
  const int current = graph.last();
  if (current < 1) return none;
  const std::vector<Keyframe> &keyframes = graph.keyframes();
  const Keyframe &now = keyframes.back();
  const KeyframeConfig &drift = config.keyframes;

  // Candidates: far back along the path, near enough that the current pose's drift-grown
  // uncertainty (3 sigma, linear in the path gap) reaches them; the nearest first.
  struct Candidate {
    int keyframe;
    double distance_m, window_m, window_rad;
  };
  std::vector<Candidate> candidates;
  for (int k = 0; k < current; ++k) {
    const Keyframe &old = keyframes[static_cast<std::size_t>(k)];
    const double gap_m = now.path_m - old.path_m;
    if (gap_m < config.min_path_gap_m) continue;
    double drift_path_m = gap_m;
    if (last_loop) {
      const auto path_of = [&](int k) { return keyframes[static_cast<std::size_t>(k)].path_m; };
      drift_path_m = std::min(drift_path_m, std::abs(old.path_m - path_of(last_loop->candidate)) +
                                                now.path_m - path_of(last_loop->current));
    }
    const double window_m =
        std::min(3.0 * (drift.edge_floor_xy_m + drift.drift_per_m * drift_path_m), config.max_window_m);
    const double window_rad = std::min(
        3.0 * (drift.edge_floor_yaw_rad + drift.drift_yaw_per_m * drift_path_m), config.max_window_rad);
    const double distance_m = (now.T_map_keyframe.translation() - old.T_map_keyframe.translation()).norm();
    if (distance_m <= config.max_candidate_distance_m + window_m)
      candidates.push_back({k, distance_m, window_m, window_rad});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate &a, const Candidate &b) { return a.distance_m < b.distance_m; });
  if (static_cast<int>(candidates.size()) > config.max_candidates)
    candidates.resize(static_cast<std::size_t>(config.max_candidates));
  if (candidates.empty()) return none;

  const Points2 current_points = graph.submap(current, config.submap_path_m, now.path_m);
  std::vector<LoopMatch> matches;
  for (const Candidate &c : candidates) {
    const Keyframe &old = keyframes[static_cast<std::size_t>(c.keyframe)];
    const Points2 candidate_points =
        graph.submap(c.keyframe, config.submap_path_m, now.path_m - config.min_path_gap_m);
    LoopMatch match =
        match_keyframes(candidate_points, current_points, old.T_map_keyframe.inverse() * now.T_map_keyframe,
                        c.window_m, c.window_rad, config, icp);
    match.candidate = c.keyframe;
    match.current = current;
    matches.push_back(match);
  }
  // The best-scoring hypothesis; another candidate that places the current keyframe
  // elsewhere with a comparable score makes it ambiguous.
  const auto best =
      std::max_element(matches.begin(), matches.end(), [](const LoopMatch &a, const LoopMatch &b) {
        const bool a_ok = a.status == LoopStatus::kAccepted, b_ok = b.status == LoopStatus::kAccepted;
        return a_ok != b_ok ? b_ok : a.score < b.score;
      });
  LoopMatch chosen = *best;
  if (chosen.status != LoopStatus::kAccepted) return chosen;
  const auto placed = [&](const LoopMatch &m) {
    return keyframes[static_cast<std::size_t>(m.candidate)].T_map_keyframe * m.T_candidate_current;
  };
  for (const LoopMatch &other : matches) {
    if (&other == &*best || other.status == LoopStatus::kLowScore) continue;
    if (other.score >= config.ambiguity_ratio * chosen.score &&
        distinct(placed(chosen), placed(other), config.distinct_m, config.distinct_rad)) {
      chosen.status = LoopStatus::kAmbiguous;
      chosen.second_score = std::max(chosen.second_score, other.score);
    }
  }
  return chosen;
}

bool agree(const KeyframeGraph &graph, const LoopMatch &earlier, const LoopMatch &later,
           const LoopClosureConfig &config) {
  const auto pose = [&](int k) { return graph.keyframes()[static_cast<std::size_t>(k)].T_map_keyframe; };
  // The motion between the two keyframes as the loops place them, against the tracking's.
  const Eigen::Isometry2d placed_earlier = pose(earlier.candidate) * earlier.T_candidate_current;
  const Eigen::Isometry2d placed_later = pose(later.candidate) * later.T_candidate_current;
  const Eigen::Isometry2d tracked = pose(earlier.current).inverse() * pose(later.current);
  return !distinct(placed_earlier.inverse() * placed_later, tracked, config.agreement_m,
                   config.agreement_rad);
}

}  // namespace omnislam::slam
