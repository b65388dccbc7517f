#pragma once

#include <optional>

#include "omnislam/mirror/mirror_config.hpp"

/// @file
/// Image formation and triangulation of the double-lobed hyperbolic mirror (mirror.md).
///
/// The model is rotationally symmetric, so a world point is given in its azimuthal
/// half-plane as (range_m, height_m): horizontal distance from the camera axis and height
/// relative to the pinhole F0 (negative below it). Angles are radians; "theta" is the
/// elevation of the incoming ray at the lobe's focus, measured from the downward vertical.
/// Panorama rows follow mirror.md sec. 0: 0-based, row 0 at the annulus edge farthest
/// from the image centre, row centres at the half-pixel (inner R = 286.5 - row px).
/// All functions are const and thread-safe.

namespace omnislam::mirror {

enum class Lobe { kInner, kOuter };

/// A point in the meridian half-plane, metres, relative to the pinhole.
struct MeridianPoint {
  double range_m = 0.0;
  double height_m = 0.0;
};

/// A ray leaving a lobe's focus towards the world, in the meridian half-plane.
struct MeridianRay {
  MeridianPoint origin;    ///< the lobe's focus
  double theta_rad = 0.0;  ///< from the downward vertical, positive away from the axis
};

class MirrorModel {
 public:
  /// Derives every lobe constant from the config. Throws std::invalid_argument if the
  /// config describes no hyperbola (c <= a, non-positive focal length or pitch, ...).
  explicit MirrorModel(const MirrorConfig &config = {});

  [[nodiscard]] const MirrorConfig &config() const { return config_; }

  /// Image radius in pixels at which `lobe` images the point, or nullopt when the point
  /// falls outside that lobe's pixel annulus (invisible) or behind the lobe's focus.
  [[nodiscard]] std::optional<double> project_radius_px(Lobe lobe, const MeridianPoint &point) const;

  /// Continuous panorama row of the point in `lobe`, or nullopt when invisible.
  [[nodiscard]] std::optional<double> project_row(Lobe lobe, const MeridianPoint &point) const;

  /// Image radius (px) of the incoming elevation theta; nullopt if theta is out of
  /// the lobe's geometric range (not necessarily inside the annulus).
  [[nodiscard]] std::optional<double> radius_px_of_theta(Lobe lobe, double theta_rad) const;

  /// Elevation theta of the ray imaged at `radius_px` (mirror.md sec. 5).
  [[nodiscard]] double theta_of_radius_px(Lobe lobe, double radius_px) const;

  /// The world ray imaged at `radius_px`.
  [[nodiscard]] MeridianRay back_project(Lobe lobe, double radius_px) const;

  /// Row <-> radius with the half-pixel convention (inner R = 286.5 - row for the thesis).
  [[nodiscard]] double radius_px_of_row(Lobe lobe, double row) const;
  [[nodiscard]] double row_of_radius_px(Lobe lobe, double radius_px) const;

  /// Closed-form intersection of the inner and outer rays (thesis eq. 2-6, signs fixed).
  /// nullopt when the rays are parallel or do not meet in front of both foci.
  [[nodiscard]] std::optional<MeridianPoint> triangulate(double theta_inner_rad,
                                                         double theta_outer_rad) const;

  /// Triangulation from continuous (sub-pixel) panorama rows.
  [[nodiscard]] std::optional<MeridianPoint> triangulate_rows(double inner_row, double outer_row) const;

  /// Disparity outer_row - inner_row of a point at infinity seen at elevation theta
  /// (mirror.md sec. 8: not exactly zero).
  [[nodiscard]] double disparity_at_infinity(double theta_rad) const;

  /// Elevations covered by the lobe's pixel annulus: {theta at the centre-side edge,
  /// theta at the far edge}.
  struct ThetaRange {
    double min_rad = 0.0;
    double max_rad = 0.0;
  };
  [[nodiscard]] ThetaRange theta_range(Lobe lobe) const;

  /// Pixel annulus of the lobe, [min, max) in px from the optical axis.
  struct RadiusRange {
    double min_px = 0.0;
    double max_px = 0.0;
  };
  [[nodiscard]] RadiusRange radius_range(Lobe lobe) const;

  /// Derived constants of one lobe (mm, rad), exposed for tests and for renderers.
  struct LobeConstants {
    double focus_r_mm = 0.0;
    double focus_z_mm = 0.0;
    double a_mm = 0.0;
    double c_mm = 0.0;
    double b_mm = 0.0;
    double k = 0.0;
    double beta_rad = 0.0;
  };
  [[nodiscard]] const LobeConstants &constants(Lobe lobe) const;

 private:
  MirrorConfig config_;
  LobeConstants inner_;
  LobeConstants outer_;
};

}  // namespace omnislam::mirror
