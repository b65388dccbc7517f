#include "omnislam/slam/correlative_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <unordered_set>

#include "omnislam/slam/planar_pose.hpp"

namespace omnislam::slam {
namespace {

// Blocks of up to 2^7 = 128 cells (6.4 m at 0.05 m) per side: a room-sized map has a few
// root blocks per yaw, a building floor a few hundred.
constexpr int kLevels = 8;
// A point's score is negligible beyond three fall-off lengths.
constexpr double kKernelSigmas = 3.0;

struct Node {
  int angle = 0;
  int x = 0;  ///< first translation of the block, cells
  int y = 0;
  int level = 0;
  double bound = 0.0;
};

}  // namespace

CorrelativeMatcher::CorrelativeMatcher(const Points2 &map_points, CorrelativeMatcherConfig config)
    : config_(config) {
  if (map_points.empty()) return;
  const double resolution = config_.resolution_m;
  const int kernel = static_cast<int>(std::ceil(kKernelSigmas * config_.sigma_m / resolution));
  Eigen::Vector2d low = map_points.front(), high = map_points.front();
  for (const Point2 &p : map_points) low = low.cwiseMin(p), high = high.cwiseMax(p);
  origin_m_ = low - Eigen::Vector2d::Constant((kernel + 1) * resolution);
  width_ = static_cast<int>(std::ceil((high.x() - origin_m_.x()) / resolution)) + kernel + 2;
  height_ = static_cast<int>(std::ceil((high.y() - origin_m_.y()) / resolution)) + kernel + 2;
  padding_ = (1 << (kLevels - 1)) - 1;
  stride_ = width_ + padding_;
  const std::size_t cells = static_cast<std::size_t>(stride_) * static_cast<std::size_t>(height_ + padding_);

  // Level 0: each cell's score is that of its centre against the nearest map point.
  std::vector<float> likelihood(cells, 0.0f);
  const double inverse_two_sigma_sq = 1.0 / (2.0 * config_.sigma_m * config_.sigma_m);
  for (const Point2 &p : map_points) {
    const Eigen::Vector2d cell = (p - origin_m_) / resolution;
    const int cx = static_cast<int>(std::floor(cell.x())), cy = static_cast<int>(std::floor(cell.y()));
    for (int y = cy - kernel; y <= cy + kernel; ++y) {
      for (int x = cx - kernel; x <= cx + kernel; ++x) {
        if (x < 0 || y < 0 || x >= width_ || y >= height_) continue;
        const Eigen::Vector2d centre = origin_m_ + resolution * Eigen::Vector2d(x + 0.5, y + 0.5);
        const auto value = static_cast<float>(std::exp(-(centre - p).squaredNorm() * inverse_two_sigma_sq));
        float &stored =
            likelihood[static_cast<std::size_t>(y + padding_) * static_cast<std::size_t>(stride_) +
                       static_cast<std::size_t>(x + padding_)];
        stored = std::max(stored, value);
      }
    }
  }
  levels_.push_back(std::move(likelihood));
  // Level k from level k-1: the block of 2^k starting at a cell is four blocks of 2^(k-1).
  for (int level = 1; level < kLevels; ++level) {
    const int half = 1 << (level - 1);
    const std::vector<float> &finer = levels_.back();
    std::vector<float> coarser(cells, 0.0f);
    const int rows = height_ + padding_;
    for (int y = 0; y < rows; ++y) {
      for (int x = 0; x < stride_; ++x) {
        const auto value = [&](int xx, int yy) {
          return xx < stride_ && yy < rows
                     ? finer[static_cast<std::size_t>(yy) * static_cast<std::size_t>(stride_) +
                             static_cast<std::size_t>(xx)]
                     : 0.0f;
        };
        coarser[static_cast<std::size_t>(y) * static_cast<std::size_t>(stride_) +
                static_cast<std::size_t>(x)] =
            std::max(std::max(value(x, y), value(x + half, y)),
                     std::max(value(x, y + half), value(x + half, y + half)));
      }
    }
    levels_.push_back(std::move(coarser));
  }
}

float CorrelativeMatcher::at(int level, int x, int y) const {
  const int px = x + padding_, py = y + padding_;
  if (px < 0 || py < 0 || px >= stride_ || py >= height_ + padding_) return 0.0f;
  return levels_[static_cast<std::size_t>(level)]
                [static_cast<std::size_t>(py) * static_cast<std::size_t>(stride_) +
                 static_cast<std::size_t>(px)];
}

Points2 CorrelativeMatcher::thinned(const Points2 &scan_base) const {
  Points2 kept;
  std::unordered_set<std::uint64_t> occupied;
  for (const Point2 &p : scan_base) {
    if (!p.allFinite()) continue;
    const auto cx = static_cast<std::int64_t>(std::floor(p.x() / config_.scan_voxel_m));
    const auto cy = static_cast<std::int64_t>(std::floor(p.y() / config_.scan_voxel_m));
    const auto key = (static_cast<std::uint64_t>(cx) << 32U) ^ static_cast<std::uint64_t>(cy & 0xffffffff);
    if (occupied.insert(key).second) kept.push_back(p);
  }
  return kept;
}

double CorrelativeMatcher::point_score(const Eigen::Vector2d &point_map) const {
  const Eigen::Vector2d cell = (point_map - origin_m_) / config_.resolution_m - Eigen::Vector2d(0.5, 0.5);
  const int x = static_cast<int>(std::floor(cell.x())), y = static_cast<int>(std::floor(cell.y()));
  const double fx = cell.x() - x, fy = cell.y() - y;
  return (1.0 - fy) * ((1.0 - fx) * at(0, x, y) + fx * at(0, x + 1, y)) +
         fy * ((1.0 - fx) * at(0, x, y + 1) + fx * at(0, x + 1, y + 1));
}

double CorrelativeMatcher::score(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base) const {
  if (empty() || scan_base.empty()) return 0.0;
  double sum = 0.0;
  for (const Point2 &p : scan_base) sum += point_score(T_map_base * p);
  return sum / static_cast<double>(scan_base.size());
}

double CorrelativeMatcher::log_likelihood(const Points2 &scan_base, const Eigen::Isometry2d &T_map_base,
                                          double outlier_share) const {
  double sum = 0.0;
  for (const Point2 &p : thinned(scan_base))
    sum += std::log(outlier_share + (1.0 - outlier_share) * (empty() ? 0.0 : point_score(T_map_base * p)));
  return sum;
}

std::vector<PoseCandidate> CorrelativeMatcher::search(const Points2 &scan_base, double min_score,
                                                      double relative_score, double distinct_m,
                                                      double distinct_rad,
                                                      const std::optional<SearchWindow> &window) const {
  const Points2 scan = thinned(scan_base);
  if (empty() || scan.empty()) return {};
  const double resolution = config_.resolution_m;

  // Yaw step: the farthest point moves by at most one cell between neighbouring yaws.
  double farthest_m = resolution;
  for (const Point2 &p : scan) farthest_m = std::max(farthest_m, p.norm());
  const double step_rad =
      std::acos(std::max(-1.0, 1.0 - resolution * resolution / (2.0 * farthest_m * farthest_m)));
  std::vector<double> yaws;
  if (window) {
    const int half = static_cast<int>(std::ceil(window->half_angle_rad / step_rad));
    for (int i = -half; i <= half; ++i) yaws.push_back(yaw_rad_of(window->T_map_base) + i * step_rad);
  } else {
    const int count = static_cast<int>(std::ceil(2.0 * std::numbers::pi / step_rad));
    for (int i = 0; i < count; ++i) yaws.push_back(2.0 * std::numbers::pi * i / count);
  }

  // Translations (cells): the robot stands inside the map's grid, or inside the window.
  int x_first = static_cast<int>(std::ceil(origin_m_.x() / resolution));
  int y_first = static_cast<int>(std::ceil(origin_m_.y() / resolution));
  int x_last = static_cast<int>(std::floor((origin_m_.x() + width_ * resolution) / resolution));
  int y_last = static_cast<int>(std::floor((origin_m_.y() + height_ * resolution) / resolution));
  if (window) {
    const Eigen::Vector2d centre = window->T_map_base.translation();
    x_first = std::max(x_first, static_cast<int>(std::floor((centre.x() - window->radius_m) / resolution)));
    y_first = std::max(y_first, static_cast<int>(std::floor((centre.y() - window->radius_m) / resolution)));
    x_last = std::min(x_last, static_cast<int>(std::ceil((centre.x() + window->radius_m) / resolution)));
    y_last = std::min(y_last, static_cast<int>(std::ceil((centre.y() + window->radius_m) / resolution)));
  }
  if (x_first > x_last || y_first > y_last) return {};

  // Each yaw's scan as cell offsets: a point's cell under translation (x, y) is offset + (x, y).
  std::vector<std::vector<Eigen::Vector2i>> offsets(yaws.size());
  for (std::size_t a = 0; a < yaws.size(); ++a) {
    const Eigen::Rotation2Dd rotation(yaws[a]);
    offsets[a].reserve(scan.size());
    for (const Point2 &p : scan) {
      const Eigen::Vector2d cell = (rotation * p - origin_m_) / resolution;
      offsets[a].emplace_back(static_cast<int>(std::floor(cell.x())), static_cast<int>(std::floor(cell.y())));
    }
  }
  const auto bound = [&](const Node &node) {
    double sum = 0.0;
    for (const Eigen::Vector2i &o : offsets[static_cast<std::size_t>(node.angle)])
      sum += at(node.level, o.x() + node.x, o.y() + node.y);
    return sum / static_cast<double>(scan.size());
  };

  // Depth first, most promising child first; a block is opened only if its bound can still
  // reach the acceptance threshold, which rises with the best score found.
  const int top = kLevels - 1, block = 1 << top;
  std::vector<Node> stack;
  for (std::size_t a = 0; a < yaws.size(); ++a) {
    for (int y = y_first; y <= y_last; y += block) {
      for (int x = x_first; x <= x_last; x += block) {
        Node node{static_cast<int>(a), x, y, top, 0.0};
        node.bound = bound(node);
        if (node.bound >= min_score) stack.push_back(node);
      }
    }
  }
  std::sort(stack.begin(), stack.end(), [](const Node &a, const Node &b) { return a.bound < b.bound; });
  double best = 0.0;
  std::vector<PoseCandidate> leaves;
  std::vector<Node> children;
  while (!stack.empty()) {
    const Node node = stack.back();
    stack.pop_back();
    const double threshold = std::max(min_score, relative_score * best);
    if (node.bound < threshold) continue;
    if (node.level == 0) {
      const double x_m = node.x * resolution, y_m = node.y * resolution;
      if (window && (Eigen::Vector2d(x_m, y_m) - window->T_map_base.translation()).norm() > window->radius_m)
        continue;
      leaves.push_back({planar_pose(x_m, y_m, yaws[static_cast<std::size_t>(node.angle)]), node.bound});
      best = std::max(best, node.bound);
      continue;
    }
    const int half = 1 << (node.level - 1);
    children.clear();
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        Node child{node.angle, node.x + dx * half, node.y + dy * half, node.level - 1, 0.0};
        if (child.x > x_last || child.y > y_last) continue;
        child.bound = bound(child);
        if (child.bound >= threshold) children.push_back(child);
      }
    }
    std::sort(children.begin(), children.end(),
              [](const Node &a, const Node &b) { return a.bound < b.bound; });
    stack.insert(stack.end(), children.begin(), children.end());
  }

  // Distinct poses, best first: a leaf near a better one is the same peak.
  std::sort(leaves.begin(), leaves.end(),
            [](const PoseCandidate &a, const PoseCandidate &b) { return a.score > b.score; });
  std::vector<PoseCandidate> distinct;
  for (const PoseCandidate &leaf : leaves) {
    if (leaf.score < relative_score * best) break;
    const bool known = std::any_of(distinct.begin(), distinct.end(), [&](const PoseCandidate &kept) {
      return (kept.T_map_base.translation() - leaf.T_map_base.translation()).norm() <= distinct_m &&
             std::abs(std::remainder(yaw_rad_of(kept.T_map_base) - yaw_rad_of(leaf.T_map_base),
                                     2.0 * std::numbers::pi)) <= distinct_rad;
    });
    if (!known) distinct.push_back(leaf);
  }
  return distinct;
}

}  // namespace omnislam::slam
