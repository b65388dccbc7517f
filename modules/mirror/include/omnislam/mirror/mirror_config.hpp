#pragma once

/// @file
/// Camera and double-lobed mirror description (mirror.md sec. 0-1).
/// Defaults are the thesis camera and mirror as rendered by scripts/render-dataset, so every
/// command works on a rendered image without a configuration file.

namespace omnislam::mirror {

/// One hyperbolic lobe, given in the camera frame: the camera pinhole F0 is the origin and
/// z points up along the optical axis. The lobe is a hyperbola with foci F0 and F (the focus
/// may be off the axis, which tilts the lobe by beta = atan2(r_focus, z_focus)), revolved
/// about the camera axis. The remaining constants (c, b, k, beta) are derived in double
/// precision so the model is exactly self-consistent (mirror.md sec. 7, point 6).
struct LobeConfig {
  double focus_r_mm = 0.0;  ///< horizontal offset of the lobe's focus from the camera axis
  double focus_z_mm = 0.0;  ///< height of the lobe's focus above the pinhole
  double a_mm = 0.0;        ///< semi-major axis of the hyperbola
};

/// How an assembled rig differs from its design (issue 12). The defaults are the design:
/// with every member at its default the model is the closed-form, rotationally symmetric one
/// of mirror.md and results are bit-identical to a build without this struct.
///
/// The mirror is a rigid body (both lobes). Its pose in the camera frame (x = image u,
/// y = image v, z up the optical axis, origin at the pinhole F0) is
///     p_camera = R (p_design - pivot) + pivot + (offset_x, offset_y, dz),
///     R = Ry(tilt_y) Rx(tilt_x),  pivot = (0, 0, inner focus height) = the designed F_I,
/// so a tilt turns the mirror about two horizontal axes through the designed inner focus
/// and the shifts then move it as a whole. The camera's true focal length is
/// focal_scale * focal_mm (a lens focused slightly differently, or a sensor at another
/// distance); the image centre is MirrorConfig::center_*_px as before.
struct RigConfig {
  double focal_scale = 1.0;         ///< true focal length / MirrorConfig::focal_mm
  double mirror_dz_mm = 0.0;        ///< mirror moved up (+) along the camera axis
  double mirror_tilt_x_rad = 0.0;   ///< mirror turned about the camera x axis (right-handed)
  double mirror_tilt_y_rad = 0.0;   ///< then about the camera y axis (right-handed)
  double mirror_offset_x_mm = 0.0;  ///< mirror moved along the camera x axis (image +u)
  double mirror_offset_y_mm = 0.0;  ///< mirror moved along the camera y axis (image +v)
  /// The whole rig (camera and mirror together) turned about the pinhole away from level:
  /// about the camera x axis, then the y axis (right-handed), so that its optical axis is off
  /// the floor's normal (a mount that is not square, a robot that leans). Rays and points
  /// are then in the level frame (z along the floor's normal, x and y the camera's turned
  /// back), where the floor is z = -camera height.
  double level_tilt_x_rad = 0.0;
  double level_tilt_y_rad = 0.0;

  /// True when the rig is exactly as designed (the closed-form model applies).
  [[nodiscard]] bool nominal() const {
    return focal_scale == 1.0 && mirror_dz_mm == 0.0 && mirror_tilt_x_rad == 0.0 &&
           mirror_tilt_y_rad == 0.0 && mirror_offset_x_mm == 0.0 && mirror_offset_y_mm == 0.0 &&
           level_tilt_x_rad == 0.0 && level_tilt_y_rad == 0.0;
  }
};

/// Camera intrinsics plus the mirror. All lengths in millimetres because the thesis's
/// tables are; the model's public functions speak metres.
struct MirrorConfig {
  int image_width_px = 1024;
  int image_height_px = 1024;
  double center_u_px = 511.5;  ///< optical axis, pixel centres at integers
  double center_v_px = 511.5;
  double focal_mm = 25.0;
  double pixel_pitch_mm = 3.5945 / 512.0;

  LobeConfig inner{0.0, 270.300, 123.794};     ///< thesis table 1.1
  LobeConfig outer{25.756, 420.300, 193.610};  ///< thesis table 1.1

  /// Radial bins [0, discard_px) are dropped; the inner lobe uses the next rows_per_lobe
  /// bins and the outer lobe the rows_per_lobe after those (thesis: 62 | 225 | 225).
  int discard_px = 62;
  int rows_per_lobe = 225;
  int columns = 360;                ///< panorama columns, one per 360/columns degrees
  double azimuth_offset_deg = 0.0;  ///< shifts the azimuth origin (thesis Anguloajuste)

  RigConfig rig;  ///< misalignments of the real rig (default: none)
  /// Depth of the reference surface below the pinhole used by the panorama maps of a
  /// misaligned rig (the floor: the camera height). Unused for a nominal rig.
  double reference_depth_mm = 1000.0;
};

}  // namespace omnislam::mirror
