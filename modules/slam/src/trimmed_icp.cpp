#include "omnislam/slam/trimmed_icp.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

namespace omnislam::slam {
namespace {

constexpr double kInlierDistanceM = 0.1;
// The pairs' residual variance is floored (an exact fit must not give them infinite weight
// against a prior): a millimetre, well below any range noise. The prior's translation
// variance is floored alike: an exact odometry step (the robot standing, its wheels still)
// must not give the prior infinite weight, whose inverse would leave the step undefined and
// the registration frozen where it started, in yaw too.
constexpr double kMinResidualVarianceM2 = 1e-6;

Eigen::Matrix2d prior_information(const Eigen::Matrix2d &translation_covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(translation_covariance);
  const Eigen::Vector2d floored = axes.eigenvalues().cwiseMax(kMinResidualVarianceM2);
  return axes.eigenvectors() * floored.cwiseInverse().asDiagonal() * axes.eigenvectors().transpose();
}

struct Pair {
  Point2 model;
  Point2 normal;  ///< model normal, zero when unknown (then the pair is point-to-point)
  Point2 sample;  ///< original (untransformed) sample point
  double residual_sq_m2;
  double weight = 1.0;   ///< relative to a point without range error (1 when unweighted)
  double tail = 1.0;     ///< the heavy-tailed factor on the fit's weight (1 without)
  double lever_m = 0.0;  ///< b: the sample point's range per pixel along the residual
};

struct Motion {
  Eigen::Isometry2d T = Eigen::Isometry2d::Identity();
  double scale = 1.0;
  [[nodiscard]] Point2 apply(const Point2 &p) const { return T.linear() * (scale * p) + T.translation(); }
};

// How the pairs are weighted: 1 / (1 + ratio b^2), b the sample point's range per pixel
// along the residual; ratio 0 weighs every pair alike (the plain fit). With tail_dof nu > 0
// the fit (not the covariance) also weighs each pair by its residual under a Student-t law
// of scale^2 s0^2 (1 + ratio b^2) (Pair::tail).
struct Weighting {
  std::span<const double> range_per_px_m;  ///< empty: no range errors known (b = 0)
  double ratio = 0.0;
  double common_m2 = 0.0;  ///< s0^2 of the residual model (the tail's scale with ratio)
  double tail_dof = 0.0;   ///< Student-t degrees of freedom of the residuals; 0: Gaussian
};

double residual_sq(const Point2 &moved, const Point2 &model, const Point2 &normal, IcpMetric metric) {
  if (metric == IcpMetric::kPointToLine && !normal.isZero()) {
    const double d = normal.dot(moved - model);
    return d * d;
  }
  return (moved - model).squaredNorm();
}

// b of sample point `p`: its range per pixel times the share of a range error that moves
// the residual (the ray's cosine to the model normal; all of it for a point-to-point pair).
double lever_m(const Point2 &p, const Motion &motion, const Point2 &normal, double range_per_px_m) {
  const double range_m = p.norm();
  if (normal.isZero() || !(range_m > 0.0)) return range_per_px_m;
  const double along = std::abs(normal.dot(motion.T.linear() * p)) / range_m;
  return along > 0.0 ? range_per_px_m * along : 0.0;  // an infinite range error across the ray moves nothing
}

// Steps 1-3 of Chetverikov 2002: pair every transformed sample point with its nearest
// model point inside dmax, sort by residual and keep the best overlap * N_p. The trimming
// stays geometric with weights too: sorted by weighted residual, a far point's wrong pair
// passes for a good one and a near point's pair is dropped (tried: sim-room-37 with more
// table tops lost 42 mm in one frame).
std::vector<Pair> trimmed_pairs(const NearestNeighbors &model, const Points2 &sample, const Motion &motion,
                                double search_radius_m, const TrimmedIcpConfig &config,
                                const Weighting &weighting) {
  const bool with_normals = config.metric == IcpMetric::kPointToLine;
  const bool with_levers = weighting.range_per_px_m.size() == sample.size();
  std::vector<Pair> pairs;
  pairs.reserve(sample.size());
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const Point2 &p = sample[i];
    const Point2 moved = motion.apply(p);
    if (const auto hit = model.nearest(moved, search_radius_m)) {
      const Point2 &m = model.points()[hit->index];
      const Point2 normal = with_normals ? model.normal(hit->index) : Point2::Zero();
      Pair pair{m, normal, p, residual_sq(moved, m, normal, config.metric)};
      if (with_levers) pair.lever_m = lever_m(p, motion, normal, weighting.range_per_px_m[i]);
      if (weighting.ratio > 0.0) {
        const double spread = 1.0 + weighting.ratio * pair.lever_m * pair.lever_m;
        pair.weight = 1.0 / spread;
        if (!(pair.weight > 0.0)) continue;  // a range unknown to within a pixel tells nothing
        if (weighting.tail_dof > 0.0) {
          const double nu = weighting.tail_dof;
          pair.tail = (nu + 1.0) / (nu + pair.residual_sq_m2 / (weighting.common_m2 * spread));
        }
      }
      pairs.push_back(pair);
    }
  }
  const auto keep = std::min(pairs.size(), static_cast<std::size_t>(config.overlap * sample.size()));
  std::nth_element(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(keep), pairs.end(),
                   [](const Pair &a, const Pair &b) { return a.residual_sq_m2 < b.residual_sq_m2; });
  pairs.resize(keep);
  return pairs;
}

// Step 5 (thesis sec. 5.1, Horn 1987, planar case): centre both sets, rotation from
// C = sum m'.p' and S = sum m' x p', optional scale, translation m_mean - s R p_mean.
Motion horn_motion(const std::vector<Pair> &pairs, bool estimate_scale) {
  Point2 model_mean = Point2::Zero(), sample_mean = Point2::Zero();
  for (const Pair &pair : pairs) {
    model_mean += pair.model;
    sample_mean += pair.sample;
  }
  model_mean /= static_cast<double>(pairs.size());
  sample_mean /= static_cast<double>(pairs.size());
  double c = 0.0, s = 0.0, sample_norm_sq = 0.0;
  for (const Pair &pair : pairs) {
    const Point2 m = pair.model - model_mean, p = pair.sample - sample_mean;
    c += m.dot(p);
    s += p.x() * m.y() - p.y() * m.x();
    sample_norm_sq += p.squaredNorm();
  }
  Motion motion;
  const Eigen::Rotation2Dd rotation(std::atan2(s, c));
  if (estimate_scale && sample_norm_sq > 0.0) motion.scale = std::hypot(c, s) / sample_norm_sq;
  motion.T.linear() = rotation.toRotationMatrix();
  motion.T.translation() = model_mean - motion.scale * (rotation * sample_mean);
  return motion;
}

// Normal equations of the residuals w.r.t. a small motion (dx, dy, dyaw) applied on the
// left of the current transform: point-to-line rows n^T [I | perp(p')], else both rows.
struct NormalEquations {
  Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
};

// One pair's share of the normal equations: J^T J and J^T r.
NormalEquations pair_terms(const Pair &pair, const Motion &motion) {
  const Point2 moved = motion.apply(pair.sample);
  Eigen::Matrix<double, 2, 3> J;
  J << 1.0, 0.0, -moved.y(), 0.0, 1.0, moved.x();
  const double w = pair.weight * pair.tail;
  if (!pair.normal.isZero()) {
    const Eigen::RowVector3d row = pair.normal.transpose() * J;
    return {w * row.transpose() * row, w * row.transpose() * pair.normal.dot(moved - pair.model)};
  }
  return {w * J.transpose() * J, w * J.transpose() * (moved - pair.model)};
}

NormalEquations normal_equations(const std::vector<Pair> &pairs, const Motion &motion) {
  NormalEquations eq;
  for (const Pair &pair : pairs) {
    const NormalEquations terms = pair_terms(pair, motion);
    eq.JtJ += terms.JtJ;
    eq.Jtr += terms.Jtr;
  }
  return eq;
}

// The left motion (dx, dy, dyaw) about the map origin from the sample origin's own motion
// u and the yaw: (dx, dy) = u - dyaw perp(t), t the sample origin in the model frame.
Eigen::Matrix3d origin_from_sample_motion(const Motion &motion) {
  const Eigen::Vector2d t = motion.T.translation();
  Eigen::Matrix3d G = Eigen::Matrix3d::Identity();
  G(0, 2) = t.y();
  G(1, 2) = -t.x();
  return G;
}

// The translations of the sample origin the pairs pin (TrimmedIcpConfig::min_constraining_pairs):
// a projector on (u, yaw) that removes the directions of u with too little information, from
// J^T J in those coordinates, whose translation block is sum w n n^T.
struct Constrained {
  Eigen::Matrix2d removed = Eigen::Matrix2d::Zero();  ///< the projector onto the removed directions of u
  int unconstrained = 0;
  [[nodiscard]] Eigen::Matrix3d projector() const {
    Eigen::Matrix3d kept = Eigen::Matrix3d::Identity();
    kept.topLeftCorner<2, 2>() -= removed;
    return kept;
  }
};
Constrained constrained_directions(const Eigen::Matrix3d &JtJ_sample, double min_pairs) {
  Constrained result;
  if (!(min_pairs > 0.0)) return result;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> information(JtJ_sample.topLeftCorner<2, 2>());
  for (int i = 0; i < 2; ++i) {
    if (information.eigenvalues()(i) >= min_pairs) continue;
    const Eigen::Vector2d v = information.eigenvectors().col(i);
    result.removed += v * v.transpose();
    ++result.unconstrained;
  }
  return result;
}

Motion point_to_line_motion(const std::vector<Pair> &pairs, const Motion &current, const PosePrior *prior,
                            double residual_variance_m2, double min_constraining_pairs) {
  const NormalEquations eq = normal_equations(pairs, current);
  Eigen::Vector3d delta;
  if (prior == nullptr) {
    delta = eq.JtJ.ldlt().solve(-eq.Jtr);
  } else {
    // Solved for the sample origin's motion and the yaw: the prior is on that origin, and
    // what the pairs do not pin of it is the prior's alone.
    const Eigen::Matrix3d G = origin_from_sample_motion(current);
    const Eigen::Matrix3d JtJ_sample = G.transpose() * eq.JtJ * G;
    const Eigen::Matrix3d P = constrained_directions(JtJ_sample, min_constraining_pairs).projector();
    Eigen::Matrix3d A = P * JtJ_sample * P / residual_variance_m2;
    Eigen::Vector3d b = -P * G.transpose() * eq.Jtr / residual_variance_m2;
    const Eigen::Matrix2d W = prior_information(prior->translation_covariance);
    const Eigen::Vector2d e = current.T.translation() - prior->T_model_sample.translation();
    A.topLeftCorner<2, 2>() += W;
    b.head<2>() -= W * e;
    delta = G * A.ldlt().solve(b);
  }
  if (!delta.allFinite()) return current;
  Eigen::Isometry2d step = Eigen::Isometry2d::Identity();
  step.linear() = Eigen::Rotation2Dd(delta.z()).toRotationMatrix();
  step.translation() = delta.head<2>();
  return {step * current.T, 1.0};
}

// A covariance of the left motion about the map origin with the prior's variance, and no
// other, along the sample origin's translations the pairs leave to it; both parts apart.
struct PriorAlong {
  Eigen::Matrix3d pairs;  ///< what the pairs pin
  Eigen::Matrix3d prior;  ///< the prior's along the rest
  [[nodiscard]] Eigen::Matrix3d sum() const { return pairs + prior; }
};
PriorAlong with_prior_along(const Eigen::Matrix3d &covariance, const Motion &motion, const Constrained &kept,
                            const PosePrior &prior) {
  const Eigen::Matrix3d G = origin_from_sample_motion(motion);
  const Eigen::Matrix3d G_inverse = G.inverse();
  const Eigen::Matrix3d P = kept.projector();
  const Eigen::Matrix3d pinned = P * G_inverse * covariance * G_inverse.transpose() * P;
  Eigen::Matrix3d held = Eigen::Matrix3d::Zero();
  held.topLeftCorner<2, 2>() = kept.removed * prior.translation_covariance * kept.removed;
  return {G * pinned * G.transpose(), G * held * G.transpose()};
}

// e: the pairs' mean squared residual, each weighted (so with weights, the residual
// variance of a point without range error).
double mean_sq(const std::vector<Pair> &pairs) {
  double sum = 0.0;
  for (const Pair &pair : pairs) sum += pair.weight * pair.residual_sq_m2;
  return pairs.empty() ? 0.0 : sum / static_cast<double>(pairs.size());
}

// The pairs' squared residuals modelled as s0^2 + k b^2 (a part every pair has, and the
// range error's, k the variance of the image error in px^2): least squares on the squares,
// each weighted by its variance under the model (2 (s0^2 + k b^2)^2 for a Gaussian
// residual), refitted from the plain mean. Returns k / s0^2, 0 when the residuals show no
// range part.
struct RangeNoise {
  double common_m2 = 0.0;  ///< s0^2
  double image_px2 = 0.0;  ///< k
  [[nodiscard]] double ratio() const { return image_px2 > 0.0 ? image_px2 / common_m2 : 0.0; }
};
RangeNoise range_noise(const std::vector<Pair> &pairs) {
  constexpr int kRefits = 4;
  double s0_sq = std::max(mean_sq(pairs), kMinResidualVarianceM2), k = 0.0;
  for (int refit = 0; refit < kRefits; ++refit) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    Eigen::Vector2d y = Eigen::Vector2d::Zero();
    for (const Pair &pair : pairs) {
      const double b_sq = pair.lever_m * pair.lever_m;
      if (!std::isfinite(b_sq)) continue;
      const double variance = s0_sq + k * b_sq;
      const Eigen::Vector2d x(1.0, b_sq);
      A += x * x.transpose() / (variance * variance);
      y += x * pair.residual_sq_m2 / (variance * variance);
    }
    if (std::abs(A.determinant()) <= 1e-12 * A.squaredNorm()) return {};
    const Eigen::Vector2d fit = A.ldlt().solve(y);
    if (!fit.allFinite() || !(fit.y() > 0.0)) return {};
    s0_sq = fit.x();
    k = fit.y();
    if (s0_sq < kMinResidualVarianceM2) {
      // The common part at its floor, the range part refitted alone.
      s0_sq = kMinResidualVarianceM2;
      k = std::max(0.0, (y.y() - A(1, 0) * s0_sq) / A(1, 1));
      if (!(k > 0.0)) return {};
    }
  }
  return {s0_sq, k};
}

