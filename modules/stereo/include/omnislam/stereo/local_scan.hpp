#pragma once

#include <vector>

/// @file
/// The local scan of one image: what the SLAM module consumes.
/// Frame: base_link (REP-105: x forward, y left, z up; origin on the mirror axis at floor
/// level), metres and radians.

namespace omnislam::stereo {

struct ScanPoint {
  double azimuth_rad = 0.0;  ///< atan2(y, x) in [0, 2 pi): the panorama column's azimuth
  double range_m = 0.0;      ///< horizontal distance from the mirror axis
  double x_m = 0.0;
  double y_m = 0.0;
  double z_m = 0.0;        ///< above the floor: camera_height_m + height relative to the pinhole
  float inner_row = 0.0f;  ///< matched panorama rows (fractional after sub-pixel refinement)
  float outer_row = 0.0f;
  int column = 0;  ///< the panorama column the point was found in
  /// How far the range moves per pixel of error in the rows that placed it (m/px): the
  /// floor plane's slope at the row for a floor contact, both rows' effect combined for a
  /// stereo point; infinite when half a pixel already loses the intersection. The
  /// registration weighs points by it (slam/trimmed_icp.hpp).
  float range_per_px_m = 0.0f;
  /// Ranged from the floor plane at the inner row (a floor contact), not by stereo.
  bool floor_ranged = false;
  /// An edge found above the floor (a table's edge, a shelf), not where something stands on
  /// it: floor seen beyond or under it does not contradict it (grid/occupancy_grid.hpp). The
  /// thesis's nearest-edge matcher does not tell: false.
  bool elevated = false;
};

/// Counts after each step of the reconstruction, for logs, profiles and tests.
struct LobeStats {
  int canny_px = 0;             ///< Canny edge pixels
  int fragment_px_removed = 0;  ///< of which in fragments too small to keep
  int horizontal_px = 0;        ///< horizontal edge pixels among the runs examined
  int runs = 0;                 ///< edge runs examined, bottom-up
  int not_local_max = 0;
  int low_contrast = 0;
  int candidates = 0;  ///< edge points handed to the matcher
  double low_threshold = 0.0;
  double high_threshold = 0.0;
  double noise_high_threshold = 0.0;  ///< the largest row threshold the frame's noise raised (0: none)
};

struct ScanStats {
  LobeStats inner;
  LobeStats outer;
  int admissible_pairs = 0;  ///< candidate pairs inside the disparity band
  int matched = 0;           ///< pairs chosen by the DP
  int occluded_inner = 0;
  int occluded_outer = 0;
  int no_intersection = 0;  ///< matches whose rays do not meet
  int outside_cutoffs = 0;  ///< points dropped by the near/far cut-offs
  int filtered_out = 0;     ///< points dropped by the one-point-per-degree filter
  // Floor-boundary search (stereo::BoundaryMethod::kFloorBoundary), per frame:
  int floor_texture_edges = 0;  ///< edges the floor hypothesis explained (free floor)
  int floor_contacts = 0;       ///< boundaries on the floor
  int undecided = 0;            ///< of which neither hypothesis won (uniform surfaces)
  int elevated = 0;             ///< boundaries above the floor (triangulated)
  int unexplained = 0;          ///< edges off the floor without an outer match
  int drops = 0;                ///< of which below the floor (a lower floor past a step down)
  float noise_scale = 0.0f;     ///< photometric residual scale (intensity in [0, 1])
  /// Sub-pixel placement error of the frame's edges (rows, Laplace scale): the spread of floor
  /// edges' outer twins about where the floor puts them.
  float twin_spread_px = 0.0f;
  int points = 0;  ///< points in the scan
  /// The frame's sensor noise, grey levels (vision/image_noise.hpp; 0 when not measured).
  float image_noise_dn = 0.0f;
};

enum class ScanStatus {
  kOk,
  kBadImage,  ///< not 8-bit single channel of the configured camera size
};

struct LocalScan {
  ScanStatus status = ScanStatus::kOk;
  std::vector<ScanPoint> points;  ///< ordered by azimuth, then bottom-up within a column
  /// Per panorama column (column j at azimuth (j + 0.5) * 360 / columns deg + the offset), how far the floor
  /// was seen to be free (m): up to the boundary found, or up to the farthest floor texture where none was;
  /// NaN where nothing was seen. Empty for the nearest-edge method.
  std::vector<float> free_range_m;
  /// Per panorama column, where the floor ended in a drop before any boundary: a lower floor
  /// (past a step down) was seen beyond, and this is the range at which the ray that reached
  /// it crossed the floor's level (the step's rim is nearer). NaN where none was seen; empty
  /// for the nearest-edge method. Not scan points: what lies there depends on the viewpoint.
  std::vector<float> drop_range_m;
  /// Per panorama column with a drop, the range in plan of the lower floor's point the ray
  /// reached (from drop_range_m to here it ran below the floor's level: over the lower floor,
  /// not where the robot can go); NaN elsewhere.
  std::vector<float> drop_lower_range_m;
  ScanStats stats;
};

}  // namespace omnislam::stereo
