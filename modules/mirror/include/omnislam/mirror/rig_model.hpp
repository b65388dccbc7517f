#pragma once

#include <Eigen/Core>
#include <optional>

#include "omnislam/mirror/mirror_model.hpp"

/// @file
/// The general (3D) image formation of a rig whose mirror and camera are not as designed
/// (RigConfig: focal scale, mirror shift along the axis, tilt and lateral offset; issue 12).
///
/// Without rotational symmetry a pixel's ray is traced: pixel -> camera ray through the
/// pinhole -> intersection with the lobe's surface of revolution in the mirror's pose ->
/// reflection about the surface normal -> world ray. The outer lobe's tilted profile
/// revolved about the mirror axis is a quartic surface, not a quadric, so the intersection
/// is found by Newton's method on the profile along the ray, started at the designed
/// mirror point (closed form, mirror.md sec. 2); it converges in 3-5 steps. Projection
/// (point -> pixel) is Gauss-Newton on the pixel, started at the designed model's pixel.
///
/// Frame: the camera frame of mirror.md (origin F0, z up the optical axis), with x along
/// image +u and y along image +v (architecture.md), in metres; for a rig turned off level
/// (RigConfig::level_tilt_*) rays and points are in the level frame, the camera frame turned
/// back by that tilt about the pinhole (z along the floor's normal). The lobes are taken as
/// the analytic surfaces: whether a lobe really covers a pixel is for the caller to judge
/// (the designed annuli of image radii, or mirror_radius_mm()). All functions are const
/// and thread-safe.

namespace omnislam::mirror {

/// A world ray: it leaves the mirror at `origin_m` along the unit `direction`.
struct Ray3 {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
};

/// A pixel in the image (architecture.md: u right, v down, centres at integers).
struct Pixel {
  double u_px = 0.0;
  double v_px = 0.0;
};

/// The closest point of two rays and how well they met.
struct RayIntersection {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  ///< midpoint of the closest approach
  double gap_m = 0.0;                                 ///< distance between the rays there
};

/// A turn about x by tilt_x_rad, then about y by tilt_y_rad (right-handed): RigConfig's tilts
/// (the mirror's, taking its design frame to the camera's; the whole rig's off level, taking
/// camera coordinates to the level frame's).
[[nodiscard]] Eigen::Matrix3d tilt_rotation(double tilt_x_rad, double tilt_y_rad);

class RigModel {
 public:
  /// Uses the design of `config` (lobes, focal_mm, pitch, centre) and its `rig`.
  /// Throws std::invalid_argument like MirrorModel on a config that describes no mirror.
  explicit RigModel(const MirrorConfig &config = {});

  [[nodiscard]] const MirrorModel &design() const { return design_; }
  [[nodiscard]] const MirrorConfig &config() const { return design_.config(); }

  /// The world ray seen through `lobe` at `pixel`, or nullopt when the camera ray misses
  /// the lobe's surface (or the surface normal is degenerate, on the axis).
  [[nodiscard]] std::optional<Ray3> back_project(Lobe lobe, const Pixel &pixel) const;

  /// The pixel at which `lobe` images `point_m` (camera frame), or nullopt when the
  /// iteration does not converge or the point is behind the mirror. The pixel is not
  /// checked against the image or the lobe's annulus.
  [[nodiscard]] std::optional<Pixel> project(Lobe lobe, const Eigen::Vector3d &point_m) const;

  /// Horizontal distance (mm) from the mirror's own axis of the lobe point seen at
  /// `pixel` (to compare with the designed lobe's extent), or nullopt when it is missed.
  [[nodiscard]] std::optional<double> mirror_radius_mm(Lobe lobe, const Pixel &pixel) const;

  /// Whether the camera ray of `pixel` meets `lobe` within the part of the surface the
  /// mirror has: the mirror radii (about its own axis) of the designed pixel annulus
  /// (mirror.md sec. 0; the renderer clips the lobes there), less `margin_px` of image
  /// radius at each edge, and for the outer lobe not hidden behind the inner lobe. Near the
  /// split between the lobes and at the rim, a misaligned rig's pixels see the other lobe,
  /// the gap or the housing instead.
  [[nodiscard]] bool sees_lobe(Lobe lobe, const Pixel &pixel, double margin_px = 0.0) const;

  /// The pixel at which the camera sees directly (not in the mirror) the point of the lobe
  /// that the designed rig images at `radius_px` and azimuth `phi_rad`: at 512 px the
  /// mirror's rim, at 62 px the edge of the inner lobe's central opening (the circles the
  /// rim method fits). nullopt when the point is behind the camera.
  [[nodiscard]] std::optional<Pixel> mirror_edge_pixel(Lobe lobe, double radius_px, double phi_rad) const;

  /// Closest approach of the inner and outer rays; nullopt when they are parallel or the
  /// closest point lies behind either ray's origin (the rays do not meet in front of the
  /// mirror, as in mirror.md sec. 6).
  [[nodiscard]] static std::optional<RayIntersection> intersect(const Ray3 &inner, const Ray3 &outer);

 private:
  struct MirrorHit {
    Eigen::Vector3d point_mm;  ///< on the lobe, mirror frame
    Eigen::Vector3d normal;    ///< unit, mirror frame
    Eigen::Vector3d ray_dir;   ///< unit camera-ray direction, mirror frame
  };
  [[nodiscard]] std::optional<MirrorHit> hit(Lobe lobe, const Pixel &pixel) const;

  MirrorModel design_;
  Eigen::Matrix3d rotation_;  ///< R: mirror (design) frame -> camera frame
  Eigen::Matrix3d level_;     ///< camera frame -> level frame (RigConfig::level_tilt_*)
  Eigen::Vector3d pivot_mm_;  ///< the designed inner focus
  Eigen::Vector3d shift_mm_;  ///< (offset_x, offset_y, dz)
  double focal_px_ = 0.0;     ///< true focal length in pixels
  struct Extent {
    double min_mm = 0.0;     ///< mirror radius at the annulus's inner edge
    double max_mm = 0.0;     ///< and at its outer edge
    double mm_per_px = 0.0;  ///< mean mirror radius per pixel of image radius
  };
  Extent inner_extent_, outer_extent_;
};

}  // namespace omnislam::mirror
