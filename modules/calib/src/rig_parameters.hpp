#pragma once

#include <array>

#include "omnislam/calib/rig_fit.hpp"
#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// The rig's parameters as one Ceres parameter block (RigParameter order), shared by the
/// fits with known points (rig_fit.cpp) and with a target of unknown pose (target_fit.cpp).

namespace omnislam::calib::detail {

// Parameters in units of similar effect (about a pixel each): px, px, 1e-3 of focal length,
// mm, mrad, mrad, mm, mm. Near-equal scales keep the trust region round.
inline constexpr std::array<double, kRigParameters> kUnit{1.0, 1.0, 1e-3, 1.0, 1e-3, 1e-3, 1.0, 1.0};

inline mirror::MirrorConfig apply(mirror::MirrorConfig config, const double *p) {
  config.center_u_px = p[kCenterU] * kUnit[kCenterU];
  config.center_v_px = p[kCenterV] * kUnit[kCenterV];
  config.rig.focal_scale = p[kFocalScale] * kUnit[kFocalScale];
  config.rig.mirror_dz_mm = p[kMirrorDz] * kUnit[kMirrorDz];
  config.rig.mirror_tilt_x_rad = p[kTiltX] * kUnit[kTiltX];
  config.rig.mirror_tilt_y_rad = p[kTiltY] * kUnit[kTiltY];
  config.rig.mirror_offset_x_mm = p[kOffsetX] * kUnit[kOffsetX];
  config.rig.mirror_offset_y_mm = p[kOffsetY] * kUnit[kOffsetY];
  return config;
}

inline std::array<double, kRigParameters> parameters_of(const mirror::MirrorConfig &config) {
  std::array<double, kRigParameters> p{config.center_u_px,
                                       config.center_v_px,
                                       config.rig.focal_scale,
                                       config.rig.mirror_dz_mm,
                                       config.rig.mirror_tilt_x_rad,
                                       config.rig.mirror_tilt_y_rad,
                                       config.rig.mirror_offset_x_mm,
                                       config.rig.mirror_offset_y_mm};
  for (int i = 0; i < kRigParameters; ++i) p[i] /= kUnit[i];
  return p;
}

}  // namespace omnislam::calib::detail