// Covariance of (x, y, yaw): sigma^2 (J^T J)^-1 with sigma^2 the residual variance.
Eigen::Matrix3d covariance_of(const std::vector<Pair> &pairs, const Motion &motion, double error_m2) {
  const NormalEquations eq = normal_equations(pairs, motion);
  if (std::abs(eq.JtJ.determinant()) < 1e-12) return Eigen::Matrix3d::Identity() * 1e6;
  return std::max(error_m2, 1e-8) * eq.JtJ.inverse();
}

// A cluster's score J_g^T r_g with its residuals first divided by (I - H_gg)^(1/2), H_gg =
// J_g A^-1 J_g^T the cluster's leverage (the bias-reduced linearisation of Bell and
// McCaffrey, "CR2"): a cluster that alone pins a direction (one wall for the motion along
// its normal) has that direction's residuals fitted away, and the plain score would say it
// made no error there. In the basis of J_g's singular vectors (J_g = U S V^T) every matrix
// is 3 x 3: H_gg = U M U^T with M = S V^T A^-1 V S.
Eigen::Vector3d leverage_adjusted_score(const Eigen::Matrix3d &A_g, const Eigen::Vector3d &b_g,
                                        const Eigen::Matrix3d &A_inverse) {
  // Leverage never reaches 1 by more than this: the cluster's error along a direction only it
  // constrains is then taken as 10x what its residuals show.
  constexpr double kMinFreedom = 1e-2;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> gram(A_g);
  const double largest = gram.eigenvalues().maxCoeff();
  if (!(largest > 0.0)) return b_g;
  Eigen::Vector3d adjusted = b_g;
  // Directions J_g spans (singular values above rounding), S and V restricted to them.
  Eigen::Matrix3d V = Eigen::Matrix3d::Zero();
  Eigen::Vector3d S = Eigen::Vector3d::Zero();
  int rank = 0;
  for (int i = 0; i < 3; ++i) {
    if (gram.eigenvalues()(i) > 1e-12 * largest) {
      V.col(rank) = gram.eigenvectors().col(i);
      S(rank) = std::sqrt(gram.eigenvalues()(i));
      ++rank;
    }
  }
  const Eigen::MatrixXd Vk = V.leftCols(rank);
  const Eigen::VectorXd Sk = S.head(rank);
  const Eigen::MatrixXd M = Sk.asDiagonal() * Vk.transpose() * A_inverse * Vk * Sk.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> leverage(0.5 * (M + M.transpose()));
  Eigen::VectorXd stretch(rank);
  for (int i = 0; i < rank; ++i)
    stretch(i) = 1.0 / std::sqrt(std::max(kMinFreedom, 1.0 - leverage.eigenvalues()(i))) - 1.0;
  const Eigen::MatrixXd &Q = leverage.eigenvectors();
  // s_g = J_g^T (I + U Q D Q^T U^T) r_g = b_g + V S Q D Q^T S^-1 V^T b_g.
  adjusted += Vk * Sk.asDiagonal() * Q * stretch.asDiagonal() * Q.transpose() *
              Sk.cwiseInverse().asDiagonal() * Vk.transpose() * b_g;
  return adjusted;
}

