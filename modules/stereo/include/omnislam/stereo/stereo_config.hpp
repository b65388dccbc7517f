#pragma once

#include "omnislam/mirror/mirror_config.hpp"
#include "omnislam/vision/vision_config.hpp"

/// @file
/// Settings of the stereo matching and of the local scan (thesis sec. 3 steps 5-7).

namespace omnislam::stereo {

/// How a match is refined below one pixel.
enum class SubpixelMethod {
  kNone,      ///< integer rows, as the thesis
  kEdgePeak,  ///< each lobe's edge row refined by a parabola through its gradient peak
  /// Disparity from an equiangular fit through SAD at d-1, d, d+1 (at the integer inner
  /// row), applied at the edge-peak inner row.
  kCostCurve,
};

/// How a matched pair of rows becomes a point.
enum class TriangulationMethod {
  kExact,  ///< the closed-form model at fractional rows (mirror.md sec. 6)
  kTable,  ///< the thesis's 225x225 table at rounded integer rows (annex A1.3)
};

/// What ends the free floor in a column.
enum class BoundaryMethod {
  kNearestEdge,    ///< the thesis: DP-matched nearest horizontal edges (sec. 3 steps 3-5)
  kFloorBoundary,  ///< the first edge that is not floor texture (floor_boundary.hpp)
};

/// The floor-boundary search (floor_boundary.hpp).
struct FloorBoundaryConfig {
  /// Horizontal edges examined per column, nearest first: a tiled floor gives two per grout
  /// line, so 400 mm tiles put ~10 between the robot and a wall 2 m away, more with shadows.
  int max_edges_per_column = 32;
  /// An edge is on the floor when the outer lobe has an edge of the same polarity within
  /// this many pixels of the row the floor predicts. Two sub-pixel edge peaks differ by
  /// ~0.2 px (1 sigma) on a calibrated rig, so 0.5 px is ~2.5 sigma; anything more lets the
  /// top of a skirting board (8 cm up, 0.8 px off at 2 m) pass as the wall's base and puts the
  /// wall ~8% too far. A rig known to worse than ~0.2 px should raise it.
  double contact_margin_px = 0.5;
  /// Error rate of the floor-or-wall test (Wald's thresholds +-ln((1 - a) / a)).
  double error_rate = 0.01;
  /// Range of a floor contact: from the floor plane (true) or from the stereo pair.
  bool floor_plane_range = true;
  /// When > 0, a floor contact's row for its floor-plane range is measured along the
  /// mirror's rays (vision/ray_subpixel.hpp), its column smoothed along itself with a
  /// Gaussian of this sigma (px), not across columns as the edge search's rows are. It
  /// removes the bend of walls seen obliquely on the realistic rooms, but off by default:
  /// the runs' figures move both ways (docs/frontend.md, "Where the degraded L-room's error
  /// comes from", 2026-12-04).
  /// 0: the edge's own sub-pixel row.
  double contact_ray_sigma_px = 0.0;
};

struct StereoConfig {
  BoundaryMethod boundary = BoundaryMethod::kFloorBoundary;
  FloorBoundaryConfig floor;
  /// Disparity search band, derived per inner row from the mirror model (no fixed
  /// 10..90 px): only points with horizontal range in [min_range_m, max_range_m] at or
  /// above the floor are searched for, widened by disparity_margin_px on both sides.
  double min_range_m = 0.3;
  double max_range_m = 6.0;
  double disparity_margin_px = 1.0;
  double occlusion_cost = 2.5;  ///< DP cost of leaving an edge point unmatched (CustoOclusao)
  SubpixelMethod subpixel = SubpixelMethod::kEdgePeak;
  TriangulationMethod triangulation = TriangulationMethod::kExact;
  /// Scan cut-offs on the horizontal range (thesis Corte_inferior / Corte_superior).
  double near_cutoff_m = 0.3;
  double far_cutoff_m = 5.0;
  bool one_point_per_degree = true;  ///< keep the nearest point of each degree (thesis Filtro)
};

/// Everything one image needs to become a local scan.
struct ScanConfig {
  mirror::MirrorConfig camera;   ///< camera intrinsics, mirror, pixel split, azimuth offset
  double camera_height_m = 1.0;  ///< pinhole F0 above the floor (base_link origin)
  vision::VisionConfig vision;
  StereoConfig stereo;
};

}  // namespace omnislam::stereo
