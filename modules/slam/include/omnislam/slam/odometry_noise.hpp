#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

/// @file
/// The odometry noise model "thesis" (architecture.md, thesis sec. 5.3), applied per step
/// and composed so errors accumulate like real dead reckoning.

namespace omnislam::slam {

/// Each step's translation length is scaled by 1 + U(-0.10, 0.10) (direction kept in the
/// robot frame); its yaw gets an added error equal to the larger in magnitude of
/// U(-0.10, 0.10) x the step's true yaw change and U(-1.5, 1.5) deg. The first pose is kept.
/// Deterministic for a given seed.
[[nodiscard]] std::vector<Eigen::Isometry2d> apply_thesis_odometry_noise(
    const std::vector<Eigen::Isometry2d> &exact, std::uint64_t seed);

}  // namespace omnislam::slam