struct RobustCovariance {
  Eigen::Matrix3d covariance;
  double dof;  ///< its degrees of freedom as an estimate (TrimmedIcpResult::covariance_dof)
};

// Cluster-robust covariance (the sandwich A^-1 B A^-1 with A = J^T J and B the sum over
// clusters of the outer product of each cluster's leverage-adjusted score): residuals are
// free to be correlated inside a cluster, and only the clusters are taken as independent.
// Clusters are bearing sectors of the sample frame.
RobustCovariance robust_covariance_of(const std::vector<Pair> &pairs, const Motion &motion, int sectors,
                                      const Eigen::Matrix3d &independent) {
  // The independent estimate has as many degrees of freedom as pairs beyond the parameters.
  const RobustCovariance fallback{independent, std::max(1.0, static_cast<double>(pairs.size()) - 3.0)};
  if (sectors < 2) return fallback;
  std::vector<Eigen::Vector3d> scores(static_cast<std::size_t>(sectors), Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> grams(static_cast<std::size_t>(sectors), Eigen::Matrix3d::Zero());
  std::vector<bool> used(static_cast<std::size_t>(sectors), false);
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  for (const Pair &pair : pairs) {
    const double bearing = std::atan2(pair.sample.y(), pair.sample.x()) + std::numbers::pi;
    const auto sector = std::min(sectors - 1, static_cast<int>(bearing / (2.0 * std::numbers::pi) * sectors));
    const NormalEquations terms = pair_terms(pair, motion);
    A += terms.JtJ;
    scores[static_cast<std::size_t>(sector)] += terms.Jtr;
    grams[static_cast<std::size_t>(sector)] += terms.JtJ;
    used[static_cast<std::size_t>(sector)] = true;
  }
  const auto clusters = static_cast<double>(std::count(used.begin(), used.end(), true));
  if (clusters < 2.0 || std::abs(A.determinant()) < 1e-12) return fallback;
  const Eigen::Matrix3d A_inverse = A.inverse();
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (std::size_t g = 0; g < scores.size(); ++g) {
    if (!used[g]) continue;
    const Eigen::Vector3d score = leverage_adjusted_score(grams[g], scores[g], A_inverse);
    B += score * score.transpose();
  }
  const Eigen::Matrix3d sandwich = A_inverse * B * A_inverse;
  // Never more confident than the independent estimate in any direction: in coordinates
  // where that one is the identity, the sandwich's variances below 1 are raised to 1.
  const Eigen::LLT<Eigen::Matrix3d> independent_factor(independent);
  if (independent_factor.info() != Eigen::Success) return fallback;
  const Eigen::Matrix3d L = independent_factor.matrixL();
  const Eigen::Matrix3d L_inverse = L.inverse();
  const Eigen::Matrix3d whitened = L_inverse * sandwich * L_inverse.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> axes(0.5 * (whitened + whitened.transpose()));
  const Eigen::Vector3d raised = axes.eigenvalues().cwiseMax(1.0);
  // The scores of the clusters sum to zero at the fit: one fewer independent one than clusters.
  return {L * axes.eigenvectors() * raised.asDiagonal() * axes.eigenvectors().transpose() * L.transpose(),
          clusters - 1.0};
}

// One run of the trimmed ICP loop from `start` under a fixed weighting.
struct Pass {
  bool valid = false;
  bool converged = false;
  int iterations = 0;
  double first_error_m2 = 0.0;
  double final_error_m2 = 0.0;   ///< e at `returned` (weighted as the pass was)
  double search_radius_m = 0.0;  ///< dmax the returned pairs were found with
  Motion returned;
  std::vector<Pair> pairs;  ///< at `returned`
};

Pass iterate(const NearestNeighbors &model, const Points2 &sample, const Motion &start,
             const TrimmedIcpConfig &config, const PosePrior *prior, const Weighting &weighting) {
  Pass pass;
  Motion current = start;
  Motion evaluated = current;  // the motion at which the last error was measured
  Motion best = current;
  double best_error = std::numeric_limits<double>::infinity();
  double best_radius = config.initial_search_radius_m;
  double previous_error = std::numeric_limits<double>::infinity();
  double search_radius = config.initial_search_radius_m;
  double evaluated_radius = search_radius;
  std::vector<Pair> pairs, best_pairs;

  for (int iteration = 0; iteration < config.max_iterations; ++iteration) {
    pairs = trimmed_pairs(model, sample, current, search_radius, config, weighting);
    if (pairs.size() < 3) break;
    evaluated = current;
    evaluated_radius = search_radius;
    const double error = mean_sq(pairs);
    if (iteration == 0) pass.first_error_m2 = error;
    pass.iterations = iteration + 1;
    pass.final_error_m2 = error;
    if (error < best_error) {
      best_error = error;
      best = current;
      best_pairs = pairs;
      best_radius = search_radius;
    }
    if (error <= config.target_error_m2 ||
        (iteration > 0 && std::abs(previous_error - error) <= config.min_relative_change * previous_error)) {
      pass.converged = true;
      break;
    }
    previous_error = error;
    // dmax shrinks to the largest distance kept in this iteration (thesis sec. 5.1 step 1).
    double largest_sq = 0.0;
    for (const Pair &pair : pairs)
      largest_sq = std::max(largest_sq, (current.apply(pair.sample) - pair.model).squaredNorm());
    search_radius = std::max(config.min_search_radius_m, std::sqrt(largest_sq));
    current = config.metric == IcpMetric::kPointToLine
                  ? point_to_line_motion(pairs, current, prior, std::max(error, kMinResidualVarianceM2),
                                         config.min_constraining_pairs)
                  : horn_motion(pairs, config.estimate_scale);
  }
  if (best_pairs.empty()) return pass;

  // The thesis keeps the global minimum and returns it when the last e is > 10% above it.
  pass.returned = evaluated;
  pass.search_radius_m = evaluated_radius;
  if (config.keep_global_minimum && pass.final_error_m2 > 1.1 * best_error) {
    pass.returned = best;
    pairs = best_pairs;
    pass.final_error_m2 = best_error;
    pass.search_radius_m = best_radius;
  }
  pass.pairs = std::move(pairs);
  pass.valid = true;
  return pass;
}

}  // namespace

