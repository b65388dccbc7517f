#include "omnislam/slam/odometry_noise.hpp"
#include "omnislam/slam/planar_pose.hpp"

#include <cmath>
#include <numbers>
#include <random>

namespace omnislam::slam {

std::vector<Eigen::Isometry2d> apply_thesis_odometry_noise(const std::vector<Eigen::Isometry2d> &exact,
                                                           std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Isometry2d> noisy;
  if (exact.empty()) return noisy;
  noisy.push_back(exact.front());
  for (std::size_t i = 1; i < exact.size(); ++i) {
    const Eigen::Isometry2d step = exact[i - 1].inverse() * exact[i];
    const double step_yaw = yaw_rad_of(step);
    const double length_scale = 1.0 + 0.10 * unit(rng);
    const double relative = 0.10 * unit(rng) * step_yaw;
    const double absolute = 1.5 * std::numbers::pi / 180.0 * unit(rng);
    const double yaw_error = std::abs(relative) > std::abs(absolute) ? relative : absolute;
    Eigen::Isometry2d noisy_step = Eigen::Isometry2d::Identity();
    noisy_step.linear() = Eigen::Rotation2Dd(step_yaw + yaw_error).toRotationMatrix();
    noisy_step.translation() = length_scale * step.translation();
    noisy.push_back(noisy.back() * noisy_step);
  }
  return noisy;
}

}  // namespace omnislam::slam