TrimmedIcpResult register_trimmed_icp(const NearestNeighbors &model, const Points2 &sample,
                                      const Eigen::Isometry2d &initial_guess, const TrimmedIcpConfig &config,
                                      const PosePrior *prior, std::span<const double> sample_range_per_px_m) {
  TrimmedIcpResult result;
  result.T_model_sample = initial_guess;
  result.sample_points = sample.size();
  if (model.empty() || sample.size() < 3) return result;

  const std::span<const double> ranges =
      sample_range_per_px_m.size() == sample.size() ? sample_range_per_px_m : std::span<const double>{};
  Pass pass = iterate(model, sample, {initial_guess, 1.0}, config, prior, {ranges, 0.0});
  if (!pass.valid) return result;
  result.first_error_m2 = pass.first_error_m2;
  result.iterations = pass.iterations;
  result.converged = pass.converged;
  // Reweighted by the range-noise model the pairs themselves show, from the last fit.
  bool weighted = false;
  if (config.metric == IcpMetric::kPointToLine && !ranges.empty()) {
    for (int i = 0; i < config.range_weighting_passes; ++i) {
      const RangeNoise noise = range_noise(pass.pairs);
      const double ratio = noise.ratio();
      if (!(ratio > 0.0)) break;
      Pass next = iterate(model, sample, pass.returned, config, prior,
                          {ranges, ratio, noise.common_m2, config.residual_tail_dof});
      if (!next.valid) break;
      result.iterations += next.iterations;
      result.converged = next.converged;
      result.range_noise_ratio = ratio;
      pass = std::move(next);
      weighted = true;
    }
  }
  const Motion &returned = pass.returned;
  result.valid = true;
  result.T_model_sample = returned.T;
  result.scale = returned.scale;
  // The fit's measures stay the plain trimmed ones (what the acceptance tests judge).
  result.final_error_m2 = pass.final_error_m2;
  result.kept_pairs = pass.pairs.size();
  if (weighted) {
    const std::vector<Pair> plain = trimmed_pairs(model, sample, returned, pass.search_radius_m, config, {});
    result.final_error_m2 = mean_sq(plain);
    result.kept_pairs = plain.size();
  }
  result.srel_percent = result.first_error_m2 > 0.0
                            ? 100.0 * (result.first_error_m2 - result.final_error_m2) / result.first_error_m2
                            : 0.0;
  std::size_t inliers = 0;
  for (const Point2 &p : sample) inliers += model.nearest(returned.apply(p), kInlierDistanceM) ? 1 : 0;
  result.inlier_share = static_cast<double>(inliers) / static_cast<double>(sample.size());
  // The covariance from the pairs as weighted by their range errors: a pair's residual
  // variance is e / weight. Without the heavy tail's factor (it reweighs residuals, it is no
  // information), but with what the Student-t fit gains over least squares when the
  // residuals follow that law: its covariance is sigma^2 (nu + 3) / (nu + 1) (J^T J)^-1 with
  // sigma^2 the law's scale, e (nu - 2) / nu for e its variance (nu > 2; 0.7 e for nu 4).
  const double nu = config.residual_tail_dof;
  const double efficiency = weighted && nu > 2.0 ? (nu + 3.0) * (nu - 2.0) / ((nu + 1.0) * nu) : 1.0;
  for (Pair &pair : pass.pairs) pair.tail = 1.0;
  result.covariance = covariance_of(pass.pairs, returned, efficiency * pass.final_error_m2);
  const RobustCovariance robust =
      robust_covariance_of(pass.pairs, returned, config.covariance_sectors, result.covariance);
  result.robust_covariance = robust.covariance;
  result.covariance_dof = robust.dof;
  if (prior != nullptr && config.metric == IcpMetric::kPointToLine) {
    const Eigen::Matrix3d G = origin_from_sample_motion(returned);
    const Constrained kept = constrained_directions(
        G.transpose() * normal_equations(pass.pairs, returned).JtJ * G, config.min_constraining_pairs);
    result.unconstrained_directions = kept.unconstrained;
    if (kept.unconstrained > 0) {
      result.covariance = with_prior_along(result.covariance, returned, kept, *prior).sum();
      const PriorAlong robust_parts = with_prior_along(result.robust_covariance, returned, kept, *prior);
      result.robust_covariance = robust_parts.sum();
      // The prior's part is a model's (infinitely many degrees of freedom): Welch and
      // Satterthwaite over the two, sized by their position variance, as the SLAM's walk is.
      const double pinned = robust_parts.pairs.topLeftCorner<2, 2>().trace();
      const double total = result.robust_covariance.topLeftCorner<2, 2>().trace();
      if (pinned > 0.0) result.covariance_dof *= (total * total) / (pinned * pinned);
    }
  }
  return result;
}

Eigen::Matrix3d predictive_covariance(const Eigen::Matrix3d &estimate, double dof) {
  if (!std::isfinite(dof)) return estimate;
  const double nu = std::max(dof, kMinPredictiveDof);
  return estimate * (nu / (nu - 2.0));
}

}  // namespace omnislam::slam
